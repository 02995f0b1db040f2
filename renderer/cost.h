/*
 * renderer/cost — the cost model of the deadline's bands: how many milliseconds a shadow map
 * and a row of the main pass are estimated to take, which the render plan holds for each view
 * (render_plan.c) and the submit pacer sizes its first band and its shadow submits by
 * (renderer/submit.c); and how many fragments a draw may rasterise into a view, the part of
 * the model that depends on how much of the image the geometry covers.
 *
 * Why: the submit pacer sized its first band and its shadow submits from pixels and triangle
 * counts alone, as if every pixel were covered once. A scene of 400 boxes stacked in one place
 * (55 KB of JSON) then ran its whole main pass as one 10 s submit past a 3 s deadline, and a
 * mesh of big overlapping triangles one shadow map of 100+ s: the deadline is checked only
 * between submits. A draw's world-space triangle area, projected, says what it covers.
 *
 * Pure (no Vulkan); unit-tested in tests/unit/test_cost.c.
 */
#ifndef UMBRA_RENDERER_COST_H
#define UMBRA_RENDERER_COST_H

#include <stdbool.h>
#include <stdint.h>
#include "draw.h"
#include "plan.h"
#include "umbra/rnd_math.h"

/* About how many fragments `tris` triangles of world-space area `area` inside bounds b
 * rasterise into a view of vp_w x vp_h pixels with clip matrix view_proj (column-major, Vulkan
 * clip space): area times the projection's area scale over b's depths, at most every triangle
 * covering all of b's pixels in the view (the cap a box reaching behind the eye gets), or for a
 * closed surface twice them; 0 for a box outside the view. */
double rnd_cost_fill(const float view_proj[16], double vp_w, double vp_h, const struct rnd_aabb *b, double area,
                     uint64_t tris, bool closed);

/* How many layers deep the cost model's per-pixel calibration already is (a closed mesh's
 * front and back over a ground; the thumbnails count 3.3): the main pass's per-row estimate grows only with the layers
 * beyond these (rnd_cost_layer_factor). */
#define RND_COST_LAYERS_CALIBRATED 4.0

/* The factor a view's per-pixel estimate takes for `fill` fragments over w x h pixels. */
double rnd_cost_layer_factor(double fill, double w, double h);

/* Shadow view v of sp (drawn at its rect[2] texels a side) for the casters rnd_shadow_view_draws
 * says it draws of draws[ndraw] (lights: sp's): its triangles (*tris) and its milliseconds. */
double rnd_cost_shadow_view_ms(const struct rnd_shadow_plan *sp, const struct rnd_light *lights,
                               const struct draw *draws, uint32_t ndraw, uint32_t v, uint64_t *tris);
/* Shading work per pixel of a view of sc (sp its shadow plan; vis: its shadows from the
 * visibility pass; aov_passes its AOV passes), in units of a hard-shadowed light's. */
double rnd_cost_pixel_units(const struct rnd_scene *sc, const struct rnd_shadow_plan *sp, bool vis, uint32_t aov_passes);
/* The main pass of a view (view_proj its camera's; draws as the camera draws them; units its
 * rnd_cost_pixel_units): milliseconds per row (*row_ms) and per band whatever its rows
 * (*fixed_ms: the vertex work every band repeats). */
void rnd_cost_main(const struct rnd_scene *sc, const float view_proj[16], const struct draw *draws, uint32_t ndraw,
                   double units, double *row_ms, double *fixed_ms);

#endif
