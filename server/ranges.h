/*
 * umbrad connection share per client address range (ranges.c): how many connections each range
 * holds now, and whether a new one fits its range's share (--max-connections-per-range).
 *
 * A range is an IPv4 /24 or an IPv6 /64 (an IPv4-mapped IPv6 address counts as its IPv4
 * address): one client that spreads its connections over the addresses of its network (an
 * IPv6 host owns a whole /64) is one client here. Loopback is not special: 127.0.0.1 and
 * 127.0.0.2 are one range (127.0.0.0/24), 127.0.1.1 another.
 *
 * Usage (conn.c): srv_ranges_create(); srv_ranges_admit() in libmicrohttpd's accept policy
 * callback refuses a connection whose range holds `share` already (and counts the refusal);
 * srv_ranges_open() when libmicrohttpd starts the connection and srv_ranges_close() (only for
 * a connection whose open returned true) when it closes it; srv_ranges_stats() for /metrics;
 * srv_ranges_destroy() (NULL-safe). Nothing here knows libmicrohttpd: unit-tested alone.
 *
 * Invariants: the table holds a slot per range with a connection open, at most max_open of
 * them (capacity twice that, so probes stay short); a range whose last connection closes leaves
 * the table. admit() only reads: the count moves at open/close, so a connection that
 * libmicrohttpd refuses after the policy said yes (its own limits, out of memory) counts for
 * nothing. Threading: one mutex, held for a probe of a few slots; safe from any thread.
 */
#ifndef UMBRA_SRV_RANGES_H
#define UMBRA_SRV_RANGES_H

#include <stdbool.h>
#include <stdint.h>
#include <sys/socket.h>

struct srv_ranges;

/* A range: its family (4 or 6) and its prefix bits, right-aligned. */
struct srv_range_key {
	uint64_t prefix;
	uint8_t family;
};

/* The range of an AF_INET / AF_INET6 address: 0, or -1 for another family (a UNIX socket). */
int srv_range_key(const struct sockaddr *sa, struct srv_range_key *out);
/* Writes "203.0.113.0/24" or "2001:db8:1:2::/64" into buf (for logs and tests). */
void srv_range_format(const struct srv_range_key *k, char *buf, size_t size);

/* share: most connections one range may hold, 0 = no limit (counted all the same); max_open:
 * most connections open at once (--max-connections). NULL when out of memory. */
struct srv_ranges *srv_ranges_create(unsigned share, unsigned max_open);
void srv_ranges_destroy(struct srv_ranges *r);

/* Whether a new connection from sa fits its range's share; a no is counted as refused. A
 * family without ranges (not IP) always fits. */
bool srv_ranges_admit(struct srv_ranges *r, const struct sockaddr *sa);
/* Counts a connection that started: true when counted (false: not IP, or the table is full,
 * which max_open rules out); only a counted one may be closed. */
bool srv_ranges_open(struct srv_ranges *r, const struct sockaddr *sa);
void srv_ranges_close(struct srv_ranges *r, const struct sockaddr *sa);

struct srv_ranges_stats {
	unsigned share;          /* 0 = no limit */
	uint64_t open;           /* connections counted now */
	uint64_t ranges;         /* ranges with a connection open now */
	uint64_t refused;        /* connections refused over the share since the start */
};
void srv_ranges_stats(struct srv_ranges *r, struct srv_ranges_stats *out);   /* zeros for NULL */

#endif
