/*
 * api/model_lod.c — meshoptimizer levels of detail of imported meshes (see model_lod.h).
 *
 * A mesh gets one level for each size of image it is drawn at (api_lod_import_error), each
 * simplified from the full mesh in one step: a pure function of the mesh and that size, so a
 * request draws the same triangles whether its model was just imported or long cached (the
 * same request, the same bytes). A level's
 * error is measured here against the full mesh (level_error), in object units: meshoptimizer's
 * own figure leaves out how far the new triangles' insides are from the surface. The measure
 * is the distance from the nearest full-mesh vertex's tangent plane, and where that comes within
 * half the level's worst, the exact distance from the full mesh's faces around the triangle,
 * met walking its surface (another part close by or a crease misled the first). Every level
 * gets its own vertex arrays, so drawing it touches only its vertices. Simplification runs on the mesh welded by
 * position (weld), so a level's normals are computed from its own triangles with a crease angle
 * (write_level) and its uvs (both sets) those of each position's first vertex: a texture seam of a
 * coarse level can show the wrong side's uvs (a thumbnail rarely can tell).
 */
#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>
#include "model_caster.h"
#include "lod_simplify.h"
#include "model_lod.h"
#include "weld.h"
#include "umbra/rnd_math.h"

/* A mesh welded by position: what the simplifier works on. meshoptimizer treats vertices at
 * the same position as attribute seams it must keep, so a flat-shaded file (an STL shares no
 * vertex between facets) would not simplify at all without this. */
struct welded {
	float *pos;           /* count unique positions */
	float *nrm;           /* their area-weighted normals over the full mesh's faces */
	uint32_t *rep;        /* the first original vertex of each (for uvs, and which side is out) */
	size_t count;
};

/* The box of n points (lo, hi; empty: +inf, -inf) and its largest side. (Comparisons, not
 * fminf/fmaxf: those are calls into libm, for their NaN rules, and positions are finite; the
 * daemon runs this over every mesh of a reply, api_mesh_bounds.) */
static float points_box(const float *p, size_t n, float lo[3], float hi[3])
{
	for (int k = 0; k < 3; k++) lo[k] = INFINITY, hi[k] = -INFINITY;
	for (size_t v = 0; v < n; v++)
		for (int k = 0; k < 3; k++) {
			float x = p[3 * v + (size_t)k];
			if (x < lo[k]) lo[k] = x;
			if (x > hi[k]) hi[k] = x;
		}
	return fmaxf(fmaxf(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
}

/* me welded by position into idx and w (api_weld_mesh: the importer's groups when its join made
 * them, me->weld_group_, else sorted now), with the welded vertices' normals. */
static bool weld(const struct api_model_mesh *me, uint32_t *idx, struct welded *w)
{
	struct api_welded wm;
	bool ok = api_weld_mesh(me->positions, me->vertex_count, me->indices, me->index_count, me->weld_group_,
	                        me->weld_groups_, idx, &wm);
	w->pos = wm.pos;
	w->rep = wm.rep;
	w->count = wm.count;
	if (!ok) return false;
	/* Vertex normals of the welded full mesh (degenerate facets, whose file normals are noise,
	 * weigh nothing); oriented like the file's. */
	w->nrm = calloc(w->count * 3, sizeof *w->nrm);
	if (!w->nrm) return false;
	for (uint32_t t = 0; t + 2 < me->index_count; t += 3) {
		float e1[3], e2[3], c[3];
		rnd_v3_sub(e1, w->pos + 3 * (size_t)idx[t + 1], w->pos + 3 * (size_t)idx[t]);
		rnd_v3_sub(e2, w->pos + 3 * (size_t)idx[t + 2], w->pos + 3 * (size_t)idx[t]);
		rnd_v3_cross(c, e1, e2);
		if (rnd_v3_dot(c, me->normals + 3 * (size_t)me->indices[t]) < 0.0f) rnd_v3_scale(c, c, -1.0f);
		for (int k = 0; k < 3; k++) rnd_v3_add(w->nrm + 3 * (size_t)idx[t + k], w->nrm + 3 * (size_t)idx[t + k], c);
	}
	for (size_t v = 0; v < w->count; v++)
		if (!rnd_v3_normalize(w->nrm + 3 * v, w->nrm + 3 * v)) memcpy(w->nrm + 3 * v, me->normals + 3 * (size_t)w->rep[v], 12);
	return true;
}

/* A uniform grid over the welded vertices: the nearest one to a point, for measuring how far a
 * level's surface is from the full mesh. */
struct grid {
	float lo[3], cell;
	uint32_t dim[3];
	uint32_t *start, *items;  /* counting-sorted vertex ids per cell */
	float *ipos;              /* their positions, in that order (a row of cells is one run) */
};

static uint32_t cell_of(const struct grid *g, const float p[3], int k)
{
	float c = (p[k] - g->lo[k]) / g->cell;
	if (c < 0) c = 0;
	uint32_t i = (uint32_t)c;
	return i >= g->dim[k] ? g->dim[k] - 1 : i;
}

/* The grid over w's points, whose box is lo..hi of largest side ext (points_box). */
static bool grid_build(struct grid *g, const struct welded *w, const float lo[3], const float hi[3], float ext)
{
	memcpy(g->lo, lo, sizeof g->lo);
	/* about two vertices per cell of a surface: cells of extent / sqrt(count / 2); but at most
	 * 8 cells a vertex in all (a surface fills few of a volume's cells: for a 1M-triangle mesh
	 * the rule alone made 125M cells, half a gigabyte to clear, 12 % of its import) */
	g->cell = fmaxf(ext / sqrtf((float)w->count * 0.5f), 1e-12f);
	double volume = 1.0, cap = 8.0 * (double)w->count + 64.0;
	for (int k = 0; k < 3; k++) volume *= (double)(hi[k] - g->lo[k]) / g->cell + 1.0;
	if (volume > cap) g->cell *= (float)cbrt(volume / cap);
	size_t cells = 1;
	for (int k = 0; k < 3; k++) {
		g->dim[k] = (uint32_t)fminf((hi[k] - g->lo[k]) / g->cell + 1.0f, 1024.0f);
		cells *= g->dim[k];
	}
	g->start = calloc(cells + 1, sizeof *g->start);
	g->items = malloc(w->count * sizeof *g->items);
	if (!g->start || !g->items) return false;
	size_t *id = malloc(w->count * sizeof *id);
	if (!id) return false;
	for (size_t v = 0; v < w->count; v++) {
		const float *p = w->pos + 3 * v;
		id[v] = ((size_t)cell_of(g, p, 2) * g->dim[1] + cell_of(g, p, 1)) * g->dim[0] + cell_of(g, p, 0);
		g->start[id[v] + 1]++;
	}
	for (size_t c = 0; c < cells; c++) g->start[c + 1] += g->start[c];
	for (size_t v = 0; v < w->count; v++) g->items[g->start[id[v]]++] = (uint32_t)v;
	for (size_t c = cells; c > 0; c--) g->start[c] = g->start[c - 1];
	g->start[0] = 0;
	free(id);
	g->ipos = malloc(w->count * 3 * sizeof *g->ipos);
	if (!g->ipos) return false;
	for (size_t i = 0; i < w->count; i++) memcpy(g->ipos + 3 * i, w->pos + 3 * (size_t)g->items[i], 3 * sizeof *g->ipos);
	return true;
}

/* Distance of p from the full mesh, estimated as its distance from the tangent plane (the
 * full mesh's vertex normal) of the nearest full-mesh vertex in the cells around it (searched up to 4
 * cells out; none that near counts as 4 cells, which marks the level as coarse). */
static float surface_distance(const struct grid *g, const struct welded *w, const float p[3])
{
	uint32_t c[3] = {cell_of(g, p, 0), cell_of(g, p, 1), cell_of(g, p, 2)};
	float best = INFINITY;
	uint32_t bv = 0;
	for (uint32_t r = 1; r <= 4 && best == INFINITY; r++) {
		uint32_t lo[3], hi[3];
		for (int k = 0; k < 3; k++) {
			lo[k] = c[k] > r ? c[k] - r : 0;
			hi[k] = c[k] + r < g->dim[k] ? c[k] + r : g->dim[k] - 1;
		}
		for (uint32_t z = lo[2]; z <= hi[2]; z++)
			for (uint32_t y = lo[1]; y <= hi[1]; y++) {
				/* cells lo[0]..hi[0] of this row: one run of items */
				size_t row = ((size_t)z * g->dim[1] + y) * g->dim[0];
				for (uint32_t i = g->start[row + lo[0]], e = g->start[row + hi[0] + 1]; i < e; i++) {
					const float *q = g->ipos + 3 * (size_t)i;
					float d0 = p[0] - q[0], d1 = p[1] - q[1], d2 = p[2] - q[2];
					float dd = d0 * d0 + d1 * d1 + d2 * d2;
					if (dd < best) { best = dd; bv = g->items[i]; }
				}
			}
	}
	if (best == INFINITY) return 4.0f * g->cell; /* far from every vertex: at least this coarse */
	float d[3];
	rnd_v3_sub(d, p, w->pos + 3 * (size_t)bv);
	return fabsf(rnd_v3_dot(d, w->nrm + 3 * (size_t)bv));
}

/* The full mesh's faces around each vertex (welded ids, compressed rows), for walking its
 * surface out from a level triangle's corners: the full mesh under a level triangle is what its
 * corners' collapses replaced, connected to them. */
struct walk {
	uint32_t *idx;              /* the full mesh's welded indices (a copy: the caller's buffers are
	                               reused for the levels) */
	uint32_t *start, *faces;    /* vertex v's faces: faces[start[v] .. start[v + 1]) */
	uint32_t *vseen, *fseen;    /* the walk that last visited a vertex / face (stamps, 0 = none) */
	uint32_t *queue;
	uint32_t stamp;
};

static bool walk_build(struct walk *k, const struct welded *w, const uint32_t *idx, size_t ni)
{
	size_t nt = ni / 3;
	k->idx = malloc((ni ? ni : 1) * sizeof *k->idx);
	if (!k->idx) return false;
	memcpy(k->idx, idx, ni * sizeof *idx);
	k->start = calloc(w->count + 1, sizeof *k->start);
	k->faces = malloc((ni ? ni : 1) * sizeof *k->faces);
	k->vseen = calloc(w->count, sizeof *k->vseen);
	k->fseen = calloc(nt ? nt : 1, sizeof *k->fseen);
	k->queue = malloc(w->count * sizeof *k->queue);
	if (!k->start || !k->faces || !k->vseen || !k->fseen || !k->queue) return false;
	for (size_t i = 0; i < ni; i++) k->start[idx[i] + 1]++;
	for (size_t v = 0; v < w->count; v++) k->start[v + 1] += k->start[v];
	for (size_t i = 0; i < ni; i++) k->faces[k->start[idx[i]]++] = (uint32_t)(i / 3);
	for (size_t v = w->count; v > 0; v--) k->start[v] = k->start[v - 1];
	k->start[0] = 0;
	k->stamp = 0;
	return true;
}

static void walk_free(struct walk *k)
{
	free(k->idx);
	free(k->start);
	free(k->faces);
	free(k->vseen);
	free(k->fseen);
	free(k->queue);
}

/* fminf(acc, x) and fmaxf(acc, x) for an accumulator that is never NaN, inline (those are
 * calls into libm): a NaN x (a degenerate face's distance) leaves acc as it is, as they do. */
static inline float min_f(float acc, float x)
{
	return x < acc ? x : acc;
}

static inline float max_f(float acc, float x)
{
	return x > acc ? x : acc;
}

/* Squared distance from p to o + t e. */
static float d2_along(const float p[3], const float o[3], const float e[3], float t)
{
	float d[3];
	for (int i = 0; i < 3; i++) d[i] = p[i] - (o[i] + t * e[i]);
	return rnd_v3_dot(d, d);
}

/* Squared distance from p to triangle abc (the closest point by its region: vertex, edge or
 * face; Ericson, Real-Time Collision Detection 5.1.5). */
static float point_triangle_d2(const float p[3], const float a[3], const float b[3], const float c[3])
{
	float ab[3], ac[3], bc[3], ap[3], bp[3], cp[3];
	rnd_v3_sub(ab, b, a);
	rnd_v3_sub(ac, c, a);
	rnd_v3_sub(ap, p, a);
	float d1 = rnd_v3_dot(ab, ap), d2 = rnd_v3_dot(ac, ap);
	if (d1 <= 0.0f && d2 <= 0.0f) return rnd_v3_dot(ap, ap);
	rnd_v3_sub(bp, p, b);
	float d3 = rnd_v3_dot(ab, bp), d4 = rnd_v3_dot(ac, bp);
	if (d3 >= 0.0f && d4 <= d3) return rnd_v3_dot(bp, bp);
	float vc = d1 * d4 - d3 * d2;
	if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return d2_along(p, a, ab, d1 / (d1 - d3));
	rnd_v3_sub(cp, p, c);
	float d5 = rnd_v3_dot(ab, cp), d6 = rnd_v3_dot(ac, cp);
	if (d6 >= 0.0f && d5 <= d6) return rnd_v3_dot(cp, cp);
	float vb = d5 * d2 - d1 * d6;
	if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return d2_along(p, a, ac, d2 / (d2 - d6));
	float va = d3 * d6 - d5 * d4;
	rnd_v3_sub(bc, c, b);
	if (va <= 0.0f && d4 - d3 >= 0.0f && d5 - d6 >= 0.0f) return d2_along(p, b, bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
	float den = 1.0f / (va + vb + vc), v = vb * den, wv = vc * den, q[3];
	for (int i = 0; i < 3; i++) q[i] = a[i] + ab[i] * v + ac[i] * wv;
	rnd_v3_sub(ap, p, q);
	return rnd_v3_dot(ap, ap);
}

/* How far a level (idx: ni indices into w) is from the full mesh: the largest distance of its
 * triangles' centroids and edge midpoints (its vertices are the full mesh's own) from the full
 * mesh's faces met walking out from the triangle's corners without leaving the ball around it
 * (its circumscribing sphere, widened by half): exact, where the faces nearest a point are among
 * those (else more, never less). That walk covers thousands of faces for a coarse level's
 * triangle, so it runs only for triangles where the cheap estimate (surface_distance) comes
 * within half the level's worst so far, and stops as soon as no sample of the triangle can
 * raise it; where the cheap estimate is far below the truth, a triangle is missed (two of the
 * ogre OBJ's levels come out 16 and 19 % under the figure of the walk run everywhere). The
 * cheap estimate alone had been the measure: a nearest vertex found in space can belong to
 * another part close by (an eyeball in its socket) or sit on a crease of the triangle's own
 * face, and every level of the 124k-triangle ogre OBJ measured 0.29 of its 12-unit height that
 * way, so none was ever drawn. meshoptimizer's own error measures the kept vertices against
 * the removed faces' planes and says nothing of the new triangles' insides: on a sphere it
 * claims 6x less than this. */
static float level_error(const struct grid *g, struct walk *k, const struct welded *w, const uint32_t *idx, size_t ni)
{
	float worst2 = 0.0f;
	for (size_t t = 0; t + 2 < ni; t += 3) {
		const float *v[3] = {w->pos + 3 * (size_t)idx[t], w->pos + 3 * (size_t)idx[t + 1], w->pos + 3 * (size_t)idx[t + 2]};
		float s[4][3], r2 = 0.0f;
		for (int a = 0; a < 3; a++) {
			s[0][a] = (v[0][a] + v[1][a] + v[2][a]) / 3.0f;
			s[1][a] = 0.5f * (v[0][a] + v[1][a]);
			s[2][a] = 0.5f * (v[1][a] + v[2][a]);
			s[3][a] = 0.5f * (v[2][a] + v[0][a]);
		}
		/* The walk is dear (a coarse level's triangle covers thousands of faces): only where the
		 * cheap estimate (surface_distance), which can understate (another part close by, a
		 * crease), comes within half the level's worst. From the worst itself levels came out
		 * up to ~25 % low (the beast OBJ's third: 0.61 against 0.79); from half of it they match
		 * the walk run everywhere but for two of the ogre's, for 10-25 % more import time (the
		 * walk everywhere: +50-90 %). */
		bool any = false;
		for (int q = 0; q < 4; q++) {
			float e = surface_distance(g, w, s[q]);
			any |= 4.0f * e * e > worst2;
		}
		if (!any) continue;
		for (int c = 0; c < 3; c++) {
			float d[3];
			rnd_v3_sub(d, v[c], s[0]);
			r2 = max_f(r2, rnd_v3_dot(d, d));
		}
		r2 *= 2.25f;
		float best[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
		if (++k->stamp == 0) {
			memset(k->vseen, 0, w->count * sizeof *k->vseen);
			memset(k->fseen, 0, (k->start[w->count] / 3) * sizeof *k->fseen);
			k->stamp = 1;
		}
		uint32_t head = 0, tail = 0;
		for (int c = 0; c < 3; c++)
			if (k->vseen[idx[t + (size_t)c]] != k->stamp) {
				k->vseen[idx[t + (size_t)c]] = k->stamp;
				k->queue[tail++] = idx[t + (size_t)c];
			}
		while (head < tail) {
			uint32_t u = k->queue[head++];
			for (uint32_t i = k->start[u]; i < k->start[u + 1]; i++) {
				uint32_t f = k->faces[i];
				if (k->fseen[f] == k->stamp) continue;
				k->fseen[f] = k->stamp;
				const uint32_t *fi = k->idx + 3 * (size_t)f;
				const float *a = w->pos + 3 * (size_t)fi[0], *b = w->pos + 3 * (size_t)fi[1], *c = w->pos + 3 * (size_t)fi[2];
				float most = 0.0f;
				for (int q = 0; q < 4; q++) most = max_f(most, best[q] = min_f(best[q], point_triangle_d2(s[q], a, b, c)));
				/* Every sample already this near a face: the rest of the walk can only find
				 * nearer ones, and this triangle cannot raise the level's worst. */
				if (most <= worst2) { head = tail; break; }
				for (int j = 0; j < 3; j++) {
					uint32_t x = fi[j];
					if (k->vseen[x] == k->stamp) continue;
					k->vseen[x] = k->stamp;
					float d[3];
					rnd_v3_sub(d, w->pos + 3 * (size_t)x, s[0]);
					if (rnd_v3_dot(d, d) <= r2) k->queue[tail++] = x;
				}
			}
		}
		for (int q = 0; q < 4; q++) worst2 = max_f(worst2, best[q]);
	}
	return sqrtf(worst2);
}

/* Crease-angle normals of a level (idx: ni indices into w), one per corner: the area-weighted
 * mean of all face normals around the corner's vertex when that is within 30 degrees of its own
 * face's (or its face is a sliver, whose own normal is noise), else the mean of those within 30
 * degrees of its face's (smooth across the fine facets of a curved surface, a crease at a real
 * edge). Face normals follow the file's normals where the winding disagrees. */
static bool corner_normals(const struct api_model_mesh *me, const struct welded *w, const uint32_t *idx, size_t ni,
                           float *nrm)
{
	size_t nt = ni / 3;
	uint32_t *start = calloc(w->count + 1, sizeof *start), *faces = malloc(ni * sizeof *faces);
	float *fn = malloc(nt * 12);
	bool ok = start && faces && fn;
	for (size_t t = 0; ok && t < nt; t++) {
		const float *a = w->pos + 3 * idx[3 * t], *b = w->pos + 3 * idx[3 * t + 1], *c = w->pos + 3 * idx[3 * t + 2];
		float e1[3], e2[3];
		rnd_v3_sub(e1, b, a);
		rnd_v3_sub(e2, c, a);
		rnd_v3_cross(fn + 3 * t, e1, e2);
		/* Winding can disagree with the file's normals: the file's normals say outside. */
		float ref[3] = {0, 0, 0};
		for (int k = 0; k < 3; k++) rnd_v3_add(ref, ref, me->normals + 3 * (size_t)w->rep[idx[3 * t + k]]);
		if (rnd_v3_dot(ref, fn + 3 * t) < 0.0f) rnd_v3_scale(fn + 3 * t, fn + 3 * t, -1.0f);
		for (int k = 0; k < 3; k++) start[idx[3 * t + k] + 1]++;
	}
	if (ok) {
		/* faces around each vertex, grouped (counting sort) */
		for (size_t v = 0; v < w->count; v++) start[v + 1] += start[v];
		for (size_t t = 0; t < nt; t++)
			for (int k = 0; k < 3; k++) faces[start[idx[3 * t + k]]++] = (uint32_t)t;
		for (size_t v = w->count; v > 0; v--) start[v] = start[v - 1];
		start[0] = 0;
	}
	const float crease = 0.866f; /* cos 30 degrees */
	for (size_t t = 0; ok && t < nt; t++) {
		float own[3], u[3], edge = 0.0f;
		if (!rnd_v3_normalize(own, fn + 3 * t)) { own[0] = 0; own[1] = 1; own[2] = 0; }
		for (int k = 0; k < 3; k++) {
			float e[3];
			rnd_v3_sub(e, w->pos + 3 * (size_t)idx[3 * t + (size_t)k], w->pos + 3 * (size_t)idx[3 * t + (size_t)(k + 1) % 3]);
			edge = max_f(edge, rnd_v3_dot(e, e));
		}
		/* A sliver's own normal is noise: it takes its vertices' normals whatever the angle. */
		bool sliver = rnd_v3_length(fn + 3 * t) < 0.02f * edge;
		for (int k = 0; k < 3; k++) {
			uint32_t v = idx[3 * t + (size_t)k];
			float all[3] = {0, 0, 0}, near[3] = {0, 0, 0}, *n = nrm + 3 * (3 * t + (size_t)k);
			for (uint32_t f = start[v]; f < start[v + 1]; f++) {
				rnd_v3_add(all, all, fn + 3 * faces[f]); /* area-weighted: slivers hardly count */
				if (rnd_v3_normalize(u, fn + 3 * faces[f]) && rnd_v3_dot(u, own) >= crease)
					rnd_v3_add(near, near, fn + 3 * faces[f]);
			}
			bool smooth = rnd_v3_normalize(all, all) && (sliver || rnd_v3_dot(all, own) >= crease);
			if (smooth) memcpy(n, all, sizeof all);
			else if (!rnd_v3_normalize(n, near)) memcpy(n, own, sizeof own);
		}
	}
	free(start);
	free(faces);
	free(fn);
	return ok;
}

/* Writes one level into the arena: corners with equal position, normal and uvs (both sets:
 * those of the position's first vertex) become one vertex again. */
static bool write_level(struct api_arena *arena, const struct api_model_mesh *me, const struct welded *w,
                        const uint32_t *idx, size_t ni, struct rnd_mesh_lod *out, size_t *bytes)
{
	const float *src[2] = {me->uvs, me->uvs1};
	float *cp = malloc(ni * 12), *cn = malloc(ni * 12), *cu[2] = {NULL, NULL}, *uv[2] = {NULL, NULL};
	unsigned int *remap = malloc(ni * sizeof *remap);
	bool ok = cp && cn && remap;
	struct meshopt_Stream st[4] = {{cp, 12, 12}, {cn, 12, 12}};
	size_t ns = 2;
	for (int k = 0; k < 2; k++)
		if (src[k] && (ok = ok && (cu[k] = malloc(ni * 8)))) st[ns++] = (struct meshopt_Stream){cu[k], 8, 8};
	if (!ok || !corner_normals(me, w, idx, ni, cn)) goto done;
	for (size_t i = 0; i < ni; i++) {
		memcpy(cp + 3 * i, w->pos + 3 * (size_t)idx[i], 12);
		for (int k = 0; k < 2; k++)
			if (cu[k]) memcpy(cu[k] + 2 * i, src[k] + 2 * (size_t)w->rep[idx[i]], 8);
	}
	size_t nv = meshopt_generateVertexRemapMulti(remap, NULL, ni, ni, st, ns);
	float *pos = api_arena_alloc(arena, nv * 12), *nrm = api_arena_alloc(arena, nv * 12);
	uint32_t *ix = api_arena_alloc(arena, ni * 4);
	ok = pos && nrm && ix;
	for (int k = 0; k < 2; k++)
		if (cu[k]) ok = ok && (uv[k] = api_arena_alloc(arena, nv * 8));
	if (!ok) goto done;
	meshopt_remapVertexBuffer(pos, cp, ni, 12, remap);
	meshopt_remapVertexBuffer(nrm, cn, ni, 12, remap);
	for (int k = 0; k < 2; k++)
		if (cu[k]) meshopt_remapVertexBuffer(uv[k], cu[k], ni, 8, remap);
	meshopt_remapIndexBuffer(ix, NULL, ni, remap);
	*out = (struct rnd_mesh_lod){pos, nrm, uv[0], ix, (uint32_t)nv, (uint32_t)ni, 0.0f, uv[1]};
	*bytes += nv * (24 + (cu[0] ? 8 : 0) + (cu[1] ? 8 : 0)) + ni * 4;
done:
	free(cp);
	free(cn);
	free(cu[0]);
	free(cu[1]);
	free(remap);
	return ok;
}

/* Removes the triangles of no area (a pole's fan collapsed onto itself): invisible, and with no
 * normal of their own. Returns the indices kept. */
static size_t drop_degenerate(const struct welded *w, uint32_t *idx, size_t ni)
{
	size_t out = 0;
	for (size_t t = 0; t + 2 < ni; t += 3) {
		float e1[3], e2[3], c[3];
		rnd_v3_sub(e1, w->pos + 3 * (size_t)idx[t + 1], w->pos + 3 * (size_t)idx[t]);
		rnd_v3_sub(e2, w->pos + 3 * (size_t)idx[t + 2], w->pos + 3 * (size_t)idx[t]);
		rnd_v3_cross(c, e1, e2);
		if (rnd_v3_dot(c, c) == 0.0f) continue;
		memmove(idx + out, idx + t, 3 * sizeof *idx);
		out += 3;
	}
	return out;
}

void api_mesh_bounds(struct api_model_mesh *me)
{
	float lo[3], hi[3];
	points_box(me->positions, me->vertex_count, lo, hi);
	for (int k = 0; k < 3; k++) {
		me->bounds[k] = me->vertex_count ? lo[k] : 0.0f;
		me->bounds[3 + k] = me->vertex_count ? hi[k] : 0.0f;
	}
}

/* Welds me by position into idx and w (the caller frees w's arrays); false when out of memory. */
static bool welded_mesh(const struct api_model_mesh *me, uint32_t *idx, struct welded *w)
{
	return me->normals && me->indices && me->index_count && idx && weld(me, idx, w);
}

static void welded_free(struct welded *w)
{
	free(w->pos);
	free(w->nrm);
	free(w->rep);
}

/* One level of me (welded w, indices cur) within relative error `want` as measured
 * (level_error), simplified in one step from the full mesh: what the request that imports the
 * model can use, without the levels in between. meshoptimizer's target is its own figure, which
 * the measure exceeds (2-3x on a bumpy sphere): aimed at a quarter of `want`, and once more,
 * closer (at most 0.3 of that aim), when that measured over. None when it would not save a
 * quarter of the triangles. */
static void mesh_one_level(struct api_model_mesh *me, const struct welded *w, const uint32_t *cur, float want,
                           struct api_arena *arena, size_t *bytes)
{
	struct rnd_mesh_lod *lod = api_arena_calloc(arena, 1, sizeof *lod);
	uint32_t *next = malloc((size_t)me->index_count * sizeof *next);
	struct grid g = {0};
	struct walk k = {0};
	size_t ni = me->index_count;
	/* The box of the welded mesh, once: the grid's, and the extent meshoptimizer's relative
	 * errors are relative to. */
	float lo[3], hi[3], extent = points_box(w->pos, w->count, lo, hi), target = 0.25f * want;
	if (!lod || !next || !(extent > 0.0f) || !grid_build(&g, w, lo, hi, extent) || !walk_build(&k, w, cur, ni))
		goto done;
	for (int attempt = 0; attempt < 2; attempt++) {
		size_t got = api_lod_simplify(next, cur, ni, w->pos, w->count, extent, target);
		if (got < 3 || got * 4 > ni * 3) break;
		got = drop_degenerate(w, next, got);
		float e = got >= 3 ? level_error(&g, &k, w, next, got) : INFINITY;
		if (e <= want * extent || attempt == 1) {
			if (got >= 3 && e <= want * extent && write_level(arena, me, w, next, got, lod, bytes)) {
				lod->error = e;
				me->lods = lod;
				me->lod_count = 1;
			}
			break;
		}
		/* at most 0.3 of the first aim: an error that does not scale with the aim (a crease
		 * the first aim collapsed, like the 100k vase's fluted foot rim: 0.0049 at both 0.8
		 * and 0.64 of it) needs a step, else the second build is thrown away too */
		target *= fminf(0.8f * want * extent / e, 0.3f);
	}
done:
	walk_free(&k);
	free(g.start);
	free(g.items);
	free(g.ipos);
	free(next);
}

/* The one level of every mesh of m that wants one, for images of output_side, and with
 * `closed` set too when mark_closed: one weld a mesh for both. */
static void finish(struct api_model *m, uint32_t output_side, bool mark_closed, struct api_arena *arena, size_t *bytes)
{
	for (uint32_t i = 0; i < m->mesh_count; i++) {
		struct api_model_mesh *me = (struct api_model_mesh *)&m->meshes[i]; /* ours until shared */
		bool level = output_side && api_mesh_wants_levels(me);
		if (!mark_closed && !level) continue;
		double t0 = api_clock_ms();
		uint32_t *idx = me->index_count ? malloc((size_t)me->index_count * sizeof *idx) : NULL;
		struct welded w = {0};
		bool welded = welded_mesh(me, idx, &w);
		if (mark_closed) me->closed = welded && api_mesh_closed(idx, me->index_count, w.pos);
		double t1 = api_clock_ms();
		if (welded && level) mesh_one_level(me, &w, idx, api_lod_import_error(output_side), arena, bytes);
		/* the environment's maps' caster, at import only (its time counts as the level's) */
		if (welded && mark_closed && api_mesh_wants_caster(m, me)) api_caster_build(me, idx, me->index_count, w.pos, w.count, arena, bytes);
		m->times.ms[API_IMPORT_CLOSED] += (float)(t1 - t0);
		m->times.ms[API_IMPORT_LEVEL] += (float)(api_clock_ms() - t1);
		welded_free(&w);
		free(idx);
	}
}

void api_model_finish_import(struct api_model *m, uint32_t output_side, struct api_arena *arena, size_t *bytes)
{
	finish(m, output_side, true, arena, bytes);
}

void api_model_build_level(struct api_model *m, uint32_t output_side, struct api_arena *arena, size_t *bytes)
{
	finish(m, output_side, false, arena, bytes);
}

float api_lod_import_error(uint32_t output_side)
{
	/* The renderer's bound (RND_LOD_MESH_PIXEL_ERROR, half a pixel) for a mesh that spans 70 %
	 * of the image, as a thumbnail frames it (half of extent / (0.7 side): 0.71 / side), less a
	 * margin: the thumbnail preset's camera allowed 0.68 / side on every 100k corpus model
	 * (rnd_lod_mesh_level; the mesh spans ~67 %). The renderer draws the level only where it
	 * fits its bound (pixels and shadow texels as they are), else the full mesh. This was
	 * 0.35 / side (half a pixel times 0.7, not over it): levels built to half what the renderer
	 * allows, and a level measured between the two, e.g. the 100k vase glb's 0.0039 against
	 * 0.0025 asked and 0.0046 allowed, thrown away after its build (the request drew 100k
	 * triangles into its 12 environment maps). */
	return output_side ? 0.6f / (float)output_side : 0.0f;
}

bool api_mesh_wants_levels(const struct api_model_mesh *me)
{
	return me->index_count / 3 >= API_LOD_MIN_TRIANGLES && me->normals && !me->colors && !me->tangents;
}
