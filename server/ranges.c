/*
 * umbrad connection share per client address range (see ranges.h): an open-addressing table
 * (linear probing, backward-shift deletion, so no tombstones) from range to open connections.
 */
#include "ranges.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct slot {
	uint64_t prefix;
	uint32_t count;          /* 0 = empty slot */
	uint8_t family;
};

struct srv_ranges {
	pthread_mutex_t mu;
	unsigned share;
	size_t mask;             /* slots - 1, a power of two minus one */
	size_t used;             /* slots with count > 0 */
	uint64_t open, refused;
	struct slot *slots;
};

int srv_range_key(const struct sockaddr *sa, struct srv_range_key *out)
{
	const uint8_t *b;
	if (!sa)
		return -1;
	if (sa->sa_family == AF_INET) {
		b = (const uint8_t *)&((const struct sockaddr_in *)sa)->sin_addr;
	} else if (sa->sa_family == AF_INET6) {
		const struct in6_addr *a6 = &((const struct sockaddr_in6 *)sa)->sin6_addr;
		if (!IN6_IS_ADDR_V4MAPPED(a6)) {
			uint64_t p = 0;
			for (int i = 0; i < 8; i++)
				p = p << 8 | a6->s6_addr[i];
			*out = (struct srv_range_key){ .prefix = p, .family = 6 };
			return 0;
		}
		b = a6->s6_addr + 12;
	} else {
		return -1;
	}
	*out = (struct srv_range_key){ .prefix = (uint64_t)b[0] << 16 | (uint64_t)b[1] << 8 | b[2], .family = 4 };
	return 0;
}

void srv_range_format(const struct srv_range_key *k, char *buf, size_t size)
{
	if (k->family == 4) {
		snprintf(buf, size, "%u.%u.%u.0/24", (unsigned)(k->prefix >> 16 & 255), (unsigned)(k->prefix >> 8 & 255),
		         (unsigned)(k->prefix & 255));
		return;
	}
	struct in6_addr a = { 0 };
	for (int i = 0; i < 8; i++)
		a.s6_addr[i] = (uint8_t)(k->prefix >> (56 - 8 * i));
	char txt[INET6_ADDRSTRLEN];
	inet_ntop(AF_INET6, &a, txt, sizeof txt);
	snprintf(buf, size, "%s/64", txt);
}

/* splitmix64's finaliser: the prefixes of one network differ in their low bits only. */
static size_t home(const struct srv_ranges *r, uint64_t prefix, uint8_t family)
{
	uint64_t x = prefix ^ (uint64_t)family << 60;
	x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
	x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
	return (size_t)(x ^ (x >> 31)) & r->mask;
}

/* The slot of k, or the empty slot where it would go. With mu held. */
static struct slot *probe(const struct srv_ranges *r, const struct srv_range_key *k)
{
	size_t i = home(r, k->prefix, k->family);
	while (r->slots[i].count && (r->slots[i].prefix != k->prefix || r->slots[i].family != k->family))
		i = (i + 1) & r->mask;
	return &r->slots[i];
}

/* Empties slot i and moves later slots of the same probe run back into the hole. With mu held. */
static void remove_at(struct srv_ranges *r, size_t i)
{
	r->slots[i].count = 0;
	for (size_t j = (i + 1) & r->mask; r->slots[j].count; j = (j + 1) & r->mask) {
		size_t h = home(r, r->slots[j].prefix, r->slots[j].family);
		/* j may move to the hole at i when its home is not in the (cyclic) interval (i, j]. */
		bool stays = i <= j ? (h > i && h <= j) : (h > i || h <= j);
		if (stays)
			continue;
		r->slots[i] = r->slots[j];
		r->slots[j].count = 0;
		i = j;
	}
	r->used--;
}

struct srv_ranges *srv_ranges_create(unsigned share, unsigned max_open)
{
	struct srv_ranges *r = calloc(1, sizeof *r);
	if (!r)
		return NULL;
	size_t n = 16;
	while (n < (size_t)max_open * 2)
		n *= 2;
	r->slots = calloc(n, sizeof *r->slots);
	if (!r->slots)
		goto err_free;
	if (pthread_mutex_init(&r->mu, NULL) != 0)
		goto err_slots;
	r->mask = n - 1;
	r->share = share;
	return r;
err_slots:
	free(r->slots);
err_free:
	free(r);
	return NULL;
}

void srv_ranges_destroy(struct srv_ranges *r)
{
	if (!r)
		return;
	pthread_mutex_destroy(&r->mu);
	free(r->slots);
	free(r);
}

bool srv_ranges_admit(struct srv_ranges *r, const struct sockaddr *sa)
{
	struct srv_range_key k;
	if (!r || !r->share || srv_range_key(sa, &k) != 0)
		return true;
	pthread_mutex_lock(&r->mu);
	bool fits = probe(r, &k)->count < r->share;
	if (!fits)
		r->refused++;
	pthread_mutex_unlock(&r->mu);
	return fits;
}

bool srv_ranges_open(struct srv_ranges *r, const struct sockaddr *sa)
{
	struct srv_range_key k;
	if (!r || srv_range_key(sa, &k) != 0)
		return false;
	bool counted = true;
	pthread_mutex_lock(&r->mu);
	struct slot *s = probe(r, &k);
	if (s->count) {
		s->count++;
	} else if (r->used < (r->mask + 1) / 2) {   /* the table stays at most half full */
		*s = (struct slot){ .prefix = k.prefix, .family = k.family, .count = 1 };
		r->used++;
	} else {
		counted = false;
	}
	if (counted)
		r->open++;
	pthread_mutex_unlock(&r->mu);
	return counted;
}

void srv_ranges_close(struct srv_ranges *r, const struct sockaddr *sa)
{
	struct srv_range_key k;
	if (!r || srv_range_key(sa, &k) != 0)
		return;
	pthread_mutex_lock(&r->mu);
	struct slot *s = probe(r, &k);
	if (s->count) {   /* else: not counted, a caller's bug; nothing to undo */
		r->open--;
		if (--s->count == 0)
			remove_at(r, (size_t)(s - r->slots));
	}
	pthread_mutex_unlock(&r->mu);
}

void srv_ranges_stats(struct srv_ranges *r, struct srv_ranges_stats *out)
{
	memset(out, 0, sizeof *out);
	if (!r)
		return;
	pthread_mutex_lock(&r->mu);
	*out = (struct srv_ranges_stats){ .share = r->share, .open = r->open, .ranges = r->used,
		                          .refused = r->refused };
	pthread_mutex_unlock(&r->mu);
}
