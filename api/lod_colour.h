/*
 * api/lod_colour — whether a level of detail (api/model_lod.h) of a vertex-coloured mesh shows
 * the mesh's colours: for every vertex of the full mesh, the colour the level shows at the
 * nearest points of its triangles within `reach` (the distance the level may be off, the
 * renderer's half pixel) against the vertex's own.
 *
 * The level's vertices are the full mesh's own, so the error is in its triangles' insides: a
 * removed vertex whose colour the level's interpolation across it does not give (a stripe
 * narrower than the level's triangles, a spot, a band's edge moved by a collapse across it).
 * A vertex counts as shown when some level triangle within reach shows its colour there (the
 * least error of those): a colour edge the level moved by less than reach, like a silhouette
 * moved by less than reach, is within what the renderer already allows.
 *
 * Threading: runs its slices on api/workers.h; the figure does not depend on the thread count.
 */
#ifndef UMBRA_API_LOD_COLOUR_H
#define UMBRA_API_LOD_COLOUR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The colour bound of a level: 2/255 of the output's 8-bit sRGB encoding, beyond one step of
 * the colours' own 8 bits (see lod_colour.c). */
#define API_LOD_COLOUR_BOUND (2.0f / 255.0f)

/* The largest colour error (max over RGB of the difference in sRGB encoding, 0..1, or over alpha
 * in its own units; past one step of the vertex's 8 bits) of level[0..nlevel) against
 * full[0..nfull), both indices into pos and
 * col (linear RGBA8 per vertex, nv of them), lo..hi the vertices' box, extent its largest side.
 * A vertex with no level triangle within reach counts as 1. Stops at the first slice's vertex over
 * `stop` (the figure is then only known to exceed it). INFINITY when out of memory. */
float api_lod_colour_error(const float *pos, const uint8_t *col, size_t nv, const uint32_t *full, size_t nfull,
                           const uint32_t *level, size_t nlevel, const float lo[3], const float hi[3], float extent,
                           float reach, float stop);

/* The share of vertices over which api_lod_colours_rough gives up (see there). */
#define API_LOD_COLOUR_ROUGH_SHARE 0.25f

/* Whether colours col (linear RGBA8, nv vertices, triangles idx[0..ni)) are too rough for any
 * level to show: more than API_LOD_COLOUR_ROUGH_SHARE of the vertices whose colour the mean of
 * their neighbours' (linear, as a level interpolates) misses by more than API_LOD_COLOUR_BOUND,
 * the error api_lod_colour_error would give a vertex that a level replaced by its ring. A level
 * keeps a few percent of the vertices, so with a quarter of them that rough it is refused after
 * its whole cost (the 100k blob with noise of +-12/255: 96 %, ~80 ms of simplification and
 * measure for no level); bands and ramps, smooth between their edges, stay well under (the
 * corpus's banded blob: 5 %). A cheap guess, one pass: it only spares a level's cost, and the
 * measure above still decides every level that is built. False when out of memory. */
bool api_lod_colours_rough(const uint8_t *col, size_t nv, const uint32_t *idx, size_t ni);

#endif
