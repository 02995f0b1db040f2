/*
 * api/ply_header — PLY headers and values (see ply_header.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "ply_header.h"

static const struct {
	const char *name;
	enum api_ply_type type;
} TYPES[] = {
	{"char", API_PLY_I8}, {"int8", API_PLY_I8}, {"uchar", API_PLY_U8}, {"uint8", API_PLY_U8},
	{"short", API_PLY_I16}, {"int16", API_PLY_I16}, {"ushort", API_PLY_U16}, {"uint16", API_PLY_U16},
	{"int", API_PLY_I32}, {"int32", API_PLY_I32}, {"uint", API_PLY_U32}, {"uint32", API_PLY_U32},
	{"float", API_PLY_F32}, {"float32", API_PLY_F32}, {"double", API_PLY_F64}, {"float64", API_PLY_F64},
};

static enum api_ply_type type_of(const char *name)
{
	for (size_t i = 0; i < sizeof TYPES / sizeof TYPES[0]; i++)
		if (!strcmp(name, TYPES[i].name)) return TYPES[i].type;
	return API_PLY_NONE;
}

int api_ply_type_size(enum api_ply_type t)
{
	static const int size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
	return t >= API_PLY_NONE && t <= API_PLY_F64 ? size[t] : 0;
}

const char *api_ply_type_name(enum api_ply_type t)
{
	static const char *const names[] = {"?", "char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
	return t >= API_PLY_NONE && t <= API_PLY_F64 ? names[t] : "?";
}

/* One header line into buf (no newline, no CR); the offset after it, or 0 at the end. */
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

/* A property line into the last element; false when it cannot be read. */
static bool add_prop(struct api_ply_header *h, const char *line)
{
	char a[32], b[32], c[32];
	if (!h->nelems || h->elems[h->nelems - 1].nprops == API_PLY_MAX_PROPS) return false;
	struct api_ply_elem *e = &h->elems[h->nelems - 1];
	struct api_ply_prop *p = &e->props[e->nprops];
	memset(p, 0, sizeof *p);
	if (sscanf(line, "property list %31s %31s %31s", a, b, c) == 3) {
		p->list = true;
		p->count_type = type_of(a);
		p->type = type_of(b);
		snprintf(p->name, sizeof p->name, "%s", c);
		if (!p->count_type || p->count_type >= API_PLY_F32) return false;
	} else if (sscanf(line, "property %31s %31s", a, b) == 2) {
		p->type = type_of(a);
		snprintf(p->name, sizeof p->name, "%s", b);
	} else {
		return false;
	}
	if (!p->type) return false;
	e->nprops++;
	return true;
}

bool api_ply_header_parse(const uint8_t *d, size_t len, struct api_ply_header *h)
{
	char line[256];
	memset(h, 0, sizeof *h);
	size_t at = header_line(d, len, 0, line, sizeof line);
	if (!at || strcmp(line, "ply")) return false;
	int format = -1;
	while ((at = header_line(d, len, at, line, sizeof line))) {
		char a[32];
		unsigned long long n;
		if (!strcmp(line, "end_header")) {
			h->data = at;
			h->format = (enum api_ply_format)format;
			return format >= 0 && h->nelems;
		}
		if (sscanf(line, "format %31s", a) == 1) {
			format = !strcmp(a, "ascii") ? API_PLY_ASCII : !strcmp(a, "binary_little_endian") ? API_PLY_LE
			         : !strcmp(a, "binary_big_endian") ? API_PLY_BE : -1;
			if (format < 0) return false;
		} else if (sscanf(line, "element %31s %llu", a, &n) == 2) {
			if (h->nelems == API_PLY_MAX_ELEMS) return false;
			struct api_ply_elem *e = &h->elems[h->nelems++];
			snprintf(e->name, sizeof e->name, "%s", a);
			e->count = n;
		} else if (!strncmp(line, "property", 8) && !add_prop(h, line)) {
			return false;
		}
		/* comment and obj_info lines are skipped */
	}
	return false;
}

int api_ply_elem_index(const struct api_ply_header *h, const char *name)
{
	for (int i = 0; i < h->nelems; i++)
		if (!strcmp(h->elems[i].name, name)) return i;
	return -1;
}

int api_ply_prop_index(const struct api_ply_elem *e, const char *name)
{
	for (int i = 0; i < e->nprops; i++)
		if (!strcmp(e->props[i].name, name)) return i;
	return -1;
}

static bool is_space(uint8_t ch)
{
	return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n';
}

static bool read_ascii(struct api_ply_reader *r, double *v)
{
	while (r->at < r->len && is_space(r->d[r->at])) r->at++;
	char buf[64];
	size_t n = 0;
	while (r->at < r->len && !is_space(r->d[r->at])) {
		if (n + 1 < sizeof buf) buf[n++] = (char)r->d[r->at];
		r->at++;
	}
	buf[n] = 0;
	char *end;
	*v = strtod(buf, &end);
	return n && !*end;
}

bool api_ply_read(struct api_ply_reader *r, enum api_ply_type t, double *v)
{
	if (r->format == API_PLY_ASCII) return read_ascii(r, v);
	int size = api_ply_type_size(t);
	if (!size || r->len - r->at < (size_t)size) return false;
	uint8_t b[8];
	for (int i = 0; i < size; i++) b[i] = r->d[r->at + (size_t)(r->format == API_PLY_BE ? size - 1 - i : i)];
	r->at += (size_t)size;
	uint64_t u = 0;
	for (int i = size - 1; i >= 0; i--) u = u << 8 | b[i];
	switch (t) {
	case API_PLY_I8: *v = (int8_t)u; break;
	case API_PLY_U8: case API_PLY_U16: case API_PLY_U32: *v = (double)u; break;
	case API_PLY_I16: *v = (int16_t)u; break;
	case API_PLY_I32: *v = (int32_t)u; break;
	case API_PLY_F32: { float f; uint32_t w = (uint32_t)u; memcpy(&f, &w, 4); *v = f; break; }
	default: { double f; memcpy(&f, &u, 8); *v = f; break; }
	}
	return true;
}
