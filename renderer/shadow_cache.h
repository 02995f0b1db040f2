/*
 * renderer/shadow_cache.h — the persistent shadow atlases and what lives in them.
 *
 * The context owns one depth atlas (D32) and one moment atlas (two channels, fp32 where the
 * device filters it, else fp16), both atlas_size² texels, and the depth bounds of the depth
 * atlas for PCSS (two RGBA32F texels per UMBRA_BOUNDS_BLOCK² block, umbra_shared.h), created
 * at start-up and kept in GENERAL layout for the life of the process. Every shadow view of every render is a square
 * tile of these atlases (atlas.c hands them out):
 *   - maps that do not follow the camera (spot and point lights, a sun's `fit` map) get cached
 *     entries keyed by a hash of everything that shapes them (caster geometry, the light's view
 *     matrices, resolution, bias, filter settings); a later request with the same key reuses
 *     the tiles and skips their shadow passes;
 *   - cascades and clipmap levels get transient tiles (they follow the camera), freed at the
 *     end of the render.
 * A request's tile sizes are planned against the whole atlas (largest halved first, never below
 * 64: rnd_atlas_fit, by the render plan), so they never depend on the cache's history;
 * unreferenced entries are evicted oldest first to make room, and a request that does not fit
 * next to other running renders waits for them: shadows are never dropped.
 *
 * Threading: every call takes the cache mutex. An entry in use by a render (refs > 0) is
 * never evicted; a new entry is only visible to other renders after its render completed
 * (rnd_cache_release with ok = true), so no render reads a tile another is writing.
 */
#ifndef UMBRA_RENDERER_SHADOW_CACHE_H
#define UMBRA_RENDERER_SHADOW_CACHE_H

#include "atlas.h"
#include "internal.h"

struct rnd_cache_request {
	uint64_t key;         /* 0 = not cacheable (transient) */
	uint32_t tiles;       /* 1, or 6 for a point light, or the cascade / level count */
	uint32_t res;         /* tile size (a power of two the plan fitted in the atlas: rnd_atlas_fit) */
};

struct rnd_cache_grant {
	uint32_t entry;       /* index for rnd_cache_release */
	struct rnd_tile tile[8];
	uint32_t res;         /* granted: the request's */
	bool hit;             /* tiles already hold this key's maps: skip their passes */
};

enum rnd_result rnd_cache_init(struct rnd_context *ctx, struct rnd_error *err);
void rnd_cache_release_all(struct rnd_context *ctx);
/* Grants tiles for n requests at once (all or none), each at the size it asks (the plan fitted
 * them all in the atlas, rnd_atlas_fit, so the same request always gets the same resolutions);
 * a hit is a completed map of the same key at that resolution. When maps of other running
 * renders leave no room, waits for them to finish, until `deadline` (CLOCK_MONOTONIC seconds,
 * 0 = no limit: RND_ERR_TIMEOUT). RND_ERR_LIMIT (at RND_AT_LIGHTS) only when the requests do not
 * fit in the atlas even alone. */
enum rnd_result rnd_cache_acquire(struct rnd_context *ctx, const struct rnd_cache_request *req, uint32_t n,
                                  double deadline, struct rnd_cache_grant *out, struct rnd_error *err);
/* Whether a completed map of this key, with `tiles` tiles of res texels, is in the atlas now
 * (what the render plan says of each map: a later grant may find it gone, or made meanwhile). */
bool rnd_cache_probe(struct rnd_context *ctx, uint64_t key, uint32_t tiles, uint32_t res);
/* Wakes every render waiting for room (after the context failed: they return
 * RND_ERR_DEVICE_LOST instead of waiting for tiles a lost render never gives back). */
void rnd_cache_wake(struct rnd_context *ctx);
/* Ends a render's use: ok = the render completed, so new entries become reusable. */
void rnd_cache_release(struct rnd_context *ctx, const struct rnd_cache_grant *g, uint32_t n, bool ok);


#endif
