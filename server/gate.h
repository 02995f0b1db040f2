/*
 * server/gate — how many renders run on the device at once (--device-renders).
 *
 * Why: lavapipe has one queue, and one render already keeps every core busy (its rasterizer
 * threads). Two renders in flight only contend for the same cores and caches: with two workers
 * on the 2-core machine the daemon answered 72 thumb-256 images/s to 4 clients, with one 93.
 * So on a CPU device the gate lets one render through at a time, while the other workers still
 * parse, read assets, encode and send in parallel with it (the overlap issue 12 asks for). On
 * a GPU it admits every worker (the CPU side is the limit there).
 *
 * Usage: srv_gate_init(&g, n) once; srv_gate_set_limit() when the device is known;
 *   if (srv_gate_enter(&g, &w, req->t_queued, deadline_s)) { render ...; srv_gate_leave(&g); }
 *   else: the deadline passed while waiting (answer 504).
 * srv_gate_oldest(): the queue time of the longest waiter, 0 when none (a long render yields
 * to it as it yields to the queue's oldest request). Waiters are admitted by priority, then in arrival order, so
 * the slot a yielding render frees goes to the waiter it yielded to, not to a newcomer.
 * Threading: every function is thread-safe; the waiter struct lives on the caller's stack.
 */
#ifndef UMBRA_SRV_GATE_H
#define UMBRA_SRV_GATE_H

#include <pthread.h>
#include <stdbool.h>

struct srv_gate_waiter {
	double t_queued;
	unsigned priority;            /* enum srv_priority: lower first, before arrival order */
	unsigned long long ticket;    /* arrival order: the gate admits waiters first come, first served */
	struct srv_gate_waiter *next;
};

struct srv_gate {
	pthread_mutex_t mu;
	pthread_cond_t cv;            /* CLOCK_MONOTONIC, as srv_now() */
	unsigned limit, running;
	unsigned long long next_ticket;
	struct srv_gate_waiter *waiting;
};

void srv_gate_init(struct srv_gate *g, unsigned limit);
void srv_gate_destroy(struct srv_gate *g);
void srv_gate_set_limit(struct srv_gate *g, unsigned limit);
/* Waits for a turn; false when deadline_s (monotonic seconds, 0 = none) passes first. Waiters
 * of a lower priority value go first (X-Priority interactive before bulk: more threads than
 * render slots take requests from the queue, server/imports.h, so its order is kept here too). */
bool srv_gate_enter(struct srv_gate *g, struct srv_gate_waiter *w, double t_queued, double deadline_s);
bool srv_gate_enter_prio(struct srv_gate *g, struct srv_gate_waiter *w, unsigned priority, double t_queued,
                         double deadline_s);
void srv_gate_leave(struct srv_gate *g);
double srv_gate_oldest(struct srv_gate *g);

#endif
