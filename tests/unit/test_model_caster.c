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
#include "caster_level.h"

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

/* Exact distance from p to triangle (a, b, c), in doubles: the nearest of the plane's foot when
 * it falls inside, and the three edges (an independent form of what the measure computes). */
static double seg_d(const double p[3], const double a[3], const double b[3])
{
	double ab[3], ap[3], l = 0, t = 0, d = 0;
	for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ap[k] = p[k] - a[k], l += ab[k] * ab[k], t += ap[k] * ab[k];
	t = l > 0 ? fmin(fmax(t / l, 0), 1) : 0;
	for (int k = 0; k < 3; k++) d += (ap[k] - t * ab[k]) * (ap[k] - t * ab[k]);
	return sqrt(d);
}

static double tri_d(const double p[3], const double a[3], const double b[3], const double c[3])
{
	double u[3], v[3], w[3], n[3];
	for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = p[k] - a[k];
	n[0] = u[1] * v[2] - u[2] * v[1], n[1] = u[2] * v[0] - u[0] * v[2], n[2] = u[0] * v[1] - u[1] * v[0];
	double uu = 0, uv = 0, vv = 0, wu = 0, wv = 0, nn = 0, wn = 0;
	for (int k = 0; k < 3; k++)
		uu += u[k] * u[k], uv += u[k] * v[k], vv += v[k] * v[k], wu += w[k] * u[k], wv += w[k] * v[k],
		nn += n[k] * n[k], wn += w[k] * n[k];
	double den = uu * vv - uv * uv, s = (vv * wu - uv * wv) / den, t = (uu * wv - uv * wu) / den;
	double best = fmin(seg_d(p, a, b), fmin(seg_d(p, a, c), seg_d(p, b, c)));
	if (den > 0 && s >= 0 && t >= 0 && s + t <= 1) best = fmin(best, fabs(wn) / sqrt(nn));
	return best;
}

/* The measure one way, searched exhaustively: every sample of every triangle of a (its corners,
 * and the m x m lattice of a triangle longer than spacing) against every triangle of b. */
static double brute_way(const uint32_t *ia, size_t na, const float *pa, const uint32_t *ib, size_t nb, const float *pb,
                        double spacing)
{
	double worst = 0;
	for (size_t t = 0; t + 2 < na; t += 3) {
		double a[3], ab[3], ac[3], longest = 0;
		for (int k = 0; k < 3; k++) {
			a[k] = pa[3 * ia[t] + k];
			ab[k] = pa[3 * ia[t + 1] + k] - a[k];
			ac[k] = pa[3 * ia[t + 2] + k] - a[k];
		}
		for (int e = 0; e < 3; e++) {
			double l = 0;
			for (int k = 0; k < 3; k++) {
				double d = e == 0 ? ab[k] : e == 1 ? ac[k] : ac[k] - ab[k];
				l += d * d;
			}
			longest = fmax(longest, sqrt(l));
		}
		int m = (int)fmin(fmax(ceil(longest / spacing), 1), 64), found_m = m;
		double found = 0;
		for (int i = 0; i <= m; i++)
			for (int j = 0; i + j <= m; j++) {
				double q[3], near = INFINITY;
				for (int k = 0; k < 3; k++) q[k] = a[k] + (double)i / m * ab[k] + (double)j / m * ac[k];
				for (size_t s = 0; s + 2 < nb; s += 3) {
					double x[3], y[3], z[3];
					for (int k = 0; k < 3; k++)
						x[k] = pb[3 * ib[s] + k], y[k] = pb[3 * ib[s + 1] + k], z[k] = pb[3 * ib[s + 2] + k];
					near = fmin(near, tri_d(q, x, y, z));
				}
				found = fmax(found, near);
			}
		worst = fmax(worst, found + longest / found_m / sqrt(3.0));
	}
	return worst;
}

/* A bumpy sphere against a coarse smooth one: the measure (which searches exactly only the
 * triangles whose cheap bound could raise it) gives the exhaustive search's figure, both ways. */
TEST(caster_error_matches_the_exhaustive_search)
{
	float *pf, *nf, *pc, *nc;
	uint32_t *fi, *ci, nvf, nif, nvc, nic;
	sphere(24, &pf, &nf, &fi, &nvf, &nif);
	sphere(7, &pc, &nc, &ci, &nvc, &nic);
	REQUIRE(pf && fi && pc && ci);
	/* bumps of up to 3 % of the radius: many triangles near the worst, whose cheap bounds mislead */
	for (uint32_t v = 0; v < nvf; v++) {
		float s = 1.0f + 0.03f * sinf(7.0f * pf[3 * v] + 5.0f * pf[3 * v + 1]) * cosf(6.0f * pf[3 * v + 2]);
		for (int k = 0; k < 3; k++) pf[3 * v + k] *= s;
	}
	const float spacing = 0.1f;
	double want_ab = brute_way(fi, nif, pf, ci, nic, pc, spacing), want_ba = brute_way(ci, nic, pc, fi, nif, pf, spacing);
	float e = api_caster_error(fi, nif, pf, ci, nic, pc, spacing);
	double want = fmax(want_ab, want_ba);
	printf("    measure %.6f, exhaustive %.6f (fine to coarse %.6f, coarse to fine %.6f)\n", (double)e, want, want_ab,
	       want_ba);
	CHECK(fabs(e - want) <= 1e-4 * want, "measure %g against exhaustive %g", (double)e, want);
	/* the direction that decides the figure, alone (swapped roles give the same measure) */
	float e2 = api_caster_error(ci, nic, pc, fi, nif, pf, spacing);
	CHECK(fabs(e2 - want) <= 1e-4 * want, "swapped: %g against %g", (double)e2, want);
	free(pf); free(nf); free(fi); free(pc); free(nc); free(ci);
}

/* The caster level's slope bias (renderer/caster_level.c) is never less than sqrt(2) raise /
 * texel, at most a quarter octave more, and takes few values over every raise and texel a map
 * can have: lavapipe compiles a function per distinct depth bias. */
TEST(caster_slope_bias_on_a_ladder_never_under_the_exact)
{
	float seen[128];
	int distinct = 0, under = 0, over = 0;
	uint32_t h = 12345u;
	for (int i = 0; i < 20000; i++) {
		h = h * 1664525u + 1013904223u;
		float texel = 0.001f + (float)(h >> 8) / 16777216.0f * 0.2f;   /* world units a texel */
		h = h * 1664525u + 1013904223u;
		float raise = texel * 4.0f * (float)(h >> 8) / 16777216.0f;    /* error up to 4 texels */
		float exact = 1.41421356f * raise / texel, got = rnd_caster_slope_bias(raise, texel);
		if (got < exact) under++;
		if (exact >= 1.0f / 256.0f && got > exact * 1.1893f) over++;
		int k = 0;
		while (k < distinct && seen[k] != got) k++;
		if (k == distinct && distinct < 128) seen[distinct++] = got;
	}
	printf("    %d distinct slope biases over 20000 maps\n", distinct);
	CHECK(under == 0, "%d biases under the exact figure", under);
	CHECK(over == 0, "%d biases more than a quarter octave over", over);
	CHECK(distinct <= 45, "%d distinct biases", distinct);
	CHECK(rnd_caster_slope_bias(0.0f, 0.01f) == 0.0f && rnd_caster_slope_bias(0.01f, 0.0f) == 0.0f, "no raise, no bias");
}
