/* tests — api/model_caster.c (the environment's shadow maps' coarse caster level): its error
 * bound holds against answers known without it (two parallel grids a known distance apart; a
 * level of a finely tessellated sphere, whose every point's distance from the sphere is
 * |r - 1|), and no level is built for a masked material or a small mesh. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"
#include "arena.h"
#include "model_caster.h"
#include "model_lod.h"

#define PI_D 3.14159265358979323846

/* A unit UV sphere of seg x seg quads, shared vertices (the poles' rows collapse to a point). */
static void sphere(int seg, float **pos, float **nrm, uint32_t **idx, uint32_t *nv, uint32_t *ni)
{
	*nv = (uint32_t)((seg + 1) * (seg + 1));
	*ni = (uint32_t)(6 * seg * seg);
	*pos = malloc(*nv * 12ull);
	*nrm = malloc(*nv * 12ull);
	*idx = malloc(*ni * 4ull);
	for (int i = 0; i <= seg; i++)
		for (int j = 0; j <= seg; j++) {
			double th = PI_D * i / seg, ph = 2 * PI_D * (j % seg) / seg;
			float *p = *pos + 3 * (size_t)(i * (seg + 1) + j), *n = *nrm + 3 * (size_t)(i * (seg + 1) + j);
			p[0] = n[0] = (float)(sin(th) * cos(ph));
			p[1] = n[1] = (float)cos(th);
			p[2] = n[2] = (float)(sin(th) * sin(ph));
		}
	uint32_t k = 0;
	for (int i = 0; i < seg; i++)
		for (int j = 0; j < seg; j++) {
			uint32_t a = (uint32_t)(i * (seg + 1) + j), b = a + 1, c = a + (uint32_t)seg + 1, d = c + 1;
			uint32_t t[6] = {a, b, c, b, d, c};   /* outward */
			memcpy(*idx + k, t, sizeof t);
			k += 6;
		}
}

/* Model m of one mesh me, the 80k-triangle sphere, its material mat (opaque). */
static bool sphere_model(struct api_model *m, struct api_model_mesh *me, struct rnd_material *mat)
{
	float *pos, *nrm;
	uint32_t *idx, nv, ni;
	sphere(200, &pos, &nrm, &idx, &nv, &ni);
	rnd_material_defaults(mat);
	*me = (struct api_model_mesh){.positions = pos, .normals = nrm, .indices = idx, .vertex_count = nv, .index_count = ni};
	*m = (struct api_model){.meshes = me, .mesh_count = 1, .materials = mat, .material_count = 1};
	return pos && nrm && idx;
}

static void sphere_free(struct api_model_mesh *me)
{
	free((void *)me->positions);
	free((void *)me->normals);
	free((void *)me->indices);
}

/* A flat n x n grid of squares over [0,1]^2 at height y (x, z in the plane). */
static void grid(int n, float y, float *pos, uint32_t *idx)
{
	for (int i = 0; i <= n; i++)
		for (int j = 0; j <= n; j++) {
			float *p = pos + 3 * (size_t)(i * (n + 1) + j);
			p[0] = (float)j / (float)n, p[1] = y, p[2] = (float)i / (float)n;
		}
	for (int i = 0, k = 0; i < n; i++)
		for (int j = 0; j < n; j++, k += 6) {
			uint32_t a = (uint32_t)(i * (n + 1) + j), b = a + 1, c = a + (uint32_t)n + 1, d = c + 1;
			uint32_t t[6] = {a, c, b, b, c, d};
			memcpy(idx + k, t, sizeof t);
		}
}

/* Two parallel grids h apart (one fine, one coarse): every point of each is exactly h from the
 * other, so the bound is h plus at most the lattice's covering radius (step / sqrt(3)). */
TEST(caster_error_of_parallel_grids_is_their_distance)
{
	enum { FINE = 40, COARSE = 3 };
	float pf[(FINE + 1) * (FINE + 1) * 3], pc[(COARSE + 1) * (COARSE + 1) * 3];
	uint32_t fi[FINE * FINE * 6], ci[COARSE * COARSE * 6];
	grid(FINE, 0.0f, pf, fi);
	const float h = 0.01f, step = 0.05f;
	grid(COARSE, h, pc, ci);
	float e = api_caster_error(fi, FINE * FINE * 6, pf, ci, COARSE * COARSE * 6, pc, step);
	printf("    grids %g apart: bound %g\n", (double)h, (double)e);
	CHECK(e >= h && e <= h + step / sqrtf(3.0f) + 1e-5f, "bound %g for distance %g", (double)e, (double)h);
	/* and the same grids swapped */
	float e2 = api_caster_error(ci, COARSE * COARSE * 6, pc, fi, FINE * FINE * 6, pf, step);
	CHECK(e2 >= h && e2 <= h + step / sqrtf(3.0f) + 1e-5f, "swapped: bound %g", (double)e2);
}

/* A sphere of 80k triangles gets a level of about API_CASTER_TRIANGLES whose claimed error is
 * no less than the distance from the sphere (|r - 1|, less the full mesh's own largest chord
 * error) of any point of 21 x 21 samples on each of its triangles; and its bound is not loose
 * beyond the lattice's term (within a hundredth of the radius). */
TEST(caster_level_error_bound_holds_on_a_sphere)
{
	struct rnd_material mat;
	struct api_model_mesh me;
	struct api_model m;
	REQUIRE(sphere_model(&m, &me, &mat));
	struct api_arena *a = api_arena_create();
	size_t bytes = 0;
	api_model_finish_import(&m, 0, a, &bytes);
	REQUIRE(me.caster != NULL, "a level for an opaque 80k-triangle sphere");
	const struct rnd_caster_level *c = me.caster;
	CHECK(c->index_count / 3 <= API_CASTER_TRIANGLES * 11 / 10 && c->index_count / 3 >= API_CASTER_TRIANGLES / 2,
	      "%u triangles", c->index_count / 3);
	CHECK(bytes >= (size_t)c->vertex_count * 12 + (size_t)c->index_count * 4, "its bytes are charged");
	double full_chord = 1.0 - cos(PI_D / 200), worst = 0.0;
	for (uint32_t t = 0; t + 2 < c->index_count; t += 3)
		for (int i = 0; i <= 20; i++)
			for (int j = 0; i + j <= 20; j++) {
				double u = i / 20.0, w = j / 20.0, q[3], r = 0;
				for (int k = 0; k < 3; k++) {
					double pa = c->positions[3 * c->indices[t] + k], pb = c->positions[3 * c->indices[t + 1] + k];
					double pc = c->positions[3 * c->indices[t + 2] + k];
					q[k] = pa + u * (pb - pa) + w * (pc - pa);
					r += q[k] * q[k];
				}
				worst = fmax(worst, fabs(sqrt(r) - 1.0) - full_chord);
			}
	printf("    %u triangles, claimed error %.5f, samples within %.5f of the sphere\n", c->index_count / 3,
	       (double)c->error, worst);
	CHECK(c->error >= worst, "claimed %g, found %g", (double)c->error, worst);
	CHECK(c->error <= worst + 2.0 / 96.0 / sqrt(3.0) + 0.01, "claimed %g is loose (found %g)", (double)c->error, worst);
	api_arena_destroy(a);
	sphere_free(&me);
}

/* No level where the depth pass needs more than positions (a masked or blended material) or
 * the mesh is too small to gain from one. */
TEST(caster_level_none_for_masked_or_small_meshes)
{
	struct rnd_material mat;
	struct api_model_mesh me;
	struct api_model m;
	REQUIRE(sphere_model(&m, &me, &mat));
	CHECK(api_mesh_wants_caster(&m, &me), "opaque and dense: wanted");
	static const enum rnd_alpha_mode modes[2] = {RND_ALPHA_MASK, RND_ALPHA_BLEND};
	for (int k = 0; k < 2; k++) {
		mat.alpha_mode = modes[k];
		struct api_arena *a = api_arena_create();
		size_t bytes = 0;
		api_model_finish_import(&m, 0, a, &bytes);
		CHECK(me.caster == NULL && !api_mesh_wants_caster(&m, &me), "alpha mode %d: no level", (int)modes[k]);
		api_arena_destroy(a);
	}
	mat.alpha_mode = RND_ALPHA_OPAQUE;
	me.index_count = 3 * (API_CASTER_MIN_TRIANGLES - 1);
	struct api_arena *a = api_arena_create();
	size_t bytes = 0;
	api_model_finish_import(&m, 0, a, &bytes);
	CHECK(me.caster == NULL && !api_mesh_wants_caster(&m, &me), "%u triangles: no level", me.index_count / 3);
	api_arena_destroy(a);
	sphere_free(&me);
}
