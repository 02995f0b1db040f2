/*
 * umbrad job queue — bounded, two priorities: every queued interactive request is handed out
 * before any bulk one; FIFO within a priority.
 *
 * The bound counts queued requests only (not those a worker is rendering), both priorities
 * together. srv_queue_push() never blocks: a full or closed queue refuses at once and the
 * caller answers 503. srv_queue_pop() blocks until a request arrives, and returns NULL once the
 * queue is closed and empty, so closing drains it.
 *
 * Threading: every function is safe from any thread. srv_queue_push() runs `before_push`
 * (may be NULL) under the queue lock right before linking the request in, once it is sure the
 * push will succeed: http.c suspends the connection there, so no worker can finish (and resume)
 * a request whose connection is not suspended yet.
 */
#ifndef UMBRA_SRV_QUEUE_H
#define UMBRA_SRV_QUEUE_H

#include "srv.h"

enum srv_push_result { SRV_PUSH_OK, SRV_PUSH_FULL, SRV_PUSH_CLOSED };

struct srv_queue *srv_queue_create(unsigned capacity);
void srv_queue_destroy(struct srv_queue *q);          /* NULL-safe; the queue must be empty */
enum srv_push_result srv_queue_push(struct srv_queue *q, struct srv_request *req,
                                    void (*before_push)(struct srv_request *req));
struct srv_request *srv_queue_pop(struct srv_queue *q);
/* srv_queue_pop that, once the queue has stayed empty with no request in work for idle_s
 * seconds — counted from the last hand-out or srv_queue_done on any thread (or the creation) —
 * and a request was handed out since the last time, calls on_idle(arg) once, without the
 * lock, on one of the waiting threads, and goes on waiting. idle_s 0: plain srv_queue_pop. */
struct srv_request *srv_queue_pop_idle(struct srv_queue *q, double idle_s, void (*on_idle)(void *arg), void *arg);
/* A request handed out by a pop is finished: idle time counts only while none is in work. */
void srv_queue_done(struct srv_queue *q);
void srv_queue_close(struct srv_queue *q);
unsigned srv_queue_depth(struct srv_queue *q);
unsigned srv_queue_depth_prio(struct srv_queue *q, enum srv_priority p);
unsigned srv_queue_capacity(const struct srv_queue *q);
/* When the longest-waiting request was queued (srv_now() seconds), 0 when none waits. */
double srv_queue_oldest(struct srv_queue *q);

#endif
