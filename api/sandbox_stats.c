/*
 * api/sandbox_stats — the import sandbox's counters (see sandbox_stats.h): relaxed atomics
 * only, so recording never waits and never takes a lock a job could hold.
 */
#include <stdatomic.h>
#include <string.h>
#include "sandbox_stats.h"

const char *const API_SBX_JOB_NAMES[API_SBX_JOBS] = {"model", "levels", "image"};
const char *const API_SBX_OUTCOME_NAMES[API_SBX_OUTCOMES] = {"ok", "invalid", "crashed", "timed_out",
                                                             "over_memory", "error"};
const double API_STATS_BUCKET_BOUNDS[API_STATS_BUCKETS] = {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25,
                                                          0.5, 1, 2.5, 5, 10, 30, 60};

struct histogram {
	atomic_uint_fast64_t bucket[API_STATS_BUCKETS], count, sum_us;
};

static atomic_uint_fast64_t started[API_SBX_JOBS], ended[API_SBX_JOBS][API_SBX_OUTCOMES];
static atomic_uint_fast64_t server_starts;
static struct histogram job_seconds[API_SBX_JOBS], stage_seconds[API_IMPORT_STAGES];

#define ADD(a, n) atomic_fetch_add_explicit(&(a), (n), memory_order_relaxed)
#define GET(a) ((uint64_t)atomic_load_explicit(&(a), memory_order_relaxed))

static void observe(struct histogram *h, double seconds)
{
	if (!(seconds >= 0)) seconds = 0;   /* NaN or a clock step back */
	size_t i = 0;
	while (i < API_STATS_BUCKETS && seconds > API_STATS_BUCKET_BOUNDS[i]) i++;
	if (i < API_STATS_BUCKETS) ADD(h->bucket[i], 1);
	ADD(h->count, 1);
	ADD(h->sum_us, (uint_fast64_t)(seconds * 1e6 + 0.5));
}

static void read_histogram(struct histogram *h, struct api_stats_histogram *out)
{
	for (size_t i = 0; i < API_STATS_BUCKETS; i++) out->bucket[i] = GET(h->bucket[i]);
	out->count = GET(h->count);
	out->sum = (double)GET(h->sum_us) / 1e6;
}

void api_sbx_stats_started(enum api_sbx_job job)
{
	if ((unsigned)job < API_SBX_JOBS) ADD(started[job], 1);
}

void api_sbx_stats_ended(enum api_sbx_job job, enum api_sbx_outcome how, double seconds)
{
	if ((unsigned)job >= API_SBX_JOBS || (unsigned)how >= API_SBX_OUTCOMES) return;
	ADD(ended[job][how], 1);
	observe(&job_seconds[job], seconds);
}

void api_sbx_stats_server_started(void)
{
	ADD(server_starts, 1);
}

void api_sbx_stats_import_times(const struct api_import_times *t)
{
	for (int k = API_IMPORT_READ + 1; k < API_IMPORT_STAGES; k++) observe(&stage_seconds[k], t->ms[k] / 1e3);
}

void api_sandbox_stats(struct api_sandbox_stats *out)
{
	memset(out, 0, sizeof *out);
	for (int j = 0; j < API_SBX_JOBS; j++) {
		out->started[j] = GET(started[j]);
		for (int o = 0; o < API_SBX_OUTCOMES; o++) out->ended[j][o] = GET(ended[j][o]);
		read_histogram(&job_seconds[j], &out->job_seconds[j]);
	}
	for (int k = 0; k < API_IMPORT_STAGES; k++) read_histogram(&stage_seconds[k], &out->stage_seconds[k]);
	out->server_starts = GET(server_starts);
	out->server_restarts = out->server_starts ? out->server_starts - 1 : 0;
}
