/*
 * server/explain.h — the render plan over HTTP (see explain.c):
 *   POST /v1/explain                the plan of a scene, as JSON (api/explain.schema.json);
 *                                   nothing rendered
 *   POST /v1/render?explain=1       the render, answered as multipart/mixed: the image, then
 *                                   the plan with what each step measured (EXPLAIN ANALYZE);
 *                                   the same with the header `Prefer: explain` (RFC 7240)
 * srv_explain_begin() runs on the polling thread (render_route.c), the rest in a worker.
 */
#ifndef UMBRA_SRV_EXPLAIN_H
#define UMBRA_SRV_EXPLAIN_H

#include <microhttpd.h>
#include <stdbool.h>
#include "api.h"
#include "srv.h"

/* The `explain` query parameter, `Prefer: explain` (req->explain_preferred too: the answer
 * carries Preference-Applied) and, for POST /v1/explain, its Accept: sets req->explain.
 * true when the request is answered already (400, 406: *refused is what the access handler
 * returns). */
bool srv_explain_begin(struct srv_request *req, struct MHD_Connection *conn, const char *accept,
                       enum MHD_Result *refused);
/* POST /v1/explain in a worker: the plan of sc as the answer (200 application/json), or the
 * error making it met (the render's own: 400, 422, 503). parse_ms: the parse's time. */
void srv_explain_answer(struct srv_server *s, struct srv_request *req, const struct api_scene *sc, double parse_ms);
/* POST /v1/render?explain=1: req->out becomes multipart/mixed of the image (bytes, len: taken)
 * and the plan rendered (t: the worker's stages). false when out of memory (bytes freed). */
bool srv_explain_multipart(struct srv_request *req, const struct api_scene *sc, const struct rnd_plan *plan,
                           const struct api_plan_times *t, uint8_t *bytes, size_t len);

#endif
