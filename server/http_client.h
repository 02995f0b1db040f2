/*
 * server/http_client — a small HTTP/1.1 client over POSIX sockets, for umbra-render's remote
 * farm (server/farm_remote.c): one POST per connection (`Connection: close`), plain http://
 * only (a daemon or a balancer on a trusted network; no TLS, no proxies, no redirects).
 *
 * Usage:
 *   struct srv_http_url u; struct srv_http_error e;
 *   if (srv_http_url_parse("http://127.0.0.1:8080", &u, &e) != SRV_HTTP_OK) ... e.msg
 *   struct srv_http_chunk body[] = {{head, hlen}, {model, mlen}, {tail, tlen}};
 *   struct srv_http_response r;
 *   if (srv_http_post(&u, "/v1/render", "Content-Type: ...\r\n", body, 3, 120, &r, &e) == SRV_HTTP_OK)
 *       ... r.status, r.body, r.len ...;
 *   srv_http_response_release(&r);     // NULL-safe, also after a failure
 *
 * SRV_HTTP_ERR_CONNECT: no connection was made (refused, unresolvable); SRV_HTTP_ERR_LOST: the
 * connection broke, timed out or closed before a whole answer (the request may or may not have
 * been seen). Both leave r empty. A signal (EINTR) does not abort a request in flight.
 * Threading: no shared state; one call per thread at a time on its own response.
 */
#ifndef UMBRA_HTTP_CLIENT_H
#define UMBRA_HTTP_CLIENT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

enum srv_http_result { SRV_HTTP_OK = 0, SRV_HTTP_ERR_URL, SRV_HTTP_ERR_CONNECT, SRV_HTTP_ERR_LOST, SRV_HTTP_ERR_MEMORY };

struct srv_http_error {
	char msg[640];
};

struct srv_http_url {
	char host[256];
	char port[8];
	char base[512];     /* path prefix without the trailing '/' ("" for the root) */
};

struct srv_http_chunk {
	const void *data;
	size_t len;
};

struct srv_http_response {
	int status;
	char content_type[128];
	char retry_after[32];
	char server_timing[1024];
	char warnings[1024];    /* Umbra-Warnings */
	uint8_t *body;          /* malloc'd, NUL-terminated */
	size_t len;
};

enum srv_http_result srv_http_url_parse(const char *url, struct srv_http_url *u, struct srv_http_error *e);
/* POSTs the chunks (their total is Content-Length) to u's base + path with the extra header
 * lines `headers` (each ending "\r\n", may be ""), waiting at most timeout_s per read or write. */
enum srv_http_result srv_http_post(const struct srv_http_url *u, const char *path, const char *headers,
                                   const struct srv_http_chunk *body, size_t nchunks, unsigned timeout_s,
                                   struct srv_http_response *r, struct srv_http_error *e);
void srv_http_response_release(struct srv_http_response *r);
/* An answer as read from the socket, raw[0, n) with raw[n] writable (malloc'd, n + 1 bytes),
 * split into r, which then owns raw (as body). false: not a whole HTTP/1.x answer (no end of
 * headers, a body shorter than Content-Length, a cut chunked body); raw is still the caller's. */
bool srv_http_response_parse(uint8_t *raw, size_t n, struct srv_http_response *r);

#endif
