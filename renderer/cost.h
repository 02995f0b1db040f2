/*
 * renderer/cost — how many fragments a draw may rasterise into a view: the part of the cost
 * model (renderer/submit.c) that depends on how much of the image the geometry covers.
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

#endif
