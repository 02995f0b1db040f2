/* tests/unit/parse_util.c — the scene parser tests' helpers (parse_util.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "test.h"
#include "parse_util.h"

bool near_f(float a, float b)
{
	return fabsf(a - b) <= 1e-5f * (1.0f + fabsf(b));
}

double dist3(const float a[3], const double b[3])
{
	double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
	return sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

/* Documents are written with ' for " to stay readable; a static ring of buffers. */
const char *q(const char *s)
{
	static char bufs[4][8192];
	static int n;
	char *b = bufs[n++ & 3];
	size_t i = 0;
	for (; s[i] && i + 1 < sizeof bufs[0]; i++) b[i] = s[i] == '\'' ? '"' : s[i];
	b[i] = 0;
	return b;
}

struct api_scene *parse(const char *doc, struct api_problem *p)
{
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	if (api_scene_parse(doc, strlen(doc), NULL, &s, p) != API_OK) return NULL;
	return s;
}

/* Parses a document that must be valid; reports the problem otherwise. */
struct api_scene *parse_ok(const char *doc_q, const char *file, int line)
{
	struct api_problem p;
	struct api_scene *s = parse(q(doc_q), &p);
	if (!s) test_fail_at(file, line, "PARSE_OK", "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	return s;
}

void check_bad(const struct bad *b, const struct api_limits *lim, int idx)
{
	struct api_problem p;
	struct api_scene *s = NULL;
	const char *doc = q(b->doc);
	memset(&p, 0, sizeof p);
	enum api_result r = api_scene_parse(doc, strlen(doc), lim, &s, &p);
	CHECK(r == API_ERR && s == NULL, "doc %d should fail: %s", idx, doc);
	if (r == API_OK) { api_scene_free(s); return; }
	CHECK(p.status == b->status, "doc %d: status %d, want %d (%s: %s)", idx, p.status, b->status, p.pointer, p.detail);
	CHECK(!strcmp(p.pointer, b->pointer), "doc %d: pointer \"%s\", want \"%s\" (%s)", idx, p.pointer, b->pointer,
	      p.detail);
	CHECK(strstr(p.detail, b->phrase) != NULL, "doc %d: detail \"%s\" lacks \"%s\"", idx, p.detail, b->phrase);
	CHECK(!strncmp(p.type, "https://umbra.dev/problems/", 27), "doc %d: type %s", idx, p.type);
	CHECK(p.title[0] != 0, "doc %d: no title", idx);
}
