/*
 * renderer/lod — level of detail of the analytic shapes from screen-space error.
 *
 * A sphere or cylinder asked for with `segments` S is tessellated with
 *   min(S, N),  N = the fewest (even) segments whose chords stay within RND_LOD_PIXEL_ERROR of a
 *               pixel of the true surface in every view of the request, and within
 *               RND_LOD_TEXEL_ERROR of a texel in every shadow map the request renders
 * (a chord of a circle of radius r over 2*pi/N lies r * (1 - cos(pi/N)) inside the arc at its
 * middle; when N < S the radius is raised so that the chords straddle the arc, half that
 * inside and half outside, see rnd_lod_radius).
 * Asking for more segments than the output can show costs time and changes nothing visible;
 * asking for fewer is honoured exactly. A mesh with simplified levels (rnd_object.lods, built
 * for imported models by api/model_lod.c) is drawn with the coarsest level whose measured error
 * stays within RND_LOD_MESH_PIXEL_ERROR in every view (the shadow passes draw that level too). Boxes, planes and other
 * meshes are not touched.
 *
 * Usage: render.c calls rnd_lod_choose() before tessellating; the rest are the pure pieces it
 * is made of (unit-tested in tests/unit/test_lod.c). No Vulkan, no allocation, thread-safe.
 */
#ifndef UMBRA_RENDERER_LOD_H
#define UMBRA_RENDERER_LOD_H

#include <stdint.h>
#include "plan.h"

/* Error bounds, measured (docs/performance.md): with 1/8 pixel the silhouettes of thumb-512
 * were visibly less well anti-aliased than MSAA 4 at full detail against a 4x4-supersampled
 * render (edge error 0.0104 against 0.0088); 1/32 pixel matches it within noise and costs the
 * same on lavapipe (the triangles are no longer what the pass pays for). 1/8 texel is well
 * below the 3x3 PCF footprint and the map's own nearest-texel quantisation. */
#define RND_LOD_PIXEL_ERROR 0.03125f
#define RND_LOD_TEXEL_ERROR 0.125f
/* Meshes: a level's error is its measured largest distance from the full mesh
 * (api/model_lod.c), reached at a few of meshoptimizer's long triangles, and its normals are
 * recomputed, so the image changes more than the bound alone says. Measured on a 100k-triangle
 * STL sphere in a 512-pixel thumbnail (edge error against a 4x4-supersampled full render): full
 * 0.0066, 1/4 pixel 0.0066 (no level fits), 1/2 pixel 0.0087, 1 pixel 0.0107. */
#define RND_LOD_MESH_PIXEL_ERROR 0.5f
/* No bound of its own in the lights' shadow maps (0): a mesh casts with the level the cameras
 * chose. A caster's error moves its shadow's edge by about as much, which the camera sees at its
 * own pixel scale, and one level in every pass keeps a mesh's shadow on itself consistent. Half
 * a texel of the 2048^2 map had a 100k-triangle model drawn in full in a 256^2 thumbnail (main
 * pass 290 ms against 22 with the camera's level). The environment's maps are the exception:
 * soft (PCSS at 64-512 texels), they draw a dense mesh's caster level where its error fits 4 of
 * their texels, with their bias raised by that error (renderer/caster_level.h). */
#define RND_LOD_MESH_TEXEL_ERROR 0.0f

/* Fewest segments (even, >= 4) for a circle of radius `radius` whose centred chords deviate at
 * most `max_error` (same units) from it; UINT32_MAX when max_error <= 0 or radius is not finite. */
uint32_t rnd_lod_circle_segments(float radius, float max_error);

/* Largest deviation from the circle of radius `radius` of a polygon of `segments` centred
 * chords (rnd_lod_radius): half the sagitta r (1 - cos(pi / segments)). */
float rnd_lod_chord_error(float radius, uint32_t segments);

/* World size of one pixel (width x height pixels across clip space) of view_proj at the point
 * of the sphere (centre, radius) nearest the viewer; for an orthographic view_proj it is the
 * same everywhere. A sphere reaching behind near (w <= near_w) gets the size at near_w. */
float rnd_lod_pixel_world(const float view_proj[16], float width, float height, const float centre[3], float radius,
                          float near_w);

/* Segments object o is tessellated with, given the world size of a pixel / texel at it and the
 * error bound in those units: min(o->segments, what the bound needs). Other shapes: o->segments. */
uint32_t rnd_lod_object_segments(const struct rnd_object *o, float pixel_world, float error_pixels);

/* Radius to tessellate a circle of `radius` with when `segments` is fewer than the `asked`:
 * scaled so that the chords straddle the circle (vertices outside by half the chord error,
 * chord middles inside by as much) instead of all lying inside it, which would shrink every
 * silhouette by the whole error. As asked (no LOD): radius unchanged. */
float rnd_lod_radius(float radius, uint32_t segments, uint32_t asked);

/* Level of a mesh with levels (o->lods) that a pixel of pixel_world and a bound of
 * error_pixels allow: the coarsest whose error (scaled to world) stays within the bound;
 * 0 = the full mesh, k = o->lods[k - 1]. Other objects: 0. */
uint32_t rnd_lod_mesh_level(const struct rnd_object *o, float pixel_world, float error_pixels);

/* Makes o the object rnd_lod_choose()'s entry `lod` for it says: a sphere / cylinder with lod
 * segments (and rnd_lod_radius), a mesh with level lod (0: unchanged). */
void rnd_lod_apply(struct rnd_object *o, uint32_t lod);
/* The level rnd_lod_choose gave object o (lod: segments, or a mesh's level), in words. */
const char *rnd_lod_detail(const struct rnd_object *o, uint32_t lod);

/* Fills segments[i] for every object of the scene (nviews views of width x height, scratch for
 * the shadow plans): segments for spheres and cylinders, the level for meshes with levels
 * (rnd_lod_apply() takes either). Estimates the scene bounds from the shapes without tessellating. On a plan
 * failure every object keeps its requested segments (the render reports the failure later). */
void rnd_lod_choose(const struct rnd_scene *sc, uint32_t nviews, struct rnd_shadow_plan *scratch,
                    uint32_t *segments);

/* Fills proxies[i] for every object of the scene (rnd_proxy_plan, renderer/proxy.h: a sphere
 * the one camera of the request sees from a given position, tessellated with segments[i] by
 * rnd_lod_choose()); zeroed (none) for the rest and for renders of several views. */
struct rnd_proxy;
void rnd_lod_proxies(const struct rnd_scene *sc, uint32_t nviews, const uint32_t *segments, struct rnd_proxy *proxies);

/* World bounds of object i as asked: an analytic shape's own (a sphere of its radius, not the
 * radius a coarser tessellation raises, rnd_lod_radius), a mesh's `drawn` bounds (its levels
 * keep a subset of its vertices, so they reach no further) or, when drawn is NULL, those of
 * its vertices (one pass over them). */
void rnd_object_bounds(const struct rnd_scene *sc, uint32_t i, const struct rnd_aabb *drawn, struct rnd_aabb *out);

#endif
