/*
 * renderer/estimate.h — sizes a render needs, computed from the scene alone before anything is
 * allocated (see estimate.c): the sheet its views are laid out on and where everything lies in
 * the readback buffer, the AOV passes, and the memory estimate the render plan carries
 * (render_plan.h) for admission. Pure arithmetic, no Vulkan; thread-safe.
 */
#ifndef UMBRA_RENDERER_ESTIMATE_H
#define UMBRA_RENDERER_ESTIMATE_H

#include <stddef.h>
#include "umbra/rnd.h"

/* The views' sheet and where everything lies in the slot's readback buffer. */
struct rnd_sheet {
	uint32_t views, cols, rows;
	uint64_t width, height;       /* pixels of the whole sheet */
	size_t px;                    /* bytes of one colour pixel */
	uint32_t passes;              /* AOV passes (0 = no AOVs) */
	uint64_t color_bytes;         /* the colour sheet, at offset 0 */
	uint64_t att_bytes;           /* one RGBA32F AOV attachment of the sheet, after the colour */
	uint64_t readback_bytes;      /* all of it */
};

/* The sheet of scene sc (which passed validation). */
void rnd_sheet_init(struct rnd_sheet *sh, const struct rnd_scene *sc);
/* AOV passes (each UMBRA_AOV_ATTACHMENTS RGBA32F targets) the scene's output.aovs need. */
uint32_t rnd_aov_passes(const struct rnd_scene *sc);
/* Bytes per pixel of an output pixel format (RGBA8 4, RGBA16 8, RGBA32F 16). */
uint64_t rnd_pixel_bytes(enum rnd_pixel_format f);
/* Float planes the scene's output.aovs make (Z 1, N 3, albedo 3, shadow one per light). */
uint32_t rnd_aov_planes(const struct rnd_scene *sc);
/* The estimate for a context whose atlas is atlas_size texels a side. */
void rnd_estimate_scene(const struct rnd_scene *sc, uint32_t atlas_size, struct rnd_estimate *e);
/* RND_ERR_LIMIT (at the AOVs, the views or the size) when one allocation would be over
 * max_allocation, the device's maxMemoryAllocationSize (0: no limit). */
enum rnd_result rnd_check_allocation(uint64_t max_allocation, const struct rnd_scene *sc, const struct rnd_estimate *e,
                                     struct rnd_error *err);

#endif
