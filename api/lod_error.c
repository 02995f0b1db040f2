/*
 * api/lod_error.c — how far a level of detail is from its full mesh (see lod_error.h): a
 * cheap estimate from the nearest full-mesh vertex's tangent plane (a grid over the vertices),
 * and where that can matter, the exact distance from the full mesh's faces met walking its
 * surface out from the level triangle's corners.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "lod_error.h"
#include "weld.h"   /* api_radix_sort */
#include "workers.h"
#include "umbra/rnd_math.h"

/* The full mesh: welded positions and their unit normals. */
struct surface {
	const float *pos, *nrm;
	size_t count;
};

/* (Comparisons, not fminf/fmaxf: those are calls into libm, for their NaN rules, and positions
 * are finite; the daemon runs this over every mesh of a reply, api_mesh_bounds.) */
float api_points_box(const float *p, size_t n, float lo[3], float hi[3])
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
static bool grid_build(struct grid *g, const struct surface *w, const float lo[3], const float hi[3], float ext)
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

/* The nearest of the vertices in cells lo..hi to p, into *best (squared; stays when none is
 * nearer) and *bv: rows in z, y order, each row's cells one run of items, the first of equals. */
static void nearest_in(const struct grid *g, const float p[3], const uint32_t lo[3], const uint32_t hi[3],
                       float *best, uint32_t *bv)
{
	for (uint32_t z = lo[2]; z <= hi[2]; z++)
		for (uint32_t y = lo[1]; y <= hi[1]; y++) {
			size_t row = ((size_t)z * g->dim[1] + y) * g->dim[0];
			for (uint32_t i = g->start[row + lo[0]], e = g->start[row + hi[0] + 1]; i < e; i++) {
				const float *q = g->ipos + 3 * (size_t)i;
				float d0 = p[0] - q[0], d1 = p[1] - q[1], d2 = p[2] - q[2];
				float dd = d0 * d0 + d1 * d1 + d2 * d2;
				if (dd < *best) { *best = dd; *bv = g->items[i]; }
			}
		}
}

/* Distance of p from the full mesh, estimated as its distance from the tangent plane (the
 * full mesh's vertex normal) of the nearest full-mesh vertex in the cells around it (searched up to 4
 * cells out; none that near counts as 4 cells, which marks the level as coarse). The nearest in
 * p's own cell first: a neighbour cell whose side is farther from p than that one cannot hold
 * a nearer vertex, so the 27 cells around p shrink to those that can (often p's own alone),
 * searched in the same order: the same vertex as the 27 would give, in a fraction of the time
 * (the level's measure makes this search for four points of every level triangle). */
static float surface_distance(const struct grid *g, const struct surface *w, const float p[3])
{
	uint32_t c[3] = {cell_of(g, p, 0), cell_of(g, p, 1), cell_of(g, p, 2)};
	float best = INFINITY;
	uint32_t bv = 0;
	nearest_in(g, p, c, c, &best, &bv);
	if (best < INFINITY) {
		/* (a margin for the rounding of cell_of's division at a cell's side) */
		float reach = sqrtf(best) * 1.01f + 1e-4f * g->cell;
		uint32_t lo[3], hi[3];
		for (int k = 0; k < 3; k++) {
			float side = g->lo[k] + (float)c[k] * g->cell;
			lo[k] = c[k] > 0 && p[k] - side <= reach ? c[k] - 1 : c[k];
			hi[k] = c[k] + 1 < g->dim[k] && side + g->cell - p[k] <= reach ? c[k] + 1 : c[k];
		}
		best = INFINITY;
		nearest_in(g, p, lo, hi, &best, &bv);
	}
	for (uint32_t r = 1; r <= 4 && best == INFINITY; r++) {
		uint32_t lo[3], hi[3];
		for (int k = 0; k < 3; k++) {
			lo[k] = c[k] > r ? c[k] - r : 0;
			hi[k] = c[k] + r < g->dim[k] ? c[k] + r : g->dim[k] - 1;
		}
		nearest_in(g, p, lo, hi, &best, &bv);
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

static bool walk_build(struct walk *k, const struct surface *w, const uint32_t *idx, size_t ni)
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

/* A level triangle's samples: s[0] its centroid, s[1..3] its edges' midpoints (its corners are
 * the full mesh's own vertices); v[] its corners. */
static void tri_samples(const struct surface *w, const uint32_t *tri, const float *v[3], float s[4][3])
{
	for (int c = 0; c < 3; c++) v[c] = w->pos + 3 * (size_t)tri[c];
	for (int a = 0; a < 3; a++) {
		s[0][a] = (v[0][a] + v[1][a] + v[2][a]) / 3.0f;
		s[1][a] = 0.5f * (v[0][a] + v[1][a]);
		s[2][a] = 0.5f * (v[1][a] + v[2][a]);
		s[3][a] = 0.5f * (v[2][a] + v[0][a]);
	}
}

/* The squared distance of the level triangle tri's samples from the full mesh's faces met
 * walking out from its corners without leaving the ball around it (its circumscribing sphere,
 * widened by half), the largest of the four; or at most worst2 (the walk stops early) when
 * every sample comes within sqrt(worst2) of a face: then the triangle cannot raise the level's
 * worst. The walk's order does not change the answer: it is the exact figure over the faces
 * of the ball's connected part, or one not above worst2. */
/* Whether each of a level triangle's samples s (corners v, ball r2 around s[0]) comes within
 * sqrt(worst2) of a full-mesh face met going downhill from its nearest corner: from a vertex to
 * its faces' vertex nearest the sample, inside the ball, until none is nearer. Those faces are
 * among walk_triangle's (each vertex on the way is one its walk queues), so when this is true
 * the walk would stop early too, and the triangle cannot raise the level's worst; a few dozen
 * faces a sample where the walk meets thousands before its early stop. */
static bool downhill_within(const struct walk *k, const struct surface *w, const uint32_t *tri, const float *v[3],
                            const float s[4][3], float r2, float worst2)
{
	for (int q = 0; q < 4; q++) {
		uint32_t u = tri[0];
		float du = INFINITY, best = INFINITY;
		for (int c = 0; c < 3; c++) {
			float d[3];
			rnd_v3_sub(d, v[c], s[q]);
			if (rnd_v3_dot(d, d) < du) du = rnd_v3_dot(d, d), u = tri[c];
		}
		for (int step = 0; step < 256 && best > worst2; step++) {
			uint32_t next = u;
			for (uint32_t i = k->start[u]; i < k->start[u + 1]; i++) {
				const uint32_t *fi = k->idx + 3 * (size_t)k->faces[i];
				best = min_f(best, point_triangle_d2(s[q], w->pos + 3 * (size_t)fi[0], w->pos + 3 * (size_t)fi[1],
				                                     w->pos + 3 * (size_t)fi[2]));
				for (int j = 0; j < 3; j++) {
					const float *x = w->pos + 3 * (size_t)fi[j];
					float d[3], e[3];
					rnd_v3_sub(d, x, s[q]);
					rnd_v3_sub(e, x, s[0]);
					if (rnd_v3_dot(d, d) < du && rnd_v3_dot(e, e) <= r2) du = rnd_v3_dot(d, d), next = fi[j];
				}
			}
			if (next == u) break;
			u = next;
		}
		if (best > worst2) return false;
	}
	return true;
}

static float walk_triangle(struct walk *k, const struct surface *w, const uint32_t *tri, float worst2)
{
	const float *v[3];
	float s[4][3], r2 = 0.0f;
	tri_samples(w, tri, v, s);
	for (int c = 0; c < 3; c++) {
		float d[3];
		rnd_v3_sub(d, v[c], s[0]);
		r2 = max_f(r2, rnd_v3_dot(d, d));
	}
	r2 *= 2.25f;
	if (worst2 > 0.0f && downhill_within(k, w, tri, v, s, r2, worst2)) return worst2;
	float best[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
	if (++k->stamp == 0) {
		memset(k->vseen, 0, w->count * sizeof *k->vseen);
		memset(k->fseen, 0, (k->start[w->count] / 3) * sizeof *k->fseen);
		k->stamp = 1;
	}
	uint32_t head = 0, tail = 0;
	for (int c = 0; c < 3; c++)
		if (k->vseen[tri[c]] != k->stamp) {
			k->vseen[tri[c]] = k->stamp;
			k->queue[tail++] = tri[c];
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
			if (most <= worst2) return most;
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
	float most = 0.0f;
	for (int q = 0; q < 4; q++) most = max_f(most, best[q]);
	return most;
}

/* The cheap estimates of level_error's triangles, each its key (the estimate's bits, inverted:
 * descending, then the triangle's index), in ESTIMATE_TASKS fixed slices on the import's threads
 * (api/workers.h): each triangle writes its own key, whatever thread measures it. */
enum { ESTIMATE_TASKS = 32 };
struct estimates {
	const struct grid *g;
	const struct surface *w;
	const uint32_t *idx;
	size_t nt;
	uint64_t *key;
};

static void estimate_slice(void *ctx, size_t i, unsigned wk)
{
	(void)wk;
	const struct estimates *q = ctx;
	for (size_t t = i * q->nt / ESTIMATE_TASKS; t < (i + 1) * q->nt / ESTIMATE_TASKS; t++) {
		const float *v[3];
		float s[4][3], e = 0.0f;
		tri_samples(q->w, q->idx + 3 * t, v, s);
		for (int k = 0; k < 4; k++) e = max_f(e, surface_distance(q->g, q->w, s[k]));
		uint32_t bits;
		memcpy(&bits, &e, sizeof bits);   /* e >= 0: its bits order as it does */
		q->key[t] = (uint64_t)~bits << 32 | (uint64_t)t;
	}
}

/* How far a level (idx: ni indices into w) is from the full mesh: the largest distance of its
 * triangles' centroids and edge midpoints (its vertices are the full mesh's own) from the full
 * mesh's faces around them (walk_triangle): exact, where the faces nearest a point are among
 * those (else more, never less). That walk covers thousands of faces for a coarse level's
 * triangle, so it runs only for triangles whose cheap estimate (surface_distance, the largest
 * of the four samples') comes within half the level's worst; where the cheap estimate is far
 * below the truth, a triangle is missed. The cheap estimate alone had been the measure: a
 * nearest vertex found in space can belong to another part close by (an eyeball in its socket)
 * or sit on a crease of the triangle's own face, and every level of the 124k-triangle ogre OBJ
 * measured 0.29 of its 12-unit height that way, so none was ever drawn. meshoptimizer's own
 * error measures the kept vertices against the removed faces' planes and says nothing of the
 * new triangles' insides: on a sphere it claims 6x less than this.
 *
 * The triangles are walked in descending order of their cheap estimates (ties: index order),
 * so that the worst rises at once, and the first triangle whose estimate is under half the
 * worst ends the measure (every later one's is too); a triangle that cannot raise the worst is
 * mostly told by a few faces downhill from its corners (downhill_within) instead of its walk.
 * The figure is the same as walking in index order, where the worst rose slowly and each walk
 * met ~2,200 faces before its early stop: the same errors, bit for bit, on the 1M, 100k and
 * real-mesh levels measured (docs/performance.md); the 1M-triangle blob STL's level at 256
 * pixels 270-530 ms -> 60-70 ms. */
static float level_error(const struct grid *g, struct walk *k, const struct surface *w, const uint32_t *idx, size_t ni)
{
	size_t nt = ni / 3;
	uint64_t *key = malloc((nt ? nt : 1) * 2 * sizeof *key);
	if (!key) return INFINITY;   /* out of memory: no level (the full mesh is always correct) */
	struct estimates q = {g, w, idx, nt, key};
	api_workers_run(ESTIMATE_TASKS, estimate_slice, &q);
	const uint64_t *order = api_radix_sort(key, key + nt, NULL, NULL, nt);
	float worst2 = 0.0f;
	for (size_t i = 0; i < nt; i++) {
		uint32_t bits = ~(uint32_t)(order[i] >> 32);
		float e;
		memcpy(&e, &bits, sizeof e);
		if (4.0f * e * e <= worst2) break;   /* this one's and every later one's estimate */
		worst2 = max_f(worst2, walk_triangle(k, w, idx + 3 * (uint32_t)order[i], worst2));
	}
	free(key);
	return sqrtf(worst2);
}

/* The figure level_error stands for: every triangle of the level walked to the end. */
static float level_error_everywhere(struct walk *k, const struct surface *w, const uint32_t *idx, size_t ni)
{
	float worst2 = 0.0f;
	for (size_t t = 0; t + 2 < ni; t += 3) worst2 = max_f(worst2, walk_triangle(k, w, idx + t, 0.0f));
	return sqrtf(worst2);
}

struct api_lod_measure {
	struct surface w;
	struct grid g;
	struct walk k;
};

struct api_lod_measure *api_lod_measure_create(const float *pos, const float *nrm, size_t nv, const uint32_t *full,
                                               size_t nfull, const float lo[3], const float hi[3], float extent)
{
	struct api_lod_measure *m = calloc(1, sizeof *m);
	if (!m) return NULL;
	m->w = (struct surface){pos, nrm, nv};
	if (!grid_build(&m->g, &m->w, lo, hi, extent) || !walk_build(&m->k, &m->w, full, nfull)) {
		api_lod_measure_destroy(m);
		return NULL;
	}
	return m;
}

void api_lod_measure_destroy(struct api_lod_measure *m)
{
	if (!m) return;
	walk_free(&m->k);
	free(m->g.start);
	free(m->g.items);
	free(m->g.ipos);
	free(m);
}

float api_lod_measure_level(struct api_lod_measure *m, const uint32_t *level, size_t nlevel, bool everywhere)
{
	return everywhere ? level_error_everywhere(&m->k, &m->w, level, nlevel)
	                  : level_error(&m->g, &m->k, &m->w, level, nlevel);
}
