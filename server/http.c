/*
 * umbrad HTTP: libmicrohttpd callbacks and the routes of contract §5.
 *
 * The access handler runs on libmicrohttpd's polling thread and never blocks on a render:
 *   1st call   (headers only)  framing (conn.c: Host, Content-Length, Transfer-Encoding), the
 *                              Host and Origin rules (origin_http.c: 421, 403, answered like a
 *                              GET once the body is dropped), route, method (OPTIONS: 204 on
 *                              the next call), Content-Type, Content-Length, readiness; any
 *                              other error is answered at once (libmicrohttpd then skips the
 *                              body, sends no "100 Continue" and closes the connection).
 *   next calls (body chunks)   appended and hashed (ETag); past --max-body -> 413.
 *   last call  (body complete) suspend + queue (full -> 503); the worker parses, and answers
 *                              412 to a POST whose If-None-Match lists the scene's ETag.
 *   after resume               the worker's answer is sent.
 * This file dispatches (routes, methods, the GET routes) and answers; POST /v1/render's (and
 * /v1/renders') headers and body are render_route.c's, GET /v1/renders/{hash} renders_route.c's,
 * the negotiation rules negotiate.c's.
 * The request struct is freed in the completion callback, which also ends the pending count
 * that the drain at exit waits for.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <microhttpd.h>
#include <netdb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include "conn.h"
#include "imports.h"
#include "log.h"
#include "metrics.h"
#include "http.h"
#include "queue.h"
#include "results.h"

const char *srv_route_name(enum srv_route r)
{
	static const char *const names[SRV_ROUTE_COUNT] = { "/v1/render", "/healthz", "/readyz",
		"/metrics", "/v1/info", "/playground", "/v1/renders", "/v1/renders/{hash}", "/v1/explain", "other" };
	return (unsigned)r < SRV_ROUTE_COUNT ? names[r] : "other";
}

bool srv_route_posts(enum srv_route r)
{
	return r == SRV_ROUTE_RENDER || r == SRV_ROUTE_RENDERS || r == SRV_ROUTE_EXPLAIN;
}

const char *srv_stage_name(enum srv_stage st)
{
	static const char *const names[SRV_STAGE_COUNT] = { "parse", "upload", "shadow", "main",
		"readback", "encode" };
	return (unsigned)st < SRV_STAGE_COUNT ? names[st] : "unknown";
}

static enum srv_route route_of(const char *url)
{
	static const struct { const char *path; enum srv_route r; } routes[] = {
		{ "/v1/render", SRV_ROUTE_RENDER }, { "/healthz", SRV_ROUTE_HEALTHZ },
		{ "/readyz", SRV_ROUTE_READYZ }, { "/metrics", SRV_ROUTE_METRICS },
		{ "/v1/info", SRV_ROUTE_INFO }, { "/v1/renders", SRV_ROUTE_RENDERS },
		{ "/v1/explain", SRV_ROUTE_EXPLAIN },
	};
	for (size_t i = 0; i < sizeof routes / sizeof routes[0]; i++)
		if (!strcmp(url, routes[i].path))
			return routes[i].r;
	if (srv_playground_path(url))
		return SRV_ROUTE_PLAYGROUND;
	if (!strncmp(url, "/v1/renders/", 12))
		return SRV_ROUTE_RESULT;
	return SRV_ROUTE_OTHER;
}

/* ---- answers ---- */

void srv_request_drop_body(struct srv_request *req)
{
	free(req->body);
	req->body = NULL;
	req->body_len = req->body_cap = 0;
	for (size_t i = 0; i < req->part_count; i++) {
		free(req->parts[i].name);
		free(req->parts[i].data);
	}
	free(req->parts);
	req->parts = NULL;
	req->part_count = 0;
}

static void request_free(struct srv_request *req)
{
	if (!req)
		return;
	if (req->post)
		MHD_destroy_post_processor(req->post);
	srv_request_drop_body(req);
	srv_kept_release(&req->kept);
	free(req->out);
	free(req);
}

const char *srv_allow_of(enum srv_route r)
{
	return srv_route_posts(r) ? "POST" : "GET, HEAD";
}

/* The headers of a render answer (POST /v1/render, POST /v1/renders, GET /v1/renders/{hash},
 * POST /v1/explain): ETag, Location, Server-Timing, Umbra-Warnings and Cache-Control; no-store
 * for the rest. A plan (explain) is no image: no ETag, and no-store (it says what the cache
 * held). */
static void render_headers(struct srv_request *req, struct MHD_Response *resp, int status)
{
	const struct srv_server *s = req->srv;
	bool explain = req->explain || req->route == SRV_ROUTE_EXPLAIN;
	bool render = req->route == SRV_ROUTE_RENDER || req->route == SRV_ROUTE_RENDERS || req->route == SRV_ROUTE_RESULT ||
	              req->route == SRV_ROUTE_EXPLAIN;
	bool fresh = status == 200 || status == 303 || status == 304;
	if (render && !explain && (fresh || status == 412) && req->etag[0])
		MHD_add_response_header(resp, MHD_HTTP_HEADER_ETAG, req->etag);
	if (render && status == 303)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_LOCATION, req->location);
	if (render && fresh && req->server_timing[0])
		MHD_add_response_header(resp, MHD_HTTP_HEADER_SERVER_TIMING, req->server_timing);
	/* What the image leaves out of what the scene asked for (never silent). */
	if (render && (status == 200 || status == 303) && req->warnings[0])
		MHD_add_response_header(resp, "Umbra-Warnings", req->warnings);
	if (req->explain_preferred && status == 200)
		MHD_add_response_header(resp, "Preference-Applied", "explain");
	const char *cc = "no-store";
	if (req->route == SRV_ROUTE_RESULT && (status == 200 || status == 304))
		cc = SRV_RESULT_CACHE_CONTROL;
	else if (render && !explain && (status == 200 || status == 303))
		cc = s->cfg.cache_control ? s->cfg.cache_control : SRV_RENDER_CACHE_CONTROL;
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, cc);
}

/* Queues an answer. body is malloc'd and becomes libmicrohttpd's (freed with free()), or NULL.
 * Logs the request and counts it. Returns what the access handler returns. */
enum MHD_Result srv_respond(struct srv_request *req, int status, const char *content_type,
                            void *body, size_t len, const char *allow)
{
	struct srv_server *s = req->srv;
	struct MHD_Response *resp =
		body ? MHD_create_response_from_buffer(len, body, MHD_RESPMEM_MUST_FREE)
		     : MHD_create_response_from_buffer(0, NULL, MHD_RESPMEM_PERSISTENT);
	if (!resp) {
		free(body);
		return MHD_NO;
	}
	if (content_type)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, content_type);
	MHD_add_response_header(resp, "X-Request-Id", req->id);
	if (allow)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_ALLOW, allow);
	if (status == 503)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, atomic_load(&s->draining) ? "5" : "1");
	srv_origin_headers(req, resp, status);
	render_headers(req, resp, status);
	if (atomic_load(&s->draining) || req->close_after)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
	enum MHD_Result r = MHD_queue_response(req->conn, (unsigned)status, resp);
	MHD_destroy_response(resp);
	if (r != MHD_YES)
		return r; /* not answered: nothing to log or count */
	req->state = SRV_REQ_ANSWERED;
	double secs = srv_now() - req->t_start;
	srv_metrics_request(s->metrics, req->route, status, secs, len);
	srv_log_request(&(struct srv_access){ .method = req->method, .path = req->path, .route = srv_route_name(req->route),
	                                      .request_id = req->id, .client = req->client_addr,
	                                      .detail = status >= 400 ? req->problem_detail : NULL,
	                                      .pointer = status >= 400 ? req->problem_pointer : NULL,
	                                      .status = status, .bytes = len, .ms = secs * 1000.0 });
	return r;
}

void srv_request_note_problem(struct srv_request *req, const struct api_problem *p)
{
	snprintf(req->problem_pointer, sizeof req->problem_pointer, "%s", p->pointer);
	snprintf(req->problem_detail, sizeof req->problem_detail, "%s", p->detail);
}

enum MHD_Result srv_respond_problem(struct srv_request *req, int status, const char *allow,
                                    const char *pointer, const char *fmt, ...)
{
	struct api_problem p;
	char detail[512];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(detail, sizeof detail, fmt, ap);
	va_end(ap);
	api_problem_set(&p, status, pointer, "%s", detail);
	srv_request_note_problem(req, &p);
	char *json = api_problem_json(&p);
	return srv_respond(req, status, "application/problem+json", json, json ? strlen(json) : 0, allow);
}

/* A request whose framing is unusable (see conn.h): problem+json typed as an HTTP error, not
 * as a scene error, and the connection closed since the body's end is unknown. */
static enum MHD_Result respond_framing(struct srv_request *req, int status, const char *detail)
{
	struct api_problem p;
	api_problem_set(&p, status, "", "%s", detail);
	snprintf(p.type, sizeof p.type, "https://umbra.dev/problems/%s",
	         status == 501 ? "not-implemented" : "malformed-request");
	snprintf(p.title, sizeof p.title, "%s", status == 501 ? "Not implemented" : "Malformed HTTP request");
	req->close_after = true;
	srv_request_note_problem(req, &p);
	char *json = api_problem_json(&p);
	return srv_respond(req, status, "application/problem+json", json, json ? strlen(json) : 0, NULL);
}

static enum MHD_Result respond_text(struct srv_request *req, int status, const char *ctype, const char *text)
{
	char *body = strdup(text);
	return srv_respond(req, status, ctype, body, body ? strlen(body) : 0, NULL);
}

/* ---- GET routes ---- */

static enum MHD_Result answer_info(struct srv_request *req)
{
	struct srv_server *s = req->srv;
	const struct srv_config *c = &s->cfg;
	struct rnd_info info;
	pthread_rwlock_rdlock(&s->ctx_lock);
	info = s->info;
	pthread_rwlock_unlock(&s->ctx_lock);
	struct api_info in = {
		.version = UMBRA_VERSION, .device = info.device_name, .driver = info.driver_name,
		.driver_info = info.driver_info, .vulkan_api = info.api_version, .cpu = info.is_cpu,
		.limits = c->limits, .max_body = c->max_body, .max_memory = c->max_memory,
		.device_max_allocation = info.max_allocation,
		.max_dimension = info.max_image_dimension < RND_MAX_DIMENSION ? info.max_image_dimension : RND_MAX_DIMENSION,
		.device_max_shadow_resolution = info.max_shadow_resolution, .deadline_ms = c->deadline_ms,
		.queue = c->queue, .workers = c->workers, .max_textures = info.max_textures,
		.device_max_textures = info.device_max_textures, .max_rss = c->max_rss, .rss = srv_rss_bytes(),
	};
	size_t len = 0;
	char *json = api_info_json(&in, &len);
	if (!json)
		return MHD_NO;
	return srv_respond(req, 200, "application/json", json, len, NULL);
}

static enum MHD_Result answer_metrics(struct srv_request *req)
{
	size_t len;
	char *text = srv_metrics_text(req->srv, &len);
	if (!text)
		return MHD_NO;
	return srv_respond(req, 200, "text/plain; version=0.0.4; charset=utf-8", text, len, NULL);
}

bool srv_is_ready(const struct srv_server *s)
{
	return atomic_load(&s->ready) && !atomic_load(&s->draining);
}

enum MHD_Result srv_answer_not_ready(struct srv_request *req)
{
	struct srv_server *s = req->srv;
	if (atomic_load(&s->draining))
		return srv_respond_problem(req, 503, NULL, "", "the server is shutting down");
	return srv_respond_problem(req, 503, NULL, "", "the renderer is not ready yet (device start-up and pipeline warm-up)");
}

/* ---- dispatch ---- */

/* OPTIONS on a route: 204 with Allow; to an allowed cross-origin caller (a CORS preflight) with
 * the Access-Control-Allow-* headers too (srv_origin_headers). */
static enum MHD_Result answer_options(struct srv_request *req)
{
	return srv_respond(req, 204, NULL, NULL, 0, srv_route_posts(req->route) ? "POST, OPTIONS" : "GET, HEAD, OPTIONS");
}

static enum MHD_Result first_call(struct srv_request *req, struct MHD_Connection *conn, const char *version)
{
	bool get = !strcmp(req->method, "GET") || !strcmp(req->method, "HEAD");
	int status;
	const char *framing = srv_conn_framing_error(conn, version, &status);
	if (framing)
		return respond_framing(req, status, framing);
	srv_conn_request_begins(&req->srv->cfg, conn);
	enum MHD_Result refused;
	if (srv_origin_refuses(req, conn, &refused))
		return refused;
	if (req->route == SRV_ROUTE_OTHER)
		return srv_respond_problem(req, 404, NULL, "", "no route %s", req->path);
	if (!strcmp(req->method, "OPTIONS")) {
		req->state = SRV_REQ_HEADERS; /* answered on the next call, as a GET */
		return MHD_YES;
	}
	bool post = srv_route_posts(req->route);
	if (post ? strcmp(req->method, "POST") != 0 : !get)
		return srv_respond_problem(req, 405, srv_allow_of(req->route), "", "%s is not allowed on %s; allowed: %s",
		                       req->method, srv_route_name(req->route), srv_allow_of(req->route));
	if ((req->route == SRV_ROUTE_RENDERS || req->route == SRV_ROUTE_RESULT) && !req->srv->results)
		return srv_respond_problem(req, 404, NULL, "", "no route %s: this server keeps no results "
		                           "(--result-cache-mb 0); POST /v1/render answers the image itself", req->path);
	if (post)
		return srv_render_begin(req, conn);
	/* GET routes answer on the next call, once libmicrohttpd has the whole request (an
	 * answer queued on the first call makes it close the connection). */
	req->state = SRV_REQ_HEADERS;
	return MHD_YES;
}

static enum MHD_Result answer_get(struct srv_request *req)
{
	struct srv_server *s = req->srv;
	if (req->refused)
		return srv_respond_problem(req, req->refused, NULL, "", "%s", req->problem_detail);
	if (!strcmp(req->method, "OPTIONS"))
		return answer_options(req);
	switch (req->route) {
	case SRV_ROUTE_HEALTHZ:
		return respond_text(req, 200, "text/plain; charset=utf-8", "ok\n");
	case SRV_ROUTE_READYZ:
		if (atomic_load(&s->leaving) && !atomic_load(&s->draining))
			return srv_respond_problem(req, 503, NULL, "", "the server is shutting down (it still answers renders for --drain-grace-ms)");
		if (!srv_is_ready(s))
			return srv_answer_not_ready(req);
		return respond_text(req, 200, "text/plain; charset=utf-8", "ready\n");
	case SRV_ROUTE_METRICS:
		return answer_metrics(req);
	case SRV_ROUTE_INFO:
		if (!atomic_load(&s->ready))
			return srv_answer_not_ready(req);
		return answer_info(req);
	case SRV_ROUTE_RESULT:
		return srv_result_get(req, req->conn);
	case SRV_ROUTE_PLAYGROUND: {
		size_t len = 0;
		if (s->cfg.no_playground)
			return srv_respond_problem(req, 404, NULL, "", "no route %s (--no-playground)", req->path);
		char *page = srv_playground_page(&len);
		if (!page)
			return srv_respond_problem(req, 503, NULL, "", "out of memory for the playground page");
		return srv_respond(req, 200, "text/html; charset=utf-8", page, len, NULL);
	}
	default:
		return MHD_NO;
	}
}

/* X-Request-Id: the caller's when it is short printable ASCII, else a new one. */
static void request_id(struct srv_request *req, struct MHD_Connection *conn)
{
	struct srv_server *s = req->srv;
	const char *id = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "X-Request-Id");
	if (id && *id && strlen(id) < sizeof req->id) {
		bool ok = true;
		for (const char *p = id; *p; p++)
			if (*p < 0x21 || *p > 0x7e)
				ok = false;
		if (ok) {
			strcpy(req->id, id);
			return;
		}
	}
	uint64_t n = atomic_fetch_add(&s->next_id, 1);
	snprintf(req->id, sizeof req->id, "%016llx-%06llx", (unsigned long long)s->id_seed, (unsigned long long)n);
}

/* The peer's address for the access log: "192.0.2.7", "2001:db8::1" (an IPv4-mapped IPv6
 * address as its IPv4 form), "" when unknown. */
static void client_address(char *out, size_t n, const struct sockaddr *sa)
{
	out[0] = 0;
	if (!sa)
		return;
	if (sa->sa_family == AF_INET) {
		inet_ntop(AF_INET, &((const struct sockaddr_in *)sa)->sin_addr, out, (socklen_t)n);
	} else if (sa->sa_family == AF_INET6) {
		const struct in6_addr *a = &((const struct sockaddr_in6 *)sa)->sin6_addr;
		if (IN6_IS_ADDR_V4MAPPED(a))
			inet_ntop(AF_INET, &a->s6_addr[12], out, (socklen_t)n);
		else
			inet_ntop(AF_INET6, a, out, (socklen_t)n);
	}
}

static enum MHD_Result access_handler(void *cls, struct MHD_Connection *conn, const char *url,
                                      const char *method, const char *version, const char *upload_data,
                                      size_t *upload_data_size, void **con_cls)
{
	struct srv_server *s = cls;
	struct srv_request *req = *con_cls;
	if (!req) {
		req = calloc(1, sizeof *req);
		if (!req)
			return MHD_NO;
		*con_cls = req;
		atomic_fetch_add(&s->pending, 1);
		req->srv = s;
		req->conn = conn;
		req->t_start = srv_now();
		const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
		req->client = srv_client_key(ci ? ci->client_addr : NULL);
		client_address(req->client_addr, sizeof req->client_addr, ci ? ci->client_addr : NULL);
		snprintf(req->method, sizeof req->method, "%s", method);
		snprintf(req->path, sizeof req->path, "%s", url);
		req->route = route_of(url);
		request_id(req, conn);
		return first_call(req, conn, version);
	}
	switch (req->state) {
	case SRV_REQ_HEADERS:
		if (*upload_data_size) {
			*upload_data_size = 0; /* a body on a GET is ignored */
			return MHD_YES;
		}
		return answer_get(req);
	case SRV_REQ_BODY:
		if (*upload_data_size) {
			size_t n = *upload_data_size;
			*upload_data_size = 0;
			if (!srv_render_body(req, upload_data, n)) {
				/* Over the limit: answer now if libmicrohttpd lets us, else after the body;
				 * a client that keeps sending far past the limit is cut off. */
				if (srv_respond_too_large(req, 0, req->post != NULL) == MHD_YES)
					return MHD_YES;
				if (req->body_discarded > 2 * s->cfg.max_body + (16u << 20))
					return MHD_NO;
			}
			return MHD_YES;
		}
		return srv_render_body_done(req, conn);
	case SRV_REQ_FINISHED:
		return srv_render_answer(req);
	case SRV_REQ_QUEUED:
	case SRV_REQ_ANSWERED:
		*upload_data_size = 0;
		return MHD_YES;
	}
	return MHD_NO;
}

static void completed(void *cls, struct MHD_Connection *conn, void **con_cls, enum MHD_RequestTerminationCode toe)
{
	struct srv_server *s = cls;
	struct srv_request *req = *con_cls;
	(void)conn;
	if (!req)
		return;
	if (toe != MHD_REQUEST_TERMINATED_COMPLETED_OK && req->state != SRV_REQ_ANSWERED)
		srv_log(SRV_LOG_WARN, "request %s %s %s ended before an answer (code %d)", req->id, req->method,
		        req->path, (int)toe);
	/* A queued request is never freed here: its connection is suspended until the worker
	 * finishes, and libmicrohttpd only completes it after resuming. */
	request_free(req);
	*con_cls = NULL;
	atomic_fetch_sub(&s->pending, 1);
}

static void mhd_log(void *cls, const char *fmt, va_list ap)
{
	char msg[512];
	(void)cls;
	vsnprintf(msg, sizeof msg, fmt, ap);
	size_t n = strlen(msg);
	while (n && (msg[n - 1] == '\n' || msg[n - 1] == '\r'))
		msg[--n] = 0;
	srv_log(SRV_LOG_WARN, "libmicrohttpd: %s", msg);
}

/* The bound port (port 0 = the kernel's pick): logged, and written to --port-file. 0 or -1 (logged). */
static int publish_port(struct srv_server *s, const char *host)
{
	const union MHD_DaemonInfo *di = MHD_get_daemon_info(s->daemon, MHD_DAEMON_INFO_BIND_PORT);
	s->port = di ? di->port : 0;
	if (!s->port) {
		di = MHD_get_daemon_info(s->daemon, MHD_DAEMON_INFO_LISTEN_FD);
		struct sockaddr_storage b;
		socklen_t bl = sizeof b;
		if (di && getsockname(di->listen_fd, (struct sockaddr *)&b, &bl) == 0)
			s->port = ntohs(b.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&b)->sin6_port
			                                        : ((struct sockaddr_in *)&b)->sin_port);
	}
	srv_log(SRV_LOG_INFO, "listening on http://%s:%u (port %u)", host, s->port, s->port);
	if (s->cfg.port_file) {
		char tmp[4096];
		snprintf(tmp, sizeof tmp, "%s.tmp", s->cfg.port_file);
		FILE *f = fopen(tmp, "w");
		bool ok = f && fprintf(f, "%u\n", s->port) > 0;
		if (f && fclose(f) != 0)
			ok = false;
		if (!ok || rename(tmp, s->cfg.port_file) != 0) {
			srv_log(SRV_LOG_ERROR, "cannot write the port file '%s': %s", s->cfg.port_file, strerror(errno));
			return -1;
		}
	}
	return 0;
}

/* Whether the listen address is a loopback one: then only loopback names are served by default. */
static bool loopback_addr(const struct sockaddr_storage *ss)
{
	if (ss->ss_family == AF_INET)
		return ntohl(((const struct sockaddr_in *)ss)->sin_addr.s_addr) >> 24 == 127;
	if (ss->ss_family != AF_INET6)
		return false;
	const struct in6_addr *a = &((const struct sockaddr_in6 *)ss)->sin6_addr;
	return IN6_IS_ADDR_LOOPBACK(a) || (IN6_IS_ADDR_V4MAPPED(a) && a->s6_addr[12] == 127);
}

int srv_http_start(struct srv_server *s)
{
	struct sockaddr_storage ss;
	socklen_t sl;
	srv_conn_prepare(&s->cfg);
	if (srv_conn_listen_addr(s->cfg.listen, &ss, &sl) != 0 || srv_conn_share_start(s) != 0)
		return -1;
	char host[128] = "";
	const char *colon = strrchr(s->cfg.listen, ':');
	snprintf(host, sizeof host, "%.*s", (int)(colon - s->cfg.listen), s->cfg.listen);
	struct srv_origin_error oerr;
	struct srv_origin_config oc = { .allowed_hosts = s->cfg.allowed_host, .cors_origins = s->cfg.cors_origin,
	                                .listen_host = host, .loopback = loopback_addr(&ss) };
	if (srv_origin_init(&s->origin, &oc, &oerr) != SRV_ORIGIN_OK) {
		srv_log(SRV_LOG_ERROR, "%s", oerr.msg);
		return -1;
	}
	/* poll(), not epoll: libmicrohttpd 0.9.75 registers sockets edge-triggered and takes a
	 * short recv() as "drained", so the end of a client that closes right after a partial
	 * body (both in one segment) raises no further edge and the connection would sit in
	 * CLOSE_WAIT until --idle-timeout. Level-triggered poll() sees it at once; a scan of
	 * --max-connections descriptors per wake-up costs microseconds. */
	unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG |
	                 MHD_USE_POLL;
	if (ss.ss_family == AF_INET6)
		flags |= MHD_USE_IPv6;
	s->daemon = MHD_start_daemon(flags, 0, srv_conn_accept, s, access_handler, s,
	                             MHD_OPTION_EXTERNAL_LOGGER, mhd_log, s,
	                             MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&ss,
	                             MHD_OPTION_CONNECTION_LIMIT, (unsigned)s->cfg.max_connections,
	                             MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)s->cfg.max_connections_per_ip,
	                             MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)s->cfg.idle_timeout_s,
	                             MHD_OPTION_NOTIFY_CONNECTION, srv_conn_notify, s,
	                             /* 0, not 1: at 1 the library answers a missing Host itself
	                              * (HTML, header block sent twice in 0.9.75); conn.c checks it */
	                             MHD_OPTION_STRICT_FOR_CLIENT, 0,
	                             MHD_OPTION_NOTIFY_COMPLETED, completed, s,
	                             MHD_OPTION_LISTEN_BACKLOG_SIZE, 1024u,
	                             MHD_OPTION_END);
	if (!s->daemon) {
		int e = errno;
		srv_conn_share_stop(s);
		srv_log(SRV_LOG_ERROR, "cannot listen on %s: %s%s", s->cfg.listen, strerror(e),
		        e == EADDRINUSE ? " (another process has that port: choose another --listen port, or port 0 "
		                          "with --port-file for any free one)" : "");
		srv_origin_release(&s->origin);
		return -1;
	}
	if (publish_port(s, host) != 0) {
		srv_http_stop(s);
		return -1;
	}
	return 0;
}

void srv_http_quiesce(struct srv_server *s)
{
	if (!s->daemon)
		return;
	MHD_socket fd = MHD_quiesce_daemon(s->daemon);
	if (fd != MHD_INVALID_SOCKET)
		close(fd);
}

void srv_http_stop(struct srv_server *s)
{
	if (s->daemon)
		MHD_stop_daemon(s->daemon);
	s->daemon = NULL;
	srv_conn_share_stop(s);
	srv_origin_release(&s->origin);
}
