/*
 * api/ply_strips.c — PLY files whose surface is a `tristrips` element (range scans, e.g. the
 * Stanford models) rewritten with a `face` element of triangles before Assimp reads them: Assimp
 * 5.2 takes the strip for one polygon and the model came out as a flat sliver with no error.
 *
 * Runs inside the import sandbox (api/sandbox_child.c) on untrusted bytes: every read is
 * bounded by the input, every count by what the input can hold. Anything it does not
 * understand is left to Assimp unchanged (returns NULL).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "ply_strips.h"

enum { MAX_PROPS = 32, MAX_ELEMS = 16 };

struct ply_prop {
	int list;                 /* 1: list property */
	int count_size, item_size; /* bytes (binary); count_size unused for scalars */
	int item_signed;
};

struct ply_elem {
	char name[32];
	uint64_t count;
	int nprops;
	struct ply_prop props[MAX_PROPS];
	size_t start, end;        /* byte range of its data */
};

static int type_size(const char *t, int *is_signed)
{
	static const struct { const char *name; int size, sgn; } types[] = {
		{"char", 1, 1}, {"int8", 1, 1}, {"uchar", 1, 0}, {"uint8", 1, 0}, {"short", 2, 1}, {"int16", 2, 1},
		{"ushort", 2, 0}, {"uint16", 2, 0}, {"int", 4, 1}, {"int32", 4, 1}, {"uint", 4, 0}, {"uint32", 4, 0},
		{"float", 4, 1}, {"float32", 4, 1}, {"double", 8, 1}, {"float64", 8, 1},
	};
	for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
		if (!strcmp(t, types[i].name)) {
			*is_signed = types[i].sgn;
			return types[i].size;
		}
	return 0;
}

/* Reads one header line into buf (without the newline); the offset after it, or 0. */
static size_t header_line(const uint8_t *d, size_t len, size_t at, char *buf, size_t size)
{
	size_t n = 0;
	while (at < len && d[at] != '\n') {
		if (n + 1 < size && d[at] != '\r') buf[n++] = (char)d[at];
		at++;
	}
	buf[n] = 0;
	return at < len ? at + 1 : 0;
}

/* Parses the header; the offset of the data, or 0. */
static size_t parse_header(const uint8_t *d, size_t len, int *binary, struct ply_elem *el, int *nel)
{
	char line[256];
	size_t at = header_line(d, len, 0, line, sizeof line);
	if (!at || strcmp(line, "ply")) return 0;
	*nel = 0;
	*binary = -1;
	while ((at = header_line(d, len, at, line, sizeof line))) {
		char a[32], b[32], c[32], e[32];
		unsigned long long n;
		if (!strcmp(line, "end_header")) return *binary >= 0 && *nel ? at : 0;
		if (sscanf(line, "format %31s", a) == 1) {
			*binary = !strcmp(a, "ascii") ? 0 : !strcmp(a, "binary_little_endian") ? 1 : -2;
			if (*binary == -2) return 0; /* big endian: left to Assimp */
		} else if (sscanf(line, "element %31s %llu", a, &n) == 2) {
			if (*nel == MAX_ELEMS) return 0;
			struct ply_elem *x = &el[(*nel)++];
			memset(x, 0, sizeof *x);
			snprintf(x->name, sizeof x->name, "%s", a);
			x->count = n;
		} else if (sscanf(line, "property list %31s %31s %31s", a, b, c) == 3) {
			if (!*nel || el[*nel - 1].nprops == MAX_PROPS) return 0;
			struct ply_prop *p = &el[*nel - 1].props[el[*nel - 1].nprops++];
			int s;
			p->list = 1;
			p->count_size = type_size(a, &s);
			p->item_size = type_size(b, &p->item_signed);
			if (!p->count_size || !p->item_size) return 0;
		} else if (sscanf(line, "property %31s %31s", a, e) == 2) {
			if (!*nel || el[*nel - 1].nprops == MAX_PROPS) return 0;
			struct ply_prop *p = &el[*nel - 1].props[el[*nel - 1].nprops++];
			p->item_size = type_size(a, &p->item_signed);
			if (!p->item_size) return 0;
		}
		/* comment / obj_info lines are skipped */
	}
	return 0;
}

static uint64_t read_uint(const uint8_t *p, int size)
{
	uint64_t v = 0;
	for (int i = size - 1; i >= 0; i--) v = v << 8 | p[i];
	return v;
}

static int64_t read_int(const uint8_t *p, int size, int is_signed)
{
	uint64_t v = read_uint(p, size);
	if (is_signed && size < 8 && (v >> (8 * size - 1)) & 1) v |= ~(uint64_t)0 << (8 * size);
	return (int64_t)v;
}

/* ASCII: the next whitespace-separated token from *at; its value in *v. 0 at the end. */
static int ascii_token(const uint8_t *d, size_t len, size_t *at, int64_t *v)
{
	while (*at < len && (d[*at] == ' ' || d[*at] == '\t' || d[*at] == '\r' || d[*at] == '\n')) (*at)++;
	if (*at >= len) return 0;
	char buf[40];
	size_t n = 0;
	while (*at < len && !(d[*at] == ' ' || d[*at] == '\t' || d[*at] == '\r' || d[*at] == '\n')) {
		if (n + 1 < sizeof buf) buf[n++] = (char)d[*at];
		(*at)++;
	}
	buf[n] = 0;
	*v = strtoll(buf, NULL, 10);
	return 1;
}

/* Walks one element's data from *at (binary or ASCII), calling on_list for the first list
 * property of each instance when given. 0 when the data is cut short. */
typedef int (*list_fn)(void *user, const int64_t *items, uint64_t n);

static int walk(const uint8_t *d, size_t len, int binary, const struct ply_elem *x, size_t *at, list_fn fn,
                void *user, int64_t *scratch, uint64_t scratch_cap)
{
	for (uint64_t i = 0; i < x->count; i++) {
		for (int k = 0; k < x->nprops; k++) {
			const struct ply_prop *p = &x->props[k];
			int64_t v;
			if (!p->list) {
				if (binary) {
					if (len - *at < (size_t)p->item_size) return 0;
					*at += (size_t)p->item_size;
				} else if (!ascii_token(d, len, at, &v)) {
					return 0;
				}
				continue;
			}
			uint64_t n;
			if (binary) {
				if (len - *at < (size_t)p->count_size) return 0;
				n = read_uint(d + *at, p->count_size);
				*at += (size_t)p->count_size;
				if (n > (len - *at) / (size_t)p->item_size) return 0;
			} else {
				if (!ascii_token(d, len, at, &v) || v < 0 || (uint64_t)v > len) return 0;
				n = (uint64_t)v;
			}
			if (fn && n > scratch_cap) return 0;
			for (uint64_t m = 0; m < n; m++) {
				if (binary) {
					v = read_int(d + *at, p->item_size, p->item_signed);
					*at += (size_t)p->item_size;
				} else if (!ascii_token(d, len, at, &v)) {
					return 0;
				}
				if (fn) scratch[m] = v;
			}
			if (fn && k == 0 && !fn(user, scratch, n)) return 0;
		}
	}
	return 1;
}

struct tris {
	int32_t *idx;
	uint64_t n, cap;       /* triangles */
	uint64_t vertices;
};

/* Strip -> triangles: (s[k], s[k+1], s[k+2]) with the winding flipped on odd k, -1 restarts the
 * strip, degenerate triangles (a repeated index) are dropped. */
static int strip_to_tris(void *user, const int64_t *s, uint64_t n)
{
	struct tris *t = user;
	uint64_t start = 0;
	for (uint64_t i = 0; i < n; i++) {
		if (s[i] < 0) { start = i + 1; continue; }
		if ((uint64_t)s[i] >= t->vertices) return 0;
		if (i < start + 2) continue;
		int64_t a = s[i - 2], b = s[i - 1], c = s[i];
		if ((i - start) % 2) { int64_t x = a; a = b; b = x; }
		if (a == b || b == c || a == c) continue;
		if (t->n == t->cap) return 0;
		t->idx[3 * t->n] = (int32_t)a;
		t->idx[3 * t->n + 1] = (int32_t)b;
		t->idx[3 * t->n + 2] = (int32_t)c;
		t->n++;
	}
	return 1;
}

/* Copies the header with the tristrips element (line and its property lines) replaced by a
 * face element of n triangles. */
static size_t write_header(const uint8_t *d, size_t hdr_end, uint64_t ntris, uint8_t *out)
{
	size_t o = 0, at = 0;
	char line[256];
	int in_strips = 0;
	while (at < hdr_end) {
		size_t next = header_line(d, hdr_end, at, line, sizeof line);
		if (!next) next = hdr_end;
		char a[32];
		unsigned long long n;
		if (sscanf(line, "element %31s %llu", a, &n) == 2) in_strips = !strcmp(a, "tristrips");
		if (in_strips && !strncmp(line, "element", 7))
			o += (size_t)sprintf((char *)out + o, "element face %llu\nproperty list uchar int vertex_indices\n",
			                     (unsigned long long)ntris);
		else if (!in_strips || strncmp(line, "property", 8)) {
			memcpy(out + o, d + at, next - at);
			o += next - at;
		}
		at = next;
	}
	return o;
}

uint8_t *api_ply_strips_to_faces(const uint8_t *d, size_t len, size_t *out_len)
{
	struct ply_elem el[MAX_ELEMS];
	int nel, binary;
	size_t data = parse_header(d, len, &binary, el, &nel);
	if (!data) return NULL;
	int strips = -1;
	uint64_t vertices = 0;
	for (int i = 0; i < nel; i++) {
		if (!strcmp(el[i].name, "face")) return NULL;
		if (!strcmp(el[i].name, "tristrips")) strips = i;
		if (!strcmp(el[i].name, "vertex")) vertices = el[i].count;
	}
	if (strips < 0 || el[strips].nprops != 1 || !el[strips].props[0].list || !vertices || vertices > INT32_MAX)
		return NULL;
	/* Each strip index yields at most one triangle; an index takes at least one input byte. */
	uint64_t cap = len;
	struct tris t = {calloc((size_t)cap, 3 * sizeof(int32_t)), 0, cap, vertices};
	int64_t *scratch = malloc((size_t)cap * sizeof *scratch);
	uint8_t *out = NULL;
	if (!t.idx || !scratch) goto done;
	size_t at = data;
	for (int i = 0; i < nel; i++) {
		el[i].start = at;
		if (!walk(d, len, binary, &el[i], &at, i == strips ? strip_to_tris : NULL, &t, scratch, cap)) goto done;
		el[i].end = at;
	}
	if (!t.n) goto done;
	/* header + other elements' bytes + faces (13 bytes binary, at most 36 characters ASCII) */
	size_t size = data + 64 + (len - data) + (size_t)t.n * 40;
	out = malloc(size);
	if (!out) goto done;
	size_t o = write_header(d, data, t.n, out);
	for (int i = 0; i < nel; i++) {
		if (i != strips) {
			memcpy(out + o, d + el[i].start, el[i].end - el[i].start);
			o += el[i].end - el[i].start;
			continue;
		}
		for (uint64_t k = 0; k < t.n; k++) {
			const int32_t *v = &t.idx[3 * k];
			if (binary) {
				out[o++] = 3;
				memcpy(out + o, v, 12); /* little endian on the machines we build for */
				o += 12;
			} else {
				o += (size_t)sprintf((char *)out + o, "\n3 %d %d %d", v[0], v[1], v[2]);
			}
		}
		if (!binary) out[o++] = '\n';
	}
	*out_len = o;
done:
	free(t.idx);
	free(scratch);
	return out;
}
