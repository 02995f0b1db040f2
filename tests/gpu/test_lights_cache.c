/* tests/gpu — the persistent shadow cache (rnd_timings.shadow_maps_rendered / _reused,
 * rnd_context_stats): maps reused across requests, a fitted sun's map, and a sheet of views that
 * redraws a single cascade per view. Two renders agreeing is the point here. */
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
