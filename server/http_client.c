/*
 * server/http_client — HTTP/1.1 POST over a fresh TCP connection (see http_client.h): the
 * request written with send(), the whole answer read until the server closes, then the status
 * line, the few headers the farm needs and the body (Content-Length or chunked) taken apart.
 */
#include <errno.h>
#include <netdb.h>
#include <poll.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>
#include "http_client.h"

enum srv_http_result srv_http_url_parse(const char *url, struct srv_http_url *u, struct srv_http_error *e)
{
	memset(u, 0, sizeof *u);
	if (strncasecmp(url, "http://", 7)) {
		snprintf(e->msg, sizeof e->msg, "server URL '%.200s' must start with http:// (no TLS here)", url);
		return SRV_HTTP_ERR_URL;
	}
	const char *h = url + 7, *end = h + strcspn(h, "/?#"), *colon = NULL;
	if (*h == '[') {   /* [v6]:port */
		const char *rb = memchr(h, ']', (size_t)(end - h));
		if (!rb) goto bad;
		snprintf(u->host, sizeof u->host, "%.*s", (int)(rb - h - 1), h + 1);
		colon = rb[1] == ':' ? rb + 1 : NULL;
	} else {
		colon = memchr(h, ':', (size_t)(end - h));
		size_t hl = (size_t)((colon ? colon : end) - h);
		if (hl >= sizeof u->host) goto bad;
		snprintf(u->host, sizeof u->host, "%.*s", (int)hl, h);
	}
	if (!u->host[0]) goto bad;
	if (colon) {
		size_t pl = (size_t)(end - colon - 1);
		if (!pl || pl >= sizeof u->port || strspn(colon + 1, "0123456789") < pl) goto bad;
		snprintf(u->port, sizeof u->port, "%.*s", (int)pl, colon + 1);
	} else {
		snprintf(u->port, sizeof u->port, "80");
	}
	if (*end && *end != '/') goto bad;
	size_t bl = strlen(end);
	while (bl && end[bl - 1] == '/') bl--;
	if (bl >= sizeof u->base) goto bad;
	snprintf(u->base, sizeof u->base, "%.*s", (int)bl, end);
	return SRV_HTTP_OK;
bad:
	snprintf(e->msg, sizeof e->msg, "server URL '%.200s' is not http://HOST[:PORT][/PATH]", url);
	return SRV_HTTP_ERR_URL;
}

/* A connect() a signal interrupted goes on in the background: wait for it (a Ctrl-C that lets
 * the requests in flight finish must not fail the one being connected). 0, or -1 with errno. */
static int finish_connect(int fd, unsigned timeout_s)
{
	struct pollfd p = {.fd = fd, .events = POLLOUT};
	int rc;
	while ((rc = poll(&p, 1, (int)timeout_s * 1000)) < 0 && errno == EINTR) {}
	if (rc == 0) errno = ETIMEDOUT;
	if (rc <= 0) return -1;
	int err = 0;
	socklen_t len = sizeof err;
	if (getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len) < 0) return -1;
	if (err) { errno = err; return -1; }
	return 0;
}

static int dial(const struct srv_http_url *u, unsigned timeout_s, struct srv_http_error *e)
{
	struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM}, *ai, *a;
	int rc = getaddrinfo(u->host, u->port, &hints, &ai);
	if (rc) {
		snprintf(e->msg, sizeof e->msg, "cannot resolve '%s': %s", u->host, gai_strerror(rc));
		return -1;
	}
	int fd = -1, err = 0;
	struct timeval tv = {.tv_sec = timeout_s};
	for (a = ai; a && fd < 0; a = a->ai_next) {
		fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
		if (fd < 0) { err = errno; continue; }
		/* SO_SNDTIMEO also bounds connect() on Linux. */
		setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
		setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
		rc = connect(fd, a->ai_addr, a->ai_addrlen);
		if (rc < 0 && errno == EINTR) rc = finish_connect(fd, timeout_s);
		if (rc < 0) { err = errno; close(fd); fd = -1; }
	}
	freeaddrinfo(ai);
	if (fd < 0) snprintf(e->msg, sizeof e->msg, "cannot connect to %s:%s: %s", u->host, u->port, strerror(err));
	return fd;
}

static bool send_all(int fd, const void *data, size_t len)
{
	const char *p = data;
	while (len) {
		ssize_t w = send(fd, p, len, MSG_NOSIGNAL);
		if (w < 0 && errno == EINTR) continue;
		if (w <= 0) return false;
		p += w;
		len -= (size_t)w;
	}
	return true;
}

/* Reads until the peer closes; *buf malloc'd. -1 on a read error or timeout (errno kept). */
static ssize_t read_all(int fd, uint8_t **buf)
{
	size_t cap = 1 << 16, n = 0;
	*buf = malloc(cap + 1);
	for (;;) {
		if (!*buf) { errno = ENOMEM; return -1; }
		if (n == cap) {
			uint8_t *nb = realloc(*buf, (cap *= 2) + 1);
			if (!nb) { free(*buf); *buf = NULL; errno = ENOMEM; return -1; }
			*buf = nb;
		}
		ssize_t r = recv(fd, *buf + n, cap - n, 0);
		if (r < 0 && errno == EINTR) continue;
		if (r < 0) return -1;
		if (r == 0) break;
		n += (size_t)r;
	}
	(*buf)[n] = 0;
	return (ssize_t)n;
}

/* The value of header `name` in the header block [h, end) into out ("" when absent). */
static void header(const char *h, const char *end, const char *name, char *out, size_t size)
{
	size_t nl = strlen(name);
	out[0] = 0;
	for (const char *l = h; l < end;) {
		const char *eol = memchr(l, '\n', (size_t)(end - l));
		if (!eol) eol = end;
		if ((size_t)(eol - l) > nl && !strncasecmp(l, name, nl) && l[nl] == ':') {
			const char *v = l + nl + 1;
			while (v < eol && (*v == ' ' || *v == '\t')) v++;
			size_t vl = (size_t)(eol - v);
			while (vl && (v[vl - 1] == '\r' || v[vl - 1] == ' ')) vl--;
			snprintf(out, size, "%.*s", (int)(vl < size ? vl : size - 1), v);
			return;
		}
		l = eol + 1;
	}
}

/* Decodes a chunked body in place; its length, or -1 when it is cut short or malformed. */
static ssize_t dechunk(uint8_t *b, size_t len)
{
	size_t in = 0, out = 0;
	for (;;) {
		char *end;
		unsigned long n = strtoul((const char *)b + in, &end, 16);
		const uint8_t *eol = memchr(b + in, '\n', len - in);
		if ((uint8_t *)end == b + in || !eol) return -1;
		in = (size_t)(eol - b) + 1;
		if (!n) return (ssize_t)out;
		if (n > len - in) return -1;
		memmove(b + out, b + in, n);
		out += n;
		in += n;
		if (in < len && b[in] == '\r') in++;
		if (in < len && b[in] == '\n') in++;
	}
}

bool srv_http_response_parse(uint8_t *raw, size_t n, struct srv_http_response *r)
{
	memset(r, 0, sizeof *r);
	char *text = (char *)raw, *eoh = strstr(text, "\r\n\r\n");
	int status;
	if (!eoh || sscanf(text, "HTTP/1.%*d %3d", &status) != 1) return false;
	char cl[32], te[64];
	header(text, eoh, "Content-Length", cl, sizeof cl);
	header(text, eoh, "Transfer-Encoding", te, sizeof te);
	header(text, eoh, "Content-Type", r->content_type, sizeof r->content_type);
	header(text, eoh, "Retry-After", r->retry_after, sizeof r->retry_after);
	header(text, eoh, "Server-Timing", r->server_timing, sizeof r->server_timing);
	header(text, eoh, "Umbra-Warnings", r->warnings, sizeof r->warnings);
	size_t off = (size_t)(eoh + 4 - text), blen = n - off;
	if (!strcasecmp(te, "chunked")) {
		ssize_t d = dechunk(raw + off, blen);
		if (d < 0) return false;
		blen = (size_t)d;
	} else if (cl[0]) {
		unsigned long long want = strtoull(cl, NULL, 10);
		if (want > blen) return false;   /* closed before the whole body */
		blen = (size_t)want;
	}
	memmove(raw, raw + off, blen);
	raw[blen] = 0;
	r->status = status;
	r->body = raw;
	r->len = blen;
	return true;
}

enum srv_http_result srv_http_post(const struct srv_http_url *u, const char *path, const char *headers,
                                   const struct srv_http_chunk *body, size_t nchunks, unsigned timeout_s,
                                   struct srv_http_response *r, struct srv_http_error *e)
{
	memset(r, 0, sizeof *r);
	size_t total = 0;
	for (size_t k = 0; k < nchunks; k++) total += body[k].len;
	char head[2048];
	bool v6 = strchr(u->host, ':');   /* an IPv6 address goes in brackets */
	int hl = snprintf(head, sizeof head, "POST %s%s HTTP/1.1\r\nHost: %s%s%s:%s\r\nConnection: close\r\n"
	                  "Content-Length: %zu\r\n%s\r\n", u->base, path, v6 ? "[" : "", u->host, v6 ? "]" : "", u->port,
	                  total, headers);
	if (hl < 0 || (size_t)hl >= sizeof head) {
		snprintf(e->msg, sizeof e->msg, "request headers too long");
		return SRV_HTTP_ERR_URL;
	}
	int fd = dial(u, timeout_s, e);
	if (fd < 0) return SRV_HTTP_ERR_CONNECT;
	bool sent = send_all(fd, head, (size_t)hl);
	for (size_t k = 0; sent && k < nchunks; k++) sent = send_all(fd, body[k].data, body[k].len);
	/* A server may answer (413, 503) before the whole body; read what it said either way. */
	int werr = errno;
	uint8_t *raw = NULL;
	ssize_t n = read_all(fd, &raw);
	int rerr = errno;
	close(fd);
	if (n < 0 && rerr == ENOMEM) {
		snprintf(e->msg, sizeof e->msg, "out of memory for the answer");
		return SRV_HTTP_ERR_MEMORY;
	}
	if (n <= 0 || !srv_http_response_parse(raw, (size_t)n, r)) {
		free(raw);
		memset(r, 0, sizeof *r);
		snprintf(e->msg, sizeof e->msg, "connection to %s:%s lost: %s", u->host, u->port,
		         n < 0 ? strerror(rerr) : !sent ? strerror(werr) : n == 0 ? "closed without an answer"
		                                                              : "closed before the whole answer");
		return SRV_HTTP_ERR_LOST;
	}
	return SRV_HTTP_OK;
}

void srv_http_response_release(struct srv_http_response *r)
{
	if (!r) return;
	free(r->body);
	memset(r, 0, sizeof *r);
}
