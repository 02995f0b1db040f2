/*
 * api/ply_strips.c — PLY files whose surface is a `tristrips` element (range scans, e.g. the
 * Stanford models) rewritten with a `face` element of triangles before Assimp reads them: Assimp
 * 5.2 takes the strip for one polygon and the model came out as a flat sliver with no error
 * (and its strip reader leaks each triangle's index array: make test-asan). Little and big
 * endian and ASCII alike.
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
#include "ply_header.h"

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

/* Walks one element's data (binary or ASCII, api/ply_header.h), calling on_list for the first
 * list property of each instance when given. 0 when the data is cut short. */
typedef int (*list_fn)(void *user, const int64_t *items, uint64_t n);

static int walk(struct api_ply_reader *r, const struct api_ply_elem *x, list_fn fn, void *user, int64_t *scratch,
                uint64_t scratch_cap)
{
	for (uint64_t i = 0; i < x->count; i++) {
		for (int k = 0; k < x->nprops; k++) {
			const struct api_ply_prop *p = &x->props[k];
			double v;
			if (!p->list) {
				if (!api_ply_read(r, p->type, &v)) return 0;
				continue;
			}
			if (!api_ply_read(r, p->count_type, &v) || !(v >= 0) || v > (double)r->len) return 0;
			uint64_t n = (uint64_t)v;
			if (r->format != API_PLY_ASCII && n > (r->len - r->at) / (size_t)api_ply_type_size(p->type)) return 0;
			if (fn && n > scratch_cap) return 0;
			for (uint64_t m = 0; m < n; m++) {
				if (!api_ply_read(r, p->type, &v) || !(v > -4e18 && v < 4e18)) return 0;
				if (fn) scratch[m] = (int64_t)v;
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
	struct api_ply_header h;
	if (!api_ply_header_parse(d, len, &h) || !h.nelems) return NULL;
	const struct api_ply_elem *el = h.elems;
	int nel = h.nelems, binary = h.format != API_PLY_ASCII;
	size_t data = h.data, start[API_PLY_MAX_ELEMS], end[API_PLY_MAX_ELEMS];
	int strips = api_ply_elem_index(&h, "tristrips"), vi = api_ply_elem_index(&h, "vertex");
	uint64_t vertices = vi >= 0 ? el[vi].count : 0;
	if (api_ply_elem_index(&h, "face") >= 0) return NULL;
	if (strips < 0 || el[strips].nprops != 1 || !el[strips].props[0].list || !vertices || vertices > INT32_MAX)
		return NULL;
	/* Each strip index yields at most one triangle; an index takes at least one input byte. */
	uint64_t cap = len;
	struct tris t = {calloc((size_t)cap, 3 * sizeof(int32_t)), 0, cap, vertices};
	int64_t *scratch = malloc((size_t)cap * sizeof *scratch);
	uint8_t *out = NULL;
	if (!t.idx || !scratch) goto done;
	struct api_ply_reader r = {d, len, data, h.format};
	for (int i = 0; i < nel; i++) {
		start[i] = r.at;
		if (!walk(&r, &el[i], i == strips ? strip_to_tris : NULL, &t, scratch, cap)) goto done;
		end[i] = r.at;
	}
	if (!t.n) goto done;
	/* header + other elements' bytes + faces (13 bytes binary, at most 36 characters ASCII) */
	size_t size = data + 64 + (len - data) + (size_t)t.n * 40;
	out = malloc(size);
	if (!out) goto done;
	size_t o = write_header(d, data, t.n, out);
	for (int i = 0; i < nel; i++) {
		if (i != strips) {
			memcpy(out + o, d + start[i], end[i] - start[i]);
			o += end[i] - start[i];
			continue;
		}
		for (uint64_t k = 0; k < t.n; k++) {
			const int32_t *v = &t.idx[3 * k];
			if (binary) {
				/* in the file's byte order (the machines we build for are little endian) */
				int32_t be[3] = {(int32_t)__builtin_bswap32((uint32_t)v[0]), (int32_t)__builtin_bswap32((uint32_t)v[1]),
				                 (int32_t)__builtin_bswap32((uint32_t)v[2])};
				out[o++] = 3;
				memcpy(out + o, h.format == API_PLY_BE ? be : v, 12);
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
