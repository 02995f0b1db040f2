/*
 * server/http.h — what the HTTP modules share (http.c: dispatch and answers; render_route.c:
 * POST /v1/render; origin_http.c: Host, Origin, CORS and the browser headers). Everything here runs on libmicrohttpd's polling thread, except
 * srv_request_finish() (srv.h), which a worker calls.
 *
 * Answers: srv_respond() queues one (body: malloc'd, becomes libmicrohttpd's, or NULL), sets
 * the common headers (X-Request-Id, Allow, Retry-After, ETag/Vary/Server-Timing for a render,
 * Cache-Control, Connection; origin_http.c's browser headers), logs and counts the request. It
 * returns what the access handler returns.
 */
#ifndef UMBRA_SRV_HTTP_H
#define UMBRA_SRV_HTTP_H

#include <microhttpd.h>
#include <stdbool.h>
#include <stddef.h>

#include "srv.h"

/* Cache-Control of render answers: POST answers (--cache-control overrides it), and the
 * content-addressed GET form (its name changes with the scene, the build and the device). */
#define SRV_RENDER_CACHE_CONTROL "no-cache"
#define SRV_RESULT_CACHE_CONTROL "public, max-age=31536000, immutable"

enum MHD_Result srv_respond(struct srv_request *req, int status, const char *content_type, void *body, size_t len,
                            const char *allow);
/* A problem+json answer with a printf-style detail at `pointer`. */
enum MHD_Result srv_respond_problem(struct srv_request *req, int status, const char *allow, const char *pointer,
                                    const char *fmt, ...) __attribute__((format(printf, 5, 6)));
/* Ready: the renderer is warmed up and the server is not draining. */
bool srv_is_ready(const struct srv_server *s);
/* 503 saying why the server is not ready (starting up, or shutting down). */
enum MHD_Result srv_answer_not_ready(struct srv_request *req);

/* The methods a route allows ("POST", "GET, HEAD"). */
const char *srv_allow_of(enum srv_route r);

/* origin_http.c: the Host and Origin rules (origin.h) applied to libmicrohttpd's request.
 * srv_origin_refuses() runs on the first call: true when the request is refused (403/421),
 * *answer then being what the access handler returns; an allowed cross-origin caller is kept
 * in req->cors_origin. srv_origin_headers() adds what every answer tells a browser. */
bool srv_origin_refuses(struct srv_request *req, struct MHD_Connection *conn, enum MHD_Result *answer);
void srv_origin_headers(struct srv_request *req, struct MHD_Response *resp, int status);

/* render_route.c, in the order the access handler calls them. */
enum MHD_Result srv_render_begin(struct srv_request *req, struct MHD_Connection *conn);
bool srv_render_body(struct srv_request *req, const char *data, size_t size);   /* false: over --max-body */
enum MHD_Result srv_render_body_done(struct srv_request *req, struct MHD_Connection *conn);
/* The 413 for a body over --max-body (n: its Content-Length, 0 = not known), saying how a
 * large model fits: a multipart part instead of base64, or `path` where there is an asset root. */
enum MHD_Result srv_respond_too_large(struct srv_request *req, unsigned long long n, bool multipart);
enum MHD_Result srv_render_answer(struct srv_request *req);
/* Hands a request with its body (req->body, parts) to the queue: MHD_YES once queued (the
 * connection suspended), else the 503 answered. */
enum MHD_Result srv_render_enqueue(struct srv_request *req);

/* renders_route.c: GET/HEAD /v1/renders/{hash}.{ext}, on the request's last call. */
enum MHD_Result srv_result_get(struct srv_request *req, struct MHD_Connection *conn);

#endif
