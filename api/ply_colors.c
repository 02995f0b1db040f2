/*
 * api/ply_colors — face colours to vertex colours, and point clouds (see ply_colors.h).
 *
 * The rewrite copies each corner's vertex record as it is (the bytes of a binary record, the
 * text of an ASCII one) and appends the face's colour, so positions, normals and uvs keep
 * their exact values and types; only the face element is written anew.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "ply_colors.h"
#include "ply_header.h"

static const char *const COLOR_NAMES[2][4] = {
	{"red", "green", "blue", "alpha"},
	{"diffuse_red", "diffuse_green", "diffuse_blue", "diffuse_alpha"},
};

/* The face element's colour properties (-1 where absent); false when it has no red/green/blue. */
static bool color_props(const struct api_ply_elem *e, int idx[4])
{
	for (int set = 0; set < 2; set++) {
		for (int k = 0; k < 4; k++) idx[k] = api_ply_prop_index(e, COLOR_NAMES[set][k]);
		if (idx[0] >= 0 && idx[1] >= 0 && idx[2] >= 0) return true;
	}
	return false;
}

/* A colour value as a byte: integers as stored (16 and 32 bits scaled down), floats 0..1. */
static uint8_t color_byte(enum api_ply_type t, double v)
{
	double x = t == API_PLY_F32 || t == API_PLY_F64 ? v * 255.0 : t == API_PLY_U16 || t == API_PLY_I16 ? v / 257.0
	           : t == API_PLY_U32 || t == API_PLY_I32 ? v / 16843009.0 : v;
	return (uint8_t)(!(x >= 0) ? 0 : x > 255 ? 255 : lrint(x));
}

struct out {
	uint8_t *d;
	size_t n, cap;
	bool bad;
};

static void put(struct out *o, const void *b, size_t n)
{
	if (o->bad) return;
	if (o->n + n > o->cap) {
		size_t cap = o->cap * 2 + n + 4096;
		uint8_t *d = realloc(o->d, cap);
		if (!d) { o->bad = true; return; }
		o->d = d;
		o->cap = cap;
	}
	memcpy(o->d + o->n, b, n);
	o->n += n;
}

static void put_str(struct out *o, const char *s)
{
	put(o, s, strlen(s));
}

static void put_int(struct out *o, enum api_ply_format f, uint32_t v, char sep)
{
	if (f == API_PLY_ASCII) {
		char buf[16];
		snprintf(buf, sizeof buf, "%c%u", sep, v);
		put_str(o, sep ? buf : buf + 1);
		return;
	}
	uint8_t b[4];
	for (int i = 0; i < 4; i++) b[f == API_PLY_BE ? 3 - i : i] = (uint8_t)(v >> (8 * i));
	put(o, b, 4);
}

/* Where each vertex record lies in the data (start[i], end[i]), reading from r->at; false
 * when a vertex property is a list or the data is cut short. */
static bool vertex_records(struct api_ply_reader *r, const struct api_ply_elem *v, size_t *start, size_t *end)
{
	for (uint64_t i = 0; i < v->count; i++) {
		double x;
		if (r->format == API_PLY_ASCII)
			while (r->at < r->len && (r->d[r->at] == ' ' || r->d[r->at] == '\t' || r->d[r->at] == '\r' ||
			                          r->d[r->at] == '\n'))
				r->at++;
		start[i] = r->at;
		for (int k = 0; k < v->nprops; k++)
			if (v->props[k].list || !api_ply_read(r, v->props[k].type, &x)) return false;
		end[i] = r->at;
	}
	return true;
}

static void write_header(struct out *o, const struct api_ply_header *h, uint64_t corners, uint64_t faces)
{
	static const char *const fmt[] = {"ascii", "binary_little_endian", "binary_big_endian"};
	char line[256];
	snprintf(line, sizeof line, "ply\nformat %s 1.0\nelement vertex %llu\n", fmt[h->format],
	         (unsigned long long)corners);
	put_str(o, line);
	const struct api_ply_elem *v = &h->elems[0];
	for (int k = 0; k < v->nprops; k++) {
		snprintf(line, sizeof line, "property %s %s\n", api_ply_type_name(v->props[k].type), v->props[k].name);
		put_str(o, line);
	}
	snprintf(line, sizeof line, "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n"
	         "element face %llu\nproperty list uchar int vertex_indices\nend_header\n", (unsigned long long)faces);
	put_str(o, line);
}

struct face_layout {
	int indices;        /* the vertex index list */
	int color[4];       /* red, green, blue, alpha (-1: 255) */
};

/* One face: reads it from r and writes its corners (vertex record + colour) to verts and the
 * face to faces; *next is the next new vertex's index. false on bad data. */
static bool one_face(struct api_ply_reader *r, const struct api_ply_header *h, const struct face_layout *fl,
                     const size_t *vs, const size_t *ve, struct out *verts, struct out *faces, uint64_t *next)
{
	const struct api_ply_elem *f = &h->elems[1];
	uint8_t rgba[4] = {255, 255, 255, 255};
	size_t list_at = 0;
	double corners = 0, n, x;
	for (int k = 0; k < f->nprops; k++) {
		const struct api_ply_prop *p = &f->props[k];
		if (p->list) {
			if (!api_ply_read(r, p->count_type, &n) || n < 0 || n > (double)(r->len - r->at)) return false;
			if (k == fl->indices) list_at = r->at, corners = n;
			for (double m = 0; m < n; m++)
				if (!api_ply_read(r, p->type, &x)) return false;
			continue;
		}
		if (!api_ply_read(r, p->type, &x)) return false;
		for (int c = 0; c < 4; c++)
			if (k == fl->color[c]) rgba[c] = color_byte(p->type, x);
	}
	/* The indices again, now that the colour is known (it may come after them). */
	struct api_ply_reader ir = {r->d, r->len, list_at, r->format};
	const struct api_ply_elem *v = &h->elems[0];
	if (corners > 255) return false;   /* the count is a uchar, as Assimp 5.2 reads lists best */
	if (h->format == API_PLY_ASCII) put_int(faces, h->format, (uint32_t)corners, 0);
	else put(faces, &(uint8_t){(uint8_t)corners}, 1);
	for (double m = 0; m < corners; m++) {
		if (!api_ply_read(&ir, f->props[fl->indices].type, &x) || !(x >= 0) || x >= (double)v->count ||
		    *next >= INT32_MAX)
			return false;
		size_t i = (size_t)x;
		put(verts, r->d + vs[i], ve[i] - vs[i]);
		if (h->format == API_PLY_ASCII) {
			char col[24];
			snprintf(col, sizeof col, " %u %u %u %u\n", rgba[0], rgba[1], rgba[2], rgba[3]);
			put_str(verts, col);
		} else {
			put(verts, rgba, 4);
		}
		put_int(faces, h->format, (uint32_t)(*next)++, ' ');
	}
	if (h->format == API_PLY_ASCII) put_str(faces, "\n");
	return true;
}

/* The layout of the face element: false unless it has an index list and a colour. */
static bool face_layout(const struct api_ply_header *h, struct face_layout *fl)
{
	const struct api_ply_elem *f = &h->elems[1];
	fl->indices = api_ply_prop_index(f, "vertex_indices");
	if (fl->indices < 0) fl->indices = api_ply_prop_index(f, "vertex_index");
	return fl->indices >= 0 && f->props[fl->indices].list && color_props(f, fl->color);
}

uint8_t *api_ply_face_colors_to_vertices(const uint8_t *d, size_t len, size_t *out_len)
{
	struct api_ply_header h;
	struct face_layout fl;
	int rgb[4];
	if (!api_ply_header_parse(d, len, &h) || h.nelems != 2 || strcmp(h.elems[0].name, "vertex") ||
	    strcmp(h.elems[1].name, "face") || !face_layout(&h, &fl) || color_props(&h.elems[0], rgb))
		return NULL;
	/* A vertex takes at least one byte of the input: counts beyond it are cut short. */
	uint64_t nv = h.elems[0].count;
	if (!nv || nv > len || !h.elems[1].count || h.elems[1].count > len) return NULL;
	size_t *vs = malloc((size_t)nv * sizeof *vs), *ve = malloc((size_t)nv * sizeof *ve);
	struct out verts = {0}, faces = {0}, all = {0};
	struct api_ply_reader r = {d, len, h.data, h.format};
	uint64_t next = 0;
	bool ok = vs && ve && vertex_records(&r, &h.elems[0], vs, ve);
	for (uint64_t i = 0; ok && i < h.elems[1].count; i++)
		ok = one_face(&r, &h, &fl, vs, ve, &verts, &faces, &next) && !verts.bad && !faces.bad;
	if (ok) {
		write_header(&all, &h, next, h.elems[1].count);
		put(&all, verts.d, verts.n);
		put(&all, faces.d, faces.n);
		ok = !all.bad && next > 0;
	}
	free(vs);
	free(ve);
	free(verts.d);
	free(faces.d);
	if (!ok) {
		free(all.d);
		return NULL;
	}
	*out_len = all.n;
	return all.d;
}

uint64_t api_ply_point_cloud(const uint8_t *d, size_t len)
{
	struct api_ply_header h;
	if (!api_ply_header_parse(d, len, &h)) return 0;
	int v = api_ply_elem_index(&h, "vertex"), f = api_ply_elem_index(&h, "face"),
	    s = api_ply_elem_index(&h, "tristrips");
	bool surface = (f >= 0 && h.elems[f].count) || (s >= 0 && h.elems[s].count);
	return v >= 0 && !surface ? h.elems[v].count : 0;
}
