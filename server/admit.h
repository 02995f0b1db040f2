/*
 * server/admit.h — admission of renders by memory (--max-memory).
 *
 * Before a render, the worker asks the renderer what the scene will allocate
 * (rnd_render_estimate) and admits it against the budget: a render whose estimate alone is over
 * the budget can never run here (422 naming the member that makes it big); one that does not
 * fit next to the renders in flight waits for them, until its deadline (then 504). A render
 * admitted alone always runs, so a waiting render is never starved by its own size.
 *
 * Usage: srv_admit_init(&a, budget) once; per render srv_admit_request(...) and, when the answer
 * is encoded, srv_admit_release(&a, need). srv_admit_destroy() at exit.
 * Threading: every call is thread-safe (one mutex + condition variable).
 */
#ifndef UMBRA_SRV_ADMIT_H
#define UMBRA_SRV_ADMIT_H

#include <pthread.h>
#include <stdint.h>
#include "api.h"

struct srv_admit {
	pthread_mutex_t mu;
	pthread_cond_t cv;
	uint64_t budget;      /* bytes; 0 = no budget (everything admitted at once) */
	uint64_t in_use;      /* estimates of the renders admitted and not released */
	uint64_t peak;        /* largest in_use seen */
};

void srv_admit_init(struct srv_admit *a, uint64_t budget);
void srv_admit_destroy(struct srv_admit *a);

/* The budget when --max-memory is not given: half of the machine's memory, or of the
 * container's (cgroup v2 memory.max, v1 memory.limit_in_bytes) when that is smaller. */
uint64_t srv_admit_default_budget(void);

/* Admits a render needing `need` bytes (est: its estimate, for the message). Returns 0 when
 * admitted (release `need` later), else fills p: 422 when need alone is over the budget,
 * 504 when `deadline` (monotonic seconds, 0 = none) passed while waiting. */
int srv_admit_request(struct srv_admit *a, const struct api_scene *sc, uint64_t need, double deadline,
                      struct api_problem *p);
/* The same for a request that holds `held` bytes admitted already (its parse's, api.h
 * api_memory_gate): on success it holds held + need, on failure still held. sc may be NULL
 * (the 422's pointer is then ""). */
int srv_admit_grow(struct srv_admit *a, const struct api_scene *sc, uint64_t held, uint64_t need, double deadline,
                   struct api_problem *p);
void srv_admit_release(struct srv_admit *a, uint64_t need);
/* Bytes admitted now and the budget, for /metrics. */
void srv_admit_stats(struct srv_admit *a, uint64_t *in_use, uint64_t *budget, uint64_t *peak);

#endif
