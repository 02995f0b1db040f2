/*
 * api/lod_error — how far a level of detail (api/model_lod.h) is from its full mesh, in object
 * units: the largest distance of the level triangles' centroids and edge midpoints (its
 * vertices are the full mesh's own) from the full mesh's faces around them. meshoptimizer's
 * own error measures the kept vertices against the removed faces' planes and says nothing of
 * the new triangles' insides (on a sphere it claims 6x less than this).
 *
 * Usage: m = api_lod_measure_create(...); e = api_lod_measure_level(m, level, n, false); ...
 *        api_lod_measure_destroy(m);
 * Ownership: the measure points into pos, nrm (not copied: they outlive it) and copies full.
 * Threading: one measure, one thread (its walk keeps scratch); measures share nothing.
 */
#ifndef UMBRA_API_LOD_ERROR_H
#define UMBRA_API_LOD_ERROR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* fminf(acc, x) and fmaxf(acc, x) for an accumulator that is never NaN, inline (those are
 * calls into libm): a NaN x (a degenerate face's distance) leaves acc as it is, as they do. */
static inline float min_f(float acc, float x)
{
	return x < acc ? x : acc;
}

static inline float max_f(float acc, float x)
{
	return x > acc ? x : acc;
}

/* The box of n points (lo, hi; empty: +inf, -inf) and its largest side. */
float api_points_box(const float *p, size_t n, float lo[3], float hi[3]);

struct api_lod_measure;

/* A measure against the full mesh full[0..nfull) (indices into the welded vertices pos, with
 * their unit normals nrm, nv of them; lo..hi their box, extent its largest side, > 0). NULL
 * when out of memory. */
struct api_lod_measure *api_lod_measure_create(const float *pos, const float *nrm, size_t nv, const uint32_t *full,
                                               size_t nfull, const float lo[3], const float hi[3], float extent);
/* NULL-safe. */
void api_lod_measure_destroy(struct api_lod_measure *m);

/* The error of the level level[0..nlevel) (indices into the same vertices); INFINITY when out
 * of memory. everywhere: the figure the measure stands for, every level triangle walked to
 * the end (dear; for tests and benchmarks). */
float api_lod_measure_level(struct api_lod_measure *m, const uint32_t *level, size_t nlevel, bool everywhere);

#endif
