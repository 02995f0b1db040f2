/*
 * renderer/visibility.h — the visibility pass: each shadowed light's shadow at the surface each
 * pixel shows, computed once per pixel before the main pass, which then reads it instead of
 * filtering the shadow maps itself (see visibility.c for why and when).
 *
 * Usage: render.c asks rnd_visibility_wanted() per view, sizes the slot's images
 * (rnd_slot_visibility: a layer per light, umbra_shared.h UMBRA_BINDING_VISIBILITY) and binds
 * them (rnd_frame_write); submit.c records
 * record_visibility() for each band just before record_main(). No state of its own; the
 * images belong to the slot, the pipelines to the context.
 */
#ifndef UMBRA_RENDERER_VISIBILITY_H
#define UMBRA_RENDERER_VISIBILITY_H

#include "record.h"

/* Whether a view of sc (its draws, its shadow plan sp) takes its shadows from the visibility
 * pass: UMBRA_VISIBILITY=0 / 1 forces it off / on (tests, comparisons) where the device and
 * the scene allow it at all. */
bool rnd_visibility_wanted(const struct rnd_context *ctx, const struct rnd_scene *sc, const struct rnd_shadow_plan *sp,
                           const struct draw *draws, uint32_t ndraw);
/* The bytes of the slot's images the pass would take for a view of sc, 0 where it cannot run
 * at all (no shadowed light, a debug view, a view too large): what a render may need beyond
 * its targets (estimate.c counts it, before the plan says whether the pass runs). */
uint64_t rnd_visibility_bytes(const struct rnd_scene *sc);
/* Where the surfaces pass draws: world positions (RND_SURFACES_FORMAT, w 1 where drawn, 0 else)
 * and geometric normals (RND_SURFACE_NORMALS_FORMAT) of what each pixel centre of the targets
 * shows, and their depth; the view fills a viewport of width x height of them (the view's own
 * size, or a coarser grid: env_pass.c). */
struct rnd_surface_targets {
	const struct rnd_image_res *positions, *normals, *depth;
	float width, height;
};
/* Draws rv's surfaces over area (rows of the targets) into t, left ready for sampling (the depth
 * as a read-only attachment). */
void record_surfaces(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, VkRect2D area,
                     const struct rnd_surface_targets *t);
/* The surfaces and visibility passes over rv's band (record_band_area), leaving both images
 * ready for sampling by the main pass. */
enum rnd_result record_visibility(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                  struct rnd_error *err);

#endif
