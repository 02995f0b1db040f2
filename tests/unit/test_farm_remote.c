/* tests — the remote farm's pure parts: server/http_client.c's URL and answer parsing, and
 * api/'s reading back of a daemon's problem+json and of a farm report line (--resume). */
#include <stdlib.h>
#include <string.h>

#include "api.h"
#include "http_client.h"
#include "test.h"

TEST(http_url_parse)
{
	struct srv_http_url u;
	struct srv_http_error e;
	REQUIRE(srv_http_url_parse("http://127.0.0.1:8080", &u, &e) == SRV_HTTP_OK, "%s", e.msg);
	CHECK(!strcmp(u.host, "127.0.0.1") && !strcmp(u.port, "8080") && !u.base[0]);
	REQUIRE(srv_http_url_parse("HTTP://umbrad/", &u, &e) == SRV_HTTP_OK, "%s", e.msg);
	CHECK(!strcmp(u.host, "umbrad") && !strcmp(u.port, "80") && !u.base[0], "no port is 80, a lone / no base");
	REQUIRE(srv_http_url_parse("http://[::1]:9/umbra//", &u, &e) == SRV_HTTP_OK, "%s", e.msg);
	CHECK(!strcmp(u.host, "::1") && !strcmp(u.port, "9") && !strcmp(u.base, "/umbra"), "%s %s %s", u.host, u.port,
	      u.base);
	CHECK(srv_http_url_parse("https://a:1", &u, &e) == SRV_HTTP_ERR_URL && strstr(e.msg, "http://"), "%s", e.msg);
	CHECK(srv_http_url_parse("http://:80", &u, &e) == SRV_HTTP_ERR_URL);
	CHECK(srv_http_url_parse("http://a:8x", &u, &e) == SRV_HTTP_ERR_URL);
	CHECK(srv_http_url_parse("http://a:", &u, &e) == SRV_HTTP_ERR_URL);
	CHECK(srv_http_url_parse("127.0.0.1:8080", &u, &e) == SRV_HTTP_ERR_URL);
}

/* raw answer text -> parse; a malloc'd copy with room for the NUL. */
static bool parse(const char *text, struct srv_http_response *r)
{
	size_t n = strlen(text);
	uint8_t *raw = malloc(n + 1);
	memcpy(raw, text, n + 1);
	if (srv_http_response_parse(raw, n, r)) return true;
	free(raw);
	return false;
}

TEST(http_answer_parse)
{
	struct srv_http_response r;
	REQUIRE(parse("HTTP/1.1 503 Service Unavailable\r\nRetry-After:  2 \r\ncontent-type: application/problem+json\r\n"
	              "Content-Length: 4\r\n\r\n{}xx", &r));
	CHECK(r.status == 503 && !strcmp(r.retry_after, "2") && !strcmp(r.content_type, "application/problem+json"));
	CHECK(r.len == 4 && !memcmp(r.body, "{}xx", 4));
	srv_http_response_release(&r);
	REQUIRE(parse("HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\nServer-Timing: main;dur=1.5\r\n\r\n"
	              "3\r\nabc\r\n2;x=y\r\nde\r\n0\r\n\r\n", &r));
	CHECK(r.status == 200 && r.len == 5 && !memcmp(r.body, "abcde", 5) && !strcmp(r.server_timing, "main;dur=1.5"));
	srv_http_response_release(&r);
	REQUIRE(parse("HTTP/1.0 200 OK\r\n\r\nto the end", &r));
	CHECK(r.len == 10, "no length: the body runs to the close");
	srv_http_response_release(&r);
	CHECK(!parse("HTTP/1.1 200 OK\r\nContent-Length: 10\r\n\r\nshort", &r), "closed before the whole body");
	CHECK(!parse("HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\n5\r\nab", &r), "a cut chunk");
	CHECK(!parse("HTTP/1.1 200 OK\r\nContent-Le", &r), "no end of headers");
	CHECK(!parse("SSH-2.0-OpenSSH\r\n\r\n", &r), "not HTTP");
}

TEST(problem_parse_back)
{
	struct api_problem p, q;
	api_problem_set(&p, 400, "/lights/0/direction", "must not be zero");
	char *doc = api_problem_json(&p);
	REQUIRE(doc);
	api_problem_parse(doc, strlen(doc), 400, &q);
	char a[1024], b[1024];
	api_problem_format(&p, a, sizeof a);
	api_problem_format(&q, b, sizeof b);
	CHECK(!strcmp(a, b), "'%s' != '%s'", a, b);
	free(doc);
	const char *html = "<html>502 Bad Gateway</html>\nmore";
	api_problem_parse(html, strlen(html), 502, &q);
	CHECK(q.status == 502 && !strcmp(q.detail, "<html>502 Bad Gateway</html>") && !q.pointer[0], "%s", q.detail);
	api_problem_parse("", 0, 504, &q);
	CHECK(q.status == 504 && strstr(q.detail, "504"), "%s", q.detail);
}

TEST(report_line_parse)
{
	struct api_report_entry e;
	struct api_problem p;
	const char *ok = "{\"file\":\"m/a.obj\",\"output\":\"t/a.png\",\"status\":\"ok\",\"ms\":1.0,\"hash\":\"00ff\"}";
	REQUIRE(api_report_line(ok, strlen(ok), &e, &p) == API_OK, "%s", p.detail);
	CHECK(!strcmp(e.file, "m/a.obj") && !strcmp(e.output, "t/a.png") && !strcmp(e.status, "ok") &&
	      !strcmp(e.hash, "00ff"));
	api_report_entry_release(&e);
	const char *old = "{\"file\":\"a.obj\",\"output\":null,\"status\":\"skipped\"}";
	REQUIRE(api_report_line(old, strlen(old), &e, &p) == API_OK);
	CHECK(!e.output && !e.hash, "a line without hash (an older report) has none");
	api_report_entry_release(&e);
	CHECK(api_report_line("{\"file\":\"a", 10, &e, &p) == API_ERR, "a line cut short");
	CHECK(api_report_line("{\"status\":\"ok\"}", 15, &e, &p) == API_ERR && !e.file);
	api_report_entry_release(NULL);
}

TEST(scene_doc_set_format)
{
	size_t n = 0;
	const char *d = "{\"width\":8,\"output\":{\"format\":\"exr\",\"transparent\":true}}";
	char *s = api_scene_doc_set_format(d, strlen(d), API_FORMAT_PNG, &n);
	REQUIRE(s);
	CHECK(n == strlen(s) && strstr(s, "\"format\":\"png\"") && strstr(s, "\"transparent\":true") &&
	      strstr(s, "\"width\":8"), "%s", s);
	free(s);
	s = api_scene_doc_set_format("{}", 2, API_FORMAT_EXR, &n);
	CHECK(s && !strcmp(s, "{\"output\":{\"format\":\"exr\"}}"), "%s", s ? s : "(null)");
	free(s);
	CHECK(!api_scene_doc_set_format("{\"output\":5}", 12, API_FORMAT_PNG, &n), "a bad output stays the daemon's 400");
	CHECK(!api_scene_doc_set_format("[1]", 3, API_FORMAT_PNG, &n));
	CHECK(!api_scene_doc_set_format("{", 1, API_FORMAT_PNG, &n));
}
