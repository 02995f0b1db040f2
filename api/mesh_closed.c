/*
 * api/mesh_closed.c — whether a welded mesh closes a volume wound outward (see model_lod.h,
 * api_mesh_closed): every edge is run by exactly two triangles, in opposite directions, found
 * by one sort of the edges as undirected keys with their direction in the lowest bit; the
 * volume's sign from the divergence theorem.
 *
 * The passes over the triangles run in EDGE_TASKS fixed slices on the import's threads
 * (api/workers.h): each slice's highest index, signed volume and count of triangles with three
 * distinct corners, combined in slice order; then each slice writes its edges from its own
 * offset; the pairs are checked in slices of the sorted edges. The volume is summed per slice
 * and the slices' sums in order, so the answer is the same whatever the thread count.
 */
#include <stdlib.h>
#include "model_lod.h"
#include "weld.h"
#include "workers.h"

enum { EDGE_TASKS = 64 };

struct edges {
	const uint32_t *idx;
	const float *pos;
	size_t nt;                  /* triangles */
	unsigned bits;              /* of the highest index */
	uint64_t *e;
	const uint64_t *sorted;
	size_t ne;
	uint32_t top[EDGE_TASKS];
	double vol[EDGE_TASKS];
	size_t at[EDGE_TASKS];      /* each slice's triangles with three corners, then its first edge */
	bool paired[EDGE_TASKS];
};

static bool distinct(const uint32_t v[3])
{
	return v[0] != v[1] && v[1] != v[2] && v[0] != v[2];
}

/* Slice s's highest index, signed volume (six times) and count of triangles with three corners. */
static void slice_volume(void *ctx, size_t s, unsigned w)
{
	(void)w;
	struct edges *q = ctx;
	uint32_t top = 0;
	size_t n = 0;
	double vol = 0.0;
	for (size_t t = s * q->nt / EDGE_TASKS; t < (s + 1) * q->nt / EDGE_TASKS; t++) {
		const uint32_t *v = q->idx + 3 * t;
		top |= v[0] | v[1] | v[2];
		if (!distinct(v)) continue;
		n++;
		const float *a = q->pos + 3 * (size_t)v[0], *b = q->pos + 3 * (size_t)v[1], *c = q->pos + 3 * (size_t)v[2];
		vol += (double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
		       (double)a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
		       (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
	}
	q->top[s] = top;
	q->vol[s] = vol;
	q->at[s] = n;
}

/* Slice s's edges from its offset: a -> b as (min << (bits + 1)) | (max << 1) | (a > b). */
static void slice_edges(void *ctx, size_t s, unsigned w)
{
	(void)w;
	struct edges *q = ctx;
	uint64_t *e = q->e + q->at[s];
	for (size_t t = s * q->nt / EDGE_TASKS; t < (s + 1) * q->nt / EDGE_TASKS; t++) {
		const uint32_t *v = q->idx + 3 * t;
		if (!distinct(v)) continue;
		for (int k = 0; k < 3; k++) {
			uint64_t a = v[k], b = v[(k + 1) % 3];
			*e++ = a < b ? (a << (q->bits + 1)) | (b << 1) : (b << (q->bits + 1)) | (a << 1) | 1u;
		}
	}
}

/* Sorted, the edges come in pairs: one way (bit 0 clear), then the other way (bit 0 set); an
 * edge run twice the same way, or by a third triangle, breaks a pair. Slice s's pairs. */
static void slice_pairs(void *ctx, size_t s, unsigned w)
{
	(void)w;
	struct edges *q = ctx;
	const uint64_t *se = q->sorted;
	size_t pairs = q->ne / 2;
	bool ok = true;
	for (size_t i = 2 * (s * pairs / EDGE_TASKS); ok && i < 2 * ((s + 1) * pairs / EDGE_TASKS); i += 2)
		ok = !(se[i] & 1u) && se[i + 1] == (se[i] | 1u);
	q->paired[s] = ok;
}

bool api_mesh_closed(const uint32_t *idx, size_t ni, const float *pos)
{
	struct edges *q = calloc(1, sizeof *q);
	if (!q) return false;
	*q = (struct edges){.idx = idx, .pos = pos, .nt = ni / 3};
	api_workers_run(EDGE_TASKS, slice_volume, q);
	uint32_t top = 0;
	double vol = 0.0;
	for (size_t s = 0; s < EDGE_TASKS; s++) {
		size_t n = q->at[s];
		top |= q->top[s];
		vol += q->vol[s];
		q->at[s] = q->ne;
		q->ne += 3 * n;
	}
	while (q->bits < 32 && top >> q->bits) q->bits++;
	/* (more vertices than any import holds), or no volume wound outward */
	bool closed = q->bits <= 31 && q->ne > 0 && q->ne % 2 == 0 && vol > 0.0;
	uint64_t *tmp = NULL;
	if (closed) {
		q->e = malloc(q->ne * sizeof *q->e);
		tmp = malloc(q->ne * sizeof *tmp);
		closed = q->e && tmp;
	}
	if (closed) {
		api_workers_run(EDGE_TASKS, slice_edges, q);
		q->sorted = api_radix_sort(q->e, tmp, NULL, NULL, q->ne);
		api_workers_run(EDGE_TASKS, slice_pairs, q);
		for (size_t s = 0; s < EDGE_TASKS; s++) closed = closed && q->paired[s];
	}
	free(q->e);
	free(tmp);
	free(q);
	return closed;
}
