/* tests/gpu — shared helpers (see gpu_util.h). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "model.h"
#include "gpu_util.h"
#include "test.h"
#include "util.h"

static struct rnd_context *g_ctx;
static bool g_ctx_failed;

static void destroy_ctx(void)
{
	rnd_context_destroy(g_ctx);
	g_ctx = NULL;
}

struct rnd_context *gpu_ctx(void)
{
	if (g_ctx || g_ctx_failed) {
		CHECK(g_ctx, "no renderer context (creation failed earlier)");
		return g_ctx;
	}
	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {0};
	cd.validation = v && strcmp(v, "1") == 0;
	struct rnd_error err = {0};
	if (rnd_context_create(&cd, &g_ctx, &err) != RND_OK) {
		g_ctx_failed = true;
		g_ctx = NULL;
		CHECK(0, "rnd_context_create: %s: %s", rnd_result_str(err.code), err.msg);
		return NULL;
	}
	atexit(destroy_ctx);
	return g_ctx;
}

struct rnd_timings gpu_last_timings;
const char *gpu_asset_root;

float *gpu_read_grey(const char *path, uint32_t w, uint32_t h)
{
	size_t len;
	uint8_t *png = test_read_file(path, &len), *rgba = NULL;
	uint32_t pw = 0, ph = 0;
	char err[200];
	float *out = NULL;
	if (png && api_image_decode(png, len, 0, &rgba, &pw, &ph, err, sizeof err) == API_OK && pw == w && ph == h &&
	    (out = malloc(sizeof *out * w * h)))
		for (uint32_t i = 0; i < w * h; i++) out[i] = rgba[4 * i] / 255.0f;
	free(png);
	free(rgba);
	return out;
}

struct api_scene *gpu_parse(const char *json)
{
	char *doc = strdup(json);
	if (!doc) return NULL;
	for (char *p = doc; *p; p++)
		if (*p == '\'') *p = '"';
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = gpu_asset_root;
	struct api_scene *s = NULL;
	struct api_problem prob = {0};
	if (api_scene_parse(doc, strlen(doc), &lim, &s, &prob) != API_OK) {
		CHECK(0, "parse: %s: %s", prob.pointer, prob.detail);
		s = NULL;
	}
	free(doc);
	return s;
}

bool gpu_render_at(const char *file, int line, struct rnd_image *img, const char *fmt, ...)
{
	memset(img, 0, sizeof *img);
	struct rnd_context *ctx = gpu_ctx();
	if (!ctx) { test_fail_at(file, line, "gpu_render", " no context"); return false; }

	va_list ap;
	va_start(ap, fmt);
	char *doc = test_vdoc(fmt, ap);
	va_end(ap);
	if (!doc) { test_fail_at(file, line, "gpu_render", " vasprintf"); return false; }

	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = gpu_asset_root;
	struct api_scene *s = NULL;
	struct api_problem prob;
	memset(&prob, 0, sizeof prob);
	if (api_scene_parse(doc, strlen(doc), &lim, &s, &prob) != API_OK) {
		test_fail_at(file, line, "api_scene_parse", " %d %s: %s\n    doc: %s", prob.status, prob.pointer,
		             prob.detail, doc);
		free(doc);
		return false;
	}
	uint32_t before = rnd_context_validation_messages(ctx);
	struct rnd_timings t;
	struct rnd_error err = {0};
	enum rnd_result r = rnd_render(ctx, &s->scene, img, &t, &err);
	uint32_t after = rnd_context_validation_messages(ctx);
	api_scene_free(s);
	bool ok = true;
	if (r != RND_OK) {
		test_fail_at(file, line, "rnd_render", " %s: %s\n    doc: %s", rnd_result_str(r), err.msg, doc);
		memset(img, 0, sizeof *img);
		ok = false;
	} else {
		gpu_last_timings = t;
	}
	if (after != before) {
		test_fail_at(file, line, "validation", " %u new Vulkan validation message(s) during this render",
		             after - before);
	}
	free(doc);
	return ok;
}

const uint8_t *gpu_px8(const struct rnd_image *img, int i, int j)
{
	return (const uint8_t *)img->pixels + (size_t)j * img->stride + (size_t)i * 4;
}

double gpu_chan(const struct rnd_image *img, int i, int j, int c)
{
	if (img->format == RND_PIXELS_RGBA16) {
		const uint16_t *p = (const uint16_t *)((const uint8_t *)img->pixels + (size_t)j * img->stride) + (size_t)i * 4;
		return p[c] / 65535.0;
	}
	if (img->format == RND_PIXELS_RGBA32F) {
		const float *p = (const float *)((const uint8_t *)img->pixels + (size_t)j * img->stride) + (size_t)i * 4;
		return p[c];
	}
	return gpu_px8(img, i, j)[c] / 255.0;
}

double gpu_srgb_encode(double x)
{
	if (x <= 0.0031308) return 12.92 * x;
	return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

double gpu_srgb_decode(double s)
{
	if (s <= 0.04045) return s / 12.92;
	return pow((s + 0.055) / 1.055, 2.4);
}

double v3_len(v3 a) { return sqrt(v3_dot(a, a)); }
v3 v3_norm(v3 a) { double l = v3_len(a); return l > 0 ? v3_scale(a, 1.0 / l) : a; }

static void cam_frame(struct gpu_cam *c, v3 pos, v3 target, v3 up, int w, int h)
{
	c->pos = pos;
	c->fwd = v3_norm(v3_sub(target, pos));
	v3 r = v3_cross(c->fwd, up);
	if (v3_len(r) < 1e-6 * v3_len(up) || v3_len(up) == 0) {
		/* §7: an up parallel to the view is replaced by -Z (+Y when the view is along Z). */
		bool along_z = fabs(c->fwd.z) > 0.999;
		up = along_z ? v3_make(0, 1, 0) : v3_make(0, 0, -1);
		r = v3_cross(c->fwd, up);
	}
	c->right = v3_norm(r);
	c->up = v3_cross(c->right, c->fwd);
	c->w = w;
	c->h = h;
}

void gpu_cam_persp(struct gpu_cam *c, v3 pos, v3 target, v3 up, double fov_y_deg, int w, int h)
{
	cam_frame(c, pos, target, up, w, h);
	c->ortho = false;
	c->tan_half = tan(fov_y_deg * GPU_DEG / 2);
}

void gpu_cam_ortho(struct gpu_cam *c, v3 pos, v3 target, v3 up, double height, int w, int h)
{
	cam_frame(c, pos, target, up, w, h);
	c->ortho = true;
	c->half_h = height / 2;
}

void gpu_cam_ray(const struct gpu_cam *c, double px, double py, v3 *o, v3 *d)
{
	double aspect = (double)c->w / c->h;
	double nx = 2 * px / c->w - 1, ny = 1 - 2 * py / c->h;
	if (c->ortho) {
		*o = v3_add(c->pos, v3_add(v3_scale(c->right, nx * c->half_h * aspect), v3_scale(c->up, ny * c->half_h)));
		*d = c->fwd;
	} else {
		*o = c->pos;
		*d = v3_norm(v3_add(c->fwd, v3_add(v3_scale(c->right, nx * c->tan_half * aspect),
		                                   v3_scale(c->up, ny * c->tan_half))));
	}
}

bool gpu_cam_project(const struct gpu_cam *c, v3 p, double *px, double *py)
{
	double aspect = (double)c->w / c->h;
	v3 rel = v3_sub(p, c->pos);
	double z = v3_dot(rel, c->fwd), x = v3_dot(rel, c->right), y = v3_dot(rel, c->up);
	double nx, ny;
	if (c->ortho) {
		nx = x / (c->half_h * aspect);
		ny = y / c->half_h;
	} else {
		if (z <= 0) return false;
		nx = x / (z * c->tan_half * aspect);
		ny = y / (z * c->tan_half);
	}
	*px = (nx + 1) * c->w / 2;
	*py = (1 - ny) * c->h / 2;
	return z > 0;
}

double gpu_ray_sphere(v3 o, v3 d, v3 c, double r, double eps)
{
	v3 oc = v3_sub(o, c);
	double a = v3_dot(d, d), b = v3_dot(oc, d), cc = v3_dot(oc, oc) - r * r;
	double disc = b * b - a * cc;
	if (disc < 0) return -1;
	double s = sqrt(disc);
	double t0 = (-b - s) / a, t1 = (-b + s) / a;
	if (t0 > eps) return t0;
	if (t1 > eps) return t1;
	return -1;
}

double gpu_ray_ground(v3 o, v3 d, double y0, double cx, double cz, double half)
{
	if (fabs(d.y) < 1e-12) return -1;
	double t = (y0 - o.y) / d.y;
	if (t <= 0) return -1;
	v3 p = v3_add(o, v3_scale(d, t));
	if (fabs(p.x - cx) > half || fabs(p.z - cz) > half) return -1;
	return t;
}

bool gpu_near_edge(const uint8_t *cls, int w, int h, int i, int j, int band)
{
	uint8_t k = cls[(size_t)j * w + i];
	for (int y = j - band; y <= j + band; y++) {
		if (y < 0 || y >= h) continue;
		for (int x = i - band; x <= i + band; x++) {
			if (x < 0 || x >= w) continue;
			if (cls[(size_t)y * w + x] != k) return true;
		}
	}
	return false;
}

long gpu_bytes_differ(const struct rnd_image *a, const struct rnd_image *b, size_t *first)
{
	if (a->width != b->width || a->height != b->height || a->stride != b->stride) return -1;
	const unsigned char *pa = a->pixels, *pb = b->pixels;
	size_t n = (size_t)a->height * a->stride;
	long diff = 0;
	for (size_t i = 0; i < n; i++)
		if (pa[i] != pb[i] && !diff++ && first) *first = i;
	return diff;
}
