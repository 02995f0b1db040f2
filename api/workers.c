/*
 * api/workers.c — the import's thread pool (see workers.h): tasks handed out one index at a
 * time from a shared counter; the caller works too and waits for the last one.
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include "workers.h"

static struct {
	pthread_mutex_t mu;
	pthread_cond_t go, done;
	pthread_t th[API_WORKERS_MAX];
	unsigned nth;                 /* threads besides the caller */
	unsigned long gen;            /* bumped per api_workers_run */
	bool quit;
	api_worker_fn fn;
	void *ctx;
	size_t n;
	atomic_size_t next;
	unsigned busy;                /* workers still inside the current generation */
	unsigned ready;               /* workers past their start (api_workers_start waits for all) */
} pool = {.mu = PTHREAD_MUTEX_INITIALIZER, .go = PTHREAD_COND_INITIALIZER, .done = PTHREAD_COND_INITIALIZER};

/* Set on a thread while it runs tasks: a loop inside a task runs on that thread alone. */
static _Thread_local bool in_task;

static void drain(unsigned w)
{
	in_task = true;
	for (size_t i; (i = atomic_fetch_add(&pool.next, 1)) < pool.n;) pool.fn(pool.ctx, i, w);
	in_task = false;
}

static void *worker(void *arg)
{
	unsigned w = (unsigned)(size_t)arg;
	pthread_mutex_lock(&pool.mu);
	/* The generations so far are not this thread's: a pool started again after earlier runs
	 * (tests do) began at 0, ran a phantom generation and took one off the next run's count
	 * of busy threads, which then returned early or waited forever. */
	unsigned long seen = pool.gen;
	pool.ready++;
	pthread_cond_signal(&pool.done);
	for (;;) {
		while (!pool.quit && pool.gen == seen) pthread_cond_wait(&pool.go, &pool.mu);
		if (pool.quit) break;
		seen = pool.gen;
		pthread_mutex_unlock(&pool.mu);
		drain(w);
		pthread_mutex_lock(&pool.mu);
		if (--pool.busy == 0) pthread_cond_signal(&pool.done);
	}
	pthread_mutex_unlock(&pool.mu);
	return NULL;
}

int api_workers_start(unsigned n)
{
	if (n > API_WORKERS_MAX) n = API_WORKERS_MAX;
	pthread_attr_t at;
	if (pool.nth || n < 2 || pthread_attr_init(&at)) return 0;
	pthread_attr_setstacksize(&at, API_WORKERS_STACK);
	pool.quit = false;
	while (pool.nth + 1 < n && !pthread_create(&pool.th[pool.nth], &at, worker, (void *)(size_t)(pool.nth + 1)))
		pool.nth++;
	pthread_attr_destroy(&at);
	/* A thread's own start makes system calls (its robust list, rseq, signal mask): all done
	 * before the caller goes on to lock the process down. */
	pthread_mutex_lock(&pool.mu);
	while (pool.ready < pool.nth) pthread_cond_wait(&pool.done, &pool.mu);
	pthread_mutex_unlock(&pool.mu);
	return pool.nth ? 0 : -1;
}

unsigned api_workers_count(void)
{
	return pool.nth + 1;
}

void api_workers_run(size_t n, api_worker_fn fn, void *ctx)
{
	if (!pool.nth || n < 2 || in_task) {
		/* (slot 0 inside a task too: a slot names the scratch of the call that runs the loop) */
		for (size_t i = 0; i < n; i++) fn(ctx, i, 0);
		return;
	}
	pthread_mutex_lock(&pool.mu);
	pool.fn = fn;
	pool.ctx = ctx;
	pool.n = n;
	atomic_store(&pool.next, 0);
	pool.busy = pool.nth;
	pool.gen++;
	pthread_cond_broadcast(&pool.go);
	pthread_mutex_unlock(&pool.mu);
	drain(0);
	pthread_mutex_lock(&pool.mu);
	while (pool.busy) pthread_cond_wait(&pool.done, &pool.mu);
	pthread_mutex_unlock(&pool.mu);
}

void api_workers_stop(void)
{
	pthread_mutex_lock(&pool.mu);
	pool.quit = true;
	pthread_cond_broadcast(&pool.go);
	pthread_mutex_unlock(&pool.mu);
	for (unsigned i = 0; i < pool.nth; i++) pthread_join(pool.th[i], NULL);
	pool.nth = pool.ready = 0;
}
