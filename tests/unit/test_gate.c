/* server/gate: at most `limit` holders at once, a waiter gives up at its deadline, the oldest
 * waiter's queue time is visible (a long render yields to it), a raised limit lets waiters in. */
#include <pthread.h>
#include <stdatomic.h>
#include <time.h>
#include <unistd.h>
#include "gate.h"
#include "test.h"

/* Monotonic seconds, as umbrad's now_s() (main.c, not linked here). */
static double now_s(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec / 1e9;
}

struct holder {
	struct srv_gate *g;
	atomic_int *inside, *most;
	int rounds;
};

static void *hold(void *arg)
{
	struct holder *h = arg;
	for (int i = 0; i < h->rounds; i++) {
		struct srv_gate_waiter w;
		if (!srv_gate_enter(h->g, &w, now_s(), 0)) continue;
		int now = atomic_fetch_add(h->inside, 1) + 1;
		int m = atomic_load(h->most);
		while (now > m && !atomic_compare_exchange_weak(h->most, &m, now)) {}
		usleep(200);
		atomic_fetch_sub(h->inside, 1);
		srv_gate_leave(h->g);
	}
	return NULL;
}

static int most_inside(unsigned limit)
{
	struct srv_gate g;
	srv_gate_init(&g, limit);
	atomic_int inside = 0, most = 0;
	struct holder h = {&g, &inside, &most, 50};
	pthread_t t[4];
	for (int i = 0; i < 4; i++) pthread_create(&t[i], NULL, hold, &h);
	for (int i = 0; i < 4; i++) pthread_join(t[i], NULL);
	srv_gate_destroy(&g);
	return atomic_load(&most);
}

TEST(gate_limits_holders)
{
	int one = most_inside(1), two = most_inside(2);
	CHECK(one == 1, "limit 1: %d inside at once", one);
	CHECK(two <= 2 && two >= 1, "limit 2: %d inside at once", two);
}

struct late {
	struct srv_gate *g;
	double queued, deadline;
	bool entered;
};

static void *enter_late(void *arg)
{
	struct late *l = arg;
	struct srv_gate_waiter w;
	l->entered = srv_gate_enter(l->g, &w, l->queued, l->deadline);
	if (l->entered) srv_gate_leave(l->g);
	return NULL;
}

TEST(gate_deadline_oldest_and_limit)
{
	struct srv_gate g;
	srv_gate_init(&g, 1);
	struct srv_gate_waiter me;
	REQUIRE(srv_gate_enter(&g, &me, now_s(), 0));
	CHECK(srv_gate_oldest(&g) == 0, "no waiter yet");

	/* A waiter whose deadline passes while the gate is held gives up. */
	double t0 = now_s();
	struct late a = {&g, t0 - 5, t0 + 0.05, true};
	pthread_t ta;
	pthread_create(&ta, NULL, enter_late, &a);
	pthread_join(ta, NULL);
	CHECK(!a.entered && now_s() >= t0 + 0.05, "entered %d after %.3f s", a.entered, now_s() - t0);

	/* Two waiters without deadlines: the oldest queue time is reported; leaving lets them in. */
	struct late b = {&g, t0 - 3, 0, false}, c = {&g, t0 - 7, 0, false};
	pthread_t tb, tc;
	pthread_create(&tb, NULL, enter_late, &b);
	pthread_create(&tc, NULL, enter_late, &c);
	for (int i = 0; i < 2000 && srv_gate_oldest(&g) != t0 - 7; i++) usleep(1000);
	CHECK(srv_gate_oldest(&g) == t0 - 7, "oldest %.3f", srv_gate_oldest(&g) - t0);
	srv_gate_leave(&g);
	pthread_join(tb, NULL);
	pthread_join(tc, NULL);
	CHECK(b.entered && c.entered && srv_gate_oldest(&g) == 0);

	/* A raised limit admits a second holder at once. */
	REQUIRE(srv_gate_enter(&g, &me, now_s(), 0));
	srv_gate_set_limit(&g, 2);
	struct late d = {&g, t0, now_s() + 5, false};
	pthread_t td;
	pthread_create(&td, NULL, enter_late, &d);
	pthread_join(td, NULL);
	CHECK(d.entered);
	srv_gate_leave(&g);
	srv_gate_destroy(&g);
}

/* Waiters enter in the order they arrived: three threads queue behind a held gate one after
 * another, and each records its turn when let in. */
struct ordered {
	struct srv_gate *g;
	atomic_int *turn;
	int got;
};

static void *enter_ordered(void *arg)
{
	struct ordered *o = arg;
	struct srv_gate_waiter w;
	if (srv_gate_enter(o->g, &w, now_s(), 0)) {
		o->got = atomic_fetch_add(o->turn, 1);
		usleep(1000);
		srv_gate_leave(o->g);
	}
	return NULL;
}

static int waiters(struct srv_gate *g)
{
	pthread_mutex_lock(&g->mu);
	int n = 0;
	for (const struct srv_gate_waiter *w = g->waiting; w; w = w->next) n++;
	pthread_mutex_unlock(&g->mu);
	return n;
}

/* Starts a thread that waits at g (held by the caller) and returns once it is queued. */
static void queue_one(struct srv_gate *g, atomic_int *turn, struct ordered *o, pthread_t *t)
{
	*o = (struct ordered){g, turn, -1};
	int before = waiters(g);
	pthread_create(t, NULL, enter_ordered, o);
	for (int k = 0; k < 2000 && waiters(g) <= before; k++) usleep(100);
}

TEST(gate_first_come_first_served)
{
	for (int round = 0; round < 20; round++) {
		struct srv_gate g;
		srv_gate_init(&g, 1);
		struct srv_gate_waiter me;
		REQUIRE(srv_gate_enter(&g, &me, now_s(), 0));
		atomic_int turn = 0;
		struct ordered o[3];
		pthread_t t[3];
		for (int i = 0; i < 3; i++) queue_one(&g, &turn, &o[i], &t[i]);
		srv_gate_leave(&g);
		for (int i = 0; i < 3; i++) pthread_join(t[i], NULL);
		CHECK(o[0].got == 0 && o[1].got == 1 && o[2].got == 2, "round %d: turns %d %d %d", round, o[0].got,
		      o[1].got, o[2].got);
		srv_gate_destroy(&g);
	}
}

/* A newcomer does not take the place a leaving holder frees from someone already waiting: the
 * slot a yielding render frees goes to the request it yielded to. */
TEST(gate_newcomer_does_not_barge)
{
	int barged = 0;
	for (int round = 0; round < 20; round++) {
		struct srv_gate g;
		srv_gate_init(&g, 1);
		struct srv_gate_waiter me;
		REQUIRE(srv_gate_enter(&g, &me, now_s(), 0));
		atomic_int turn = 0;
		struct ordered a;
		pthread_t t;
		queue_one(&g, &turn, &a, &t);
		srv_gate_leave(&g);
		REQUIRE(srv_gate_enter(&g, &me, now_s(), 0));   /* at once, as a newcomer */
		int mine = atomic_fetch_add(&turn, 1);
		srv_gate_leave(&g);
		pthread_join(t, NULL);
		if (mine != 1 || a.got != 0) barged++;
		srv_gate_destroy(&g);
	}
	CHECK(barged == 0, "the newcomer went first in %d of 20 rounds", barged);
}
