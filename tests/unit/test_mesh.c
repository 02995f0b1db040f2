/* tests — renderer/mesh.c tessellation and renderer/scene.c defaults. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "mesh.h"
#include "test.h"
#include "umbra/rnd.h"
#include "umbra/rnd_math.h"

#define PI_F 3.14159265358979323846f

struct tess {
	uint32_t vc, ic;
	struct rnd_vertex *v;
	uint32_t *i;
	struct rnd_aabb bounds;
	enum rnd_result r;
	struct rnd_error err;
};

static void tess_run(struct tess *t, const struct rnd_object *o, uint32_t base)
{
	memset(t, 0, sizeof *t);
	rnd_mesh_counts(o, &t->vc, &t->ic);
	t->v = calloc(t->vc ? t->vc : 1, sizeof *t->v);
	t->i = calloc(t->ic ? t->ic : 1, sizeof *t->i);
	rnd_aabb_empty(&t->bounds);
	t->r = rnd_mesh_write(o, t->v, t->i, base, &t->bounds, &t->err);
}

static void tess_free(struct tess *t)
{
	free(t->v);
	free(t->i);
}

static struct rnd_object shape(enum rnd_shape s)
{
	struct rnd_object o;
	rnd_object_defaults(&o);
	o.shape = s;
	return o;
}

static void set_trs(struct rnd_object *o, float tx, float ty, float tz, const float q[4], float sx, float sy, float sz)
{
	float t[3] = {tx, ty, tz}, s[3] = {sx, sy, sz};
	rnd_mat4_trs(o->model, t, q, s);
}

static const float q_id[4] = {0, 0, 0, 1};

/* Convex-shape invariants: every non-degenerate triangle's winding normal points away from
 * centre c and agrees with its vertex normals; vertex normals are unit and point outward. */
static int check_outward(const struct tess *t, const float c[3], uint32_t base, const char *what)
{
	int bad = 0, degenerate = 0;
	for (uint32_t k = 0; k < t->vc; k++) {
		const struct rnd_vertex *v = &t->v[k];
		float d[3];
		rnd_v3_sub(d, v->pos, c);
		if (fabsf(rnd_v3_length(v->nrm) - 1.0f) > 1e-4f) {
			if (bad++ < 3) CHECK(0, "%s: normal %u not unit (%g)", what, k, rnd_v3_length(v->nrm));
		}
		if (rnd_v3_dot(v->nrm, d) <= 0) {
			if (bad++ < 3) CHECK(0, "%s: normal %u points inward", what, k);
		}
	}
	for (uint32_t k = 0; k < t->ic; k += 3) {
		uint32_t a = t->i[k] - base, b = t->i[k + 1] - base, cc = t->i[k + 2] - base;
		if (a >= t->vc || b >= t->vc || cc >= t->vc) {
			if (bad++ < 3) CHECK(0, "%s: index out of range at %u", what, k);
			continue;
		}
		float e1[3], e2[3], g[3], centroid[3], d[3], navg[3];
		rnd_v3_sub(e1, t->v[b].pos, t->v[a].pos);
		rnd_v3_sub(e2, t->v[cc].pos, t->v[a].pos);
		rnd_v3_cross(g, e1, e2);
		if (rnd_v3_length(g) < 1e-9f) { degenerate++; continue; }
		for (int i = 0; i < 3; i++) {
			centroid[i] = (t->v[a].pos[i] + t->v[b].pos[i] + t->v[cc].pos[i]) / 3.0f;
			navg[i] = t->v[a].nrm[i] + t->v[b].nrm[i] + t->v[cc].nrm[i];
		}
		rnd_v3_sub(d, centroid, c);
		if (rnd_v3_dot(g, d) <= 0) {
			if (bad++ < 3) CHECK(0, "%s: triangle %u winds inward", what, k / 3);
		}
		if (rnd_v3_dot(g, navg) <= 0) {
			if (bad++ < 3) CHECK(0, "%s: triangle %u winding disagrees with its normals", what, k / 3);
		}
	}
	CHECK(degenerate == 0, "%s: %d degenerate triangles", what, degenerate);
	return bad;
}

TEST(mesh_counts_plane_box)
{
	struct rnd_object p = shape(RND_SHAPE_PLANE), b = shape(RND_SHAPE_BOX);
	uint32_t vc, ic;
	rnd_mesh_counts(&p, &vc, &ic);
	CHECK(vc == 4 && ic == 6, "plane %u %u", vc, ic);
	CHECK(rnd_object_triangle_count(&p) == 2, "plane triangles");
	rnd_mesh_counts(&b, &vc, &ic);
	CHECK(vc == 24 && ic == 36, "box %u %u", vc, ic);
	CHECK(rnd_object_triangle_count(&b) == 12, "box triangles");
}

TEST(mesh_counts_sphere_segments)
{
	static const uint32_t segs[] = {3, 4, 8, 17, 64, 128, 316};
	for (size_t k = 0; k < sizeof segs / sizeof segs[0]; k++) {
		struct rnd_object o = shape(RND_SHAPE_SPHERE);
		o.segments = segs[k];
		uint32_t vc, ic, s = segs[k], l = s / 2 < 2 ? 2 : s / 2;
		rnd_mesh_counts(&o, &vc, &ic);
		uint64_t tri = rnd_object_triangle_count(&o);
		bool whole = ic == 3 * (ic / 3);
		CHECK(tri == ic / 3 && whole, "segments %u: triangle count %llu vs indices %u", s,
		      (unsigned long long)tri, ic);
		CHECK(tri == 2ull * s * (l - 1), "segments %u: %llu triangles, want %u", s, (unsigned long long)tri,
		      2 * s * (l - 1));
	}
	struct rnd_object o = shape(RND_SHAPE_SPHERE);
	o.segments = 316;
	uint64_t tri = rnd_object_triangle_count(&o);
	CHECK(tri > 98000 && tri < 101000, "316 segments ~ 100k triangles: %llu", (unsigned long long)tri);
	o.segments = 64;
	tri = rnd_object_triangle_count(&o);
	CHECK(tri > 0.95 * 64 * 64 && tri <= 64 * 64, "64 segments ~ 4096 triangles: %llu", (unsigned long long)tri);
}

TEST(mesh_counts_cylinder_segments)
{
	static const uint32_t segs[] = {3, 5, 16, 64, 1000};
	for (size_t k = 0; k < sizeof segs / sizeof segs[0]; k++) {
		struct rnd_object o = shape(RND_SHAPE_CYLINDER);
		o.segments = segs[k];
		uint32_t vc, ic;
		rnd_mesh_counts(&o, &vc, &ic);
		CHECK(ic == 12 * segs[k], "cylinder %u: %u indices", segs[k], ic);
		CHECK(rnd_object_triangle_count(&o) == 4ull * segs[k], "cylinder %u: triangles", segs[k]);
	}
}

TEST(mesh_counts_mesh_variants)
{
	float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
	float nrm[12] = {0};
	uint32_t idx[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
	struct rnd_object o = shape(RND_SHAPE_MESH);
	o.positions = pos; o.vertex_count = 4; o.indices = idx; o.index_count = 12;
	uint32_t vc, ic;
	rnd_mesh_counts(&o, &vc, &ic);
	CHECK(vc == 12 && ic == 12, "indexed, no normals: un-indexed %u %u", vc, ic);
	o.normals = nrm;
	rnd_mesh_counts(&o, &vc, &ic);
	CHECK(vc == 4 && ic == 12, "indexed with normals: as given %u %u", vc, ic);
	CHECK(rnd_object_triangle_count(&o) == 4, "4 triangles");
	o.indices = NULL; o.index_count = 0; o.vertex_count = 3; o.normals = NULL;
	rnd_mesh_counts(&o, &vc, &ic);
	CHECK(vc == 3 && ic == 3, "triangle list %u %u", vc, ic);
	CHECK(rnd_object_triangle_count(&o) == 1, "1 triangle");
}

/* The second uv set follows the vertices rnd_mesh_write wrote: as given (indexed, with
 * normals), one per corner (indexed without normals), and each vertex's own uv where the
 * object has no uvs1 (so a slot on set 1 reads set 0). */
TEST(mesh_uv1_follows_the_written_vertices)
{
	float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
	float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1}, uv1[8] = {10, 11, 12, 13, 14, 15, 16, 17};
	uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
	struct rnd_object o = shape(RND_SHAPE_MESH);
	o.positions = pos; o.vertex_count = 4; o.indices = idx; o.index_count = 6; o.uvs = uv; o.uvs1 = uv1;
	for (int variant = 0; variant < 3; variant++) {
		o.normals = variant == 1 ? NULL : nrm;
		o.uvs1 = variant == 2 ? NULL : uv1;
		struct tess t;
		tess_run(&t, &o, 0);
		REQUIRE(t.r == RND_OK, "%s", t.err.msg);
		float *out = calloc(2 * (size_t)t.vc, sizeof *out);
		REQUIRE(out);
		rnd_mesh_write_uv1(&o, t.v, t.vc, out);
		int wrong = 0;
		for (uint32_t k = 0; k < t.vc; k++) {
			uint32_t src = variant == 1 ? idx[k] : k;
			const float *want = variant == 2 ? t.v[k].uv : uv1 + 2 * src;
			wrong += out[2 * k] != want[0] || out[2 * k + 1] != want[1];
		}
		CHECK(t.vc == (variant == 1 ? 6u : 4u) && wrong == 0, "variant %d: %u vertices, %d wrong", variant, t.vc, wrong);
		free(out);
		tess_free(&t);
	}
}

TEST(mesh_sphere_vertices_on_surface)
{
	static const uint32_t segs[] = {3, 8, 33, 64};
	for (size_t k = 0; k < sizeof segs / sizeof segs[0]; k++) {
		struct rnd_object o = shape(RND_SHAPE_SPHERE);
		o.segments = segs[k];
		o.radius = 2.5f;
		set_trs(&o, 1, 2, -3, q_id, 1, 1, 1);
		struct tess t;
		tess_run(&t, &o, 0);
		REQUIRE(t.r == RND_OK, "write: %s", t.err.msg);
		float c[3] = {1, 2, -3};
		int off = 0;
		for (uint32_t i = 0; i < t.vc; i++) {
			float d[3];
			rnd_v3_sub(d, t.v[i].pos, c);
			if (fabsf(rnd_v3_length(d) - 2.5f) > 1e-4f) off++;
		}
		CHECK(off == 0, "segments %u: %d vertices off the sphere", segs[k], off);
		CHECK(check_outward(&t, c, 0, "sphere") == 0, "segments %u outward", segs[k]);
		tess_free(&t);
	}
}

TEST(mesh_sphere_uvs)
{
	struct rnd_object o = shape(RND_SHAPE_SPHERE);
	o.segments = 16;
	struct tess t;
	tess_run(&t, &o, 0);
	REQUIRE(t.r == RND_OK, "write");
	int bad = 0;
	for (uint32_t i = 0; i < t.vc; i++) {
		const struct rnd_vertex *v = &t.v[i];
		if (v->uv[0] < 0 || v->uv[0] > 1 || v->uv[1] < 0 || v->uv[1] > 1) bad++;
		/* v = latitude / pi measured from +Y. */
		float lat = acosf(fmaxf(-1.0f, fminf(1.0f, v->pos[1])));
		if (fabsf(v->uv[1] - lat / PI_F) > 1e-3f) bad++;
		/* u = longitude / 2pi away from the poles and the seam. */
		if (fabsf(v->pos[1]) < 0.99f && v->uv[0] > 0.01f && v->uv[0] < 0.99f) {
			float lon = atan2f(v->pos[2], -v->pos[0]);
			if (lon < 0) lon += 2 * PI_F;
			if (fabsf(v->uv[0] - lon / (2 * PI_F)) > 1e-3f) bad++;
		}
	}
	CHECK(bad == 0, "%d bad sphere UVs", bad);
	tess_free(&t);
}

TEST(mesh_box_outward_and_bounds)
{
	struct rnd_object o = shape(RND_SHAPE_BOX);
	o.size[0] = 2; o.size[1] = 4; o.size[2] = 6;
	set_trs(&o, 10, 0, 0, q_id, 1, 1, 1);
	struct tess t;
	tess_run(&t, &o, 0);
	REQUIRE(t.r == RND_OK, "write: %s", t.err.msg);
	float c[3] = {10, 0, 0};
	CHECK(check_outward(&t, c, 0, "box") == 0, "box outward");
	CHECK(fabsf(t.bounds.min[0] - 9) < 1e-6f && fabsf(t.bounds.max[0] - 11) < 1e-6f, "x bounds");
	CHECK(fabsf(t.bounds.min[1] + 2) < 1e-6f && fabsf(t.bounds.max[1] - 2) < 1e-6f, "y bounds");
	CHECK(fabsf(t.bounds.min[2] + 3) < 1e-6f && fabsf(t.bounds.max[2] - 3) < 1e-6f, "z bounds");
	/* Flat normals: each normal is one of the 6 axis directions, 4 vertices each. */
	int axis_count[6] = {0};
	for (uint32_t i = 0; i < t.vc; i++)
		for (int a = 0; a < 3; a++) {
			if (t.v[i].nrm[a] > 0.999f) axis_count[2 * a]++;
			if (t.v[i].nrm[a] < -0.999f) axis_count[2 * a + 1]++;
		}
	for (int a = 0; a < 6; a++) CHECK(axis_count[a] == 4, "face %d has %d vertices", a, axis_count[a]);
	for (uint32_t i = 0; i < t.vc; i++)
		CHECK(t.v[i].uv[0] >= 0 && t.v[i].uv[0] <= 1 && t.v[i].uv[1] >= 0 && t.v[i].uv[1] <= 1, "uv in 0..1");
	struct rnd_aabb lb;
	rnd_mesh_local_bounds(&o, &lb);
	CHECK(lb.min[0] == -1 && lb.max[1] == 2 && lb.max[2] == 3, "local bounds");
	tess_free(&t);
}

TEST(mesh_bounds_grow_not_reset)
{
	struct rnd_object o = shape(RND_SHAPE_BOX);
	struct rnd_vertex v[24];
	uint32_t idx[36];
	struct rnd_aabb b;
	struct rnd_error err;
	rnd_aabb_empty(&b);
	float far[3] = {100, 100, 100};
	rnd_aabb_add_point(&b, far);
	REQUIRE(rnd_mesh_write(&o, v, idx, 0, &b, &err) == RND_OK, "write");
	CHECK(b.max[0] == 100 && b.min[0] == -0.5f && b.min[1] == -0.5f, "bounds grown: %g %g", b.min[0], b.max[0]);
}

TEST(mesh_plane_xz_normal_up)
{
	struct rnd_object o = shape(RND_SHAPE_PLANE);
	o.size[0] = 10; o.size[1] = 0; o.size[2] = 4;
	struct tess t;
	tess_run(&t, &o, 0);
	REQUIRE(t.r == RND_OK, "write");
	for (uint32_t i = 0; i < t.vc; i++) {
		CHECK(t.v[i].pos[1] == 0, "y = 0");
		CHECK(fabsf(t.v[i].pos[0]) == 5 && fabsf(t.v[i].pos[2]) == 2, "corner");
		CHECK(t.v[i].nrm[1] > 0.9999f, "normal +Y");
	}
	for (uint32_t k = 0; k < t.ic; k += 3) {
		float e1[3], e2[3], g[3];
		rnd_v3_sub(e1, t.v[t.i[k + 1]].pos, t.v[t.i[k]].pos);
		rnd_v3_sub(e2, t.v[t.i[k + 2]].pos, t.v[t.i[k]].pos);
		rnd_v3_cross(g, e1, e2);
		CHECK(g[1] > 0, "triangle %u is CCW seen from +Y", k / 3);
	}
	struct rnd_aabb lb;
	rnd_mesh_local_bounds(&o, &lb);
	CHECK(lb.min[0] == -5 && lb.max[0] == 5 && lb.min[1] == 0 && lb.max[1] == 0 && lb.max[2] == 2, "local bounds");
	tess_free(&t);
}

TEST(mesh_cylinder_outward)
{
	static const uint32_t segs[] = {3, 7, 64};
	for (size_t k = 0; k < sizeof segs / sizeof segs[0]; k++) {
		struct rnd_object o = shape(RND_SHAPE_CYLINDER);
		o.segments = segs[k]; o.radius = 0.5f; o.height = 3;
		set_trs(&o, 0, 1.5f, 0, q_id, 1, 1, 1);
		struct tess t;
		tess_run(&t, &o, 0);
		REQUIRE(t.r == RND_OK, "write");
		float c[3] = {0, 1.5f, 0};
		CHECK(check_outward(&t, c, 0, "cylinder") == 0, "segments %u", segs[k]);
		CHECK(fabsf(t.bounds.min[1] - 0) < 1e-6f && fabsf(t.bounds.max[1] - 3) < 1e-6f, "height bounds");
		CHECK(t.bounds.max[0] <= 0.5f + 1e-6f && t.bounds.min[2] >= -0.5f - 1e-6f, "radius bounds");
		tess_free(&t);
	}
}

TEST(mesh_negative_scale_keeps_front_faces)
{
	float h = sqrtf(0.5f), q[4] = {h, 0, 0, h};
	struct { enum rnd_shape s; float sx, sy, sz; } cases[] = {
		{RND_SHAPE_BOX, -1, 1, 1}, {RND_SHAPE_BOX, -2, 1, 3}, {RND_SHAPE_SPHERE, 1, -1, 1},
		{RND_SHAPE_SPHERE, -1, -1, -1}, {RND_SHAPE_CYLINDER, 2, 2, -0.5f}, {RND_SHAPE_BOX, -1, -1, 1},
	};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		struct rnd_object o = shape(cases[k].s);
		o.segments = 12;
		set_trs(&o, 3, -1, 2, q, cases[k].sx, cases[k].sy, cases[k].sz);
		struct tess t;
		tess_run(&t, &o, 0);
		REQUIRE(t.r == RND_OK, "write");
		float c[3] = {3, -1, 2};
		CHECK(check_outward(&t, c, 0, "mirrored") == 0, "case %zu (scale %g %g %g)", k, cases[k].sx,
		      cases[k].sy, cases[k].sz);
		tess_free(&t);
	}
}

TEST(mesh_base_vertex_offsets_indices)
{
	struct rnd_object o = shape(RND_SHAPE_SPHERE);
	o.segments = 8;
	struct tess t;
	tess_run(&t, &o, 1000);
	REQUIRE(t.r == RND_OK, "write");
	uint32_t lo = UINT32_MAX, hi = 0;
	for (uint32_t k = 0; k < t.ic; k++) {
		if (t.i[k] < lo) lo = t.i[k];
		if (t.i[k] > hi) hi = t.i[k];
	}
	CHECK(lo == 1000 && hi < 1000 + t.vc && hi >= 1000 + t.vc - 2, "indices span [%u, %u]", lo, hi);
	float c[3] = {0, 0, 0};
	CHECK(check_outward(&t, c, 1000, "offset sphere") == 0, "outward");
	tess_free(&t);
}

TEST(mesh_flat_normals_computed)
{
	/* A tetrahedron, CCW from outside, without normals: flat normals per face. */
	float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
	uint32_t idx[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
	struct rnd_object o = shape(RND_SHAPE_MESH);
	o.positions = pos; o.vertex_count = 4; o.indices = idx; o.index_count = 12;
	set_trs(&o, 0, 0, 0, q_id, 2, 2, 2);
	struct tess t;
	tess_run(&t, &o, 0);
	REQUIRE(t.r == RND_OK, "write: %s", t.err.msg);
	float c[3] = {0.5f, 0.5f, 0.5f};
	CHECK(check_outward(&t, c, 0, "tetrahedron") == 0, "outward");
	/* The first face (0,2,1) lies in z = 0: its normal is -Z on all three vertices. */
	for (int k = 0; k < 3; k++) CHECK(t.v[k].nrm[2] < -0.9999f, "face 0 normal -Z");
	float s = 1.0f / sqrtf(3.0f);
	for (int k = 9; k < 12; k++)
		CHECK(fabsf(t.v[k].nrm[0] - s) < 1e-5f && fabsf(t.v[k].nrm[1] - s) < 1e-5f, "slanted face normal");
	CHECK(t.bounds.max[0] == 2 && t.bounds.max[2] == 2 && t.bounds.min[1] == 0, "bounds scaled");
	/* Mirrored: winding and normals still agree and point outward. */
	tess_free(&t);
	set_trs(&o, 0, 0, 0, q_id, -1, 1, 1);
	tess_run(&t, &o, 0);
	REQUIRE(t.r == RND_OK, "write mirrored");
	float cm[3] = {-0.25f, 0.25f, 0.25f};
	CHECK(check_outward(&t, cm, 0, "mirrored tetrahedron") == 0, "outward mirrored");
	tess_free(&t);
}

TEST(mesh_given_normals_and_uvs)
{
	float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	float nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
	float uvs[6] = {0, 0, 1, 0, 0, 1};
	uint32_t idx[3] = {0, 1, 2};
	struct rnd_object o = shape(RND_SHAPE_MESH);
	o.positions = pos; o.vertex_count = 3; o.indices = idx; o.index_count = 3; o.normals = nrm; o.uvs = uvs;
	set_trs(&o, 0, 0, 5, q_id, 1, 1, 4);
	struct tess t;
	tess_run(&t, &o, 7);
	REQUIRE(t.r == RND_OK, "write: %s", t.err.msg);
	CHECK(t.vc == 3 && t.ic == 3, "as given");
	CHECK(t.i[0] == 7 && t.i[1] == 8 && t.i[2] == 9, "offset indices");
	CHECK(t.v[1].pos[0] == 1 && t.v[1].pos[2] == 5, "translated");
	CHECK(t.v[2].uv[1] == 1 && t.v[1].uv[0] == 1, "uvs copied");
	for (int k = 0; k < 3; k++) CHECK(fabsf(t.v[k].nrm[2] - 1) < 1e-6f, "normal renormalised after scale");
	tess_free(&t);
	/* Triangle list without indices, with normals. */
	o.indices = NULL; o.index_count = 0;
	tess_run(&t, &o, 0);
	REQUIRE(t.r == RND_OK, "write list: %s", t.err.msg);
	CHECK(t.vc == 3 && t.i[0] == 0 && t.i[2] == 2, "list indices");
	tess_free(&t);
}

TEST(mesh_rejects_bad_indices)
{
	float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	uint32_t idx[3] = {0, 1, 3};
	struct rnd_object o = shape(RND_SHAPE_MESH);
	o.positions = pos; o.vertex_count = 3; o.indices = idx; o.index_count = 3;
	struct tess t;
	tess_run(&t, &o, 0);
	CHECK(t.r == RND_ERR_INVALID, "out-of-range index rejected: %d", t.r);
	CHECK(t.err.code == RND_ERR_INVALID && strstr(t.err.msg, "index") != NULL, "message: %s", t.err.msg);
	tess_free(&t);

	uint32_t idx4[4] = {0, 1, 2, 0};
	o.indices = idx4; o.index_count = 4;
	tess_run(&t, &o, 0);
	CHECK(t.r == RND_ERR_INVALID && strstr(t.err.msg, "multiple of 3"), "index count 4: %s", t.err.msg);
	tess_free(&t);

	o.indices = NULL; o.index_count = 0; o.vertex_count = 2;
	tess_run(&t, &o, 0);
	CHECK(t.r == RND_ERR_INVALID && strstr(t.err.msg, "multiple of 3"), "2 vertices: %s", t.err.msg);
	tess_free(&t);

	float nanpos[9] = {0, 0, 0, NAN, 0, 0, 0, 1, 0};
	o.positions = nanpos; o.vertex_count = 3;
	tess_run(&t, &o, 0);
	CHECK(t.r == RND_ERR_INVALID && strstr(t.err.msg, "finite"), "NaN position: %s", t.err.msg);
	tess_free(&t);
}

TEST(mesh_rejects_singular_model)
{
	struct rnd_object o = shape(RND_SHAPE_BOX);
	set_trs(&o, 0, 0, 0, q_id, 1, 0, 1);
	struct tess t;
	tess_run(&t, &o, 0);
	CHECK(t.r == RND_ERR_INVALID && t.err.msg[0] != 0, "singular model: %d %s", t.r, t.err.msg);
	tess_free(&t);
}

TEST(mesh_local_bounds_shapes)
{
	struct rnd_aabb b;
	struct rnd_object o = shape(RND_SHAPE_SPHERE);
	o.radius = 3;
	rnd_mesh_local_bounds(&o, &b);
	CHECK(b.min[0] == -3 && b.max[1] == 3 && b.max[2] == 3, "sphere");
	o = shape(RND_SHAPE_CYLINDER);
	o.radius = 2; o.height = 5;
	rnd_mesh_local_bounds(&o, &b);
	CHECK(b.min[0] == -2 && b.max[1] == 2.5f && b.min[1] == -2.5f && b.max[2] == 2, "cylinder");
	float pos[9] = {1, 2, 3, -1, 0, 7, 4, -5, 0};
	o = shape(RND_SHAPE_MESH);
	o.positions = pos; o.vertex_count = 3;
	rnd_mesh_local_bounds(&o, &b);
	CHECK(b.min[0] == -1 && b.min[1] == -5 && b.min[2] == 0 && b.max[0] == 4 && b.max[1] == 2 && b.max[2] == 7, "mesh");
	o.vertex_count = 0;
	rnd_mesh_local_bounds(&o, &b);
	CHECK(rnd_aabb_is_empty(&b), "empty mesh");
}

TEST(scene_defaults_contract)
{
	struct rnd_scene s;
	rnd_scene_defaults(&s);
	CHECK(s.width == 512 && s.height == 512, "512x512");
	CHECK(s.camera.type == RND_CAMERA_PERSPECTIVE && fabsf(s.camera.fov_y - PI_F / 4) < 1e-6f, "fov 45");
	CHECK(s.camera.position[2] == 5 && s.camera.target[0] == 0 && s.camera.up[1] == 1, "camera frame");
	CHECK(s.environment.background[0] == 0.5f && s.environment.background[3] == 1, "background");
	CHECK(s.environment.ambient_sky[2] == 0.9f && s.environment.ambient_ground[0] == 0.3f &&
	      s.environment.ambient_intensity == 0.3f, "ambient");
	CHECK(s.output.pixels == RND_PIXELS_RGBA8 && s.output.tonemap == RND_TONEMAP_NEUTRAL && s.output.msaa == 4, "output");
	CHECK(s.object_count == 0 && s.light_count == 0 && s.objects == NULL, "empty scene");

	struct rnd_material m;
	rnd_material_defaults(&m);
	CHECK(m.base_color[0] == 0.8f && m.base_color[3] == 1 && m.roughness == 0.5f && m.alpha_cutoff == 0.5f, "material");

	struct rnd_object o;
	rnd_object_defaults(&o);
	float id[16];
	rnd_mat4_identity(id);
	CHECK(memcmp(o.model, id, sizeof id) == 0, "identity model");
	CHECK(o.segments == 64 && o.radius == 1 && o.height == 1 && o.size[1] == 1, "shape defaults");
	CHECK(o.cast_shadows && o.receive_shadows && o.double_sided, "flags");

	struct rnd_light l;
	rnd_light_defaults(&l, RND_LIGHT_DIRECTIONAL);
	CHECK(l.intensity == 3 && l.color[1] == 1 && l.shadow.enabled, "directional");
	rnd_light_defaults(&l, RND_LIGHT_SPOT);
	CHECK(l.type == RND_LIGHT_SPOT && l.intensity == 10 && fabsf(l.outer_angle - PI_F / 4) < 1e-6f &&
	      l.inner_angle == 0, "spot");
	rnd_light_defaults(&l, RND_LIGHT_POINT);
	CHECK(l.intensity == 10 && l.range == 0 && l.radius == 0, "point");
	CHECK(l.shadow.filter == RND_FILTER_AUTO && l.shadow.pcf_radius == 1 && l.shadow.split_lambda == 0.75f &&
	      l.shadow.blend == 0.1f && l.shadow.fade == 0.1f && l.shadow.vsm_blur == 2 &&
	      l.shadow.vsm_light_bleed == 0.2f && !l.shadow.contact_enabled && l.shadow.resolution == 0, "shadow");
}

TEST(scene_image_release_and_result_str)
{
	rnd_image_release(NULL);
	struct rnd_image img = {0};
	rnd_image_release(&img);
	img.width = 4; img.height = 4;
	img.pixels = malloc(64);
	img.aov_count = 2;
	img.aov[0] = malloc(64);
	img.aov[1] = malloc(64);
	rnd_image_release(&img);   /* ASan reports a leak if a plane is not freed */
	CHECK(img.pixels == NULL && img.aov[0] == NULL && img.aov_count == 0 && img.width == 0, "zeroed");
	CHECK(strcmp(rnd_result_str(RND_OK), "ok") == 0, "ok");
	for (int r = RND_ERR_INVALID; r <= RND_ERR_IO; r++) {
		const char *s = rnd_result_str((enum rnd_result)r);
		CHECK(s && s[0] && strcmp(s, "unknown result") != 0, "name of %d", r);
	}
}
