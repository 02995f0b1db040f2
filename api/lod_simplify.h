/*
 * api/lod_simplify — meshoptimizer's simplification of a welded mesh (api/model_lod.c's one
 * level), in pieces when the mesh is large.
 *
 * meshoptimizer 0.18 simplified a 1M-triangle mesh (500k vertices) at ~0.7 us a triangle, three
 * times its rate on a 100k one: its arrays per vertex and per edge outgrow the cache; and one
 * pass runs on one core while the other waits. A mesh of ~100k triangles or more is therefore
 * cut into k^3 pieces by a grid over its box (k up to 8, at least API_LOD_PIECE_TRIANGLES each on
 * average, by centroid; a mesh under 8 times that is one piece, simplified as before), each
 * simplified on the import's threads with its cut kept
 * (meshopt_SimplifyLockBorder, the mesh's own borders too), and the whole, by then a fraction of
 * its size, once more without locks so that the cuts go as well. Each pass aims at the same
 * target: the two passes' errors can add up, and the level is measured against the full mesh
 * afterwards all the same (api/model_lod.c), so the bound holds whatever this does.
 *
 * Threading: no shared state. Memory: malloc'd scratch of the mesh's size (the importer's
 * limits bound it); without it, one pass over the whole.
 */
#ifndef UMBRA_API_LOD_SIMPLIFY_H
#define UMBRA_API_LOD_SIMPLIFY_H

#include <stddef.h>
#include <stdint.h>

/* Triangles a piece is made of, about; a mesh with fewer than 8 times as many is one piece. */
#define API_LOD_PIECE_TRIANGLES 12000u

/* idx[0..ni) over pos[0..nv) (welded, extent its box's largest side) simplified within the
 * relative error `target` (meshoptimizer's measure, relative to extent) into dst (room for ni);
 * returns the indices written. */
size_t api_lod_simplify(uint32_t *dst, const uint32_t *idx, size_t ni, const float *pos, size_t nv, float extent,
                        float target);

#endif
