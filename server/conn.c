/*
 * umbrad connections: the listen address, the file-descriptor budget, the per-connection
 * header timeout and the HTTP/1.1 framing checks libmicrohttpd 0.9.75 does not make.
 *
 * Called by http.c only, on libmicrohttpd's polling thread (srv_conn_accept, srv_conn_notify,
 * srv_conn_framing_error, srv_conn_request_begins) or before it starts (srv_conn_prepare,
 * srv_conn_share_start, srv_conn_listen_addr). The timeouts live in libmicrohttpd's
 * connection, the limits in struct srv_config, the connections per range in s->ranges.
 *
 * What the library answers by itself (HTML, before any callback of ours runs) is listed in the
 * README ("Limits of the HTTP layer"); srv_conn_framing_error covers what it lets through.
 */
#include <errno.h>
#include <microhttpd.h>
#include <netdb.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
#include <sys/socket.h>

#include "conn.h"
#include "log.h"
#include "ranges.h"

/* File descriptors kept for everything that is not a client connection: the listen socket,
 * the epoll and signalling descriptors, the Vulkan driver, the pipeline cache, log output. */
#define FD_RESERVE 64u

void srv_conn_prepare(struct srv_config *cfg)
{
	struct rlimit rl;
	if (getrlimit(RLIMIT_NOFILE, &rl) != 0)
		return;
	/* The soft limit is often 1024: as many connections as the default --max-connections
	 * leave no descriptor for anything else, and accept() then fails with EMFILE for every
	 * client instead of the library refusing the one over the limit. */
	if (rl.rlim_cur != RLIM_INFINITY && rl.rlim_cur < rl.rlim_max) {
		struct rlimit want = { rl.rlim_max, rl.rlim_max };
		if (setrlimit(RLIMIT_NOFILE, &want) == 0)
			rl.rlim_cur = rl.rlim_max;
	}
	if (rl.rlim_cur == RLIM_INFINITY || rl.rlim_cur >= (rlim_t)cfg->max_connections + FD_RESERVE)
		return;
	unsigned fit = rl.rlim_cur > FD_RESERVE * 2 ? (unsigned)(rl.rlim_cur - FD_RESERVE) : FD_RESERVE;
	srv_log(SRV_LOG_WARN, "--max-connections %u lowered to %u: the open-file limit is %llu", cfg->max_connections,
	        fit, (unsigned long long)rl.rlim_cur);
	cfg->max_connections = fit;
}

int srv_conn_share_start(struct srv_server *s)
{
	struct srv_config *cfg = &s->cfg;
	if (cfg->max_connections_per_range == SRV_SHARE_DEFAULT)
		cfg->max_connections_per_range = cfg->max_connections / 4 ? cfg->max_connections / 4 : 1;
	s->ranges = srv_ranges_create(cfg->max_connections_per_range, cfg->max_connections);
	if (!s->ranges) {
		srv_log(SRV_LOG_ERROR, "out of memory for the table of %u connections", cfg->max_connections);
		return -1;
	}
	return 0;
}

void srv_conn_share_stop(struct srv_server *s)
{
	srv_ranges_destroy(s->ranges);
	s->ranges = NULL;
}

enum MHD_Result srv_conn_accept(void *cls, const struct sockaddr *addr, socklen_t len)
{
	struct srv_server *s = cls;
	(void)len;
	return srv_ranges_admit(s->ranges, addr) ? MHD_YES : MHD_NO;
}

int srv_conn_listen_addr(const char *listen, struct sockaddr_storage *ss, socklen_t *len)
{
	char host[256];
	const char *colon = strrchr(listen, ':');
	if (!colon || colon == listen) {
		srv_log(SRV_LOG_ERROR, "--listen '%s': expected ADDR:PORT", listen);
		return -1;
	}
	const char *h = listen;
	size_t hl = (size_t)(colon - listen);
	if (*h == '[' && hl >= 2 && h[hl - 1] == ']') {
		h++;
		hl -= 2;
	}
	if (hl >= sizeof host) {
		srv_log(SRV_LOG_ERROR, "--listen '%s': address too long", listen);
		return -1;
	}
	memcpy(host, h, hl);
	host[hl] = 0;
	struct addrinfo hints = { .ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM, .ai_flags = AI_PASSIVE };
	struct addrinfo *ai = NULL;
	int e = getaddrinfo(host, colon + 1, &hints, &ai);
	if (e != 0) {
		srv_log(SRV_LOG_ERROR, "--listen '%s': %s", listen, gai_strerror(e));
		return -1;
	}
	memcpy(ss, ai->ai_addr, ai->ai_addrlen);
	*len = ai->ai_addrlen;
	freeaddrinfo(ai);
	return 0;
}

/* socket_ctx of a connection that counts for its range (srv_ranges_open said yes). */
static char counted_mark;

/* Counts the connection for its range at start (the accept policy's check and this count run
 * one after the other on the polling thread, with no other accept between them), and uncounts
 * it at close. */
static void count_connection(struct srv_server *s, struct MHD_Connection *conn, void **socket_ctx,
                             enum MHD_ConnectionNotificationCode code)
{
	const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
	const struct sockaddr *sa = ci ? ci->client_addr : NULL;
	if (code == MHD_CONNECTION_NOTIFY_STARTED) {
		*socket_ctx = srv_ranges_open(s->ranges, sa) ? &counted_mark : NULL;
	} else if (code == MHD_CONNECTION_NOTIFY_CLOSED && *socket_ctx == &counted_mark) {
		srv_ranges_close(s->ranges, sa);
		*socket_ctx = NULL;
	}
}

void srv_conn_notify(void *cls, struct MHD_Connection *conn, void **socket_ctx,
                     enum MHD_ConnectionNotificationCode code)
{
	struct srv_server *s = cls;
	const struct srv_config *cfg = &s->cfg;
	count_connection(s, conn, socket_ctx, code);
	/* A new connection gets the shorter header timeout until its first request head is
	 * complete (srv_conn_request_begins): a client that connects and sends nothing, or
	 * almost nothing, holds a slot for seconds rather than a whole keep-alive period. The
	 * library has released its connection lock before this callback (daemon.c,
	 * internal_add_connection), so changing the timeout here is safe. */
	if (code == MHD_CONNECTION_NOTIFY_STARTED && cfg->header_timeout_s &&
	    cfg->header_timeout_s < cfg->idle_timeout_s)
		MHD_set_connection_option(conn, MHD_CONNECTION_OPTION_TIMEOUT, cfg->header_timeout_s);
}

void srv_conn_request_begins(const struct srv_config *cfg, struct MHD_Connection *conn)
{
	const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_TIMEOUT);
	if (ci && ci->connection_timeout != cfg->idle_timeout_s)
		MHD_set_connection_option(conn, MHD_CONNECTION_OPTION_TIMEOUT, cfg->idle_timeout_s);
}

/* Counts of the framing headers, with the first value of each. */
struct framing {
	unsigned host, content_length, transfer_encoding;
	const char *first_cl;
	bool cl_differ;
};

static enum MHD_Result count_header(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
	struct framing *f = cls;
	(void)kind;
	if (!key)
		return MHD_YES;
	if (!strcasecmp(key, MHD_HTTP_HEADER_HOST)) {
		f->host++;
	} else if (!strcasecmp(key, MHD_HTTP_HEADER_CONTENT_LENGTH)) {
		if (f->content_length++ == 0)
			f->first_cl = value;
		else if (strcmp(f->first_cl ? f->first_cl : "", value ? value : "") != 0)
			f->cl_differ = true;
	} else if (!strcasecmp(key, MHD_HTTP_HEADER_TRANSFER_ENCODING)) {
		f->transfer_encoding++;
	}
	return MHD_YES;
}

const char *srv_conn_framing_error(struct MHD_Connection *conn, const char *version, int *status)
{
	struct framing f = { 0 };
	MHD_get_connection_values(conn, MHD_HEADER_KIND, count_header, &f);
	*status = 400;
	/* RFC 9112 §3.2: a server MUST answer 400 to an HTTP/1.1 request without exactly one
	 * Host. libmicrohttpd's own check (MHD_OPTION_STRICT_FOR_CLIENT 1) answers HTML with
	 * its header block twice in 0.9.75, so the check is made here instead. */
	bool http11 = version && !strcasecmp(version, MHD_HTTP_VERSION_1_1);
	if (http11 && f.host == 0)
		return "an HTTP/1.1 request needs a Host header";
	if (f.host > 1)
		return "more than one Host header";
	/* The library reads the body by the first Content-Length and ignores the others; a
	 * proxy in front may have used another one (request smuggling). Identical copies are
	 * one value (RFC 9110 §8.6). */
	if (f.cl_differ)
		return "Content-Length headers with different values";
	/* With both, the library frames by Transfer-Encoding and a proxy may frame by
	 * Content-Length (RFC 9112 §6.1: such a message ought to be handled as an error). */
	if (f.transfer_encoding && f.content_length)
		return "both Transfer-Encoding and Content-Length";
	if (f.transfer_encoding) {
		const char *te = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_TRANSFER_ENCODING);
		if (f.transfer_encoding > 1 || !te || strcasecmp(te, "chunked") != 0) {
			/* The library only decodes "chunked"; any other coding would be read as a body
			 * that ends when the connection does. */
			*status = 501;
			return "Transfer-Encoding other than a single 'chunked' is not supported";
		}
	}
	return NULL;
}
