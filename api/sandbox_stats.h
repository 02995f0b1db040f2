/*
 * api/sandbox_stats — what the import sandbox (api/sandbox.h) did since the process started,
 * for operators: jobs by kind and how they ended, fork-server starts, the wall time of each
 * job and the stages of each model import. server/metrics.c prints them on /metrics.
 *
 * Usage: api_sandbox_stats(&s) fills a caller-owned snapshot; nothing to free. The recorders
 * below it are api/'s own (api/sandbox.c, api/model.c call them).
 *
 * Invariants: started[k] >= sum over o of ended[k][o] (a job running now is started, not yet
 * ended); every ended job is observed once in job_seconds[k]; every model import that succeeded
 * (not a cache hit) is observed once per stage in stage_seconds[] (model-read excluded: that is
 * the request's reading of the bytes, done before the import and for cache hits too).
 *
 * Threading: lock-free (relaxed atomics). Each counter is exact; a snapshot taken while jobs
 * run is not one instant across counters.
 */
#ifndef UMBRA_API_SANDBOX_STATS_H
#define UMBRA_API_SANDBOX_STATS_H

#include <stdint.h>
#include "api.h"

/* What a sandbox job does: a model import (its level of detail for the request included), a
 * cached model's levels of detail for another size (api/model_levels.c), an image decode. */
enum api_sbx_job { API_SBX_JOB_MODEL, API_SBX_JOB_LEVELS, API_SBX_JOB_IMAGE, API_SBX_JOBS };

/* How a job ended. */
enum api_sbx_outcome {
	API_SBX_OUT_OK,
	API_SBX_OUT_INVALID,      /* the importer refused the bytes, or its reply failed validation (400) */
	API_SBX_OUT_CRASHED,      /* the child died of a signal (the seccomp filter's SIGSYS included) or
	                             exited with an unexpected code (400) */
	API_SBX_OUT_TIMED_OUT,    /* over --import-timeout-ms: wall clock or CPU time (422) */
	API_SBX_OUT_OVER_MEMORY,  /* over --import-memory (422) */
	API_SBX_OUT_ERROR,        /* the helper could not be started or reached, or stopped before
	                             reporting (500) */
	API_SBX_OUTCOMES
};

extern const char *const API_SBX_JOB_NAMES[API_SBX_JOBS];         /* "model", "levels", "image" */
extern const char *const API_SBX_OUTCOME_NAMES[API_SBX_OUTCOMES]; /* "ok", "invalid", "crashed", ... */

/* Upper bounds (seconds) of the histograms' buckets, 1 ms to 60 s; above the last is +Inf. */
#define API_STATS_BUCKETS 15
extern const double API_STATS_BUCKET_BOUNDS[API_STATS_BUCKETS];

struct api_stats_histogram {
	uint64_t bucket[API_STATS_BUCKETS];   /* non-cumulative: observations <= bound[i] and > bound[i-1] */
	uint64_t count;                       /* all observations, those over the last bound included */
	double sum;                           /* seconds (kept in microseconds) */
};

struct api_sandbox_stats {
	uint64_t started[API_SBX_JOBS];
	uint64_t ended[API_SBX_JOBS][API_SBX_OUTCOMES];
	uint64_t server_starts;      /* fork servers started, the first one included */
	uint64_t server_restarts;    /* of which after an earlier one died or stopped answering */
	struct api_stats_histogram job_seconds[API_SBX_JOBS];           /* each job, start to validated reply */
	struct api_stats_histogram stage_seconds[API_IMPORT_STAGES];    /* per API_IMPORT_STAGE_NAMES */
};

/* A snapshot of the counters since the process started. */
void api_sandbox_stats(struct api_sandbox_stats *out);

/* ---- recorders (api/ only) ---- */
void api_sbx_stats_started(enum api_sbx_job job);
void api_sbx_stats_ended(enum api_sbx_job job, enum api_sbx_outcome how, double seconds);
void api_sbx_stats_server_started(void);
/* A model import that succeeded: its stages (t->ms, milliseconds). */
void api_sbx_stats_import_times(const struct api_import_times *t);

#endif
