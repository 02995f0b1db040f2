/*
 * server/admit.c — admission of renders by their estimated memory (see admit.h).
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "admit.h"
#include "clock.h"

/* After a render that held this much, freed heap memory goes back to the system at once
 * (glibc keeps it otherwise, and RSS would stay at the size of the largest request seen). */

void srv_admit_init(struct srv_admit *a, uint64_t budget)
{
	memset(a, 0, sizeof *a);
	pthread_mutex_init(&a->mu, NULL);
	srv_cond_init_monotonic(&a->cv);
	a->budget = budget;
}

void srv_admit_destroy(struct srv_admit *a)
{
	pthread_cond_destroy(&a->cv);
	pthread_mutex_destroy(&a->mu);
}

/* A number from the first line of a file, or 0 ("max", missing, unreadable). */
static uint64_t read_u64_file(const char *path)
{
	FILE *f = fopen(path, "r");
	if (!f) return 0;
	unsigned long long v = 0;
	if (fscanf(f, "%llu", &v) != 1) v = 0;
	fclose(f);
	return v;
}

uint64_t srv_admit_default_budget(void)
{
	long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
	uint64_t mem = pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page : 0;
	uint64_t cg = read_u64_file("/sys/fs/cgroup/memory.max");
	if (!cg) cg = read_u64_file("/sys/fs/cgroup/memory/memory.limit_in_bytes");
	if (cg && (!mem || cg < mem)) mem = cg;
	return mem / 2;
}

/* The member that makes a render big: the AOVs when asked for, else the views or the size. */
static const char *big_member(const struct api_scene *sc)
{
	if (sc->scene.output.aovs) return "/output/aovs";
	if (sc->scene.view_count > 1) return sc->views_key_ && !strcmp(sc->views_key_, "turntable") ? "/turntable" : "/views";
	return sc->scene.height > sc->scene.width ? "/height" : "/width";
}

int srv_admit_request(struct srv_admit *a, const struct api_scene *sc, uint64_t need, double deadline,
                      struct api_problem *p)
{
	return srv_admit_grow(a, sc, 0, need, deadline, p);
}

int srv_admit_grow(struct srv_admit *a, const struct api_scene *sc, uint64_t held, uint64_t need, double deadline,
                   struct api_problem *p)
{
	if (a->budget && held + need > a->budget) {
		api_problem_set(p, 422, sc ? big_member(sc) : "", "this request needs about %.0f MB of memory, over this "
		                "server's --max-memory of %.0f MB", (held + need) / 1e6, a->budget / 1e6);
		return -1;
	}
	pthread_mutex_lock(&a->mu);
	/* What it holds is given back while it waits: two requests that each hold some and wait for
	 * more would otherwise wait for each other. Alone, a request within the budget always runs. */
	a->in_use -= held;
	while (a->budget && a->in_use && a->in_use + held + need > a->budget) {
		int e;
		if (deadline > 0) {
			struct timespec ts = srv_timespec(deadline);
			e = pthread_cond_timedwait(&a->cv, &a->mu, &ts);
		} else {
			e = pthread_cond_wait(&a->cv, &a->mu);
		}
		if (e == ETIMEDOUT) {
			a->in_use += held;
			pthread_mutex_unlock(&a->mu);
			api_problem_set(p, 504, "", "the request passed its deadline waiting for %.0f MB of memory (%.0f of %.0f MB "
			                "held by requests in flight)", need / 1e6, a->in_use / 1e6, a->budget / 1e6);
			return -1;
		}
	}
	a->in_use += held + need;
	if (a->in_use > a->peak) a->peak = a->in_use;
	pthread_mutex_unlock(&a->mu);
	return 0;
}

void srv_admit_release(struct srv_admit *a, uint64_t need)
{
	if (!need) return;
	pthread_mutex_lock(&a->mu);
	a->in_use = a->in_use > need ? a->in_use - need : 0;
	pthread_cond_broadcast(&a->cv);
	pthread_mutex_unlock(&a->mu);
}

void srv_admit_stats(struct srv_admit *a, uint64_t *in_use, uint64_t *budget, uint64_t *peak)
{
	pthread_mutex_lock(&a->mu);
	if (in_use) *in_use = a->in_use;
	if (budget) *budget = a->budget;
	if (peak) *peak = a->peak;
	pthread_mutex_unlock(&a->mu);
}
