/* tests — renderer/plan.c: a sun's one `fit` map: the scene's or the casters' box covered on
 * whole texels, finer texels where the camera sees the casters close, a low sun's light-space
 * box; checked against values computed here independently. */
#include <math.h>
#include <string.h>
#include "test.h"
#include "plan.h"
#include "plan_util.h"

/* ---- fit ----------------------------------------------------------------------------------- */

TEST(plan_fit_covers_scene_bounds)
{
	static const float dirs[][3] = {{0, -1, 0}, {-0.3f, -1, -0.5f}, {1, -0.2f, 0.1f}, {0.05f, -1, 0.02f}, {0, 1, 0}, {0.6f, -0.6f, -0.6f}};
	struct rnd_aabb boxes[2];
	set_box(&boxes[0], -3, 0, -2, 4, 2.5f, 1);
	set_box(&boxes[1], 95, -10, 40, 140, 30, 60);
	for (int bi = 0; bi < 2; bi++)
		for (int di = 0; di < 6; di++) {
			struct fixture f;
			fixture_fit_sun(&f, 1.0f, dirs[di]);
			f.light.shadow.resolution = 1024;
			struct rnd_camera_plan cp;
			static struct rnd_shadow_plan sp;
			struct rnd_error err = {0};
			REQUIRE(rnd_camera_plan(&f.scene.camera, 512, 512, &boxes[bi], &cp, &err) == RND_OK, "camera: %s", err.msg);
			REQUIRE(rnd_shadow_plan(&f.scene, &boxes[bi], &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
			REQUIRE(sp.view_count == 1 && sp.lights[0].view_count == 1, "box %d dir %d: %u views", bi, di, sp.view_count);
			CHECK(sp.resolution == 1024, "resolution %u", sp.resolution);
			const struct umbra_shadow_view *v = &sp.views[0];
			CHECK(sp.view_ortho[0] && v->params[1] == 0.0f, "fit view is orthographic");
			CHECK(v->rect[2] == 1024.0f, "tile size %g", v->rect[2]);
			double len = sqrt((double)dirs[di][0] * dirs[di][0] + (double)dirs[di][1] * dirs[di][1] + (double)dirs[di][2] * dirs[di][2]);
			double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
			for (int i = 0; i < 8; i++) {
				double p[3], n[3];
				corner(&boxes[bi], i, p);
				double w = ndc3(v->view_proj, p, n);
				CHECK(fabs(w - 1.0) < 1e-6, "ortho w %g", w);
				CHECK(inside_clip(n, 0.0), "box %d dir %d corner %d at clip %.6f %.6f %.6f", bi, di, i, n[0], n[1], n[2]);
				for (int a = 0; a < 2; a++) { lo[a] = fmin(lo[a], n[a]); hi[a] = fmax(hi[a], n[a]); }
			}
			/* Moving along the light increases depth (near 0, far 1). */
			double p0[3] = {0.5 * (boxes[bi].min[0] + boxes[bi].max[0]), 0.5 * (boxes[bi].min[1] + boxes[bi].max[1]),
			                0.5 * (boxes[bi].min[2] + boxes[bi].max[2])}, p1[3], n0[3], n1[3];
			for (int k = 0; k < 3; k++) p1[k] = p0[k] + dirs[di][k] / len;
			ndc3(v->view_proj, p0, n0);
			ndc3(v->view_proj, p1, n1);
			CHECK(n1[2] > n0[2], "depth does not grow along the light: %g -> %g", n0[2], n1[2]);
			CHECK(fabs(n1[0] - n0[0]) < 1e-5 && fabs(n1[1] - n0[1]) < 1e-5, "light direction is not the view axis");
			/* Reasonably tight: the larger light-space extent spans most of the map. */
			double span = fmax(hi[0] - lo[0], hi[1] - lo[1]);
			CHECK(span > 1.9, "box %d dir %d: fit uses only %.3f of the map width", bi, di, span);
		}
}

/* A sun over a 2 m object on a 40 m ground that casts nothing (rnd_shadow_plan_with's
 * casters): the fitted map is a smaller tile around the casters (at most 1024, 2048 under a
 * sun 8 degrees up, whose map is a long box) with texels no coarser than the default map's
 * around the whole scene, on whole texels from the light basis' origin, with the filter's
 * reach as margin; a light that asks for a resolution spends it on the casters, less than
 * the default too (issue 31: it kept the whole scene, texels 20 times coarser here), more than
 * it finer than the default's; no caster at all gives the smallest tile. */
TEST(plan_fit_covers_the_casters_on_whole_texels)
{
	static const float dirs[][3] = {{-0.5f, -1, -0.3f}, {0.2f, -1, 0.1f}, {1, -0.15f, 0.3f}};
	static const enum rnd_filter filters[] = {RND_FILTER_PCF, RND_FILTER_PCSS};
	struct rnd_aabb scene, casters, empty;
	set_box(&scene, -20, 0, -20, 20, 2, 20);
	set_box(&casters, 3, 0, -1, 5, 2, 1);
	rnd_aabb_empty(&empty);
	for (int di = 0; di < 3; di++)
		for (int fi = 0; fi < 2; fi++) {
			struct fixture f;
			fixture_fit_sun(&f, 40.0f, dirs[di]);
			f.light.shadow.filter = filters[fi];
			struct rnd_camera_plan cp;
			static struct rnd_shadow_plan whole, part, asked, none;
			struct rnd_error err = {0};
			REQUIRE(rnd_camera_plan(&f.scene.camera, 512, 512, &scene, &cp, &err) == RND_OK, "camera: %s", err.msg);
			REQUIRE(rnd_shadow_plan(&f.scene, &scene, &cp, &whole, &err) == RND_OK, "whole: %s", err.msg);
			REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, 0, &part, &err) == RND_OK, "casters: %s",
			        err.msg);
			REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &empty, &cp, NULL, 0, &none, &err) == RND_OK, "none: %s",
			        err.msg);
			const struct umbra_shadow_view *w = &whole.views[0], *v = &part.views[0];
			CHECK(w->rect[2] == 2048.0f && v->rect[2] <= (di == 2 ? 2048.0f : 1024.0f) &&
			      part.lights[0].resolution == (uint32_t)v->rect[2],
			      "dir %d filter %d: tiles %g (whole scene) and %g (casters)", di, fi, w->rect[2], v->rect[2]);
			CHECK(none.views[0].rect[2] == 64.0f, "no caster: tile %g", none.views[0].rect[2]);
			CHECK(v->params[0] <= w->params[0] * (1.0f + 1e-5f), "dir %d filter %d: texel %g, the whole scene's %g", di,
			      fi, v->params[0], w->params[0]);
			double reach = (filters[fi] == RND_FILTER_PCSS ? 24.0 : (double)part.lights[0].pcf_radius) + 2.0;
			double origin[3] = {0, 0, 0}, no[3];
			ndc3(v->view_proj, origin, no);
			for (int a = 0; a < 2; a++)
				CHECK(frac_dist((no[a] * 0.5 + 0.5) * v->rect[2], 0.0) < 1e-3,
				      "dir %d filter %d axis %d: the light basis' origin at texel %.4f, not on the grid", di, fi, a,
				      (no[a] * 0.5 + 0.5) * v->rect[2]);
			for (int i = 0; i < 8; i++) {
				double p[3], nv[3];
				corner(&casters, i, p);
				ndc3(v->view_proj, p, nv);
				for (int a = 0; a < 2; a++) {
					double tv = (nv[a] * 0.5 + 0.5) * v->rect[2];
					CHECK(tv >= reach - 1e-3 && tv <= v->rect[2] - reach + 1e-3,
					      "dir %d filter %d corner %d axis %d at texel %.2f of %g: less than %g texels of margin", di, fi,
					      i, a, tv, v->rect[2], reach);
				}
			}
			f.light.shadow.resolution = 1024;
			REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, 0, &asked, &err) == RND_OK, "asked: %s",
			        err.msg);
			REQUIRE(rnd_shadow_plan(&f.scene, &scene, &cp, &whole, &err) == RND_OK, "whole: %s", err.msg);
			CHECK(asked.views[0].rect[2] == 1024.0f && asked.views[0].params[0] < 0.5f * whole.views[0].params[0],
			      "dir %d filter %d: asked 1024: tile %g, texel %g, the whole scene's at 1024 %g", di, fi,
			      asked.views[0].rect[2], asked.views[0].params[0], whole.views[0].params[0]);
			f.light.shadow.resolution = 4096;
			REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, 0, &asked, &err) == RND_OK, "4096: %s",
			        err.msg);
			CHECK(asked.views[0].rect[2] == 4096.0f && asked.views[0].params[0] < v->params[0],
			      "dir %d filter %d: asked 4096: tile %g, texel %g, the default's %g", di, fi, asked.views[0].rect[2],
			      asked.views[0].params[0], v->params[0]);
		}
}

/* The casters' texel follows the camera: a 128-texel-high image of a 0.3 m object 20 cm over a
 * 14 m ground seen from 40 m keeps the whole scene's texels, seen from 1.5 m gets finer ones
 * (PCF's 3-texel kernel within a pixel) but at most one doubling of the tile. */
TEST(plan_fit_texels_finer_where_the_camera_sees_the_casters)
{
	static const float dir[3] = {-0.2f, -0.8f, 0.6f};
	struct rnd_aabb scene, casters;
	set_box(&scene, -7, 0, -7, 7, 0.5f, 7);
	set_box(&casters, -0.15f, 0.2f, -0.15f, 0.15f, 0.5f, 0.15f);
	static struct rnd_shadow_plan plan[2];
	for (int c = 0; c < 2; c++) {
		struct fixture f;
		fixture_fit_sun(&f, 14.0f, dir);
		f.light.shadow.filter = RND_FILTER_PCF;
		f.scene.width = f.scene.height = 128;
		float d = c ? 1.5f : 40.0f;
		camera_at(&f.scene.camera, 0, d * 0.6f, d * 0.8f, 0, 0.3f, 0, 0, 0);
		struct rnd_camera_plan cp;
		struct rnd_error err = {0};
		REQUIRE(rnd_camera_plan(&f.scene.camera, 128, 128, &scene, &cp, &err) == RND_OK, "camera: %s", err.msg);
		REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, 0, &plan[c], &err) == RND_OK, "plan: %s",
		        err.msg);
	}
	const struct umbra_shadow_view *far = &plan[0].views[0], *near = &plan[1].views[0];
	CHECK(near->params[0] < 0.6f * far->params[0], "texel %g from 1.5 m, %g from 40 m", near->params[0], far->params[0]);
	CHECK(near->rect[2] <= 2.0f * far->rect[2], "tile %g from 1.5 m, %g from 40 m", near->rect[2], far->rect[2]);
	CHECK(plan[1].lights[0].size_rule == RND_SIZE_CASTERS, "size rule %u", plan[1].lights[0].size_rule);
}

/* Issue 31: a 14-degree PCSS sun over a 1 m plate 1.2 m above a 6 m ground (the traced
 * tests/gpu/truth/plate_sun): its widest penumbra, tan(7 deg) x 1.23 m = 0.15 m in half-width,
 * is some 50 of the whole scene's texels (3 mm) and its search reaches 24. The casters' map
 * takes texels at least 0.15 m / 24 wide, coarser than the scene's, in the tile they need
 * (256 here), with the search's reach as margin; an asked 4096 the same texels and tile. */
TEST(plan_fit_wide_sun_pcss_texels_as_coarse_as_its_search_needs)
{
	static const float dir[3] = {0.2f, -1, 0};
	struct rnd_aabb scene, casters;
	set_box(&scene, -3, 0, -3, 3, 1.21f, 3);
	set_box(&casters, -0.5f, 1.19f, -0.5f, 0.5f, 1.21f, 0.5f);
	static struct rnd_shadow_plan whole, part, asked;
	struct fixture f;
	fixture_fit_sun(&f, 6.0f, dir);
	f.light.shadow.filter = RND_FILTER_PCSS;
	f.light.angular_diameter = 14.0f * (float)PI_D / 180.0f;
	struct rnd_camera_plan cp;
	struct rnd_error err = {0};
	REQUIRE(rnd_camera_plan(&f.scene.camera, 128, 128, &scene, &cp, &err) == RND_OK, "camera: %s", err.msg);
	REQUIRE(rnd_shadow_plan(&f.scene, &scene, &cp, &whole, &err) == RND_OK, "whole: %s", err.msg);
	REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, 0, &part, &err) == RND_OK, "casters: %s", err.msg);
	const struct umbra_shadow_view *w = &whole.views[0], *v = &part.views[0];
	double len = sqrt(0.2 * 0.2 + 1.0), penumbra = tan(7.0 * PI_D / 180.0) * 1.21 * len;
	CHECK(v->params[0] >= penumbra / 24.0 * (1.0 - 1e-4) && v->params[0] > 1.5f * w->params[0],
	      "texel %g: the search needs %g, the whole scene's %g", v->params[0], penumbra / 24.0, w->params[0]);
	CHECK(v->rect[2] == 256.0f && part.lights[0].size_rule == RND_SIZE_SEARCH, "tile %g, size rule %u", v->rect[2],
	      part.lights[0].size_rule);
	for (int i = 0; i < 8; i++) {
		double p[3], nv[3];
		corner(&casters, i, p);
		ndc3(v->view_proj, p, nv);
		for (int a = 0; a < 2; a++) {
			double tv = (nv[a] * 0.5 + 0.5) * v->rect[2];
			CHECK(tv >= 26.0 - 1e-3 && tv <= v->rect[2] - 26.0 + 1e-3, "corner %d axis %d at texel %.2f of %g", i, a,
			      tv, v->rect[2]);
		}
	}
	f.light.shadow.resolution = 4096;
	REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, 0, &asked, &err) == RND_OK, "4096: %s", err.msg);
	const struct umbra_shadow_view *a = &asked.views[0];
	CHECK(fabsf(a->params[0] - v->params[0]) <= 1e-5f * v->params[0] && a->rect[2] == v->rect[2],
	      "asked 4096: tile %g, texel %g; the default's %g, %g",
	      asked.views[0].rect[2], asked.views[0].params[0], v->rect[2], v->params[0]);
}

/* A sun 7 degrees above a 30 m plane: the bounds' light-space box is ~8:1, and the fitted map
 * is that box (both axes span the map), not the square around it that left 7/8 of its rows
 * empty; a sun 60 degrees up (box under 2:1) and PCSS keep square texels. */
TEST(plan_fit_low_sun_uses_the_light_space_box)
{
	struct rnd_aabb box;
	set_box(&box, -15, 0, -15, 15, 1.2f, 15);
	static const float low[3] = {-0.794f, -0.1219f, -0.5955f}, high[3] = {-0.5f, -1, -0.3f};
	for (int t = 0; t < 3; t++) {
		struct fixture f;
		fixture_fit_sun(&f, 30.0f, t == 1 ? high : low);
		if (t == 2) { f.light.angular_diameter = 0.01f; f.light.shadow.filter = RND_FILTER_PCSS; }
		struct rnd_camera_plan cp;
		static struct rnd_shadow_plan sp;
		struct rnd_error err = {0};
		REQUIRE(rnd_camera_plan(&f.scene.camera, 128, 128, &box, &cp, &err) == RND_OK, "camera: %s", err.msg);
		REQUIRE(rnd_shadow_plan(&f.scene, &box, &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
		const struct umbra_shadow_view *v = &sp.views[0];
		double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
		for (int i = 0; i < 8; i++) {
			double p[3], n[3];
			corner(&box, i, p);
			ndc3(v->view_proj, p, n);
			CHECK(inside_clip(n, 1e-5), "case %d corner %d outside the map", t, i);
			for (int a = 0; a < 2; a++) { lo[a] = fmin(lo[a], n[a]); hi[a] = fmax(hi[a], n[a]); }
		}
		double sx = hi[0] - lo[0], sy = hi[1] - lo[1];
		const float *m = v->view_proj;   /* half-widths of the view from its row scales */
		double hx = 1.0 / sqrt((double)m[0] * m[0] + (double)m[4] * m[4] + (double)m[8] * m[8]);
		double hy = 1.0 / sqrt((double)m[1] * m[1] + (double)m[5] * m[5] + (double)m[9] * m[9]);
		if (t == 0)
			CHECK(sx > 1.9 && sy > 1.9 && fmax(hx, hy) > 4.0 * fmin(hx, hy),
			      "low sun: the bounds span %.3f x %.3f of a %.2f x %.2f map", sx, sy, hx, hy);
		else
			CHECK(fabs(hx - hy) < 1e-4 * hx && fmax(sx, sy) > 1.9, "case %d: square map expected, %.3f x %.3f", t, hx,
			      hy);
		/* params[0] (the texel size the shaders use) is the larger side of a texel */
		double texel = 2.0 * fmax(hx, hy) / v->rect[2];
		CHECK(fabs(v->params[0] - texel) < 1e-4 * texel, "case %d: texel size %g, expected %g", t, v->params[0], texel);
	}
}
