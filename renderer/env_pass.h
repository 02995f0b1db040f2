/*
 * renderer/env_pass.h — the environment pass: the environment map's shadows computed once per
 * texel of a grid coarser than the view (rnd_env_pass_scale; env_pass.c says why), which
 * the main pass reads back with a bilateral upsample (shaders/ibl.glsl env_pass_read).
 *
 * Usage: the render plan asks rnd_env_pass_wanted() (env_shadow.h) per view; render.c sizes the slot's images
 * (rnd_slot_env_pass); rnd_frame_write binds them (or the slot's white stand-ins); submit.c
 * records record_env_pass() once per view, after the shadow maps and before the first band.
 * The images belong to the slot, the pipeline to the context.
 */
#ifndef UMBRA_RENDERER_ENV_PASS_H
#define UMBRA_RENDERER_ENV_PASS_H

#include "record.h"

/* The view's pixels per texel of the pass's grid, a side: UMBRA_ENV_PASS_SCALE (2), more for
 * views larger than RND_ENV_PASS_GRID texels a side at that scale, at most RND_ENV_PASS_MAX_SCALE. */
#define RND_ENV_PASS_GRID 192u
#define RND_ENV_PASS_MAX_SCALE 4u
uint32_t rnd_env_pass_scale(uint32_t w, uint32_t h);
/* The pass's grid for a w x h view: ceil(w / scale) x ceil(h / scale). */
void rnd_env_pass_size(uint32_t w, uint32_t h, uint32_t *pw, uint32_t *ph);
/* Makes the slot's pass images match a w x h view. */
enum rnd_result rnd_slot_env_pass(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h,
                                  struct rnd_error *err);
void rnd_env_pass_release(struct rnd_context *ctx, struct rnd_slot *s);
/* What the pass of view rv computes from, hashed (never 0), after rnd_frame_write wrote the
 * view's constants and the upload its geometry: the constants (camera, lights, shadow views
 * with their atlas rectangles, the environment's directions and weights), the atlas's maps by
 * their cache keys (a key names a map's contents: shadow_keys.h), the geometry the surfaces
 * pass draws (the slot's vertex and index bytes, the draws) and the grid's size. The slot's
 * images hold the pass of equal inputs where s->env_pass_key equals it: a request that comes
 * back (the same model, transform, environment and camera) draws neither the surfaces nor
 * the visibility again (~17 ms of a 256² thumbnail on lavapipe). */
uint64_t rnd_env_pass_key(const struct rnd_slot *s, const struct record_view *rv, const uint64_t *map_keys,
                          uint32_t nmaps, uint64_t vertex_bytes, uint64_t index_bytes);
/* The surfaces at the pass's scale, then the visibility pass over them, left ready for sampling. */
enum rnd_result record_env_pass(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                struct rnd_error *err);

#endif
