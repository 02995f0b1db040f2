/*
 * server/origin_http — origin.c's rules on libmicrohttpd's requests, and what every answer tells
 * a browser. Runs on the polling thread, called by http.c: srv_origin_refuses() on a request's
 * first call, srv_origin_headers() from srv_respond() (http.h).
 *
 * A refusal (421 for the Host, 403 for the Origin) is answered like a GET: once the request is
 * complete, its body read and dropped. An answer queued on the first call makes libmicrohttpd
 * close the connection with the body unread, and a browser still sending its form then sees a
 * reset instead of the 403 page. A body over --max-body by its Content-Length, or of unknown
 * length (chunked), is not waited for: answered at once, the connection closed.
 */
#include <errno.h>
#include <microhttpd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "http.h"
#include "origin.h"

static const char *header(struct MHD_Connection *conn, const char *name)
{
	return MHD_lookup_connection_value(conn, MHD_HEADER_KIND, name);
}

/* Whether the request's body is short enough to read before refusing it: none, or a
 * Content-Length within --max-body. */
static bool body_bounded(struct MHD_Connection *conn, uint64_t max_body)
{
	if (header(conn, MHD_HTTP_HEADER_TRANSFER_ENCODING))
		return false;
	const char *cl = header(conn, MHD_HTTP_HEADER_CONTENT_LENGTH);
	if (!cl)
		return true;
	char *end;
	errno = 0;
	unsigned long long n = strtoull(cl, &end, 10);
	return !errno && end != cl && !*end && n <= max_body;
}

bool srv_origin_refuses(struct srv_request *req, struct MHD_Connection *conn, enum MHD_Result *answer)
{
	struct srv_origin_request q = {
		.method = req->method, .host = header(conn, MHD_HTTP_HEADER_HOST), .origin = header(conn, "Origin"),
		.sec_fetch_site = header(conn, "Sec-Fetch-Site"), .sec_fetch_mode = header(conn, "Sec-Fetch-Mode"),
		.probe = req->route == SRV_ROUTE_HEALTHZ || req->route == SRV_ROUTE_READYZ,
	};
	char detail[sizeof req->problem_detail] = "";
	int status = 403;
	switch (srv_origin_check(&req->srv->origin, &q, detail, sizeof detail)) {
	case SRV_ORIGIN_PASS:
		return false;
	case SRV_ORIGIN_CORS: {
		snprintf(req->cors_origin, sizeof req->cors_origin, "%s", q.origin);
		const char *pna = header(conn, "Access-Control-Request-Private-Network");
		req->cors_private_network = pna && !strcasecmp(pna, "true");
		return false;
	}
	case SRV_ORIGIN_BAD_HOST:
		status = 421;
		break;
	case SRV_ORIGIN_REFUSED:
		break;
	}
	if (!body_bounded(conn, req->srv->cfg.max_body)) {
		*answer = srv_respond_problem(req, status, NULL, "", "%s", detail);
		return true;
	}
	/* http.c answers it on the request's last call (answer_get), the body dropped meanwhile. */
	req->refused = status;
	snprintf(req->problem_detail, sizeof req->problem_detail, "%s", detail);
	req->state = SRV_REQ_HEADERS;
	*answer = MHD_YES;
	return true;
}

void srv_origin_headers(struct srv_request *req, struct MHD_Response *resp, int status)
{
	bool page = req->route == SRV_ROUTE_PLAYGROUND && status == 200;
	bool by_accept = (req->route == SRV_ROUTE_RENDER || req->route == SRV_ROUTE_RENDERS) &&
	                 (status == 200 || status == 303 || status == 412);
	bool cors = req->srv->origin.cors;
	MHD_add_response_header(resp, "X-Content-Type-Options", "nosniff");
	MHD_add_response_header(resp, "Referrer-Policy", "no-referrer");
	MHD_add_response_header(resp, "Content-Security-Policy", page ? srv_playground_csp() : SRV_CSP_API);
	/* With --cors-origin, whether an answer may be read depends on the Origin it was asked with. */
	if (by_accept || cors)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_VARY, by_accept && cors ? "Accept, Prefer, Origin" : by_accept ? "Accept, Prefer" : "Origin");
	if (!req->cors_origin[0])
		return;
	MHD_add_response_header(resp, "Access-Control-Allow-Origin", req->cors_origin);
	MHD_add_response_header(resp, "Access-Control-Expose-Headers", SRV_CORS_EXPOSE_HEADERS);
	MHD_add_response_header(resp, "Timing-Allow-Origin", req->cors_origin);
	if (strcmp(req->method, "OPTIONS") != 0)
		return;
	MHD_add_response_header(resp, "Access-Control-Allow-Methods", srv_allow_of(req->route));
	MHD_add_response_header(resp, "Access-Control-Allow-Headers", SRV_CORS_ALLOW_HEADERS);
	MHD_add_response_header(resp, "Access-Control-Max-Age", SRV_CORS_MAX_AGE);
	/* Chromium's Private Network Access: a public page calling a daemon on a private address. */
	if (req->cors_private_network)
		MHD_add_response_header(resp, "Access-Control-Allow-Private-Network", "true");
}
