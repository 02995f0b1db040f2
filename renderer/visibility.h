/*
 * renderer/visibility.h — the visibility pass: each shadowed light's shadow at the surface each
 * pixel shows, computed once per pixel before the main pass, which then reads it instead of
 * filtering the shadow maps itself (see visibility.c for why and when).
 *
 * Usage: the render plan decides per view whether it runs (visibility_plan.h); render.c sizes the slot's images
 * (rnd_slot_visibility: a layer per light, umbra_shared.h UMBRA_BINDING_VISIBILITY) and binds
 * them (rnd_frame_write); submit.c records
 * record_visibility() for each band just before record_main(). No state of its own; the
 * images belong to the slot, the pipelines to the context.
 */
#ifndef UMBRA_RENDERER_VISIBILITY_H
#define UMBRA_RENDERER_VISIBILITY_H

#include "record.h"
#include "visibility_plan.h"

/* Where the surfaces pass draws: world positions (RND_SURFACES_FORMAT, w 1 where drawn, 0 else)
 * and geometric normals (RND_SURFACE_NORMALS_FORMAT) of what each pixel centre of the targets
 * shows, and their depth; the view fills a viewport of width x height of them (the view's own
 * size, or a coarser grid: env_pass.c). */
struct rnd_surface_targets {
	const struct rnd_image_res *positions, *normals, *depth;
	float width, height;
	const struct rnd_image_res *shading;   /* pixel shading's inputs too (deferred.c), or NULL */
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
