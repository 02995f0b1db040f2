/* tests — api/model_lod.c (meshoptimizer levels of imported meshes) and the renderer's choice
 * of a level (renderer/lod.c): a flat-shaded UV sphere (every facet its own vertices, as an STL
 * arrives) gets, for smaller and smaller images, levels of fewer and fewer triangles whose
 * claimed error bounds how far their surface is from the sphere, with outward unit normals; the
 * level chosen for a pixel size is the coarsest whose error fits. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"
#include "arena.h"
#include <meshoptimizer.h>
#include "lod.h"
#include "lod_error.h"
#include "lod_simplify.h"
#include "model_conv.h"
#include "model_lod.h"
#include "weld.h"
#include "workers.h"

#define PI_D 3.14159265358979323846

/* A unit UV sphere of seg x seg quads, flat-shaded: 6 vertices per quad, face normals. */
static void flat_sphere(int seg, float **pos, float **nrm, uint32_t **idx, uint32_t *nv, uint32_t *ni)
{
	*nv = *ni = (uint32_t)(6 * seg * seg);
	*pos = malloc(*nv * 12);
	*nrm = malloc(*nv * 12);
	*idx = malloc(*ni * 4);
	uint32_t k = 0;
	for (int i = 0; i < seg; i++)
		for (int j = 0; j < seg; j++) {
			double q[4][3];
			for (int c = 0; c < 4; c++) {
				int ii = i + (c >> 1), jj = (j + (c & 1)) % seg;
				double th = PI_D * ii / seg, ph = 2 * PI_D * jj / seg;
				q[c][0] = -sin(th) * cos(ph); q[c][1] = cos(th); q[c][2] = sin(th) * sin(ph); /* as mesh.c */
				if (ii == 0 || ii == seg) q[c][0] = q[c][2] = 0; /* poles: one position */
			}
			static const int tri[2][3] = {{0, 2, 1}, {1, 2, 3}};
			for (int t = 0; t < 2; t++)
				for (int c = 0; c < 3; c++, k++) {
					for (int a = 0; a < 3; a++) (*pos)[3 * k + a] = (float)q[tri[t][c]][a];
					double m[3] = {0, 0, 0};
					for (int cc = 0; cc < 3; cc++)
						for (int a = 0; a < 3; a++) m[a] += q[tri[t][cc]][a] / 3;
					double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
					for (int a = 0; a < 3; a++) (*nrm)[3 * k + a] = (float)(m[a] / l);
					(*idx)[k] = k;
				}
		}
}

/* The levels of the one mesh me for images of 1024, 256, 64 and 16 pixels, finest first, as
 * me->lods (at most 4, in `keep`); returns the arena holding them (the caller destroys it) and
 * the bytes charged for them. */
static struct api_arena *build_levels(struct api_model_mesh *me, struct rnd_mesh_lod keep[4], size_t *bytes)
{
	struct api_model m = {0};
	m.meshes = me;
	m.mesh_count = 1;
	struct api_arena *a = api_arena_create();
	*bytes = 0;
	uint32_t n = 0;
	static const uint32_t sides[4] = {1024, 256, 64, 16};
	for (int k = 0; k < 4; k++) {
		me->lods = NULL;
		me->lod_count = 0;
		api_model_build_level(&m, sides[k], a, bytes);
		if (me->lod_count) keep[n++] = me->lods[0];
	}
	me->lods = keep;
	me->lod_count = n;
	return a;
}

TEST(model_lod_levels_of_flat_sphere_keep_their_error)
{
	float *pos, *nrm;
	uint32_t *idx, nv, ni;
	flat_sphere(160, &pos, &nrm, &idx, &nv, &ni); /* 51,200 triangles */
	struct api_model_mesh me = {.positions = pos, .normals = nrm, .indices = idx, .vertex_count = nv, .index_count = ni};
	size_t bytes;
	struct rnd_mesh_lod keep[4];
	struct api_arena *a = build_levels(&me, keep, &bytes);
	REQUIRE(me.lod_count >= 3, "levels: %u", me.lod_count);
	CHECK(bytes > 0, "the cache is charged for the levels");
	uint32_t prev_tris = ni / 3;
	float prev_err = 0;
	for (uint32_t l = 0; l < me.lod_count; l++) {
		const struct rnd_mesh_lod *lv = &me.lods[l];
		uint32_t tris = lv->index_count / 3;
		CHECK(tris * 4 <= prev_tris * 3, "level %u: %u triangles after %u", l + 1, tris, prev_tris);
		CHECK(lv->error >= prev_err && lv->error > 0, "level %u: error %g after %g", l + 1, lv->error, prev_err);
		CHECK(lv->vertex_count < lv->index_count, "level %u is indexed (%u vertices)", l + 1, lv->vertex_count);
		/* The claimed error bounds the distance of the level's surface from the sphere (beyond the
		 * input's own chord error): every vertex and every triangle's centroid. */
		double input = 1 - cos(PI_D / 160), worst = 0;
		for (uint32_t t = 0; t < tris; t++) {
			double c[3] = {0, 0, 0};
			for (int k = 0; k < 3; k++) {
				const float *p = lv->positions + 3 * lv->indices[3 * t + (uint32_t)k];
				for (int x = 0; x < 3; x++) c[x] += p[x] / 3;
				double r = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
				worst = fmax(worst, fabs(r - 1));
			}
			worst = fmax(worst, fabs(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) - 1));
		}
		CHECK(worst <= lv->error + input + 1e-5, "level %u: surface %g from the sphere, claimed %g", l + 1, worst,
		      lv->error);
		/* Normals: unit, never inward, and smooth across the facets: nearly all within 26 degrees
		 * of the sphere's (a coarse level's few steep fan triangles at the poles get creases). */
		int inward = 0, off = 0;
		for (uint32_t v = 0; v < lv->vertex_count; v++) {
			const float *p = lv->positions + 3 * v, *n = lv->normals + 3 * v;
			double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
			double r = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
			double cosang = (n[0] * p[0] + n[1] * p[1] + n[2] * p[2]) / r;
			if (fabs(len - 1) > 1e-3 || cosang <= 0) inward++;
			if (cosang < 0.9) off++;
		}
		CHECK(inward == 0, "level %u: %d normals not unit or inward", l + 1, inward);
		CHECK(off * 50 <= (int)lv->vertex_count, "level %u: %d of %u normals more than 26 degrees off", l + 1, off,
		      lv->vertex_count);
		prev_tris = tris;
		prev_err = lv->error;
	}
	api_arena_destroy(a);
	free(pos); free(nrm); free(idx);
}

/* Another part close by: an "eyeball", a sphere of radius 0.3 whose top pokes through the unit
 * sphere's surface (centre at z 0.75), both flat-shaded. A level's error is its distance from
 * the full mesh; the eyeball's vertices next to the big sphere's triangles, with their normals
 * every which way, must not inflate it (measured from the nearest vertex in space and its
 * tangent plane, the 124k-triangle ogre OBJ's eyes and creases made every level look 0.29 of
 * its height off, so that none was ever drawn). */
TEST(model_lod_error_ignores_a_part_close_by)
{
	float *pos, *nrm, *pos2, *nrm2;
	uint32_t *idx, *idx2, nv, ni, nv2, ni2;
	flat_sphere(160, &pos, &nrm, &idx, &nv, &ni);
	flat_sphere(40, &pos2, &nrm2, &idx2, &nv2, &ni2);
	float *p = malloc((size_t)(nv + nv2) * 12), *n = malloc((size_t)(nv + nv2) * 12);
	uint32_t *x = malloc((size_t)(ni + ni2) * 4);
	memcpy(p, pos, (size_t)nv * 12);
	memcpy(n, nrm, (size_t)nv * 12);
	for (uint32_t i = 0; i < nv2; i++)
		for (int k = 0; k < 3; k++) {
			p[3 * (nv + i) + (uint32_t)k] = 0.3f * pos2[3 * i + (uint32_t)k] + (k == 2 ? 0.75f : 0.0f);
			n[3 * (nv + i) + (uint32_t)k] = nrm2[3 * i + (uint32_t)k];
		}
	memcpy(x, idx, (size_t)ni * 4);
	for (uint32_t i = 0; i < ni2; i++) x[ni + i] = nv + idx2[i];
	struct api_model_mesh me = {.positions = p, .normals = n, .indices = x, .vertex_count = nv + nv2,
	                            .index_count = ni + ni2};
	size_t bytes;
	struct rnd_mesh_lod keep[4];
	struct api_arena *a = build_levels(&me, keep, &bytes);
	REQUIRE(me.lod_count >= 2, "levels: %u", me.lod_count);
	/* each level's triangles against the two spheres: its claimed error is not far above that */
	for (uint32_t l = 0; l < 2; l++) {
		const struct rnd_mesh_lod *lv = &me.lods[l];
		double worst = 0;
		for (uint32_t t = 0; t < lv->index_count / 3; t++) {
			double c[3] = {0, 0, 0};
			for (int k = 0; k < 3; k++)
				for (int q = 0; q < 3; q++) c[q] += lv->positions[3 * lv->indices[3 * t + (uint32_t)k] + (uint32_t)q] / 3;
			double r = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
			double r2 = sqrt(c[0] * c[0] + c[1] * c[1] + (c[2] - 0.75) * (c[2] - 0.75));
			worst = fmax(worst, fmin(fabs(r - 1), fabs(r2 - 0.3)));
		}
		printf("    level %u: %u triangles, claimed error %.5f, centroids within %.5f of a sphere\n", l + 1,
		       lv->index_count / 3, lv->error, worst);
		CHECK(lv->error <= 2 * worst + 0.002, "level %u claims %g, its centroids are within %g of the spheres", l + 1,
		      lv->error, worst);
	}
	api_arena_destroy(a);
	free(pos); free(nrm); free(idx); free(pos2); free(nrm2); free(idx2); free(p); free(n); free(x);
}

/* Both uv sets and the tangents (a normal map's) travel into the levels: each level vertex has
 * those of a full-mesh vertex at its position (here uv = (x, y), uv1 = (z, x + y), the tangent
 * (-z, 0, x) with w the hemisphere's sign: functions of the position, so exact). A mesh with
 * tangents had no level at all before: it drew every triangle into every thumbnail and its
 * environment maps. */
TEST(model_lod_levels_carry_uv_sets_and_tangents)
{
	float *pos, *nrm;
	uint32_t *idx, nv, ni;
	flat_sphere(160, &pos, &nrm, &idx, &nv, &ni);
	float *uv = malloc(nv * 8), *uv1 = malloc(nv * 8), *tan = malloc(nv * 16);
	REQUIRE(uv && uv1 && tan);
	for (uint32_t v = 0; v < nv; v++) {
		const float *p = pos + 3 * v;
		uv[2 * v] = p[0], uv[2 * v + 1] = p[1];
		uv1[2 * v] = p[2], uv1[2 * v + 1] = p[0] + p[1];
		tan[4 * v] = -p[2], tan[4 * v + 1] = 0.0f, tan[4 * v + 2] = p[0], tan[4 * v + 3] = p[1] < 0.0f ? -1.0f : 1.0f;
	}
	struct api_model_mesh me = {.positions = pos, .normals = nrm, .uvs = uv, .uvs1 = uv1, .tangents = tan,
	                            .indices = idx, .vertex_count = nv, .index_count = ni};
	CHECK(api_mesh_wants_levels(&me));
	size_t bytes;
	struct rnd_mesh_lod keep[4];
	struct api_arena *a = build_levels(&me, keep, &bytes);
	REQUIRE(me.lod_count >= 2, "levels: %u", me.lod_count);
	for (uint32_t l = 0; l < me.lod_count; l++) {
		const struct rnd_mesh_lod *lv = &me.lods[l];
		REQUIRE(lv->uvs && lv->uvs1 && lv->tangents, "level %u has uvs %p, uvs1 %p, tangents %p", l + 1,
		        (void *)lv->uvs, (void *)lv->uvs1, (void *)lv->tangents);
		CHECK(lv->index_count * 4 <= ni * 3, "level %u: %u of %u indices", l + 1, lv->index_count, ni);
		uint32_t wrong = 0;
		for (uint32_t v = 0; v < lv->vertex_count; v++) {
			const float *p = lv->positions + 3 * v, *t = lv->uvs + 2 * v, *t1 = lv->uvs1 + 2 * v, *g = lv->tangents + 4 * v;
			wrong += t[0] != p[0] || t[1] != p[1] || t1[0] != p[2] || t1[1] != p[0] + p[1] || g[0] != -p[2] || g[1] != 0.0f ||
			         g[2] != p[0] || g[3] != (p[1] < 0.0f ? -1.0f : 1.0f);
		}
		CHECK(wrong == 0, "level %u: %u of %u vertices with other uvs or tangents", l + 1, wrong, lv->vertex_count);
	}
	api_arena_destroy(a);
	free(pos); free(nrm); free(idx); free(uv); free(uv1); free(tan);
}

TEST(model_lod_small_meshes_get_no_levels)
{
	float *pos, *nrm;
	uint32_t *idx, nv, ni;
	flat_sphere(40, &pos, &nrm, &idx, &nv, &ni); /* 3,200 triangles */
	struct api_model_mesh me = {.positions = pos, .normals = nrm, .indices = idx, .vertex_count = nv, .index_count = ni};
	struct api_model m = {0};
	m.meshes = &me;
	m.mesh_count = 1;
	struct api_arena *a = api_arena_create();
	size_t bytes = 0;
	api_model_build_level(&m, 64, a, &bytes);
	CHECK(me.lod_count == 0 && bytes == 0, "%u levels", me.lod_count);
	api_arena_destroy(a);
	free(pos); free(nrm); free(idx);
}

TEST(lod_mesh_level_is_coarsest_within_bound)
{
	static const float p[3] = {0, 0, 0};
	struct rnd_mesh_lod lv[3] = {{p, p, NULL, NULL, 1, 0, 0.001f}, {p, p, NULL, NULL, 1, 0, 0.01f},
	                             {p, p, NULL, NULL, 1, 0, 0.1f}};
	struct rnd_object o;
	rnd_object_defaults(&o);
	o.shape = RND_SHAPE_MESH;
	o.lods = lv;
	o.lod_count = 3;
	CHECK(rnd_lod_mesh_level(&o, 0.01f, 0.25f) == 1, "allowed 0.0025: level 1 (0.001)");
	CHECK(rnd_lod_mesh_level(&o, 0.001f, 0.25f) == 0, "allowed 0.00025: the full mesh");
	CHECK(rnd_lod_mesh_level(&o, 1.0f, 0.25f) == 3, "allowed 0.25: the coarsest");
	o.model[0] = o.model[5] = o.model[10] = 4.0f; /* four times larger: errors too */
	CHECK(rnd_lod_mesh_level(&o, 0.01f, 0.25f) == 0, "scaled 4: allowed 0.000625 in object units");
	struct rnd_object full = o;
	rnd_lod_apply(&full, 0);
	CHECK(full.index_count == o.index_count && full.positions == o.positions, "level 0 is the mesh as given");
	rnd_lod_apply(&full, 2);
	CHECK(full.positions == lv[1].positions && full.vertex_count == 1, "level 2 swaps in lods[1]");
}

TEST(model_mesh_closed_needs_watertight_outward_winding)
{
	/* a tetrahedron wound outward (counter-clockwise seen from outside) */
	static const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
	static const uint32_t out[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
	uint32_t in[12], open[9], twisted[12];
	for (int i = 0; i < 12; i += 3) { in[i] = out[i]; in[i + 1] = out[i + 2]; in[i + 2] = out[i + 1]; }
	memcpy(open, out, sizeof open);
	memcpy(twisted, out, sizeof twisted);
	twisted[1] = out[2]; twisted[2] = out[1]; /* one face turned around */
	CHECK(api_mesh_closed(out, 12, pos, 4), "outward tetrahedron");
	CHECK(!api_mesh_closed(in, 12, pos, 4), "inward: back faces are what shows from outside");
	CHECK(!api_mesh_closed(open, 9, pos, 4), "a face missing");
	CHECK(!api_mesh_closed(twisted, 12, pos, 4), "one face wound the other way");
	uint32_t doubled[24];
	memcpy(doubled, out, sizeof out);
	memcpy(doubled + 12, out, sizeof out);
	CHECK(!api_mesh_closed(doubled, 24, pos, 4), "every edge used four times");
	CHECK(!api_mesh_closed(out, 12, pos, 3), "an index past the vertices");
	/* two tetrahedra sharing vertex 0 (a pinch): still two closed volumes, its edges sorted at
	 * one vertex among six others */
	static const float pos2[21] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0, 0, -1, 0, 0, 0, -1};
	uint32_t two[24];
	memcpy(two, out, sizeof out);
	for (int i = 0; i < 12; i++) two[12 + i] = out[i] ? out[i] + 3 : 0;   /* mirrored: wound the other way */
	for (int i = 12; i < 24; i += 3) { uint32_t t = two[i + 1]; two[i + 1] = two[i + 2]; two[i + 2] = t; }
	CHECK(api_mesh_closed(two, 24, pos2, 7), "two tetrahedra pinched at a vertex");
	/* a flat-shaded sphere (no vertex shared) is closed once welded by position */
	float *p, *n;
	uint32_t *idx, nv, ni;
	flat_sphere(40, &p, &n, &idx, &nv, &ni);
	CHECK(!api_mesh_closed(idx, ni, p, nv), "unwelded facets share no edge");
	struct api_model_mesh me = {.positions = p, .normals = n, .indices = idx, .vertex_count = nv, .index_count = ni};
	struct api_model m = {0};
	m.meshes = &me;
	m.mesh_count = 1;
	struct api_arena *a = api_arena_create();
	size_t bytes = 0;
	api_model_finish_import(&m, 0, a, &bytes);
	api_arena_destroy(a);
	CHECK(me.closed, "welded flat sphere is closed");
	free(p); free(n); free(idx);
}

/* The triangles of a (seg + 1)^2-vertex latitude-longitude grid (vertex i * (seg + 1) + j),
 * two a quad, 6 seg^2 indices into idx. */
static void grid_sphere_indices(uint32_t seg, uint32_t *idx)
{
	uint32_t k = 0;
	for (uint32_t i = 0; i < seg; i++)
		for (uint32_t j = 0; j < seg; j++) {
			uint32_t q[4] = {i * (seg + 1) + j, i * (seg + 1) + j + 1, (i + 1) * (seg + 1) + j, (i + 1) * (seg + 1) + j + 1};
			uint32_t t[6] = {q[0], q[2], q[1], q[1], q[2], q[3]};
			memcpy(idx + k, t, sizeof t);
			k += 6;
		}
}

/* The centroid of each triangle idx[0..ni) over pos: its largest distance from the unit sphere. */
static double worst_centroid(const float *pos, const uint32_t *idx, size_t ni)
{
	double worst = 0;
	for (size_t t = 0; t + 2 < ni; t += 3) {
		double c[3] = {0, 0, 0};
		for (int k = 0; k < 3; k++)
			for (int x = 0; x < 3; x++) c[x] += pos[3 * (size_t)idx[t + (size_t)k] + (size_t)x] / 3.0;
		worst = fmax(worst, fabs(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) - 1));
	}
	return worst;
}

/* A mesh of 8 times API_LOD_PIECE_TRIANGLES or more is simplified in pieces, then as a whole:
 * as coarse and about as close as meshoptimizer's one pass over it (the pieces' cuts, kept by
 * the first passes, gone: they would leave thousands of triangles along three great circles).
 * On this sphere: 11.3k triangles 0.0015 from it, against 14.1k and 0.0018. */
TEST(model_lod_large_mesh_simplified_in_pieces)
{
	enum { SEG = 360 };   /* 2 x 360^2 = 259,200 triangles: 8 pieces */
	uint32_t nv = (SEG + 1) * (SEG + 1), ni = 6 * SEG * SEG;
	float *pos = malloc(nv * 12ull);
	uint32_t *idx = malloc(ni * 4ull), *a = malloc(ni * 4ull), *b = malloc(ni * 4ull);
	REQUIRE(pos && idx && a && b);
	for (uint32_t i = 0; i <= SEG; i++)
		for (uint32_t j = 0; j <= SEG; j++) {
			double th = PI_D * i / SEG, ph = 2 * PI_D * j / SEG;
			float *p = pos + 3 * (i * (SEG + 1) + j);
			p[0] = (float)(sin(th) * cos(ph)), p[1] = (float)cos(th), p[2] = (float)(sin(th) * sin(ph));
		}
	grid_sphere_indices(SEG, idx);
	REQUIRE(ni / 3 >= 8 * API_LOD_PIECE_TRIANGLES);
	float target = 0.25f * api_lod_import_error(256);
	size_t na = api_lod_simplify(a, idx, ni, pos, nv, 2.0f, target);
	size_t nb = meshopt_simplify(b, idx, ni, pos, nv, 12, 3, target, 0, NULL);
	int bad = 0;
	for (size_t i = 0; i < na; i++) bad += a[i] >= nv;
	CHECK(bad == 0 && na % 3 == 0, "%d indices out of range", bad);
	CHECK(na * 10 < ni && na * 10 <= nb * 11 && na * 2 >= nb, "pieces: %zu triangles, one pass %zu, of %u", na / 3,
	      nb / 3, ni / 3);
	double ea = worst_centroid(pos, a, na), eb = worst_centroid(pos, b, nb), input = 1 - cos(PI_D / SEG);
	CHECK(ea <= 1.5 * eb + input, "pieces: centroids up to %g from the sphere, one pass %g", ea, eb);
	free(pos);
	free(idx);
	free(a);
	free(b);
}

/* A level's measured error (api/lod_error.h): walking its triangles in order of their cheap
 * estimates, skipping those whose few faces downhill already prove them within the worst, and
 * the nearest-vertex search narrowed to the cells that can hold a nearer one, comes out as the
 * figure it stands for (every triangle walked to the end), bit for bit, on a bumpy sphere of
 * shared vertices (radius 1 + 0.04 sin 6 theta sin 5 phi) and its levels at three aims; and the
 * figure is not a hair above the distance of the level's centroids from the surface (a
 * lower bound of it: the full mesh's chords sit within `input` of the sphere). */
TEST(model_lod_level_error_ordered_equals_every_walk)
{
	enum { SEG = 200 };   /* 2 x 200^2 = 80,000 triangles */
	uint32_t nv = (SEG + 1) * (SEG + 1), ni = 6 * SEG * SEG;
	float *pos = malloc(nv * 12ull), *nrm = malloc(nv * 12ull);
	uint32_t *idx = malloc(ni * 4ull), *lv = malloc(ni * 4ull);
	REQUIRE(pos && nrm && idx && lv);
	for (uint32_t i = 0; i <= SEG; i++)
		for (uint32_t j = 0; j <= SEG; j++) {
			double th = PI_D * i / SEG, ph = 2 * PI_D * j / SEG, r = 1 + 0.04 * sin(6 * th) * sin(5 * ph);
			float *p = pos + 3 * (i * (SEG + 1) + j), *n = nrm + 3 * (i * (SEG + 1) + j);
			n[0] = (float)(sin(th) * cos(ph)), n[1] = (float)cos(th), n[2] = (float)(sin(th) * sin(ph));
			for (int k = 0; k < 3; k++) p[k] = (float)(r * n[k]);
		}
	grid_sphere_indices(SEG, idx);
	float lo[3], hi[3], ext = api_points_box(pos, nv, lo, hi);
	struct api_lod_measure *m = api_lod_measure_create(pos, nrm, nv, idx, ni, lo, hi, ext);
	REQUIRE(m);
	const float aims[3] = {0.0005f, 0.002f, 0.008f};
	for (int a = 0; a < 3; a++) {
		size_t nl = api_lod_simplify(lv, idx, ni, pos, nv, 2.08f, aims[a]);
		REQUIRE(nl >= 3 && nl < ni, "aim %g: %zu indices", aims[a], nl);
		float fast = api_lod_measure_level(m, lv, nl, false), all = api_lod_measure_level(m, lv, nl, true);
		printf("    aim %g: %zu triangles, error %g, every triangle walked %g\n", aims[a], nl / 3, fast, all);
		CHECK(fast == all, "aim %g: %.9g measured, %.9g walking every triangle", aims[a], fast, all);
		/* the centroids' distance from the bumpy sphere, less the full mesh's own chord error */
		double worst = 0, input = 0.04 * 6 * PI_D / SEG * PI_D / SEG + 1 - cos(PI_D / SEG);
		for (size_t t = 0; t < nl; t += 3) {
			double c[3] = {0, 0, 0};
			for (int v = 0; v < 3; v++)
				for (int x = 0; x < 3; x++) c[x] += pos[3 * (size_t)lv[t + (size_t)v] + (size_t)x] / 3.0;
			double r = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), th = acos(c[1] / r), ph = atan2(c[2], c[0]);
			worst = fmax(worst, fabs(r - (1 + 0.04 * sin(6 * th) * sin(5 * ph))));
		}
		CHECK(fast >= worst * 0.5 - input, "aim %g: measured %g, centroids %g off the surface", aims[a], fast, worst);
	}
	api_lod_measure_destroy(m);
	free(pos);
	free(nrm);
	free(idx);
	free(lv);
}

/* The worst-first walk must give the every-walk figure where the cheap estimate misranks the
 * level's triangles (on the bumpy sphere above the worst estimate is also the worst triangle,
 * so a measure that walked only the first triangle, or stopped at estimates under the worst
 * instead of under half of it, passed there). A flat 15 x 7 grid (spacing 0.05) with two domes,
 * b sin(pi u) sin(pi v) over 6 x 6 cells each, and a level of one triangle over each, corners on
 * the dome's rim: every sample of a level triangle (centroid, edge midpoints) lies right under a
 * full-mesh vertex, so the estimate is the dome's height there times that vertex normal's y.
 * Dome A: 0.009 high, normals up: estimate 0.009, truth ~0.009. Dome W: 0.02 high, its normals
 * leaning to y = 0.3 (a model's authored normals can): estimate 0.006, truth ~0.02. A is walked
 * first; W's estimate is under A's truth but over half of it, so W must be walked too. */
TEST(model_lod_level_error_walks_a_misranked_worst)
{
	enum { NI = 15, NJ = 7 };
	float pos[NI * NJ * 3], nrm[NI * NJ * 3];
	uint32_t idx[(NI - 1) * (NJ - 1) * 6], ni = 0;
	for (uint32_t i = 0; i < NI; i++)
		for (uint32_t j = 0; j < NJ; j++) {
			float *p = pos + 3 * (i * NJ + j), *n = nrm + 3 * (i * NJ + j);
			bool w = i >= 8;
			double u = ((double)i - (w ? 8 : 0)) / 6, v = (double)j / 6, b = w ? 0.02 : 0.009;
			p[0] = 0.05f * (float)i, p[2] = 0.05f * (float)j;
			p[1] = i == 7 ? 0.0f : (float)(b * sin(PI_D * u) * sin(PI_D * v));
			n[0] = w ? (float)sqrt(1 - 0.09) : 0.0f, n[1] = w ? 0.3f : 1.0f, n[2] = 0.0f;
		}
	for (uint32_t i = 0; i + 1 < NI; i++)
		for (uint32_t j = 0; j + 1 < NJ; j++) {
			uint32_t a = i * NJ + j, q[6] = {a, a + 1, a + NJ, a + 1, a + NJ + 1, a + NJ};
			for (int k = 0; k < 6; k++) idx[ni++] = q[k];
		}
	float lo[3], hi[3], ext = api_points_box(pos, NI * NJ, lo, hi);
	struct api_lod_measure *m = api_lod_measure_create(pos, nrm, NI * NJ, idx, ni, lo, hi, ext);
	REQUIRE(m);
	/* dome A: corners (0,0) (6,0) (0,6); dome W: (8,0) (14,0) (8,6) (grid i, j) */
	const uint32_t level[6] = {0, 6 * NJ, 6, 8 * NJ, 14 * NJ, 8 * NJ + 6};
	float fast = api_lod_measure_level(m, level, 6, false), all = api_lod_measure_level(m, level, 6, true);
	float a_only = api_lod_measure_level(m, level, 3, true), w_only = api_lod_measure_level(m, level + 3, 3, true);
	CHECK(a_only > 0.0085f && a_only <= 0.009f && w_only > 0.019f && w_only <= 0.02f, "dome A %g, dome W %g", a_only,
	      w_only);
	CHECK(fast == all, "%.9g measured, %.9g walking every triangle (the worst, dome W, estimated under dome A)", fast,
	      all);
	api_lod_measure_destroy(m);
}

/* The import's threads (api/workers.h) change nothing but the time: a flat-shaded sphere of
 * 259,200 facets joined (the weld's radix sort in slices and buckets, the groups joined), welded,
 * checked closed (the edges in slices) and simplified in pieces gives the same bytes with 1 and 3
 * threads, and its level the same measure (the estimates in slices); and every task runs once. */
static void tally(void *ctx, size_t i, unsigned w)
{
	uint32_t *seen = ctx;
	__atomic_fetch_add(&seen[i], 1u + (w >= api_workers_count() ? 1000u : 0u), __ATOMIC_RELAXED);
}

TEST(model_lod_threads_give_the_same_bytes)
{
	uint32_t *out[2] = {NULL, NULL}, *widx[2] = {NULL, NULL}, joined[2] = {0, 0};
	size_t got[2] = {0, 0}, welded[2] = {0, 0};
	bool closed[2] = {false, false}, flipped[2] = {true, true};
	float measured[2] = {0.0f, 1.0f};
	float *wpos[2] = {NULL, NULL};
	for (int run = 0; run < 2; run++) {
		api_workers_start(run ? 3 : 1);
		CHECK(api_workers_count() == (run ? 3u : 1u), "%u threads", api_workers_count());
		static uint32_t seen[1000];
		memset(seen, 0, sizeof seen);
		api_workers_run(1000, tally, seen);
		int wrong = 0;
		for (int i = 0; i < 1000; i++) wrong += seen[i] != 1;
		CHECK(wrong == 0, "%d of 1000 tasks not run exactly once", wrong);
		float *pos, *nrm;
		uint32_t *idx, nv, ni;
		flat_sphere(360, &pos, &nrm, &idx, &nv, &ni);
		struct api_arena *a = api_arena_create();
		const uint32_t *group;
		uint32_t groups;
		REQUIRE(a);
		joined[run] = api_join_vertices(pos, nrm, NULL, nv, idx, ni, a, &group, &groups);
		struct api_welded w;
		widx[run] = malloc(ni * 4ull);
		out[run] = malloc(ni * 4ull);
		REQUIRE(widx[run] && out[run] && api_weld_mesh(pos, joined[run], idx, ni, group, groups, widx[run], &w));
		REQUIRE(ni / 3 >= 8 * API_LOD_PIECE_TRIANGLES);
		welded[run] = w.count;
		wpos[run] = w.pos;
		w.pos = NULL;
		got[run] = api_lod_simplify(out[run], widx[run], ni, wpos[run], w.count, 2.0f, 0.25f * api_lod_import_error(256));
		/* the closedness check's slices: closed, and not with one face in a late slice flipped */
		closed[run] = api_mesh_closed(widx[run], ni, wpos[run], w.count);
		uint32_t *f = widx[run] + ni - 300, keep = f[0];
		f[0] = f[1], f[1] = keep;
		flipped[run] = api_mesh_closed(widx[run], ni, wpos[run], w.count);
		f[1] = f[0], f[0] = keep;
		/* the level's measure: its estimates in slices */
		float lo[3], hi[3], ext = api_points_box(wpos[run], w.count, lo, hi), *nrm_w = malloc(w.count * 12ull);
		REQUIRE(nrm_w);
		for (size_t v = 0; v < w.count; v++) rnd_v3_normalize(nrm_w + 3 * v, wpos[run] + 3 * v);
		struct api_lod_measure *m = api_lod_measure_create(wpos[run], nrm_w, w.count, widx[run], ni, lo, hi, ext);
		REQUIRE(m);
		measured[run] = api_lod_measure_level(m, out[run], got[run], false);
		api_lod_measure_destroy(m);
		free(nrm_w);
		api_welded_release(&w);
		api_arena_destroy(a);
		free(pos), free(nrm), free(idx);
		api_workers_stop();
	}
	CHECK(joined[0] == joined[1] && welded[0] == welded[1] && welded[0] * 3 < joined[0], "joined %u / %u, welded %zu / %zu",
	      joined[0], joined[1], welded[0], welded[1]);
	CHECK(!memcmp(widx[0], widx[1], 6ull * 360 * 360 * 4) && !memcmp(wpos[0], wpos[1], welded[0] * 12),
	      "the same welded mesh");
	CHECK(got[0] == got[1] && got[0] > 0 && got[0] * 10 < 6ull * 360 * 360 && !memcmp(out[0], out[1], got[0] * 4),
	      "the same level: %zu / %zu indices", got[0], got[1]);
	CHECK(closed[0] && closed[1] && !flipped[0] && !flipped[1], "closed %d %d, one face flipped %d %d", closed[0],
	      closed[1], flipped[0], flipped[1]);
	CHECK(measured[0] > 0.0f && !memcmp(&measured[0], &measured[1], sizeof measured[0]), "the level measured %.9g / %.9g",
	      measured[0], measured[1]);
	for (int run = 0; run < 2; run++) free(out[run]), free(widx[run]), free(wpos[run]);
}
