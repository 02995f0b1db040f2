/* tests — connections per client address range (server/ranges.c): which addresses are one
 * range, the share enforced per range and not across ranges, the table emptied as connections
 * close (backward-shift deletion keeps every other range findable). */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <string.h>

#include "ranges.h"
#include "test.h"

static struct sockaddr_storage addr(const char *text)
{
	struct sockaddr_storage ss;
	memset(&ss, 0, sizeof ss);
	struct sockaddr_in *a4 = (struct sockaddr_in *)&ss;
	struct sockaddr_in6 *a6 = (struct sockaddr_in6 *)&ss;
	if (inet_pton(AF_INET, text, &a4->sin_addr) == 1)
		a4->sin_family = AF_INET;
	else if (inet_pton(AF_INET6, text, &a6->sin6_addr) == 1)
		a6->sin6_family = AF_INET6;
	return ss;
}

static const char *range_of(const char *text, char *buf, size_t size)
{
	struct sockaddr_storage ss = addr(text);
	struct srv_range_key k;
	if (srv_range_key((struct sockaddr *)&ss, &k) != 0)
		return "none";
	srv_range_format(&k, buf, size);
	return buf;
}

TEST(ranges_key_is_ipv4_24_and_ipv6_64)
{
	char b[64];
	CHECK(!strcmp(range_of("203.0.113.77", b, sizeof b), "203.0.113.0/24"), "%s", b);
	CHECK(!strcmp(range_of("127.0.0.2", b, sizeof b), "127.0.0.0/24"), "loopback is not special: %s", b);
	CHECK(!strcmp(range_of("::ffff:198.51.100.9", b, sizeof b), "198.51.100.0/24"), "v4-mapped: %s", b);
	CHECK(!strcmp(range_of("2001:db8:1:2:aaaa::1", b, sizeof b), "2001:db8:1:2::/64"), "%s", b);
	CHECK(!strcmp(range_of("::1", b, sizeof b), "::/64"), "%s", b);
	struct sockaddr_storage un = { .ss_family = AF_UNIX };
	struct srv_range_key k;
	CHECK(srv_range_key((struct sockaddr *)&un, &k) == -1);
}

TEST(ranges_share_holds_per_range)
{
	struct srv_ranges *r = srv_ranges_create(3, 16);
	REQUIRE(r);
	struct sockaddr_storage a1 = addr("10.1.2.3"), a2 = addr("10.1.2.200"), b1 = addr("10.1.3.3");
	struct sockaddr *a = (struct sockaddr *)&a1, *a_other = (struct sockaddr *)&a2, *b = (struct sockaddr *)&b1;
	for (int i = 0; i < 3; i++) {
		CHECK(srv_ranges_admit(r, i % 2 ? a_other : a), "connection %d of the range fits", i);
		CHECK(srv_ranges_open(r, i % 2 ? a_other : a));
	}
	CHECK(!srv_ranges_admit(r, a), "a fourth from the range is refused");
	CHECK(!srv_ranges_admit(r, a_other), "another address of the same /24 is refused too");
	CHECK(srv_ranges_admit(r, b), "another /24 is served");
	CHECK(srv_ranges_open(r, b));
	struct srv_ranges_stats st;
	srv_ranges_stats(r, &st);
	CHECK(st.open == 4 && st.ranges == 2 && st.refused == 2 && st.share == 3, "open %llu ranges %llu refused %llu",
	      (unsigned long long)st.open, (unsigned long long)st.ranges, (unsigned long long)st.refused);
	srv_ranges_close(r, a_other);
	CHECK(srv_ranges_admit(r, a), "a closed connection frees its place in the share");
	srv_ranges_destroy(r);
	srv_ranges_destroy(NULL);
}

TEST(ranges_share_zero_counts_without_limit)
{
	struct srv_ranges *r = srv_ranges_create(0, 8);
	REQUIRE(r);
	struct sockaddr_storage a1 = addr("192.0.2.1");
	for (int i = 0; i < 8; i++) {
		CHECK(srv_ranges_admit(r, (struct sockaddr *)&a1));
		CHECK(srv_ranges_open(r, (struct sockaddr *)&a1));
	}
	struct srv_ranges_stats st;
	srv_ranges_stats(r, &st);
	CHECK(st.open == 8 && st.ranges == 1 && st.refused == 0);
	srv_ranges_destroy(r);
}

/* Many ranges in a small table, opened and closed in an order that makes probe runs wrap and
 * holes open in their middle: every count stays findable and the table ends empty. */
TEST(ranges_table_survives_churn)
{
	enum { N = 200 };
	struct srv_ranges *r = srv_ranges_create(2, N);
	REQUIRE(r);
	struct sockaddr_storage ss[N];
	char text[32];
	for (int i = 0; i < N; i++) {
		snprintf(text, sizeof text, "10.%d.%d.1", i / 7, i * 13 % 251);
		ss[i] = addr(text);
		CHECK(srv_ranges_open(r, (struct sockaddr *)&ss[i]), "%s", text);
	}
	for (int i = 0; i < N; i += 3) srv_ranges_close(r, (struct sockaddr *)&ss[i]);
	int wrong = 0;
	for (int i = 0; i < N; i++) {
		/* share 2: a range with one open fits, so admit says yes for all; open a second and
		 * the ones still holding one are then full. */
		if (!srv_ranges_admit(r, (struct sockaddr *)&ss[i])) wrong++;
		srv_ranges_open(r, (struct sockaddr *)&ss[i]);
		bool full = !srv_ranges_admit(r, (struct sockaddr *)&ss[i]);
		if (full != (i % 3 != 0)) wrong++;
	}
	CHECK(wrong == 0, "%d ranges with a wrong count", wrong);
	for (int i = 0; i < N; i++) {
		srv_ranges_close(r, (struct sockaddr *)&ss[i]);
		if (i % 3 != 0) srv_ranges_close(r, (struct sockaddr *)&ss[i]);
	}
	struct srv_ranges_stats st;
	srv_ranges_stats(r, &st);
	CHECK(st.open == 0 && st.ranges == 0, "open %llu ranges %llu", (unsigned long long)st.open,
	      (unsigned long long)st.ranges);
	srv_ranges_destroy(r);
}
