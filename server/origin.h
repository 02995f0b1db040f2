/*
 * server/origin — who may call the daemon from a browser, and what browsers are told.
 *
 *   Host      --allowed-host LIST: the names a request's Host header may carry (port ignored),
 *             against DNS rebinding (a page of evil.example whose name now resolves to
 *             127.0.0.1 is "same-origin" with the daemon to the browser). Default: on a
 *             loopback --listen address only localhost, 127.0.0.1, ::1 and the listen host;
 *             on any other address every name (a daemon behind a balancer sees the names
 *             clients use). /healthz and /readyz are never refused: they tell nothing.
 *   Origin    a browser request whose Origin is not the daemon's own (the Host's host and
 *             port, either scheme: a TLS terminator may sit in front) and not in
 *             --cors-origin LIST (origins, or *) is refused, so a page of another site can
 *             neither render (a cross-site form or fetch costs a render even unread) nor read.
 *             Without Origin (curl, scripts) nothing changes, except that a request a browser
 *             marks Sec-Fetch-Site: cross-site needs an allowed origin too (a belt for browsers
 *             that send no Origin); a top-level GET/HEAD navigation (a link to the playground)
 *             stays allowed.
 *   CORS      an allowed cross-origin request gets the SRV_CORS_* headers below, its origin
 *             echoed in Access-Control-Allow-Origin; a preflight (OPTIONS) is answered 204.
 *
 * Pure: no libmicrohttpd. http.c reads the headers into a struct srv_origin_request, asks
 * srv_origin_check() and answers or adds the headers.
 *
 * Ownership: srv_origin_init() fills a caller-owned struct srv_origin (it allocates the lists);
 * srv_origin_release() frees them, accepts NULL and a zeroed struct, and may be called twice.
 * A zeroed struct srv_origin allows every Host and no cross-origin caller.
 * Threading: read-only after init; srv_origin_check() may run on any thread.
 */
#ifndef UMBRA_SRV_ORIGIN_H
#define UMBRA_SRV_ORIGIN_H

#include <stdbool.h>
#include <stddef.h>

/* Longest Origin or host this module compares (longer ones never match a list). */
#define SRV_ORIGIN_MAX 320

/* The request headers a cross-origin caller may send (every one the daemon reads, and the
 * balancer's X-Umbra-Affinity); the answer headers it may read (beyond the CORS-safelisted
 * Content-Type and Content-Length); how long a browser may keep a preflight's answer
 * (seconds; Chromium caps it at 7200). */
#define SRV_CORS_ALLOW_HEADERS "Content-Type, Accept, If-None-Match, Prefer, X-Priority, X-Request-Id, X-Umbra-Affinity"
#define SRV_CORS_EXPOSE_HEADERS "ETag, Server-Timing, Retry-After, X-Request-Id, Umbra-Warnings, Preference-Applied"
#define SRV_CORS_MAX_AGE "7200"
/* Content-Security-Policy of every answer but the playground page (which has its own, built
 * with the page: server/www/embed.sh): nothing in an answer may run or be framed. */
#define SRV_CSP_API "default-src 'none'; frame-ancestors 'none'"

enum srv_origin_result { SRV_ORIGIN_OK = 0, SRV_ORIGIN_ERR_INVALID, SRV_ORIGIN_ERR_NOMEM };

struct srv_origin_error {
	char msg[256];                 /* names the flag and the entry ("--cors-origin: ...") */
};

/* What srv_origin_init() is built from. The strings are read during the call only. */
struct srv_origin_config {
	const char *allowed_hosts;     /* --allowed-host: comma-separated names, "*" = any; NULL = default */
	const char *cors_origins;      /* --cors-origin: comma-separated origins, "*" = any; NULL = none */
	const char *listen_host;       /* the host of --listen (brackets allowed), for the default */
	bool loopback;                 /* --listen resolved to a loopback address */
};

struct srv_origin {
	bool hosts_only;               /* only the names in hosts[] are served (false: any Host) */
	char **hosts;                  /* normalised (lowercase, no brackets, no trailing dot) */
	size_t host_count;
	bool cors;                     /* --cors-origin given: answers carry Vary: Origin */
	bool any_origin;               /* --cors-origin * */
	char **origins;                /* normalised: scheme://host[:port], default port left out */
	size_t origin_count;
};

/* Returns SRV_ORIGIN_OK, or an error with err->msg naming the flag and the bad entry. On error
 * *o is left released. */
enum srv_origin_result srv_origin_init(struct srv_origin *o, const struct srv_origin_config *c,
                                       struct srv_origin_error *err);
void srv_origin_release(struct srv_origin *o);

/* One request's headers (NULL = absent). */
struct srv_origin_request {
	const char *method;
	const char *host;
	const char *origin;
	const char *sec_fetch_site;
	const char *sec_fetch_mode;
	bool probe;                    /* /healthz or /readyz: no Host check */
};

enum srv_origin_verdict {
	SRV_ORIGIN_PASS,               /* no Origin, or the daemon's own: no CORS headers */
	SRV_ORIGIN_CORS,               /* an allowed cross-origin request: answer with the CORS headers */
	SRV_ORIGIN_BAD_HOST,           /* Host not allowed: 421 */
	SRV_ORIGIN_REFUSED,            /* a cross-origin caller not allowed: 403 */
};

/* The verdict on one request; for BAD_HOST and REFUSED, `detail` (size bytes) says why and
 * which flag would allow it. */
enum srv_origin_verdict srv_origin_check(const struct srv_origin *o, const struct srv_origin_request *q,
                                         char *detail, size_t size);

#endif
