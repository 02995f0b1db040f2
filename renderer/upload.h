/*
 * renderer/upload.h — tessellation into the slot's buffers (see upload.c), called by render.c
 * once per render before anything is recorded.
 *
 * Threading: the slot is the caller's; its vertex and index buffers are grown (after their last
 * fence: nothing of the slot is in flight while it is held) and written through their mapping.
 */
#ifndef UMBRA_RENDERER_UPLOAD_H
#define UMBRA_RENDERER_UPLOAD_H

#include "submit.h"

/* Tessellates every object (at level lod[i], renderer/lod.h) into the slot's buffers, and after
 * a sphere's mesh its camera's proxy where proxies[i] has one (renderer/proxy.h); fills
 * draws[0..object_count) and the scene bounds. Checks the pacer's deadline as it goes: a
 * scene of millions of triangles takes seconds. */
struct rnd_proxy;
enum rnd_result rnd_upload_scene(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                 const struct rnd_pacer *pacer, const uint32_t *lod, const struct rnd_proxy *proxies,
                                 struct draw *draws, struct rnd_aabb *bounds, struct rnd_error *err);

#endif
