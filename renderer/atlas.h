/*
 * renderer/atlas.h — a square texture atlas carved into power-of-two square tiles (a buddy
 * quadtree): alloc finds the first free tile of the asked size in a fixed scan order and
 * splits larger free tiles to get one; free merges four free siblings back into their parent.
 *
 * Pure bookkeeping: no Vulkan, no allocation after init. Not thread-safe: the caller locks
 * (renderer/shadow_cache.c holds the context's cache mutex around every call). rnd_atlas_fit
 * needs no atlas and no lock.
 *
 *   struct rnd_atlas a; rnd_atlas_init(&a, 8192, 64);
 *   struct rnd_tile t; if (rnd_atlas_alloc(&a, 1024, &t)) { ... t.x, t.y, t.size ...; rnd_atlas_free(&a, &t); }
 *   rnd_atlas_release(&a);
 */
#ifndef UMBRA_RENDERER_ATLAS_H
#define UMBRA_RENDERER_ATLAS_H

#include <stdbool.h>
#include <stdint.h>

struct rnd_tile {
	uint32_t x, y, size;   /* texels */
	uint32_t node;         /* quadtree node index (for free) */
};

struct rnd_atlas {
	uint32_t size, min_tile, levels;
	uint8_t *state;        /* per node: 0 free, 1 split, 2 used */
	uint32_t node_count;
	uint64_t used_texels;
	uint32_t used_tiles;
};

/* size and min_tile powers of two, min_tile <= size, size / min_tile <= 2048 (12 levels).
 * False when out of memory or the sizes break those rules. */
bool rnd_atlas_init(struct rnd_atlas *a, uint32_t size, uint32_t min_tile);
void rnd_atlas_release(struct rnd_atlas *a);
/* A free tile of exactly `size` texels (a power of two between min_tile and the atlas size). */
bool rnd_atlas_alloc(struct rnd_atlas *a, uint32_t size, struct rnd_tile *out);
void rnd_atlas_free(struct rnd_atlas *a, const struct rnd_tile *t);
/* Share of the atlas's texels in used tiles, 0..1. */
double rnd_atlas_occupancy(const struct rnd_atlas *a);

/* The side of each of n maps' tiles in an atlas of `atlas` texels a side, a function of the maps
 * alone (not of what the atlas holds or what other renders use), so the same request always
 * draws the same maps: map k wants tiles[k] tiles of want[k] texels; each is clamped to
 * min_tile..atlas, then the largest (the first of equals) halved until all tiles together fit
 * in the atlas. False when even min_tile tiles do not fit. The render plan sizes every map by
 * it (render_plan.c); the shadow cache grants those sizes. */
bool rnd_atlas_fit(const uint32_t *tiles, const uint32_t *want, uint32_t n, uint32_t atlas, uint32_t min_tile,
                   uint32_t *res);

#endif
