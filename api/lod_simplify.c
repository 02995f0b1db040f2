/*
 * api/lod_simplify.c — meshoptimizer's simplification of a welded mesh, in pieces that fit the
 * cache when the mesh is large (see lod_simplify.h).
 */
#include <meshoptimizer.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "lod_simplify.h"
#include "workers.h"

/* Each triangle's piece: its centroid's cell of a k x k x k grid over lo..hi. */
static uint32_t piece_of(const float *pos, const uint32_t *t, const float lo[3], const float hi[3], uint32_t k)
{
	uint32_t c[3];
	for (int a = 0; a < 3; a++) {
		float m = (pos[3 * (size_t)t[0] + a] + pos[3 * (size_t)t[1] + a] + pos[3 * (size_t)t[2] + a]) / 3.0f;
		float f = hi[a] > lo[a] ? (m - lo[a]) / (hi[a] - lo[a]) * (float)k : 0.0f;
		c[a] = f <= 0.0f ? 0 : f >= (float)k ? k - 1 : (uint32_t)f;
	}
	return (c[2] * k + c[1]) * k + c[0];
}

/* Each triangle's piece, in PIECE_TASKS tasks of consecutive triangles on the import's threads. */
enum { PIECE_TASKS = 64 };
struct piece_of_task {
	const float *pos, *lo, *hi;
	const uint32_t *idx;
	size_t nt;
	uint32_t k, *piece;
};

static void pieces_of(void *ctx, size_t task, unsigned w)
{
	(void)w;
	const struct piece_of_task *q = ctx;
	for (size_t t = task * q->nt / PIECE_TASKS; t < (task + 1) * q->nt / PIECE_TASKS; t++)
		q->piece[t] = piece_of(q->pos, q->idx + 3 * t, q->lo, q->hi, q->k);
}

/* The triangles of idx grouped by piece into by[] (piece p: by[3 * start[p] .. 3 * start[p + 1])). */
static void group_pieces(const float *pos, const uint32_t *idx, size_t nt, const float lo[3], const float hi[3],
                         uint32_t k, uint32_t *by, size_t *start, uint32_t *piece)
{
	uint32_t np = k * k * k;
	struct piece_of_task q = {pos, lo, hi, idx, nt, k, piece};
	api_workers_run(PIECE_TASKS, pieces_of, &q);
	memset(start, 0, (np + 1) * sizeof *start);
	for (size_t t = 0; t < nt; t++) start[piece[t] + 1]++;
	for (uint32_t p = 0; p < np; p++) start[p + 1] += start[p];
	for (size_t t = 0; t < nt; t++) memcpy(by + 3 * start[piece[t]]++, idx + 3 * t, 12);
	for (uint32_t p = np; p > 0; p--) start[p] = start[p - 1];
	start[0] = 0;
}

/* Scratch for simplify_part: a vertex's local id (~0u outside the part in hand), the local
 * vertices' global ids and positions, the part's local indices. */
struct part {
	uint32_t *local, *global, *lidx;
	float *lpos;
};

/* Triangles tri[0..n) (global ids) simplified on their own, within abs_target (object units),
 * with meshoptimizer's options; appended to out (global ids), which may be tri. */
static size_t simplify_part(const float *pos, const uint32_t *tri, size_t n, float abs_target, unsigned options,
                            struct part *s, uint32_t *out)
{
	size_t nv = 0;
	for (size_t i = 0; i < n; i++) {
		uint32_t v = tri[i];
		if (s->local[v] == ~0u) {
			s->global[nv] = v;
			memcpy(s->lpos + 3 * nv, pos + 3 * (size_t)v, 12);
			s->local[v] = (uint32_t)nv++;
		}
		s->lidx[i] = s->local[v];
	}
	/* meshoptimizer's error is relative to the extent of what it is given */
	float scale = meshopt_simplifyScale(s->lpos, nv, 12);
	size_t got = n && scale > 0.0f ? meshopt_simplify(s->lidx, s->lidx, n, s->lpos, nv, 12, 3, abs_target / scale,
	                                                  options, NULL) : 0;
	for (size_t i = 0; i < got; i++) out[i] = s->global[s->lidx[i]];
	for (size_t i = 0; i < nv; i++) s->local[s->global[i]] = ~0u;
	return got;
}

/* The pieces, each simplified on its own with its borders locked: piece p in place in
 * by[3 * start[p] ..), its count in cnt[p]; slot w's scratch for the thread in slot w. */
struct pieces {
	const float *pos;
	uint32_t *by;
	const size_t *start;
	size_t *cnt;
	float abs_target;
	struct part *s;
};

static void simplify_piece(void *ctx, size_t p, unsigned w)
{
	struct pieces *q = ctx;
	uint32_t *tri = q->by + 3 * q->start[p];
	q->cnt[p] = simplify_part(q->pos, tri, 3 * (q->start[p + 1] - q->start[p]), q->abs_target,
	                          meshopt_SimplifyLockBorder, &q->s[w], tri);
}

/* Slot w's scratch: every vertex's local id (all ~0u), room for ni indices and nvl vertices. */
static bool part_alloc(struct part *s, size_t nv, size_t nvl, size_t ni)
{
	s->local = malloc(nv * sizeof *s->local);
	s->global = malloc(nvl * sizeof *s->global);
	s->lidx = malloc(ni * sizeof *s->lidx);
	s->lpos = malloc(nvl * 12);
	if (!s->local || !s->global || !s->lidx || !s->lpos) return false;
	memset(s->local, 0xff, nv * sizeof *s->local);
	return true;
}

static void part_free(struct part *s)
{
	free(s->local);
	free(s->global);
	free(s->lidx);
	free(s->lpos);
}

/* The pieces on the import's threads (api/workers.h), then joined in piece order: the same
 * indices whatever the thread count. */
static size_t simplify_pieces(uint32_t *dst, const float *pos, size_t nv, uint32_t *by, const size_t *start,
                              uint32_t np, float abs_target, struct part *s)
{
	size_t most = 0, got = 0;
	for (uint32_t p = 0; p < np; p++)
		if (start[p + 1] - start[p] > most) most = start[p + 1] - start[p];
	unsigned nw = api_workers_count();
	size_t *cnt = malloc(np * sizeof *cnt);
	bool ok = cnt != NULL;
	for (unsigned w = 1; w < nw && ok; w++) ok = part_alloc(&s[w], nv, 3 * most < nv ? 3 * most : nv, 3 * most);
	if (ok) {
		struct pieces q = {pos, by, start, cnt, abs_target, s};
		api_workers_run(np, simplify_piece, &q);
		for (uint32_t p = 0; p < np; p++) {
			memcpy(dst + got, by + 3 * start[p], cnt[p] * sizeof *dst);
			got += cnt[p];
		}
	} else {
		/* one thread, its own scratch */
		for (uint32_t p = 0; p < np; p++)
			got += simplify_part(pos, by + 3 * start[p], 3 * (start[p + 1] - start[p]), abs_target,
			                     meshopt_SimplifyLockBorder, &s[0], dst + got);
	}
	for (unsigned w = 1; w < nw; w++) part_free(&s[w]);
	free(cnt);
	return got;
}

size_t api_lod_simplify(uint32_t *dst, const uint32_t *idx, size_t ni, const float *pos, size_t nv, float extent,
                        float target)
{
	size_t nt = ni / 3;
	uint32_t k = 1;
	while (k < 8 && (size_t)(k + 1) * (k + 1) * (k + 1) * API_LOD_PIECE_TRIANGLES <= nt) k++;
	uint32_t np = k * k * k;
	struct part s[API_WORKERS_MAX] = {{0}};
	uint32_t *by = k > 1 ? malloc(ni * sizeof *by) : NULL, *piece = by ? malloc(nt * sizeof *piece) : NULL;
	size_t *start = piece ? malloc((np + 1) * sizeof *start) : NULL;
	size_t got = 0;
	if (start && part_alloc(&s[0], nv, nv, ni)) {
		float lo[3] = {pos[0], pos[1], pos[2]}, hi[3] = {pos[0], pos[1], pos[2]};
		for (size_t v = 0; v < nv; v++)
			for (int a = 0; a < 3; a++) {
				if (pos[3 * v + a] < lo[a]) lo[a] = pos[3 * v + a];
				if (pos[3 * v + a] > hi[a]) hi[a] = pos[3 * v + a];
			}
		group_pieces(pos, idx, nt, lo, hi, k, by, start, piece);
		got = simplify_pieces(dst, pos, nv, by, start, np, target * extent, s);
		/* then the whole, a fraction of its size now: the cuts, kept so far, go too */
		got = simplify_part(pos, dst, got, target * extent, 0, &s[0], dst);
	} else {
		got = meshopt_simplify(dst, idx, ni, pos, nv, 12, 3, target, 0, NULL);
	}
	free(by);
	free(piece);
	free(start);
	part_free(&s[0]);
	return got;
}
