/*
 * api/scene_parse — scene documents (contract v1, JSON) to renderer scenes.
 *
 * One pass over the document with jansson: every member is checked for type and range, and
 * every object for unknown members (except `extras` and `x-*`), while the rnd_scene is filled.
 * The first error wins and is reported as a 400 problem whose pointer is the RFC 6901 path of
 * the offending member, kept in pctx.ptr as the walk descends. Things that are valid but over
 * a limit, or not supported by the renderer yet, are 422s; they are deferred until the whole
 * document has been validated, so a 400 anywhere always takes precedence.
 *
 * Vectors (colours, positions, quaternions, matrices, mesh arrays) are reported at the member,
 * never at one element: "/lights/0/color" with "color must not have negative components".
 * Every array the rnd_scene points to lives in the scene's arena (api/arena.h), except the
 * geometry and textures of imported models: those live in the (immutable, cached) model
 * (api/model.h), of which the scene holds a reference until api_scene_free().
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <jansson.h>
#include "api.h"
#include "arena.h"
#include "base64.h"
#include "ground.h"
#include "preset.h"
#include "model.h"
#include "sandbox.h"
#include "umbra/rnd_math.h"

#define DEG2RAD (3.14159265358979323846 / 180.0)
#define PROBLEMS "https://umbra.dev/problems/"

struct pctx {
	struct api_arena *arena;
	struct api_problem *p;
	const struct api_limits *lim;
	uint64_t asset_hash;          /* FNV-1a of every file read under the asset root */
	char ptr[sizeof(((struct api_problem *)0)->pointer)];
	size_t len;
	/* The first deferred 422 (limit or unsupported feature). */
	bool pending;
	struct api_problem pend;
	/* Materials: named ones first (in document order), then inline ones, then the default. */
	json_t *mat_index;            /* name -> integer index */
	struct rnd_material *mats;
	uint32_t mat_count, mat_cap;
	uint32_t default_mat;         /* UINT32_MAX until an object needs it */
	/* Models: the request's binary parts, every model the scene holds a reference to, and the
	 * one the object being parsed imported (taken by parse_root). */
	const struct api_part *parts;
	size_t nparts;
	struct model_ref *models;
	const uint32_t *object_source;  /* document object of each rnd object (NULL: the same index) */
	const char *views_key;          /* "views" or "turntable" when the document has either */
	struct api_model *cur_model;
	/* Ground placement (api/ground.h): margin per document object, > 0 for placement "ground". */
	float *ground_margin;
	size_t cur_object;
};

/* A reference to an imported model, released in api_scene_free() (the node is in the arena). */
struct model_ref {
	struct model_ref *next;
	struct api_model *model;
};

static void model_refs_release(struct model_ref *r)
{
	for (; r; r = r->next) api_model_release(r->model);
}

/* ---- JSON Pointer of the member being checked ---- */

static size_t ptr_push(struct pctx *c, const char *key)
{
	size_t old = c->len, n = c->len, cap = sizeof c->ptr - 1;
	if (n < cap) c->ptr[n++] = '/';
	for (const char *s = key; *s && n < cap; s++) {
		if (*s == '~' || *s == '/') {
			if (n + 2 > cap) break;
			c->ptr[n++] = '~';
			c->ptr[n++] = *s == '~' ? '0' : '1';
		} else {
			c->ptr[n++] = *s;
		}
	}
	c->ptr[n] = 0;
	c->len = n;
	return old;
}

static size_t ptr_index(struct pctx *c, size_t i)
{
	char b[24];
	snprintf(b, sizeof b, "%zu", i);
	return ptr_push(c, b);
}

static void ptr_pop(struct pctx *c, size_t old)
{
	c->len = old;
	c->ptr[old] = 0;
}

/* ---- errors ---- */

static int vfail(struct pctx *c, const char *fmt, va_list ap)
{
	char buf[sizeof c->p->detail];
	vsnprintf(buf, sizeof buf, fmt, ap);
	api_problem_set(c->p, 400, c->ptr, "%s", buf);
	return -1;
}

/* 400 at the current pointer. Returns -1 so callers can `return fail(...)`. */
__attribute__((format(printf, 2, 3)))
static int fail(struct pctx *c, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vfail(c, fmt, ap);
	va_end(ap);
	return -1;
}

/* 400 at the member `key` of the current object. */
__attribute__((format(printf, 3, 4)))
static int fail_at(struct pctx *c, const char *key, const char *fmt, ...)
{
	size_t old = ptr_push(c, key);
	va_list ap;
	va_start(ap, fmt);
	vfail(c, fmt, ap);
	va_end(ap);
	ptr_pop(c, old);
	return -1;
}

/* Records a 422 at the current pointer (plus `key` when not NULL) unless one is recorded. */
__attribute__((format(printf, 4, 5)))
static void defer(struct pctx *c, bool unsupported, const char *key, const char *fmt, ...)
{
	if (c->pending) return;
	size_t old = key ? ptr_push(c, key) : c->len;
	char buf[sizeof c->pend.detail];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
	api_problem_set(&c->pend, 422, c->ptr, "%s", buf);
	if (unsupported) {
		snprintf(c->pend.type, sizeof c->pend.type, PROBLEMS "unsupported-feature");
		snprintf(c->pend.title, sizeof c->pend.title, "Feature not supported");
	}
	c->pending = true;
	ptr_pop(c, old);
}

static const char *type_name(const json_t *v)
{
	switch (json_typeof(v)) {
	case JSON_OBJECT: return "an object";
	case JSON_ARRAY: return "an array";
	case JSON_STRING: return "a string";
	case JSON_INTEGER: case JSON_REAL: return "a number";
	case JSON_TRUE: return "true";
	case JSON_FALSE: return "false";
	default: return "null";
	}
}

/* ---- unknown members ---- */

static bool is_free_member(const char *key)
{
	return !strcmp(key, "extras") || !strncmp(key, "x-", 2);
}

static bool in_list(const char *key, const char *const *list)
{
	for (; list && *list; list++)
		if (!strcmp(key, *list)) return true;
	return false;
}

/* Levenshtein distance, capped: strings longer than 32 bytes are "far". */
static int edit_distance(const char *a, const char *b)
{
	size_t la = strlen(a), lb = strlen(b);
	if (la > 32 || lb > 32) return 99;
	int row[33];
	for (size_t j = 0; j <= lb; j++) row[j] = (int)j;
	for (size_t i = 1; i <= la; i++) {
		int diag = row[0];
		row[0] = (int)i;
		for (size_t j = 1; j <= lb; j++) {
			int up = row[j];
			int best = diag + (a[i - 1] != b[j - 1]);
			if (up + 1 < best) best = up + 1;
			if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
			row[j] = best;
			diag = up;
		}
	}
	return row[lb];
}

/* Rejects members of obj named in neither list. `what` names the object in the message. */
static int check_members(struct pctx *c, json_t *obj, const char *const *list, const char *const *list2,
                         const char *what)
{
	const char *key;
	json_t *v;
	json_object_foreach(obj, key, v) {
		if (is_free_member(key) || in_list(key, list) || in_list(key, list2)) continue;
		/* Suggest a member within 2 edits, fewer for short names ("x" is not a typo of "up"). */
		const char *best = NULL;
		int bestd = (int)strlen(key) / 2 + 2;
		if (bestd > 3) bestd = 3;
		for (int l = 0; l < 2; l++)
			for (const char *const *s = l ? list2 : list; s && *s; s++) {
				int d = edit_distance(key, *s);
				if (d < bestd) { bestd = d; best = *s; }
			}
		if (best)
			return fail_at(c, key, "unknown member \"%.64s\" in %s (did you mean \"%s\"?)", key, what, best);
		return fail_at(c, key, "unknown member \"%.64s\" in %s (only \"extras\" and names starting with "
		               "\"x-\" may be added)", key, what);
	}
	return 0;
}

/* ---- typed members: each returns 1 when present and valid, 0 when absent, -1 on error ---- */

struct range { double lo, hi; bool lo_open, hi_open; };

static const struct range R_ANY = {-FLT_MAX, FLT_MAX, false, false};
static const struct range R_NONNEG = {0, FLT_MAX, false, false};
static const struct range R_POS = {0, FLT_MAX, true, false};
static const struct range R_UNIT = {0, 1, false, false};

static void range_text(char *buf, size_t n, const struct range *r)
{
	bool lo = r->lo > -FLT_MAX, hi = r->hi < FLT_MAX;
	if (lo && hi && !r->lo_open && !r->hi_open)
		snprintf(buf, n, "between %g and %g", r->lo, r->hi);
	else if (lo && hi)
		snprintf(buf, n, "%s %g and %s %g", r->lo_open ? "greater than" : "at least", r->lo,
		         r->hi_open ? "less than" : "at most", r->hi);
	else if (lo)
		snprintf(buf, n, "%s %g", r->lo_open ? "greater than" : "at least", r->lo);
	else if (hi)
		snprintf(buf, n, "%s %g", r->hi_open ? "less than" : "at most", r->hi);
	else
		snprintf(buf, n, "a finite number no larger than %g in magnitude", (double)FLT_MAX);
}

static bool in_range(double d, const struct range *r)
{
	if (!isfinite(d) || d < r->lo || d > r->hi) return false;
	if (r->lo_open && d <= r->lo) return false;
	if (r->hi_open && d >= r->hi) return false;
	return true;
}

static int check_num(struct pctx *c, const char *name, json_t *v, const struct range *r, double *out)
{
	if (!json_is_number(v)) return fail(c, "%s must be a number, not %s", name, type_name(v));
	double d = json_number_value(v);
	if (!in_range(d, r)) {
		char t[128];
		range_text(t, sizeof t, r);
		return fail(c, "%s must be %s (got %g)", name, t, d);
	}
	*out = d;
	return 0;
}

static int get_num(struct pctx *c, json_t *obj, const char *key, const struct range *r, double *out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = ptr_push(c, key);
	int rc = check_num(c, key, v, r, out);
	ptr_pop(c, old);
	return rc < 0 ? -1 : 1;
}

static int get_float(struct pctx *c, json_t *obj, const char *key, const struct range *r, float *out)
{
	double d;
	int rc = get_num(c, obj, key, r, &d);
	if (rc == 1) *out = (float)d;
	return rc;
}

/* Degrees in the document, radians in the scene. */
static int get_angle(struct pctx *c, json_t *obj, const char *key, const struct range *r, float *out)
{
	double d;
	int rc = get_num(c, obj, key, r, &d);
	if (rc == 1) *out = (float)(d * DEG2RAD);
	return rc;
}

static int check_int(struct pctx *c, const char *name, json_t *v, long long lo, long long hi, long long *out)
{
	long long i;
	if (json_is_integer(v)) {
		i = json_integer_value(v);
	} else if (json_is_real(v)) {
		double d = json_real_value(v);
		/* 2.0 is an integer in JSON's number model. */
		if (d != floor(d) || d < -9e15 || d > 9e15)
			return fail(c, "%s must be an integer (got %g)", name, d);
		i = (long long)d;
	} else {
		return fail(c, "%s must be an integer, not %s", name, type_name(v));
	}
	if (i < lo || i > hi) return fail(c, "%s must be between %lld and %lld (got %lld)", name, lo, hi, i);
	*out = i;
	return 0;
}

static int get_int(struct pctx *c, json_t *obj, const char *key, long long lo, long long hi, long long *out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = ptr_push(c, key);
	int rc = check_int(c, key, v, lo, hi, out);
	ptr_pop(c, old);
	return rc < 0 ? -1 : 1;
}

static int get_u32(struct pctx *c, json_t *obj, const char *key, long long lo, long long hi, uint32_t *out)
{
	long long i;
	int rc = get_int(c, obj, key, lo, hi, &i);
	if (rc == 1) *out = (uint32_t)i;
	return rc;
}

static int get_bool(struct pctx *c, json_t *obj, const char *key, bool *out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	if (!json_is_boolean(v)) return fail_at(c, key, "%s must be true or false, not %s", key, type_name(v));
	*out = json_is_true(v);
	return 1;
}

static int get_string(struct pctx *c, json_t *obj, const char *key, const char **out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	if (!json_is_string(v)) return fail_at(c, key, "%s must be a string, not %s", key, type_name(v));
	*out = json_string_value(v);
	return 1;
}

static int check_enum(struct pctx *c, const char *name, json_t *v, const char *const *names, int *out)
{
	char list[256];
	size_t n = 0;
	list[0] = 0;
	for (int i = 0; names[i]; i++)
		n += (size_t)snprintf(list + n, n < sizeof list ? sizeof list - n : 0, "%s\"%s\"", i ? ", " : "",
		                      names[i]);
	if (!json_is_string(v)) return fail(c, "%s must be one of %s, not %s", name, list, type_name(v));
	const char *s = json_string_value(v);
	for (int i = 0; names[i]; i++)
		if (!strcmp(s, names[i])) { *out = i; return 0; }
	return fail(c, "%s must be one of %s (got \"%.40s\")", name, list, s);
}

static int get_enum(struct pctx *c, json_t *obj, const char *key, const char *const *names, int *out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = ptr_push(c, key);
	int rc = check_enum(c, key, v, names, out);
	ptr_pop(c, old);
	return rc < 0 ? -1 : 1;
}

enum {
	V_NONNEG = 1u << 0,   /* colours */
	V_NONZERO = 1u << 1,  /* directions, up, quaternions */
	V_NOZERO_COMP = 1u << 2, /* scale */
	V_POS = 1u << 3,      /* sizes */
	V_ALPHA01 = 1u << 4,  /* a 4th component is an alpha in 0..1 */
};

/* A fixed-size vector of nmin..nmax numbers. Returns the count (>0), 0 when absent, -1. */
static int check_vec(struct pctx *c, const char *name, json_t *v, float *out, int nmin, int nmax, unsigned flags)
{
	char want[32];
	if (nmin == nmax) snprintf(want, sizeof want, "%d numbers", nmin);
	else snprintf(want, sizeof want, "%d or %d numbers", nmin, nmax);
	if (!json_is_array(v)) return fail(c, "%s must be an array of %s, not %s", name, want, type_name(v));
	size_t n = json_array_size(v);
	if (n < (size_t)nmin || n > (size_t)nmax) return fail(c, "%s must have %s (got %zu)", name, want, n);
	double tmp[16], len2 = 0;
	for (size_t i = 0; i < n; i++) {
		json_t *e = json_array_get(v, i);
		if (!json_is_number(e))
			return fail(c, "element %zu of %s must be a number, not %s", i, name, type_name(e));
		double d = json_number_value(e);
		if (!in_range(d, &R_ANY)) return fail(c, "element %zu of %s is out of range (got %g)", i, name, d);
		tmp[i] = d;
		len2 += d * d;
	}
	for (size_t i = 0; i < n; i++) {
		bool alpha = (flags & V_ALPHA01) && i == 3;
		if (alpha && (tmp[i] < 0 || tmp[i] > 1))
			return fail(c, "the alpha of %s must be between 0 and 1 (got %g)", name, tmp[i]);
		if ((flags & V_NONNEG) && tmp[i] < 0)
			return fail(c, "%s must not have negative components (element %zu is %g)", name, i, tmp[i]);
		if ((flags & V_POS) && !(tmp[i] > 0))
			return fail(c, "%s components must be greater than 0 (element %zu is %g)", name, i, tmp[i]);
		if ((flags & V_NOZERO_COMP) && tmp[i] == 0)
			return fail(c, "%s components must not be 0 (element %zu is 0)", name, i);
	}
	if ((flags & V_NONZERO) && !(len2 > 0)) return fail(c, "%s must not be zero", name);
	for (size_t i = 0; i < n; i++) out[i] = (float)tmp[i];
	return (int)n;
}

static int get_vec(struct pctx *c, json_t *obj, const char *key, float *out, int nmin, int nmax, unsigned flags)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = ptr_push(c, key);
	int rc = check_vec(c, key, v, out, nmin, nmax, flags);
	ptr_pop(c, old);
	return rc;
}

static int require_object(struct pctx *c, json_t *v, const char *name)
{
	if (!json_is_object(v)) return fail(c, "%s must be an object, not %s", name, type_name(v));
	return 0;
}

/* ---- base64 and binary arrays ---- */

/* Decodes a base64 member into the arena. Returns 0 or -1 (400 at the current pointer). */
static int decode_b64_member(struct pctx *c, const char *name, json_t *v, unsigned char **out, size_t *len)
{
	const char *s = json_string_value(v);
	size_t n = json_string_length(v);
	size_t cap = api_base64_decoded_max(n);
	unsigned char *buf = api_arena_alloc(c->arena, cap);
	if (!buf) return fail(c, "%s is too large to decode (out of memory)", name);
	size_t bad = 0, got = 0;
	if (api_base64_decode(s, n, buf, cap, &got, &bad) != API_OK) {
		if (bad < n) return fail(c, "%s is not valid base64 (bad character at offset %zu)", name, bad);
		return fail(c, "%s is not valid base64 (truncated or over-padded)", name);
	}
	*out = buf;
	*len = got;
	return 0;
}

static uint32_t load_le32(const unsigned char *b)
{
	return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* A mesh array: flat JSON numbers, or base64 of little-endian float32 / uint32 (indices).
 * Returns 1 with *out (arena) and *count, 0 when absent, -1 on error. */
static int get_data(struct pctx *c, json_t *obj, const char *key, bool indices, void **out, size_t *count)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = ptr_push(c, key);
	int rc = -1;
	const char *kind = indices ? "non-negative integers" : "numbers";
	if (json_is_array(v)) {
		size_t n = json_array_size(v);
		uint32_t *u = api_arena_calloc(c->arena, n ? n : 1, 4);
		if (!u) { fail(c, "%s is too large (out of memory)", key); goto out; }
		float *f = (float *)u;
		for (size_t i = 0; i < n; i++) {
			json_t *e = json_array_get(v, i);
			if (!json_is_number(e)) {
				fail(c, "element %zu of %s must be a number, not %s", i, key, type_name(e));
				goto out;
			}
			double d = json_number_value(e);
			if (indices) {
				if (d < 0 || d > 4294967295.0 || d != floor(d)) {
					fail(c, "element %zu of %s must be an integer between 0 and 4294967295 (got %g)", i,
					     key, d);
					goto out;
				}
				u[i] = (uint32_t)d;
			} else {
				if (!in_range(d, &R_ANY)) {
					fail(c, "element %zu of %s is out of range (got %g)", i, key, d);
					goto out;
				}
				f[i] = (float)d;
			}
		}
		*out = u;
		*count = n;
		rc = 1;
	} else if (json_is_string(v)) {
		unsigned char *b;
		size_t n;
		if (decode_b64_member(c, key, v, &b, &n) < 0) goto out;
		if (n % 4) {
			fail(c, "%s must decode to whole 4-byte little-endian values (got %zu bytes)", key, n);
			goto out;
		}
		/* In place: element i is read from bytes 4i..4i+3 before it is written there. */
		uint32_t *u = (uint32_t *)(void *)b;
		for (size_t i = 0; i < n / 4; i++) {
			uint32_t w = load_le32(b + 4 * i);
			if (!indices) {
				float fv;
				memcpy(&fv, &w, 4);
				if (!isfinite(fv)) {
					fail(c, "element %zu of %s is not a finite number", i, key);
					goto out;
				}
			}
			u[i] = w;
		}
		*out = u;
		*count = n / 4;
		rc = 1;
	} else {
		fail(c, "%s must be an array of %s or a base64 string, not %s", key, kind, type_name(v));
	}
out:
	ptr_pop(c, old);
	return rc;
}

/* ---- materials ---- */

/* The renderer's bounds on base-colour textures (renderer/render.c textures()). */
#define MAX_TEXTURE_SIDE 16384u
#define MAX_TEXTURE_PIXELS (64ull << 20)
#define MAX_TEXTURES 16u

static const char *const MATERIAL_MEMBERS[] = {"base_color", "base_color_texture", "alpha_mode", "alpha_cutoff",
                                               "roughness", "metallic", "emissive", "shadow_catcher", NULL};

static int parse_material(struct pctx *c, json_t *j, struct rnd_material *m, const char *what)
{
	if (require_object(c, j, what) < 0 || check_members(c, j, MATERIAL_MEMBERS, NULL, "a material") < 0)
		return -1;
	rnd_material_defaults(m);
	float col[4] = {0, 0, 0, 1};
	int n = get_vec(c, j, "base_color", col, 3, 4, V_NONNEG | V_ALPHA01);
	if (n < 0) return -1;
	if (n > 0) memcpy(m->base_color, col, sizeof col);
	static const char *const alpha_modes[] = {"opaque", "mask", NULL};
	int mode;
	int rc = get_enum(c, j, "alpha_mode", alpha_modes, &mode);
	if (rc < 0) return -1;
	if (rc) m->alpha_mode = mode ? RND_ALPHA_MASK : RND_ALPHA_OPAQUE;
	if (get_float(c, j, "alpha_cutoff", &R_UNIT, &m->alpha_cutoff) < 0 ||
	    get_float(c, j, "roughness", &R_UNIT, &m->roughness) < 0 ||
	    get_float(c, j, "metallic", &R_UNIT, &m->metallic) < 0 ||
	    get_vec(c, j, "emissive", m->emissive, 3, 3, V_NONNEG) < 0 ||
	    get_bool(c, j, "shadow_catcher", &m->shadow_catcher) < 0)
		return -1;
	json_t *tex = json_object_get(j, "base_color_texture");
	if (tex) {
		size_t old = ptr_push(c, "base_color_texture");
		unsigned char *b;
		size_t len;
		if (!json_is_string(tex)) {
			fail(c, "base_color_texture must be a base64 PNG or JPEG string, not %s", type_name(tex));
			ptr_pop(c, old);
			return -1;
		}
		if (decode_b64_member(c, "base_color_texture", tex, &b, &len) < 0) { ptr_pop(c, old); return -1; }
		bool png = len >= 8 && !memcmp(b, "\x89PNG\r\n\x1a\n", 8);
		bool jpeg = len >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff;
		if (!png && !jpeg) {
			fail(c, "base_color_texture must be a base64 PNG or JPEG image");
			ptr_pop(c, old);
			return -1;
		}
		/* Decoded now (a texture the renderer would refuse is caught here, with its pointer) and
		 * copied into the arena, which owns it with the rest of the scene. */
		uint8_t *rgba = NULL;
		uint32_t w = 0, h = 0;
		char err[300];
		int status;
		/* In a sandboxed helper process (api/sandbox.h): libpng/libjpeg never see request bytes here. */
		if (api_sandbox_decode_image(b, len, MAX_TEXTURE_PIXELS, c->lim, &rgba, &w, &h, &status, err, sizeof err) !=
		    API_OK) {
			api_problem_set(c->p, status, c->ptr, "base_color_texture could not be decoded: %s", err);
			ptr_pop(c, old);
			return -1;
		}
		struct rnd_texture *t = api_arena_alloc(c->arena, sizeof *t);
		uint8_t *px = api_arena_calloc(c->arena, (size_t)w * h, 4);
		if (!t || !px) {
			free(rgba);
			fail(c, "base_color_texture is too large (out of memory)");
			ptr_pop(c, old);
			return -1;
		}
		memcpy(px, rgba, (size_t)w * h * 4);
		free(rgba);
		t->rgba = px;
		t->width = w;
		t->height = h;
		m->base_color_texture = t;
		if (w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE)
			defer(c, false, NULL, "base_color_texture is %ux%u texels, over the limit of %u per side", w, h,
			      MAX_TEXTURE_SIDE);
		ptr_pop(c, old);
	}
	return 0;
}

static int add_material(struct pctx *c, uint32_t *index)
{
	if (c->mat_count >= c->mat_cap) return fail(c, "too many materials");
	*index = c->mat_count++;
	return 0;
}

/* ---- transforms ---- */

static const char *const TRANSFORM_MEMBERS[] = {"translation", "rotation", "scale", "matrix", NULL};

static int parse_transform(struct pctx *c, json_t *j, float model[16])
{
	if (require_object(c, j, "transform") < 0 ||
	    check_members(c, j, TRANSFORM_MEMBERS, NULL, "a transform") < 0)
		return -1;
	json_t *mj = json_object_get(j, "matrix");
	if (mj) {
		const char *other = json_object_get(j, "translation") ? "translation"
		                    : json_object_get(j, "rotation") ? "rotation"
		                    : json_object_get(j, "scale") ? "scale" : NULL;
		if (other)
			return fail_at(c, "matrix", "matrix cannot be combined with %s (use either matrix or "
			               "translation/rotation/scale)", other);
		float m[16];
		if (get_vec(c, j, "matrix", m, 16, 16, 0) < 0) return -1;
		if (m[3] != 0 || m[7] != 0 || m[11] != 0 || m[15] != 1)
			return fail_at(c, "matrix", "matrix must be affine: its last row (elements 3, 7, 11, 15 in "
			               "column-major order) must be 0, 0, 0, 1");
		memcpy(model, m, sizeof m);
	} else {
		float t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
		if (get_vec(c, j, "translation", t, 3, 3, 0) < 0 ||
		    get_vec(c, j, "rotation", q, 4, 4, V_NONZERO) < 0 ||
		    get_vec(c, j, "scale", s, 3, 3, V_NOZERO_COMP) < 0)
			return -1;
		rnd_mat4_trs(model, t, q, s);
	}
	float det = rnd_mat4_det3(model);
	if (!(fabsf(det) > 0) || !isfinite(det)) {
		const char *key = mj ? "matrix" : "scale";
		return fail_at(c, key, "the transform is singular or out of range (determinant %g)", (double)det);
	}
	return 0;
}

/* ---- objects ---- */

static const char *const OBJECT_COMMON[] = {"shape", "name", "transform", "material", "cast_shadows",
                                            "receive_shadows", "double_sided", NULL};
static const char *const SHAPES[] = {"plane", "box", "sphere", "cylinder", "mesh", "model", NULL};
enum { SHAPE_MODEL = 5 };
static const char *const SHAPE_MEMBERS[][5] = {
	{"size", "placement", "margin", NULL},
	{"size", NULL},
	{"radius", "segments", NULL},
	{"radius", "height", "segments", NULL},
	{"positions", "indices", "normals", "uvs", NULL},
	{"data", "format", "path", "part", NULL},
};
#define MAX_SEGMENTS 1000000

static int parse_mesh(struct pctx *c, json_t *j, struct rnd_object *o)
{
	void *pos = NULL, *idx = NULL, *nrm = NULL, *uv = NULL;
	size_t npos = 0, nidx = 0, nnrm = 0, nuv = 0;
	int rc = get_data(c, j, "positions", false, &pos, &npos);
	if (rc < 0) return -1;
	if (rc == 0) return fail_at(c, "positions", "positions is required for a mesh");
	if (npos % 3) return fail_at(c, "positions", "positions must hold 3 numbers per vertex (got %zu numbers)", npos);
	if (npos / 3 > UINT32_MAX) return fail_at(c, "positions", "positions has too many vertices");
	uint32_t nv = (uint32_t)(npos / 3);
	if ((rc = get_data(c, j, "indices", true, &idx, &nidx)) < 0) return -1;
	if (rc) {
		if (nidx % 3) return fail_at(c, "indices", "indices must hold 3 per triangle (got %zu)", nidx);
		if (nidx > UINT32_MAX) return fail_at(c, "indices", "indices has too many elements");
		const uint32_t *u = idx;
		for (size_t i = 0; i < nidx; i++)
			if (u[i] >= nv)
				return fail_at(c, "indices", "element %zu of indices (%u) is not below the vertex count %u",
				               i, u[i], nv);
		o->indices = u;
		o->index_count = (uint32_t)nidx;
	} else if (nv % 3) {
		return fail_at(c, "positions", "without indices, positions must hold whole triangles (%u vertices "
		               "is not a multiple of 3)", nv);
	}
	if ((rc = get_data(c, j, "normals", false, &nrm, &nnrm)) < 0) return -1;
	if (rc && nnrm != npos)
		return fail_at(c, "normals", "normals must have one xyz per vertex: %zu numbers for %u vertices (got %zu)",
		               npos, nv, nnrm);
	if ((rc = get_data(c, j, "uvs", false, &uv, &nuv)) < 0) return -1;
	if (rc && nuv != (size_t)nv * 2)
		return fail_at(c, "uvs", "uvs must have one uv pair per vertex: %zu numbers for %u vertices (got %zu)",
		               (size_t)nv * 2, nv, nuv);
	o->positions = pos;
	o->vertex_count = nv;
	o->normals = nnrm ? nrm : NULL;
	o->uvs = nuv ? uv : NULL;
	return 0;
}

#define MAX_ASSET_BYTES (1ull << 30)

/* Reads `path` (already checked: relative, no ".." component) under the asset root into a
 * malloc'd buffer. Symlinks are followed only while they stay inside the root. 0 or -1 (400 at
 * the current pointer, 500 when the root itself is unusable). */
static int read_asset(struct pctx *c, const char *path, unsigned char **out, size_t *len)
{
	const char *root = c->lim->asset_root;
	if (!root || !root[0]) return fail(c, "path cannot be used: no asset root configured on this server");
	char rroot[PATH_MAX], full[PATH_MAX], real[PATH_MAX];
	if (!realpath(root, rroot)) {
		api_problem_set(c->p, 500, c->ptr, "the asset root cannot be resolved: %s", strerror(errno));
		return -1;
	}
	if ((size_t)snprintf(full, sizeof full, "%s/%s", rroot, path) >= sizeof full)
		return fail(c, "path is too long");
	if (!realpath(full, real)) return fail(c, "path \"%.128s\" cannot be opened: %s", path, strerror(errno));
	size_t n = strlen(rroot);
	bool inside = !strcmp(rroot, "/") || (!strncmp(real, rroot, n) && real[n] == '/');
	if (!inside) return fail(c, "path \"%.128s\" leaves the asset root (through a symbolic link)", path);
	/* O_NONBLOCK: opening a FIFO (or a device) must not wait for a writer; anything but a
	 * regular file is refused right after, before a read could block. */
	int fd = open(real, O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
	if (fd < 0) return fail(c, "path \"%.128s\" cannot be opened: %s", path, strerror(errno));
	struct stat st;
	int rc = 0;
	unsigned char *buf = NULL;
	if (fstat(fd, &st) < 0 || !S_ISREG(st.st_mode)) {
		rc = fail(c, "path \"%.128s\" is not a regular file", path);
	} else if ((uint64_t)st.st_size > MAX_ASSET_BYTES || !st.st_size) {
		rc = fail(c, "path \"%.128s\" is empty or larger than %llu bytes", path, MAX_ASSET_BYTES);
	} else if (!(buf = malloc((size_t)st.st_size))) {
		rc = fail(c, "path \"%.128s\" is too large to read (out of memory)", path);
	} else {
		size_t got = 0;
		while (got < (size_t)st.st_size) {
			ssize_t r = read(fd, buf + got, (size_t)st.st_size - got);
			if (r < 0 && errno == EINTR) continue;
			if (r <= 0) break;
			got += (size_t)r;
		}
		if (got != (size_t)st.st_size) {
			free(buf);
			buf = NULL;
			rc = fail(c, "path \"%.128s\" could not be read", path);
		}
	}
	close(fd);
	*out = buf;
	*len = buf ? (size_t)st.st_size : 0;
	/* The answer depends on the file, not only on the request: fold its bytes (and name)
	 * into the scene's asset hash so the server's ETag changes when the file does. */
	if (buf) {
		uint64_t h = c->asset_hash ? c->asset_hash : 0xcbf29ce484222325ull;
		for (const char *q = path; *q; q++) h = (h ^ (unsigned char)*q) * 0x100000001b3ull;
		for (size_t i = 0; i < *len; i++) h = (h ^ buf[i]) * 0x100000001b3ull;
		c->asset_hash = h;
	}
	return rc;
}

static int parse_model(struct pctx *c, json_t *j)
{
	static const char *const sources[] = {"data", "path", "part"};
	const char *first = NULL;
	for (int i = 0; i < 3; i++) {
		if (!json_object_get(j, sources[i])) continue;
		if (first)
			return fail_at(c, sources[i], "%s cannot be combined with %s: a model has one source", sources[i],
			               first);
		first = sources[i];
	}
	if (!first) return fail(c, "a model needs one of data (base64 file), path or part");
	static const char *const formats[] = {"glb", "gltf", "obj", "stl", "ply", NULL};
	int f;
	if (get_enum(c, j, "format", formats, &f) < 0) return -1;
	bool given = json_object_get(j, "format") != NULL;
	json_t *v = json_object_get(j, first);
	size_t old = ptr_push(c, first);
	int rc = 0;
	unsigned char *b = NULL;
	size_t len = 0;
	if (!json_is_string(v)) {
		rc = fail(c, "%s must be a string, not %s", first, type_name(v));
	} else if (!strcmp(first, "data")) {
		if (decode_b64_member(c, "data", v, &b, &len) < 0) rc = -1;
		else if (!len) rc = fail(c, "data must not be empty");
	} else if (!strcmp(first, "path")) {
		const char *s = json_string_value(v);
		bool bad = !s[0] || s[0] == '/' || s[0] == '\\' || strchr(s, ':') || strchr(s, '\\');
		/* No ".." segment anywhere: the path never escapes the asset root. */
		for (const char *q = s; !bad && *q; q = strchr(q, '/') ? strchr(q, '/') + 1 : q + strlen(q))
			if (q[0] == '.' && q[1] == '.' && (q[2] == '/' || q[2] == 0)) bad = true;
		if (bad) rc = fail(c, "path must be a relative path inside the asset root (no leading \"/\", no \"..\")");
		else rc = read_asset(c, s, &b, &len);
		if (!rc && !given) { /* the extension says what the bytes may not (obj, ascii stl) */
			const char *dot = strrchr(s, '.');
			for (int i = 0; dot && formats[i]; i++)
				if (!strcasecmp(dot + 1, formats[i])) { f = i; given = true; }
		}
	} else if (!json_string_length(v)) {
		rc = fail(c, "part must name a part of the multipart request");
	} else {
		const char *name = json_string_value(v);
		size_t i = 0;
		while (i < c->nparts && (!c->parts[i].name || strcmp(c->parts[i].name, name))) i++;
		if (i == c->nparts) rc = fail(c, "part \"%.64s\" is not a part of this request", name);
		else if (!c->parts[i].len) rc = fail(c, "part \"%.64s\" is empty", name);
		else b = (unsigned char *)c->parts[i].data, len = c->parts[i].len;
	}
	if (rc == 0) {
		struct api_model *m = NULL;
		char err[400];
		int status;
		struct model_ref *ref = api_arena_alloc(c->arena, sizeof *ref);
		if (!ref) {
			rc = fail(c, "out of memory");
		} else if (api_model_get(b, len, given ? (enum api_model_format)f : API_MODEL_SNIFF, c->lim, &m, &status,
		                         err, sizeof err) != API_OK) {
			/* Named by the object's name, else by its path, else by its source member; 400 for a bad
			 * file, 422 over the import time/memory limit, 500 when the importer cannot run. */
			json_t *nm = json_object_get(j, "name");
			const char *what = json_is_string(nm) ? json_string_value(nm)
			                   : !strcmp(first, "path") ? json_string_value(v) : NULL;
			if (what)
				api_problem_set(c->p, status, c->ptr, "model \"%.128s\" (%s) could not be imported: %s", what, first,
				                err);
			else api_problem_set(c->p, status, c->ptr, "the model in %s could not be imported: %s", first, err);
			rc = -1;
		} else {
			ref->model = m;
			ref->next = c->models;
			c->models = ref;
			c->cur_model = m;
		}
	}
	if (!strcmp(first, "path")) free(b);
	ptr_pop(c, old);
	return rc < 0 ? -1 : 0;
}

/* A plane's `placement: "ground"` (and `margin`, default 3): placed under the other objects
 * once they are all known (api/ground.h), so it takes neither a transform nor a size. */
static int parse_placement(struct pctx *c, json_t *j)
{
	static const char *const placements[] = {"ground", NULL};
	static const struct range mr = {0, 1000, true, false};
	int pl = -1;
	float margin = 3;
	if (get_enum(c, j, "placement", placements, &pl) < 0 || get_float(c, j, "margin", &mr, &margin) < 0) return -1;
	if (pl < 0 && json_object_get(j, "margin")) return fail_at(c, "margin", "margin is only used with placement");
	if (pl < 0) return 0;
	if (json_object_get(j, "transform"))
		return fail_at(c, "transform", "a plane with placement \"ground\" places itself: it takes no transform");
	if (json_object_get(j, "size"))
		return fail_at(c, "size", "a plane with placement \"ground\" is sized by margin, not size");
	c->ground_margin[c->cur_object] = margin;
	return 0;
}

static int parse_object(struct pctx *c, json_t *j, struct rnd_object *o)
{
	if (require_object(c, j, "each entry of objects") < 0) return -1;
	json_t *sv = json_object_get(j, "shape");
	if (!sv) return fail_at(c, "shape", "shape is required (one of \"plane\", \"box\", \"sphere\", \"cylinder\", "
	                        "\"mesh\", \"model\")");
	int shape;
	if (get_enum(c, j, "shape", SHAPES, &shape) < 0) return -1;
	char what[32];
	snprintf(what, sizeof what, "a %s object", SHAPES[shape]);
	if (check_members(c, j, OBJECT_COMMON, SHAPE_MEMBERS[shape], what) < 0) return -1;
	rnd_object_defaults(o);
	const char *name;
	if (get_string(c, j, "name", &name) < 0) return -1;
	switch (shape) {
	case 0: { /* plane */
		float sz[2] = {1, 1};
		if (get_vec(c, j, "size", sz, 2, 2, V_POS) < 0 || parse_placement(c, j) < 0) return -1;
		o->shape = RND_SHAPE_PLANE;
		o->size[0] = sz[0]; o->size[1] = 0; o->size[2] = sz[1];
		break;
	}
	case 1: /* box */
		o->shape = RND_SHAPE_BOX;
		o->size[0] = o->size[1] = o->size[2] = 1;
		if (get_vec(c, j, "size", o->size, 3, 3, V_POS) < 0) return -1;
		break;
	case 2: case 3: /* sphere, cylinder */
		o->shape = shape == 2 ? RND_SHAPE_SPHERE : RND_SHAPE_CYLINDER;
		o->radius = 1;
		o->height = 1;
		o->segments = 64;
		if (get_float(c, j, "radius", &R_POS, &o->radius) < 0 ||
		    (shape == 3 && get_float(c, j, "height", &R_POS, &o->height) < 0) ||
		    get_u32(c, j, "segments", 3, MAX_SEGMENTS, &o->segments) < 0)
			return -1;
		break;
	case 4:
		o->shape = RND_SHAPE_MESH;
		if (parse_mesh(c, j, o) < 0) return -1;
		break;
	default:
		/* An empty mesh until parse_root expands it into one object per mesh instance. */
		o->shape = RND_SHAPE_MESH;
		if (parse_model(c, j) < 0) return -1;
		break;
	}
	json_t *t = json_object_get(j, "transform");
	if (t) {
		size_t old = ptr_push(c, "transform");
		int rc = parse_transform(c, t, o->model);
		ptr_pop(c, old);
		if (rc < 0) return -1;
	}
	json_t *m = json_object_get(j, "material");
	if (json_is_string(m)) {
		json_t *ix = c->mat_index ? json_object_get(c->mat_index, json_string_value(m)) : NULL;
		if (!ix)
			return fail_at(c, "material", "material \"%.64s\" is not defined in materials",
			               json_string_value(m));
		o->material = (uint32_t)json_integer_value(ix);
	} else if (m) {
		size_t old = ptr_push(c, "material");
		uint32_t mi = 0;
		int rc = json_is_object(m) ? add_material(c, &mi)
		         : fail(c, "material must be the name of a material or a material object, not %s", type_name(m));
		if (rc == 0) rc = parse_material(c, m, &c->mats[mi], "material");
		ptr_pop(c, old);
		if (rc < 0) return -1;
		o->material = mi;
	} else {
		if (c->default_mat == UINT32_MAX) {
			if (add_material(c, &c->default_mat) < 0) return -1;
			rnd_material_defaults(&c->mats[c->default_mat]);
		}
		o->material = c->default_mat;
	}
	if (get_bool(c, j, "cast_shadows", &o->cast_shadows) < 0 ||
	    get_bool(c, j, "receive_shadows", &o->receive_shadows) < 0 ||
	    get_bool(c, j, "double_sided", &o->double_sided) < 0)
		return -1;
	return 0;
}

/* ---- shadows ---- */

static const char *const SHADOW_MEMBERS[] = {"enabled", "filter", "resolution", "pcf_radius", "bias",
                                             "directional", "vsm", "contact", NULL};
static const char *const BIAS_MEMBERS[] = {"constant", "slope", "normal", NULL};
static const char *const DIRECTIONAL_MEMBERS[] = {"mode", "cascades", "split_lambda", "max_distance", "blend",
                                                  "fade", "clipmap_levels", "clipmap_extent", NULL};
static const char *const VSM_MEMBERS[] = {"precision", "blur", "light_bleed_reduction", "exponent", NULL};
static const char *const CONTACT_MEMBERS[] = {"enabled", "distance", "steps", "thickness", NULL};

/* Enters the sub-object `key` of j: 1 when present (pointer pushed, *old set), 0 absent, -1. */
static int enter(struct pctx *c, json_t *j, const char *key, const char *const *members, const char *what,
                 json_t **sub, size_t *old)
{
	*sub = json_object_get(j, key);
	if (!*sub) return 0;
	*old = ptr_push(c, key);
	if (require_object(c, *sub, key) < 0 || check_members(c, *sub, members, NULL, what) < 0) {
		ptr_pop(c, *old);
		return -1;
	}
	return 1;
}

/* Applies the members present in j over *s (root settings, then a light's own). */
static int parse_shadow(struct pctx *c, json_t *j, struct rnd_shadow *s, const char *what)
{
	if (require_object(c, j, what) < 0 || check_members(c, j, SHADOW_MEMBERS, NULL, "shadow settings") < 0)
		return -1;
	static const char *const filters[] = {"auto", "hard", "pcf", "pcss", "vsm", "evsm", NULL};
	static const enum rnd_filter filter_values[] = {RND_FILTER_AUTO, RND_FILTER_HARD, RND_FILTER_PCF,
	                                                RND_FILTER_PCSS, RND_FILTER_VSM, RND_FILTER_EVSM};
	int e, rc;
	if (get_bool(c, j, "enabled", &s->enabled) < 0) return -1;
	if ((rc = get_enum(c, j, "filter", filters, &e)) < 0) return -1;
	if (rc) s->filter = filter_values[e];
	if ((rc = get_u32(c, j, "resolution", 64, 8192, &s->resolution)) < 0) return -1;
	if (rc && c->lim->max_shadow_resolution && s->resolution > c->lim->max_shadow_resolution)
		defer(c, false, "resolution", "shadow resolution %u is over this server's limit of %u", s->resolution,
		      c->lim->max_shadow_resolution);
	if (get_u32(c, j, "pcf_radius", 0, 5, &s->pcf_radius) < 0) return -1;

	json_t *sub;
	size_t old;
	if ((rc = enter(c, j, "bias", BIAS_MEMBERS, "bias", &sub, &old)) < 0) return -1;
	if (rc) {
		rc = get_float(c, sub, "constant", &R_NONNEG, &s->bias_constant) < 0 ||
		     get_float(c, sub, "slope", &R_NONNEG, &s->bias_slope) < 0 ||
		     get_float(c, sub, "normal", &R_NONNEG, &s->bias_normal) < 0;
		ptr_pop(c, old);
		if (rc) return -1;
		s->bias_set = true;
	}
	if ((rc = enter(c, j, "directional", DIRECTIONAL_MEMBERS, "directional shadow settings", &sub, &old)) < 0)
		return -1;
	if (rc) {
		static const char *const modes[] = {"auto", "fit", "cascades", "clipmap", NULL};
		static const enum rnd_dir_mode mode_values[] = {RND_DIR_AUTO, RND_DIR_FIT, RND_DIR_CASCADES,
		                                                RND_DIR_CLIPMAP};
		int m = -1;
		rc = get_enum(c, sub, "mode", modes, &m) < 0 ||
		     get_u32(c, sub, "cascades", 1, 4, &s->cascades) < 0 ||
		     get_float(c, sub, "split_lambda", &R_UNIT, &s->split_lambda) < 0 ||
		     get_float(c, sub, "max_distance", &R_POS, &s->max_distance) < 0 ||
		     get_float(c, sub, "blend", &R_UNIT, &s->blend) < 0 ||
		     get_float(c, sub, "fade", &R_UNIT, &s->fade) < 0 ||
		     get_u32(c, sub, "clipmap_levels", 1, 8, &s->clipmap_levels) < 0 ||
		     get_float(c, sub, "clipmap_extent", &R_POS, &s->clipmap_extent) < 0;
		ptr_pop(c, old);
		if (rc) return -1;
		if (m >= 0) s->dir_mode = mode_values[m];
	}
	if ((rc = enter(c, j, "vsm", VSM_MEMBERS, "vsm settings", &sub, &old)) < 0) return -1;
	if (rc) {
		static const char *const precisions[] = {"auto", "fp32", "fp16", NULL};
		static const enum rnd_vsm_precision prec_values[] = {RND_VSM_AUTO, RND_VSM_FP32, RND_VSM_FP16};
		static const struct range blur = {0, 64, false, false}, expo = {0, 42, true, false};
		int pr = -1;
		rc = get_enum(c, sub, "precision", precisions, &pr) < 0 ||
		     get_float(c, sub, "blur", &blur, &s->vsm_blur) < 0 ||
		     get_float(c, sub, "light_bleed_reduction", &R_UNIT, &s->vsm_light_bleed) < 0 ||
		     get_float(c, sub, "exponent", &expo, &s->vsm_exponent) < 0;
		ptr_pop(c, old);
		if (rc) return -1;
		if (pr >= 0) s->vsm_precision = prec_values[pr];
	}
	if ((rc = enter(c, j, "contact", CONTACT_MEMBERS, "contact shadow settings", &sub, &old)) < 0) return -1;
	if (rc) {
		rc = get_bool(c, sub, "enabled", &s->contact_enabled) < 0 ||
		     get_float(c, sub, "distance", &R_POS, &s->contact_distance) < 0 ||
		     get_u32(c, sub, "steps", 1, 256, &s->contact_steps) < 0 ||
		     get_float(c, sub, "thickness", &R_POS, &s->contact_thickness) < 0;
		/* Parsed and validated, but the renderer does not march contact shadows yet: asking
		 * for them is a 422, never a silently different image. */
		if (!rc && s->contact_enabled)
			defer(c, true, "enabled", "contact shadows are not supported by this renderer yet; leave "
			      "contact.enabled false (soft shadows near contact come from the shadow filter)");
		ptr_pop(c, old);
		if (rc) return -1;
	}
	return 0;
}

/* ---- lights ---- */

static const char *const LIGHT_COMMON[] = {"type", "name", "color", "intensity", "shadow", NULL};
static const char *const LIGHT_TYPES[] = {"directional", "spot", "point", NULL};
static const char *const LIGHT_MEMBERS[][7] = {
	{"direction", "angular_diameter", NULL},
	{"position", "direction", "range", "inner_angle", "outer_angle", "radius", NULL},
	{"position", "range", "radius", NULL},
};

static int parse_light(struct pctx *c, json_t *j, struct rnd_light *l, const struct rnd_shadow *root_shadow)
{
	if (require_object(c, j, "each entry of lights") < 0) return -1;
	if (!json_object_get(j, "type"))
		return fail_at(c, "type", "type is required (one of \"directional\", \"spot\", \"point\")");
	int type;
	if (get_enum(c, j, "type", LIGHT_TYPES, &type) < 0) return -1;
	char what[32];
	snprintf(what, sizeof what, "a %s light", LIGHT_TYPES[type]);
	if (check_members(c, j, LIGHT_COMMON, LIGHT_MEMBERS[type], what) < 0) return -1;
	static const enum rnd_light_type types[] = {RND_LIGHT_DIRECTIONAL, RND_LIGHT_SPOT, RND_LIGHT_POINT};
	rnd_light_defaults(l, types[type]);
	const char *name;
	if (get_string(c, j, "name", &name) < 0) return -1;
	if (type != 2) {
		int rc = get_vec(c, j, "direction", l->direction, 3, 3, V_NONZERO);
		if (rc < 0) return -1;
		if (!rc) return fail_at(c, "direction", "direction is required for %s", what);
	}
	if (type != 0) {
		int rc = get_vec(c, j, "position", l->position, 3, 3, 0);
		if (rc < 0) return -1;
		if (!rc) return fail_at(c, "position", "position is required for %s", what);
	}
	if (get_vec(c, j, "color", l->color, 3, 3, V_NONNEG) < 0 ||
	    get_float(c, j, "intensity", &R_NONNEG, &l->intensity) < 0)
		return -1;
	static const struct range diameter = {0, 90, false, true}, inner = {0, 90, false, true},
	                          outer = {0, 90, true, true};
	if (type == 0 && get_angle(c, j, "angular_diameter", &diameter, &l->angular_diameter) < 0) return -1;
	if (type != 0 && (get_float(c, j, "range", &R_NONNEG, &l->range) < 0 ||
	                  get_float(c, j, "radius", &R_NONNEG, &l->radius) < 0))
		return -1;
	if (type == 1) {
		double in = 0, out = 45;
		if (get_num(c, j, "inner_angle", &inner, &in) < 0 || get_num(c, j, "outer_angle", &outer, &out) < 0)
			return -1;
		if (in > out) {
			const char *key = json_object_get(j, "inner_angle") ? "inner_angle" : "outer_angle";
			return fail_at(c, key, "inner_angle (%g) must not be greater than outer_angle (%g)", in, out);
		}
		l->inner_angle = (float)(in * DEG2RAD);
		l->outer_angle = (float)(out * DEG2RAD);
	}
	l->shadow = *root_shadow;
	json_t *sh = json_object_get(j, "shadow");
	if (json_is_boolean(sh)) {
		l->shadow.enabled = json_is_true(sh);
	} else if (sh) {
		size_t old = ptr_push(c, "shadow");
		int rc = json_is_object(sh) ? parse_shadow(c, sh, &l->shadow, "shadow")
		         : fail(c, "shadow must be an object of shadow settings or a boolean, not %s", type_name(sh));
		ptr_pop(c, old);
		if (rc < 0) return -1;
	}
	return 0;
}

/* ---- camera ---- */

static const char *const CAMERA_MEMBERS[] = {"type", "position", "target", "up", "fov_y", "height", "near",
                                             "far", "exposure", "fit", "direction", "margin", NULL};

static int parse_camera(struct pctx *c, json_t *j, struct rnd_camera *cam)
{
	if (require_object(c, j, "camera") < 0 || check_members(c, j, CAMERA_MEMBERS, NULL, "a camera") < 0)
		return -1;
	static const char *const types[] = {"perspective", "orthographic", NULL};
	static const char *const fits[] = {"scene", "objects", NULL};
	static const struct range fov = {0, 180, true, true}, ev = {-64, 64, false, false},
	                          margin = {0, 1, false, true};
	int type = 0, fit = -1, rc;
	if (get_enum(c, j, "type", types, &type) < 0 || get_enum(c, j, "fit", fits, &fit) < 0) return -1;
	cam->type = type ? RND_CAMERA_ORTHOGRAPHIC : RND_CAMERA_PERSPECTIVE;
	if (get_vec(c, j, "position", cam->position, 3, 3, 0) < 0 ||
	    get_vec(c, j, "target", cam->target, 3, 3, 0) < 0 ||
	    get_vec(c, j, "up", cam->up, 3, 3, V_NONZERO) < 0 ||
	    get_angle(c, j, "fov_y", &fov, &cam->fov_y) < 0 ||
	    get_float(c, j, "exposure", &ev, &cam->exposure) < 0)
		return -1;
	if ((rc = get_float(c, j, "height", &R_POS, &cam->height)) < 0) return -1;
	if (type == 1 && !rc) return fail_at(c, "height", "an orthographic camera requires height (world units "
	                                     "covered by the image height)");
	double nr = 0, fr = 0;
	int has_near = get_num(c, j, "near", &R_POS, &nr), has_far;
	if (has_near < 0 || (has_far = get_num(c, j, "far", &R_POS, &fr)) < 0) return -1;
	if (has_near && has_far && !(fr > nr))
		return fail_at(c, "far", "far (%g) must be greater than near (%g)", fr, nr);
	if (has_near) cam->near = (float)nr;
	if (has_far) cam->far = (float)fr;
	float dir[3];
	if ((rc = get_vec(c, j, "direction", dir, 3, 3, V_NONZERO)) < 0) return -1;
	if (rc && fit < 0) return fail_at(c, "direction", "direction is only used with fit");
	if (rc) memcpy(cam->fit_direction, dir, sizeof dir);
	float mg = 0;
	if ((rc = get_float(c, j, "margin", &margin, &mg)) < 0) return -1;
	if (rc && fit < 0) return fail_at(c, "margin", "margin is only used with fit");
	if (rc) cam->fit_margin = mg;
	if (fit >= 0) {
		cam->fit = fit ? RND_FIT_OBJECTS : RND_FIT_SCENE;
		if (cam->fit_direction[0] == 0 && cam->fit_direction[1] == 0 && cam->fit_direction[2] == 0) {
			/* No direction and none from the defaults: a three-quarter view from above. */
			cam->fit_direction[0] = -1; cam->fit_direction[1] = -0.75f; cam->fit_direction[2] = -1;
		}
	} else {
		cam->fit = RND_FIT_NONE;
		if (!memcmp(cam->position, cam->target, sizeof cam->position))
			return fail_at(c, json_object_get(j, "target") ? "target" : "position",
			               "target must differ from position (the view direction would be zero)");
	}
	return 0;
}

/* ---- root ---- */

static const char *const ROOT_MEMBERS[] = {"width", "height", "camera", "environment", "materials", "objects",
                                           "lights", "shadows", "output", "views", "turntable", "preset", NULL};
static const char *const ENV_MEMBERS[] = {"background", "ambient", NULL};
static const char *const AMBIENT_MEMBERS[] = {"sky", "ground", "intensity", NULL};
static const char *const OUTPUT_MEMBERS[] = {"format", "bit_depth", "transparent", "tonemap", "msaa", "aovs",
                                             "debug", "debug_light", "png_level", NULL};
static const char *const TURNTABLE_MEMBERS[] = {"frames", "elevation", "distance", NULL};

static int parse_environment(struct pctx *c, json_t *j, struct rnd_environment *env)
{
	if (require_object(c, j, "environment") < 0 ||
	    check_members(c, j, ENV_MEMBERS, NULL, "the environment") < 0)
		return -1;
	float bg[4] = {0, 0, 0, 1};
	int n = get_vec(c, j, "background", bg, 3, 4, V_NONNEG | V_ALPHA01);
	if (n < 0) return -1;
	if (n) memcpy(env->background, bg, sizeof bg);
	json_t *sub;
	size_t old;
	int rc = enter(c, j, "ambient", AMBIENT_MEMBERS, "the ambient light", &sub, &old);
	if (rc < 0) return -1;
	if (rc) {
		rc = get_vec(c, sub, "sky", env->ambient_sky, 3, 3, V_NONNEG) < 0 ||
		     get_vec(c, sub, "ground", env->ambient_ground, 3, 3, V_NONNEG) < 0 ||
		     get_float(c, sub, "intensity", &R_NONNEG, &env->ambient_intensity) < 0;
		ptr_pop(c, old);
		if (rc) return -1;
	}
	return 0;
}

static int parse_output(struct pctx *c, json_t *j, struct api_scene *s)
{
	struct rnd_output *o = &s->scene.output;
	if (require_object(c, j, "output") < 0 || check_members(c, j, OUTPUT_MEMBERS, NULL, "output") < 0)
		return -1;
	static const char *const formats[] = {"png", "exr", NULL};
	static const char *const tonemaps[] = {"neutral", "aces", "none", NULL};
	static const enum rnd_tonemap tonemap_values[] = {RND_TONEMAP_NEUTRAL, RND_TONEMAP_ACES, RND_TONEMAP_NONE};
	static const char *const debugs[] = {"none", "shadow", "cascades", "normals", "depth", "atlas", NULL};
	static const enum rnd_debug debug_values[] = {RND_DEBUG_NONE, RND_DEBUG_SHADOW, RND_DEBUG_CASCADES,
	                                              RND_DEBUG_NORMALS, RND_DEBUG_DEPTH, RND_DEBUG_ATLAS};
	int e, rc;
	if ((rc = get_enum(c, j, "format", formats, &e)) < 0) return -1;
	if (rc) {
		s->format = e ? API_FORMAT_EXR : API_FORMAT_PNG;
		s->format_explicit = 1;
	}
	if ((rc = get_u32(c, j, "bit_depth", 8, 16, &s->bit_depth)) < 0) return -1;
	if (rc && s->bit_depth != 8 && s->bit_depth != 16)
		return fail_at(c, "bit_depth", "bit_depth must be 8 or 16 (got %u)", s->bit_depth);
	if (get_bool(c, j, "transparent", &o->transparent) < 0) return -1;
	if ((rc = get_enum(c, j, "tonemap", tonemaps, &e)) < 0) return -1;
	if (rc) o->tonemap = tonemap_values[e];
	if ((rc = get_u32(c, j, "msaa", 1, 4, &o->msaa)) < 0) return -1;
	if (rc && o->msaa != 1 && o->msaa != 4) return fail_at(c, "msaa", "msaa must be 1 or 4 (got %u)", o->msaa);
	if ((rc = get_enum(c, j, "debug", debugs, &e)) < 0) return -1;
	if (rc) o->debug = debug_values[e];
	if (get_u32(c, j, "debug_light", 0, UINT32_MAX, &o->debug_light) < 0) return -1;
	long long lvl;
	if ((rc = get_int(c, j, "png_level", -1, 9, &lvl)) < 0) return -1;
	if (rc) s->png_level = (int)lvl;
	json_t *a = json_object_get(j, "aovs");
	if (a) {
		size_t old = ptr_push(c, "aovs");
		static const char *const aovs[] = {"shadow", "depth", "normal", "albedo", NULL};
		static const uint32_t aov_bits[] = {RND_AOV_SHADOW, RND_AOV_DEPTH, RND_AOV_NORMAL, RND_AOV_ALBEDO};
		rc = 0;
		if (!json_is_array(a)) rc = fail(c, "aovs must be an array of names, not %s", type_name(a));
		for (size_t i = 0; !rc && i < json_array_size(a); i++) {
			size_t o2 = ptr_index(c, i);
			if (check_enum(c, "each aov", json_array_get(a, i), aovs, &e) < 0) rc = -1;
			ptr_pop(c, o2);
			if (rc) break;
			if (o->aovs & aov_bits[e]) rc = fail(c, "aovs lists \"%s\" twice", aovs[e]);
			o->aovs |= aov_bits[e];
		}
		/* The default format is PNG, which has no room for AOVs. Without an explicit format the
		 * request may still choose EXR (Accept, the CLI's -o name): api_scene_check_output()
		 * decides once that choice is made. */
		if (!rc && o->aovs && s->format_explicit && s->format == API_FORMAT_PNG)
			rc = fail(c, "aovs need format \"exr\": a PNG has no room for AOV channels");
		ptr_pop(c, old);
		if (rc) return -1;
	}
	return 0;
}

static void set_pixels(struct api_scene *s)
{
	if (s->format == API_FORMAT_EXR) s->scene.output.pixels = RND_PIXELS_RGBA32F;
	else s->scene.output.pixels = s->bit_depth == 16 ? RND_PIXELS_RGBA16 : RND_PIXELS_RGBA8;
}

/* Replaces every model object by one mesh object per instance of its model, under the
 * object's transform, with the model's materials (appended to the scene's) unless the object
 * names its own. Returns 0 or -1 (out of memory / too many objects). */
static int expand_models(struct pctx *c, json_t *objs, struct api_model *const *models, struct rnd_scene *sc)
{
	uint64_t nobj = 0, nmat = c->mat_count;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		nobj += models[i] ? models[i]->instance_count : 1;
		if (models[i] && !json_object_get(json_array_get(objs, i), "material")) nmat += models[i]->material_count;
	}
	if (nobj > UINT32_MAX / 2 || nmat > UINT32_MAX / 2) return fail(c, "the scene has too many objects");
	struct rnd_object *objects = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *objects);
	struct rnd_material *mats = api_arena_calloc(c->arena, nmat ? nmat : 1, sizeof *mats);
	uint32_t *source = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *source);
	if (!objects || !mats || !source) return fail(c, "out of memory");
	c->object_source = source;
	memcpy(mats, c->mats, c->mat_count * sizeof *mats);
	uint32_t no = 0, nm = c->mat_count;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct api_model *m = models[i];
		if (!m) {
			source[no] = i;
			objects[no++] = sc->objects[i];
			continue;
		}
		bool own = json_object_get(json_array_get(objs, i), "material") != NULL;
		uint32_t base = nm;
		if (!own) {
			memcpy(mats + nm, m->materials, m->material_count * sizeof *mats);
			nm += m->material_count;
		}
		for (uint32_t k = 0; k < m->instance_count; k++) {
			const struct api_model_instance *in = &m->instances[k];
			const struct api_model_mesh *me = &m->meshes[in->mesh];
			source[no] = i;
			struct rnd_object *o = &objects[no++];
			*o = sc->objects[i];   /* shadows, sidedness, material override */
			o->shape = RND_SHAPE_MESH;
			o->positions = me->positions;
			o->vertex_count = me->vertex_count;
			o->indices = me->indices;
			o->index_count = me->index_count;
			o->normals = me->normals;
			o->uvs = me->uvs;
			o->lods = me->lods;
			o->lod_count = me->lod_count;
			o->closed = me->closed;
			rnd_mat4_mul(o->model, sc->objects[i].model, in->model);
			if (!own) o->material = base + me->material;
		}
	}
	c->mats = mats;
	c->mat_count = c->mat_cap = nm;
	sc->objects = objects;
	sc->object_count = no;
	return 0;
}

/* ---- several views ---- */

#define MAX_VIEWS 1024u
/* The renderer's bounds on a sheet (renderer/render.c rnd_render()). */
#define MAX_SHEET_SIDE 65536u
#define MAX_SHEET_PIXELS (1ull << 28)

struct turntable {
	uint32_t frames;      /* 0 = no turntable */
	double elevation;     /* degrees */
	double distance;      /* 0 = fitted */
};

/* Centre and radius of the scene's "objects" bounds: every object except planes and shadow
 * catchers (all objects when that leaves none; the unit sphere at the origin when empty). */
static void objects_sphere(const struct rnd_scene *sc, const struct rnd_material *mats, double centre[3],
                           double *radius)
{
	double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
	for (int pass = 0; pass < 2 && lo[0] > hi[0]; pass++)
		for (uint32_t i = 0; i < sc->object_count; i++) {
			const struct rnd_object *o = &sc->objects[i];
			if (!pass && (o->shape == RND_SHAPE_PLANE || mats[o->material].shadow_catcher)) continue;
			api_object_bounds(o, lo, hi);
		}
	if (lo[0] > hi[0]) {
		centre[0] = centre[1] = centre[2] = 0;
		*radius = 1;
		return;
	}
	double d2 = 0;
	for (int k = 0; k < 3; k++) {
		centre[k] = 0.5 * (lo[k] + hi[k]);
		d2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
	}
	*radius = fmax(0.5 * sqrt(d2), 1e-3);
}


/* The turntable's cameras: frame k looks at the objects' bounds centre from azimuth 360°·k/N
 * (frame 0 on +Z, then counter-clockwise seen from above, i.e. towards +X) at the elevation,
 * from `distance`, or else from where the bounding sphere fills the frame up to a 0.1 margin
 * (as camera fit does). Perspective, up +Y, fov_y from the root camera when it is a perspective
 * one (else 45°), exposure from the root camera; near/far derived from the scene bounds (a
 * root camera's near/far were chosen for its own position). */
static int turntable_views(struct pctx *c, const struct turntable *tt, struct rnd_scene *sc)
{
	struct rnd_camera *vs = api_arena_calloc(c->arena, tt->frames, sizeof *vs);
	if (!vs) return fail_at(c, "turntable", "out of memory");
	double centre[3], r;
	objects_sphere(sc, c->mats, centre, &r);
	const struct rnd_camera *root = &sc->camera;
	double fov = root->type == RND_CAMERA_PERSPECTIVE && root->fov_y > 0 ? root->fov_y : 45.0 * DEG2RAD;
	double dist = tt->distance;
	if (!(dist > 0)) {
		double aspect = (double)sc->width / sc->height, half = 0.5 * fov * (1.0 - 2.0 * 0.1);
		double half_x = atan(tan(half) * fmin(aspect, 1.0));
		dist = r / sin(fmin(half, half_x));
	}
	double el = tt->elevation * DEG2RAD;
	for (uint32_t k = 0; k < tt->frames; k++) {
		struct rnd_camera *v = &vs[k];
		double az = 2.0 * M_PI * k / tt->frames;
		/* Unit vector from the centre to the camera (the view direction is its opposite). */
		double d[3] = {cos(el) * sin(az), sin(el), cos(el) * cos(az)};
		v->type = RND_CAMERA_PERSPECTIVE;
		for (int i = 0; i < 3; i++) {
			v->target[i] = (float)centre[i];
			v->position[i] = (float)(centre[i] + dist * d[i]);
			v->fit_direction[i] = (float)-d[i];
		}
		v->up[0] = 0; v->up[1] = 1; v->up[2] = 0;
		v->fov_y = (float)fov;
		v->exposure = root->exposure;
		v->fit = RND_FIT_NONE;
		v->fit_margin = 0.1f;
	}
	sc->views = vs;
	sc->view_count = tt->frames;
	return 0;
}

/* Places the planes with placement "ground" under the other objects (models expanded). */
static int place_ground(struct pctx *c, struct rnd_scene *sc)
{
	float *margin = api_arena_calloc(c->arena, sc->object_count ? sc->object_count : 1, sizeof *margin);
	if (!margin) return fail(c, "out of memory");
	for (uint32_t i = 0; i < sc->object_count; i++)
		margin[i] = c->ground_margin[c->object_source ? c->object_source[i] : i];
	api_ground_place((struct rnd_object *)sc->objects, sc->object_count, c->mats, margin);
	return 0;
}

static int parse_root(struct pctx *c, json_t *root, struct api_scene *s)
{
	struct rnd_scene *sc = &s->scene;
	if (!json_is_object(root)) return fail(c, "the scene document must be a JSON object, not %s", type_name(root));
	if (check_members(c, root, ROOT_MEMBERS, NULL, "the scene") < 0) return -1;
	if (get_u32(c, root, "width", 1, 8192, &sc->width) < 0 || get_u32(c, root, "height", 1, 8192, &sc->height) < 0)
		return -1;

	/* Objects are counted first: they size the material array (inline materials). */
	json_t *objs = json_object_get(root, "objects");
	if (!objs) return fail_at(c, "objects", "objects is required (it may be an empty array)");
	if (!json_is_array(objs)) return fail_at(c, "objects", "objects must be an array, not %s", type_name(objs));
	size_t nobj = json_array_size(objs);

	json_t *mats = json_object_get(root, "materials");
	size_t nmat = 0;
	if (mats) {
		if (!json_is_object(mats))
			return fail_at(c, "materials", "materials must be an object mapping names to materials, not %s",
			               type_name(mats));
		nmat = json_object_size(mats);
	}
	if (nobj > UINT32_MAX / 2 || nmat > UINT32_MAX / 2) return fail(c, "the scene has too many objects");
	c->mat_cap = (uint32_t)(nmat + nobj + 1);
	c->mats = api_arena_calloc(c->arena, c->mat_cap, sizeof *c->mats);
	struct rnd_object *objects = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *objects);
	c->ground_margin = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *c->ground_margin);
	c->mat_index = json_object();
	if (!c->mats || !objects || !c->ground_margin || !c->mat_index) return fail(c, "out of memory");
	if (mats) {
		size_t old = ptr_push(c, "materials");
		const char *name;
		json_t *m;
		int rc = 0;
		json_object_foreach(mats, name, m) {
			size_t o2 = ptr_push(c, name);
			uint32_t mi = 0;
			rc = add_material(c, &mi);
			if (!rc) rc = parse_material(c, m, &c->mats[mi], "a material");
			if (!rc) json_object_set_new(c->mat_index, name, json_integer(mi));
			ptr_pop(c, o2);
			if (rc) break;
		}
		ptr_pop(c, old);
		if (rc) return -1;
	}

	/* `camera` is required unless `views` or `turntable` gives the cameras; when present with
	 * them it supplies the defaults of every view (views: each member not given; turntable:
	 * fov_y, near, far, exposure). */
	json_t *cam = json_object_get(root, "camera"), *views = json_object_get(root, "views"),
	       *turn = json_object_get(root, "turntable");
	if (cam) {
		size_t old = ptr_push(c, "camera");
		int rc = parse_camera(c, cam, &sc->camera);
		ptr_pop(c, old);
		if (rc < 0) return -1;
	} else if (!views && !turn) {
		return fail_at(c, "camera", "camera is required (unless views or turntable gives the cameras)");
	}
	if (views && turn) return fail_at(c, "turntable", "turntable cannot be combined with views");
	if (views) {
		size_t old = ptr_push(c, "views");
		int rc = 0;
		size_t n = json_is_array(views) ? json_array_size(views) : 0;
		struct rnd_camera *vs = NULL;
		if (!n) rc = fail(c, "views must be a non-empty array of cameras");
		else if (n > MAX_VIEWS) rc = fail(c, "views has %zu cameras, at most %u are allowed", n, MAX_VIEWS);
		else if (!(vs = api_arena_calloc(c->arena, n, sizeof *vs))) rc = fail(c, "out of memory");
		for (size_t i = 0; !rc && i < n; i++) {
			vs[i] = sc->camera;
			size_t o2 = ptr_index(c, i);
			rc = parse_camera(c, json_array_get(views, i), &vs[i]);
			ptr_pop(c, o2);
		}
		ptr_pop(c, old);
		if (rc) return -1;
		sc->views = vs;
		sc->view_count = (uint32_t)n;
	}
	struct turntable tt = {0};
	if (turn) {
		json_t *sub;
		size_t old;
		int rc = enter(c, root, "turntable", TURNTABLE_MEMBERS, "turntable", &sub, &old);
		if (rc < 0) return -1;
		static const struct range elev = {-90, 90, false, false};
		long long frames = 0;
		double el = 20, dist = 0;
		rc = get_int(c, sub, "frames", 1, MAX_VIEWS, &frames);
		if (rc == 0) rc = fail_at(c, "frames", "frames is required for a turntable");
		if (rc > 0 && (get_num(c, sub, "elevation", &elev, &el) < 0 || get_num(c, sub, "distance", &R_POS, &dist) < 0))
			rc = -1;
		ptr_pop(c, old);
		if (rc < 0) return -1;
		tt.frames = (uint32_t)frames;
		tt.elevation = el;
		tt.distance = dist;
	}

	json_t *env = json_object_get(root, "environment");
	if (env) {
		size_t old = ptr_push(c, "environment");
		int rc = parse_environment(c, env, &sc->environment);
		ptr_pop(c, old);
		if (rc < 0) return -1;
	}

	{
		size_t old = ptr_push(c, "objects");
		uint64_t total = 0;
		int rc = 0;
		struct api_model **models = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *models);
		if (!models) return fail(c, "out of memory");
		for (size_t i = 0; i < nobj; i++) {
			size_t o2 = ptr_index(c, i);
			c->cur_model = NULL;
			c->cur_object = i;
			rc = parse_object(c, json_array_get(objs, i), &objects[i]);
			models[i] = c->cur_model;
			if (!rc) {
				uint64_t t = models[i] ? models[i]->triangles : rnd_object_triangle_count(&objects[i]);
				total += t;
				s->triangles = total;
				uint64_t max = c->lim->max_triangles;
				if (max && t > max)
					defer(c, false, (objects[i].shape == RND_SHAPE_SPHERE ||
					                 objects[i].shape == RND_SHAPE_CYLINDER) ? "segments" : NULL,
					      "this object has %llu triangles, over this server's limit of %llu",
					      (unsigned long long)t, (unsigned long long)max);
				else if (max && total > max)
					defer(c, false, NULL, "the scene has more than %llu triangles (this server's limit) "
					      "with this object", (unsigned long long)max);
			}
			ptr_pop(c, o2);
			if (rc) break;
		}
		ptr_pop(c, old);
		if (rc) return -1;
		sc->objects = objects;
		sc->object_count = (uint32_t)nobj;
		if (c->models && expand_models(c, objs, models, sc) < 0) return -1;
		if (place_ground(c, sc) < 0) return -1;
	}
	if (tt.frames && turntable_views(c, &tt, sc) < 0) return -1;
	/* `fit` (scene or objects) stays for the renderer: it frames the bounds tightly to the
	 * margin, leaving planes and shadow catchers out for `objects`. */
	struct rnd_shadow root_shadow;
	rnd_shadow_defaults(&root_shadow);
	json_t *shj = json_object_get(root, "shadows");
	if (json_is_boolean(shj)) {
		root_shadow.enabled = json_is_true(shj);
	} else if (shj) {
		size_t old = ptr_push(c, "shadows");
		int rc = parse_shadow(c, shj, &root_shadow, "shadows");
		ptr_pop(c, old);
		if (rc < 0) return -1;
	}

	json_t *lights = json_object_get(root, "lights");
	if (lights) {
		if (!json_is_array(lights))
			return fail_at(c, "lights", "lights must be an array, not %s", type_name(lights));
		size_t n = json_array_size(lights);
		if (n > UINT32_MAX / 2) return fail_at(c, "lights", "too many lights");
		struct rnd_light *ls = api_arena_calloc(c->arena, n ? n : 1, sizeof *ls);
		if (!ls) return fail(c, "out of memory");
		size_t old = ptr_push(c, "lights");
		int rc = 0;
		for (size_t i = 0; !rc && i < n; i++) {
			size_t o2 = ptr_index(c, i);
			rc = parse_light(c, json_array_get(lights, i), &ls[i], &root_shadow);
			ptr_pop(c, o2);
		}
		if (!rc && c->lim->max_lights && n > c->lim->max_lights)
			defer(c, false, NULL, "the scene has %zu lights, over this server's limit of %u", n,
			      c->lim->max_lights);
		ptr_pop(c, old);
		if (rc) return -1;
		sc->lights = ls;
		sc->light_count = (uint32_t)n;
	}

	json_t *out = json_object_get(root, "output");
	if (out) {
		size_t old = ptr_push(c, "output");
		int rc = parse_output(c, out, s);
		if (!rc) {
			bool given = json_object_get(out, "debug_light") != NULL;
			uint32_t dl = sc->output.debug_light;
			if (given && dl >= sc->light_count)
				rc = fail_at(c, "debug_light", "debug_light %u names no light (the scene has %u)", dl,
				             sc->light_count);
			else if (!given && sc->output.debug == RND_DEBUG_SHADOW && sc->light_count == 0)
				rc = fail_at(c, "debug", "debug \"shadow\" shows light debug_light (0), but the scene "
				             "has no lights");
		}
		ptr_pop(c, old);
		if (rc < 0) return -1;
	}
	set_pixels(s);

	uint64_t px = (uint64_t)sc->width * sc->height;
	if (c->lim->max_pixels && px > c->lim->max_pixels)
		defer(c, false, sc->height > sc->width ? "height" : "width",
		      "width x height = %llu pixels is over this server's limit of %llu", (unsigned long long)px,
		      (unsigned long long)c->lim->max_pixels);
	if (sc->view_count) {
		/* Several views: the whole sheet counts (ceil(sqrt(n)) columns, unused cells included). */
		uint32_t n = sc->view_count, cols = 1;
		while (cols * cols < n) cols++;
		uint32_t rows = (n + cols - 1) / cols;
		uint64_t sw = (uint64_t)cols * sc->width, sh = (uint64_t)rows * sc->height, sheet = sw * sh;
		const char *key = views ? "views" : "turntable";
		c->views_key = key;
		if (c->lim->max_pixels && sheet > c->lim->max_pixels)
			defer(c, false, key, "%u views of %ux%u make a %llux%llu sheet (%llu pixels), over this server's "
			      "limit of %llu", n, sc->width, sc->height, (unsigned long long)sw, (unsigned long long)sh,
			      (unsigned long long)sheet, (unsigned long long)c->lim->max_pixels);
		else if (sw > MAX_SHEET_SIDE || sh > MAX_SHEET_SIDE || sheet > MAX_SHEET_PIXELS)
			defer(c, false, key, "%u views of %ux%u make a %llux%llu sheet, over the renderer's limit (%u per "
			      "side, %llu pixels)", n, sc->width, sc->height, (unsigned long long)sw, (unsigned long long)sh,
			      MAX_SHEET_SIDE, (unsigned long long)MAX_SHEET_PIXELS);
	}

	sc->materials = c->mats;
	sc->material_count = c->mat_count;
	const struct rnd_texture *seen[MAX_TEXTURES];
	uint32_t ntex = 0;
	for (uint32_t i = 0; i < c->mat_count && ntex <= MAX_TEXTURES; i++) {
		const struct rnd_texture *t = c->mats[i].base_color_texture;
		uint32_t k = 0;
		while (t && k < ntex && seen[k] != t) k++;
		if (!t || k < ntex) continue;
		if (ntex == MAX_TEXTURES) {
			defer(c, false, "materials", "the scene has more than %u distinct base-colour textures (the "
			      "renderer's limit)", MAX_TEXTURES);
			break;
		}
		seen[ntex++] = t;
	}
	return 0;
}

enum api_result api_scene_parse(const char *json, size_t len, const struct api_limits *limits,
                                struct api_scene **out, struct api_problem *p)
{
	return api_scene_parse_parts(json, len, limits, NULL, 0, out, p);
}

enum api_result api_scene_parse_parts(const char *json, size_t len, const struct api_limits *limits,
                                      const struct api_part *parts, size_t nparts,
                                      struct api_scene **out, struct api_problem *p)
{
	struct api_problem scratch;
	struct api_limits deflim;
	if (!p) p = &scratch;
	if (!out) return api_problem_set(p, 500, "", "api_scene_parse: no output pointer");
	*out = NULL;
	if (!limits) {
		api_limits_defaults(&deflim);
		limits = &deflim;
	}
	if (!json) json = "", len = 0;

	json_error_t je;
	json_t *root = json_loadb(json, len, JSON_REJECT_DUPLICATES, &je);
	if (!root) {
		api_problem_set(p, 400, "", "malformed JSON at line %d, column %d: %s", je.line, je.column, je.text);
		snprintf(p->type, sizeof p->type, PROBLEMS "malformed-json");
		snprintf(p->title, sizeof p->title, "Malformed JSON");
		return API_ERR;
	}
	if (api_preset_apply(&root, p) < 0) {
		json_decref(root);
		return API_ERR;
	}
	struct pctx c = {.p = p, .lim = limits, .default_mat = UINT32_MAX, .parts = parts, .nparts = nparts};
	c.arena = api_arena_create();
	struct api_scene *s = c.arena ? api_arena_alloc(c.arena, sizeof *s) : NULL;
	if (!s) {
		json_decref(root);
		api_arena_destroy(c.arena);
		return api_problem_set(p, 500, "", "out of memory parsing the scene");
	}
	s->arena_ = c.arena;
	rnd_scene_defaults(&s->scene);
	s->format = API_FORMAT_PNG;
	s->bit_depth = 8;
	s->png_level = -1;

	int rc = parse_root(&c, root, s);
	json_decref(c.mat_index);
	json_decref(root);
	if (rc == 0 && c.pending) {
		*p = c.pend;
		rc = -1;
	}
	if (rc < 0) {
		model_refs_release(c.models);
		api_arena_destroy(c.arena);
		return API_ERR;
	}
	s->models_ = c.models;
	s->object_source_ = c.object_source;
	s->views_key_ = c.views_key;
	s->asset_hash = c.asset_hash;
	*out = s;
	return API_OK;
}

void api_scene_free(struct api_scene *s)
{
	/* The scene itself lives in its arena; the models it points into are referenced. */
	if (!s) return;
	model_refs_release(s->models_);
	api_arena_destroy(s->arena_);
}

enum api_result api_scene_check_output(const struct api_scene *s, struct api_problem *p)
{
	struct api_problem scratch;
	if (!p) p = &scratch;
	if (s && s->format == API_FORMAT_PNG && s->scene.output.aovs)
		return api_problem_set(p, 400, "/output/aovs", "aovs need an EXR answer (output.format \"exr\", "
		                       "Accept: image/x-exr, or an .exr output file): the default format PNG has no room "
		                       "for AOV channels");
	return API_OK;
}

enum api_result api_scene_set_format(struct api_scene *s, enum api_format f, struct api_problem *p)
{
	struct api_problem scratch;
	if (!p) p = &scratch;
	if (!s) return api_problem_set(p, 500, "", "api_scene_set_format: no scene");
	if (f == API_FORMAT_PNG && s->scene.output.aovs)
		return api_problem_set(p, 400, "/output/aovs", "aovs need format \"exr\": a PNG has no room for AOV "
		                       "channels");
	s->format = f;
	s->format_explicit = 1;
	set_pixels(s);
	return API_OK;
}
