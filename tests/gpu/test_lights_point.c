/* tests/gpu — point lights (contract §2, §3, §7): cube-map shadows of a point light in a closed
 * room against analytic projections, and continuity across cube-face boundaries. Checked against
 * ray casts against the exact shapes (lights_util.h), never the renderer's own output. */
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
