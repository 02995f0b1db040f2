/*
 * server/explain.c — the render plan over HTTP (see explain.h).
 *
 * Why multipart/mixed for a render with its plan: the answer stays the image HTTP clients
 * expect (its own part, its own Content-Type, the same bytes as without `explain`), and the
 * plan travels beside it as JSON, in one round trip, measured on the very render that made
 * the image; RFC 2046's multipart is what mail and HTTP libraries already split (Python's
 * email parser, curl's output saved as is, a few lines in a browser). A JSON answer with the
 * image in base64 would grow it by a third and hide it from image tools; a header cannot hold
 * a plan. The answer is not cacheable (Cache-Control: no-store, no ETag): it says what the
 * shadow cache held and how long each step took.
 *
 * Why `Prefer: explain` as the header form (RFC 7240): asking for more of an answer without
 * changing what the resource is, is what Prefer is for (`return=representation`,
 * `respond-async`); a preference a server or a cache in between does not know is ignored, not
 * refused, and the answer says which it honoured (`Preference-Applied: explain`), so a client
 * checks that header rather than guessing from the Content-Type; render answers say
 * `Vary: Accept, Prefer`. A private `Umbra-Explain: 1` would need all three conventions made
 * up again. Being a preference, it is lenient where `?explain=` is strict: elsewhere than
 * POST /v1/render, or with a value it does not know, it is ignored.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "explain.h"
#include "http.h"
#include "log.h"

/* One Prefer header's preferences (comma-separated, each `token[=value][;param...]`): is one of
 * them `explain` (no value, or 1, true, analyze; quoted or not)? */
static enum MHD_Result prefer_header(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
	(void)kind;
	bool *found = cls;
	if (strcasecmp(key, "Prefer") != 0 || !value) return MHD_YES;
	for (const char *p = value; *p;) {
		p += strspn(p, " \t,");
		size_t n = strcspn(p, "=;, \t");
		if (n == 7 && !strncasecmp(p, "explain", 7)) {
			const char *v = p + n;
			v += strspn(v, " \t");
			if (*v != '=') {
				*found = true;
				break;
			}
			v++;
			v += strspn(v, " \t\"");
			size_t vn = strcspn(v, "\";, \t");
			if ((vn == 1 && *v == '1') || (vn == 4 && !strncasecmp(v, "true", 4)) || (vn == 7 && !strncasecmp(v, "analyze", 7))) {
				*found = true;
				break;
			}
		}
		p += strcspn(p, ",");
	}
	return MHD_YES;
}

bool srv_explain_begin(struct srv_request *req, struct MHD_Connection *conn, const char *accept,
                       enum MHD_Result *refused)
{
	const char *ex = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "explain");
	if (ex) {
		if (req->route != SRV_ROUTE_RENDER) {
			*refused = srv_respond_problem(req, 400, NULL, "", "explain=%.20s is for POST /v1/render (the image with "
			                               "its plan); POST /v1/explain answers the plan alone", ex);
			return true;
		}
		if (strcmp(ex, "1") && strcasecmp(ex, "true") && strcasecmp(ex, "analyze")) {
			*refused = srv_respond_problem(req, 400, NULL, "", "explain=%.20s: 1 (or true, analyze) adds the render's "
			                               "plan, measured, to its answer (multipart/mixed)", ex);
			return true;
		}
		req->explain = true;
	}
	/* The header form, every Prefer header read (a preference may come in any of them). */
	bool preferred = false;
	if (req->route == SRV_ROUTE_RENDER)
		MHD_get_connection_values(conn, MHD_HEADER_KIND, prefer_header, &preferred);
	if (preferred) {
		req->explain = true;
		req->explain_preferred = true;
	}
	/* The plan is JSON: an Accept that excludes it is a 406 (none, any JSON type, or a wildcard is fine). */
	if (req->route == SRV_ROUTE_EXPLAIN && accept && *accept && !strcasestr(accept, "json") &&
	    !strstr(accept, "*/*") && !strcasestr(accept, "application/*")) {
		*refused = srv_respond_problem(req, 406, NULL, "", "POST /v1/explain answers application/json; Accept: %.200s "
		                               "names no JSON type", accept);
		return true;
	}
	return false;
}

void srv_explain_answer(struct srv_server *s, struct srv_request *req, const struct api_scene *sc, double parse_ms)
{
	struct srv_plan plan = {0};
	struct rnd_error err = {0};
	struct api_problem p = {0};
	enum rnd_result r = srv_plan(s, &sc->scene, &plan, &err);
	if (r != RND_OK) {
		if (r == RND_ERR_DEVICE_LOST)
			api_problem_set(&p, 503, "", "the renderer is not available (%s); retry", err.msg[0] ? err.msg : "no context");
		else
			api_problem_from_render(&p, sc, &err, r == RND_ERR_LIMIT ? 422 : r == RND_ERR_INVALID ? 400 : 503);
		srv_request_note_problem(req, &p);
		req->status = p.status;
		req->content_type = "application/problem+json";
		req->out = (uint8_t *)api_problem_json(&p);
		req->out_len = req->out ? strlen((char *)req->out) : 0;
		return;
	}
	struct api_plan_times t = {parse_ms, -1, -1};
	size_t len = 0;
	char *json = api_plan_json(sc, plan.plan, &t, &len);
	srv_plan_release(&plan);
	req->status = json ? 200 : 503;
	req->content_type = json ? "application/json" : NULL;
	req->out = (uint8_t *)json;
	req->out_len = len;
	snprintf(req->server_timing, sizeof req->server_timing, "parse;dur=%.3f", parse_ms);
}

/* Appends n bytes at *at. */
static void put(uint8_t **at, const void *data, size_t n)
{
	memcpy(*at, data, n);
	*at += n;
}

bool srv_explain_multipart(struct srv_request *req, const struct api_scene *sc, const struct rnd_plan *plan,
                           const struct api_plan_times *t, uint8_t *bytes, size_t len)
{
	size_t jlen = 0;
	char *json = api_plan_json(sc, plan, t, &jlen);
	/* A boundary the image does not hold (RFC 2046 §5.1.1): the request's id, made longer if
	 * it ever does. */
	char boundary[72];
	int bl = snprintf(boundary, sizeof boundary, "umbra-plan-%.40s", req->id);
	for (unsigned k = 0; json && memmem(bytes, len, boundary, (size_t)bl) && k < 8; k++)
		bl = snprintf(boundary, sizeof boundary, "umbra-plan-%.40s-%u", req->id, k);
	char head[256], mid[160], tail[96];
	int hl = snprintf(head, sizeof head, "--%s\r\nContent-Type: %s\r\nContent-Disposition: inline; name=\"image\"\r\n\r\n",
	                  boundary, api_format_mime(sc->format));
	int ml = snprintf(mid, sizeof mid, "\r\n--%s\r\nContent-Type: application/json\r\nContent-Disposition: inline; "
	                  "name=\"plan\"\r\n\r\n", boundary);
	int tl = snprintf(tail, sizeof tail, "\r\n--%s--\r\n", boundary);
	uint8_t *out = json ? malloc((size_t)hl + len + (size_t)ml + jlen + (size_t)tl) : NULL;
	if (!out) {
		srv_log(SRV_LOG_WARN, "request %s: out of memory for the plan's answer", req->id);
		free(json);
		free(bytes);
		return false;
	}
	uint8_t *at = out;
	put(&at, head, (size_t)hl);
	put(&at, bytes, len);
	put(&at, mid, (size_t)ml);
	put(&at, json, jlen);
	put(&at, tail, (size_t)tl);
	free(json);
	free(bytes);
	snprintf(req->mime, sizeof req->mime, "multipart/mixed; boundary=%s", boundary);
	req->status = 200;
	req->content_type = req->mime;
	req->out = out;
	req->out_len = (size_t)(at - out);
	return true;
}
