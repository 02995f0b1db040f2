/*
 * api/mesh_closed.c — whether a welded mesh closes a volume wound outward (see model_lod.h,
 * api_mesh_closed): every edge is run by exactly two triangles, in opposite directions, found
 * by grouping the edges by their lower vertex (a counting sort over the welded vertices: two
 * passes over the triangles) and sorting each vertex's few edges, their direction in the lowest
 * bit; the volume's sign from the divergence theorem. (Until 2026-12-05 one radix sort of all
 * edges as 64-bit keys: several passes over 24 MB for a 1M-triangle mesh.)
 *
 * The volume runs in EDGE_TASKS fixed slices of triangles on the import's threads
 * (api/workers.h), summed per slice and the slices' sums in order; the pairs are checked in
 * slices of vertices. The answer is the same whatever the thread count.
 */
#include <stdlib.h>
#include "model_lod.h"
#include "workers.h"

enum { EDGE_TASKS = 64 };

struct edges {
	const uint32_t *idx;
	const float *pos;
	size_t nt, nv;              /* triangles, vertices */
	uint32_t *start;            /* vertex v's edges (those whose lower end it is): at[start[v] .. start[v + 1]) */
	uint32_t *at;               /* each: (its higher end << 1) | 1 when it runs from there to v */
	double vol[EDGE_TASKS];
	bool fine[EDGE_TASKS];      /* every index under nv; then, every pair found */
};

static bool distinct(const uint32_t v[3])
{
	return v[0] != v[1] && v[1] != v[2] && v[0] != v[2];
}

/* Slice s's signed volume (six times), and whether its indices are all under nv. */
static void slice_volume(void *ctx, size_t s, unsigned w)
{
	(void)w;
	struct edges *q = ctx;
	uint32_t top = 0;
	double vol = 0.0;
	for (size_t t = s * q->nt / EDGE_TASKS; t < (s + 1) * q->nt / EDGE_TASKS; t++) {
		const uint32_t *v = q->idx + 3 * t;
		uint32_t hi = v[0] > v[1] ? v[0] : v[1];
		top = hi > top ? hi : top;
		top = v[2] > top ? v[2] : top;
		if (!distinct(v) || top >= q->nv) continue;
		const float *a = q->pos + 3 * (size_t)v[0], *b = q->pos + 3 * (size_t)v[1], *c = q->pos + 3 * (size_t)v[2];
		vol += (double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
		       (double)a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
		       (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
	}
	q->vol[s] = vol;
	q->fine[s] = top < q->nv;
}

/* The edges grouped by their lower end (a counting sort: count, then place), one pass each. */
static void group_edges(struct edges *q)
{
	for (size_t t = 0; t < q->nt; t++) {
		const uint32_t *v = q->idx + 3 * t;
		if (!distinct(v)) continue;
		for (int k = 0; k < 3; k++) {
			uint32_t a = v[k], b = v[(k + 1) % 3];
			q->start[(a < b ? a : b) + 1]++;
		}
	}
	for (size_t v = 0; v < q->nv; v++) q->start[v + 1] += q->start[v];
	for (size_t t = 0; t < q->nt; t++) {
		const uint32_t *v = q->idx + 3 * t;
		if (!distinct(v)) continue;
		for (int k = 0; k < 3; k++) {
			uint32_t a = v[k], b = v[(k + 1) % 3];
			q->at[q->start[a < b ? a : b]++] = a < b ? b << 1 : (a << 1) | 1u;
		}
	}
	for (size_t v = q->nv; v > 0; v--) q->start[v] = q->start[v - 1];
	q->start[0] = 0;
}

static int cmp_u32(const void *a, const void *b)
{
	uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
	return (x > y) - (x < y);
}

/* Sorted, a vertex's edges come in pairs: to a vertex (bit 0 clear), then back from it (bit 0
 * set); an edge run twice the same way, or by a third triangle, breaks a pair. The vertices of
 * slice s (a few edges each: sorted in place by insertion, a pole's fan by qsort). */
static void slice_pairs(void *ctx, size_t s, unsigned w)
{
	(void)w;
	struct edges *q = ctx;
	bool ok = true;
	for (size_t v = s * q->nv / EDGE_TASKS; ok && v < (s + 1) * q->nv / EDGE_TASKS; v++) {
		uint32_t *e = q->at + q->start[v], n = q->start[v + 1] - q->start[v];
		if (n > 32) qsort(e, n, sizeof *e, cmp_u32);
		else
			for (uint32_t i = 1; i < n; i++)
				for (uint32_t j = i, x = e[i]; j > 0 && e[j - 1] > x; j--) e[j] = e[j - 1], e[j - 1] = x;
		ok = n % 2 == 0;
		for (uint32_t i = 0; ok && i < n; i += 2) ok = !(e[i] & 1u) && e[i + 1] == (e[i] | 1u);
	}
	q->fine[s] = ok;
}

bool api_mesh_closed(const uint32_t *idx, size_t ni, const float *pos, size_t nv)
{
	struct edges *q = calloc(1, sizeof *q);
	if (!q) return false;
	*q = (struct edges){.idx = idx, .pos = pos, .nt = ni / 3, .nv = nv};
	api_workers_run(EDGE_TASKS, slice_volume, q);
	double vol = 0.0;
	bool closed = nv > 0 && nv < (1u << 31) && 3 * q->nt < UINT32_MAX;
	for (size_t s = 0; s < EDGE_TASKS; s++) {
		vol += q->vol[s];
		closed = closed && q->fine[s];
	}
	/* (indices past the vertices, more than 32-bit offsets hold), or no volume wound outward */
	closed = closed && q->nt > 0 && vol > 0.0;
	if (closed) {
		q->start = calloc(nv + 1, sizeof *q->start);
		q->at = malloc(3 * q->nt * sizeof *q->at);
		closed = q->start && q->at;
	}
	if (closed) {
		group_edges(q);
		api_workers_run(EDGE_TASKS, slice_pairs, q);
		for (size_t s = 0; s < EDGE_TASKS; s++) closed = closed && q->fine[s];
	}
	free(q->start);
	free(q->at);
	free(q);
	return closed;
}
