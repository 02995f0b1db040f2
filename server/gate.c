/* server/gate — see gate.h. A counting semaphore with a list of its waiters (at most the threads
 * less one, so linear scans are fine), admitting them in priority, then ticket order. */
#include <time.h>
#include "clock.h"
#include "gate.h"

void srv_gate_init(struct srv_gate *g, unsigned limit)
{
	pthread_mutex_init(&g->mu, NULL);
	srv_cond_init_monotonic(&g->cv);
	g->limit = limit ? limit : 1;
	g->running = 0;
	g->next_ticket = 0;
	g->waiting = NULL;
}

void srv_gate_destroy(struct srv_gate *g)
{
	pthread_cond_destroy(&g->cv);
	pthread_mutex_destroy(&g->mu);
}

void srv_gate_set_limit(struct srv_gate *g, unsigned limit)
{
	pthread_mutex_lock(&g->mu);
	g->limit = limit ? limit : 1;
	pthread_cond_broadcast(&g->cv);
	pthread_mutex_unlock(&g->mu);
}

/* With mu held: w may enter now (a free place, and no one waiting who came before it). */
static bool my_turn(const struct srv_gate *g, const struct srv_gate_waiter *w)
{
	if (g->running >= g->limit) return false;
	for (const struct srv_gate_waiter *o = g->waiting; o; o = o->next)
		if (o->priority < w->priority || (o->priority == w->priority && o->ticket < w->ticket)) return false;
	return true;
}

static void unlink_waiter(struct srv_gate *g, struct srv_gate_waiter *w)
{
	for (struct srv_gate_waiter **p = &g->waiting; *p; p = &(*p)->next)
		if (*p == w) {
			*p = w->next;
			return;
		}
}

bool srv_gate_enter(struct srv_gate *g, struct srv_gate_waiter *w, double t_queued, double deadline_s)
{
	return srv_gate_enter_prio(g, w, 0, t_queued, deadline_s);
}

bool srv_gate_enter_prio(struct srv_gate *g, struct srv_gate_waiter *w, unsigned priority, double t_queued,
                         double deadline_s)
{
	struct timespec until = srv_timespec(deadline_s > 0 ? deadline_s : 0);
	pthread_mutex_lock(&g->mu);
	w->t_queued = t_queued;
	w->priority = priority;
	w->ticket = g->next_ticket++;
	w->next = g->waiting;
	g->waiting = w;
	bool in = true;
	while (!my_turn(g, w)) {
		if (deadline_s <= 0) {
			pthread_cond_wait(&g->cv, &g->mu);
		} else if (pthread_cond_timedwait(&g->cv, &g->mu, &until) != 0 && !my_turn(g, w)) {
			in = false;
			break;
		}
	}
	unlink_waiter(g, w);
	if (in) g->running++;
	/* Whoever is next in line may be able to enter too (a limit above 1, or this waiter gave up). */
	pthread_cond_broadcast(&g->cv);
	pthread_mutex_unlock(&g->mu);
	return in;
}

void srv_gate_leave(struct srv_gate *g)
{
	pthread_mutex_lock(&g->mu);
	if (g->running) g->running--;
	pthread_cond_broadcast(&g->cv);   /* the next ticket must wake, whichever thread that is */
	pthread_mutex_unlock(&g->mu);
}

double srv_gate_oldest(struct srv_gate *g)
{
	pthread_mutex_lock(&g->mu);
	double oldest = 0;
	for (const struct srv_gate_waiter *w = g->waiting; w; w = w->next)
		if (oldest <= 0 || w->t_queued < oldest) oldest = w->t_queued;
	pthread_mutex_unlock(&g->mu);
	return oldest;
}
