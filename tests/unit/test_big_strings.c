/* tests/unit/test_big_strings.c — api/big_strings: a document's big plain string values parsed
 * outside jansson's lexer must give jansson's own tree, and jansson's own errors (with their
 * line and column) for documents that do not parse; and a scene with a big inline mesh parses
 * to the same mesh as the same mesh given as a small one. */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include "api.h"
#include "big_strings.h"
#include "test.h"

/* A printf'd document whose "%s" arguments are big strings: `big` bytes of `fill` repeated. */
static char *doc_with(const char *fmt, size_t big, const char *fill, int nbig)
{
	char *s = malloc(big + 1);
	if (!s) return NULL;
	size_t fl = strlen(fill);
	for (size_t i = 0; i < big; i++) s[i] = fill[i % fl];
	s[big] = 0;
	const char *a[4] = {s, s, s, s};
	size_t n = strlen(fmt) + (size_t)nbig * big + 1;
	char *d = malloc(n);
	if (d) snprintf(d, n, fmt, a[0], a[1], a[2], a[3]);
	free(s);
	return d;
}

/* api_json_load and json_loadb agree on doc: both parse to equal trees, or both fail with the
 * same text, line and column. */
static void same_as_jansson(const char *what, const char *doc)
{
	json_error_t ea, eb;
	struct api_big_strings big;
	json_t *a = api_json_load(doc, strlen(doc), JSON_REJECT_DUPLICATES, &ea, NULL, &big);
	api_big_strings_free(&big);
	json_t *b = json_loadb(doc, strlen(doc), JSON_REJECT_DUPLICATES, &eb);
	CHECK(!a == !b, "%s: parsed by one and not the other (%s / %s)", what, a ? "ok" : ea.text, b ? "ok" : eb.text);
	if (a && b) CHECK(json_equal(a, b), "%s: the trees differ", what);
	if (!a && !b)
		CHECK(!strcmp(ea.text, eb.text) && ea.line == eb.line && ea.column == eb.column,
		      "%s: errors differ: %d:%d %s / %d:%d %s", what, ea.line, ea.column, ea.text, eb.line, eb.column, eb.text);
	json_decref(a);
	json_decref(b);
}

TEST(big_strings_same_tree_as_jansson)
{
	const size_t big = API_BIG_STRING + 123;
	static const struct { const char *what, *fmt, *fill; int n; } cases[] = {
		{"model data", "{\"objects\":[{\"shape\":\"model\",\"data\":\"%s\",\"format\":\"stl\"}]}", "QUJD", 1},
		{"several, in arrays and objects", "{\"a\":[\"%s\",1,{\"b\":\"%s\"}],\"c\" : \"%s\" ,\"d\":[[\"%s\"]]}", "xy=", 4},
		{"a big key is left to jansson", "{\"%s\":1}", "k", 1},
		{"escapes are left to jansson", "{\"a\":\"%s\"}", "ab\\\"c\\\\", 1},
		{"UTF-8 is left to jansson", "{\"a\":\"%s\"}", "h\xc3\xa9", 1},
		{"a small string next to a big one", "{\"a\":\"x\",\"b\":\"%s\",\"c\":\"\"}", "0123456789", 1},
		{"whitespace around", "{ \"a\" :\n \"%s\"\n}", "Zz", 1},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		char *d = doc_with(cases[i].fmt, big, cases[i].fill, cases[i].n);
		REQUIRE(d);
		same_as_jansson(cases[i].what, d);
		free(d);
	}
}

TEST(big_strings_same_errors_as_jansson)
{
	const size_t big = API_BIG_STRING + 7;
	static const struct { const char *what, *fmt, *fill; } cases[] = {
		{"a syntax error after a big string", "{\"a\":\"%s\",\n \"b\": x}", "QUJD"},
		{"unterminated", "{\"a\":\"%s", "QUJD"},
		{"duplicate keys", "{\"a\":\"%s\",\"a\":1}", "QUJD"},
		{"\\u0000 in a small string", "{\"a\":\"%s\",\"b\":\"x\\u0000y\"}", "QUJD"},
		{"a control character in a big string", "{\"a\":\"%s\"}", "QU\tJD"},
		{"invalid UTF-8 in a big string", "{\"a\":\"%s\"}", "Q\xffJD"},
		{"trailing garbage", "{\"a\":\"%s\"} x", "QUJD"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		char *d = doc_with(cases[i].fmt, big, cases[i].fill, 1);
		REQUIRE(d);
		json_error_t e;
		struct api_big_strings big;
		json_t *j = api_json_load(d, strlen(d), JSON_REJECT_DUPLICATES, &e, NULL, &big);
		CHECK(!j && big.n == 0, "%s: parsed", cases[i].what);
		json_decref(j);
		same_as_jansson(cases[i].what, d);
		free(d);
	}
}

/* A mesh whose base64 positions are far over API_BIG_STRING parses to the same vertices as the
 * same mesh under the threshold would (base64 of little-endian floats, read back here). */
TEST(big_strings_scene_with_a_big_inline_mesh)
{
	const size_t ntri = 4000;   /* 4000 * 9 floats * 4 bytes = 144,000 bytes -> 192,000 base64 */
	size_t nf = ntri * 9;
	float *pos = malloc(nf * sizeof *pos);
	REQUIRE(pos);
	for (size_t i = 0; i < nf; i++) pos[i] = (float)((i * 7919) % 1000) / 100.0f - 5.0f;
	static const char tb[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	const uint8_t *src = (const uint8_t *)pos;
	size_t nb = nf * 4, nch = (nb + 2) / 3 * 4;
	char *b64 = malloc(nch + 1);
	REQUIRE(b64);
	for (size_t i = 0, o = 0; i < nb; i += 3) {
		uint32_t w = (uint32_t)src[i] << 16 | (i + 1 < nb ? (uint32_t)src[i + 1] << 8 : 0) | (i + 2 < nb ? src[i + 2] : 0);
		b64[o++] = tb[w >> 18 & 63];
		b64[o++] = tb[w >> 12 & 63];
		b64[o++] = i + 1 < nb ? tb[w >> 6 & 63] : '=';
		b64[o++] = i + 2 < nb ? tb[w & 63] : '=';
	}
	b64[nch] = 0;
	CHECK(nch > API_BIG_STRING, "the string is not big: %zu", nch);
	size_t dn = nch + 512;
	char *doc = malloc(dn);
	REQUIRE(doc);
	snprintf(doc, dn,
	         "{\"width\":16,\"height\":16,\"camera\":{\"type\":\"perspective\",\"position\":[0,0,20],\"target\":[0,0,0],"
	         "\"up\":[0,1,0]},\"objects\":[{\"shape\":\"mesh\",\"positions\":\"%s\"}],\"lights\":[]}",
	         b64);
	struct api_scene *s = NULL;
	struct api_problem p;
	enum api_result r = api_scene_parse(doc, strlen(doc), NULL, &s, &p);
	CHECK(r == API_OK, "parse: %s: %s", p.pointer, p.detail);
	if (r == API_OK) {
		const struct rnd_object *o = &s->scene.objects[0];
		CHECK(o->shape == RND_SHAPE_MESH && o->vertex_count == ntri * 3, "vertices %u", o->vertex_count);
		bool same = o->positions && o->vertex_count == ntri * 3 && !memcmp(o->positions, pos, nf * sizeof *pos);
		CHECK(same, "the positions differ from the ones encoded");
		api_scene_free(s);
	}
	free(doc);
	free(b64);
	free(pos);
}

/* Members named in `keep` stay placeholders that api_big_string() reads from the document; the
 * other big strings are back in the tree. */
TEST(big_strings_kept_members_read_from_the_document)
{
	const size_t big = API_BIG_STRING + 5;
	char *d = doc_with("{\"data\":\"%s\",\"other\":\"%s\",\"list\":[\"%s\"],\"small\":\"abc\"}", big, "QUJD", 3);
	REQUIRE(d);
	static const char *const keep[] = {"data", "small", NULL};
	struct api_big_strings bs;
	json_error_t e;
	json_t *j = api_json_load(d, strlen(d), 0, &e, keep, &bs);
	REQUIRE(j);
	json_t *ref = json_loadb(d, strlen(d), 0, NULL);
	REQUIRE(ref);
	const char *want = json_string_value(json_object_get(ref, "data"));
	size_t n = 0;
	const char *got = api_big_string(&bs, json_object_get(j, "data"), &n);
	CHECK(bs.n == 3, "%zu strings cut", bs.n);
	CHECK(json_string_length(json_object_get(j, "data")) < 16, "the kept member was copied into the tree");
	CHECK(n == big && !memcmp(got, want, n), "the kept member's bytes differ");
	CHECK(json_equal(json_object_get(j, "other"), json_object_get(ref, "other")) &&
	      json_equal(json_object_get(j, "list"), json_object_get(ref, "list")), "the other big strings are not back");
	got = api_big_string(&bs, json_object_get(j, "small"), &n);
	CHECK(n == 3 && !memcmp(got, "abc", 3), "a small kept member reads as itself");
	json_decref(ref);
	json_decref(j);
	api_big_strings_free(&bs);
	free(d);
}
