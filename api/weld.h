/*
 * api/weld — a mesh's vertices grouped by position, by sorting: the one grouping the importer
 * makes of a mesh, shared by the join of an STL's corners (api_join_vertices, which hands it
 * on as the mesh's weld classes), the closedness check and the level of detail
 * (api/model_lod.c). Before, each of the three hashed the same corners again; a hash of
 * millions of keys misses the cache on nearly every one, where a radix sort reads and writes
 * in order.
 *
 * Positions are equal here when they quantize to the same point of a grid of 2^-20 of their
 * box's largest side (21 bits an axis, one 64-bit key): a seam written with sin(2 pi) != 0 is
 * closed, as the level's simplifier needs (api/model_lod.c).
 *
 * Usage: struct api_weld w; if (api_weld_sort(pos, nv, &w)) { ... w.group[v] ... }
 *        api_weld_release(&w);
 * Threading: no shared state. Memory: malloc'd (the importer's limits bound it).
 */
#ifndef UMBRA_API_WELD_H
#define UMBRA_API_WELD_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

struct api_weld {
	uint32_t *group;     /* group[v]: the group of vertex v, 0 .. groups - 1, in key order */
	uint32_t *order;     /* the vertices by group, each group's in vertex order ... */
	uint32_t *start;     /* ... group g being order[start[g] .. start[g + 1]) */
	size_t groups;
};

/* Groups pos[0..nv) (xyz, finite). false when out of memory (w is then empty). */
bool api_weld_sort(const float *pos, uint32_t nv, struct api_weld *w);
void api_weld_release(struct api_weld *w);

/* x rounded to the nearest integer, ties to even (lrintf's answer in the default rounding
 * mode), without a call into libm; 0 for |x| >= 2^22 and NaN (where the weld's and the join's
 * keys took lrintf's LONG_MIN, whose low bits are 0). */
static inline int32_t api_round_even(float x)
{
	const float big = 12582912.0f;   /* 1.5 * 2^23: adding it rounds to an integer (IEEE: not folded away) */
	return fabsf(x) < 4194304.0f ? (int32_t)((x + big) - big) : 0;
}

/* A mesh welded: the groups its indices refer to, as vertices of their own. */
struct api_welded {
	float *pos;          /* xyz of each: its group's last vertex's position (by vertex number) */
	uint32_t *rep;       /* its group's first vertex (for the attributes that the weld drops) */
	size_t count;
};

/* The vertices indices[0..ni) name, welded (by group[], groups of them: the importer's weld,
 * or NULL: sorted here), numbered in the order the indices first meet them, into idx[0..ni)
 * and *out (malloc'd; api_welded_release). Vertices no index names are left out. This is
 * what meshoptimizer's remap of the quantized positions made before, number for number.
 * false when out of memory (release *out all the same). */
bool api_weld_mesh(const float *pos, uint32_t nv, const uint32_t *indices, uint32_t ni, const uint32_t *group,
                   size_t groups, uint32_t *idx, struct api_welded *out);
void api_welded_release(struct api_welded *w);

/* Sorts keys[0..n) (n < 2^32) stably, with vals[0..n) moved along when not NULL, by the bits
 * where the keys differ, 11 bits a pass; tmp and vtmp hold n more each (vtmp unused without
 * vals). Returns the sorted keys: keys or tmp (the values then in vals or vtmp alike). */
uint64_t *api_radix_sort(uint64_t *keys, uint64_t *tmp, uint32_t *vals, uint32_t *vtmp, size_t n);

#endif
