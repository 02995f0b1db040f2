/*
 * umbrad import threads (see imports.h): the parked requests in a FIFO linked through
 * srv_request.next, the imports running (at most `slots`) and a count per client among the
 * requests taken and not yet answered, under one mutex.
 */
#include <netinet/in.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "imports.h"
#include "srv.h"

struct holder {
	uint64_t client;
	unsigned n;
};

struct srv_imports {
	pthread_mutex_t mu;
	pthread_cond_t parked_cv;
	unsigned slots, running, parked;
	unsigned taken;                    /* requests taken, not yet answered (importing or rendering) */
	bool closed;
	struct holder *held;               /* [2 slots]: clients with requests taken (n > 0) */
	struct srv_request *head, *tail;   /* parked */
};

struct srv_imports *srv_imports_create(unsigned slots)
{
	struct srv_imports *im = calloc(1, sizeof *im);
	if (!im) return NULL;
	im->slots = slots ? slots : 1;
	im->held = calloc(srv_imports_threads(im->slots), sizeof *im->held);
	if (!im->held) goto fail;
	if (pthread_mutex_init(&im->mu, NULL) != 0) goto fail;
	if (pthread_cond_init(&im->parked_cv, NULL) != 0) {
		pthread_mutex_destroy(&im->mu);
		goto fail;
	}
	return im;
fail:
	free(im->held);
	free(im);
	return NULL;
}

void srv_imports_destroy(struct srv_imports *im)
{
	if (!im) return;
	pthread_cond_destroy(&im->parked_cv);
	pthread_mutex_destroy(&im->mu);
	free(im->held);
	free(im);
}

void srv_imports_park(struct srv_imports *im, struct srv_request *req)
{
	pthread_mutex_lock(&im->mu);
	req->next = NULL;
	if (im->tail) im->tail->next = req;
	else im->head = req;
	im->tail = req;
	im->parked++;
	pthread_cond_signal(&im->parked_cv);
	pthread_mutex_unlock(&im->mu);
}

/* With mu held: the entry of client's running imports, or a free one (NULL: neither). */
static struct holder *holder_of(struct srv_imports *im, uint64_t client, bool or_free)
{
	struct holder *free_one = NULL;
	for (unsigned i = 0; i < srv_imports_threads(im->slots); i++) {
		if (im->held[i].n && im->held[i].client == client) return &im->held[i];
		if (!im->held[i].n && !free_one) free_one = &im->held[i];
	}
	return or_free ? free_one : NULL;
}

/* With mu held: unlinks and returns the parked request of the client with the fewest imports
 * running, the first parked among equals. */
static struct srv_request *unpark(struct srv_imports *im)
{
	struct srv_request *best = NULL, *best_prev = NULL, *prev = NULL;
	unsigned best_n = ~0u;
	for (struct srv_request *r = im->head; r; prev = r, r = r->next) {
		const struct holder *h = holder_of(im, r->client, false);
		unsigned n = h ? h->n : 0;
		if (n < best_n) { best = r; best_prev = prev; best_n = n; }
	}
	if (!best) return NULL;
	if (best_prev) best_prev->next = best->next;
	else im->head = best->next;
	if (im->tail == best) im->tail = best_prev;
	best->next = NULL;
	im->parked--;
	return best;
}

struct srv_request *srv_imports_take(struct srv_imports *im)
{
	pthread_mutex_lock(&im->mu);
	/* a request to import and an import slot free (the threads beyond the slots render what
	 * they imported meanwhile) */
	while (!(im->head && im->running < im->slots) && !(im->closed && !im->head))
		pthread_cond_wait(&im->parked_cv, &im->mu);
	struct srv_request *req = unpark(im);
	if (req) {
		/* one per import thread: a free entry exists if the client has none */
		struct holder *h = holder_of(im, req->client, true);
		if (h) {
			h->client = req->client;
			h->n++;
		}
		im->running++;
		im->taken++;
	}
	pthread_mutex_unlock(&im->mu);
	return req;
}

void srv_imports_imported(struct srv_imports *im)
{
	pthread_mutex_lock(&im->mu);
	if (im->running) im->running--;
	pthread_cond_broadcast(&im->parked_cv);
	pthread_mutex_unlock(&im->mu);
}

void srv_imports_done(struct srv_imports *im, uint64_t client)
{
	pthread_mutex_lock(&im->mu);
	struct holder *h = holder_of(im, client, false);
	if (h) h->n--;
	if (im->taken) im->taken--;
	pthread_mutex_unlock(&im->mu);
}

unsigned srv_imports_threads(unsigned slots)
{
	return 2 * (slots ? slots : 1);
}

void srv_imports_close(struct srv_imports *im)
{
	pthread_mutex_lock(&im->mu);
	im->closed = true;
	pthread_cond_broadcast(&im->parked_cv);
	pthread_mutex_unlock(&im->mu);
}

void srv_imports_counts(struct srv_imports *im, unsigned *running, unsigned *parked)
{
	pthread_mutex_lock(&im->mu);
	if (running) *running = im->running;
	if (parked) *parked = im->parked;
	pthread_mutex_unlock(&im->mu);
}

uint64_t srv_client_key(const struct sockaddr *sa)
{
	uint64_t k = 0;
	if (sa && sa->sa_family == AF_INET) {
		const struct sockaddr_in *a = (const struct sockaddr_in *)sa;
		memcpy(&k, &a->sin_addr, 4);
		k |= 4ull << 56;
	} else if (sa && sa->sa_family == AF_INET6) {
		const struct sockaddr_in6 *a = (const struct sockaddr_in6 *)sa;
		memcpy(&k, &a->sin6_addr, 8);   /* the /64: one host's addresses */
		k ^= 6ull << 56;
	}
	return k;
}
