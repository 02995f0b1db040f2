/*
 * server/renders_route — GET and HEAD /v1/renders/{hash}.{ext}, the form of a render a shared
 * cache can store (POST /v1/renders answers 303 to it: worker.c). On the polling thread:
 *   the image in the result cache (results.h)   -> 200, ETag, Cache-Control immutable
 *   If-None-Match lists "{hash}" (and it is known) -> 304
 *   only its scene kept (the image evicted)     -> the scene queued and rendered again (200)
 *   neither                                     -> 404 problem+json: POST the scene again
 * The URL names its content: the hash is the ETag's (negotiate.h srv_etag_of: the canonical
 * scene, its files, the format, the build and the device), so an answer never changes and may
 * be cached for a year. A scene rendered again whose hash differs (a file under --asset-root
 * changed since) answers 404 too (worker.c), never another image under that name.
 */
#include <microhttpd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "http.h"
#include "metrics.h"
#include "negotiate.h"
#include "results.h"

static enum MHD_Result render_again(struct srv_request *req, struct srv_kept_scene *scene)
{
	struct srv_server *s = req->srv;
	if (!srv_is_ready(s)) {
		srv_kept_release(scene);
		return srv_answer_not_ready(req);
	}
	srv_scene_give(scene, req);
	req->priority = SRV_PRIO_INTERACTIVE;
	srv_metrics_add(s->metrics, SRV_CTR_RESULT_RENDERED_AGAIN, 1);
	return srv_render_enqueue(req);
}

enum MHD_Result srv_result_get(struct srv_request *req, struct MHD_Connection *conn)
{
	struct srv_server *s = req->srv;
	uint64_t hash;
	if (!srv_result_path(req->path, &hash, req->result_ext, sizeof req->result_ext))
		return srv_respond_problem(req, 404, NULL, "", "no route %s: a stored render is /v1/renders/ and 16 hex "
		                           "digits, a dot and its format (the Location of POST /v1/renders)", req->path);
	req->result_hash = hash;
	req->etag_hash = hash;
	srv_etag_format(req->etag, sizeof req->etag, hash);
	const char *inm = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_IF_NONE_MATCH);
	struct srv_result_image img = { 0 };
	struct srv_kept_scene scene = { 0 };
	bool conditional = srv_etag_matches(inm, req->etag);
	enum srv_result_found f = srv_results_get(s->results, hash, req->result_ext, conditional ? NULL : &img, &scene);
	if (f != SRV_RESULT_NONE && conditional) {
		srv_metrics_add(s->metrics, SRV_CTR_NOT_MODIFIED, 1);
		return srv_respond(req, 304, NULL, NULL, 0, NULL);
	}
	switch (f) {
	case SRV_RESULT_IMAGE:
		srv_metrics_add(s->metrics, SRV_CTR_RESULT_HIT, 1);
		snprintf(req->warnings, sizeof req->warnings, "%s", img.warnings ? img.warnings : "");
		free((char *)img.warnings);
		return srv_respond(req, 200, img.mime, img.data, img.len, NULL);
	case SRV_RESULT_SCENE:
		srv_metrics_add(s->metrics, SRV_CTR_RESULT_MISS, 1);
		return render_again(req, &scene);
	case SRV_RESULT_NONE:
		break;
	}
	srv_metrics_add(s->metrics, SRV_CTR_RESULT_MISS, 1);
	return srv_respond_problem(req, 404, NULL, "", "no stored render %s: this server no longer has it (or never "
	                           "rendered it: a restart, another replica, or the result cache's bound, "
	                           "--result-cache-mb); POST the scene to /v1/renders again", req->path);
}
