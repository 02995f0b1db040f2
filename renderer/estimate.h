/*
 * renderer/estimate.h — sizes a render needs, computed from the scene alone before anything is
 * allocated (see estimate.c). Pure arithmetic; thread-safe.
 */
#ifndef UMBRA_RENDERER_ESTIMATE_H
#define UMBRA_RENDERER_ESTIMATE_H

#include "internal.h"

/* AOV passes (each UMBRA_AOV_ATTACHMENTS RGBA32F targets) the scene's output.aovs need. */
uint32_t rnd_aov_passes(const struct rnd_scene *sc);
/* Bytes per pixel of an output pixel format (RGBA8 4, RGBA16 8, RGBA32F 16). */
uint64_t rnd_pixel_bytes(enum rnd_pixel_format f);
/* Float planes the scene's output.aovs make (Z 1, N 3, albedo 3, shadow one per light). */
uint32_t rnd_aov_planes(const struct rnd_scene *sc);
/* The estimate for a context whose atlas is atlas_size texels a side. */
void rnd_estimate_scene(const struct rnd_scene *sc, uint32_t atlas_size, struct rnd_estimate *e);
/* RND_ERR_LIMIT (at the AOVs, the views or the size) when one allocation would be over the
 * device's maxMemoryAllocationSize. */
enum rnd_result rnd_check_allocation(const struct rnd_context *ctx, const struct rnd_scene *sc,
                                     const struct rnd_estimate *e, struct rnd_error *err);

#endif
