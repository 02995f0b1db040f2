/*
 * api/json_walk.c — walking a JSON document for the scene parser (see scene_internal.h): the
 * RFC 6901 pointer of the member being checked, 400 and deferred 422 problems at that pointer,
 * unknown-member checks with near-miss suggestions, and typed getters (numbers in ranges,
 * integers, enums, vectors, base64 blobs, mesh arrays).
 *
 * Vectors (colours, positions, quaternions, matrices, mesh arrays) are reported at the member,
 * never at one element: "/lights/0/color" with "color must not have negative components".
 * Pure (jansson only): every function works on one pctx, so parses run in parallel.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base64.h"
#include "scene_internal.h"

/* ---- JSON Pointer of the member being checked ---- */

size_t api_ptr_push(struct pctx *c, const char *key)
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

size_t api_ptr_index(struct pctx *c, size_t i)
{
	char b[24];
	snprintf(b, sizeof b, "%zu", i);
	return api_ptr_push(c, b);
}

void api_ptr_pop(struct pctx *c, size_t old)
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

/* 400 at the current pointer. Returns -1 so callers can `return api_fail(...)`. */
void api_warn(struct pctx *c, const char *fmt, ...)
{
	size_t n = strlen(c->warnings);
	if (n && n + 2 < sizeof c->warnings) memcpy(c->warnings + n, "; ", 3), n += 2;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(c->warnings + n, sizeof c->warnings - n, fmt, ap);
	va_end(ap);
}

int api_fail(struct pctx *c, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vfail(c, fmt, ap);
	va_end(ap);
	return -1;
}

/* 400 at the member `key` of the current object. */
int api_fail_at(struct pctx *c, const char *key, const char *fmt, ...)
{
	size_t old = api_ptr_push(c, key);
	va_list ap;
	va_start(ap, fmt);
	vfail(c, fmt, ap);
	va_end(ap);
	api_ptr_pop(c, old);
	return -1;
}

/* Records a 422 at the current pointer (plus `key` when not NULL) unless one is recorded. */
void api_defer(struct pctx *c, bool unsupported, const char *key, const char *fmt, ...)
{
	if (c->pending) return;
	size_t old = key ? api_ptr_push(c, key) : c->len;
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
	api_ptr_pop(c, old);
}

const char *api_type_name(const json_t *v)
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

bool api_free_member(const char *key)
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

/* The member key of obj was read into the parsed scene (scene_internal.h). Out of memory:
 * c->reads_lost, and the whole document is hashed as it came. */
void api_member_read(struct pctx *c, json_t *obj, const char *key)
{
	if (c->reads_lost) return;
	if (c->nreads == c->reads_cap) {
		size_t cap = c->reads_cap ? 2 * c->reads_cap : 64;
		struct api_member_read *r = realloc(c->reads, cap * sizeof *r);
		if (!r) {
			c->reads_lost = true;
			return;
		}
		c->reads = r;
		c->reads_cap = cap;
	}
	c->reads[c->nreads++] = (struct api_member_read){obj, key};
}

/* Rejects members of obj named in neither list. `what` names the object in the message. */
int api_check_members(struct pctx *c, json_t *obj, const char *const *list, const char *const *list2,
                         const char *what)
{
	const char *key;
	json_t *v;
	json_object_foreach(obj, key, v) {
		if (api_free_member(key) || in_list(key, list) || in_list(key, list2)) continue;
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
			return api_fail_at(c, key, "unknown member \"%.64s\" in %s (did you mean \"%s\"?)", key, what, best);
		return api_fail_at(c, key, "unknown member \"%.64s\" in %s (only \"extras\" and names starting with "
		               "\"x-\" may be added)", key, what);
	}
	return 0;
}


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

int api_check_num(struct pctx *c, const char *name, json_t *v, const struct range *r, double *out)
{
	if (!json_is_number(v)) return api_fail(c, "%s must be a number, not %s", name, api_type_name(v));
	double d = json_number_value(v);
	if (!in_range(d, r)) {
		char t[128];
		range_text(t, sizeof t, r);
		return api_fail(c, "%s must be %s (got %g)", name, t, d);
	}
	*out = d;
	return 0;
}

int api_get_num(struct pctx *c, json_t *obj, const char *key, const struct range *r, double *out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = api_ptr_push(c, key);
	int rc = api_check_num(c, key, v, r, out);
	api_ptr_pop(c, old);
	if (rc < 0) return -1;
	api_member_read(c, obj, key);
	return 1;
}

int api_get_float(struct pctx *c, json_t *obj, const char *key, const struct range *r, float *out)
{
	double d;
	int rc = api_get_num(c, obj, key, r, &d);
	if (rc == 1) *out = (float)d;
	return rc;
}

/* Degrees in the document, radians in the scene. */
int api_get_angle(struct pctx *c, json_t *obj, const char *key, const struct range *r, float *out)
{
	double d;
	int rc = api_get_num(c, obj, key, r, &d);
	if (rc == 1) *out = (float)(d * DEG2RAD);
	return rc;
}

int api_check_int(struct pctx *c, const char *name, json_t *v, long long lo, long long hi, long long *out)
{
	long long i;
	if (json_is_integer(v)) {
		i = json_integer_value(v);
	} else if (json_is_real(v)) {
		double d = json_real_value(v);
		/* 2.0 is an integer in JSON's number model. */
		if (d != floor(d) || d < -9e15 || d > 9e15)
			return api_fail(c, "%s must be an integer (got %g)", name, d);
		i = (long long)d;
	} else {
		return api_fail(c, "%s must be an integer, not %s", name, api_type_name(v));
	}
	if (i < lo || i > hi) return api_fail(c, "%s must be between %lld and %lld (got %lld)", name, lo, hi, i);
	*out = i;
	return 0;
}

int api_get_int(struct pctx *c, json_t *obj, const char *key, long long lo, long long hi, long long *out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = api_ptr_push(c, key);
	int rc = api_check_int(c, key, v, lo, hi, out);
	api_ptr_pop(c, old);
	if (rc < 0) return -1;
	api_member_read(c, obj, key);
	return 1;
}

int api_get_u32(struct pctx *c, json_t *obj, const char *key, long long lo, long long hi, uint32_t *out)
{
	long long i;
	int rc = api_get_int(c, obj, key, lo, hi, &i);
	if (rc == 1) *out = (uint32_t)i;
	return rc;
}

int api_get_bool(struct pctx *c, json_t *obj, const char *key, bool *out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	if (!json_is_boolean(v)) return api_fail_at(c, key, "%s must be true or false, not %s", key, api_type_name(v));
	*out = json_is_true(v);
	api_member_read(c, obj, key);
	return 1;
}

int api_get_string(struct pctx *c, json_t *obj, const char *key, const char **out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	if (!json_is_string(v)) return api_fail_at(c, key, "%s must be a string, not %s", key, api_type_name(v));
	*out = json_string_value(v);
	return 1;
}

int api_check_enum(struct pctx *c, const char *name, json_t *v, const char *const *names, int *out)
{
	char list[256];
	size_t n = 0;
	list[0] = 0;
	for (int i = 0; names[i]; i++)
		n += (size_t)snprintf(list + n, n < sizeof list ? sizeof list - n : 0, "%s\"%s\"", i ? ", " : "",
		                      names[i]);
	if (!json_is_string(v)) return api_fail(c, "%s must be one of %s, not %s", name, list, api_type_name(v));
	const char *s = json_string_value(v);
	for (int i = 0; names[i]; i++)
		if (!strcmp(s, names[i])) { *out = i; return 0; }
	return api_fail(c, "%s must be one of %s (got \"%.40s\")", name, list, s);
}

int api_get_enum(struct pctx *c, json_t *obj, const char *key, const char *const *names, int *out)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = api_ptr_push(c, key);
	int rc = api_check_enum(c, key, v, names, out);
	api_ptr_pop(c, old);
	if (rc < 0) return -1;
	api_member_read(c, obj, key);
	return 1;
}


/* A fixed-size vector of nmin..nmax numbers. Returns the count (>0), 0 when absent, -1. */
int api_check_vec(struct pctx *c, const char *name, json_t *v, float *out, int nmin, int nmax, unsigned flags)
{
	char want[32];
	if (nmin == nmax) snprintf(want, sizeof want, "%d numbers", nmin);
	else snprintf(want, sizeof want, "%d or %d numbers", nmin, nmax);
	if (!json_is_array(v)) return api_fail(c, "%s must be an array of %s, not %s", name, want, api_type_name(v));
	size_t n = json_array_size(v);
	if (n < (size_t)nmin || n > (size_t)nmax) return api_fail(c, "%s must have %s (got %zu)", name, want, n);
	double tmp[16], len2 = 0;
	for (size_t i = 0; i < n; i++) {
		json_t *e = json_array_get(v, i);
		if (!json_is_number(e))
			return api_fail(c, "element %zu of %s must be a number, not %s", i, name, api_type_name(e));
		double d = json_number_value(e);
		if (!in_range(d, &R_ANY)) return api_fail(c, "element %zu of %s is out of range (got %g)", i, name, d);
		tmp[i] = d;
		len2 += d * d;
	}
	for (size_t i = 0; i < n; i++) {
		bool alpha = (flags & V_ALPHA01) && i == 3;
		if (alpha && (tmp[i] < 0 || tmp[i] > 1))
			return api_fail(c, "the alpha of %s must be between 0 and 1 (got %g)", name, tmp[i]);
		if ((flags & V_NONNEG) && tmp[i] < 0)
			return api_fail(c, "%s must not have negative components (element %zu is %g)", name, i, tmp[i]);
		if ((flags & V_POS) && !(tmp[i] > 0))
			return api_fail(c, "%s components must be greater than 0 (element %zu is %g)", name, i, tmp[i]);
		if ((flags & V_NOZERO_COMP) && tmp[i] == 0)
			return api_fail(c, "%s components must not be 0 (element %zu is 0)", name, i);
	}
	if ((flags & V_NONZERO) && !(len2 > 0)) return api_fail(c, "%s must not be zero", name);
	for (size_t i = 0; i < n; i++) out[i] = (float)tmp[i];
	return (int)n;
}

int api_get_vec(struct pctx *c, json_t *obj, const char *key, float *out, int nmin, int nmax, unsigned flags)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = api_ptr_push(c, key);
	int rc = api_check_vec(c, key, v, out, nmin, nmax, flags);
	api_ptr_pop(c, old);
	if (rc > 0) api_member_read(c, obj, key);
	return rc;
}

int api_require_object(struct pctx *c, json_t *v, const char *name)
{
	if (!json_is_object(v)) return api_fail(c, "%s must be an object, not %s", name, api_type_name(v));
	return 0;
}

/* ---- base64 and binary arrays ---- */

/* Decodes a base64 member into the arena. Returns 0 or -1 (400 at the current pointer). */
int api_decode_b64_member(struct pctx *c, const char *name, json_t *v, unsigned char **out, size_t *len)
{
	size_t n;
	const char *s = api_big_string(c->big, v, &n);
	size_t cap = api_base64_decoded_max(n);
	unsigned char *buf = api_arena_alloc(c->arena, cap);
	if (!buf) return api_fail(c, "%s is too large to decode (out of memory)", name);
	size_t bad = 0, got = 0;
	if (api_base64_decode(s, n, buf, cap, &got, &bad) != API_OK) {
		if (bad < n) return api_fail(c, "%s is not valid base64 (bad character at offset %zu)", name, bad);
		return api_fail(c, "%s is not valid base64 (truncated or over-padded)", name);
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
int api_get_data(struct pctx *c, json_t *obj, const char *key, bool indices, void **out, size_t *count)
{
	json_t *v = json_object_get(obj, key);
	if (!v) return 0;
	size_t old = api_ptr_push(c, key);
	int rc = -1;
	const char *kind = indices ? "non-negative integers" : "numbers";
	if (json_is_array(v)) {
		size_t n = json_array_size(v);
		uint32_t *u = api_arena_calloc(c->arena, n ? n : 1, 4);
		if (!u) { api_fail(c, "%s is too large (out of memory)", key); goto out; }
		float *f = (float *)u;
		for (size_t i = 0; i < n; i++) {
			json_t *e = json_array_get(v, i);
			if (!json_is_number(e)) {
				api_fail(c, "element %zu of %s must be a number, not %s", i, key, api_type_name(e));
				goto out;
			}
			double d = json_number_value(e);
			if (indices) {
				if (d < 0 || d > 4294967295.0 || d != floor(d)) {
					api_fail(c, "element %zu of %s must be an integer between 0 and 4294967295 (got %g)", i,
					     key, d);
					goto out;
				}
				u[i] = (uint32_t)d;
			} else {
				if (!in_range(d, &R_ANY)) {
					api_fail(c, "element %zu of %s is out of range (got %g)", i, key, d);
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
		if (api_decode_b64_member(c, key, v, &b, &n) < 0) goto out;
		if (n % 4) {
			api_fail(c, "%s must decode to whole 4-byte little-endian values (got %zu bytes)", key, n);
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
					api_fail(c, "element %zu of %s is not a finite number", i, key);
					goto out;
				}
			}
			u[i] = w;
		}
		*out = u;
		*count = n / 4;
		rc = 1;
	} else {
		api_fail(c, "%s must be an array of %s or a base64 string, not %s", key, kind, api_type_name(v));
	}
out:
	api_ptr_pop(c, old);
	return rc;
}

/* Enters the sub-object `key` of j: 1 when present (pointer pushed, *old set), 0 absent, -1. */
int api_enter(struct pctx *c, json_t *j, const char *key, const char *const *members, const char *what,
                 json_t **sub, size_t *old)
{
	*sub = json_object_get(j, key);
	if (!*sub) return 0;
	*old = api_ptr_push(c, key);
	if (api_require_object(c, *sub, key) < 0 || api_check_members(c, *sub, members, NULL, what) < 0) {
		api_ptr_pop(c, *old);
		return -1;
	}
	return 1;
}

