/* tests — api/workers.c, the import's thread pool: every task of a run exactly once, and the run
 * returns only when all are done, across the pool's stops and starts (the unit tests start and
 * stop it many times; the importer's child starts it once). */
#include <stdatomic.h>
#include "test.h"
#include "workers.h"

enum { TASKS = 64 };
struct hits { atomic_uint n[TASKS]; };

static void count(void *ctx, size_t i, unsigned w)
{
	struct hits *h = ctx;
	(void)w;
	for (volatile unsigned k = 0; k < 2000; k++) {}   /* long enough for the threads to overlap */
	atomic_fetch_add(&h->n[i], 1);
}

/* A pool started after earlier runs began at generation 0 while the pool's count was past it:
 * each new thread ran a phantom generation first and took one off the next run's count of busy
 * threads, so a run could return with tasks still running, or wait forever (a unit test hung
 * 13 minutes in stl_binary_reader_gives_the_same_bytes_on_threads). Timing-dependent: before
 * the fix, 4 of 6 runs of this test hung beside two busy loops; it needs many restarts. */
TEST(workers_restarted_pool_runs_every_task_once)
{
	for (int cycle = 0; cycle < 400; cycle++) {
		REQUIRE(api_workers_start(3) == 0 && api_workers_count() == 3);
		for (int run = 0; run < 2; run++) {
			struct hits h;
			for (int i = 0; i < TASKS; i++) atomic_init(&h.n[i], 0);
			api_workers_run(TASKS, count, &h);
			int wrong = 0;
			for (int i = 0; i < TASKS; i++) wrong += atomic_load(&h.n[i]) != 1;
			CHECK(wrong == 0, "cycle %d run %d: %d tasks not run exactly once when the run returned", cycle, run, wrong);
			if (wrong) break;
		}
		api_workers_stop();
	}
}
