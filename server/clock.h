/*
 * server/clock — the daemon's waits run on CLOCK_MONOTONIC (srv_now() seconds): condition
 * variables that time out on it, and a deadline in those seconds as a timespec for
 * pthread_cond_timedwait. Used by the queue, admission by memory and the device gate.
 * Threading: pure functions.
 */
#ifndef UMBRA_SRV_CLOCK_H
#define UMBRA_SRV_CLOCK_H

#include <pthread.h>
#include <time.h>

/* Monotonic seconds: every time the daemon measures or waits on. */
double srv_now(void);
/* pthread_cond_init on CLOCK_MONOTONIC; its result (0 = done). */
int srv_cond_init_monotonic(pthread_cond_t *cv);
/* Monotonic seconds (as srv_now()) as an absolute timespec. */
struct timespec srv_timespec(double seconds);

#endif
