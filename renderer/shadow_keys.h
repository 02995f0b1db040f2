/*
 * renderer/shadow_keys.h — the keys cached shadow maps are found by (see shadow_keys.c): a map
 * that does not follow the camera (a spot or point light's, a sun's `fit` map) is kept in the
 * atlas under a hash of everything that shapes it, and a later request whose map has the same
 * key reuses it instead of drawing it (shadow_cache.c). The render plan makes the keys
 * (render_plan.c) and says which maps the cache holds. Pure: no Vulkan, thread-safe.
 */
#ifndef UMBRA_RENDERER_SHADOW_KEYS_H
#define UMBRA_RENDERER_SHADOW_KEYS_H

#include "draw.h"
#include "plan.h"

/* What every map's key starts from: the casters' geometry as the scene gives it (each caster's
 * shape and level of detail lod[i], its model matrix, a mesh's positions and indices), their
 * culling and alpha masks (with what the alpha test reads: texture coordinates, vertex colours,
 * the material's alpha and base colour texture), and the scene bounds (the maps' far planes). */
uint64_t rnd_caster_key(const struct rnd_scene *sc, const struct draw *draws, const uint32_t *lod,
                        const struct rnd_aabb *bounds);

/* The key of light i's maps (lp its plan, views[lp->first_view..] where they look, before the
 * atlas places them): the casters' key, the light's type, filter, bias, resolution, moments'
 * settings and its views. Never 0 (0 is "not cacheable"). */
uint64_t rnd_map_key(uint64_t casters, const struct rnd_light *L, const struct rnd_light_plan *lp,
                     const struct umbra_shadow_view *views);

#endif
