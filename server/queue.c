/*
 * umbrad job queue (see queue.h): two singly linked FIFO lists under one mutex.
 */
#include "queue.h"

#include <stdlib.h>

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
};

struct srv_queue *srv_queue_create(unsigned capacity)
{
	struct srv_queue *q = calloc(1, sizeof *q);
	if (!q)
		return NULL;
	if (pthread_mutex_init(&q->mu, NULL) != 0)
		goto err_free;
	if (pthread_cond_init(&q->nonempty, NULL) != 0)
		goto err_mutex;
	q->capacity = capacity;
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

struct srv_request *srv_queue_pop(struct srv_queue *q)
{
	struct srv_request *req = NULL;
	pthread_mutex_lock(&q->mu);
	while (q->count == 0 && !q->closed)
		pthread_cond_wait(&q->nonempty, &q->mu);
	for (int p = 0; p < SRV_PRIO_COUNT && !req; p++) {
		struct srv_fifo *f = &q->fifo[p];
		if (!f->head)
			continue;
		req = f->head;
		f->head = req->next;
		if (!f->head)
			f->tail = NULL;
		f->count--;
		q->count--;
		req->next = NULL;
	}
	pthread_mutex_unlock(&q->mu);
	return req;
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
