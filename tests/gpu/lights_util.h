/*
 * tests/gpu/lights_util — helpers the light tests (tests/gpu/test_lights*.c) share: lrender (a
 * render with its timings on any context, R_OK / R_FAIL / R_UNSUPPORTED), make_ctx (a second
 * context), analytic occluders (struct occ: spheres and boxes rotated about Y) with their ray
 * casts and scene JSON, cameras, agreement (a debug shadow view against per-pixel classes) and
 * image_diff. Everything is computed here, never taken from the renderer's output.
 */
#ifndef UMBRA_TESTS_LIGHTS_UTIL_H
#define UMBRA_TESTS_LIGHTS_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "api.h"
#include "gpu_util.h"
#include "util.h"

enum { R_FAIL = 0, R_OK = 1, R_UNSUPPORTED = 2 };

struct occ {
	bool box;
	v3 c;
	double r;      /* sphere */
	v3 half;       /* box half sizes */
	double yaw;    /* box rotation about +Y, radians */
};

/* gpu_render_at with the render's timings and a context of the caller's choosing (NULL = the
 * binary's). allow_422: a 422 "not supported" answer from the parser is returned as
 * R_UNSUPPORTED instead of failing the test. lrender: at the caller's file and line. */
int lrender_at(const char *file, int line, struct rnd_context *ctx, struct rnd_image *img, struct rnd_timings *t,
               bool allow_422, const char *fmt, ...) __attribute__((format(printf, 7, 8)));
/* A second context (validation as the binary's), e.g. with a tiny atlas. */
struct rnd_context *make_ctx(uint32_t atlas_size, int line);
/* A pixel's first channel, 0..255. */
int val8(const struct rnd_image *img, int i, int j);

/* Nearest occluder hit along o + t d (t > eps), -1 when none. */
double ray_occs(v3 o, v3 d, const struct occ *oc, int n, double eps);
/* Is p in the shadow of a point light at lp (segment p -> lp blocked)? */
bool point_shadowed(v3 p, v3 lp, const struct occ *oc, int n);
/* JSON objects for the occluders, appended to buf. */
void occ_json(char *buf, size_t n, const struct occ *oc, int count, int segments);
/* A camera's JSON, and the same camera for gpu_util.h's projections. */
void cam_json(char *buf, size_t n, bool ortho, v3 pos, v3 tgt, v3 up, double fov_or_h);
void cam_make(struct gpu_cam *c, bool ortho, v3 pos, v3 tgt, v3 up, double fov_or_h, int w, int h);
/* Compares a debug shadow view (img) with per-pixel classes (GPU_CLS_*): agreement over LIT /
 * SHADOW pixels with no other class within `band` pixels. */
double agreement(const struct rnd_image *img, const uint8_t *cls, int w, int h, int band, long *n_lit, long *n_sh,
                 long *bad_lit, long *bad_sh);
/* Pixels of a and b (same size) whose first channels differ by more than tol; *maxd the largest
 * difference (GPU_TEST_VERBOSE=1 prints the first five). */
long image_diff(const struct rnd_image *a, const struct rnd_image *b, int tol, int *maxd);
#define lrender(ctx, img, t, ...) lrender_at(__FILE__, __LINE__, (ctx), (img), (t), false, __VA_ARGS__)

#endif
