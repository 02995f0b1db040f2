/*
 * api/model_lod — simplified levels of an imported model's dense meshes (meshoptimizer), so
 * that the renderer can draw a million-triangle model in a thumbnail with the triangles the
 * thumbnail can show (renderer/lod.h picks the level from pixel and shadow-texel size).
 *
 * Usage: api/model.c calls api_model_build_lods() once per imported model, before the model
 * is shared (cached); the levels live in the model's arena and are immutable afterwards.
 * Threading: touches only the model it is given.
 */
#ifndef UMBRA_API_MODEL_LOD_H
#define UMBRA_API_MODEL_LOD_H

#include <stddef.h>
#include "arena.h"
#include "model.h"

/* Meshes with fewer triangles are left alone: drawing them costs less than choosing. */
#define API_LOD_MIN_TRIANGLES 20000u

/* Builds the levels of every mesh of m with at least API_LOD_MIN_TRIANGLES triangles into
 * arena; adds their size to *bytes. A level that cannot be built (out of memory) ends that
 * mesh's list: fewer levels are always correct, only slower. Also sets each mesh's `bounds`
 * (min and max of its positions) and `closed`:
 * welded by position, every edge is shared by exactly two triangles that run it in opposite
 * directions, and the enclosed volume is positive (wound outward), so the renderer may cull
 * back faces when the camera is outside it. Out of memory: not closed. */
void api_model_build_lods(struct api_model *m, struct api_arena *arena, size_t *bytes);

/* Whether triangles idx (ni indices into pos) close a volume wound outward; pure. Triangles
 * with a repeated index are left out. */
bool api_mesh_closed(const uint32_t *idx, size_t ni, const float *pos);

/* The relative error (fraction of the mesh's extent) each level is simplified to; pure. */
float api_lod_level_error(unsigned level);
#define API_LOD_LEVELS 8u

#endif
