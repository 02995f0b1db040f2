/*
 * api/model_caster — the coarse caster level of a dense opaque mesh: what the environment's
 * shadow maps draw instead of the mesh (struct rnd_caster_level; renderer/caster_level.h says
 * where and with what bias).
 *
 * Why: the thumbnail preset lights by the studio environment, whose 12 shadow directions each
 * draw a PCSS map of 128-256 texels a side (renderer/env_shadow.c). Those maps are soft: they
 * cannot show detail finer than a few of their texels, yet every one of them drew every triangle
 * the camera draws (a closed 100k-triangle sphere: 1.2M depth-only triangles, mostly under a
 * texel, 1.1 s of a 1.4 s first request on lavapipe).
 *
 * What: meshoptimizer's meshopt_simplifySloppy (vertex clustering: fast, positions only, so
 * attribute seams do not matter) of the mesh welded by position, to API_CASTER_TRIANGLES, its
 * vertices compacted. Its error is measured both ways (api_caster_error): the largest distance
 * of the coarse surface from the full one and of the full one from the coarse one, sampled on a
 * lattice and bounded by the lattice's covering radius, so the bound holds between samples too.
 * A mesh built once at import, whatever size of image it is drawn at (the maps' sizes do not
 * follow the image's).
 *
 * When (api_mesh_wants_caster): API_CASTER_MIN_TRIANGLES or more, its material opaque (a masked
 * or blended one's depth pass reads its texture: the full path), and the coarse level saving
 * three quarters of the triangles. glTF skins are dropped at import (api/gltf_decode.c), so no
 * mesh moves after it; vertex colours and tangents do not reach a depth pass.
 *
 * Threading: touches only the mesh it is given. Memory: the level in the model's arena; malloc'd
 * scratch of the mesh's size while measuring (the importer's limits bound both).
 */
#ifndef UMBRA_API_MODEL_CASTER_H
#define UMBRA_API_MODEL_CASTER_H

#include <stddef.h>
#include <stdint.h>
#include "arena.h"
#include "model.h"

/* Triangles the level is simplified to. The maps are 128-256 texels a side over the casters'
 * box; a closed mesh shows about half its triangles to a map, over ~50k texels of a 256 map:
 * 8192 triangles are ~12 texels each, where lavapipe's cost per triangle (a 4x4 block at least)
 * no longer dominates the map's. */
#define API_CASTER_TRIANGLES 8192u
/* Meshes with fewer triangles draw whole: a level would save too little. */
#define API_CASTER_MIN_TRIANGLES (4u * API_CASTER_TRIANGLES)

/* Whether mesh me of model m gets a caster level: enough triangles, an opaque material, and no
 * camera level (me->lods, built first) under API_CASTER_MIN_TRIANGLES: the farm corpus's 100k
 * meshes with a ~27k level ran 5.2-5.8 -> 3.8-4.7 images/s with the caster built for them too
 * (its import cost more than their maps saved); the level-less ones (a bumpy sphere) are where
 * the maps drew 1.2M triangles. */
bool api_mesh_wants_caster(const struct api_model *m, const struct api_model_mesh *me);

/* Builds me->caster from the mesh welded by position (idx[0..ni) into pos[0..nv), the weld the
 * closedness check made) into arena, adding its size to *bytes; leaves it NULL when
 * simplification does not save three quarters of the triangles or memory runs out (the full
 * mesh is always correct, only slower). */
void api_caster_build(struct api_model_mesh *me, const uint32_t *idx, size_t ni, const float *pos, size_t nv,
                      struct api_arena *arena, size_t *bytes);

/* A bound on the distance between the surfaces of triangles a (na indices into pa) and b (nb
 * into pb), both ways: every point of either lies within it of the other. Each side's vertices
 * must all be named by its indices (a welded or compacted mesh). spacing: the lattice's step on
 * triangles longer than it (each triangle adds how far its points can be from its samples, at
 * most its lattice step / sqrt(3)); INFINITY when memory runs out or a side has no triangle. */
float api_caster_error(const uint32_t *ia, size_t na, const float *pa, const uint32_t *ib, size_t nb, const float *pb,
                       float spacing);

#endif
