/* tests/gpu — shared helpers for the GPU test binary: one lazily created renderer context,
 * JSON -> image rendering with validation-message checks, and an independent camera model
 * (contract §1) to predict where world points land and which surface each pixel sees. */
#ifndef UMBRA_GPU_UTIL_H
#define UMBRA_GPU_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "umbra/rnd.h"

struct api_scene;

#define GPU_PI 3.14159265358979323846
#define GPU_DEG (GPU_PI / 180.0)

/* The binary's context (validation when UMBRA_VALIDATION=1); NULL (and a failed CHECK) when
 * it cannot be created. Destroyed at exit. */
struct rnd_context *gpu_ctx(void);

/* Parses `json` (single quotes are turned into double quotes first, so documents stay
 * readable in C) and renders it into *img. Returns true on success; on failure the calling
 * test fails (reported at the caller's file:line). Any new validation message fails the test. */
bool gpu_render_at(const char *file, int line, struct rnd_image *img, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
#define gpu_render(img, ...) gpu_render_at(__FILE__, __LINE__, (img), __VA_ARGS__)
/* The scene of `json` (single quotes allowed, default limits), for tests that change its
 * fields before rnd_render; NULL (and a failed CHECK) when it does not parse. api_scene_free()
 * it. */
struct api_scene *gpu_parse(const char *json);
/* The timings of the last successful gpu_render (shadow maps rendered / reused). */
extern struct rnd_timings gpu_last_timings;

/* Pixel access: channel c of pixel (i, j) as 0..1 (RGBA8 or RGBA16), or the raw 8-bit value. */
double gpu_chan(const struct rnd_image *img, int i, int j, int c);
const uint8_t *gpu_px8(const struct rnd_image *img, int i, int j);

double gpu_srgb_encode(double linear);
double gpu_srgb_decode(double encoded);

/* ---- vectors ---- */
typedef struct { double x, y, z; } v3;
static inline v3 v3_make(double x, double y, double z) { v3 r = {x, y, z}; return r; }
static inline v3 v3_add(v3 a, v3 b) { return v3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline v3 v3_sub(v3 a, v3 b) { return v3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline v3 v3_scale(v3 a, double s) { return v3_make(a.x * s, a.y * s, a.z * s); }
static inline double v3_dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline v3 v3_cross(v3 a, v3 b)
{
	return v3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
double v3_len(v3 a);
v3 v3_norm(v3 a);

/* ---- camera (contract §1 and §7), computed independently of the renderer ---- */
struct gpu_cam {
	v3 pos, fwd, right, up;
	bool ortho;
	double tan_half;   /* perspective: tan(fov_y / 2) */
	double half_h;     /* orthographic: height / 2 */
	int w, h;
};
void gpu_cam_persp(struct gpu_cam *c, v3 pos, v3 target, v3 up, double fov_y_deg, int w, int h);
void gpu_cam_ortho(struct gpu_cam *c, v3 pos, v3 target, v3 up, double height, int w, int h);
/* Ray through image point (px, py) in pixel units (pixel (i, j)'s centre is (i+0.5, j+0.5)).
 * d is normalised. */
void gpu_cam_ray(const struct gpu_cam *c, double px, double py, v3 *o, v3 *d);
/* World point -> image point (pixel units as above); false when behind the camera. */
bool gpu_cam_project(const struct gpu_cam *c, v3 p, double *px, double *py);

/* ---- analytic geometry ---- */
/* Smallest t > eps with |o + t d - c| = r, or -1. d need not be normalised. */
double gpu_ray_sphere(v3 o, v3 d, v3 c, double r, double eps);
/* t of the hit with the plane y = y0 inside |x - cx|, |z - cz| <= half, or -1. */
double gpu_ray_ground(v3 o, v3 d, double y0, double cx, double cz, double half);

/* Pixel classes for analytic comparisons. */
enum { GPU_CLS_BG = 0, GPU_CLS_OBJ = 1, GPU_CLS_LIT = 2, GPU_CLS_SHADOW = 3, GPU_CLS_SKIP = 4 };
/* True when pixel (i, j) of cls (w x h) has a pixel of another class within Chebyshev
 * distance `band`. */
bool gpu_near_edge(const uint8_t *cls, int w, int h, int i, int j, int band);

/* A grey (or RGBA: its red) PNG as 0..1 floats, w x h (malloc'd); NULL when missing or of
 * another size. */
float *gpu_read_grey(const char *path, uint32_t w, uint32_t h);
/* The asset root of gpu_render and gpu_parse (NULL: none, the default). */
extern const char *gpu_asset_root;

/* Bytes of a and b that differ (-1 when their sizes differ); *first (may be NULL): the first. */
long gpu_bytes_differ(const struct rnd_image *a, const struct rnd_image *b, size_t *first);

#endif
