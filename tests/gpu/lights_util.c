/* tests/gpu/lights_util.c — the light tests' helpers (lights_util.h): renders with timings on any
 * context, analytic occluders (ray casts against spheres and rotated boxes), scene JSON for
 * them and cameras, and image comparisons. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"
#include "util.h"
#include "lights_util.h"

/* ---- rendering with timings, on any context ---- */

/* gpu_render_at with the render's timings and a context of the caller's choosing (NULL = the
 * binary's). allow_422: a 422 "not supported" answer from the parser is returned as
 * R_UNSUPPORTED instead of failing the test. */
int lrender_at(const char *file, int line, struct rnd_context *ctx, struct rnd_image *img,
               struct rnd_timings *t, bool allow_422, const char *fmt, ...)
{
	memset(img, 0, sizeof *img);
	struct rnd_timings dummy;
	if (!t) t = &dummy;
	memset(t, 0, sizeof *t);
	if (!ctx) ctx = gpu_ctx();
	if (!ctx) { test_fail_at(file, line, "lrender", " no context"); return R_FAIL; }
	va_list ap;
	va_start(ap, fmt);
	char *doc = test_vdoc(fmt, ap);
	va_end(ap);
	if (!doc) { test_fail_at(file, line, "lrender", " vasprintf"); return R_FAIL; }

	struct api_limits lim;
	api_limits_defaults(&lim);
	struct api_scene *s = NULL;
	struct api_problem prob;
	memset(&prob, 0, sizeof prob);
	if (api_scene_parse(doc, strlen(doc), &lim, &s, &prob) != API_OK) {
		if (allow_422 && prob.status == 422) {
			printf("    note: 422 %s: %s (%s) — skipped\n", prob.pointer, prob.detail, prob.title);
			free(doc);
			return R_UNSUPPORTED;
		}
		test_fail_at(file, line, "api_scene_parse", " %d %s: %s\n    doc: %s", prob.status, prob.pointer,
		             prob.detail, doc);
		free(doc);
		return R_FAIL;
	}
	uint32_t before = rnd_context_validation_messages(ctx);
	struct rnd_error err = {0};
	enum rnd_result r = rnd_render(ctx, &s->scene, img, t, &err);
	uint32_t after = rnd_context_validation_messages(ctx);
	int ok = R_OK;
	if (r != RND_OK) {
		test_fail_at(file, line, "rnd_render", " %s: %s\n    doc: %s", rnd_result_str(r), err.msg, doc);
		memset(img, 0, sizeof *img);
		ok = R_FAIL;
	}
	if (after != before)
		test_fail_at(file, line, "validation", " %u new Vulkan validation message(s) during this render",
		             after - before);
	/* LIGHTS_DUMP=dir: write every image as a PNG there (for looking at failures). */
	const char *dump = getenv("LIGHTS_DUMP");
	if (dump && ok == R_OK && (img->format == RND_PIXELS_RGBA8 || img->format == RND_PIXELS_RGBA16)) {
		static int seq;
		uint8_t *png = NULL;
		size_t len = 0;
		struct api_problem p2;
		if (api_png_encode(img, 1, &png, &len, &p2) == API_OK) {
			char path[512];
			snprintf(path, sizeof path, "%s/lights_%03d_line%d.png", dump, seq++, line);
			FILE *f = fopen(path, "wb");
			if (f) { fwrite(png, 1, len, f); fclose(f); }
			free(png);
		}
	}
	api_scene_free(s);
	free(doc);
	return ok;
}

/* A second context (validation as the binary's), e.g. with a tiny atlas. */
struct rnd_context *make_ctx(uint32_t atlas_size, int line)
{
	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {0};
	cd.validation = v && strcmp(v, "1") == 0;
	cd.atlas_size = atlas_size;
	struct rnd_context *ctx = NULL;
	struct rnd_error err = {0};
	if (rnd_context_create(&cd, &ctx, &err) != RND_OK) {
		test_fail_at(__FILE__, line, "rnd_context_create", " atlas %u: %s: %s", atlas_size, rnd_result_str(err.code),
		             err.msg);
		return NULL;
	}
	return ctx;
}

int val8(const struct rnd_image *img, int i, int j) { return gpu_px8(img, i, j)[0]; }

static void fmt_v3(char *b, size_t n, v3 v) { snprintf(b, n, "[%.9g,%.9g,%.9g]", v.x, v.y, v.z); }

/* ---- analytic occluders: spheres and boxes (rotated about Y by yaw) ---- */

static v3 rot_y(v3 p, double a)
{
	/* R_y(a): (1,0,0) -> (cos a, 0, -sin a), as the glTF quaternion (0, sin a/2, 0, cos a/2). */
	return v3_make(p.x * cos(a) + p.z * sin(a), p.y, -p.x * sin(a) + p.z * cos(a));
}

/* Smallest t > eps where o + t d enters the box (or leaves it, from inside), or -1. */
static double ray_box(v3 o, v3 d, const struct occ *b, double eps)
{
	v3 lo = rot_y(v3_sub(o, b->c), -b->yaw), ld = rot_y(d, -b->yaw);
	double oo[3] = {lo.x, lo.y, lo.z}, dd[3] = {ld.x, ld.y, ld.z}, hh[3] = {b->half.x, b->half.y, b->half.z};
	double tmin = -1e300, tmax = 1e300;
	for (int k = 0; k < 3; k++) {
		if (fabs(dd[k]) < 1e-15) {
			if (fabs(oo[k]) > hh[k]) return -1;
			continue;
		}
		double t1 = (-hh[k] - oo[k]) / dd[k], t2 = (hh[k] - oo[k]) / dd[k];
		if (t1 > t2) { double x = t1; t1 = t2; t2 = x; }
		if (t1 > tmin) tmin = t1;
		if (t2 < tmax) tmax = t2;
	}
	if (tmax < tmin) return -1;
	if (tmin > eps) return tmin;
	if (tmax > eps) return tmax;
	return -1;
}

static double ray_occ(v3 o, v3 d, const struct occ *b, double eps)
{
	return b->box ? ray_box(o, d, b, eps) : gpu_ray_sphere(o, d, b->c, b->r, eps);
}

/* Nearest occluder hit along o + t d (t > eps), -1 when none. */
double ray_occs(v3 o, v3 d, const struct occ *oc, int n, double eps)
{
	double best = -1;
	for (int k = 0; k < n; k++) {
		double t = ray_occ(o, d, &oc[k], eps);
		if (t > 0 && (best < 0 || t < best)) best = t;
	}
	return best;
}

/* Is p in the shadow of a point light at lp (segment p -> lp blocked)? */
bool point_shadowed(v3 p, v3 lp, const struct occ *oc, int n)
{
	v3 d = v3_sub(lp, p);
	for (int k = 0; k < n; k++) {
		double t = ray_occ(p, d, &oc[k], 1e-9);
		if (t > 0 && t < 1) return true;
	}
	return false;
}

/* JSON objects for the occluders, appended to buf. */
void occ_json(char *buf, size_t n, const struct occ *oc, int count, int segments)
{
	size_t len = strlen(buf);
	for (int k = 0; k < count; k++) {
		char c[96];
		fmt_v3(c, sizeof c, oc[k].c);
		if (oc[k].box)
			len += snprintf(buf + len, n - len,
			                ",{'shape':'box','size':[%.9g,%.9g,%.9g],'transform':{'translation':%s,"
			                "'rotation':[0,%.9g,0,%.9g]}}",
			                2 * oc[k].half.x, 2 * oc[k].half.y, 2 * oc[k].half.z, c, sin(oc[k].yaw / 2),
			                cos(oc[k].yaw / 2));
		else
			len += snprintf(buf + len, n - len,
			                ",{'shape':'sphere','radius':%.9g,'segments':%d,'transform':{'translation':%s}}",
			                oc[k].r, segments, c);
	}
}

void cam_json(char *buf, size_t n, bool ortho, v3 pos, v3 tgt, v3 up, double fov_or_h)
{
	char p[96], t[96], u[96];
	fmt_v3(p, sizeof p, pos);
	fmt_v3(t, sizeof t, tgt);
	fmt_v3(u, sizeof u, up);
	if (ortho)
		snprintf(buf, n, "{'type':'orthographic','position':%s,'target':%s,'up':%s,'height':%.9g}", p, t, u, fov_or_h);
	else
		snprintf(buf, n, "{'type':'perspective','position':%s,'target':%s,'up':%s,'fov_y':%.9g}", p, t, u, fov_or_h);
}

void cam_make(struct gpu_cam *c, bool ortho, v3 pos, v3 tgt, v3 up, double fov_or_h, int w, int h)
{
	if (ortho) gpu_cam_ortho(c, pos, tgt, up, fov_or_h, w, h);
	else gpu_cam_persp(c, pos, tgt, up, fov_or_h, w, h);
}

/* Compares a debug shadow view (img) with per-pixel classes (GPU_CLS_*): agreement over LIT /
 * SHADOW pixels with no other class within `band` pixels. */
double agreement(const struct rnd_image *img, const uint8_t *cls, int w, int h, int band, long *n_lit,
                        long *n_sh, long *bad_lit, long *bad_sh)
{
	long n = 0, agree = 0;
	*n_lit = *n_sh = *bad_lit = *bad_sh = 0;
	for (int j = 0; j < h; j++)
		for (int i = 0; i < w; i++) {
			uint8_t k = cls[(size_t)j * w + i];
			if (k != GPU_CLS_LIT && k != GPU_CLS_SHADOW) continue;
			if (gpu_near_edge(cls, w, h, i, j, band)) continue;
			bool lit = val8(img, i, j) > 127;
			n++;
			if (k == GPU_CLS_LIT) { (*n_lit)++; if (!lit) (*bad_lit)++; }
			else { (*n_sh)++; if (lit) (*bad_sh)++; }
			agree += lit == (k == GPU_CLS_LIT);
		}
	return n ? (double)agree / n : 0;
}


long image_diff(const struct rnd_image *a, const struct rnd_image *b, int tol, int *maxd)
{
	long n = 0;
	*maxd = 0;
	for (uint32_t j = 0; j < a->height; j++)
		for (uint32_t i = 0; i < a->width; i++) {
			int d = abs(val8(a, i, j) - val8(b, i, j));
			if (d > *maxd) *maxd = d;
			n += d > tol;
			if (d > tol && getenv("GPU_TEST_VERBOSE") && n <= 5)
				printf("      px (%u,%u): %d vs %d\n", i, j, val8(a, i, j), val8(b, i, j));
		}
	return n;
}
