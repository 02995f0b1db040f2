/*
 * api/model_lod — a simplified level of an imported model's dense meshes (meshoptimizer), so
 * that the renderer can draw a million-triangle model in a thumbnail with the triangles the
 * thumbnail can show (renderer/lod.h draws it where its measured error fits the camera's
 * pixel, else the full mesh).
 *
 * When: one level per size of image (the largest side of a request's images, api_limits.
 * output_side), for a mesh of API_LOD_MIN_TRIANGLES or more. The importer builds the one its
 * request needs, in its sandbox and under its limits (api_model_finish_import); a cached model
 * drawn at another size gets that size's level then, in the sandbox too (api/model_levels.h).
 * No work for sizes nobody asked for: a farm draws each model once, and the eight levels built
 * at every import before cost ~25 times drawing a 100k-triangle mesh in full. A level depends
 * on the mesh and the size only, so a request draws the same whatever the cache held.
 * The importer also marks each mesh closed or not (api_model_finish_import); the daemon sets
 * the bounds (api_mesh_bounds) when it takes the reply.
 * Threading: touches only the model it is given.
 */
#ifndef UMBRA_API_MODEL_LOD_H
#define UMBRA_API_MODEL_LOD_H

#include <stddef.h>
#include "arena.h"
#include "model.h"

/* Meshes with fewer triangles are left alone: drawing them costs less than choosing. */
#define API_LOD_MIN_TRIANGLES 20000u

/* Whether levels are built for this mesh: at least API_LOD_MIN_TRIANGLES triangles and normals
 * (levels carry positions, normals, uvs, vertex colours and tangents; a coloured mesh's level
 * must also show its colours, api/lod_colour.h, or there is none). */
bool api_mesh_wants_levels(const struct api_model_mesh *me);

/* The level of every mesh of m that wants one (api_mesh_wants_levels) for images of
 * output_side into arena, as each mesh's lods (one level, or none where simplification saves
 * under a quarter of the triangles or comes out over the bound, or memory ran out: the full mesh
 * is always correct, only slower); adds their size to *bytes. */
void api_model_build_level(struct api_model *m, uint32_t output_side, struct api_arena *arena, size_t *bytes);

/* What the importer does last (in its sandbox, api/model_import.c): sets each mesh's `closed`
 * (welded by position, every edge is shared by exactly two triangles that run it in opposite
 * directions, and the enclosed volume is positive: wound outward, so the renderer may cull back
 * faces when the camera is outside it; out of memory: not closed) and, for a request whose
 * images are at most output_side pixels across (0 = unknown: none), api_model_build_level(),
 * so that a new model's first render need not draw what its pixels cannot show. */
void api_model_finish_import(struct api_model *m, uint32_t output_side, struct api_arena *arena, size_t *bytes);
/* The relative error (fraction of the mesh's extent) a level for output_side is measured
 * within; pure. */
float api_lod_import_error(uint32_t output_side);

/* Sets me->bounds: min xyz, max xyz of its positions (0 for a mesh without vertices). */
void api_mesh_bounds(struct api_model_mesh *me);

/* Whether triangles idx (ni indices into pos: nv vertices) close a volume wound outward; pure.
 * Triangles with a repeated index are left out; an index past nv: not closed. */
bool api_mesh_closed(const uint32_t *idx, size_t ni, const float *pos, size_t nv);

/* Levels of one mesh on the wire (api/model_wire.h): one per size. */
#define API_LOD_LEVELS 1u

#endif
