/* server/clock — see clock.h. */
#include <math.h>
#include "clock.h"

double srv_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int srv_cond_init_monotonic(pthread_cond_t *cv)
{
	pthread_condattr_t ca;
	pthread_condattr_init(&ca);
	pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
	int e = pthread_cond_init(cv, &ca);
	pthread_condattr_destroy(&ca);
	return e;
}

struct timespec srv_timespec(double seconds)
{
	double whole, frac = modf(seconds, &whole);
	struct timespec ts = {(time_t)whole, (long)(frac * 1e9)};
	return ts;
}
