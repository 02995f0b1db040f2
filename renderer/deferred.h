/*
 * renderer/deferred.h — pixel shading: a view whose surfaces are dense and plain is shaded once
 * per pixel centre, and its samples take those colours, instead of once per fragment.
 *
 * Why: lavapipe runs the fragment shader for a whole 4x4 block per triangle touching it, and
 * with MSAA for every triangle covering any sample of it. A 100k-triangle model in a 256^2
 * thumbnail ran the full shading (and the visibility pass's look-up of its pixel) ~6 times a
 * pixel: 970 M instructions a render under callgrind, 610 M of them in the main pass's shader.
 *
 * How (with the visibility pass, renderer/visibility.c, whose passes it extends):
 *  1. surfaces (single-sample): position and triangle plane as always, and the shading inputs
 *     (interpolated normal, vertex colour, material, draw flags: shaders/surface_shade.frag);
 *  2. the visibility pass's fullscreen triangle shades each pixel centre with the main pass's own
 *     function (shaders/shade.glsl, from vis_shade.frag), shadows filtered there, into an image
 *     of the output's colour format;
 *  3. the main pass draws depth only, MSAA 4 (no fragment shader);
 *  4. a resolve (shaders/resolve.frag) gives each sample the colour of the pixel centre, its own
 *     or a 4-neighbour's, whose triangle plane passes nearest to the sample's depth, and writes
 *     the mean of the four: what the MSAA resolve of per-fragment shading gives inside surfaces
 *     and, along silhouettes, the colour of the surface each sample shows, shaded at the nearest
 *     pixel centre that shows it.
 *
 * When (visibility_plan.c rnd_pixel_shading_wanted, the render plan's decision): the view runs the visibility pass (dense triangles, wide shadow
 * filters) or is lit by an environment map over dense triangles (one face per 16 pixels: the
 * thumbnail preset's studio), MSAA 4, no debug view, no environment map as the background, and
 * every draw is plain: opaque, no texture (vertex colours are fine), no glTF material extension
 * lobe (clearcoat, sheen, specular, spec-gloss: the forward path draws those), not an analytic
 * sphere's proxy. The environment's light and shadows are shade.glsl's, as per fragment. UMBRA_PIXEL_SHADING=0 / 1 forces it off / on where
 * the device and the scene allow it. No state of its own; the images belong to the slot
 * (rnd_slot_pixel_shading), the pipelines to the context.
 */
#ifndef UMBRA_RENDERER_DEFERRED_H
#define UMBRA_RENDERER_DEFERRED_H

#include "record.h"

/* Whether the device can: standard sample locations (resolve.frag assumes them), a sampled
 * 4-sample depth image, RGBA32UI colour attachments that can be sampled. Once, at create. */
bool rnd_deferred_supported(struct rnd_context *ctx);
/* The main pass of a pixel-shaded band (after record_visibility): depth only, MSAA 4, then the
 * resolve into the slot's colour target, left as record_main leaves it for the readback. */
enum rnd_result record_deferred_main(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                     struct rnd_error *err);

#endif
