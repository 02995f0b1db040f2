/*
 * api/ground — world bounds of scene objects, and the ground plane that places itself.
 *
 * Usage (api/scene_objects.c, after models are expanded into mesh objects):
 *   float margin[n];   // > 0 for each plane object with "placement": "ground", else 0
 *   api_ground_place(objects, n, materials, margin);
 *
 * A ground plane is centred under the other objects' world bounds (x, z), sits just below their
 * lowest point (min y less API_GROUND_GAP × the largest extent of those bounds: resolvable in
 * depth, so a model's own flat bottom is drawn, not the ground through it) and is a square of
 * side margin × that extent. "Other
 * objects" are those the camera's `fit: "objects"` frames: every object except planes and shadow
 * catchers; when none is left (only planes), the ground sits at y = 0 under the origin with
 * side = margin. The bounds are exact per shape under any transform (a box by its corners, a
 * sphere or cylinder by its extent along each axis, a mesh by its transformed vertices), so a
 * rotated or scaled object stands on the plane rather than floating above it.
 *
 * Pure code (no jansson, no Vulkan): tested in tests/unit/test_ground.c. Thread-safe.
 */
#ifndef UMBRA_API_GROUND_H
#define UMBRA_API_GROUND_H

#include <stdint.h>
#include "umbra/rnd.h"

#define API_GROUND_GAP 1e-4

/* Grows [lo, hi] by the object's exact world-space bounds (its model matrix applied). */
void api_object_bounds(const struct rnd_object *o, double lo[3], double hi[3]);

/* Places every object i with margin[i] > 0 (which must be a RND_SHAPE_PLANE) as the ground of
 * the others: its model matrix becomes a translation to the bounds' base and its size the side.
 * mats may be NULL (no object is then a shadow catcher). */
void api_ground_place(struct rnd_object *objs, uint32_t n, const struct rnd_material *mats, const float *margin);

#endif
