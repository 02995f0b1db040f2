/*
 * renderer/env_analysis.h — what the CPU learns from an environment map, once per map: its
 * light in coarse bins, the spherical harmonics of its irradiance (the diffuse light), and the
 * directions its shadows are drawn from (a median cut of its light into regions of equal
 * energy, after Debevec's "A median cut algorithm for light probe sampling", 2005).
 *
 * Pure math: no Vulkan; tests/unit/test_env.c.
 * Directions here are the map's own (env.h turns them into the scene's by the rotation).
 */
#ifndef UMBRA_RENDERER_ENV_ANALYSIS_H
#define UMBRA_RENDERER_ENV_ANALYSIS_H

#include <stdbool.h>
#include <stdint.h>
#include "umbra/rnd.h"

/* The map averaged into RND_ENV_BINS_W x RND_ENV_BINS_H bins (equal steps of longitude and
 * latitude, rows from the zenith), linear RGB. */
#define RND_ENV_BINS_W 128
#define RND_ENV_BINS_H 64
struct rnd_env_bins {
	float rgb[RND_ENV_BINS_H][RND_ENV_BINS_W][3];
};

/* One shadow direction: a region of the map. */
struct rnd_env_dir {
	float dir[3];        /* unit, the map's frame, towards the sky */
	float share;         /* the region's part of the map's light (luminance x solid angle) */
	float sin_radius;    /* sin of the angular radius of a cap of the region's solid angle */
};

/* Bins of a w x h equirectangular map (rgb: w * h * 3 floats, rows from the top). Any size;
 * each bin averages the texels whose centres fall in it (a map narrower than the bins is read
 * at the bin's centre). */
void rnd_env_bin(const float *rgb, uint32_t w, uint32_t h, struct rnd_env_bins *out);

/* The direction of bin centre (x + 0.5, y + 0.5) of the bins (scene convention of rnd.h's
 * rnd_env_map: u = 0.5 + atan2(z, x) / 2pi, v = 0.5 - asin(y) / pi). */
void rnd_env_bin_dir(float x, float y, float d[3]);

/* Spherical harmonics (order 2, 9 coefficients per channel) of the irradiance over pi:
 * E(n) / pi = sum_i sh[i] Y_i(n) with Y_i of rnd_env_sh_basis (so a white map of radiance 1
 * gives 1 everywhere). */
void rnd_env_sh(const struct rnd_env_bins *b, float sh[9][3]);
void rnd_env_sh_basis(const float n[3], float y[9]);

/* Up to `count` directions (0..32): a sun first where the map has one (a compact source of a
 * tenth of its light or more: one direction of its own size), then the rest of the light in
 * regions of equal shares, the brightest cut finest. With `ground`, the upper hemisphere (y > 0) gets `count` and the lower one
 * RND_ENV_GROUND_DIRS more, listed after them (a ground plane hides those: they are never
 * drawn, only weighed). Returns how many were written (fewer for a map with less light in
 * places than regions to cut; 0 for a black map); *upper those of the first kind. */
#define RND_ENV_GROUND_DIRS 4u
uint32_t rnd_env_directions(const struct rnd_env_bins *b, uint32_t count, bool ground, struct rnd_env_dir *out,
                            uint32_t *upper);

/* The shadow directions of one render, in the scene's frame (the render plan's, render_plan.h;
 * env.h's rnd_env_use takes them): the first `mapped` get shadow maps, the rest (below a
 * ground) are only weighed. */
struct rnd_env_plan {
	uint32_t ndirs, mapped;
	struct rnd_env_dir dirs[RND_MAX_ENV_DIRECTIONS + RND_ENV_GROUND_DIRS];
	bool ground;
	float ground_n[3];
};
/* env->shadow_directions regions of the light of a map binned as b, turned by env->rotation;
 * with a ground (its unit normal, NULL = none) only those above it get maps. b NULL: none. */
void rnd_env_plan_dirs(const struct rnd_env_bins *b, const struct rnd_environment *env, const float *ground_n,
                       struct rnd_env_plan *out);

/* Rec. 709 luminance. */
static inline float rnd_env_luminance(const float c[3])
{
	return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

#endif
