/*
 * renderer/mesh — tessellates the contract's shapes (§2) into world-space triangles.
 *
 * Every shape is first generated in object space with counter-clockwise front faces seen
 * from outside; the model matrix is then applied to positions and its inverse transpose to
 * normals. A mirroring model (det < 0) would turn the winding around, so each triangle's
 * last two indices are swapped to keep front faces front. Vertex layouts:
 *   plane     4 vertices, 2 triangles
 *   box       6 faces x 4 vertices (flat normals), 12 triangles
 *   sphere    (L+1) rings x (S+1) vertices (seam column duplicated for UVs), L = max(S/2, 2),
 *             2*S*(L-1) triangles (the pole bands are fans; the last south-pole vertex is unused)
 *   cylinder  2 side rings of S+1 vertices + 2 caps of 1+S vertices, 4*S triangles
 *   mesh      as given; without normals the triangles are un-indexed (3 vertices each) so
 *             that each can carry its flat face normal.
 * Pure C, no state: thread-safe.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "mesh.h"

#define PI_F 3.14159265358979323846f

static enum rnd_result mesh_error(struct rnd_error *err, enum rnd_result code, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

static enum rnd_result mesh_error(struct rnd_error *err, enum rnd_result code, const char *fmt, ...)
{
	if (err) {
		va_list ap;
		err->code = code;
		err->vk_result = 0;
		va_start(ap, fmt);
		vsnprintf(err->msg, sizeof err->msg, fmt, ap);
		va_end(ap);
	}
	return code;
}

static uint32_t shape_segments(const struct rnd_object *o)
{
	return o->segments < 3 ? 3 : o->segments;
}

static uint32_t sphere_latitudes(uint32_t s)
{
	return s / 2 < 2 ? 2 : s / 2;
}

/* Counts in 64 bits: a huge `segments` must not wrap around. */
static void counts64(const struct rnd_object *o, uint64_t *vc, uint64_t *ic)
{
	uint64_t s = shape_segments(o), l = sphere_latitudes((uint32_t)s), tri;
	switch (o->shape) {
	case RND_SHAPE_PLANE: *vc = 4; *ic = 6; return;
	case RND_SHAPE_BOX: *vc = 24; *ic = 36; return;
	case RND_SHAPE_SPHERE: *vc = (l + 1) * (s + 1); *ic = 3 * 2 * s * (l - 1); return;
	case RND_SHAPE_CYLINDER: *vc = 4 * s + 4; *ic = 3 * 4 * s; return;
	case RND_SHAPE_MESH:
		tri = o->indices ? o->index_count / 3 : o->vertex_count / 3;
		*ic = tri * 3;
		if (o->normals && o->indices) *vc = o->vertex_count;
		else *vc = tri * 3;
		return;
	}
	*vc = 0; *ic = 0;
}

void rnd_mesh_counts(const struct rnd_object *o, uint32_t *vertex_count, uint32_t *index_count)
{
	uint64_t vc, ic;
	counts64(o, &vc, &ic);
	*vertex_count = vc > UINT32_MAX ? UINT32_MAX : (uint32_t)vc;
	*index_count = ic > UINT32_MAX ? UINT32_MAX : (uint32_t)ic;
}

uint64_t rnd_object_triangle_count(const struct rnd_object *o)
{
	uint64_t vc, ic;
	counts64(o, &vc, &ic);
	return ic / 3;
}

/* ---- object-space generators: each writes vertices and 0-based local indices ---- */

static void set_vertex(struct rnd_vertex *v, float px, float py, float pz, float nx, float ny, float nz,
                       float u, float tv)
{
	v->pos[0] = px; v->pos[1] = py; v->pos[2] = pz;
	v->nrm[0] = nx; v->nrm[1] = ny; v->nrm[2] = nz;
	v->uv[0] = u; v->uv[1] = tv;
	v->color[0] = v->color[1] = v->color[2] = v->color[3] = 255;
	v->tangent[0] = 127; v->tangent[1] = 0; v->tangent[2] = 0; v->tangent[3] = 127;
}

static int8_t snorm8(float f)
{
	f = !(f >= -1.0f) ? -1.0f : f > 1.0f ? 1.0f : f;   /* NaN -> -1 */
	return (int8_t)lrintf(f * 127.0f);
}

/* Vertex colour and tangent of source vertex i of a mesh, when it has them. */
static void mesh_extras(const struct rnd_object *o, uint32_t i, struct rnd_vertex *v)
{
	if (o->colors) memcpy(v->color, o->colors + 4 * (size_t)i, 4);
	if (o->tangents)
		for (int k = 0; k < 4; k++) v->tangent[k] = snorm8(o->tangents[4 * (size_t)i + (size_t)k]);
}

/* One quad face: centre direction n, in-face axes u, v with u x v = n (so the quad
 * (-u-v, +u-v, +u+v, -u+v) is counter-clockwise seen from n), scaled by half. */
static void quad_face(struct rnd_vertex *vt, uint32_t *ix, uint32_t first, const float n[3], const float u[3],
                      const float v[3], const float half[3], float normal_offset)
{
	static const float su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
	for (int k = 0; k < 4; k++) {
		float p[3];
		for (int i = 0; i < 3; i++) p[i] = (n[i] * normal_offset + u[i] * su[k] + v[i] * sv[k]) * half[i];
		set_vertex(&vt[k], p[0], p[1], p[2], n[0], n[1], n[2], 0.5f * (su[k] + 1.0f), 1.0f - 0.5f * (sv[k] + 1.0f));
	}
	static const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
	for (int k = 0; k < 6; k++) ix[k] = first + q[k];
}

static void gen_plane(const struct rnd_object *o, struct rnd_vertex *vt, uint32_t *ix)
{
	static const float n[3] = {0, 1, 0}, u[3] = {1, 0, 0}, v[3] = {0, 0, -1};
	float half[3] = {0.5f * o->size[0], 0.0f, 0.5f * o->size[2]};
	quad_face(vt, ix, 0, n, u, v, half, 0.0f);
}

static void gen_box(const struct rnd_object *o, struct rnd_vertex *vt, uint32_t *ix)
{
	static const float faces[6][3][3] = {
		/* normal       u             v */
		{{1, 0, 0},  {0, 0, -1}, {0, 1, 0}},
		{{-1, 0, 0}, {0, 0, 1},  {0, 1, 0}},
		{{0, 1, 0},  {1, 0, 0},  {0, 0, -1}},
		{{0, -1, 0}, {1, 0, 0},  {0, 0, 1}},
		{{0, 0, 1},  {1, 0, 0},  {0, 1, 0}},
		{{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
	};
	float half[3] = {0.5f * o->size[0], 0.5f * o->size[1], 0.5f * o->size[2]};
	for (uint32_t f = 0; f < 6; f++)
		quad_face(vt + 4 * f, ix + 6 * f, 4 * f, faces[f][0], faces[f][1], faces[f][2], half, 1.0f);
}

/* Longitude phi runs so that u = phi/2pi increases to the right seen from outside
 * (x = -cos phi, z = sin phi, as three.js); latitude theta = 0 at +Y, v = theta/pi. */
static void gen_sphere(const struct rnd_object *o, struct rnd_vertex *vt, uint32_t *ix)
{
	uint32_t s = shape_segments(o), l = sphere_latitudes(s), row = s + 1, k = 0;
	float r = o->radius;
	for (uint32_t i = 0; i <= l; i++) {
		float theta = PI_F * (float)i / (float)l;
		float st = sinf(theta), ct = cosf(theta);
		if (i == 0) { st = 0.0f; ct = 1.0f; }
		if (i == l) { st = 0.0f; ct = -1.0f; }
		for (uint32_t j = 0; j <= s; j++) {
			float phi = 2.0f * PI_F * (float)j / (float)s;
			float nx = -cosf(phi) * st, ny = ct, nz = sinf(phi) * st;
			/* A pole vertex serves the fan triangle j, so it takes that triangle's middle u. */
			float u = (float)j / (float)s;
			if ((i == 0 || i == l) && j < s) u = ((float)j + 0.5f) / (float)s;
			set_vertex(&vt[i * row + j], r * nx, r * ny, r * nz, nx, ny, nz, u, (float)i / (float)l);
		}
	}
	for (uint32_t i = 0; i < l; i++)
		for (uint32_t j = 0; j < s; j++) {
			uint32_t a = i * row + j, b = a + row;
			/* Quad (a, a+1 above; b, b+1 below) as (a, b, a+1) + (a+1, b, b+1); in the pole
			 * bands one of them is degenerate and the other uses pole vertex j. */
			if (i == 0) { ix[k++] = a; ix[k++] = b; ix[k++] = b + 1; continue; }
			ix[k++] = a; ix[k++] = b; ix[k++] = a + 1;
			if (i != l - 1) { ix[k++] = a + 1; ix[k++] = b; ix[k++] = b + 1; }
		}
}

static void gen_cylinder(const struct rnd_object *o, struct rnd_vertex *vt, uint32_t *ix)
{
	uint32_t s = shape_segments(o), row = s + 1, k = 0;
	float r = o->radius, h = 0.5f * o->height;
	/* Side: ring 0 at +h, ring 1 at -h. */
	for (uint32_t i = 0; i < 2; i++)
		for (uint32_t j = 0; j <= s; j++) {
			float phi = 2.0f * PI_F * (float)j / (float)s;
			float nx = -cosf(phi), nz = sinf(phi);
			set_vertex(&vt[i * row + j], r * nx, i ? -h : h, r * nz, nx, 0.0f, nz, (float)j / (float)s, (float)i);
		}
	for (uint32_t j = 0; j < s; j++) {
		uint32_t a = j, b = j + row;
		ix[k++] = a; ix[k++] = b; ix[k++] = a + 1;
		ix[k++] = a + 1; ix[k++] = b; ix[k++] = b + 1;
	}
	/* Caps: centre then s rim vertices, flat normals, planar UVs. */
	for (uint32_t c = 0; c < 2; c++) {
		uint32_t first = 2 * row + c * (s + 1);
		float y = c ? -h : h, ny = c ? -1.0f : 1.0f;
		set_vertex(&vt[first], 0.0f, y, 0.0f, 0.0f, ny, 0.0f, 0.5f, 0.5f);
		for (uint32_t j = 0; j < s; j++) {
			float phi = 2.0f * PI_F * (float)j / (float)s;
			float x = -cosf(phi), z = sinf(phi);
			set_vertex(&vt[first + 1 + j], r * x, y, r * z, 0.0f, ny, 0.0f, 0.5f + 0.5f * x, 0.5f + 0.5f * z);
		}
		for (uint32_t j = 0; j < s; j++) {
			uint32_t p = first + 1 + j, q = first + 1 + (j + 1) % s;
			ix[k++] = first;
			ix[k++] = c ? q : p;
			ix[k++] = c ? p : q;
		}
	}
}

static enum rnd_result check_mesh(const struct rnd_object *o, struct rnd_error *err)
{
	if (o->vertex_count > 0 && !o->positions)
		return mesh_error(err, RND_ERR_INVALID, "mesh: %u vertices but no positions", o->vertex_count);
	if (o->indices) {
		if (o->index_count % 3 != 0)
			return mesh_error(err, RND_ERR_INVALID, "mesh: index count %u is not a multiple of 3",
			                  o->index_count);
		for (uint32_t i = 0; i < o->index_count; i++)
			if (o->indices[i] >= o->vertex_count)
				return mesh_error(err, RND_ERR_INVALID,
				                  "mesh: index %u (at %u) references a missing vertex (vertex count %u)",
				                  o->indices[i], i, o->vertex_count);
	} else if (o->index_count > 0) {
		return mesh_error(err, RND_ERR_INVALID, "mesh: index count %u but no indices", o->index_count);
	} else if (o->vertex_count % 3 != 0) {
		return mesh_error(err, RND_ERR_INVALID,
		                  "mesh: %u vertices without indices is not a triangle list (not a multiple of 3)",
		                  o->vertex_count);
	}
	for (uint64_t i = 0; i < 3ull * o->vertex_count; i++)
		if (!isfinite(o->positions[i]))
			return mesh_error(err, RND_ERR_INVALID, "mesh: position %llu is not finite",
			                  (unsigned long long)(i / 3));
	return RND_OK;
}

static void gen_mesh(const struct rnd_object *o, struct rnd_vertex *vt, uint32_t *ix)
{
	if (o->normals && o->indices) {
		for (uint32_t i = 0; i < o->vertex_count; i++) {
			const float *p = o->positions + 3 * i, *n = o->normals + 3 * i;
			const float *t = o->uvs ? o->uvs + 2 * i : NULL;
			set_vertex(&vt[i], p[0], p[1], p[2], n[0], n[1], n[2], t ? t[0] : 0.0f, t ? t[1] : 0.0f);
			mesh_extras(o, i, &vt[i]);
		}
		memcpy(ix, o->indices, (size_t)o->index_count * sizeof *ix);
		return;
	}
	uint32_t tri = o->indices ? o->index_count / 3 : o->vertex_count / 3;
	for (uint32_t t = 0; t < tri; t++) {
		uint32_t src[3];
		for (int k = 0; k < 3; k++) src[k] = o->indices ? o->indices[3 * t + k] : 3 * t + (uint32_t)k;
		float face[3] = {0.0f, 1.0f, 0.0f};
		if (!o->normals) {
			float e1[3], e2[3], c[3];
			rnd_v3_sub(e1, o->positions + 3 * src[1], o->positions + 3 * src[0]);
			rnd_v3_sub(e2, o->positions + 3 * src[2], o->positions + 3 * src[0]);
			rnd_v3_cross(c, e1, e2);
			if (rnd_v3_normalize(c, c)) memcpy(face, c, sizeof face);
		}
		for (int k = 0; k < 3; k++) {
			const float *p = o->positions + 3 * src[k];
			const float *n = o->normals ? o->normals + 3 * src[k] : face;
			const float *uv = o->uvs ? o->uvs + 2 * src[k] : NULL;
			set_vertex(&vt[3 * t + (uint32_t)k], p[0], p[1], p[2], n[0], n[1], n[2], uv ? uv[0] : 0.0f,
			           uv ? uv[1] : 0.0f);
			mesh_extras(o, src[k], &vt[3 * t + (uint32_t)k]);
			ix[3 * t + (uint32_t)k] = 3 * t + (uint32_t)k;
		}
	}
}

void rnd_mesh_write_uv1(const struct rnd_object *o, const struct rnd_vertex *vertices, uint32_t count, float *out)
{
	if (o->shape != RND_SHAPE_MESH || !o->uvs1) {
		for (uint32_t i = 0; i < count; i++) memcpy(out + 2 * (size_t)i, vertices[i].uv, 8);
		return;
	}
	/* gen_mesh's order: the vertices as given (indexed, with normals), else one per corner */
	bool shared = o->normals && o->indices;
	for (uint32_t i = 0; i < count; i++) {
		uint32_t src = shared ? i : o->indices ? o->indices[i] : i;
		memcpy(out + 2 * (size_t)i, o->uvs1 + 2 * (size_t)src, 8);
	}
}

/* rnd_mesh_write(); with shape_only, positions and indices alone (no normal or tangent is
 * transformed: rnd_mesh_measure wants the shape); with checked, a mesh's arrays are not
 * checked again (rnd_mesh_measure did). */
static enum rnd_result write_shape(const struct rnd_object *o, struct rnd_vertex *vertices, uint32_t *indices,
                                   uint32_t base_vertex, struct rnd_aabb *bounds, bool shape_only, bool checked,
                                   struct rnd_error *err)
{
	uint64_t vc, ic;
	float nm[16];
	counts64(o, &vc, &ic);
	if (vc > UINT32_MAX || ic > UINT32_MAX || (uint64_t)base_vertex + vc > UINT32_MAX)
		return mesh_error(err, RND_ERR_LIMIT, "object needs %llu vertices and %llu indices after base %u: over 32-bit indexing",
		                  (unsigned long long)vc, (unsigned long long)ic, base_vertex);
	if (!rnd_mat4_normal_matrix(nm, o->model))
		return mesh_error(err, RND_ERR_INVALID, "object model matrix is singular (scale 0?)");
	for (int i = 0; i < 16; i++)
		if (!isfinite(o->model[i]))
			return mesh_error(err, RND_ERR_INVALID, "object model matrix is not finite");

	switch (o->shape) {
	case RND_SHAPE_PLANE: gen_plane(o, vertices, indices); break;
	case RND_SHAPE_BOX: gen_box(o, vertices, indices); break;
	case RND_SHAPE_SPHERE: gen_sphere(o, vertices, indices); break;
	case RND_SHAPE_CYLINDER: gen_cylinder(o, vertices, indices); break;
	case RND_SHAPE_MESH: {
		enum rnd_result r = checked ? RND_OK : check_mesh(o, err);
		if (r != RND_OK) return r;
		gen_mesh(o, vertices, indices);
		break;
	}
	default:
		return mesh_error(err, RND_ERR_INVALID, "unknown shape %d", (int)o->shape);
	}

	bool flip = rnd_mat4_det3(o->model) < 0.0f;
	bool tangents = o->shape == RND_SHAPE_MESH && o->tangents;
	for (uint32_t i = 0; i < (uint32_t)vc; i++) {
		struct rnd_vertex *v = &vertices[i];
		rnd_mat4_mul_point(v->pos, o->model, v->pos);
		if (bounds) rnd_aabb_add_point(bounds, v->pos);
		if (shape_only) continue;
		rnd_mat4_mul_dir(v->nrm, nm, v->nrm);
		if (!rnd_v3_normalize(v->nrm, v->nrm)) { v->nrm[0] = 0.0f; v->nrm[1] = 1.0f; v->nrm[2] = 0.0f; }
		if (tangents) {
			/* Tangents follow the surface (the model matrix itself); a mirror turns the
			 * bitangent around, so its sign flips with the winding. */
			float t[3] = {v->tangent[0] / 127.0f, v->tangent[1] / 127.0f, v->tangent[2] / 127.0f};
			rnd_mat4_mul_dir(t, o->model, t);
			if (!rnd_v3_normalize(t, t)) { t[0] = 1.0f; t[1] = 0.0f; t[2] = 0.0f; }
			for (int k = 0; k < 3; k++) v->tangent[k] = snorm8(t[k]);
			v->tangent[3] = (v->tangent[3] < 0) != flip ? -127 : 127;
		}
	}
	for (uint32_t i = 0; i < (uint32_t)ic; i += 3) {
		if (flip) { uint32_t t = indices[i + 1]; indices[i + 1] = indices[i + 2]; indices[i + 2] = t; }
		indices[i] += base_vertex; indices[i + 1] += base_vertex; indices[i + 2] += base_vertex;
	}
	return RND_OK;
}

enum rnd_result rnd_mesh_write(const struct rnd_object *o, struct rnd_vertex *vertices, uint32_t *indices,
                               uint32_t base_vertex, struct rnd_aabb *bounds, struct rnd_error *err)
{
	return write_shape(o, vertices, indices, base_vertex, bounds, false, false, err);
}

enum rnd_result rnd_mesh_write_measured(const struct rnd_object *o, struct rnd_vertex *vertices, uint32_t *indices,
                                        uint32_t base_vertex, struct rnd_error *err)
{
	return write_shape(o, vertices, indices, base_vertex, NULL, false, true, err);
}

/* Corner k of triangle t: its world position (in buf, or where it is stored). */
typedef const float *corner_fn(const void *user, uint32_t t, int k, float buf[3]);

/* An estimate's input (renderer/cost.h): at most RND_MESH_AREA_SAMPLES triangles, evenly
 * strided, scaled up; every plan measures it, and a pass over a 1M-triangle mesh would cost a
 * few ms of a 25 ms render. Inlined where it is called, with the corner function it is given. */
static inline __attribute__((always_inline)) double sampled_area(uint32_t tris, corner_fn *corner, const void *user)
{
	uint32_t stride = tris > RND_MESH_AREA_SAMPLES ? tris / RND_MESH_AREA_SAMPLES : 1;
	double sum = 0.0;
	uint32_t taken = 0;
	for (uint32_t t = 0; t < tris; t += stride, taken++) {
		float ab[3], bb[3], cb[3];
		const float *a = corner(user, t, 0, ab), *b = corner(user, t, 1, bb), *c = corner(user, t, 2, cb);
		float e1[3], e2[3], n[3];
		rnd_v3_sub(e1, b, a);
		rnd_v3_sub(e2, c, a);
		rnd_v3_cross(n, e1, e2);
		sum += 0.5 * sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
	}
	return taken ? sum * ((double)tris / taken) : 0.0;
}

struct written { const struct rnd_vertex *vertices; const uint32_t *indices; };

static const float *written_corner(const void *user, uint32_t t, int k, float buf[3])
{
	const struct written *w = user;
	(void)buf;
	return w->vertices[w->indices[3 * t + (uint32_t)k]].pos;
}

double rnd_mesh_area(const struct rnd_vertex *vertices, const uint32_t *indices, uint32_t index_count)
{
	struct written w = {vertices, indices};
	return sampled_area(index_count / 3, written_corner, &w);
}

/* A mesh's corner as rnd_mesh_write() writes it: its source position through the model matrix,
 * the last two corners swapped by a mirroring one. */
struct source { const struct rnd_object *o; bool flip; };

static const float *source_corner(const void *user, uint32_t t, int k, float buf[3])
{
	const struct source *s = user;
	uint32_t c = 3 * t + (uint32_t)(s->flip && k ? 3 - k : k);
	uint32_t src = s->o->indices ? s->o->indices[c] : c;
	rnd_mat4_mul_point(buf, s->o->model, s->o->positions + 3 * (size_t)src);
	return buf;
}

/* A mesh's bounds as rnd_mesh_write() grows them: every vertex it writes through the model
 * matrix (with normals and indices, every given vertex; else each triangle's corners, which
 * are the vertices the indices name). */
static enum rnd_result mesh_bounds(const struct rnd_object *o, struct rnd_aabb *bounds, struct rnd_error *err)
{
	bool all = (o->normals && o->indices) || !o->indices;
	uint8_t *used = all ? NULL : calloc(o->vertex_count ? o->vertex_count : 1, 1);
	if (!all && !used) return mesh_error(err, RND_ERR_OOM, "out of memory measuring a mesh of %u vertices", o->vertex_count);
	uint32_t n = o->indices || !all ? o->vertex_count : o->vertex_count / 3 * 3;
	if (used)
		for (uint32_t i = 0; i < o->index_count / 3 * 3; i++) used[o->indices[i]] = 1;
	for (uint32_t i = 0; i < n; i++) {
		if (used && !used[i]) continue;
		float p[3];
		rnd_mat4_mul_point(p, o->model, o->positions + 3 * (size_t)i);
		rnd_aabb_add_point(bounds, p);
	}
	free(used);
	return RND_OK;
}

enum rnd_result rnd_mesh_measure(const struct rnd_object *o, struct rnd_vertex *keep_vertices, uint32_t *keep_indices,
                                 struct rnd_aabb *bounds, double *area, struct rnd_error *err)
{
	uint64_t vc, ic;
	counts64(o, &vc, &ic);
	*area = 0.0;
	if (vc > UINT32_MAX || ic > UINT32_MAX)
		return mesh_error(err, RND_ERR_LIMIT, "object needs %llu vertices and %llu indices: over 32-bit indexing",
		                  (unsigned long long)vc, (unsigned long long)ic);
	if (o->shape != RND_SHAPE_MESH) {
		/* Analytic shapes are small (their level of detail bounds them): written as
		 * rnd_mesh_write writes them, so that their bounds and area are its own; into the
		 * caller's memory (whole, to be copied instead of written again) or scratch (the
		 * shape alone). */
		bool keep = keep_vertices && keep_indices;
		struct rnd_vertex *v = keep ? keep_vertices : malloc((vc ? vc : 1) * sizeof *v);
		uint32_t *x = keep ? keep_indices : malloc((ic ? ic : 1) * sizeof *x);
		enum rnd_result r = v && x ? write_shape(o, v, x, 0, bounds, !keep, false, err)
		                           : mesh_error(err, RND_ERR_OOM, "out of memory measuring an object of %llu vertices",
		                                        (unsigned long long)vc);
		if (r == RND_OK) *area = rnd_mesh_area(v, x, (uint32_t)ic);
		if (!keep) {
			free(v);
			free(x);
		}
		return r;
	}
	float nm[16];
	if (!rnd_mat4_normal_matrix(nm, o->model)) return mesh_error(err, RND_ERR_INVALID, "object model matrix is singular (scale 0?)");
	for (int i = 0; i < 16; i++)
		if (!isfinite(o->model[i])) return mesh_error(err, RND_ERR_INVALID, "object model matrix is not finite");
	enum rnd_result r = check_mesh(o, err);
	if (r == RND_OK) r = mesh_bounds(o, bounds, err);
	if (r != RND_OK) return r;
	struct source src = {o, rnd_mat4_det3(o->model) < 0.0f};
	*area = sampled_area((uint32_t)(ic / 3), source_corner, &src);
	return RND_OK;
}

void rnd_mesh_local_bounds(const struct rnd_object *o, struct rnd_aabb *out)
{
	float h[3] = {0, 0, 0};
	rnd_aabb_empty(out);
	switch (o->shape) {
	case RND_SHAPE_PLANE: h[0] = 0.5f * o->size[0]; h[2] = 0.5f * o->size[2]; break;
	case RND_SHAPE_BOX: for (int i = 0; i < 3; i++) h[i] = 0.5f * o->size[i]; break;
	case RND_SHAPE_SPHERE: h[0] = h[1] = h[2] = o->radius; break;
	case RND_SHAPE_CYLINDER: h[0] = h[2] = o->radius; h[1] = 0.5f * o->height; break;
	case RND_SHAPE_MESH:
		if (o->mesh_bounds && o->vertex_count) {
			memcpy(out->min, o->mesh_bounds, sizeof out->min);
			memcpy(out->max, o->mesh_bounds + 3, sizeof out->max);
		} else if (o->positions) {
			for (uint32_t i = 0; i < o->vertex_count; i++) rnd_aabb_add_point(out, o->positions + 3 * i);
		}
		return;
	default:
		return;
	}
	for (int i = 0; i < 3; i++) { h[i] = fabsf(h[i]); out->min[i] = -h[i]; out->max[i] = h[i]; }
}
