/* tests/gpu — spot lights and filters (contract §2, §4): the spot cone, an oblique spot's shadow
 * against analytic values, and VSM/EVSM light bleeding between stacked plates. */
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
