/*
 * umbrad HTTP: libmicrohttpd callbacks and the routes of contract §5.
 *
 * The access handler runs on libmicrohttpd's polling thread and never blocks on a render:
 *   1st call   (headers only)  framing (conn.c: Host, Content-Length, Transfer-Encoding), route,
 *                              method, Content-Type, Content-Length, readiness; an error
 *                              is answered at once (libmicrohttpd then skips the body, sends no
 *                              "100 Continue" and closes the connection).
 *   next calls (body chunks)   appended and hashed (ETag); past --max-body -> 413.
 *   last call  (body complete) If-None-Match -> 304, else suspend + queue (full -> 503).
 *   after resume               the worker's answer is sent.
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

#include "buf.h"
#include "conn.h"
#include "log.h"
#include "metrics.h"
#include "queue.h"
#include "srv.h"

#define FNV_OFFSET 0xcbf29ce484222325ull
#define FNV_PRIME 0x100000001b3ull

static uint64_t fnv1a(uint64_t h, const void *data, size_t len)
{
	const unsigned char *p = data;
	for (size_t i = 0; i < len; i++) {
		h ^= p[i];
		h *= FNV_PRIME;
	}
	return h;
}

const char *srv_route_name(enum srv_route r)
{
	static const char *const names[SRV_ROUTE_COUNT] = { "/v1/render", "/healthz", "/readyz",
		"/metrics", "/v1/info", "/playground", "other" };
	return (unsigned)r < SRV_ROUTE_COUNT ? names[r] : "other";
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
		{ "/v1/info", SRV_ROUTE_INFO },
	};
	for (size_t i = 0; i < sizeof routes / sizeof routes[0]; i++)
		if (!strcmp(url, routes[i].path))
			return routes[i].r;
	if (srv_playground_path(url))
		return SRV_ROUTE_PLAYGROUND;
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
	free(req->out);
	free(req);
}

/* Queues an answer. body is malloc'd and becomes libmicrohttpd's (freed with free()), or NULL.
 * Logs the request and counts it. Returns what the access handler returns. */
static enum MHD_Result respond(struct srv_request *req, int status, const char *content_type,
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
	if (req->route == SRV_ROUTE_RENDER && (status == 200 || status == 304)) {
		MHD_add_response_header(resp, MHD_HTTP_HEADER_ETAG, req->etag);
		MHD_add_response_header(resp, MHD_HTTP_HEADER_VARY, "Accept");
		if (req->server_timing[0])
			MHD_add_response_header(resp, MHD_HTTP_HEADER_SERVER_TIMING, req->server_timing);
		/* What the image leaves out of what the scene asked for (never silent). */
		if (status == 200 && req->warnings[0]) MHD_add_response_header(resp, "Umbra-Warnings", req->warnings);
	}
	if (req->route != SRV_ROUTE_RENDER || status != 200)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
	if (atomic_load(&s->draining) || req->close_after)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
	enum MHD_Result r = MHD_queue_response(req->conn, (unsigned)status, resp);
	MHD_destroy_response(resp);
	if (r != MHD_YES)
		return r; /* not answered: nothing to log or count */
	req->state = SRV_REQ_ANSWERED;
	double secs = srv_now() - req->t_start;
	srv_metrics_request(s->metrics, req->route, status, secs, len);
	srv_log_request(req->method, req->path, srv_route_name(req->route), status, len, secs * 1000.0, req->id,
	                status >= 400 ? req->problem_detail : NULL, status >= 400 ? req->problem_pointer : NULL);
	return r;
}

static enum MHD_Result respond_problem(struct srv_request *req, int status, const char *allow,
                                       const char *pointer, const char *fmt, ...)
	__attribute__((format(printf, 5, 6)));

void srv_request_note_problem(struct srv_request *req, const struct api_problem *p)
{
	snprintf(req->problem_pointer, sizeof req->problem_pointer, "%s", p->pointer);
	snprintf(req->problem_detail, sizeof req->problem_detail, "%s", p->detail);
}

static enum MHD_Result respond_problem(struct srv_request *req, int status, const char *allow,
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
	return respond(req, status, "application/problem+json", json, json ? strlen(json) : 0, allow);
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
	return respond(req, status, "application/problem+json", json, json ? strlen(json) : 0, NULL);
}

static enum MHD_Result respond_text(struct srv_request *req, int status, const char *ctype, const char *text)
{
	char *body = strdup(text);
	return respond(req, status, ctype, body, body ? strlen(body) : 0, NULL);
}

/* ---- GET routes ---- */

static enum MHD_Result answer_info(struct srv_request *req)
{
	struct srv_server *s = req->srv;
	struct srv_buf b = { 0 };
	const struct srv_config *c = &s->cfg;
	struct rnd_info info;
	pthread_rwlock_rdlock(&s->ctx_lock);
	info = s->info;
	pthread_rwlock_unlock(&s->ctx_lock);

	srv_buf_puts(&b, "{\"name\":\"umbrad\",\"version\":");
	srv_buf_json_str(&b, UMBRA_VERSION);
	srv_buf_puts(&b, ",\"contract\":\"scene-v1\",\"device\":");
	srv_buf_json_str(&b, info.device_name);
	srv_buf_puts(&b, ",\"driver\":");
	srv_buf_json_str(&b, info.driver_name);
	srv_buf_puts(&b, ",\"driver_info\":");
	srv_buf_json_str(&b, info.driver_info);
	srv_buf_printf(&b, ",\"vulkan_api\":\"%u.%u.%u\",\"cpu\":%s", (info.api_version >> 22) & 0x7fu,
	               (info.api_version >> 12) & 0x3ffu, info.api_version & 0xfffu, info.is_cpu ? "true" : "false");
	srv_buf_printf(&b, ",\"limits\":{\"max_body\":%llu,\"max_pixels\":%llu,\"max_triangles\":%llu,"
	                   "\"max_lights\":%u,\"max_shadow_resolution\":%u,\"max_dimension\":%u,"
	                   "\"device_max_shadow_resolution\":%u,\"deadline_ms\":%u,\"queue\":%u,\"workers\":%u,"
	                   "\"max_memory\":%llu,\"device_max_allocation\":%llu,\"import_timeout_ms\":%u,\"import_memory\":%llu,"
	                   "\"max_textures\":%u,\"device_max_textures\":%u}",
	               (unsigned long long)c->max_body, (unsigned long long)c->limits.max_pixels,
	               (unsigned long long)c->limits.max_triangles, c->limits.max_lights,
	               c->limits.max_shadow_resolution, info.max_image_dimension < 8192 ? info.max_image_dimension : 8192,
	               info.max_shadow_resolution, c->deadline_ms, c->queue, c->workers,
	               (unsigned long long)c->max_memory, (unsigned long long)info.max_allocation, c->limits.import_timeout_ms,
	               (unsigned long long)c->limits.import_memory, info.max_textures, info.device_max_textures);
	srv_buf_puts(&b, ",\"filters\":[\"hard\",\"pcf\",\"pcss\",\"vsm\",\"evsm\"]"
	                 ",\"formats\":[\"png\",\"exr\"],\"media_types\":[\"image/png\",\"image/x-exr\"]"
	                 ",\"priorities\":[\"interactive\",\"bulk\"]}\n");
	size_t len;
	char *json = srv_buf_detach(&b, &len);
	if (!json)
		return MHD_NO;
	return respond(req, 200, "application/json", json, len, NULL);
}

static enum MHD_Result answer_metrics(struct srv_request *req)
{
	size_t len;
	char *text = srv_metrics_text(req->srv, &len);
	if (!text)
		return MHD_NO;
	return respond(req, 200, "text/plain; version=0.0.4; charset=utf-8", text, len, NULL);
}

static bool is_ready(const struct srv_server *s)
{
	return atomic_load(&s->ready) && !atomic_load(&s->draining);
}

static enum MHD_Result answer_not_ready(struct srv_request *req)
{
	struct srv_server *s = req->srv;
	if (atomic_load(&s->draining))
		return respond_problem(req, 503, NULL, "", "the server is shutting down");
	return respond_problem(req, 503, NULL, "", "the renderer is not ready yet (device start-up and pipeline warm-up)");
}

/* ---- POST /v1/render ---- */

/* Content-Type must be application/json (parameters such as charset allowed) or a +json type. */
static bool json_content_type(const char *ct)
{
	if (!ct)
		return false;
	while (*ct == ' ' || *ct == '\t')
		ct++;
	size_t n = strcspn(ct, "; \t");
	if (n == 16 && !strncasecmp(ct, "application/json", 16))
		return true;
	return n > 17 && !strncasecmp(ct, "application/", 12) && !strncasecmp(ct + n - 5, "+json", 5);
}

static bool multipart_content_type(const char *ct)
{
	if (!ct)
		return false;
	while (*ct == ' ' || *ct == '\t')
		ct++;
	return !strncasecmp(ct, "multipart/form-data", 19) && strchr("; \t", ct[19]);
}

/* Grows a byte buffer to hold `need` bytes plus a NUL. */
static bool grow(uint8_t **data, size_t *cap, size_t need)
{
	if (need + 1 <= *cap)
		return true;
	size_t c = *cap ? *cap : 4096;
	while (c < need + 1)
		c *= 2;
	uint8_t *p = realloc(*data, c);
	if (!p)
		return false;
	*data = p;
	*cap = c;
	return true;
}

#define MAX_PARTS 64

/* libmicrohttpd's multipart parser hands over each part's bytes in order. */
static enum MHD_Result part_data(void *cls, enum MHD_ValueKind kind, const char *key, const char *filename,
                                 const char *content_type, const char *transfer_encoding, const char *data,
                                 uint64_t off, size_t size)
{
	struct srv_request *req = cls;
	(void)kind; (void)filename; (void)content_type; (void)transfer_encoding;
	if (!key)
		return MHD_YES;
	struct srv_part *part = NULL;
	for (size_t i = 0; i < req->part_count; i++)
		if (!strcmp(req->parts[i].name, key))
			part = &req->parts[i];
	if (part && off == 0 && part->len) {
		req->part_error = "two parts have the same name";
		return MHD_NO;
	}
	if (!part) {
		if (req->part_count == MAX_PARTS) {
			req->part_error = "more than 64 parts";
			return MHD_NO;
		}
		struct srv_part *parts = realloc(req->parts, (req->part_count + 1) * sizeof *parts);
		if (!parts)
			return MHD_NO;
		req->parts = parts;
		part = &parts[req->part_count];
		*part = (struct srv_part){ .name = strdup(key) };
		if (!part->name)
			return MHD_NO;
		req->part_count++;
	}
	if (!grow(&part->data, &part->cap, part->len + size))
		return MHD_NO;
	memcpy(part->data + part->len, data, size);
	part->len += size;
	part->data[part->len] = 0;
	return MHD_YES;
}

/* Accept: 1 when image/x-exr is preferred (higher q) over image/png, 0 for PNG (also without
 * the header; a tie keeps PNG, the default), -1 when the header accepts neither (q = 0 or not
 * named, no wildcard): that request is answered 406. Wildcards count with their q for both. */
static int accept_choice(const char *accept)
{
	if (!accept || !*accept)
		return 0;
	double q_png = -1, q_exr = -1, q_wild = -1;
	bool spec_png = false, spec_exr = false;
	const char *p = accept;
	while (*p) {
		while (*p == ' ' || *p == ',')
			p++;
		if (!*p)
			break;
		size_t item = strcspn(p, ",");
		char buf[128];
		size_t n = item < sizeof buf - 1 ? item : sizeof buf - 1;
		memcpy(buf, p, n);
		buf[n] = 0;
		p += item;
		double q = 1;
		char *semi = strchr(buf, ';');
		if (semi) {
			*semi = 0;
			char *qs = strstr(semi + 1, "q=");
			if (qs)
				q = strtod(qs + 2, NULL);
		}
		char *end = buf + strlen(buf);
		while (end > buf && (end[-1] == ' ' || end[-1] == '\t'))
			*--end = 0;
		if (!strcasecmp(buf, "image/png")) {
			q_png = q;
			spec_png = true;
		} else if (!strcasecmp(buf, "image/x-exr")) {
			q_exr = q;
			spec_exr = true;
		} else if (!strcasecmp(buf, "image/*") || !strcasecmp(buf, "*/*")) {
			if (q > q_wild)
				q_wild = q;
		}
	}
	if (!spec_png)
		q_png = q_wild;
	if (!spec_exr)
		q_exr = q_wild;
	if (q_png <= 0 && q_exr <= 0)
		return -1;
	return q_exr > 0 && q_exr > q_png ? 1 : 0;
}

/* Called by queue_push() under the queue lock, once the push is certain (see queue.h). */
static void suspend_before_push(struct srv_request *req)
{
	req->state = SRV_REQ_QUEUED;
	req->t_queued = srv_now();
	MHD_suspend_connection(req->conn);
}

bool srv_etag_matches(const char *inm, const char *etag)
{
	if (!inm)
		return false;
	size_t el = strlen(etag);
	const char *p = inm;
	while (*p) {
		while (*p == ' ' || *p == ',' || *p == '\t')
			p++;
		if (!*p)
			break;
		/* "*" is not a match: a render always has a representation to make, and an
		 * unconditional 304 would hide it. */
		if (!strncmp(p, "W/", 2))
			p += 2;
		size_t n = strcspn(p, ", \t");
		if (n == el && !strncmp(p, etag, el))
			return true;
		p += n;
	}
	return false;
}

static enum MHD_Result render_begin(struct srv_request *req, struct MHD_Connection *conn)
{
	struct srv_server *s = req->srv;
	if (!is_ready(s))
		return answer_not_ready(req);
	const char *ct = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
	bool multipart = multipart_content_type(ct);
	if (!multipart && !json_content_type(ct))
		return respond_problem(req, 415, NULL, "", "Content-Type must be application/json or multipart/form-data, not '%s'",
		                       ct ? ct : "(none)");
	const char *ce = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_ENCODING);
	if (ce && strcasecmp(ce, "identity") != 0)
		return respond_problem(req, 415, NULL, "", "Content-Encoding '%s' is not supported", ce);
	const char *prio = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "X-Priority");
	if (!prio || !strcasecmp(prio, "interactive"))
		req->priority = SRV_PRIO_INTERACTIVE;
	else if (!strcasecmp(prio, "bulk"))
		req->priority = SRV_PRIO_BULK;
	else
		return respond_problem(req, 400, NULL, "", "X-Priority must be interactive or bulk, not '%s'", prio);
	const char *cl = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
	if (cl) {
		char *end;
		errno = 0;
		unsigned long long n = strtoull(cl, &end, 10);
		if (!errno && end != cl && n > s->cfg.max_body)
			return respond_problem(req, 413, NULL, "", "the body of %llu bytes is over the limit of %llu bytes",
			                       n, (unsigned long long)s->cfg.max_body);
		if (!errno && end != cl && n > 0 && !multipart) {
			req->body = malloc((size_t)n + 1);
			if (!req->body)
				return respond_problem(req, 503, NULL, "", "out of memory for a body of %llu bytes", n);
			req->body_cap = (size_t)n + 1;
		}
	}
	if (multipart) {
		req->post = MHD_create_post_processor(conn, 64 * 1024, part_data, req);
		if (!req->post)
			return respond_problem(req, 400, NULL, "", "multipart/form-data without a usable boundary");
	}
	const char *accept = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_ACCEPT);
	int choice = accept_choice(accept);
	if (choice < 0)
		return respond_problem(req, 406, NULL, "", "this server answers image/png or image/x-exr (or a problem+json "
		                       "document); Accept: %.200s names neither", accept);
	req->want_exr = choice == 1;
	req->body_hash = FNV_OFFSET;
	req->state = SRV_REQ_BODY;
	return MHD_YES;
}

/* A chunk of body. Returns false when over the limit. */
static bool render_body(struct srv_request *req, const char *data, size_t size)
{
	struct srv_server *s = req->srv;
	if (req->body_discarded || req->body_received + size > s->cfg.max_body) {
		if (!req->body_discarded)
			srv_request_drop_body(req);
		req->body_discarded += req->body_received + size;
		req->body_received = 0;
		return false;
	}
	req->body_received += size;
	req->body_hash = fnv1a(req->body_hash, data, size);
	if (req->body_oom)
		return true; /* the rest is read and dropped; answered 503 at the end */
	if (req->post) {
		if (!req->part_error && MHD_post_process(req->post, data, size) != MHD_YES && !req->part_error)
			req->part_error = "malformed multipart/form-data body";
		return true;
	}
	if (req->body_len + size + 1 > req->body_cap) {
		size_t cap = req->body_cap ? req->body_cap : 4096;
		while (cap < req->body_len + size + 1)
			cap *= 2;
		if (cap > s->cfg.max_body + 1)
			cap = s->cfg.max_body + 1;
		char *p = realloc(req->body, cap);
		if (!p) {
			srv_request_drop_body(req);
			req->body_oom = true;
			return true;
		}
		req->body = p;
		req->body_cap = cap;
	}
	memcpy(req->body + req->body_len, data, size);
	req->body_len += size;
	return true;
}

static enum MHD_Result render_body_done(struct srv_request *req, struct MHD_Connection *conn)
{
	struct srv_server *s = req->srv;
	if (req->body_discarded)
		return respond_problem(req, 413, NULL, "", "the body is over the limit of %llu bytes",
		                       (unsigned long long)s->cfg.max_body);
	if (req->body_oom)
		return respond_problem(req, 503, NULL, "", "out of memory while reading the body");
	if (req->post) {
		if (MHD_destroy_post_processor(req->post) != MHD_YES && !req->part_error)
			req->part_error = "truncated multipart/form-data body";
		req->post = NULL;
		if (req->part_error)
			return respond_problem(req, 400, NULL, "", "%s", req->part_error);
		/* The `scene` part is the document; the others stay as named parts. */
		for (size_t i = 0; i < req->part_count; i++) {
			if (strcmp(req->parts[i].name, "scene") != 0)
				continue;
			req->body = (char *)req->parts[i].data;
			req->body_len = req->parts[i].len;
			req->body_cap = req->parts[i].cap;
			free(req->parts[i].name);
			req->parts[i] = req->parts[--req->part_count];
			break;
		}
		if (!req->body)
			return respond_problem(req, 400, NULL, "", "the multipart/form-data request has no `scene` part");
	}
	if (!req->body_len)
		return respond_problem(req, 400, NULL, "", "the request has no body: a scene document is required");
	req->body[req->body_len] = 0;

	/* ETag: the body, the format negotiation, the build and the device. */
	uint64_t h = req->body_hash;
	h = fnv1a(h, req->want_exr ? "\0exr" : "\0png", 4);
	h = fnv1a(h, UMBRA_VERSION, strlen(UMBRA_VERSION));
	pthread_rwlock_rdlock(&s->ctx_lock);
	h = fnv1a(h, s->info.device_name, strlen(s->info.device_name));
	h = fnv1a(h, s->info.driver_info, strlen(s->info.driver_info));
	pthread_rwlock_unlock(&s->ctx_lock);
	snprintf(req->etag, sizeof req->etag, "\"%016llx\"", (unsigned long long)h);
	/* A scene that reads models from --asset-root may change without its body changing: its
	 * ETag is only known after parsing, so it never gets an early 304. */
	bool reads_assets = memmem(req->body, req->body_len, "\"path\"", 6) != NULL;
	const char *inm = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_IF_NONE_MATCH);
	if (reads_assets && inm) snprintf(req->if_none_match, sizeof req->if_none_match, "%s", inm);
	if (!reads_assets && srv_etag_matches(inm, req->etag)) {
		srv_metrics_add(s->metrics, SRV_CTR_NOT_MODIFIED, 1);
		return respond(req, 304, NULL, NULL, 0, NULL);
	}

	switch (srv_queue_push(s->queue, req, suspend_before_push)) {
	case SRV_PUSH_OK:
		return MHD_YES;
	case SRV_PUSH_FULL:
		srv_metrics_add(s->metrics, SRV_CTR_QUEUE_REJECTED, 1);
		return respond_problem(req, 503, NULL, "", "the render queue is full (%u waiting)", srv_queue_capacity(s->queue));
	case SRV_PUSH_CLOSED:
		break;
	}
	return respond_problem(req, 503, NULL, "", "the server is shutting down");
}

void srv_request_finish(struct srv_request *req)
{
	req->state = SRV_REQ_FINISHED;
	MHD_resume_connection(req->conn);
}

static enum MHD_Result render_answer(struct srv_request *req)
{
	uint8_t *out = req->out;
	req->out = NULL;
	if (!out && req->status == 200)
		req->status = 500;
	return respond(req, req->status ? req->status : 500, out ? req->content_type : NULL, out,
	               out ? req->out_len : 0, NULL);
}

/* ---- dispatch ---- */

static const char *allow_of(enum srv_route r)
{
	return r == SRV_ROUTE_RENDER ? "POST" : "GET, HEAD";
}

static enum MHD_Result first_call(struct srv_request *req, struct MHD_Connection *conn, const char *version)
{
	bool get = !strcmp(req->method, "GET") || !strcmp(req->method, "HEAD");
	int status;
	const char *framing = srv_conn_framing_error(conn, version, &status);
	if (framing)
		return respond_framing(req, status, framing);
	srv_conn_request_begins(&req->srv->cfg, conn);
	if (req->route == SRV_ROUTE_OTHER)
		return respond_problem(req, 404, NULL, "", "no route %s", req->path);
	if (req->route == SRV_ROUTE_RENDER ? strcmp(req->method, "POST") != 0 : !get)
		return respond_problem(req, 405, allow_of(req->route), "", "%s is not allowed on %s; allowed: %s",
		                       req->method, srv_route_name(req->route), allow_of(req->route));
	if (req->route == SRV_ROUTE_RENDER)
		return render_begin(req, conn);
	/* GET routes answer on the next call, once libmicrohttpd has the whole request (an
	 * answer queued on the first call makes it close the connection). */
	req->state = SRV_REQ_HEADERS;
	return MHD_YES;
}

static enum MHD_Result answer_get(struct srv_request *req)
{
	struct srv_server *s = req->srv;
	switch (req->route) {
	case SRV_ROUTE_HEALTHZ:
		return respond_text(req, 200, "text/plain; charset=utf-8", "ok\n");
	case SRV_ROUTE_READYZ:
		if (!is_ready(s))
			return answer_not_ready(req);
		return respond_text(req, 200, "text/plain; charset=utf-8", "ready\n");
	case SRV_ROUTE_METRICS:
		return answer_metrics(req);
	case SRV_ROUTE_INFO:
		if (!atomic_load(&s->ready))
			return answer_not_ready(req);
		return answer_info(req);
	case SRV_ROUTE_PLAYGROUND: {
		size_t len = 0;
		if (s->cfg.no_playground)
			return respond_problem(req, 404, NULL, "", "no route %s (--no-playground)", req->path);
		char *page = srv_playground_page(&len);
		if (!page)
			return respond_problem(req, 503, NULL, "", "out of memory for the playground page");
		return respond(req, 200, "text/html; charset=utf-8", page, len, NULL);
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
			if (!render_body(req, upload_data, n)) {
				/* Over the limit: answer now if libmicrohttpd lets us, else after the body;
				 * a client that keeps sending far past the limit is cut off. */
				if (respond_problem(req, 413, NULL, "", "the body is over the limit of %llu bytes",
				                    (unsigned long long)s->cfg.max_body) == MHD_YES)
					return MHD_YES;
				if (req->body_discarded > 2 * s->cfg.max_body + (16u << 20))
					return MHD_NO;
			}
			return MHD_YES;
		}
		return render_body_done(req, conn);
	case SRV_REQ_FINISHED:
		return render_answer(req);
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

int srv_http_start(struct srv_server *s)
{
	struct sockaddr_storage ss;
	socklen_t sl;
	srv_conn_prepare(&s->cfg);
	if (srv_conn_listen_addr(s->cfg.listen, &ss, &sl) != 0)
		return -1;
	/* poll(), not epoll: libmicrohttpd 0.9.75 registers sockets edge-triggered and takes a
	 * short recv() as "drained", so the end of a client that closes right after a partial
	 * body (both in one segment) raises no further edge and the connection would sit in
	 * CLOSE_WAIT until --idle-timeout. Level-triggered poll() sees it at once; a scan of
	 * --max-connections descriptors per wake-up costs microseconds. */
	unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG |
	                 MHD_USE_POLL;
	if (ss.ss_family == AF_INET6)
		flags |= MHD_USE_IPv6;
	s->daemon = MHD_start_daemon(flags, 0, NULL, NULL, access_handler, s,
	                             MHD_OPTION_EXTERNAL_LOGGER, mhd_log, s,
	                             MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&ss,
	                             MHD_OPTION_CONNECTION_LIMIT, (unsigned)s->cfg.max_connections,
	                             MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)s->cfg.max_connections_per_ip,
	                             MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)s->cfg.idle_timeout_s,
	                             MHD_OPTION_NOTIFY_CONNECTION, srv_conn_notify, &s->cfg,
	                             /* 0, not 1: at 1 the library answers a missing Host itself
	                              * (HTML, header block sent twice in 0.9.75); conn.c checks it */
	                             MHD_OPTION_STRICT_FOR_CLIENT, 0,
	                             MHD_OPTION_NOTIFY_COMPLETED, completed, s,
	                             MHD_OPTION_LISTEN_BACKLOG_SIZE, 1024u,
	                             MHD_OPTION_END);
	if (!s->daemon) {
		int e = errno;
		srv_log(SRV_LOG_ERROR, "cannot listen on %s: %s%s", s->cfg.listen, strerror(e),
		        e == EADDRINUSE ? " (another process has that port: choose another --listen port, or port 0 "
		                          "with --port-file for any free one)" : "");
		return -1;
	}
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
	char host[128] = "";
	const char *colon = strrchr(s->cfg.listen, ':');
	snprintf(host, sizeof host, "%.*s", (int)(colon - s->cfg.listen), s->cfg.listen);
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
}
