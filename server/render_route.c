/*
 * server/render_route — POST /v1/render and POST /v1/renders on the polling thread (see http.c
 * for the call order): the checks on its headers (readiness, Content-Type, Content-Encoding,
 * X-Priority, Content-Length, Accept), the body in chunks (a JSON document, or
 * multipart/form-data whose `scene` part is the document and whose other parts are named model
 * files), the hand-over to the queue, and the answer once a worker has finished. The ETag and
 * If-None-Match (412) are the worker's: they depend on the parsed scene (worker.c).
 * Negotiation rules live in negotiate.c; this file only applies them to libmicrohttpd's request.
 */
#include <errno.h>
#include <microhttpd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "explain.h"
#include "http.h"
#include "metrics.h"
#include "negotiate.h"
#include "queue.h"

/* A part's buffer past this is sized to the whole body at once (below). */
#define PART_PRESIZE (4u << 20)

/* Grows a part's buffer (len bytes used) to hold `need` bytes plus a NUL: doubling, but once
 * past PART_PRESIZE straight to the body's length (`whole`: Content-Length, the most a part can
 * hold; 0 when unknown), a fresh buffer hinted for huge pages before its first write
 * (api_mem_huge). A 50 MB model part was copied by every doubling and faulted in 4 KiB at a
 * time as it arrived. */
static bool grow(uint8_t **data, size_t len, size_t *cap, size_t need, size_t whole)
{
	if (need + 1 <= *cap)
		return true;
	size_t c = *cap ? *cap : 4096;
	while (c < need + 1)
		c *= 2;
	if (c < PART_PRESIZE) {
		uint8_t *p = realloc(*data, c);
		if (!p)
			return false;
		*data = p;
		*cap = c;
		return true;
	}
	if (whole + 1 > c)
		c = whole + 1;
	uint8_t *p = malloc(c);
	if (!p)
		return false;
	api_mem_huge(p, c);
	if (len)
		memcpy(p, *data, len);
	free(*data);
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
	if (!grow(&part->data, part->len, &part->cap, part->len + size, req->content_length))
		return MHD_NO;
	memcpy(part->data + part->len, data, size);
	part->len += size;
	part->data[part->len] = 0;
	return MHD_YES;
}

/* Called by queue_push() under the queue lock, once the push is certain (see queue.h). */
static void suspend_before_push(struct srv_request *req)
{
	req->state = SRV_REQ_QUEUED;
	req->t_queued = srv_now();
	MHD_suspend_connection(req->conn);
}

enum MHD_Result srv_render_begin(struct srv_request *req, struct MHD_Connection *conn)
{
	struct srv_server *s = req->srv;
	if (!srv_is_ready(s))
		return srv_answer_not_ready(req);
	const char *ct = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
	bool multipart = srv_multipart_content_type(ct);
	if (!multipart && !srv_json_content_type(ct))
		return srv_respond_problem(req, 415, NULL, "", "Content-Type must be application/json or multipart/form-data, not '%s'",
		                       ct ? ct : "(none)");
	const char *ce = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_ENCODING);
	if (ce && strcasecmp(ce, "identity") != 0)
		return srv_respond_problem(req, 415, NULL, "", "Content-Encoding '%s' is not supported", ce);
	const char *prio = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "X-Priority");
	if (!prio || !strcasecmp(prio, "interactive"))
		req->priority = SRV_PRIO_INTERACTIVE;
	else if (!strcasecmp(prio, "bulk"))
		req->priority = SRV_PRIO_BULK;
	else
		return srv_respond_problem(req, 400, NULL, "", "X-Priority must be interactive or bulk, not '%s'", prio);
	const char *cl = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
	if (cl) {
		char *end;
		errno = 0;
		unsigned long long n = strtoull(cl, &end, 10);
		if (!errno && end != cl && n > s->cfg.max_body) return srv_respond_too_large(req, n, multipart);
		if (!errno && end != cl)
			req->content_length = (size_t)n;
		if (!errno && end != cl && n > 0 && !multipart) {
			req->body = malloc((size_t)n + 1);
			if (!req->body)
				return srv_respond_problem(req, 503, NULL, "", "out of memory for a body of %llu bytes", n);
			api_mem_huge(req->body, (size_t)n + 1);
			req->body_cap = (size_t)n + 1;
		}
	}
	if (multipart) {
		req->post = MHD_create_post_processor(conn, 64 * 1024, part_data, req);
		if (!req->post)
			return srv_respond_problem(req, 400, NULL, "", "multipart/form-data without a usable boundary");
	}
	const char *accept = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_ACCEPT);
	enum MHD_Result refused;
	if (srv_explain_begin(req, conn, accept, &refused))
		return refused;
	enum srv_accept choice = srv_accept_choice(accept);
	/* POST /v1/explain answers JSON (srv_explain_begin checked its Accept); a render with its
	 * plan answers multipart/mixed, whose image part is negotiated as ever (PNG when Accept
	 * names none: multipart/mixed alone). */
	if (req->route == SRV_ROUTE_EXPLAIN || (req->explain && choice == SRV_ACCEPT_NONE))
		choice = SRV_ACCEPT_PNG;
	if (choice == SRV_ACCEPT_NONE)
		return srv_respond_problem(req, 406, NULL, "", "this server answers image/png, image/webp, image/avif or image/x-exr (or a "
		                       "problem+json document); Accept: %.200s names none of them", accept);
	req->want = choice;
	req->state = SRV_REQ_BODY;
	return MHD_YES;
}

enum MHD_Result srv_respond_too_large(struct srv_request *req, unsigned long long n, bool multipart)
{
	const struct srv_server *s = req->srv;
	char size[64] = "";
	if (n) snprintf(size, sizeof size, " of %llu bytes", n);
	/* What makes a big model fit: its raw bytes as a part (base64 in JSON is 4/3 of them), or
	 * no upload at all by path. */
	const char *how = multipart ? (s->cfg.asset_root ? "; a large model can be named by \"path\" under this server's "
	                                                   "asset root instead of uploaded" : "")
	                  : s->cfg.asset_root ? "; send a large model as a multipart/form-data part (its raw bytes, "
	                                        "not base64: 3/4 of the size) or name it by \"path\" under this server's "
	                                        "asset root"
	                  : "; send a large model as a multipart/form-data part (its raw bytes, not base64: 3/4 of the "
	                    "size)";
	return srv_respond_problem(req, 413, NULL, "", "the body%s is over this server's limit of %llu bytes "
	                       "(--max-body)%s", size, (unsigned long long)s->cfg.max_body, how);
}

/* A chunk of body. Returns false when over the limit. */
bool srv_render_body(struct srv_request *req, const char *data, size_t size)
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

enum MHD_Result srv_render_body_done(struct srv_request *req, struct MHD_Connection *conn)
{
	if (req->body_discarded) return srv_respond_too_large(req, 0, req->post != NULL);
	if (req->body_oom)
		return srv_respond_problem(req, 503, NULL, "", "out of memory while reading the body");
	if (req->post) {
		if (MHD_destroy_post_processor(req->post) != MHD_YES && !req->part_error)
			req->part_error = "truncated multipart/form-data body";
		req->post = NULL;
		if (req->part_error)
			return srv_respond_problem(req, 400, NULL, "", "%s", req->part_error);
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
			return srv_respond_problem(req, 400, NULL, "", "the multipart/form-data request has no `scene` part");
	}
	if (!req->body_len)
		return srv_respond_problem(req, 400, NULL, "", "the request has no body: a scene document is required");
	req->body[req->body_len] = 0;

	/* The ETag is the parsed scene's (worker.c): If-None-Match is checked there. */
	const char *inm = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_IF_NONE_MATCH);
	if (inm) snprintf(req->if_none_match, sizeof req->if_none_match, "%s", inm);
	return srv_render_enqueue(req);
}

enum MHD_Result srv_render_enqueue(struct srv_request *req)
{
	struct srv_server *s = req->srv;
	switch (srv_queue_push(s->queue, req, suspend_before_push)) {
	case SRV_PUSH_OK:
		return MHD_YES;
	case SRV_PUSH_FULL:
		srv_metrics_add(s->metrics, SRV_CTR_QUEUE_REJECTED, 1);
		return srv_respond_problem(req, 503, NULL, "", "the render queue is full (%u waiting)", srv_queue_capacity(s->queue));
	case SRV_PUSH_CLOSED:
		break;
	}
	return srv_respond_problem(req, 503, NULL, "", "the server is shutting down");
}

void srv_request_finish(struct srv_request *req)
{
	req->state = SRV_REQ_FINISHED;
	MHD_resume_connection(req->conn);
}

enum MHD_Result srv_render_answer(struct srv_request *req)
{
	uint8_t *out = req->out;
	req->out = NULL;
	if (!out && req->status == 200)
		req->status = 500;
	return srv_respond(req, req->status ? req->status : 500, out ? req->content_type : NULL, out,
	               out ? req->out_len : 0, NULL);
}
