/*
 * umbrad job queue (see queue.h): two singly linked FIFO lists under one mutex.
 */
#include "queue.h"
#include "clock.h"

#include <errno.h>
#include <stdlib.h>
#include <time.h>

struct srv_fifo {
	struct srv_request *head, *tail;
	unsigned count;
};

struct srv_queue {
	pthread_mutex_t mu;
	pthread_cond_t nonempty;
	struct srv_fifo fifo[SRV_PRIO_COUNT];
	unsigned count, capacity;
	bool closed;
	unsigned busy;      /* requests handed out and not yet srv_queue_done */
	bool idle_due;      /* a request was handed out since on_idle last ran (srv_queue_pop_idle) */
	double active_at;   /* srv_now() of the last hand-out or srv_queue_done (or the creation) */
};

struct srv_queue *srv_queue_create(unsigned capacity)
{
	struct srv_queue *q = calloc(1, sizeof *q);
	if (!q)
		return NULL;
	if (pthread_mutex_init(&q->mu, NULL) != 0)
		goto err_free;
	if (srv_cond_init_monotonic(&q->nonempty) != 0)
		goto err_mutex;
	q->capacity = capacity;
	q->idle_due = true;
	q->active_at = srv_now();
	return q;

err_mutex:
	pthread_mutex_destroy(&q->mu);
err_free:
	free(q);
	return NULL;
}

void srv_queue_destroy(struct srv_queue *q)
{
	if (!q)
		return;
	pthread_cond_destroy(&q->nonempty);
	pthread_mutex_destroy(&q->mu);
	free(q);
}

enum srv_push_result srv_queue_push(struct srv_queue *q, struct srv_request *req,
                                    void (*before_push)(struct srv_request *req))
{
	pthread_mutex_lock(&q->mu);
	if (q->closed) {
		pthread_mutex_unlock(&q->mu);
		return SRV_PUSH_CLOSED;
	}
	if (q->count >= q->capacity) {
		pthread_mutex_unlock(&q->mu);
		return SRV_PUSH_FULL;
	}
	if (before_push)
		before_push(req);
	struct srv_fifo *f = &q->fifo[req->priority];
	req->next = NULL;
	if (f->tail)
		f->tail->next = req;
	else
		f->head = req;
	f->tail = req;
	f->count++;
	q->count++;
	pthread_cond_signal(&q->nonempty);
	pthread_mutex_unlock(&q->mu);
	return SRV_PUSH_OK;
}

/* The first request in priority order; the lock is held. */
static struct srv_request *take(struct srv_queue *q)
{
	for (int p = 0; p < SRV_PRIO_COUNT; p++) {
		struct srv_fifo *f = &q->fifo[p];
		struct srv_request *req = f->head;
		if (!req)
			continue;
		f->head = req->next;
		if (!f->head)
			f->tail = NULL;
		f->count--;
		q->count--;
		req->next = NULL;
		q->busy++;
		q->idle_due = true;
		q->active_at = srv_now();
		return req;
	}
	return NULL;
}

struct srv_request *srv_queue_pop(struct srv_queue *q)
{
	return srv_queue_pop_idle(q, 0, NULL, NULL);
}

struct srv_request *srv_queue_pop_idle(struct srv_queue *q, double idle_s, void (*on_idle)(void *arg), void *arg)
{
	pthread_mutex_lock(&q->mu);
	while (q->count == 0 && !q->closed) {
		/* While a request is in work, its thread starts the idle period when it is done (it
		 * comes back here): the others just wait. */
		if (idle_s <= 0 || !on_idle || !q->idle_due || q->busy) {
			pthread_cond_wait(&q->nonempty, &q->mu);
			continue;
		}
		/* The period counts from the last request handed out or done, whichever thread did
		 * it: a thread that began waiting earlier must not cut another's period short (the
		 * idle trim would find the last request's shadow maps used too recently to go). */
		double due = q->active_at + idle_s;
		if (srv_now() >= due) {
			q->idle_due = false;
			pthread_mutex_unlock(&q->mu);
			on_idle(arg);
			pthread_mutex_lock(&q->mu);
			continue;
		}
		struct timespec ts = srv_timespec(due);
		pthread_cond_timedwait(&q->nonempty, &q->mu, &ts);
	}
	struct srv_request *req = take(q);
	pthread_mutex_unlock(&q->mu);
	return req;
}

void srv_queue_done(struct srv_queue *q)
{
	pthread_mutex_lock(&q->mu);
	if (q->busy)
		q->busy--;
	q->active_at = srv_now();
	/* A waiting thread starts the idle period when the done one is not coming back. */
	if (q->busy == 0)
		pthread_cond_signal(&q->nonempty);
	pthread_mutex_unlock(&q->mu);
}

void srv_queue_close(struct srv_queue *q)
{
	pthread_mutex_lock(&q->mu);
	q->closed = true;
	pthread_cond_broadcast(&q->nonempty);
	pthread_mutex_unlock(&q->mu);
}

unsigned srv_queue_depth(struct srv_queue *q)
{
	pthread_mutex_lock(&q->mu);
	unsigned n = q->count;
	pthread_mutex_unlock(&q->mu);
	return n;
}

unsigned srv_queue_depth_prio(struct srv_queue *q, enum srv_priority p)
{
	pthread_mutex_lock(&q->mu);
	unsigned n = q->fifo[p].count;
	pthread_mutex_unlock(&q->mu);
	return n;
}

double srv_queue_oldest(struct srv_queue *q)
{
	double t = 0;
	pthread_mutex_lock(&q->mu);
	for (int p = 0; p < SRV_PRIO_COUNT; p++)
		if (q->fifo[p].head && (t == 0 || q->fifo[p].head->t_queued < t))
			t = q->fifo[p].head->t_queued;
	pthread_mutex_unlock(&q->mu);
	return t;
}

unsigned srv_queue_capacity(const struct srv_queue *q)
{
	return q->capacity;
}
