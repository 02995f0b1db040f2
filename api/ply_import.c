/*
 * api/ply_import.c — PLY without Assimp (see ply_import.h).
 *
 * Assimp 5.2 reads a PLY's vertices and faces as they are (shared vertices, faces as lists of
 * their indices), with its own number parsing for ASCII (fast_atof, strtol10), its own colour
 * scaling per type and a white default material; then triangulates quads, makes normals
 * (GenSmoothNormals on shared vertices: each vertex takes its last face's normal, summed only
 * with vertices at the same position) and joins identical vertices (api/assimp_post.h does
 * those three the same way). This reads the same values the same way: x, y, z; nx, ny, nz;
 * red, green, blue, alpha (or r, g, b); u, v (or s, t, tx, ty, texture_u, texture_v) of a
 * vertex, of any scalar type, other vertex properties skipped; a face's vertex_indices (or
 * vertex_index) list of 3 or 4 integers.
 *
 * Strips and face colours are first rewritten as the Assimp path rewrites them
 * (api/ply_strips.h, api/ply_colors.h); a file with face colours is then post-processed
 * without Assimp's join and joined by api_join_vertices where it has no uvs, as that path does.
 *
 * Left to Assimp, for its behaviour and its messages (and api/model_import.c's point cloud
 * refusal): elements other than one vertex and one face element in that order, face properties other than the index list, lists among a
 * vertex's properties, a property named twice, a texture file in the header, faces of other
 * than 3 or 4 corners, indices out of range, data cut short, an ASCII file not written one
 * element a line or with numbers Assimp would read differently, a binary file whose data
 * starts with a line feed byte (Assimp drops it, taking it for the end of the header's line),
 * and a file of no triangle with an area.
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "assimp_post.h"
#include "errmsg.h"
#include "model_conv.h"
#include "model_import.h"
#include "ply_colors.h"
#include "ply_strips.h"
#include "model_wire.h"
#include "ply_header.h"
#include "ply_import.h"
#include "umbra/rnd_math.h"

#define NOT_MINE API_PLY_NOT_MINE
#define NO_MEMORY (-3)   /* (not NOT_MINE, nor API_ASSIMP_POST_GIVE_UP) */

/* What a vertex property is to Assimp's LoadVertex. */
enum sem { SEM_NONE, SEM_X, SEM_Y, SEM_Z, SEM_NX, SEM_NY, SEM_NZ, SEM_R, SEM_G, SEM_B, SEM_A, SEM_U, SEM_V, SEM_COUNT };

static enum sem semantic_of(const char *n)
{
	static const struct {
		const char *name;
		enum sem sem;
	} names[] = {
		{"x", SEM_X}, {"y", SEM_Y}, {"z", SEM_Z}, {"nx", SEM_NX}, {"ny", SEM_NY}, {"nz", SEM_NZ},
		{"red", SEM_R}, {"green", SEM_G}, {"blue", SEM_B}, {"alpha", SEM_A}, {"r", SEM_R}, {"g", SEM_G},
		{"b", SEM_B}, {"u", SEM_U}, {"s", SEM_U}, {"tx", SEM_U}, {"texture_u", SEM_U}, {"v", SEM_V},
		{"t", SEM_V}, {"ty", SEM_V}, {"texture_v", SEM_V},
	};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
		if (!strcmp(n, names[i].name)) return names[i].sem;
	return SEM_NONE;
}

/* One value as Assimp's PropertyInstance::ValueUnion holds it. */
struct value {
	enum api_ply_type type;
	union { uint32_t u; int32_t i; float f; double d; };
};

static bool is_unsigned(enum api_ply_type t)
{
	return t == API_PLY_U8 || t == API_PLY_U16 || t == API_PLY_U32;
}

/* ConvertTo<float> */
static float as_float(const struct value *v)
{
	return v->type == API_PLY_F32 ? v->f : v->type == API_PLY_F64 ? (float)v->d
	       : is_unsigned(v->type) ? (float)v->u : (float)v->i;
}

/* ConvertTo<unsigned int> */
static uint32_t as_uint(const struct value *v)
{
	return is_unsigned(v->type) ? v->u : (uint32_t)v->i;
}

/* PLYImporter::NormalizeColorValue, type by type (its uint divides by 0xFFFF, its int is
 * x / 255 + 0.5). */
static float as_colour(const struct value *v)
{
	switch (v->type) {
	case API_PLY_F32: return v->f;
	case API_PLY_F64: return (float)v->d;
	case API_PLY_U8: return (float)v->u / (float)0xFF;
	case API_PLY_I8: return (float)(v->i + (0xFF / 2)) / (float)0xFF;
	case API_PLY_U16: return (float)v->u / (float)0xFFFF;
	case API_PLY_I16: return (float)(v->i + (0xFFFF / 2)) / (float)0xFFFF;
	case API_PLY_U32: return (float)v->u / (float)0xFFFF;
	case API_PLY_I32: return ((float)v->i / (float)0xFF) + 0.5f;
	default: return 0.0f;
	}
}

/* The data after the header: binary values in order, or ASCII tokens one element a line. */
struct reader {
	const uint8_t *d;
	size_t len, at;
	enum api_ply_format format;
	size_t line_end;      /* ASCII: the end of the current line */
};

static bool read_binary(struct reader *r, enum api_ply_type t, struct value *v)
{
	int size = api_ply_type_size(t);
	if (r->len - r->at < (size_t)size) return false;
	uint8_t b[8];
	for (int k = 0; k < size; k++) b[k] = r->d[r->at + (size_t)(r->format == API_PLY_BE ? size - 1 - k : k)];
	r->at += (size_t)size;
	v->type = t;
	switch (t) {
	case API_PLY_U8: v->u = b[0]; break;
	case API_PLY_I8: v->i = (int8_t)b[0]; break;
	case API_PLY_U16: { uint16_t x; memcpy(&x, b, 2); v->u = x; break; }
	case API_PLY_I16: { int16_t x; memcpy(&x, b, 2); v->i = x; break; }
	case API_PLY_U32: memcpy(&v->u, b, 4); break;
	case API_PLY_I32: memcpy(&v->i, b, 4); break;
	case API_PLY_F32: memcpy(&v->f, b, 4); break;
	default: memcpy(&v->d, b, 8); break;
	}
	return true;
}

/* An ASCII integer as strtoul10 (digits) or strtol10 (a sign, then digits) reads it: at most
 * 9 digits, so that neither wraps. */
static size_t ascii_int(const char *s, size_t n, bool sign, int64_t *out)
{
	size_t i = sign && n && (s[0] == '-' || s[0] == '+');
	size_t d0 = i;
	int64_t v = 0;
	for (; i < n && s[i] >= '0' && s[i] <= '9'; i++) v = v * 10 + (s[i] - '0');
	if (i == d0 || i - d0 > 9) return 0;
	*out = s[0] == '-' ? -v : v;
	return i;
}

/* The next ASCII token of the current line, read as type t. */
static bool read_ascii(struct reader *r, enum api_ply_type t, struct value *v)
{
	while (r->at < r->line_end && (r->d[r->at] == ' ' || r->d[r->at] == '\t')) r->at++;
	const char *s = (const char *)r->d + r->at;
	size_t n = r->line_end - r->at, used;
	v->type = t;
	if (t == API_PLY_F32) used = api_assimp_atof(s, n, &v->f);
	else if (t == API_PLY_F64) used = api_assimp_atod(s, n, &v->d);
	else {
		int64_t x = 0;
		used = ascii_int(s, n, !is_unsigned(t), &x);
		if (is_unsigned(t)) v->u = (uint32_t)x; else v->i = (int32_t)x;
	}
	if (!used || (used < n && s[used] != ' ' && s[used] != '\t')) return false;
	r->at += used;
	return true;
}

/* ASCII: onto the next line (it must hold something); binary: nothing. */
static bool next_line(struct reader *r)
{
	if (r->format != API_PLY_ASCII) return true;
	size_t e = r->at;
	while (e < r->len && r->d[e] != '\n') e++;
	r->line_end = e > r->at && r->d[e - 1] == '\r' ? e - 1 : e;
	bool any = false;
	for (size_t i = r->at; i < r->line_end && !any; i++) any = r->d[i] != ' ' && r->d[i] != '\t';
	return any;
}

/* ASCII: the line read to its end (nothing left but blanks), then past it. */
static bool end_line(struct reader *r)
{
	if (r->format != API_PLY_ASCII) return true;
	while (r->at < r->line_end && (r->d[r->at] == ' ' || r->d[r->at] == '\t')) r->at++;
	if (r->at != r->line_end) return false;
	while (r->at < r->len && r->d[r->at] != '\n') r->at++;
	if (r->at < r->len) r->at++;
	return true;
}

static bool read_value(struct reader *r, enum api_ply_type t, struct value *v)
{
	return r->format == API_PLY_ASCII ? read_ascii(r, t, v) : read_binary(r, t, v);
}

/* The mesh as read, before post-processing (malloc'd). */
struct ply_mesh {
	float *pos, *nrm, *uv, *col;
	uint32_t *corners;
	uint8_t *sizes;
	uint32_t nv, nf, ncorners;
	bool quads;
};

static void ply_mesh_free(struct ply_mesh *m)
{
	free(m->pos);
	free(m->nrm);
	free(m->uv);
	free(m->col);
	free(m->corners);
	free(m->sizes);
}

/* The vertex element: each property's semantic into sem (none twice); false: not mine. */
static bool vertex_semantics(const struct api_ply_elem *e, enum sem *sem)
{
	bool seen[SEM_COUNT] = {false};
	for (int i = 0; i < e->nprops; i++) {
		if (e->props[i].list) return false;
		sem[i] = semantic_of(e->props[i].name);
		if (sem[i] != SEM_NONE && seen[sem[i]]) return false;
		seen[sem[i]] = true;
	}
	return seen[SEM_X] && seen[SEM_Y] && seen[SEM_Z];
}

/* Vertices into m (its arrays allocated by what the properties hold): 0, NOT_MINE, NO_MEMORY. */
static int read_vertices(struct reader *r, const struct api_ply_elem *e, const enum sem *sem, struct ply_mesh *m)
{
	bool has_n = false, has_c = false, has_uv = false, has_a = false;
	for (int i = 0; i < e->nprops; i++) {
		has_n |= sem[i] >= SEM_NX && sem[i] <= SEM_NZ;
		has_c |= sem[i] >= SEM_R && sem[i] <= SEM_A;
		has_a |= sem[i] == SEM_A;
		has_uv |= sem[i] == SEM_U || sem[i] == SEM_V;
	}
	size_t nv = m->nv;
	m->pos = calloc(nv, 12);
	m->nrm = has_n ? calloc(nv, 12) : NULL;
	m->col = has_c ? calloc(nv, 16) : NULL;
	m->uv = has_uv ? calloc(nv, 12) : NULL;
	if (!m->pos || (has_n && !m->nrm) || (has_c && !m->col) || (has_uv && !m->uv)) return NO_MEMORY;
	for (size_t v = 0; v < nv; v++) {
		if (!next_line(r)) return NOT_MINE;
		if (m->col && !has_a) m->col[4 * v + 3] = 1.0f;
		for (int i = 0; i < e->nprops; i++) {
			struct value x;
			if (!read_value(r, e->props[i].type, &x)) return NOT_MINE;
			switch (sem[i]) {
			case SEM_X: case SEM_Y: case SEM_Z: m->pos[3 * v + (size_t)(sem[i] - SEM_X)] = as_float(&x); break;
			case SEM_NX: case SEM_NY: case SEM_NZ: m->nrm[3 * v + (size_t)(sem[i] - SEM_NX)] = as_float(&x); break;
			case SEM_R: case SEM_G: case SEM_B: case SEM_A: m->col[4 * v + (size_t)(sem[i] - SEM_R)] = as_colour(&x); break;
			case SEM_U: case SEM_V: m->uv[3 * v + (size_t)(sem[i] - SEM_U)] = as_float(&x); break;
			default: break;
			}
		}
		if (!end_line(r)) return NOT_MINE;
		const float *p = m->pos + 3 * v;
		for (int k = 0; k < 3; k++)
			if (!(fabsf(p[k]) <= 1e18f)) return NOT_MINE;   /* not finite, or overflowing products */
	}
	return 0;
}

/* Faces (3 or 4 indices each, in range) into m: 0, NOT_MINE, NO_MEMORY. */
static int read_faces(struct reader *r, const struct api_ply_prop *list, struct ply_mesh *m)
{
	if (list->type == API_PLY_F32 || list->type == API_PLY_F64) return NOT_MINE;
	m->sizes = malloc(m->nf ? m->nf : 1);
	m->corners = malloc((size_t)(m->nf ? m->nf : 1) * 4 * sizeof *m->corners);
	if (!m->sizes || !m->corners) return NO_MEMORY;
	for (uint32_t f = 0; f < m->nf; f++) {
		struct value c, x;
		if (!next_line(r) || !read_value(r, list->count_type, &c)) return NOT_MINE;
		uint32_t n = as_uint(&c);
		if (n != 3 && n != 4) return NOT_MINE;
		m->sizes[f] = (uint8_t)n;
		m->quads |= n == 4;
		for (uint32_t k = 0; k < n; k++) {
			if (!read_value(r, list->type, &x) || as_uint(&x) >= m->nv) return NOT_MINE;
			m->corners[m->ncorners++] = as_uint(&x);
		}
		if (!end_line(r)) return NOT_MINE;
	}
	return 0;
}

/* The header as this reader takes it: vertex then face, the face's one property an index
 * list; the reader set at the data. */
static bool header_fits(const uint8_t *d, size_t len, const struct api_ply_header *h, enum sem *sem, struct reader *r)
{
	if (h->nelems != 2 || strcmp(h->elems[0].name, "vertex") || strcmp(h->elems[1].name, "face")) return false;
	const struct api_ply_elem *v = &h->elems[0], *f = &h->elems[1];
	if (!v->count || !f->count || v->count > UINT32_MAX / 4 || f->count > UINT32_MAX / 4) return false;
	if (v->count > len || f->count > len) return false;   /* a byte each at least */
	if (f->nprops != 1 || !f->props[0].list ||
	    (strcmp(f->props[0].name, "vertex_indices") && strcmp(f->props[0].name, "vertex_index")))
		return false;
	if (!vertex_semantics(v, sem)) return false;
	/* the header's last line exactly "end_header" and its line end; no texture file named */
	bool crlf = h->data >= 12 && !memcmp(d + h->data - 12, "end_header\r\n", 12);
	if (!crlf && (h->data < 11 || memcmp(d + h->data - 11, "end_header\n", 11))) return false;
	if (memmem(d, h->data, "TextureFile", 11)) return false;
	if (h->format != API_PLY_ASCII && h->data < len && d[h->data] == '\n') return false;
	*r = (struct reader){.d = d, .len = len, .at = h->data, .format = h->format};
	return true;
}

/* The header and data read into m, post-processed into *me (face_colors: as the Assimp path
 * reads a file whose face colours api/ply_colors.h moved to its vertices: no join by Assimp,
 * then api_join_vertices where the mesh has no uvs). 0, NOT_MINE or NO_MEMORY. */
static int read_mesh(const uint8_t *d, size_t len, bool face_colors, struct api_arena *arena, struct api_model_mesh *me,
                     size_t *bytes)
{
	struct api_ply_header h;
	enum sem sem[API_PLY_MAX_PROPS];
	struct reader r;
	if (!api_ply_header_parse(d, len, &h) || !header_fits(d, len, &h, sem, &r)) return NOT_MINE;
	struct ply_mesh m = {.nv = (uint32_t)h.elems[0].count, .nf = (uint32_t)h.elems[1].count};
	int rc = read_vertices(&r, &h.elems[0], sem, &m);
	if (rc == 0) rc = read_faces(&r, &h.elems[1].props[0], &m);
	if (rc == 0) {
		struct api_assimp_mesh a = {.pos = m.pos, .nrm = m.nrm, .uv = m.uv, .col = m.col, .nv = m.nv,
		                            .corners = m.corners, .sizes = m.sizes, .nfaces = m.nf, .quads = m.quads,
		                            .no_join = face_colors};
		rc = api_assimp_post(&a, arena, me, bytes);
		if (rc == API_ASSIMP_POST_GIVE_UP) rc = NOT_MINE;
		else if (rc == API_WIRE_OVER_MEMORY) rc = NO_MEMORY;
	}
	ply_mesh_free(&m);
	if (rc == 0 && face_colors && !me->uvs && me->vertex_count)
		me->vertex_count = api_join_vertices((float *)me->positions, (float *)me->normals, (uint8_t *)me->colors,
		                                     me->vertex_count, (uint32_t *)me->indices, me->index_count, arena,
		                                     &me->weld_group_, &me->weld_groups_);
	return rc == 0 && !api_model_meshes_have_area(me, 1) ? NOT_MINE : rc;
}

int api_ply_import(const uint8_t *d, size_t len, struct api_arena *arena, struct api_model *out, size_t *bytes,
                   char *err, size_t errsize)
{
	*bytes = 0;
	/* strips and face colours rewritten as the Assimp path rewrites them (api_model_import_assimp) */
	size_t rlen = 0;
	uint8_t *re = api_ply_strips_to_faces(d, len, &rlen);
	bool face_colors = false;
	if (!re) face_colors = (re = api_ply_face_colors_to_vertices(d, len, &rlen)) != NULL;
	struct api_model_mesh *me = api_arena_calloc(arena, 1, sizeof *me);
	struct api_model_instance *inst = api_arena_calloc(arena, 1, sizeof *inst);
	struct rnd_material *mat = api_arena_calloc(arena, 1, sizeof *mat);
	int rc = me && inst && mat ? read_mesh(re ? re : d, re ? rlen : len, face_colors, arena, me, bytes) : NO_MEMORY;
	free(re);
	if (rc == NO_MEMORY) {
		api_err_set(err, errsize, "out of memory importing the model");
		return API_WIRE_OVER_MEMORY;
	}
	if (rc != 0) return rc;
	/* Assimp's default PLY material: white (its diffuse), as api_conv_material reads it */
	rnd_material_defaults(mat);
	for (int k = 0; k < 4; k++) mat->base_color[k] = 1.0f;
	inst->mesh = 0;
	rnd_mat4_identity(inst->model);
	*out = (struct api_model){.meshes = me, .mesh_count = 1, .instances = inst, .instance_count = 1, .materials = mat,
	                          .material_count = 1, .triangles = me->index_count / 3, .format = API_MODEL_PLY};
	*bytes += sizeof *me + sizeof *inst + sizeof *mat;
	return API_WIRE_OK;
}
