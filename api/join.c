/*
 * api/join.c — api_join_vertices (declared in model_conv.h): the corners of a flat-shaded mesh
 * (an STL's, a PLY's with face colours) joined where they are one vertex, within the groups of
 * the sorted weld (api/weld.h), which the mesh then keeps for the closedness check and the level.
 */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <meshoptimizer.h>
#include "model_conv.h"
#include "weld.h"
#include "workers.h"

/* What join_vertices compares of a corner. */
struct join_key {
	float pos[3];
	int16_t nrm[3];
	uint8_t col[4];
	int16_t pad;   /* zero: keys are compared byte for byte */
};

static void join_key_of(const float *pos, const float *nrm, const uint8_t *col, uint32_t v, struct join_key *k)
{
	memset(k, 0, sizeof *k);
	for (int a = 0; a < 3; a++) {
		k->pos[a] = pos[3 * (size_t)v + (size_t)a] + 0.0f;   /* -0 is 0 */
		k->nrm[a] = (int16_t)api_round_even(nrm[3 * (size_t)v + (size_t)a] * 16384.0f);
	}
	if (col) memcpy(k->col, col + 4 * (size_t)v, 4);
}

struct keyed {
	struct join_key k;
	uint32_t v;
};

static int keyed_cmp(const void *a, const void *b)
{
	const struct keyed *x = a, *y = b;
	int c = memcmp(&x->k, &y->k, sizeof x->k);
	return c ? c : (x->v > y->v) - (x->v < y->v);
}

/* lead[v] for the members m[0..n) of one weld group (in vertex order): the first member with
 * v's key. A few members are compared with each other; many (a fan of a million facets around
 * one apex) are sorted by key instead. -1 without memory. */
static int join_group(const float *pos, const float *nrm, const uint8_t *col, const uint32_t *m, uint32_t n,
                      uint32_t *lead)
{
	enum { FEW = 16 };
	if (n <= FEW) {
		struct join_key k[FEW];
		uint32_t first[FEW], nk = 0;
		for (uint32_t i = 0; i < n; i++) {
			join_key_of(pos, nrm, col, m[i], &k[nk]);
			uint32_t j = 0;
			while (j < nk && memcmp(&k[j], &k[nk], sizeof k[0])) j++;
			if (j == nk) first[nk++] = m[i];
			lead[m[i]] = first[j];
		}
		return 0;
	}
	struct keyed *s = malloc(n * sizeof *s);
	if (!s) return -1;
	for (uint32_t i = 0; i < n; i++) {
		join_key_of(pos, nrm, col, m[i], &s[i].k);
		s[i].v = m[i];
	}
	qsort(s, n, sizeof *s, keyed_cmp);
	for (uint32_t i = 0; i < n; i++) lead[s[i].v] = i && !memcmp(&s[i].k, &s[i - 1].k, sizeof s[i].k) ? lead[s[i - 1].v] : s[i].v;
	free(s);
	return 0;
}

/* The weld's groups joined in GROUP_TASKS tasks of consecutive groups on the import's threads
 * (api/workers.h): each writes lead[] of its own members only. */
enum { GROUP_TASKS = 64 };
struct groups {
	const float *pos, *nrm;
	const uint8_t *col;
	const struct api_weld *w;
	uint32_t *lead;
	atomic_int failed;
};

static void join_groups(void *ctx, size_t task, unsigned wk)
{
	(void)wk;
	struct groups *q = ctx;
	const struct api_weld *w = q->w;
	for (size_t g = task * w->groups / GROUP_TASKS; g < (task + 1) * w->groups / GROUP_TASKS; g++)
		if (join_group(q->pos, q->nrm, q->col, w->order + w->start[g], w->start[g + 1] - w->start[g], q->lead))
			atomic_store(&q->failed, 1);
}

uint32_t api_join_vertices(float *pos, float *nrm, uint8_t *col, uint32_t nv, uint32_t *idx, uint32_t ni,
                           struct api_arena *arena, const uint32_t **weld_group, uint32_t *weld_groups)
{
	*weld_group = NULL;
	*weld_groups = 0;
	struct api_weld w;
	uint32_t *remap = malloc((size_t)(nv ? nv : 1) * sizeof *remap);
	if (!remap || !api_weld_sort(pos, nv, &w)) {
		free(remap);
		return nv;
	}
	struct groups q = {pos, nrm, col, &w, remap, 0};
	api_workers_run(GROUP_TASKS, join_groups, &q);
	int rc = atomic_load(&q.failed) ? -1 : 0;
	uint32_t *jg = rc == 0 ? api_arena_calloc(arena, nv ? nv : 1, sizeof *jg) : NULL;
	if (!jg) {
		api_weld_release(&w);
		free(remap);
		return nv;
	}
	/* Numbered in the order they first occur (a leader comes first in its group); each joined
	 * vertex keeps its weld group. */
	uint32_t unique = 0;
	for (uint32_t v = 0; v < nv; v++) {
		uint32_t l = remap[v];
		remap[v] = l == v ? unique++ : remap[l];
		jg[remap[v]] = w.group[v];
	}
	/* new ids follow first occurrences: remap[v] <= v, so moving down in order is safe */
	for (uint32_t v = 0; v < nv; v++)
		if (remap[v] != v) {
			memcpy(pos + 3 * (size_t)remap[v], pos + 3 * (size_t)v, 12);
			memcpy(nrm + 3 * (size_t)remap[v], nrm + 3 * (size_t)v, 12);
			if (col) memcpy(col + 4 * (size_t)remap[v], col + 4 * (size_t)v, 4);
		}
	meshopt_remapIndexBuffer(idx, idx, ni, remap);
	*weld_group = jg;
	*weld_groups = (uint32_t)w.groups;
	api_weld_release(&w);
	free(remap);
	return unique;
}
