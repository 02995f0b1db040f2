/* tests — srv_queue_pop_idle() (server/queue.c): the idle callback that lets umbrad give memory
 * back runs once per idle period, only when the queue is empty and no request is in work, and
 * again after the next request is done. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "clock.h"
#include "queue.h"
#include "test.h"

struct idle_worker {
	struct srv_queue *q;
	atomic_int idles, served;
};

static void on_idle(void *arg)
{
	struct idle_worker *w = arg;
	atomic_fetch_add(&w->idles, 1);
}

static void *worker(void *arg)
{
	struct idle_worker *w = arg;
	struct srv_request *req;
	while ((req = srv_queue_pop_idle(w->q, 0.02, on_idle, w))) {
		atomic_fetch_add(&w->served, 1);
		srv_queue_done(w->q);
	}
	return NULL;
}

static void sleep_ms(int ms)
{
	struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
	nanosleep(&ts, NULL);
}

/* Waits (bounded) until *v reaches want; returns its value. */
static int wait_for(atomic_int *v, int want)
{
	for (int i = 0; i < 1000 && atomic_load(v) < want; i++) sleep_ms(10);
	return atomic_load(v);
}

TEST(queue_idle_runs_once_per_idle_period_not_while_busy)
{
	struct idle_worker w = {0};
	w.q = srv_queue_create(4);
	REQUIRE(w.q);
	struct srv_request a, b;
	memset(&a, 0, sizeof a);
	memset(&b, 0, sizeof b);
	/* A request in work on another thread (popped, not done): no idle period yet. */
	REQUIRE(srv_queue_push(w.q, &a, NULL) == SRV_PUSH_OK);
	CHECK(srv_queue_pop(w.q) == &a, "pop");
	pthread_t th;
	REQUIRE(pthread_create(&th, NULL, worker, &w) == 0);
	sleep_ms(200);
	CHECK(atomic_load(&w.idles) == 0, "idle ran %d times while a request was in work", atomic_load(&w.idles));
	srv_queue_done(w.q);
	CHECK(wait_for(&w.idles, 1) == 1, "idle did not run after the request was done");
	sleep_ms(200);
	CHECK(atomic_load(&w.idles) == 1, "idle ran %d times in one idle period", atomic_load(&w.idles));
	/* The next request starts a new period. */
	REQUIRE(srv_queue_push(w.q, &b, NULL) == SRV_PUSH_OK);
	CHECK(wait_for(&w.served, 1) == 1, "the request was not served");
	CHECK(wait_for(&w.idles, 2) == 2, "idle did not run after the second request");
	srv_queue_close(w.q);
	pthread_join(th, NULL);
	srv_queue_destroy(w.q);
}

/* Two workers: the one that finished first must not cut the idle period of the one still in
 * work short. The period counts from the last request done, on any thread (found in review:
 * umbrad's idle trim ran 2.9 s after the last request with --idle-trim 3, found that request's
 * shadow maps used too recently to go, and gave nothing back). */
struct hold_worker {
	struct srv_queue *q;
	struct srv_request *slow;
	atomic_int idles;
	_Atomic double done_at, idle_at;
};

static void on_idle_at(void *arg)
{
	struct hold_worker *w = arg;
	atomic_store(&w->idle_at, srv_now());
	atomic_fetch_add(&w->idles, 1);
}

static void *hold_worker_main(void *arg)
{
	struct hold_worker *w = arg;
	struct srv_request *req;
	while ((req = srv_queue_pop_idle(w->q, 0.5, on_idle_at, w))) {
		sleep_ms(req == w->slow ? 400 : 100);
		if (req == w->slow) atomic_store(&w->done_at, srv_now());
		srv_queue_done(w->q);
	}
	return NULL;
}

TEST(queue_idle_period_counts_from_the_last_request_done_on_any_thread)
{
	struct hold_worker w = {0};
	struct srv_request a, b;
	memset(&a, 0, sizeof a);
	memset(&b, 0, sizeof b);
	w.q = srv_queue_create(4);
	w.slow = &b;
	REQUIRE(w.q);
	pthread_t th[2];
	for (int i = 0; i < 2; i++) REQUIRE(pthread_create(&th[i], NULL, hold_worker_main, &w) == 0);
	/* The creation's idle period first. Then one thread takes a (0.1 s) and waits again while
	 * the other still holds b (0.4 s): the idle may run only 0.5 s after b is done. */
	CHECK(wait_for(&w.idles, 1) == 1, "idle did not run after the creation");
	REQUIRE(srv_queue_push(w.q, &a, NULL) == SRV_PUSH_OK);
	REQUIRE(srv_queue_push(w.q, &b, NULL) == SRV_PUSH_OK);
	CHECK(wait_for(&w.idles, 2) == 2, "idle did not run after the requests");
	double done = atomic_load(&w.done_at), idle = atomic_load(&w.idle_at);
	CHECK(done > 0 && idle - done >= 0.5, "idle ran %.3f s after the last request was done (idle_s 0.5)",
	      idle - done);
	srv_queue_close(w.q);
	for (int i = 0; i < 2; i++) pthread_join(th[i], NULL);
	srv_queue_destroy(w.q);
}
