/*
 * api/model_caster.c — the environment's shadow maps' coarse caster level of a dense mesh (see
 * model_caster.h): meshoptimizer's sloppy simplification, and the bound on its distance from
 * the full mesh, both ways, measured on a lattice of samples against a grid of triangles.
 */
#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>
#include "model_caster.h"
#include "workers.h"
#include "umbra/rnd_math.h"

/* The lattice step of the error's samples, as a fraction of the mesh's extent: the bound adds
 * at most step / sqrt(3) (0.6 % of the extent) to the worst sample. A 256-texel map over the
 * casters' box has texels of ~0.5 % of the extent: about a texel over what the samples found.
 * Measured on the 100k corpus blob: extent / 128 sampled each of its triangles 6 times (their
 * sides are ~1/110 of the extent), 790k searches; / 96 samples them at their corners only,
 * ~130k searches in all. */
#define CASTER_SAMPLE_STEPS 96.0f

/* A uniform grid of triangles (each in every cell its box touches), for the nearest one to a
 * point. */
struct tgrid {
	const float *pos;
	const uint32_t *idx;
	float lo[3], cell;
	int n[3];
	uint32_t *start, *items;   /* cell c's triangles: items[start[c] .. start[c + 1]) */
	float *sphere;             /* per triangle (index offset / 3): centroid xyz and the radius
	                              reaching its corners, to pass over most candidates cheaply */
};

static int cell_of(const struct tgrid *g, float x, int k)
{
	int c = (int)floorf((x - g->lo[k]) / g->cell);
	return c < 0 ? 0 : c >= g->n[k] ? g->n[k] - 1 : c;
}

/* The cell range [c0, c1] of triangle t's box. */
static void tri_cells(const struct tgrid *g, size_t t, int c0[3], int c1[3])
{
	for (int k = 0; k < 3; k++) {
		float a = g->pos[3 * (size_t)g->idx[t] + k], b = g->pos[3 * (size_t)g->idx[t + 1] + k];
		float c = g->pos[3 * (size_t)g->idx[t + 2] + k];
		c0[k] = cell_of(g, fminf(a, fminf(b, c)), k);
		c1[k] = cell_of(g, fmaxf(a, fmaxf(b, c)), k);
	}
}

/* Grid over triangles idx[0..ni) of pos, in the box lo..hi (holding every point it is asked
 * about), with ~a few triangles per cell of the surface. */
static bool tgrid_build(struct tgrid *g, const uint32_t *idx, size_t ni, const float *pos, const float lo[3],
                        const float hi[3])
{
	memset(g, 0, sizeof *g);
	g->pos = pos;
	g->idx = idx;
	float side = fmaxf(fmaxf(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
	/* ~8 cells a triangle in all (a surface crosses ~6 n^2 of the n^3: a few triangles each of
	 * those), at most 128 a side: a grid of 160 a side for a 100k mesh spent more on its 4M
	 * empty cells than the searches saved */
	float per_axis = fminf(fmaxf(cbrtf(8.0f * (float)(ni / 3)), 1.0f), 128.0f);
	g->cell = side > 0.0f ? side / per_axis * 1.001f : 1.0f;
	size_t cells = 1;
	for (int k = 0; k < 3; k++) {
		g->lo[k] = lo[k];
		g->n[k] = (int)((hi[k] - lo[k]) / g->cell) + 1;
		cells *= (size_t)g->n[k];
	}
	g->start = calloc(cells + 1, sizeof *g->start);
	g->sphere = malloc((ni / 3 ? ni / 3 : 1) * 4 * sizeof *g->sphere);
	if (!g->start || !g->sphere) return false;
	for (size_t t = 0; t + 2 < ni; t += 3) {
		float *sp = g->sphere + 4 * (t / 3), r2 = 0.0f;
		for (int k = 0; k < 3; k++)
			sp[k] = (pos[3 * (size_t)idx[t] + k] + pos[3 * (size_t)idx[t + 1] + k] + pos[3 * (size_t)idx[t + 2] + k]) / 3.0f;
		for (int c = 0; c < 3; c++) {
			float d[3];
			rnd_v3_sub(d, pos + 3 * (size_t)idx[t + (size_t)c], sp);
			r2 = fmaxf(r2, rnd_v3_dot(d, d));
		}
		sp[3] = sqrtf(r2);
	}
	size_t total = 0;
	for (int pass = 0; pass < 2; pass++) {
		for (size_t t = 0; t + 2 < ni; t += 3) {
			int c0[3], c1[3];
			tri_cells(g, t, c0, c1);
			for (int z = c0[2]; z <= c1[2]; z++)
				for (int y = c0[1]; y <= c1[1]; y++)
					for (int x = c0[0]; x <= c1[0]; x++) {
						size_t c = ((size_t)z * (size_t)g->n[1] + (size_t)y) * (size_t)g->n[0] + (size_t)x;
						if (pass == 0) g->start[c + 1]++;
						else g->items[g->start[c]++] = (uint32_t)t;
					}
		}
		if (pass == 1) break;
		for (size_t c = 0; c < cells; c++) g->start[c + 1] += g->start[c];
		total = g->start[cells];
		g->items = malloc((total ? total : 1) * sizeof *g->items);
		if (!g->items) return false;
	}
	/* the fill moved each start to its cell's end: back one cell */
	memmove(g->start + 1, g->start, cells * sizeof *g->start);
	g->start[0] = 0;
	return true;
}

static void tgrid_free(struct tgrid *g)
{
	free(g->sphere);
	free(g->start);
	free(g->items);
}

/* Squared distance from p to triangle (a, b, c): the closest point by its Voronoi region
 * (Ericson, Real-Time Collision Detection 5.1.5). */
static float seg_dist2(const float p[3], const float a[3], const float b[3])
{
	float ab[3], ap[3], q[3];
	rnd_v3_sub(ab, b, a); rnd_v3_sub(ap, p, a);
	float l = rnd_v3_dot(ab, ab), t = l > 0.0f ? fminf(fmaxf(rnd_v3_dot(ap, ab) / l, 0.0f), 1.0f) : 0.0f;
	for (int k = 0; k < 3; k++) q[k] = ap[k] - t * ab[k];
	return rnd_v3_dot(q, q);
}

static float point_tri_dist2(const float p[3], const float a[3], const float b[3], const float c[3])
{
	float ab[3], ac[3], ap[3], bp[3], cp[3], q[3], d[3], n[3];
	rnd_v3_sub(ab, b, a); rnd_v3_sub(ac, c, a); rnd_v3_sub(ap, p, a);
	rnd_v3_cross(n, ab, ac);
	/* a degenerate triangle (a pole's sliver) is its edges: the regions below divide by 0 */
	float ln = rnd_v3_dot(n, n), l2 = fmaxf(rnd_v3_dot(ab, ab), rnd_v3_dot(ac, ac));
	if (!(ln > 1e-12f * l2 * l2)) return fminf(seg_dist2(p, a, b), fminf(seg_dist2(p, a, c), seg_dist2(p, b, c)));
	float d1 = rnd_v3_dot(ab, ap), d2 = rnd_v3_dot(ac, ap);
	if (d1 <= 0 && d2 <= 0) return rnd_v3_dot(ap, ap);
	rnd_v3_sub(bp, p, b);
	float d3 = rnd_v3_dot(ab, bp), d4 = rnd_v3_dot(ac, bp);
	if (d3 >= 0 && d4 <= d3) return rnd_v3_dot(bp, bp);
	rnd_v3_sub(cp, p, c);
	float d5 = rnd_v3_dot(ab, cp), d6 = rnd_v3_dot(ac, cp);
	if (d6 >= 0 && d5 <= d6) return rnd_v3_dot(cp, cp);
	float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
	if (vc <= 0 && d1 >= 0 && d3 <= 0) {
		float v = d1 / (d1 - d3);
		for (int k = 0; k < 3; k++) q[k] = a[k] + v * ab[k];
	} else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
		float w = d2 / (d2 - d6);
		for (int k = 0; k < 3; k++) q[k] = a[k] + w * ac[k];
	} else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
		float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
		for (int k = 0; k < 3; k++) q[k] = b[k] + w * (c[k] - b[k]);
	} else {
		float den = va + vb + vc, v = vb / den, w = vc / den;
		for (int k = 0; k < 3; k++) q[k] = a[k] + v * ab[k] + w * ac[k];
	}
	rnd_v3_sub(d, p, q);
	return rnd_v3_dot(d, d);
}

/* Squared distance from p to cell (x, y, z). */
static float cell_dist2(const struct tgrid *g, const float p[3], int x, int y, int z)
{
	int c[3] = {x, y, z};
	float d2 = 0.0f;
	for (int k = 0; k < 3; k++) {
		float lo = g->lo[k] + (float)c[k] * g->cell, e = fmaxf(fmaxf(lo - p[k], p[k] - (lo + g->cell)), 0.0f);
		d2 += e * e;
	}
	return d2;
}

static float tri_dist2(const struct tgrid *g, const float p[3], uint32_t t)
{
	const uint32_t *c = g->idx + t;
	return point_tri_dist2(p, g->pos + 3 * (size_t)c[0], g->pos + 3 * (size_t)c[1], g->pos + 3 * (size_t)c[2]);
}

/* Distance from p to the grid's nearest triangle. *hint: a triangle near p (the nearest to a
 * neighbouring sample), whose distance bounds the search; left at the nearest found. Cells in
 * rings around p's, until the block searched holds everything nearer than the nearest found
 * (exact: a nearer triangle has a point in the block, so it is listed in one of its cells). */
static float tgrid_dist(const struct tgrid *g, const float p[3], uint32_t *hint)
{
	float best = tri_dist2(g, p, *hint);
	if (!(best < INFINITY)) best = INFINITY;   /* (not NaN, whatever the hint) */
	int c[3] = {cell_of(g, p[0], 0), cell_of(g, p[1], 1), cell_of(g, p[2], 2)};
	for (int r = 0;; r++) {
		float wall = INFINITY;   /* from p to the nearest cell outside the block (none past the grid's edge) */
		for (int k = 0; k < 3; k++) {
			if (c[k] - r > 0) wall = fminf(wall, p[k] - (g->lo[k] + (float)(c[k] - r) * g->cell));
			if (c[k] + r + 1 < g->n[k]) wall = fminf(wall, g->lo[k] + (float)(c[k] + r + 1) * g->cell - p[k]);
		}
		for (int z = c[2] - r; z <= c[2] + r; z++)
			for (int y = c[1] - r; y <= c[1] + r; y++)
				for (int x = c[0] - r; x <= c[0] + r; x++) {
					if (abs(x - c[0]) != r && abs(y - c[1]) != r && abs(z - c[2]) != r) continue;   /* inner rings: done */
					if (x < 0 || y < 0 || z < 0 || x >= g->n[0] || y >= g->n[1] || z >= g->n[2]) continue;
					if (cell_dist2(g, p, x, y, z) > best) continue;   /* nothing in it can be nearer */
					size_t cell = ((size_t)z * (size_t)g->n[1] + (size_t)y) * (size_t)g->n[0] + (size_t)x;
					for (uint32_t k = g->start[cell]; k < g->start[cell + 1]; k++) {
						const float *sp = g->sphere + 4 * (g->items[k] / 3);
						float e[3], reach = sqrtf(best) + sp[3];
						rnd_v3_sub(e, p, sp);
						if (rnd_v3_dot(e, e) > reach * reach) continue;   /* its sphere is farther */
						float d = tri_dist2(g, p, g->items[k]);
						if (d < best) best = d, *hint = g->items[k];
					}
				}
		if (best <= wall * wall || wall == INFINITY) return sqrtf(best);
	}
}

/* A cheap bound on p's distance to the grid's nearest triangle: the nearer of *hint and the
 * triangles listed in p's own cell (the nearest of all is no farther); *hint left at that one. */
static float tgrid_bound(const struct tgrid *g, const float p[3], uint32_t *hint)
{
	float best = tri_dist2(g, p, *hint);
	if (!(best < INFINITY)) best = INFINITY;
	size_t cell = ((size_t)cell_of(g, p[2], 2) * (size_t)g->n[1] + (size_t)cell_of(g, p[1], 1)) * (size_t)g->n[0] +
	              (size_t)cell_of(g, p[0], 0);
	for (uint32_t k = g->start[cell]; k < g->start[cell + 1]; k++) {
		const float *sp = g->sphere + 4 * (g->items[k] / 3);
		float e[3], reach = sqrtf(best) + sp[3];
		rnd_v3_sub(e, p, sp);
		if (rnd_v3_dot(e, e) > reach * reach) continue;
		float d = tri_dist2(g, p, g->items[k]);
		if (d < best) best = d, *hint = g->items[k];
	}
	return sqrtf(best);
}

static inline float max2(float a, float b)
{
	return a > b ? a : b;   /* (not fmaxf: a call into libm per sample, for its NaN rules) */
}

/* One direction of the measure: triangles ia over pa (nva vertices) against the grid. Per
 * vertex: a cheap bound on its distance (vb), its exact distance once searched (vd, -1 before),
 * the nearest triangle found so far (near: the next search's hint). */
struct way {
	const uint32_t *ia;
	const float *pa;
	const struct tgrid *g;
	float spacing, *vb, *vd;
	uint32_t *near;
};

/* The bound of triangle ia[t..t+3): the largest distance at its samples plus how far a point of
 * it can be from the nearest sample (the distance is 1-Lipschitz). The samples: its corners, and
 * for a triangle longer than spacing the lattice of m x m similar triangles that divides it (the
 * covering radius of a triangle of longest side l is at most l / sqrt(3)), row by row, each
 * search seeded with its neighbour's nearest triangle (the first's with its corner's). exact:
 * the samples' distances searched (tgrid_dist), else their cheap bounds (tgrid_bound): a bound
 * on the exact figure. */
static float tri_bound(struct way *w, size_t t, bool exact)
{
	const float *a = w->pa + 3 * (size_t)w->ia[t], *b = w->pa + 3 * (size_t)w->ia[t + 1], *c = w->pa + 3 * (size_t)w->ia[t + 2];
	float ab[3], ac[3], bc[3], found = 0.0f;
	for (int k = 0; k < 3; k++) {
		uint32_t v = w->ia[t + (size_t)k];
		if (exact && w->vd[v] < 0.0f) w->vd[v] = tgrid_dist(w->g, w->pa + 3 * (size_t)v, &w->near[v]);
		found = max2(found, exact ? w->vd[v] : w->vb[v]);
	}
	rnd_v3_sub(ab, b, a); rnd_v3_sub(ac, c, a); rnd_v3_sub(bc, c, b);
	float longest = sqrtf(fmaxf(rnd_v3_dot(ab, ab), fmaxf(rnd_v3_dot(ac, ac), rnd_v3_dot(bc, bc))));
	float steps = ceilf(longest / w->spacing);
	int m = steps > 1.0f ? steps < 64.0f ? (int)steps : 64 : 1;
	uint32_t row = w->near[w->ia[t]], hint;
	for (int i = 0; i <= m && m > 1; i++) {
		hint = row;
		for (int j = 0; i + j <= m; j++) {
			float u = (float)i / (float)m, s = (float)j / (float)m, q[3];
			for (int k = 0; k < 3; k++) q[k] = a[k] + u * ab[k] + s * ac[k];
			found = max2(found, exact ? tgrid_dist(w->g, q, &hint) : tgrid_bound(w->g, q, &hint));
			if (j == 0) row = hint;
		}
	}
	return found + longest / (float)m / sqrtf(3.0f);
}

/* The cheap passes in BOUND_TASKS fixed slices on the import's threads (api/workers.h), each
 * with its own chain of hints: the vertices' bounds, then the triangles', and each slice's
 * highest. Only the cheap bounds depend on the slicing, never the measure (one_way). */
enum { BOUND_TASKS = 64 };
struct bound_task {
	struct way *w;
	size_t nva, nt;
	float *ub;
	size_t top[BOUND_TASKS];
};

static void bound_vertices(void *ctx, size_t task, unsigned wk)
{
	(void)wk;
	struct bound_task *q = ctx;
	uint32_t hint = 0;
	for (size_t v = task * q->nva / BOUND_TASKS; v < (task + 1) * q->nva / BOUND_TASKS; v++) {
		q->w->vb[v] = tgrid_bound(q->w->g, q->w->pa + 3 * v, &hint);
		q->w->near[v] = hint;
		q->w->vd[v] = -1.0f;
	}
}

static void bound_triangles(void *ctx, size_t task, unsigned wk)
{
	(void)wk;
	struct bound_task *q = ctx;
	size_t t0 = task * q->nt / BOUND_TASKS, top = t0;
	for (size_t t = t0; t < (task + 1) * q->nt / BOUND_TASKS; t++) {
		q->ub[t] = tri_bound(q->w, 3 * t, false);   /* (reads w's arrays only) */
		if (q->ub[t] > q->ub[top]) top = t;
	}
	q->top[task] = top;
}

/* A bound on the distance from the surface of triangles ia (over pa: nva vertices, each named
 * by them) to the grid's: the largest of the triangles' exact bounds (tri_bound). Searched
 * exactly only where a triangle's cheap bound exceeds the largest exact one so far, starting
 * from the triangle of the largest cheap bound: the same figure as searching every triangle
 * (one skipped is no higher than the result), whatever the threads. The 100k corpus blob's
 * searches of every vertex and lattice sample took 150 + 60 ms on one thread; the cheap bounds
 * leave ~20 triangles of 108k to search, and run on every core. */
static float one_way(const uint32_t *ia, size_t na, const float *pa, size_t nva, const struct tgrid *g, float spacing)
{
	size_t nt = na / 3, n = nva ? nva : 1, top = 0;
	struct way w = {ia, pa, g, spacing, malloc(n * sizeof *w.vb), malloc(n * sizeof *w.vd), malloc(n * sizeof *w.near)};
	struct bound_task *q = malloc(sizeof *q);
	float worst = INFINITY, *ub = malloc((nt ? nt : 1) * sizeof *ub);
	if (!w.vb || !w.vd || !w.near || !ub || !q) goto done;
	*q = (struct bound_task){&w, nva, nt, ub, {0}};
	api_workers_run(BOUND_TASKS, bound_vertices, q);
	api_workers_run(BOUND_TASKS, bound_triangles, q);
	for (size_t k = 0; k < BOUND_TASKS && nt; k++)
		if (ub[q->top[k]] > ub[top]) top = q->top[k];
	worst = nt ? tri_bound(&w, 3 * top, true) : 0.0f;
	for (size_t t = 0; t < nt; t++)
		if (!(ub[t] <= worst)) worst = max2(worst, tri_bound(&w, 3 * t, true));
done:
	free(w.vb);
	free(w.vd);
	free(w.near);
	free(ub);
	free(q);
	return worst;
}

/* The box of both point sets. */
static void box2(const float *pa, size_t na, const float *pb, size_t nb, float lo[3], float hi[3])
{
	for (int k = 0; k < 3; k++) lo[k] = INFINITY, hi[k] = -INFINITY;
	for (int s = 0; s < 2; s++) {
		const float *p = s ? pb : pa;
		size_t n = s ? nb : na;
		for (size_t v = 0; v < n; v++)
			for (int k = 0; k < 3; k++) {
				lo[k] = fminf(lo[k], p[3 * v + (size_t)k]);
				hi[k] = fmaxf(hi[k], p[3 * v + (size_t)k]);
			}
	}
}

/* Vertices idx[0..ni) reaches: its largest index + 1. */
static size_t named_vertices(const uint32_t *idx, size_t ni)
{
	size_t top = 0;
	for (size_t i = 0; i < ni; i++) top = idx[i] + 1u > top ? idx[i] + 1u : top;
	return top;
}

float api_caster_error(const uint32_t *ia, size_t na, const float *pa, const uint32_t *ib, size_t nb, const float *pb,
                       float spacing)
{
	size_t nva = named_vertices(ia, na), nvb = named_vertices(ib, nb);
	float lo[3], hi[3];
	box2(pa, nva, pb, nvb, lo, hi);
	if (!(spacing > 0.0f) || na < 3 || nb < 3) return INFINITY;
	struct tgrid ga, gb;
	float e = INFINITY;
	bool ok = tgrid_build(&ga, ia, na, pa, lo, hi) && tgrid_build(&gb, ib, nb, pb, lo, hi);
	if (ok) e = fmaxf(one_way(ia, na, pa, nva, &gb, spacing), one_way(ib, nb, pb, nvb, &ga, spacing));
	tgrid_free(&ga);
	tgrid_free(&gb);
	return e;
}

bool api_mesh_wants_caster(const struct api_model *m, const struct api_model_mesh *me)
{
	if (me->index_count / 3 < API_CASTER_MIN_TRIANGLES) return false;
	/* A camera level this request draws (built just before) already this coarse: the maps draw
	 * it, and building the caster would cost more import than it saves them. */
	if (me->lod_count && me->lods[0].index_count / 3 < API_CASTER_MIN_TRIANGLES) return false;
	return me->material < m->material_count && m->materials[me->material].alpha_mode == RND_ALPHA_OPAQUE;
}

/* The sloppy level (dst[0..got) into pos[0..nv)) with its vertices compacted, each named once
 * in the order its indices meet them: malloc'd *ix and *p, *n vertices. */
static bool compact(const uint32_t *dst, size_t got, const float *pos, size_t nv, uint32_t **ix, float **p, uint32_t *n)
{
	uint32_t *remap = malloc(nv * sizeof *remap);
	*ix = malloc(got * sizeof **ix);
	*p = NULL;
	*n = 0;
	if (remap && *ix) {
		memset(remap, 0xff, nv * sizeof *remap);
		for (size_t i = 0; i < got; i++) {
			if (remap[dst[i]] == UINT32_MAX) remap[dst[i]] = (*n)++;
			(*ix)[i] = remap[dst[i]];
		}
		*p = malloc((size_t)*n * 12);
	}
	if (*p)
		for (size_t v = 0; v < nv; v++)
			if (remap[v] != UINT32_MAX) memcpy(*p + 3 * (size_t)remap[v], pos + 3 * v, 12);
	free(remap);
	return *p != NULL;
}

void api_caster_build(struct api_model_mesh *me, const uint32_t *idx, size_t ni, const float *pos, size_t nv,
                      struct api_arena *arena, size_t *bytes)
{
	me->caster = NULL;
	uint32_t *dst = ni >= 3 ? malloc(ni * sizeof *dst) : NULL, *ix = NULL, n = 0;
	float *p = NULL;
	if (!dst) return;
	/* target_error 1 (the whole extent): the triangle count alone says how coarse */
	size_t got = meshopt_simplifySloppy(dst, idx, ni, pos, nv, 12, 3u * API_CASTER_TRIANGLES, 1.0f, NULL);
	if (got < 3 || got * 4 > ni || !compact(dst, got, pos, nv, &ix, &p, &n)) goto done;
	float lo[3], hi[3];
	box2(pos, nv, NULL, 0, lo, hi);
	float extent = fmaxf(fmaxf(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
	float error = api_caster_error(idx, ni, pos, ix, got, p, extent / CASTER_SAMPLE_STEPS);
	struct rnd_caster_level *lv = api_arena_alloc(arena, sizeof *lv);
	uint32_t *aix = api_arena_alloc(arena, got * sizeof *aix);
	float *ap = api_arena_alloc(arena, (size_t)n * 12);
	if (!(error < INFINITY) || !lv || !aix || !ap) goto done;
	memcpy(aix, ix, got * sizeof *aix);
	memcpy(ap, p, (size_t)n * 12);
	*lv = (struct rnd_caster_level){ap, aix, n, (uint32_t)got, error};
	*bytes += (size_t)n * 12 + got * sizeof *aix + sizeof *lv;
	me->caster = lv;
done:
	free(p);
	free(ix);
	free(dst);
}
