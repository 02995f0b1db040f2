/*
 * api/workers.h — a small pool of threads for the import's parallel loops, started once by the
 * process that wants it (the sandboxed importer's child starts it BEFORE its lockdown: after it,
 * no thread can ever be created, see api/sandbox_child.c).
 *
 *   api_workers_start(n)            n - 1 threads join the caller (n <= API_WORKERS_MAX); 0, or
 *                                   -1 when none could be created (the loops then run serially)
 *   api_workers_run(n, fn, ctx)     fn(ctx, i, w) for every i in 0..n, on the caller and the
 *                                   pool; returns when all are done. w (< api_workers_count())
 *                                   is the thread's slot, for per-thread scratch.
 *   api_workers_stop()              joins the threads (tests; the importer's child just exits)
 *
 * Without a pool, or inside a task (a loop in a loop), every call runs on the caller, in order. Results must not depend on the
 * thread count: each task writes only its own outputs (the callers keep that promise).
 * One process-wide pool, used by one thread at a time (the child's main thread).
 */
#ifndef API_WORKERS_H
#define API_WORKERS_H

#include <stddef.h>

#define API_WORKERS_MAX 8
/* Each worker's stack: the loops run meshoptimizer and small helpers; RLIMIT_AS counts it. */
#define API_WORKERS_STACK (512u << 10)

typedef void (*api_worker_fn)(void *ctx, size_t i, unsigned w);

int api_workers_start(unsigned n);
unsigned api_workers_count(void);
void api_workers_run(size_t n, api_worker_fn fn, void *ctx);
void api_workers_stop(void);

#endif
