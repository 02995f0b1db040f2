/* tests/gpu — spot and point lights (contract §2, §3, §4, §7): cube-map shadows of a point light
 * in a closed room against analytic projections, continuity across cube-face boundaries, the
 * spot cone and an oblique spot's shadow, VSM/EVSM light bleeding, the persistent shadow cache
 * (rnd_timings.shadow_maps_rendered / _reused, rnd_context_stats), many lights in a tiny atlas,
 * the atlas debug view and turntables that render camera-independent maps once.
 *
 * Everything is checked against values computed here (ray casts against the exact shapes),
 * never against the renderer's own output, except where the point is that two renders agree. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"
#include "util.h"

/* ---- rendering with timings, on any context ---- */

enum { R_FAIL = 0, R_OK = 1, R_UNSUPPORTED = 2 };

/* gpu_render_at with the render's timings and a context of the caller's choosing (NULL = the
 * binary's). allow_422: a 422 "not supported" answer from the parser is returned as
 * R_UNSUPPORTED instead of failing the test. */
static int lrender_at(const char *file, int line, struct rnd_context *ctx, struct rnd_image *img,
                      struct rnd_timings *t, bool allow_422, const char *fmt, ...)
	__attribute__((format(printf, 7, 8)));
static int lrender_at(const char *file, int line, struct rnd_context *ctx, struct rnd_image *img,
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
#define lrender(ctx, img, t, ...) lrender_at(__FILE__, __LINE__, (ctx), (img), (t), false, __VA_ARGS__)

/* A second context (validation as the binary's), e.g. with a tiny atlas. */
static struct rnd_context *make_ctx(uint32_t atlas_size, int line)
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

static int val8(const struct rnd_image *img, int i, int j) { return gpu_px8(img, i, j)[0]; }

static void fmt_v3(char *b, size_t n, v3 v) { snprintf(b, n, "[%.9g,%.9g,%.9g]", v.x, v.y, v.z); }

/* ---- analytic occluders: spheres and boxes (rotated about Y by yaw) ---- */

struct occ {
	bool box;
	v3 c;
	double r;      /* sphere */
	v3 half;       /* box half sizes */
	double yaw;    /* box rotation about +Y, radians */
};

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
static double ray_occs(v3 o, v3 d, const struct occ *oc, int n, double eps)
{
	double best = -1;
	for (int k = 0; k < n; k++) {
		double t = ray_occ(o, d, &oc[k], eps);
		if (t > 0 && (best < 0 || t < best)) best = t;
	}
	return best;
}

/* Is p in the shadow of a point light at lp (segment p -> lp blocked)? */
static bool point_shadowed(v3 p, v3 lp, const struct occ *oc, int n)
{
	v3 d = v3_sub(lp, p);
	for (int k = 0; k < n; k++) {
		double t = ray_occ(p, d, &oc[k], 1e-9);
		if (t > 0 && t < 1) return true;
	}
	return false;
}

/* JSON objects for the occluders, appended to buf. */
static void occ_json(char *buf, size_t n, const struct occ *oc, int count, int segments)
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

static void cam_json(char *buf, size_t n, bool ortho, v3 pos, v3 tgt, v3 up, double fov_or_h)
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

static void cam_make(struct gpu_cam *c, bool ortho, v3 pos, v3 tgt, v3 up, double fov_or_h, int w, int h)
{
	if (ortho) gpu_cam_ortho(c, pos, tgt, up, fov_or_h, w, h);
	else gpu_cam_persp(c, pos, tgt, up, fov_or_h, w, h);
}

/* Compares a debug shadow view (img) with per-pixel classes (GPU_CLS_*): agreement over LIT /
 * SHADOW pixels with no other class within `band` pixels. */
static double agreement(const struct rnd_image *img, const uint8_t *cls, int w, int h, int band, long *n_lit,
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

/* ======================================================================================== */
/* 1. Point light in a closed room, occluders in all six directions                          */
/* ======================================================================================== */

#define ROOM_X 4.0   /* x, z in [-4, 4] */
#define ROOM_H 5.0   /* y in [0, 5] */

/* First hit of a ray from inside the room with its walls; *axis = 0/1/2 (x/y/z). */
static double room_hit(v3 o, v3 d, int *axis)
{
	double best = 1e300;
	double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
	double lo[3] = {-ROOM_X, 0, -ROOM_X}, hi[3] = {ROOM_X, ROOM_H, ROOM_X};
	for (int k = 0; k < 3; k++) {
		if (fabs(dd[k]) < 1e-15) continue;
		double t = ((dd[k] > 0 ? hi[k] : lo[k]) - oo[k]) / dd[k];
		if (t > 0 && t < best) { best = t; *axis = k; }
	}
	return best < 1e299 ? best : -1;
}

/* Near an edge of the room (where two walls meet)? */
static bool room_corner(v3 p, double m)
{
	int near = 0;
	near += fabs(fabs(p.x) - ROOM_X) < m;
	near += fabs(fabs(p.z) - ROOM_X) < m;
	near += p.y < m || p.y > ROOM_H - m;
	return near >= 2;
}

TEST(lights_point_room_six_directions)
{
	const v3 L = v3_make(0.3, 2.4, -0.2);
	const double D = 1.2;
	/* Spheres on +-x and +-z, cubes on +-y (the floor and the ceiling). */
	struct occ oc[6] = {
		{false, v3_add(L, v3_make(D, 0, 0)), 0.3, {0}, 0},
		{false, v3_add(L, v3_make(-D, 0, 0)), 0.3, {0}, 0},
		{true, v3_add(L, v3_make(0, D, 0)), 0, {0.25, 0.25, 0.25}, 0},
		{true, v3_add(L, v3_make(0, -D, 0)), 0, {0.25, 0.25, 0.25}, 0.3},
		{false, v3_add(L, v3_make(0, 0, D)), 0.3, {0}, 0},
		{false, v3_add(L, v3_make(0, 0, -D)), 0.3, {0}, 0},
	};
	const char *names[6] = {"+x sphere", "-x sphere", "+y cube", "-y cube", "+z sphere", "-z sphere"};
	char objs[4096] =
		"{'shape':'plane','size':[8,8]},"
		"{'shape':'plane','size':[8,8],'transform':{'translation':[0,5,0]}},"
		"{'shape':'plane','size':[5,8],'transform':{'translation':[4,2.5,0],'rotation':[0,0,0.70710678,0.70710678]}},"
		"{'shape':'plane','size':[5,8],'transform':{'translation':[-4,2.5,0],'rotation':[0,0,0.70710678,0.70710678]}},"
		"{'shape':'plane','size':[8,5],'transform':{'translation':[0,2.5,4],'rotation':[0.70710678,0,0,0.70710678]}},"
		"{'shape':'plane','size':[8,5],'transform':{'translation':[0,2.5,-4],'rotation':[0.70710678,0,0,0.70710678]}}";
	occ_json(objs, sizeof objs, oc, 6, 48);

	/* Expected shadow centre of each occluder: the ray from the light through its centre. */
	v3 centre[6];
	for (int k = 0; k < 6; k++) {
		int ax;
		v3 d = v3_norm(v3_sub(oc[k].c, L));
		centre[k] = v3_add(L, v3_scale(d, room_hit(L, d, &ax)));
	}

	struct { bool ortho; v3 pos, tgt, up; double f; const char *label; } cams[] = {
		{false, {-3.5, 4.5, -3.5}, {1.5, 1.2, 1.5}, {0, 1, 0}, 90, "persp: floor, +x, +z walls"},
		{false, {3.5, 0.5, 3.5}, {-1.5, 3.8, -1.5}, {0, 1, 0}, 90, "persp: ceiling, -x, -z walls"},
		{true, {0.3, 4.9, -0.2}, {0.3, 0, -0.2}, {0, 0, -1}, 7.9, "ortho: floor from below the ceiling"},
		{true, {0.3, 2.5, 3.9}, {0.3, 2.5, 0}, {0, 1, 0}, 4.9, "ortho: -z wall"},
	};
	const int W = 160, H = 160;
	int centre_checked[6] = {0}, ring_checked[6] = {0};
	uint8_t *cls = malloc((size_t)W * H);
	for (size_t ci = 0; ci < sizeof cams / sizeof cams[0]; ci++) {
		char cj[512];
		cam_json(cj, sizeof cj, cams[ci].ortho, cams[ci].pos, cams[ci].tgt, cams[ci].up, cams[ci].f);
		struct gpu_cam cam;
		cam_make(&cam, cams[ci].ortho, cams[ci].pos, cams[ci].tgt, cams[ci].up, cams[ci].f, W, H);
		struct rnd_image img;
		if (!lrender(NULL, &img, NULL,
		             "{'width':%d,'height':%d,'camera':%s,'objects':[%s],"
		             "'lights':[{'type':'point','position':[%.9g,%.9g,%.9g]}],"
		             "'output':{'debug':'shadow','msaa':1}}",
		             W, H, cj, objs, L.x, L.y, L.z))
			continue;
		for (int j = 0; j < H; j++)
			for (int i = 0; i < W; i++) {
				v3 o, d;
				gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
				int ax = -1;
				double tr = room_hit(o, d, &ax), to = ray_occs(o, d, oc, 6, 0);
				uint8_t k;
				if (tr < 0) k = GPU_CLS_SKIP;
				else if (to > 0 && to < tr) k = GPU_CLS_OBJ;
				else {
					v3 p = v3_add(o, v3_scale(d, tr));
					if (room_corner(p, 0.04)) k = GPU_CLS_SKIP;
					else k = point_shadowed(p, L, oc, 6) ? GPU_CLS_SHADOW : GPU_CLS_LIT;
				}
				cls[(size_t)j * W + i] = k;
			}
		long nl, ns, bl, bs;
		double f = agreement(&img, cls, W, H, 2, &nl, &ns, &bl, &bs);
		printf("    [room, %s] agreement %.3f%% (%ld lit, %ld shadow px; %ld lit read as shadow, %ld shadow read as lit)\n",
		       cams[ci].label, 100 * f, nl, ns, bl, bs);
		CHECK(f >= 0.99, "[%s] agreement with the analytic point-light shadows %.3f%% < 99%%", cams[ci].label, 100 * f);
		CHECK(ns >= 50 && nl >= 500, "[%s] coverage: %ld lit, %ld shadow px", cams[ci].label, nl, ns);

		/* Per occluder: the shadow centre reads dark; points two shadow radii away on the same
		 * wall read lit (where the analytic classification agrees and the camera sees them). */
		for (int k = 0; k < 6; k++) {
			int ax;
			v3 d = v3_norm(v3_sub(oc[k].c, L));
			room_hit(L, d, &ax);
			double dist = v3_len(v3_sub(centre[k], L)), oc_dist = v3_len(v3_sub(oc[k].c, L));
			double rad = (oc[k].box ? 0.25 * sqrt(2.0) : oc[k].r) * dist / oc_dist;
			v3 t1 = ax == 0 ? v3_make(0, 1, 0) : v3_make(1, 0, 0), t2 = ax == 2 ? v3_make(0, 1, 0) : v3_make(0, 0, 1);
			v3 pts[5] = {centre[k], v3_add(centre[k], v3_scale(t1, 2 * rad)), v3_sub(centre[k], v3_scale(t1, 2 * rad)),
			             v3_add(centre[k], v3_scale(t2, 2 * rad)), v3_sub(centre[k], v3_scale(t2, 2 * rad))};
			for (int q = 0; q < 5; q++) {
				v3 p = pts[q];
				if (fabs(p.x) > ROOM_X - 0.1 + (ax == 0) || fabs(p.z) > ROOM_X - 0.1 + (ax == 2) ||
				    (ax != 1 && (p.y < 0.1 || p.y > ROOM_H - 0.1)))
					continue;
				double px, py;
				if (!gpu_cam_project(&cam, p, &px, &py)) continue;
				if (px < 3 || py < 3 || px > W - 3 || py > H - 3) continue;
				int i = (int)px, j = (int)py;
				if (cls[(size_t)j * W + i] == GPU_CLS_OBJ || cls[(size_t)j * W + i] == GPU_CLS_SKIP) continue;
				/* The camera must see p itself (not an occluder in front of it). */
				v3 o, dd;
				gpu_cam_ray(&cam, px, py, &o, &dd);
				double to = ray_occs(o, dd, oc, 6, 0);
				if (to > 0 && to < v3_len(v3_sub(p, o)) - 1e-6) continue;
				bool expect_shadow = point_shadowed(p, L, oc, 6);
				if (q == 0 && !expect_shadow) continue;
				if (q > 0 && expect_shadow) continue;
				int v = val8(&img, i, j);
				if (q == 0) {
					centre_checked[k]++;
					CHECK(v < 64, "[%s] %s: shadow centre (%.2f,%.2f,%.2f) at px (%d,%d) reads %d, expected dark",
					      cams[ci].label, names[k], p.x, p.y, p.z, i, j, v);
				} else {
					ring_checked[k]++;
					CHECK(v > 191, "[%s] %s: lit point (%.2f,%.2f,%.2f) at px (%d,%d) reads %d, expected lit",
					      cams[ci].label, names[k], p.x, p.y, p.z, i, j, v);
				}
			}
		}
		rnd_image_release(&img);
	}
	for (int k = 0; k < 6; k++) {
		printf("    [room] %s: shadow centre (%.2f,%.2f,%.2f) checked in %d view(s), %d lit points around it\n",
		       names[k], centre[k].x, centre[k].y, centre[k].z, centre_checked[k], ring_checked[k]);
		CHECK(centre_checked[k] >= 1, "%s: no camera saw the centre of its shadow (cube face not covered)", names[k]);
		CHECK(ring_checked[k] >= 2, "%s: only %d lit points around its shadow checked", names[k], ring_checked[k]);
	}
	free(cls);
}

/* ======================================================================================== */
/* 2. No seams where cube faces meet                                                          */
/* ======================================================================================== */

TEST(lights_point_no_seam_open_floor)
{
	/* Point light 2 m above a 20 x 20 plane, nothing else: the whole floor is lit, including
	 * the cube-face boundaries |x| = 2 or |z| = 2 (bottom face / side faces) and the diagonals
	 * |x| = |z| (side faces). */
	const int W = 192, H = 192;
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(0, 10, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), 16, W, H);
	struct rnd_image img;
	if (!lrender(NULL, &img, NULL,
	             "{'width':%d,'height':%d,"
	             "'camera':{'type':'orthographic','position':[0,10,0],'target':[0,0,0],'up':[0,0,-1],'height':16},"
	             "'objects':[{'shape':'plane','size':[20,20]}],"
	             "'lights':[{'type':'point','position':[0,2,0]}],'output':{'debug':'shadow','msaa':1}}",
	             W, H))
		return;
	long n = 0, ok = 0, nb = 0, okb = 0;
	int minv = 255, minb = 255;
	for (int j = 0; j < H; j++)
		for (int i = 0; i < W; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			if (gpu_ray_ground(o, d, 0, 0, 0, 10) < 0) continue;
			int v = val8(&img, i, j);
			n++;
			ok += v >= 250;
			if (v < minv) minv = v;
			/* Within 2 px (0.17 m) of a face boundary. */
			double ax = fabs(o.x), az = fabs(o.z), px = 16.0 / H;
			bool boundary = (fabs(ax - az) < 2 * px * 1.5 && ax > 2 - 2 * px) ||
			                (fabs(ax - 2) < 2 * px && az < 2) || (fabs(az - 2) < 2 * px && ax < 2);
			if (boundary) { nb++; okb += v >= 250; if (v < minb) minb = v; }
		}
	rnd_image_release(&img);
	double f = n ? (double)ok / n : 0;
	printf("    [open floor] %.3f%% of %ld floor px >= 250 (min %d); near face boundaries %ld/%ld (min %d)\n", 100 * f, n,
	       minv, okb, nb, minb);
	CHECK(n > 30000, "coverage %ld", n);
	CHECK(f >= 0.999, "only %.3f%% of the floor is lit (>= 250)", 100 * f);
	CHECK(nb > 500 && okb == nb, "%ld of %ld px along the cube-face boundaries are < 250 (min %d)", nb - okb, nb, minb);
}

/* Visibility (0..1) at world point p of a debug image seen by cam; -1 outside. */
static double vis_at(const struct rnd_image *img, const struct gpu_cam *cam, v3 p, int *pi, int *pj)
{
	double px, py;
	gpu_cam_project(cam, p, &px, &py);
	int i = (int)floor(px), j = (int)floor(py);
	if (i < 0 || j < 0 || i >= (int)img->width || j >= (int)img->height) return -1;
	if (pi) *pi = i;
	if (pj) *pj = j;
	return val8(img, i, j) / 255.0;
}

TEST(lights_point_no_seam_shadow_across_faces)
{
	/* Two bars 1 m above the floor under a point light at (0, 2, 0):
	 *  bar 1 along x, its shadow (x ~ 1..3, |z| < 0.2) crosses x = 2, the boundary between the
	 *        bottom cube face and the +x face;
	 *  bar 2 turned 45 degrees, its shadow (around (2.6, 0, 2.6), long along (1, 0, -1)) crosses
	 *        the diagonal x = z between the +x and +z faces. */
	const v3 L = v3_make(0, 2, 0);
	struct occ oc[2] = {
		{true, {1.0, 1.0, 0}, 0, {0.5, 0.02, 0.1}, 0},
		{true, {1.3, 1.0, 1.3}, 0, {0.5, 0.02, 0.1}, GPU_PI / 4},
	};
	char objs[2048] = "{'shape':'plane','size':[20,20]}";
	occ_json(objs, sizeof objs, oc, 2, 0);
	const int W = 192, H = 192;
	const double VH = 4.6;
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(2.1, 10, 1.5), v3_make(2.1, 0, 1.5), v3_make(0, 0, -1), VH, W, H);
	const char *filters[] = {"'filter':'pcf'", "'filter':'hard'"};
	uint8_t *cls = malloc((size_t)W * H);
	for (int j = 0; j < H; j++)
		for (int i = 0; i < W; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			double tg = gpu_ray_ground(o, d, 0, 0, 0, 10), to = ray_occs(o, d, oc, 2, 0);
			uint8_t k = tg < 0 ? GPU_CLS_BG : to > 0 && to < tg ? GPU_CLS_OBJ
			          : point_shadowed(v3_add(o, v3_scale(d, tg)), L, oc, 2) ? GPU_CLS_SHADOW : GPU_CLS_LIT;
			cls[(size_t)j * W + i] = k;
		}
	const double px = VH / H;
	for (int fi = 0; fi < 2; fi++) {
		struct rnd_image img;
		if (!lrender(NULL, &img, NULL,
		             "{'width':%d,'height':%d,"
		             "'camera':{'type':'orthographic','position':[2.1,10,1.5],'target':[2.1,0,1.5],'up':[0,0,-1],'height':%.9g},"
		             "'objects':[%s],'lights':[{'type':'point','position':[0,2,0],'shadow':{%s}}],"
		             "'output':{'debug':'shadow','msaa':1}}",
		             W, H, VH, objs, filters[fi]))
			continue;
		long nl, ns, bl, bs;
		double f = agreement(&img, cls, W, H, 2, &nl, &ns, &bl, &bs);
		printf("    [seams, %s] analytic agreement %.3f%% (%ld lit, %ld shadow px; %ld/%ld wrong)\n", filters[fi], 100 * f,
		       nl, ns, bl, bs);
		CHECK(f >= 0.995, "[%s] agreement %.3f%%", filters[fi], 100 * f);

		/* Lines perpendicular to each face boundary, at offsets inside the shadow and outside
		 * it (away from the analytic edges): no jump > 0.5 between neighbouring pixels, inside
		 * dark, outside lit, all the way across the boundary. */
		struct { v3 c, u, w; double s0, s1; double offs[7]; const char *label; } bars[2] = {
			/* bar 1: along x from 1.6 to 2.9 (its ends are at ~0.98 and ~3.06; the bar itself
			 * hides x < 1.5 near z = 0), offsets along z */
			{{2.25, 0, 0}, {1, 0, 0}, {0, 0, 1}, -0.65, 0.65, {0, -0.1, 0.1, -0.33, 0.33, -0.45, 0.45},
			 "bar 1 across x = 2 (bottom/+x)"},
			/* bar 2: along u = (1,0,-1)/sqrt2 through the diagonal, offsets along (1,0,1)/sqrt2;
			 * seen from the light at an angle, the 4 cm thick bar's shadow spans about -0.27 ..
			 * +0.28 across */
			{{2.6, 0, 2.6}, {M_SQRT1_2, 0, -M_SQRT1_2}, {M_SQRT1_2, 0, M_SQRT1_2}, -0.75, 0.75,
			 {0, -0.12, 0.12, -0.4, 0.4, -0.5, 0.5}, "bar 2 across x = z (+x/+z)"},
		};
		for (int b = 0; b < 2; b++) {
			const double *offs = bars[b].offs;
			for (size_t oi = 0; oi < 7; oi++) {
				bool inside = fabs(offs[oi]) < 0.2;
				double maxjump = 0, prev = -1, worst = inside ? 0 : 1;
				int npts = 0, wi = -1, wj = -1;
				for (double s = bars[b].s0; s <= bars[b].s1 + 1e-9; s += px * 0.5) {
					v3 p = v3_add(bars[b].c, v3_add(v3_scale(bars[b].u, s), v3_scale(bars[b].w, offs[oi])));
					int i, j;
					double v = vis_at(&img, &cam, p, &i, &j);
					if (v < 0) continue;
					/* skip pixels near an analytic class change (bar ends, the bar itself) */
					if (gpu_near_edge(cls, W, H, i, j, 2) || cls[(size_t)j * W + i] == GPU_CLS_OBJ) { prev = -1; continue; }
					npts++;
					if (prev >= 0 && fabs(v - prev) > maxjump) maxjump = fabs(v - prev);
					prev = v;
					if (inside ? v > worst : v < worst) { worst = v; wi = i; wj = j; }
				}
				if (getenv("GPU_TEST_VERBOSE"))
					printf("      [%s, %s] offset %+.2f: %d px, max jump %.3f, %s %.3f\n", filters[fi], bars[b].label,
					       offs[oi], npts, maxjump, inside ? "max" : "min", worst);
				CHECK(npts >= 20, "[%s, %s] offset %+.2f: only %d samples", filters[fi], bars[b].label, offs[oi], npts);
				CHECK(maxjump <= 0.5, "[%s, %s] offset %+.2f: visibility jumps by %.3f between neighbouring px",
				      filters[fi], bars[b].label, offs[oi], maxjump);
				if (inside)
					CHECK(worst <= 0.1, "[%s, %s] inside the shadow (offset %+.2f) px (%d,%d) reads %.3f",
					      filters[fi], bars[b].label, offs[oi], wi, wj, worst);
				else
					CHECK(worst >= 250 / 255.0, "[%s, %s] outside the shadow (offset %+.2f) px (%d,%d) reads %.3f",
					      filters[fi], bars[b].label, offs[oi], wi, wj, worst);
			}
		}
		/* Bar 1's long edges (z = +-0.2 * scale): the 50% crossing, found per pixel column
		 * from the centre outwards, follows the analytic edge within 1.5 px on both sides of
		 * x = 2, and moves by at most 1.5 px between neighbouring columns. */
		double max_dev = 0, max_step = 0;
		int cols = 0;
		for (int side = -1; side <= 1; side += 2) {
			double prev_edge = NAN;
			for (double x = 1.6; x <= 2.9; x += px) {
				/* analytic: first lit pixel centre moving outwards along z */
				double an = NAN, me = NAN;
				double prev_v = -1;
				for (double z = 0; z <= 0.5; z += px / 4) {
					v3 p = v3_make(x, 0, side * z);
					if (isnan(an) && !point_shadowed(p, L, oc, 2)) an = z;
					double v = vis_at(&img, &cam, p, NULL, NULL);
					if (isnan(me) && prev_v >= 0 && prev_v < 0.5 && v >= 0.5) me = z;
					prev_v = v;
				}
				if (isnan(an) || isnan(me)) { max_dev = INFINITY; continue; }
				cols++;
				double dev = fabs(me - an) / px;
				if (dev > max_dev) max_dev = dev;
				if (!isnan(prev_edge) && fabs(me - prev_edge) / px > max_step) max_step = fabs(me - prev_edge) / px;
				prev_edge = me;
			}
		}
		printf("    [seams, %s] bar 1 edge across x = 2: %d columns, max deviation from analytic %.2f px, max step %.2f px\n",
		       filters[fi], cols, max_dev, max_step);
		CHECK(max_dev <= 1.5, "[%s] bar 1 shadow edge deviates %.2f px from the analytic edge", filters[fi], max_dev);
		CHECK(max_step <= 1.5, "[%s] bar 1 shadow edge steps %.2f px between neighbouring columns", filters[fi], max_step);
		rnd_image_release(&img);
	}
	free(cls);
}

/* ======================================================================================== */
/* 3. Spot: the cone, and an oblique spot's shadow                                          */
/* ======================================================================================== */

TEST(lights_spot_cone_black_outside)
{
	/* Beauty with no ambient and no tone map: ground outside the outer cone is black (0);
	 * inside the inner cone at least 80% of the Lambert term alone (the GGX lobe only adds). */
	const v3 lp = v3_make(-2, 3, 0.5), ld = v3_make(1, -1, 0.2);
	const double outer = 30, inner = 25, intensity = 40;
	const int W = 160, H = 160;
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(1, 10, 0.5), v3_make(1, 0, 0.5), v3_make(0, 0, -1), 12, W, H);
	struct rnd_image img;
	if (!lrender(NULL, &img, NULL,
	             "{'width':%d,'height':%d,"
	             "'camera':{'type':'orthographic','position':[1,10,0.5],'target':[1,0,0.5],'up':[0,0,-1],'height':12},"
	             "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	             "'objects':[{'shape':'plane','size':[16,16]},"
	             "{'shape':'sphere','radius':0.4,'segments':32,'transform':{'translation':[0,1,0.9]}}],"
	             "'lights':[{'type':'spot','position':[%.9g,%.9g,%.9g],'direction':[%.9g,%.9g,%.9g],"
	             "'outer_angle':%.9g,'inner_angle':%.9g,'intensity':%.9g}],'output':{'msaa':1,'tonemap':'none'}}",
	             W, H, lp.x, lp.y, lp.z, ld.x, ld.y, ld.z, outer, inner, intensity))
		return;
	v3 dn = v3_norm(ld);
	long n_out = 0, bad_out = 0, n_in = 0, bad_in = 0;
	int max_out = 0, wi = -1, wj = -1, wv = 0;
	double worst = 1e9, wpred = 0;
	for (int j = 0; j < H; j++)
		for (int i = 0; i < W; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			double tg = gpu_ray_ground(o, d, 0, 0, 0, 8);
			if (tg < 0) continue;
			v3 p = v3_add(o, v3_scale(d, tg));
			if (gpu_ray_sphere(o, d, v3_make(0, 1, 0.9), 0.45, 0) > 0) continue;  /* the sphere and its rim */
			v3 to = v3_sub(p, lp);
			double ang = acos(v3_dot(v3_norm(to), dn)) / GPU_DEG;
			const uint8_t *q = gpu_px8(&img, i, j);
			int mx = q[0] > q[1] ? q[0] : q[1];
			if (q[2] > mx) mx = q[2];
			if (ang > outer + 1) {
				n_out++;
				if (mx > 0) bad_out++;
				if (mx > max_out) max_out = mx;
			} else if (ang < inner - 1) {
				/* lit unless the sphere shadows it (with a margin for the filter) */
				if (gpu_ray_sphere(p, v3_sub(lp, p), v3_make(0, 1, 0.9), 0.5, 1e-9) > 0) continue;
				double d2 = v3_dot(to, to), cosi = -to.y / sqrt(d2);
				double lin = 0.8 / GPU_PI * intensity * cosi / d2;   /* Lambert, base colour 0.8 */
				double pred = 255 * gpu_srgb_encode(fmin(0.8 * lin, 1.0));
				n_in++;
				if (q[1] < pred - 1) bad_in++;
				if (q[1] - pred < worst) { worst = q[1] - pred; wi = i; wj = j; wv = q[1]; wpred = pred; }
			}
		}
	rnd_image_release(&img);
	printf("    [spot cone] outside the cone: %ld px, max value %d; inside the inner cone: %ld px, %ld below 80%% of "
	       "the Lambert prediction (worst px (%d,%d) %d vs %.1f)\n",
	       n_out, max_out, n_in, bad_in, wi, wj, wv, wpred);
	CHECK(n_out > 5000 && n_in > 1000, "coverage: %ld outside, %ld inside", n_out, n_in);
	CHECK(bad_out == 0, "%ld ground px outside the outer cone are not black (max %d)", bad_out, max_out);
	CHECK(bad_in == 0, "%ld ground px inside the inner cone are darker than predicted (worst (%d,%d): %d vs %.1f)", bad_in,
	      wi, wj, wv, wpred);
}

TEST(lights_spot_oblique_analytic)
{
	/* A hard point-like spot low over the ground (about 40 degrees from vertical, aimed past
	 * the sphere): a long, skewed shadow. */
	const v3 lp = v3_make(-3, 3.2, 1.0), ld = v3_make(3.5, -3.2, -1.3);
	const v3 sc = v3_make(-0.8, 1.2, 0.3);
	const double sr = 0.6, outer = 40;
	const int W = 192, H = 192;
	struct gpu_cam cam;
	const v3 cpos = v3_make(2, 8, 6), ctgt = v3_make(0.5, 0, -0.3);
	gpu_cam_persp(&cam, cpos, ctgt, v3_make(0, 1, 0), 55, W, H);
	uint8_t *cls = malloc((size_t)W * H);
	v3 dn = v3_norm(ld);
	double cos_lim = cos((outer - 3) * GPU_DEG);
	for (int j = 0; j < H; j++)
		for (int i = 0; i < W; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			double ts = gpu_ray_sphere(o, d, sc, sr, 0), tg = gpu_ray_ground(o, d, 0, 0, 0, 10);
			uint8_t k;
			if (ts < 0 && tg < 0) k = GPU_CLS_BG;
			else if (ts > 0 && (tg < 0 || ts < tg)) k = GPU_CLS_OBJ;
			else {
				v3 p = v3_add(o, v3_scale(d, tg));
				double t = gpu_ray_sphere(p, v3_sub(lp, p), sc, sr, 1e-9);
				k = t > 0 && t < 1 ? GPU_CLS_SHADOW : GPU_CLS_LIT;
				if (v3_dot(v3_norm(v3_sub(p, lp)), dn) < cos_lim) k = GPU_CLS_SKIP;
			}
			cls[(size_t)j * W + i] = k;
		}
	const char *filters[] = {"'filter':'hard'", "'filter':'pcf','pcf_radius':1", "'filter':'pcf','pcf_radius':3"};
	for (int fi = 0; fi < 3; fi++) {
		struct rnd_image img;
		if (!lrender(NULL, &img, NULL,
		             "{'width':%d,'height':%d,"
		             "'camera':{'type':'perspective','position':[2,8,6],'target':[0.5,0,-0.3],'up':[0,1,0],'fov_y':55},"
		             "'objects':[{'shape':'plane','size':[20,20]},"
		             "{'shape':'sphere','radius':%.9g,'segments':96,'transform':{'translation':[%.9g,%.9g,%.9g]}}],"
		             "'lights':[{'type':'spot','position':[%.9g,%.9g,%.9g],'direction':[%.9g,%.9g,%.9g],"
		             "'outer_angle':%.9g,'radius':0,'shadow':{%s}}],'output':{'debug':'shadow','msaa':1}}",
		             W, H, sr, sc.x, sc.y, sc.z, lp.x, lp.y, lp.z, ld.x, ld.y, ld.z, outer, filters[fi]))
			continue;
		long nl, ns, bl, bs;
		double f = agreement(&img, cls, W, H, 2, &nl, &ns, &bl, &bs);
		/* background (no geometry) reads 255 */
		long bg = 0, bg_ok = 0;
		for (int j = 0; j < H; j++)
			for (int i = 0; i < W; i++)
				if (cls[(size_t)j * W + i] == GPU_CLS_BG && !gpu_near_edge(cls, W, H, i, j, 1)) {
					bg++;
					bg_ok += val8(&img, i, j) == 255;
				}
		printf("    [oblique spot, %s] agreement %.3f%% (%ld lit, %ld shadow; %ld lit-as-shadow, %ld shadow-as-lit); "
		       "background %ld/%ld\n",
		       filters[fi], 100 * f, nl, ns, bl, bs, bg_ok, bg);
		CHECK(ns >= 300 && nl >= 3000, "[%s] coverage: %ld lit, %ld shadow", filters[fi], nl, ns);
		CHECK(f >= 0.995, "[%s] agreement %.3f%% < 99.5%%", filters[fi], 100 * f);
		CHECK(bg_ok == bg, "[%s] %ld background px are not 255", filters[fi], bg - bg_ok);
		rnd_image_release(&img);
	}
	free(cls);
}

/* ======================================================================================== */
/* 4. VSM / EVSM light bleeding                                                              */
/* ======================================================================================== */

/* Plate A: 2 x 0.02 x 2 at height 1 over x, z in [-1, 1]; plate B: the same at height 2 over
 * x in [0, 2]. Ground region kinds by where the ray towards the light crosses the plates. */
enum { G_LIT, G_A_ONLY, G_B_ONLY, G_BOTH, G_EDGE, G_OTHER };

static bool in_rect(double x, double z, double cx, double hx, double hz, double m)
{
	return fabs(x - cx) < hx - m && fabs(z) < hz - m;
}
static bool out_rect(double x, double z, double cx, double hx, double hz, double m)
{
	return fabs(x - cx) > hx + m || fabs(z) > hz + m;
}

/* toward: unit direction from p to the light (directional) or NULL with lpos for a spot. */
static int plate_region(v3 p, bool spot, v3 lpos, v3 toward, double m)
{
	v3 d = spot ? v3_sub(lpos, p) : toward;
	if (d.y <= 0) return G_OTHER;
	v3 a = v3_add(p, v3_scale(d, (1.0 - p.y) / d.y)), b = v3_add(p, v3_scale(d, (2.0 - p.y) / d.y));
	bool ina = in_rect(a.x, a.z, 0, 1, 1, m), outa = out_rect(a.x, a.z, 0, 1, 1, m);
	bool inb = in_rect(b.x, b.z, 1, 1, 1, m), outb = out_rect(b.x, b.z, 1, 1, 1, m);
	if (outa && outb) return G_LIT;
	if (ina && inb) return G_BOTH;
	if (ina && outb) return G_A_ONLY;
	if (inb && outa) return G_B_ONLY;
	return G_EDGE;
}

TEST(lights_vsm_evsm_light_bleeding)
{
	/* Camera under the plates (y = 0.9 < 0.99, looking down): it sees only the ground. */
	const int W = 192, H = 160;
	struct gpu_cam cam;
	gpu_cam_persp(&cam, v3_make(0.6, 0.9, 2.5), v3_make(0.6, 0, -0.5), v3_make(0, 1, 0), 60, W, H);
	const v3 spot = v3_make(0.2, 6, 0.1);
	const v3 sun = v3_norm(v3_make(-0.15, -1, 0.1)); /* the way the light travels */
	/* kind: 0 spot, 1 point (both at `spot`), 2 sun */
	struct { int kind; const char *filter; double bound; int res; } cases[] = {
		{0, "vsm", 0.3, 512}, {0, "evsm", 0.1, 512}, {1, "vsm", 0.3, 512},
		{1, "evsm", 0.1, 512}, {2, "vsm", 0.3, 1024}, {2, "evsm", 0.1, 1024},
	};
	for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
		char light[512];
		bool is_spot = cases[c].kind < 2;
		if (cases[c].kind == 0)
			snprintf(light, sizeof light, "{'type':'spot','position':[%.9g,%.9g,%.9g],'direction':[0,-1,0],'outer_angle':60}",
			         spot.x, spot.y, spot.z);
		else if (cases[c].kind == 1)
			snprintf(light, sizeof light, "{'type':'point','position':[%.9g,%.9g,%.9g]}", spot.x, spot.y, spot.z);
		else
			snprintf(light, sizeof light, "{'type':'directional','direction':[%.9g,%.9g,%.9g]}", sun.x, sun.y, sun.z);
		struct rnd_image img;
		if (!lrender(NULL, &img, NULL,
		             "{'width':%d,'height':%d,"
		             "'camera':{'type':'perspective','position':[0.6,0.9,2.5],'target':[0.6,0,-0.5],'up':[0,1,0],'fov_y':60},"
		             "'objects':[{'shape':'plane','size':[12,12]},"
		             "{'shape':'box','size':[2,0.02,2],'transform':{'translation':[0,1,0]}},"
		             "{'shape':'box','size':[2,0.02,2],'transform':{'translation':[1,2,0]}}],"
		             "'lights':[%s],'shadows':{'filter':'%s','resolution':%d,'directional':{'mode':'fit'}},"
		             "'output':{'debug':'shadow','msaa':1}}",
		             W, H, light, cases[c].filter, cases[c].res))
			continue;
		long n[G_OTHER + 1] = {0}, lit_ok = 0, mid = 0, edge_n = 0;
		double sum[G_OTHER + 1] = {0}, mx[G_OTHER + 1] = {0}, mn[G_OTHER + 1];
		for (int k = 0; k <= G_OTHER; k++) mn[k] = 1;
		v3 toward = v3_scale(sun, -1);
		for (int j = 0; j < H; j++)
			for (int i = 0; i < W; i++) {
				v3 o, d;
				gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
				double tg = gpu_ray_ground(o, d, 0, 0, 0, 6);
				if (tg < 0) continue;
				v3 p = v3_add(o, v3_scale(d, tg));
				double v = val8(&img, i, j) / 255.0;
				int k = plate_region(p, is_spot, spot, toward, 0.15);
				if (k == G_EDGE) {
					/* the penumbra proper: within 5 cm of an edge (on the plates' planes) */
					if (plate_region(p, is_spot, spot, toward, 0.05) != G_EDGE) continue;
					edge_n++;
					mid += v > 0.05 && v < 0.95;
				}
				n[k]++;
				sum[k] += v;
				if (v > mx[k]) mx[k] = v;
				if (v < mn[k]) mn[k] = v;
				if (k == G_LIT) lit_ok += v >= 0.95;
			}
		rnd_image_release(&img);
		const char *lt = cases[c].kind == 0 ? "spot" : cases[c].kind == 1 ? "point" : "sun";
		printf("    [%s %s] under both plates: %ld px, mean %.3f, max %.3f (bound %.2f); under A only: mean %.3f max %.3f; "
		       "under B only: mean %.3f max %.3f; lit: %ld px, min %.3f, %.2f%% >= 0.95; penumbra: %ld of %ld px "
		       "strictly between 0.05 and 0.95\n",
		       lt, cases[c].filter, n[G_BOTH], n[G_BOTH] ? sum[G_BOTH] / n[G_BOTH] : -1, mx[G_BOTH], cases[c].bound,
		       n[G_A_ONLY] ? sum[G_A_ONLY] / n[G_A_ONLY] : -1, mx[G_A_ONLY],
		       n[G_B_ONLY] ? sum[G_B_ONLY] / n[G_B_ONLY] : -1, mx[G_B_ONLY], n[G_LIT], mn[G_LIT],
		       n[G_LIT] ? 100.0 * lit_ok / n[G_LIT] : 0, mid, edge_n);
		CHECK(n[G_BOTH] >= 300 && n[G_LIT] >= 1000 && n[G_A_ONLY] >= 100, "[%s %s] coverage: %ld both, %ld lit, %ld A only",
		      lt, cases[c].filter, n[G_BOTH], n[G_LIT], n[G_A_ONLY]);
		CHECK(mx[G_BOTH] <= cases[c].bound, "[%s %s] light bleeding under both plates: max visibility %.3f > %.2f", lt,
		      cases[c].filter, mx[G_BOTH], cases[c].bound);
		CHECK(mx[G_A_ONLY] <= cases[c].bound && mx[G_B_ONLY] <= cases[c].bound,
		      "[%s %s] under one plate: max visibility %.3f (A), %.3f (B) > %.2f", lt, cases[c].filter, mx[G_A_ONLY],
		      mx[G_B_ONLY], cases[c].bound);
		CHECK(lit_ok == n[G_LIT], "[%s %s] %ld of %ld fully lit px read < 0.95 (min %.3f)", lt, cases[c].filter,
		      n[G_LIT] - lit_ok, n[G_LIT], mn[G_LIT]);
		if (strcmp(cases[c].filter, "vsm") == 0)
			CHECK(mid >= 10, "[%s vsm] penumbra is not soft: %ld of %ld edge px have intermediate values", lt, mid, edge_n);
	}
}

/* ======================================================================================== */
/* 5. The shadow cache: reuse across requests                                                */
/* ======================================================================================== */

#define REUSE_SCENE                                                                                        \
	"{'width':144,'height':144,'camera':%s,"                                                               \
	"'objects':[{'shape':'plane','size':[12,12]},"                                                         \
	"{'shape':'sphere','radius':0.6,'segments':48,'transform':{'translation':[%.9g,0.8,0]}},"              \
	"{'shape':'box','size':[0.6,0.6,0.6],'transform':{'translation':[-1.8,0.3,-1.7]}},"                    \
	"{'shape':'cylinder','radius':0.3,'height':1,'segments':24,'transform':{'translation':[1.6,0.5,1.7]}}]," \
	"'lights':[{'type':'spot','position':[%.9g,4,2],'direction':[3,-4,-2],'outer_angle':45},"              \
	"{'type':'spot','position':[3,4.5,1],'direction':[-3,-4.5,-1.5],'outer_angle':40},"                    \
	"{'type':'point','position':[0.5,3,%.9g]}],"                                                           \
	"'shadows':{'enabled':true,'filter':'pcf'%s},'output':{'debug':'shadow','debug_light':%d,'msaa':1}}"

/* The sequence runs at a fixed 512 per map, so that the atlas holds several variants of the
 * scene at once (whatever the renderer's own choice of resolution). */
static const char *g_reuse_res = ",'resolution':512";

static int reuse_render(int line, struct rnd_context *ctx, struct rnd_image *img, struct rnd_timings *t, const char *cam,
                        double sphere_x, double spot_x, double point_z, int debug_light)
{
	return lrender_at(__FILE__, line, ctx, img, t, false, REUSE_SCENE, cam, sphere_x, spot_x, point_z, g_reuse_res,
	                  debug_light);
}

static long image_diff(const struct rnd_image *a, const struct rnd_image *b, int tol, int *maxd)
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

TEST(lights_shadow_cache_reuse)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	const char *camA = "{'type':'perspective','position':[5,6,7],'target':[0,0.5,0],'up':[0,1,0],'fov_y':50}";
	const char *camB = "{'type':'perspective','position':[-6,5,-5],'target':[0,0.5,0],'up':[0,1,0],'fov_y':50}";
	/* A sphere x of 0.0004321 keeps this scene's keys apart from any other test's. */
	const double sx = 0.0004321, spx = -3, pz = -2.5;
	struct rnd_stats s0, s1;
	struct rnd_timings t;
	struct rnd_image a, b, b2;

	/* Renderer-chosen resolution: a second camera close to the first reuses every map. */
	{
		g_reuse_res = "";
		const double sx0 = 0.0001234;
		struct rnd_timings t0;
		struct rnd_image i0;
		const char *camF = "{'type':'perspective','position':[18,15,21],'target':[0,0.5,0],'up':[0,1,0],'fov_y':50}";
		if (reuse_render(__LINE__, ctx, &i0, &t0, camA, sx0, spx, pz, 0)) {
			rnd_image_release(&i0);
			CHECK(t0.shadow_maps_rendered == 8 && t0.shadow_maps_reused == 0,
			      "default resolution, first render: rendered %u reused %u, expected 8 / 0", t0.shadow_maps_rendered,
			      t0.shadow_maps_reused);
			if (reuse_render(__LINE__, ctx, &i0, &t0, camB, sx0, spx, pz, 0)) {
				rnd_image_release(&i0);
				printf("    [reuse, default resolution] camera A then B: rendered %u, reused %u\n", t0.shadow_maps_rendered,
				       t0.shadow_maps_reused);
				CHECK(t0.shadow_maps_rendered == 0 && t0.shadow_maps_reused == 8,
				      "default resolution, other camera: rendered %u reused %u, expected 0 / 8", t0.shadow_maps_rendered,
				      t0.shadow_maps_reused);
			}
			/* Informational: a camera three times as far (the renderer may size maps by how
			 * much of the view a light covers, which then changes their keys). */
			if (reuse_render(__LINE__, ctx, &i0, &t0, camF, sx0, spx, pz, 0)) {
				rnd_image_release(&i0);
				printf("    [reuse, default resolution] camera 3x farther: rendered %u, reused %u%s\n",
				       t0.shadow_maps_rendered, t0.shadow_maps_reused,
				       t0.shadow_maps_reused == 8 ? "" : " (note: maps not reused across camera distance)");
			}
		}
		g_reuse_res = ",'resolution':512";
	}

	rnd_context_stats(ctx, &s0);
	REQUIRE(reuse_render(__LINE__, ctx, &a, &t, camA, sx, spx, pz, 0));
	rnd_context_stats(ctx, &s1);
	printf("    [reuse] first render: rendered %u, reused %u; cache hits +%llu, misses +%llu; cached maps %u, "
	       "atlas occupancy %.4f\n",
	       t.shadow_maps_rendered, t.shadow_maps_reused, (unsigned long long)(s1.shadow_cache_hits - s0.shadow_cache_hits),
	       (unsigned long long)(s1.shadow_cache_misses - s0.shadow_cache_misses), s1.cached_maps, s1.atlas_occupancy);
	CHECK(t.shadow_maps_rendered == 8 && t.shadow_maps_reused == 0, "first render: rendered %u reused %u, expected 8 / 0",
	      t.shadow_maps_rendered, t.shadow_maps_reused);
	CHECK(s1.shadow_cache_misses - s0.shadow_cache_misses == 3 && s1.shadow_cache_hits == s0.shadow_cache_hits,
	      "first render: misses +%llu hits +%llu, expected +3 / +0",
	      (unsigned long long)(s1.shadow_cache_misses - s0.shadow_cache_misses),
	      (unsigned long long)(s1.shadow_cache_hits - s0.shadow_cache_hits));
	CHECK(s1.cached_maps >= 3, "cached maps %u after the first render", s1.cached_maps);
	rnd_image_release(&a);

	/* Same scene, another camera: every map is reused. */
	s0 = s1;
	REQUIRE(reuse_render(__LINE__, ctx, &b, &t, camB, sx, spx, pz, 0));
	rnd_context_stats(ctx, &s1);
	printf("    [reuse] other camera: rendered %u, reused %u (shadow stage %.2f ms); hits +%llu, misses +%llu\n",
	       t.shadow_maps_rendered, t.shadow_maps_reused, t.shadow_ms,
	       (unsigned long long)(s1.shadow_cache_hits - s0.shadow_cache_hits),
	       (unsigned long long)(s1.shadow_cache_misses - s0.shadow_cache_misses));
	CHECK(t.shadow_maps_rendered == 0 && t.shadow_maps_reused == 8, "other camera: rendered %u reused %u, expected 0 / 8",
	      t.shadow_maps_rendered, t.shadow_maps_reused);
	CHECK(s1.shadow_cache_hits - s0.shadow_cache_hits == 3 && s1.shadow_cache_misses == s0.shadow_cache_misses,
	      "other camera: hits +%llu misses +%llu, expected +3 / +0",
	      (unsigned long long)(s1.shadow_cache_hits - s0.shadow_cache_hits),
	      (unsigned long long)(s1.shadow_cache_misses - s0.shadow_cache_misses));

	/* The same request again: byte-identical. */
	if (reuse_render(__LINE__, ctx, &b2, &t, camB, sx, spx, pz, 0)) {
		int md;
		long nd = image_diff(&b, &b2, 0, &md);
		CHECK(nd == 0, "repeating the request changed %ld px (max %d)", nd, md);
		CHECK(t.shadow_maps_reused == 8, "repeat: reused %u", t.shadow_maps_reused);
		rnd_image_release(&b2);
	}

	/* The reused maps give what freshly rendered maps give: the same request on a new context
	 * (empty cache) for each light's debug view. */
	struct rnd_context *fresh = make_ctx(0, __LINE__);
	if (fresh) {
		for (int dl = 0; dl < 3; dl++) {
			struct rnd_image r1, r2;
			struct rnd_timings t1, t2;
			if (!reuse_render(__LINE__, ctx, &r1, &t1, camB, sx, spx, pz, dl)) continue;
			if (reuse_render(__LINE__, fresh, &r2, &t2, camB, sx, spx, pz, dl)) {
				int md;
				long nd = image_diff(&r1, &r2, 0, &md), nd2 = image_diff(&r1, &r2, 2, &md);
				printf("    [reuse] light %d: reused render (reused %u) vs fresh context (%s %u): %ld px differ, %ld by > 2, "
				       "max %d\n",
				       dl, t1.shadow_maps_reused, dl ? "reused" : "rendered", dl ? t2.shadow_maps_reused : t2.shadow_maps_rendered,
				       nd, nd2, md);
				CHECK(t1.shadow_maps_reused == 8, "light %d: reused %u", dl, t1.shadow_maps_reused);
				if (dl == 0) CHECK(t2.shadow_maps_rendered == 8, "fresh context rendered %u", t2.shadow_maps_rendered);
				CHECK(nd2 <= 2, "light %d: the reused maps' view differs from a fresh render in %ld px (max %d)", dl, nd2, md);
				rnd_image_release(&r2);
			}
			rnd_image_release(&r1);
		}
		rnd_context_destroy(fresh);
	}

	/* Move the sphere by 1 cm: every spot / point map is re-rendered (casters changed), and
	 * light 0's view changes only around the sphere and its shadow. */
	s0 = s1;
	rnd_context_stats(ctx, &s0);
	struct rnd_image m;
	if (reuse_render(__LINE__, ctx, &m, &t, camB, sx + 0.01, spx, pz, 0)) {
		rnd_context_stats(ctx, &s1);
		printf("    [reuse] sphere moved 1 cm: rendered %u, reused %u; misses +%llu, hits +%llu\n", t.shadow_maps_rendered,
		       t.shadow_maps_reused, (unsigned long long)(s1.shadow_cache_misses - s0.shadow_cache_misses),
		       (unsigned long long)(s1.shadow_cache_hits - s0.shadow_cache_hits));
		CHECK(t.shadow_maps_rendered == 8 && t.shadow_maps_reused == 0, "object moved: rendered %u reused %u, expected 8 / 0",
		      t.shadow_maps_rendered, t.shadow_maps_reused);
		CHECK(s1.shadow_cache_misses - s0.shadow_cache_misses == 3, "object moved: misses +%llu, expected +3",
		      (unsigned long long)(s1.shadow_cache_misses - s0.shadow_cache_misses));
		/* Where light 0's view may change: the sphere (both positions) and the band around the
		 * boundary of its shadow on the ground (both positions), dilated by 3 px. */
		const int W = 144, H = 144;
		struct gpu_cam cam;
		gpu_cam_persp(&cam, v3_make(-6, 5, -5), v3_make(0, 0.5, 0), v3_make(0, 1, 0), 50, W, H);
		const v3 l0 = v3_make(spx, 4, 2);
		uint8_t *zone = calloc((size_t)W * H, 1), *sh[2];
		for (int q = 0; q < 2; q++) {
			sh[q] = calloc((size_t)W * H, 1);
			v3 c = v3_make(sx + 0.01 * q, 0.8, 0);
			for (int j = 0; j < H; j++)
				for (int i = 0; i < W; i++) {
					v3 o, d;
					gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
					if (gpu_ray_sphere(o, d, c, 0.6, 0) > 0) { sh[q][(size_t)j * W + i] = 1; continue; }
					double tg = gpu_ray_ground(o, d, 0, 0, 0, 6);
					if (tg < 0) { sh[q][(size_t)j * W + i] = 3; continue; }
					v3 p = v3_add(o, v3_scale(d, tg));
					double ts = gpu_ray_sphere(p, v3_sub(l0, p), c, 0.6, 1e-9);
					sh[q][(size_t)j * W + i] = ts > 0 && ts < 1 ? 2 : 0;
				}
		}
		for (int j = 0; j < H; j++)
			for (int i = 0; i < W; i++)
				for (int q = 0; q < 2; q++)
					if (sh[q][(size_t)j * W + i] == 1 || gpu_near_edge(sh[q], W, H, i, j, 3)) zone[(size_t)j * W + i] = 1;
		long changed = 0, outside = 0;
		int wi = -1, wj = -1, wd = 0;
		for (int j = 0; j < H; j++)
			for (int i = 0; i < W; i++) {
				int dv = abs(val8(&b, i, j) - val8(&m, i, j));
				if (dv <= 2) continue;
				changed++;
				if (!zone[(size_t)j * W + i]) { outside++; if (dv > wd) { wd = dv; wi = i; wj = j; } }
			}
		printf("    [reuse] sphere moved 1 cm: light 0's view changed in %ld px (%ld outside the sphere / its shadow's "
		       "edge)\n", changed, outside);
		CHECK(changed > 0, "moving the sphere by 1 cm changed nothing in light 0's view");
		CHECK(outside <= 3, "%ld px changed away from the sphere and its shadow's edge (worst %d at (%d,%d))", outside, wd,
		      wi, wj);
		free(zone);
		free(sh[0]);
		free(sh[1]);
		rnd_image_release(&m);
	}

	/* Move light 0 (a spot): only its map is re-rendered; then the point light: only its six. */
	struct { double spx, pz; unsigned rendered, reused; const char *label; } moves[] = {
		{spx + 0.1, pz, 1, 7, "spot 0 moved 10 cm"},
		{spx, pz + 0.1, 6, 2, "point light moved 10 cm"},
	};
	for (int k = 0; k < 2; k++) {
		rnd_context_stats(ctx, &s0);
		struct rnd_image x;
		if (!reuse_render(__LINE__, ctx, &x, &t, camB, sx, moves[k].spx, moves[k].pz, 0)) continue;
		rnd_context_stats(ctx, &s1);
		unsigned long long dh = s1.shadow_cache_hits - s0.shadow_cache_hits, dm = s1.shadow_cache_misses - s0.shadow_cache_misses;
		printf("    [reuse] %s: rendered %u, reused %u; hits +%llu, misses +%llu\n", moves[k].label, t.shadow_maps_rendered,
		       t.shadow_maps_reused, dh, dm);
		CHECK(t.shadow_maps_rendered == moves[k].rendered && t.shadow_maps_reused == moves[k].reused,
		      "%s: rendered %u reused %u, expected %u / %u", moves[k].label, t.shadow_maps_rendered, t.shadow_maps_reused,
		      moves[k].rendered, moves[k].reused);
		CHECK(dh == 2 && dm == 1, "%s: hits +%llu misses +%llu, expected +2 / +1", moves[k].label, dh, dm);
		if (k == 0) {
			int md;
			long nd = image_diff(&b, &x, 2, &md);
			CHECK(nd > 0, "moving spot 0 did not change its shadow view");
		}
		rnd_image_release(&x);
	}
	rnd_image_release(&b);
}

/* A sun's one `fit` map does not follow the camera: like a spot's, it is kept for later
 * requests of the same casters and light (renderer/render.c grant_tiles), and what a reused map
 * draws is what a fresh one draws. Boxes and a plane only: their triangles do not depend on the
 * camera (a sphere's tessellation does, and with it the casters' key). Cascades follow the
 * camera and are drawn by every request. */
#define SUN_REUSE_CAM "{'type':'perspective','position':[%d,5,6],'target':[0,0.4,0],'up':[0,1,0],'fov_y':50}"
#define SUN_REUSE_SCENE                                                                                     \
	"{'width':96,'height':96,'camera':" SUN_REUSE_CAM ",'objects':[{'shape':'plane','size':[8,8]},"        \
	"{'shape':'box','size':[0.8,0.8,0.8],'transform':{'translation':[%.9g,0.4,0.00071]}},"                  \
	"{'shape':'box','size':[0.4,1.2,0.4],'transform':{'translation':[1.2,0.6,-0.9]}}],"                     \
	"'lights':[{'type':'directional','direction':[0.5,-1,0.4],"                                           \
	"'shadow':{'filter':'%s','directional':{'mode':'%s'%s}}}],"                                             \
	"'output':{'debug':'shadow','msaa':1}}"

TEST(lights_shadow_cache_reuses_a_fitted_sun)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	struct rnd_timings t;
	struct rnd_image a, b, fresh_b, moved;
	REQUIRE(lrender(ctx, &a, &t, SUN_REUSE_SCENE, 5, -0.9, "pcf", "fit", "") == R_OK);
	CHECK(t.shadow_maps_rendered == 1, "first request: rendered %u", t.shadow_maps_rendered);
	rnd_image_release(&a);
	/* Another camera, the same casters: the map is kept. */
	REQUIRE(lrender(ctx, &b, &t, SUN_REUSE_SCENE, -5, -0.9, "pcf", "fit", "") == R_OK);
	CHECK(t.shadow_maps_rendered == 0 && t.shadow_maps_reused == 1, "other camera: rendered %u reused %u, expected 0 / 1",
	      t.shadow_maps_rendered, t.shadow_maps_reused);
	struct rnd_context *fresh = make_ctx(0, __LINE__);
	if (fresh) {
		if (lrender(fresh, &fresh_b, &t, SUN_REUSE_SCENE, -5, -0.9, "pcf", "fit", "") == R_OK) {
			CHECK(t.shadow_maps_rendered == 1, "fresh context: rendered %u", t.shadow_maps_rendered);
			int md;
			long nd = image_diff(&b, &fresh_b, 0, &md);
			CHECK(nd == 0, "the kept sun map draws %ld px differently from a fresh one (max %d)", nd, md);
			rnd_image_release(&fresh_b);
		}
		rnd_context_destroy(fresh);
	}
	/* A caster moved: drawn again, and its shadow moved with it. */
	if (lrender(ctx, &moved, &t, SUN_REUSE_SCENE, -5, -0.5, "pcf", "fit", "") == R_OK) {
		CHECK(t.shadow_maps_rendered == 1 && t.shadow_maps_reused == 0, "box moved: rendered %u reused %u",
		      t.shadow_maps_rendered, t.shadow_maps_reused);
		int md;
		CHECK(image_diff(&b, &moved, 8, &md) > 20, "moving the box did not move its shadow");
		rnd_image_release(&moved);
	}
	rnd_image_release(&b);
	/* Cascades follow the camera: every request draws them. */
	for (int k = 0; k < 2; k++) {
		struct rnd_image c;
		if (lrender(ctx, &c, &t, SUN_REUSE_SCENE, 5, -0.9, "pcf", "cascades", "") != R_OK) break;
		CHECK(t.shadow_maps_rendered == 4 && t.shadow_maps_reused == 0, "cascades, request %d: rendered %u reused %u", k,
		      t.shadow_maps_rendered, t.shadow_maps_reused);
		rnd_image_release(&c);
	}
	/* Moment maps (EVSM, PCSS: the depth bounds) kept and reused draw what fresh ones draw. */
	static const char *const kept_filters[] = {"evsm", "pcss"};
	for (int f = 0; f < 2; f++) {
		struct rnd_image warm, cold;
		struct rnd_context *ctx2 = make_ctx(0, __LINE__);
		if (!ctx2) break;
		if (lrender(ctx, &warm, &t, SUN_REUSE_SCENE, 5, -0.9, kept_filters[f], "fit", "") == R_OK) rnd_image_release(&warm);
		if (lrender(ctx, &warm, &t, SUN_REUSE_SCENE, -5, -0.9, kept_filters[f], "fit", "") == R_OK) {
			CHECK(t.shadow_maps_reused == 1, "%s: other camera reused %u", kept_filters[f], t.shadow_maps_reused);
			if (lrender(ctx2, &cold, &t, SUN_REUSE_SCENE, -5, -0.9, kept_filters[f], "fit", "") == R_OK) {
				int md;
				long nd = image_diff(&warm, &cold, 0, &md);
				CHECK(nd == 0, "%s: the kept map draws %ld px differently from a fresh one (max %d)", kept_filters[f], nd, md);
				rnd_image_release(&cold);
			}
			rnd_image_release(&warm);
		}
		rnd_context_destroy(ctx2);
	}
	/* `auto` over a scene this small chooses the fit map: kept as well. */
	for (int k = 0; k < 2; k++) {
		struct rnd_image c;
		if (lrender(ctx, &c, &t, SUN_REUSE_SCENE, k ? -5 : 5, -0.7, "pcf", "auto", "") != R_OK) break;
		CHECK(t.shadow_maps_rendered + t.shadow_maps_reused == 1 && t.shadow_maps_reused == (uint32_t)k,
		      "auto, request %d: rendered %u reused %u", k, t.shadow_maps_rendered, t.shadow_maps_reused);
		rnd_image_release(&c);
	}
	/* One cascade is one map too, and it follows the camera all the same: never kept. */
	for (int k = 0; k < 2; k++) {
		struct rnd_image c;
		if (lrender(ctx, &c, &t, SUN_REUSE_SCENE, k ? -5 : 5, -0.9, "pcf", "cascades", ",'cascades':1") != R_OK) break;
		CHECK(t.shadow_maps_rendered == 1 && t.shadow_maps_reused == 0, "one cascade, request %d: rendered %u reused %u", k,
		      t.shadow_maps_rendered, t.shadow_maps_reused);
		rnd_image_release(&c);
	}
}

/* A sheet of two views under a sun of one cascade: each view draws the cascade around its own
 * camera (it follows the camera however many cascades there are; with one, later views used
 * to be planned as a fit map and read view 0's cascade through it). Each cell is what a
 * single-view request of that camera draws. Boxes only: the views' tessellation is the same. */
TEST(lights_sheet_redraws_a_single_cascade_per_view)
{
	static const char *const scene =
		"'objects':[{'shape':'plane','size':[8,8]},"
		"{'shape':'box','size':[0.8,0.8,0.8],'transform':{'translation':[-0.9,0.4,0]}},"
		"{'shape':'box','size':[0.4,1.2,0.4],'transform':{'translation':[1.2,0.6,-0.9]}}],"
		"'lights':[{'type':'directional','direction':[0.5,-1,0.4],"
		"'shadow':{'filter':'pcf','directional':{'mode':'cascades','cascades':1}}}],"
		"'output':{'debug':'shadow','msaa':1}}";
	struct rnd_image sheet, one[2];
	REQUIRE(lrender(NULL, &sheet, NULL, "{'width':96,'height':96,'views':[" SUN_REUSE_CAM "," SUN_REUSE_CAM "],%s", 5, -5,
	                scene) == R_OK);
	CHECK(sheet.width == 192 && sheet.height == 96, "sheet %ux%u", sheet.width, sheet.height);
	for (int k = 0; k < 2; k++) {
		if (lrender(NULL, &one[k], NULL, "{'width':96,'height':96,'camera':" SUN_REUSE_CAM ",%s", k ? -5 : 5, scene) != R_OK)
			continue;
		long diff = 0, shadowed = 0;
		for (uint32_t j = 0; j < 96; j++)
			for (uint32_t i = 0; i < 96; i++) {
				diff += val8(&sheet, 96 * (uint32_t)k + i, j) != val8(&one[k], i, j);
				shadowed += val8(&one[k], i, j) < 128;
			}
		CHECK(shadowed > 50, "view %d: almost no shadow (%ld px): the test sees nothing", k, shadowed);
		CHECK(diff == 0, "view %d of the sheet differs from its single-view render in %ld px", k, diff);
		rnd_image_release(&one[k]);
	}
	rnd_image_release(&sheet);
}

/* ======================================================================================== */
/* 6. Sixteen shadowed lights, and a tiny atlas                                              */
/* ======================================================================================== */

static void sixteen_lights_doc(char *buf, size_t n, int debug_light)
{
	size_t len = snprintf(buf, n,
	                      "{'width':128,'height':128,"
	                      "'camera':{'type':'perspective','position':[7,8,9],'target':[0,0.5,0],'up':[0,1,0],'fov_y':50},"
	                      "'objects':[{'shape':'plane','size':[16,16]},"
	                      "{'shape':'sphere','radius':0.7,'segments':32,'transform':{'translation':[0,0.9,0]}},"
	                      "{'shape':'box','size':[0.8,1.2,0.8],'transform':{'translation':[2.2,0.6,-1.5]}},"
	                      "{'shape':'cylinder','radius':0.35,'height':1.4,'segments':24,'transform':{'translation':[-2,0.7,1.8]}},"
	                      "{'shape':'box','size':[3,0.1,0.5],'transform':{'translation':[-1,1.8,-2]}}],"
	                      "'lights':[");
	for (int k = 0; k < 16; k++) {
		double a = 2 * GPU_PI * k / 16, r = 3.5 + (k % 3) * 0.6, y = 3.5 + (k % 4) * 0.5;
		double x = r * cos(a), z = r * sin(a);
		const char *sep = k ? "," : "";
		switch (k % 4) {
		case 0:
		case 2:
			len += snprintf(buf + len, n - len,
			                "%s{'type':'spot','position':[%.6g,%.6g,%.6g],'direction':[%.6g,%.6g,%.6g],'outer_angle':50,"
			                "'intensity':2}", sep, x, y, z, -x, -y, -z);
			break;
		case 1:
			len += snprintf(buf + len, n - len, "%s{'type':'point','position':[%.6g,%.6g,%.6g],'intensity':2}", sep, x, y, z);
			break;
		default:
			len += snprintf(buf + len, n - len,
			                "%s{'type':'directional','direction':[%.6g,-1,%.6g],'intensity':0.3%s}", sep, -x / 4, -z / 4,
			                k == 3 ? ",'shadow':{'directional':{'mode':'cascades'}}" : ",'shadow':{'directional':{'mode':'fit'}}");
			break;
		}
	}
	snprintf(buf + len, n - len,
	         "],'shadows':{'filter':'pcf','pcf_radius':1},'output':{'debug':'shadow','debug_light':%d,'msaa':1}}",
	         debug_light);
}

TEST(lights_sixteen_lights_tiny_atlas)
{
	/* 8 spots, 4 points, 4 directional (1 with 4 cascades, 3 fitted): 8 + 24 + 4 + 3 = 39 views. */
	char doc[8192];
	const int dl = 4; /* a spot */
	sixteen_lights_doc(doc, sizeof doc, dl);
	struct rnd_image big, tiny, tiny2;
	struct rnd_timings t;
	struct rnd_stats st;
	bool have_big = lrender(NULL, &big, &t, "%s", doc) == R_OK;
	if (have_big) {
		rnd_context_stats(gpu_ctx(), &st);
		printf("    [16 lights, atlas %u] rendered %u, reused %u; occupancy %.4f, %u tiles, %u cached maps\n", st.atlas_size,
		       t.shadow_maps_rendered, t.shadow_maps_reused, st.atlas_occupancy, st.atlas_tiles, st.cached_maps);
		CHECK(t.shadow_maps_rendered + t.shadow_maps_reused == 39, "views %u + %u, expected 39", t.shadow_maps_rendered,
		      t.shadow_maps_reused);
		CHECK(st.atlas_occupancy > 0 && st.atlas_occupancy <= 1, "occupancy %.4f", st.atlas_occupancy);
	}
	/* 512 x 512 atlas: 64 tiles of 64^2 at most; the maps must shrink to fit. */
	struct rnd_context *ctx = make_ctx(512, __LINE__);
	REQUIRE(ctx);
	if (lrender(ctx, &tiny, &t, "%s", doc) == R_OK) {
		rnd_context_stats(ctx, &st);
		printf("    [16 lights, atlas %u] rendered %u, reused %u (shadow %.1f ms, main %.1f ms); occupancy %.4f, %u tiles, "
		       "%u cached maps; validation messages %u\n",
		       st.atlas_size, t.shadow_maps_rendered, t.shadow_maps_reused, t.shadow_ms, t.main_ms, st.atlas_occupancy,
		       st.atlas_tiles, st.cached_maps, rnd_context_validation_messages(ctx));
		CHECK(st.atlas_size == 512, "atlas size %u", st.atlas_size);
		CHECK(t.shadow_maps_rendered == 39 && t.shadow_maps_reused == 0, "tiny atlas: rendered %u reused %u",
		      t.shadow_maps_rendered, t.shadow_maps_reused);
		CHECK(st.atlas_occupancy > 0 && st.atlas_occupancy <= 1, "occupancy %.4f", st.atlas_occupancy);
		CHECK(st.cached_maps == 15, "cached maps %u, expected 15 (8 spots + 4 points + 3 fitted suns)", st.cached_maps);
		if (have_big) {
			/* Lower resolution, same shadows: lit / shadowed agree on most pixels. */
			long n = 0, agree = 0;
			for (int j = 0; j < 128; j++)
				for (int i = 0; i < 128; i++) {
					n++;
					agree += (val8(&big, i, j) > 127) == (val8(&tiny, i, j) > 127);
				}
			printf("    [16 lights] light %d's view, atlas 512 vs 4096: %.2f%% of px agree on lit/shadowed\n", dl,
			       100.0 * agree / n);
			CHECK(agree >= 0.95 * n, "tiny atlas view of light %d agrees with the full one on only %.2f%% of px", dl,
			      100.0 * agree / n);
		}
		/* Again: the atlas was over-committed, so the maps were drawn below the resolution the
		 * lights ask for. Tile sizes are planned from the request alone (not from what the cache
		 * holds), so the same request plans the same smaller maps and reuses the 12 spot/point
		 * maps (32 views) and the 3 fitted suns' (which do not follow the camera); only the
		 * cascaded sun's 4 views render again — to the same bytes. */
		if (lrender(ctx, &tiny2, &t, "%s", doc) == R_OK) {
			rnd_context_stats(ctx, &st);
			printf("    [16 lights, atlas 512] again: rendered %u, reused %u; hits %llu, misses %llu; occupancy %.4f\n",
			       t.shadow_maps_rendered, t.shadow_maps_reused, (unsigned long long)st.shadow_cache_hits,
			       (unsigned long long)st.shadow_cache_misses, st.atlas_occupancy);
			CHECK(t.shadow_maps_reused == 35 && t.shadow_maps_rendered == 4, "again: rendered %u reused %u, expected 4 / 35",
			      t.shadow_maps_rendered, t.shadow_maps_reused);
			CHECK(st.shadow_cache_hits == 15 && st.shadow_cache_misses == 15, "hits %llu misses %llu, expected 15 / 15",
			      (unsigned long long)st.shadow_cache_hits, (unsigned long long)st.shadow_cache_misses);
			int md;
			long nd = image_diff(&tiny, &tiny2, 0, &md);
			CHECK(nd == 0, "the second tiny-atlas render differs in %ld px (max %d)", nd, md);
			rnd_image_release(&tiny2);
		}
		rnd_image_release(&tiny);
	}
	CHECK(rnd_context_validation_messages(ctx) == 0, "%u validation messages", rnd_context_validation_messages(ctx));
	rnd_context_destroy(ctx);
	if (have_big) rnd_image_release(&big);
}

/* ======================================================================================== */
/* 7. Debug atlas view                                                                       */
/* ======================================================================================== */

TEST(lights_debug_atlas_view)
{
	struct rnd_image img;
	struct rnd_timings t;
	if (!lrender(NULL, &img, &t,
	             "{'width':128,'height':128,"
	             "'camera':{'type':'perspective','position':[4,3,4],'target':[0,0.5,0],'up':[0,1,0],'fov_y':45},"
	             "'objects':[{'shape':'plane','size':[6.0001,6]},"
	             "{'shape':'sphere','radius':0.8,'segments':32,'transform':{'translation':[0,0.8,0]}}],"
	             "'lights':[{'type':'directional','direction':[-0.6,-1,-0.4],'shadow':{'directional':{'mode':'fit'}}},"
	             "{'type':'spot','position':[2,3,1],'direction':[-2,-3,-1]},{'type':'point','position':[-1.5,2,1]}],"
	             "'output':{'debug':'atlas','msaa':1}}"))
		return;
	/* The directional (fit) map holds linear depth: a gradient over the ground with the
	 * sphere darker; spot / point tiles hold perspective depth (near 1, almost white); texels
	 * no map holds show whatever their page holds (the atlases are not cleared, so pages no
	 * tile ever used read 0, black: renderer/shadow_cache.c). */
	long dark = 0, white = 0, n = 0;
	int mn = 255, mx = 0, levels = 0;
	bool seen[256] = {false};
	for (uint32_t j = 0; j < img.height; j++)
		for (uint32_t i = 0; i < img.width; i++) {
			const uint8_t *p = gpu_px8(&img, i, j);
			int v = p[0];
			n++;
			dark += v < 128;
			white += v >= 250;
			if (v < mn) mn = v;
			if (v > mx) mx = v;
			if (!seen[v]) { seen[v] = true; levels++; }
			if (p[1] != v || p[2] != v) { CHECK(0, "atlas view px (%u,%u) is not grey", i, j); i = img.width; j = img.height; }
		}
	printf("    [atlas view %ux%u] rendered %u maps; %ld dark (< 128), %ld white (>= 250) of %ld px; min %d max %d, %d grey "
	       "levels\n",
	       img.width, img.height, t.shadow_maps_rendered + t.shadow_maps_reused, dark, white, n, mn, mx, levels);
	CHECK(dark >= 20 && white >= 20 && levels >= 16,
	      "atlas view is not varied: %ld dark, %ld white px, %d levels (min %d, max %d)", dark, white, levels, mn, mx);
	rnd_image_release(&img);
}

/* ======================================================================================== */
/* 8. A turntable renders the spot map once                                                 */
/* ======================================================================================== */

TEST(lights_turntable_spot_rendered_once)
{
	struct rnd_image img;
	struct rnd_timings t;
	int r = lrender_at(__FILE__, __LINE__, NULL, &img, &t, true,
	                   "{'width':96,'height':96,'turntable':{'frames':4,'elevation':30},"
	                   "'objects':[{'shape':'plane','size':[6.0002,6]},"
	                   "{'shape':'sphere','radius':0.5,'segments':32,'transform':{'translation':[0,0.9,0]}}],"
	                   "'lights':[{'type':'spot','position':[0.3,4,0.2],'direction':[-0.3,-4,-0.2],'outer_angle':50}],"
	                   "'output':{'debug':'shadow','msaa':1}}");
	if (r == R_UNSUPPORTED) { printf("    note: turntable not supported yet; skipped\n"); return; }
	if (r != R_OK) return;
	printf("    [turntable 4 frames] rendered %u, reused %u; sheet %ux%u, %u views in %u columns\n", t.shadow_maps_rendered,
	       t.shadow_maps_reused, img.width, img.height, img.view_count, img.view_columns);
	CHECK(t.shadow_maps_rendered == 1 && t.shadow_maps_reused == 3, "turntable: rendered %u reused %u, expected 1 / 3",
	      t.shadow_maps_rendered, t.shadow_maps_reused);
	CHECK(img.view_count == 4 && img.view_columns == 2 && img.width == 192 && img.height == 192,
	      "sheet %ux%u, %u views, %u columns", img.width, img.height, img.view_count, img.view_columns);
	/* Every frame sees the sphere's shadow under it (dark) and lit ground. */
	for (uint32_t v = 0; v < img.view_count && img.width == 192; v++) {
		int x0 = (v % 2) * 96, y0 = (v / 2) * 96;
		long dark = 0, lit = 0;
		for (int j = 0; j < 96; j++)
			for (int i = 0; i < 96; i++) {
				int val = val8(&img, x0 + i, y0 + j);
				dark += val < 64;
				lit += val > 191; /* lit ground or background */
			}
		CHECK(dark > 20 && lit > 200, "frame %u: %ld dark, %ld lit px", v, dark, lit);
	}
	rnd_image_release(&img);
}
