/*
 * server/origin — the Host allow-list and the Origin / Sec-Fetch-Site rules of origin.h, as pure
 * functions of the flags and a request's headers. Names are compared in one normal form:
 * lowercase, IPv6 without brackets, one trailing dot dropped; origins as scheme://host[:port]
 * with the scheme's default port left out (how browsers serialise them).
 */
#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "origin.h"

/* ---- names ---- */

static bool host_char(unsigned char c, bool ipv6)
{
	return isalnum(c) || c == '-' || c == '.' || c == '_' || (ipv6 && (c == ':' || c == '%'));
}

/* Splits an authority "host[:port]" (a Host header, or an origin after its "scheme://") into
 * its normalised host and port (0 = none). IPv6 in brackets ("[::1]:8080"); a bare address
 * with several colons ("::1") is a host without a port. Returns false when malformed. */
static bool split_authority(const char *a, size_t n, char *host, size_t hsize, unsigned *port)
{
	const char *h = a, *rest = a + n;
	size_t hl = n;
	bool ipv6 = false;
	*port = 0;
	if (n && a[0] == '[') {
		const char *close = memchr(a, ']', n);
		if (!close)
			return false;
		h = a + 1;
		hl = (size_t)(close - h);
		rest = close + 1;
		ipv6 = true;
	} else {
		const char *colon = memchr(a, ':', n);
		if (colon && memchr(colon + 1, ':', n - (size_t)(colon + 1 - a))) {
			ipv6 = true; /* bare IPv6, no port */
		} else if (colon) {
			hl = (size_t)(colon - a);
			rest = colon;
		}
	}
	if (rest < a + n) {
		if (*rest != ':')
			return false;
		unsigned long p = 0;
		for (const char *c = rest + 1; c < a + n; c++) {
			if (!isdigit((unsigned char)*c) || (p = p * 10 + (unsigned long)(*c - '0')) > 65535)
				return false;
		}
		*port = (unsigned)p; /* "host:" = no port (RFC 3986 allows an empty one) */
	}
	if (hl > 1 && h[hl - 1] == '.')
		hl--;
	if (!hl || hl >= hsize)
		return false;
	for (size_t i = 0; i < hl; i++) {
		if (!host_char((unsigned char)h[i], ipv6))
			return false;
		host[i] = (char)tolower((unsigned char)h[i]);
	}
	host[hl] = 0;
	return true;
}

struct parsed_origin {
	char scheme[32];
	char host[SRV_ORIGIN_MAX];
	unsigned port;                 /* as given, or the scheme's default (0: none) */
};

static unsigned default_port(const char *scheme)
{
	return !strcmp(scheme, "http") ? 80 : !strcmp(scheme, "https") ? 443 : 0;
}

/* "scheme://authority" with nothing after (a trailing "/" when slash_ok: a flag's entry). */
static bool origin_parse(const char *s, size_t n, bool slash_ok, struct parsed_origin *po)
{
	const char *sep = memmem(s, n, "://", 3); /* s need not end at n (an entry of a list) */
	if (!sep || sep == s || (size_t)(sep - s) >= sizeof po->scheme || (size_t)(sep - s) + 3 >= n)
		return false;
	size_t sl = (size_t)(sep - s);
	for (size_t i = 0; i < sl; i++) {
		unsigned char c = (unsigned char)s[i];
		if (!(isalpha(c) || (i && (isdigit(c) || c == '+' || c == '-' || c == '.'))))
			return false;
		po->scheme[i] = (char)tolower(c);
	}
	po->scheme[sl] = 0;
	const char *a = sep + 3;
	size_t an = n - sl - 3;
	if (slash_ok && an > 1 && a[an - 1] == '/')
		an--;
	if (memchr(a, '/', an) || memchr(a, '@', an) || !split_authority(a, an, po->host, sizeof po->host, &po->port))
		return false;
	if (!po->port)
		po->port = default_port(po->scheme);
	return true;
}

/* The origin as a browser serialises it. False when it does not fit `size`. */
static bool origin_format(const struct parsed_origin *po, char *out, size_t size)
{
	bool v6 = strchr(po->host, ':') != NULL;
	int n;
	if (po->port && po->port != default_port(po->scheme))
		n = snprintf(out, size, "%s://%s%s%s:%u", po->scheme, v6 ? "[" : "", po->host, v6 ? "]" : "", po->port);
	else
		n = snprintf(out, size, "%s://%s%s%s", po->scheme, v6 ? "[" : "", po->host, v6 ? "]" : "");
	return n >= 0 && (size_t)n < size;
}

/* ---- lists ---- */

static bool in_list(char *const *list, size_t count, const char *s)
{
	for (size_t i = 0; i < count; i++)
		if (!strcmp(list[i], s))
			return true;
	return false;
}

static enum srv_origin_result list_add(char ***list, size_t *count, const char *s)
{
	if (in_list(*list, *count, s))
		return SRV_ORIGIN_OK;
	char **l = realloc(*list, (*count + 1) * sizeof *l);
	if (!l)
		return SRV_ORIGIN_ERR_NOMEM;
	*list = l;
	if (!(l[*count] = strdup(s)))
		return SRV_ORIGIN_ERR_NOMEM;
	(*count)++;
	return SRV_ORIGIN_OK;
}

/* The next comma-separated entry of *p, spaces trimmed; false at the end. */
static bool next_entry(const char **p, const char **start, size_t *len)
{
	if (!**p)
		return false;
	const char *e = strchr(*p, ',');
	if (!e)
		e = *p + strlen(*p);
	const char *b = *p;
	*p = *e ? e + 1 : e;
	while (b < e && isspace((unsigned char)*b))
		b++;
	while (e > b && isspace((unsigned char)e[-1]))
		e--;
	*start = b;
	*len = (size_t)(e - b);
	return true;
}

/* err->msg from a printf-style message; returns r. An entry is quoted with "'%.*s'", SHOWN(n), s. */
#define SHOWN(n) (int)((n) > 200 ? 200 : (n))
static enum srv_origin_result fail(struct srv_origin_error *err, enum srv_origin_result r, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));
static enum srv_origin_result fail(struct srv_origin_error *err, enum srv_origin_result r, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err->msg, sizeof err->msg, fmt, ap);
	va_end(ap);
	return r;
}

static enum srv_origin_result parse_hosts(struct srv_origin *o, const char *list, struct srv_origin_error *err)
{
	const char *p = list, *s;
	size_t n;
	char host[SRV_ORIGIN_MAX];
	unsigned port;
	bool any = false;
	while (next_entry(&p, &s, &n)) {
		if (!n)
			continue; /* "a,,b" or a trailing comma */
		if (n == 1 && *s == '*') {
			any = true;
			continue;
		}
		if (!split_authority(s, n, host, sizeof host, &port))
			return fail(err, SRV_ORIGIN_ERR_INVALID, "--allowed-host: '%.*s' is not a host name or address", SHOWN(n), s);
		if (port)
			return fail(err, SRV_ORIGIN_ERR_INVALID, "--allowed-host: '%.*s' has a port; give the name alone "
			            "(every port is served)", SHOWN(n), s);
		enum srv_origin_result r = list_add(&o->hosts, &o->host_count, host);
		if (r)
			return fail(err, r, "--allowed-host: out of memory");
	}
	if (!any && !o->host_count)
		return fail(err, SRV_ORIGIN_ERR_INVALID, "--allowed-host: no host in '%.*s'", SHOWN(strlen(list)), list);
	o->hosts_only = !any;
	return SRV_ORIGIN_OK;
}

static enum srv_origin_result parse_origins(struct srv_origin *o, const char *list, struct srv_origin_error *err)
{
	const char *p = list, *s;
	size_t n;
	struct parsed_origin po;
	char norm[SRV_ORIGIN_MAX];
	o->cors = true;
	while (next_entry(&p, &s, &n)) {
		if (!n)
			continue; /* "a,,b" or a trailing comma */
		if (n == 1 && *s == '*') {
			o->any_origin = true;
			continue;
		}
		if (n == 4 && !strncasecmp(s, "null", 4))
			return fail(err, SRV_ORIGIN_ERR_INVALID, "--cors-origin: '%.*s': every sandboxed or file: page sends "
			            "that origin; use * to allow every caller", SHOWN(n), s);
		if (!origin_parse(s, n, true, &po) || !origin_format(&po, norm, sizeof norm))
			return fail(err, SRV_ORIGIN_ERR_INVALID, "--cors-origin: '%.*s' is not an origin "
			            "(scheme://host[:port], no path)", SHOWN(n), s);
		enum srv_origin_result r = list_add(&o->origins, &o->origin_count, norm);
		if (r)
			return fail(err, r, "--cors-origin: out of memory");
	}
	if (!o->any_origin && !o->origin_count)
		return fail(err, SRV_ORIGIN_ERR_INVALID, "--cors-origin: no origin in '%.*s'", SHOWN(strlen(list)), list);
	return SRV_ORIGIN_OK;
}

/* On a loopback address, the loopback names and the listen host; elsewhere every name. */
static enum srv_origin_result default_hosts(struct srv_origin *o, const char *listen_host, bool loopback)
{
	static const char *const names[] = { "localhost", "127.0.0.1", "::1" };
	char host[SRV_ORIGIN_MAX];
	unsigned port;
	enum srv_origin_result r = SRV_ORIGIN_OK;
	if (!loopback)
		return SRV_ORIGIN_OK;
	o->hosts_only = true;
	for (size_t i = 0; i < sizeof names / sizeof names[0] && !r; i++)
		r = list_add(&o->hosts, &o->host_count, names[i]);
	if (!r && listen_host && split_authority(listen_host, strlen(listen_host), host, sizeof host, &port))
		r = list_add(&o->hosts, &o->host_count, host);
	return r;
}

enum srv_origin_result srv_origin_init(struct srv_origin *o, const struct srv_origin_config *c,
                                       struct srv_origin_error *err)
{
	enum srv_origin_result r;
	memset(o, 0, sizeof *o);
	err->msg[0] = 0;
	if (c->allowed_hosts)
		r = parse_hosts(o, c->allowed_hosts, err);
	else if ((r = default_hosts(o, c->listen_host, c->loopback)))
		snprintf(err->msg, sizeof err->msg, "the default --allowed-host: out of memory");
	if (!r && c->cors_origins)
		r = parse_origins(o, c->cors_origins, err);
	if (r)
		srv_origin_release(o);
	return r;
}

static void list_free(char ***list, size_t *count)
{
	for (size_t i = 0; i < *count; i++)
		free((*list)[i]);
	free(*list);
	*list = NULL;
	*count = 0;
}

void srv_origin_release(struct srv_origin *o)
{
	if (!o)
		return;
	list_free(&o->hosts, &o->host_count);
	list_free(&o->origins, &o->origin_count);
	memset(o, 0, sizeof *o);
}

/* ---- requests ---- */

static bool is(const char *v, const char *want)
{
	return v && !strcasecmp(v, want);
}

/* The Origin's host and port are the Host's (a Host without a port: the scheme's default). The
 * scheme is not compared: the daemon speaks http, but a TLS terminator in front makes the
 * page's origin https with the same Host. */
static bool same_origin(const struct parsed_origin *po, const char *host, unsigned hport)
{
	if (strcmp(po->host, host) != 0)
		return false;
	return hport ? po->port == hport : default_port(po->scheme) && po->port == default_port(po->scheme);
}

static enum srv_origin_verdict check_origin(const struct srv_origin *o, const struct srv_origin_request *q,
                                            const char *host, unsigned hport, char *detail, size_t size)
{
	struct parsed_origin po;
	char norm[SRV_ORIGIN_MAX];
	size_t n = strlen(q->origin);
	bool parsed = n < SRV_ORIGIN_MAX && origin_parse(q->origin, n, false, &po) && origin_format(&po, norm, sizeof norm);
	/* A browser that calls the request cross-site knows better than the Host header. */
	if (parsed && host && !is(q->sec_fetch_site, "cross-site") && same_origin(&po, host, hport))
		return SRV_ORIGIN_PASS;
	/* With *, any origin a browser can send (an opaque one is "null") is echoed back, nothing
	 * else: the answer repeats it in a header. */
	if (o->any_origin && (parsed || !strcmp(q->origin, "null")))
		return SRV_ORIGIN_CORS;
	if (parsed && in_list(o->origins, o->origin_count, norm))
		return SRV_ORIGIN_CORS;
	snprintf(detail, size, "Origin '%.200s' may not call this daemon from a browser: start umbrad with "
	         "--cors-origin %.200s to allow that origin", q->origin, parsed ? norm : q->origin);
	return SRV_ORIGIN_REFUSED;
}

enum srv_origin_verdict srv_origin_check(const struct srv_origin *o, const struct srv_origin_request *q,
                                         char *detail, size_t size)
{
	char host[SRV_ORIGIN_MAX];
	unsigned hport = 0;
	bool host_ok = q->host && split_authority(q->host, strlen(q->host), host, sizeof host, &hport);
	/* No Host at all is an HTTP/1.0 client (conn.c refuses HTTP/1.1 without one); no browser. */
	if (q->host && o->hosts_only && !q->probe && (!host_ok || !in_list(o->hosts, o->host_count, host))) {
		snprintf(detail, size, "Host '%.200s' is not a name this daemon answers to: start umbrad with "
		         "--allowed-host %.200s (a comma-separated list, or *) to serve it", q->host, host_ok ? host : q->host);
		return SRV_ORIGIN_BAD_HOST;
	}
	if (q->origin)
		return check_origin(o, q, host_ok ? host : NULL, hport, detail, size);
	/* A link followed from another site (GET or HEAD, top-level) stays allowed: it renders
	 * nothing and the page it opens calls the daemon as its own origin. */
	bool navigation = (is(q->method, "GET") || is(q->method, "HEAD")) && is(q->sec_fetch_mode, "navigate");
	if (is(q->sec_fetch_site, "cross-site") && !o->any_origin && !navigation) {
		snprintf(detail, size, "a cross-site browser request without an Origin header: only the origins given "
		         "to --cors-origin may call this daemon from another site");
		return SRV_ORIGIN_REFUSED;
	}
	return SRV_ORIGIN_PASS;
}
