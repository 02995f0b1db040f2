/*
 * renderer/atlas.c — buddy-quadtree tile allocator (see atlas.h).
 *
 * Nodes are stored level by level: level 0 is the whole atlas (node 0), level k holds 4^k
 * nodes in row-major order of a 2^k x 2^k grid, starting at index (4^k - 1) / 3.
 */
#include <stdlib.h>
#include <string.h>
#include "atlas.h"

enum { FREE = 0, SPLIT = 1, USED = 2 };

static uint32_t level_base(uint32_t k) { return (uint32_t)((((uint64_t)1 << (2 * k)) - 1) / 3); }

static bool pow2(uint32_t v) { return v && !(v & (v - 1)); }

bool rnd_atlas_init(struct rnd_atlas *a, uint32_t size, uint32_t min_tile)
{
	memset(a, 0, sizeof *a);
	if (!pow2(size) || !pow2(min_tile) || min_tile > size) return false;
	uint32_t levels = 1;
	while ((size >> (levels - 1)) > min_tile) levels++;
	if (levels > 12) return false;
	a->node_count = level_base(levels);
	a->state = calloc(a->node_count, 1);
	if (!a->state) return false;
	a->size = size;
	a->min_tile = min_tile;
	a->levels = levels;
	return true;
}

void rnd_atlas_release(struct rnd_atlas *a)
{
	free(a->state);
	memset(a, 0, sizeof *a);
}

/* Depth-first search under node (level k, grid cell cx, cy) for a free node at level target. */
static bool find(struct rnd_atlas *a, uint32_t k, uint32_t cx, uint32_t cy, uint32_t target, struct rnd_tile *out)
{
	uint32_t n = level_base(k) + cy * (1u << k) + cx;
	uint8_t st = a->state[n];
	if (st == USED) return false;
	if (k == target) {
		if (st != FREE) return false;
		a->state[n] = USED;
		uint32_t ts = a->size >> k;
		out->x = cx * ts; out->y = cy * ts; out->size = ts; out->node = n;
		return true;
	}
	if (st == FREE) {
		/* Split: the children start free. */
		a->state[n] = SPLIT;
		uint32_t cb = level_base(k + 1);
		for (uint32_t j = 0; j < 2; j++)
			for (uint32_t i = 0; i < 2; i++) a->state[cb + (2 * cy + j) * (1u << (k + 1)) + 2 * cx + i] = FREE;
	}
	for (uint32_t j = 0; j < 2; j++)
		for (uint32_t i = 0; i < 2; i++)
			if (find(a, k + 1, 2 * cx + i, 2 * cy + j, target, out)) return true;
	/* Nothing found below: undo a split that left all four children free. */
	uint32_t cb = level_base(k + 1), w = 1u << (k + 1), nfree = 0;
	for (uint32_t j = 0; j < 2; j++)
		for (uint32_t i = 0; i < 2; i++) nfree += a->state[cb + (2 * cy + j) * w + 2 * cx + i] == FREE;
	if (nfree == 4) a->state[n] = FREE;
	return false;
}

bool rnd_atlas_alloc(struct rnd_atlas *a, uint32_t size, struct rnd_tile *out)
{
	if (!a->state || !pow2(size) || size > a->size || size < a->min_tile) return false;
	uint32_t target = 0;
	while ((a->size >> target) > size) target++;
	if (!find(a, 0, 0, 0, target, out)) return false;
	a->used_texels += (uint64_t)size * size;
	a->used_tiles++;
	return true;
}

void rnd_atlas_free(struct rnd_atlas *a, const struct rnd_tile *t)
{
	if (!a->state || t->node >= a->node_count || a->state[t->node] != USED) return;
	a->state[t->node] = FREE;
	a->used_texels -= (uint64_t)t->size * t->size;
	a->used_tiles--;
	/* Merge upwards while all four siblings are free. */
	uint32_t k = 0;
	while ((a->size >> k) > t->size) k++;
	uint32_t cx = t->x / t->size, cy = t->y / t->size;
	while (k > 0) {
		uint32_t px = cx / 2, py = cy / 2, cb = level_base(k), w = 1u << k, nfree = 0;
		for (uint32_t j = 0; j < 2; j++)
			for (uint32_t i = 0; i < 2; i++) nfree += a->state[cb + (2 * py + j) * w + 2 * px + i] == FREE;
		if (nfree != 4) break;
		k--;
		a->state[level_base(k) + py * (1u << k) + px] = FREE;
		cx = px; cy = py;
	}
}

double rnd_atlas_occupancy(const struct rnd_atlas *a)
{
	return a->size ? (double)a->used_texels / ((double)a->size * a->size) : 0.0;
}

bool rnd_atlas_fit(const uint32_t *tiles, const uint32_t *want, uint32_t n, uint32_t atlas, uint32_t min_tile,
                   uint32_t *res)
{
	for (uint32_t k = 0; k < n; k++) res[k] = want[k] < min_tile ? min_tile : want[k] > atlas ? atlas : want[k];
	for (;;) {
		uint64_t need = 0;
		uint32_t big = n;
		for (uint32_t k = 0; k < n; k++) {
			need += (uint64_t)tiles[k] * res[k] * res[k];
			if (res[k] > min_tile && (big == n || res[k] > res[big])) big = k;
		}
		if (need <= (uint64_t)atlas * atlas) return true;
		if (big == n) return false;
		res[big] /= 2;
	}
}
