/* tests — renderer/camera.c and plan.c: camera planning, cascade splits, shadow views (fit, cascades, spot,
 * point cube faces) and frustum culling, checked against values computed here independently. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"
#include "frame.h"
#include "plan.h"

#define PI_D 3.14159265358979323846

/* Clip-space transform of a world point in double (the matrix entries are the plan's floats). */
static void clip4(const float m[16], const double p[3], double c[4])
{
	for (int r = 0; r < 4; r++) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

/* x/w, y/w, z/w; returns w. */
static double ndc3(const float m[16], const double p[3], double n[3])
{
	double c[4];
	clip4(m, p, c);
	for (int i = 0; i < 3; i++) n[i] = c[i] / c[3];
	return c[3];
}

static bool inside_clip(const double n[3], double eps)
{
	return fabs(n[0]) <= 1.0 + eps && fabs(n[1]) <= 1.0 + eps && n[2] >= -eps && n[2] <= 1.0 + eps;
}

static void set_box(struct rnd_aabb *b, float x0, float y0, float z0, float x1, float y1, float z1)
{
	b->min[0] = x0; b->min[1] = y0; b->min[2] = z0;
	b->max[0] = x1; b->max[1] = y1; b->max[2] = z1;
}

static void corner(const struct rnd_aabb *b, int i, double p[3])
{
	p[0] = i & 1 ? b->max[0] : b->min[0];
	p[1] = i & 2 ? b->max[1] : b->min[1];
	p[2] = i & 4 ? b->max[2] : b->min[2];
}

/* A scene with one plane of side `size` at y = 0 and one light; bounds computed here. */
struct fixture {
	struct rnd_scene scene;
	struct rnd_material mat;
	struct rnd_object obj;
	struct rnd_light light;
	struct rnd_aabb bounds;
};

static void fixture_init(struct fixture *f, float size, enum rnd_light_type type)
{
	memset(f, 0, sizeof *f);
	rnd_scene_defaults(&f->scene);
	rnd_material_defaults(&f->mat);
	rnd_object_defaults(&f->obj);
	f->obj.shape = RND_SHAPE_PLANE;
	f->obj.size[0] = size; f->obj.size[1] = 0; f->obj.size[2] = size;
	rnd_light_defaults(&f->light, type);
	f->scene.materials = &f->mat; f->scene.material_count = 1;
	f->scene.objects = &f->obj; f->scene.object_count = 1;
	f->scene.lights = &f->light; f->scene.light_count = 1;
	set_box(&f->bounds, -0.5f * size, 0, -0.5f * size, 0.5f * size, 0, 0.5f * size);
}

static void set3(float v[3], float x, float y, float z) { v[0] = x; v[1] = y; v[2] = z; }

/* fixture_init with a sun along dir and a single `fit` map. */
static void fixture_fit_sun(struct fixture *f, float size, const float dir[3])
{
	fixture_init(f, size, RND_LIGHT_DIRECTIONAL);
	memcpy(f->light.direction, dir, sizeof f->light.direction);
	f->light.shadow.dir_mode = RND_DIR_FIT;
}

/* Camera at pos looking at target, explicit near/far (0 = derived). */
static void camera_at(struct rnd_camera *c, float px, float py, float pz, float tx, float ty, float tz,
                      float znear, float zfar)
{
	set3(c->position, px, py, pz);
	set3(c->target, tx, ty, tz);
	set3(c->up, 0, 1, 0);
	c->near = znear; c->far = zfar;
}

static double frac_d(double x) { return x - floor(x); }
/* Distance between two fractional parts on the unit circle (0.9999 and 0.0001 are close). */
static double frac_dist(double a, double b)
{
	double d = fabs(frac_d(a) - frac_d(b));
	return d > 0.5 ? 1.0 - d : d;
}

/* ---- cascade splits ---------------------------------------------------------------------- */

TEST(plan_cascade_splits_practical_scheme)
{
	const double n = 0.1, f = 100.0;
	const float lambdas[4] = {0.0f, 0.5f, 0.75f, 1.0f};
	for (int li = 0; li < 4; li++) {
		double lam = lambdas[li];
		float s[4];
		rnd_cascade_splits((float)n, (float)f, 4, lambdas[li], s);
		for (int i = 1; i <= 4; i++) {
			double t = i / 4.0;
			double want = lam * n * pow(f / n, t) + (1.0 - lam) * (n + (f - n) * t);
			CHECK(fabs(s[i - 1] - want) <= 1e-5 * want, "lambda %g split %d = %.7g, want %.7g", lam, i, s[i - 1], want);
		}
		CHECK(s[3] == 100.0f, "lambda %g: last split %.9g is not exactly far", lam, s[3]);
		for (int i = 1; i < 4; i++) CHECK(s[i] > s[i - 1], "lambda %g: split %d %g <= split %d %g", lam, i, s[i], i - 1, s[i - 1]);
		CHECK(s[0] > n, "lambda %g: first split %g not beyond near", lam, s[0]);
	}
	/* Odd values: the last split is still exactly far (no pow/lerp rounding drift). */
	static const float odd[][3] = {{0.37f, 77.7f, 0.6f}, {0.013f, 913.3f, 0.9f}, {1.7f, 3.3f, 0.33f}, {0.05f, 141.42136f, 0.75f}};
	for (int i = 0; i < 4; i++) {
		float s[4];
		rnd_cascade_splits(odd[i][0], odd[i][1], 4, odd[i][2], s);
		CHECK(s[3] == odd[i][1], "near %g far %.9g lambda %g: last split %.9g", odd[i][0], odd[i][1], odd[i][2], s[3]);
		for (int k = 1; k < 4; k++) CHECK(s[k] > s[k - 1], "odd case %d not increasing", i);
	}
	/* Fewer cascades: the last used split is exactly far, unused entries hold far. */
	for (uint32_t cnt = 1; cnt <= 3; cnt++) {
		float s[4] = {-1, -1, -1, -1};
		rnd_cascade_splits(0.1f, 100.0f, cnt, 0.75f, s);
		CHECK(s[cnt - 1] == 100.0f, "n=%u: last split %.9g", cnt, s[cnt - 1]);
		for (uint32_t i = cnt; i < 4; i++) CHECK(s[i] == 100.0f, "n=%u: unused split %u = %g", cnt, i, s[i]);
		for (uint32_t i = 1; i < cnt; i++) CHECK(s[i] > s[i - 1], "n=%u: splits not increasing", cnt);
	}
}

/* ---- cascades: stable under camera rotation and translation ------------------------------ */

static void cascade_fixture(struct fixture *f)
{
	fixture_init(f, 200.0f, RND_LIGHT_DIRECTIONAL);
	set3(f->light.direction, -0.35f, -1.0f, -0.55f);
	f->light.shadow.dir_mode = RND_DIR_CASCADES;
	f->light.shadow.cascades = 4;
}

TEST(plan_cascades_bit_identical_under_rotation)
{
	struct fixture f;
	cascade_fixture(&f);
	static const float targets[][3] = {
		{0, 0, 0}, {10, 1, -3}, {-5, 2.2f, 7}, {1.3f, -4, 9.5f}, {-8, 0.5f, -8}, {0.2f, 3.9f, -30},
	};
	static struct rnd_shadow_plan plans[6];
	const float pos[3] = {1.3f, 2.0f, -0.7f};
	for (int t = 0; t < 6; t++) {
		struct rnd_camera_plan cp;
		struct rnd_error err = {0};
		camera_at(&f.scene.camera, pos[0], pos[1], pos[2], targets[t][0], targets[t][1], targets[t][2], 0.1f, 80.0f);
		REQUIRE(rnd_camera_plan(&f.scene.camera, 800, 600, &f.bounds, &cp, &err) == RND_OK, "camera: %s", err.msg);
		REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, &plans[t], &err) == RND_OK, "shadow: %s", err.msg);
		REQUIRE(plans[t].view_count == 4, "target %d: %u views", t, plans[t].view_count);
		REQUIRE(plans[t].lights[0].view_count == 4 && plans[t].lights[0].first_view == 0, "light plan");
	}
	for (int t = 1; t < 6; t++)
		for (int i = 0; i < 4; i++) {
			CHECK(memcmp(plans[t].views[i].view_proj, plans[0].views[i].view_proj, sizeof plans[0].views[i].view_proj) == 0,
			      "target %d cascade %d: view_proj differs from target 0", t, i);
			CHECK(memcmp(plans[t].views[i].params, plans[0].views[i].params, sizeof plans[0].views[i].params) == 0,
			      "target %d cascade %d: params differ", t, i);
		}
	/* Cascades grow: each covers more world than the previous (texel size increasing). */
	for (int i = 1; i < 4; i++)
		CHECK(plans[0].views[i].params[0] > plans[0].views[i - 1].params[0], "cascade %d texel %g <= cascade %d texel %g",
		      i, plans[0].views[i].params[0], i - 1, plans[0].views[i - 1].params[0]);
}

TEST(plan_cascades_texel_grid_fixed_under_translation)
{
	struct fixture f;
	cascade_fixture(&f);
	const double P[3] = {0.37, 0.0, -1.91};     /* a fixed world point near the camera */
	double frac0[4][2] = {{0}}, texel0[4] = {0};
	double moved_max[4] = {0};
	struct rnd_shadow_plan *sp = NULL;
	static struct rnd_shadow_plan plan;
	sp = &plan;
	for (int k = 0; k < 24; k++) {
		float dx = 0.0123f * (float)k, dy = 0.0041f * (float)k, dz = -0.0087f * (float)k;
		struct rnd_camera_plan cp;
		struct rnd_error err = {0};
		camera_at(&f.scene.camera, 0.8f + dx, 1.7f + dy, 1.1f + dz, 0.8f + dx + 3.0f, 1.7f + dy - 1.0f, 1.1f + dz - 4.0f,
		          0.1f, 90.0f);
		REQUIRE(rnd_camera_plan(&f.scene.camera, 640, 480, &f.bounds, &cp, &err) == RND_OK, "camera: %s", err.msg);
		REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, sp, &err) == RND_OK, "shadow: %s", err.msg);
		REQUIRE(sp->view_count == 4, "%u views", sp->view_count);
		double res = sp->resolution;
		for (int c = 0; c < 4; c++) {
			const struct umbra_shadow_view *v = &sp->views[c];
			CHECK(v->rect[2] == (float)res, "cascade %d: resolution %g in view, plan %g", c, v->rect[2], res);
			double n[3];
			ndc3(v->view_proj, P, n);
			double tp[2] = {(n[0] * 0.5 + 0.5) * res, (n[1] * 0.5 + 0.5) * res};
			if (k == 0) {
				frac0[c][0] = tp[0]; frac0[c][1] = tp[1]; texel0[c] = v->params[0];
				continue;
			}
			CHECK(v->params[0] == texel0[c], "step %d cascade %d: texel size %g changed from %g", k, c, v->params[0], texel0[c]);
			for (int a = 0; a < 2; a++) {
				double d = frac_dist(tp[a], frac0[c][a]);
				CHECK(d <= 1e-3, "step %d cascade %d axis %d: texel coord %.5f vs %.5f (fraction moved by %.5f)",
				      k, c, a, tp[a], frac0[c][a], d);
				double moved = fabs(tp[a] - frac0[c][a]);
				if (moved > moved_max[c]) moved_max[c] = moved;
			}
		}
	}
	/* The cascade really followed the camera (cascade 0 moved by whole texels at least once). */
	CHECK(moved_max[0] >= 0.999, "cascade 0 never moved: max %g texels", moved_max[0]);
}

/* Cascade c contains every point of the camera frustum up to depth splits[c] (the shader picks
 * cascade c for those), and its depth range covers the scene bounds. */
TEST(plan_cascades_cover_their_slices)
{
	struct fixture f;
	cascade_fixture(&f);
	struct rnd_camera_plan cp;
	static struct rnd_shadow_plan sp;
	struct rnd_error err = {0};
	camera_at(&f.scene.camera, 2.0f, 3.0f, 5.0f, -10.0f, 0.0f, -20.0f, 0.1f, 120.0f);
	REQUIRE(rnd_camera_plan(&f.scene.camera, 1024, 576, &f.bounds, &cp, &err) == RND_OK, "camera: %s", err.msg);
	REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
	REQUIRE(sp.view_count == 4, "%u views", sp.view_count);
	const struct rnd_light_plan *lp = &sp.lights[0];
	double right[3];
	right[0] = cp.fwd[1] * cp.up[2] - cp.fwd[2] * cp.up[1];
	right[1] = cp.fwd[2] * cp.up[0] - cp.fwd[0] * cp.up[2];
	right[2] = cp.fwd[0] * cp.up[1] - cp.fwd[1] * cp.up[0];
	double ty = tan(cp.fov_y * 0.5), tx = ty * cp.aspect;
	for (int c = 0; c < 4; c++) {
		const struct umbra_shadow_view *v = &sp.views[c];
		CHECK(sp.view_ortho[c], "cascade %d not ortho", c);
		CHECK(v->params[1] == 0.0f, "cascade %d params.y %g", c, v->params[1]);
		double z = lp->splits[c] * 0.999;
		/* Frustum corners and edge midpoints of the slice at depth z, and the eye itself. */
		for (int sx = -1; sx <= 1; sx++)
			for (int sy = -1; sy <= 1; sy++) {
				double p[3], n[3];
				for (int k = 0; k < 3; k++)
					p[k] = cp.pos[k] + z * (cp.fwd[k] + sx * tx * right[k] + sy * ty * cp.up[k]);
				ndc3(v->view_proj, p, n);
				CHECK(fabs(n[0]) <= 1.0 && fabs(n[1]) <= 1.0, "cascade %d slice point (%d,%d) at ndc %.6f %.6f", c, sx, sy,
				      n[0], n[1]);
			}
		for (int i = 0; i < 8; i++) {
			double p[3], n[3];
			corner(&f.bounds, i, p);
			ndc3(v->view_proj, p, n);
			CHECK(n[2] >= 0.0 && n[2] <= 1.0, "cascade %d: bounds corner %d depth %g", c, i, n[2]);
		}
	}
}

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
 * reach as margin; a light that asks for less than the default resolution keeps the whole
 * scene, one that asks for more spends it on the casters (finer than the default's); no
 * caster at all gives the smallest tile. */
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
			REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, &part, &err) == RND_OK, "casters: %s",
			        err.msg);
			REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &empty, &cp, NULL, &none, &err) == RND_OK, "none: %s",
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
			REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, &asked, &err) == RND_OK, "asked: %s",
			        err.msg);
			REQUIRE(rnd_shadow_plan(&f.scene, &scene, &cp, &whole, &err) == RND_OK, "whole: %s", err.msg);
			CHECK(!memcmp(&asked.views[0], &whole.views[0], sizeof asked.views[0]),
			      "dir %d: an asked-for resolution under the default must keep the whole scene's map", di);
			f.light.shadow.resolution = 4096;
			REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, &asked, &err) == RND_OK, "4096: %s",
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
		REQUIRE(rnd_shadow_plan_with(&f.scene, &scene, &casters, &cp, NULL, &plan[c], &err) == RND_OK, "plan: %s",
		        err.msg);
	}
	const struct umbra_shadow_view *far = &plan[0].views[0], *near = &plan[1].views[0];
	CHECK(near->params[0] < 0.6f * far->params[0], "texel %g from 1.5 m, %g from 40 m", near->params[0], far->params[0]);
	CHECK(near->rect[2] <= 2.0f * far->rect[2], "tile %g from 1.5 m, %g from 40 m", near->rect[2], far->rect[2]);
	CHECK(plan[1].lights[0].size_rule == RND_SIZE_CASTERS, "size rule %u", plan[1].lights[0].size_rule);
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

/* ---- auto mode ------------------------------------------------------------------------------- */

TEST(plan_auto_mode_chooses_fit_or_cascades)
{
	struct rnd_error err = {0};
	struct rnd_camera_plan cp;
	static struct rnd_shadow_plan sp;
	{
		struct fixture f;
		fixture_init(&f, 4.0f, RND_LIGHT_DIRECTIONAL);
		set3(f.light.direction, -0.3f, -1, -0.4f);
		REQUIRE(f.light.shadow.dir_mode == RND_DIR_AUTO, "default dir mode is auto");
		camera_at(&f.scene.camera, 0, 3, 5, 0, 0, 0, 0, 0);
		REQUIRE(rnd_camera_plan(&f.scene.camera, 512, 512, &f.bounds, &cp, &err) == RND_OK, "camera: %s", err.msg);
		REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
		CHECK(sp.view_count == 1 && sp.lights[0].view_count == 1, "small scene nearby: %u views, want 1 (fit)", sp.view_count);
	}
	{
		struct fixture f;
		fixture_init(&f, 400.0f, RND_LIGHT_DIRECTIONAL);
		set3(f.light.direction, -0.3f, -1, -0.4f);
		camera_at(&f.scene.camera, 0, 2, 0, 10, 0, -10, 0, 0);
		REQUIRE(rnd_camera_plan(&f.scene.camera, 512, 512, &f.bounds, &cp, &err) == RND_OK, "camera: %s", err.msg);
		REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
		CHECK(sp.view_count == 4 && sp.lights[0].view_count == 4, "400 m plane from 2 m: %u views, want 4 cascades", sp.view_count);
		const float *s = sp.lights[0].splits;
		CHECK(s[0] > 0 && s[0] < s[1] && s[1] < s[2] && s[2] < s[3], "splits %g %g %g %g", s[0], s[1], s[2], s[3]);
		/* cascades: 2 in auto mode gives 2 views. */
		f.light.shadow.cascades = 2;
		REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
		CHECK(sp.view_count == 2, "cascades 2: %u views", sp.view_count);
	}
	{
		/* The same big plane seen from far away is one scale: fit. */
		struct fixture f;
		fixture_init(&f, 400.0f, RND_LIGHT_DIRECTIONAL);
		camera_at(&f.scene.camera, 0, 600, 600, 0, 0, 0, 0, 0);
		REQUIRE(rnd_camera_plan(&f.scene.camera, 512, 512, &f.bounds, &cp, &err) == RND_OK, "camera: %s", err.msg);
		REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
		CHECK(sp.view_count == 1, "400 m plane from 850 m: %u views, want 1 (fit)", sp.view_count);
	}
}

/* ---- spot and point lights ------------------------------------------------------------------- */

TEST(plan_spot_frustum_contains_cone)
{
	struct fixture f;
	fixture_init(&f, 20.0f, RND_LIGHT_SPOT);
	set3(f.light.position, 1.0f, 5.0f, -0.5f);
	set3(f.light.direction, 0.2f, -1.0f, 0.1f);
	const double outer = 35.0 * PI_D / 180.0;
	f.light.outer_angle = (float)outer;
	struct rnd_camera_plan cp;
	static struct rnd_shadow_plan sp;
	struct rnd_error err = {0};
	for (int pass = 0; pass < 2; pass++) {
		f.light.range = pass == 0 ? 0.0f : 9.0f;
		REQUIRE(rnd_camera_plan(&f.scene.camera, 512, 512, &f.bounds, &cp, &err) == RND_OK, "camera: %s", err.msg);
		REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
		REQUIRE(sp.view_count == 1 && sp.lights[0].view_count == 1, "spot: %u views", sp.view_count);
		const struct umbra_shadow_view *v = &sp.views[0];
		CHECK(!sp.view_ortho[0] && v->params[1] == 1.0f, "spot view is perspective");
		double d[3] = {0.2, -1.0, 0.1}, len = sqrt(0.04 + 1 + 0.01);
		for (int k = 0; k < 3; k++) d[k] /= len;
		double reach = f.light.range;
		if (reach <= 0) { /* farthest bounds corner from the light */
			reach = 0;
			for (int i = 0; i < 8; i++) {
				double p[3], s = 0;
				corner(&f.bounds, i, p);
				for (int k = 0; k < 3; k++) s += (p[k] - f.light.position[k]) * (p[k] - f.light.position[k]);
				reach = fmax(reach, sqrt(s));
			}
		}
		CHECK(v->params[3] >= reach, "far %g < reach %g", v->params[3], reach);
		/* The axis maps to the view centre. */
		double a[3], n[3];
		for (int k = 0; k < 3; k++) a[k] = f.light.position[k] + 3.0 * d[k];
		double w = ndc3(v->view_proj, a, n);
		CHECK(w > 0 && fabs(n[0]) < 1e-5 && fabs(n[1]) < 1e-5, "axis at ndc %g %g (w %g)", n[0], n[1], w);
		CHECK(n[2] > 0 && n[2] < 1, "axis depth %g", n[2]);
		/* An orthonormal basis around the axis. */
		double u[3] = {0, 0, 1}, e1[3], e2[3];
		e1[0] = d[1] * u[2] - d[2] * u[1]; e1[1] = d[2] * u[0] - d[0] * u[2]; e1[2] = d[0] * u[1] - d[1] * u[0];
		double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
		for (int k = 0; k < 3; k++) e1[k] /= l1;
		e2[0] = d[1] * e1[2] - d[2] * e1[1]; e2[1] = d[2] * e1[0] - d[0] * e1[2]; e2[2] = d[0] * e1[1] - d[1] * e1[0];
		for (int ti = 0; ti <= 4; ti++)
			for (int pi = 0; pi < 16; pi++)
				for (int ri = 0; ri < 3; ri++) {
					double th = outer * 0.999 * ti / 4.0, ph = 2.0 * PI_D * pi / 16.0;
					double dist = (ri == 0 ? 0.5 : ri == 1 ? 0.5 * reach : reach) * 0.999;
					double p[3];
					for (int k = 0; k < 3; k++)
						p[k] = f.light.position[k] + dist * (cos(th) * d[k] + sin(th) * (cos(ph) * e1[k] + sin(ph) * e2[k]));
					ndc3(v->view_proj, p, n);
					CHECK(inside_clip(n, 1e-6), "range %g: cone point theta %.3f phi %.3f dist %.2f at clip %.5f %.5f %.5f",
					      f.light.range, th, ph, dist, n[0], n[1], n[2]);
				}
		/* A point just outside the far range is beyond depth 1; one behind the light is culled (w < 0). */
		for (int k = 0; k < 3; k++) a[k] = f.light.position[k] + reach * 1.2 * d[k];
		ndc3(v->view_proj, a, n);
		CHECK(n[2] > 1.0, "point at 1.2 x reach has depth %g", n[2]);
	}
}

static int shader_face(const double d[3])
{
	double ax = fabs(d[0]), ay = fabs(d[1]), az = fabs(d[2]);
	if (ax >= ay && ax >= az) return d[0] > 0 ? 0 : 1;
	if (ay >= az) return d[1] > 0 ? 2 : 3;
	return d[2] > 0 ? 4 : 5;
}

TEST(plan_point_faces_cover_major_axis_directions)
{
	struct fixture f;
	fixture_init(&f, 20.0f, RND_LIGHT_POINT);
	set3(f.light.position, 0.5f, 2.0f, -0.3f);
	f.light.radius = 0.1f; /* PCSS: the widest filter margin */
	struct rnd_camera_plan cp;
	static struct rnd_shadow_plan sp;
	struct rnd_error err = {0};
	REQUIRE(rnd_camera_plan(&f.scene.camera, 512, 512, &f.bounds, &cp, &err) == RND_OK, "camera: %s", err.msg);
	REQUIRE(rnd_shadow_plan(&f.scene, &f.bounds, &cp, &sp, &err) == RND_OK, "shadow: %s", err.msg);
	REQUIRE(sp.view_count == 6 && sp.lights[0].view_count == 6 && sp.lights[0].first_view == 0, "point: %u views", sp.view_count);
	CHECK(sp.lights[0].filter == UMBRA_FILTER_PCSS, "auto filter with radius is PCSS (%u)", sp.lights[0].filter);
	static const double axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
	for (int fc = 0; fc < 6; fc++) {
		CHECK(!sp.view_ortho[fc] && sp.views[fc].params[1] == 1.0f, "face %d perspective", fc);
		CHECK(sp.view_light[fc] == 0, "face %d light %u", fc, sp.view_light[fc]);
		double p[3], n[3];
		for (int k = 0; k < 3; k++) p[k] = f.light.position[k] + 2.0 * axes[fc][k];
		double w = ndc3(sp.views[fc].view_proj, p, n);
		CHECK(w > 0 && fabs(n[0]) < 1e-5 && fabs(n[1]) < 1e-5, "face %d axis at %g %g (w %g)", fc, n[0], n[1], w);
	}
	double reach = 0;
	for (int i = 0; i < 8; i++) {
		double p[3], s = 0;
		corner(&f.bounds, i, p);
		for (int k = 0; k < 3; k++) s += (p[k] - f.light.position[k]) * (p[k] - f.light.position[k]);
		reach = fmax(reach, sqrt(s));
	}
	int tested = 0;
	/* A lat-long grid of directions plus the ties the shader breaks (x before y before z). */
	for (int la = 0; la <= 24; la++)
		for (int lo = 0; lo < 48; lo++) {
			double th = PI_D * la / 24.0, ph = 2.0 * PI_D * lo / 48.0;
			double d[3] = {sin(th) * cos(ph), cos(th), sin(th) * sin(ph)};
			int fc = shader_face(d);
			for (int ri = 0; ri < 2; ri++) {
				double dist = ri == 0 ? 0.3 : reach * 0.999, p[3], n[3];
				for (int k = 0; k < 3; k++) p[k] = f.light.position[k] + dist * d[k];
				ndc3(sp.views[fc].view_proj, p, n);
				CHECK(inside_clip(n, 1e-6), "dir %.3f %.3f %.3f face %d dist %.2f at clip %.5f %.5f %.5f", d[0], d[1], d[2], fc, dist,
				      n[0], n[1], n[2]);
				tested++;
			}
		}
	for (int sx = -1; sx <= 1; sx += 2)
		for (int sy = -1; sy <= 1; sy += 2)
			for (int sz = -1; sz <= 1; sz += 2) {
				double d[3] = {sx / sqrt(3.0), sy / sqrt(3.0), sz / sqrt(3.0)}, p[3], n[3];
				int fc = shader_face(d);
				CHECK(fc == (sx > 0 ? 0 : 1), "tie goes to x");
				for (int k = 0; k < 3; k++) p[k] = f.light.position[k] + 1.0 * d[k];
				ndc3(sp.views[fc].view_proj, p, n);
				CHECK(inside_clip(n, 1e-6), "diagonal %d %d %d face %d at %.5f %.5f %.5f", sx, sy, sz, fc, n[0], n[1], n[2]);
				/* and inside the filter margin: strictly within the frame */
				CHECK(fabs(n[0]) < 1.0 - 1e-3 && fabs(n[1]) < 1.0 - 1e-3, "diagonal on the face edge: %g %g", n[0], n[1]);
			}
	CHECK(tested > 0, "no directions");
}

TEST(plan_shadow_limits_and_errors)
{
	static struct rnd_light lights[64];
	struct rnd_aabb b;
	set_box(&b, -5, 0, -5, 5, 1, 5);
	struct rnd_scene sc;
	rnd_scene_defaults(&sc);
	struct rnd_camera_plan cp;
	static struct rnd_shadow_plan sp;
	struct rnd_error err = {0};
	REQUIRE(rnd_camera_plan(&sc.camera, 512, 512, &b, &cp, &err) == RND_OK, "camera: %s", err.msg);
	/* 42 point lights = 252 views fit; 43 = 258 do not. */
	for (int i = 0; i < 64; i++) {
		rnd_light_defaults(&lights[i], RND_LIGHT_POINT);
		set3(lights[i].position, (float)(i % 8) - 4.0f, 2.0f, (float)(i / 8) - 4.0f);
	}
	sc.lights = lights;
	sc.light_count = 42;
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_OK, "42 point lights: %s", err.msg);
	CHECK(sp.view_count == 252, "%u views", sp.view_count);
	for (uint32_t i = 0; i < 42; i++)
		CHECK(sp.lights[i].first_view == 6 * i && sp.lights[i].view_count == 6 && sp.view_light[6 * i + 5] == i, "light %u layout", i);
	sc.light_count = 43;
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_ERR_LIMIT, "43 point lights must exceed the view limit");
	/* Disabled shadows take no views. */
	lights[0].shadow.enabled = false;
	sc.light_count = 43;
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_OK, "42 shadowed of 43: %s", err.msg);
	CHECK(sp.lights[0].view_count == 0 && sp.lights[1].first_view == 0, "unshadowed light takes no view");
	lights[0].shadow.enabled = true;
	/* Moment filters plan moment views; EVSM keeps the caller's exponent for render.c to clamp. */
	sc.light_count = 1;
	lights[0].shadow.filter = RND_FILTER_VSM;
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_OK && sp.lights[0].moments && !sp.lights[0].evsm &&
	      sp.lights[0].filter == UMBRA_FILTER_MOMENTS, "vsm plans moment maps");
	lights[0].shadow.filter = RND_FILTER_EVSM;
	lights[0].shadow.vsm_exponent = 7.0f;
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_OK && sp.lights[0].evsm && sp.lights[0].evsm_exponent == 7.0f,
	      "evsm plans moment maps with the exponent");
	lights[0].shadow.vsm_exponent = 0.0f;
	lights[0].shadow.filter = RND_FILTER_AUTO;
	/* Resolution: the largest any light asks for; default 2048. */
	sc.light_count = 2;
	lights[0].shadow.resolution = 512; lights[1].shadow.resolution = 4096;
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_OK && sp.resolution == 4096, "resolution %u", sp.resolution);
	lights[0].shadow.resolution = 0; lights[1].shadow.resolution = 0;
	/* Without a resolution, a point light's face size follows its share of the view: between
	 * 256 and 512, a power of two, and a light whose lit region fills the view gets 512; a
	 * hard one (no radius, PCF) up to twice that, 1024 at most. */
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_OK, "%s", err.msg);
	for (uint32_t i = 0; i < 2; i++) {
		uint32_t r = sp.lights[i].resolution;
		CHECK(r >= 256 && r <= 1024 && (r & (r - 1)) == 0, "light %u: face size %u", i, r);
	}
	lights[0].radius = lights[1].radius = 0.1f;
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_OK, "%s", err.msg);
	for (uint32_t i = 0; i < 2; i++) {
		uint32_t r = sp.lights[i].resolution;
		CHECK(r >= 256 && r <= 512 && (r & (r - 1)) == 0, "soft light %u: face size %u", i, r);
	}
	lights[0].radius = lights[1].radius = 0.0f;
	/* A resolution that is not a power of two rounds up to the next tile size. */
	lights[0].shadow.resolution = 1000;
	CHECK(rnd_shadow_plan(&sc, &b, &cp, &sp, &err) == RND_OK && sp.lights[0].resolution == 1024,
	      "1000 -> %u", sp.lights[0].resolution);
	lights[0].shadow.resolution = 0;
}

/* ---- frustum culling ------------------------------------------------------------------------- */

TEST(plan_aabb_in_frustum)
{
	float view[16], proj[16], m[16];
	float eye[3] = {0, 0, 0}, tgt[3] = {0, 0, -1}, up[3] = {0, 1, 0};
	rnd_mat4_look_at(view, eye, tgt, up);
	/* Orthographic: x, y in -1..1, visible z from -1 (near) to -10 (far). */
	rnd_mat4_ortho(proj, -1, 1, -1, 1, 1, 10);
	rnd_mat4_mul(m, proj, view);
	struct rnd_aabb b;
	set_box(&b, -0.5f, -0.5f, -5, 0.5f, 0.5f, -4);
	CHECK(rnd_aabb_in_frustum(&b, m, false) && rnd_aabb_in_frustum(&b, m, true), "inside");
	set_box(&b, -5, -5, -20, 5, 5, 5);
	CHECK(rnd_aabb_in_frustum(&b, m, false), "box containing the frustum");
	set_box(&b, 2, -0.5f, -5, 3, 0.5f, -4);
	CHECK(!rnd_aabb_in_frustum(&b, m, false) && !rnd_aabb_in_frustum(&b, m, true), "right of the frustum");
	set_box(&b, -3, -0.5f, -5, -1.01f, 0.5f, -4);
	CHECK(!rnd_aabb_in_frustum(&b, m, false), "left of the frustum");
	set_box(&b, -0.5f, 1.5f, -5, 0.5f, 2, -4);
	CHECK(!rnd_aabb_in_frustum(&b, m, false), "above the frustum");
	set_box(&b, -0.5f, -2, -5, 0.5f, -1.2f, -4);
	CHECK(!rnd_aabb_in_frustum(&b, m, false), "below the frustum");
	set_box(&b, 0.5f, -0.5f, -5, 3, 0.5f, -4);
	CHECK(rnd_aabb_in_frustum(&b, m, false), "straddling the right plane");
	set_box(&b, -0.5f, -0.5f, -12, 0.5f, 0.5f, -8);
	CHECK(rnd_aabb_in_frustum(&b, m, false), "straddling the far plane");
	set_box(&b, -0.5f, -0.5f, -2, 0.5f, 0.5f, -0.5f);
	CHECK(rnd_aabb_in_frustum(&b, m, false), "straddling the near plane");
	set_box(&b, -0.5f, -0.5f, -14, 0.5f, 0.5f, -11);
	CHECK(!rnd_aabb_in_frustum(&b, m, false) && !rnd_aabb_in_frustum(&b, m, true), "beyond far, with or without no_near");
	/* Between the eye and the near plane, and behind the eye: culled, unless no_near. */
	set_box(&b, -0.5f, -0.5f, -0.9f, 0.5f, 0.5f, -0.2f);
	CHECK(!rnd_aabb_in_frustum(&b, m, false), "in front of the near plane is outside");
	CHECK(rnd_aabb_in_frustum(&b, m, true), "no_near keeps a box in front of the near plane");
	set_box(&b, -0.5f, -0.5f, 3, 0.5f, 0.5f, 4);
	CHECK(!rnd_aabb_in_frustum(&b, m, false), "behind the eye is outside");
	CHECK(rnd_aabb_in_frustum(&b, m, true), "no_near keeps a caster behind the eye (depth clamp)");
	set_box(&b, 2, -0.5f, 3, 3, 0.5f, 4);
	CHECK(!rnd_aabb_in_frustum(&b, m, true), "no_near still tests the side planes");

	/* Perspective 90 degrees, near 1, far 10: at depth 5 the half-width is 5. */
	rnd_mat4_perspective(proj, (float)(PI_D / 2), 1.0f, 1.0f, 10.0f);
	rnd_mat4_mul(m, proj, view);
	set_box(&b, 3, -1, -5.5f, 4, 1, -5);
	CHECK(rnd_aabb_in_frustum(&b, m, false), "perspective: inside near the side");
	set_box(&b, 6, -1, -5.5f, 7, 1, -5);
	CHECK(!rnd_aabb_in_frustum(&b, m, false), "perspective: beside the frustum");
	set_box(&b, -1, -1, 2, 1, 1, 3);
	CHECK(!rnd_aabb_in_frustum(&b, m, false), "perspective: behind the camera");
	set_box(&b, -0.2f, -0.2f, -0.8f, 0.2f, 0.2f, -0.5f);
	CHECK(!rnd_aabb_in_frustum(&b, m, false), "perspective: before the near plane");
	set_box(&b, 4.5f, -1, -5.5f, 8, 1, -5);
	CHECK(rnd_aabb_in_frustum(&b, m, false), "perspective: straddling the side");

	/* The camera's reversed-Z view_proj: both depth planes still cull. */
	struct rnd_camera cam;
	struct rnd_scene sc;
	rnd_scene_defaults(&sc);
	cam = sc.camera;
	camera_at(&cam, 0, 0, 0, 0, 0, -1, 1.0f, 10.0f);
	struct rnd_camera_plan cp;
	struct rnd_error err = {0};
	REQUIRE(rnd_camera_plan(&cam, 512, 512, NULL, &cp, &err) == RND_OK, "camera: %s", err.msg);
	set_box(&b, -0.5f, -0.5f, -5, 0.5f, 0.5f, -4);
	CHECK(rnd_aabb_in_frustum(&b, cp.view_proj, false), "camera: inside");
	set_box(&b, -0.5f, -0.5f, -14, 0.5f, 0.5f, -11);
	CHECK(!rnd_aabb_in_frustum(&b, cp.view_proj, false), "camera: beyond far");
	set_box(&b, -0.2f, -0.2f, -0.8f, 0.2f, 0.2f, -0.5f);
	CHECK(!rnd_aabb_in_frustum(&b, cp.view_proj, false), "camera: before near");
	set_box(&b, -1, -1, 2, 1, 1, 3);
	CHECK(!rnd_aabb_in_frustum(&b, cp.view_proj, false), "camera: behind");
}

/* ---- camera ---------------------------------------------------------------------------------- */

TEST(plan_camera_derived_near_far_bracket_bounds)
{
	struct rnd_scene sc;
	rnd_scene_defaults(&sc);
	struct rnd_aabb b;
	set_box(&b, -2, 0, -3, 3, 1.5f, 2);
	static const float cams[][6] = {{6, 4, 8, 0, 0.5f, 0}, {0, 30, 0.1f, 0, 0, 0}, {-15, 1, 2, 3, 0, -1}};
	for (int ci = 0; ci < 3; ci++) {
		for (int ortho = 0; ortho < 2; ortho++) {
			struct rnd_camera cam = sc.camera;
			camera_at(&cam, cams[ci][0], cams[ci][1], cams[ci][2], cams[ci][3], cams[ci][4], cams[ci][5], 0, 0);
			if (ortho) { cam.type = RND_CAMERA_ORTHOGRAPHIC; cam.height = 8; }
			struct rnd_camera_plan cp;
			struct rnd_error err = {0};
			REQUIRE(rnd_camera_plan(&cam, 640, 480, &b, &cp, &err) == RND_OK, "camera: %s", err.msg);
			CHECK(cp.ortho == (ortho != 0), "ortho flag");
			double f[3] = {cams[ci][3] - cams[ci][0], cams[ci][4] - cams[ci][1], cams[ci][5] - cams[ci][2]};
			double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
			double dmin = 1e30, dmax = -1e30;
			for (int i = 0; i < 8; i++) {
				double p[3], z = 0, n[3];
				corner(&b, i, p);
				for (int k = 0; k < 3; k++) z += (p[k] - cams[ci][k]) * f[k] / fl;
				dmin = fmin(dmin, z); dmax = fmax(dmax, z);
				ndc3(cp.view_proj, p, n);
				CHECK(n[2] >= 0.0 && n[2] <= 1.0, "cam %d ortho %d: corner %d depth %g outside 0..1", ci, ortho, i, n[2]);
			}
			CHECK(cp.znear <= dmin && cp.zfar >= dmax, "cam %d ortho %d: near/far %g %g do not bracket %g..%g", ci, ortho,
			      cp.znear, cp.zfar, dmin, dmax);
			CHECK(cp.znear >= 0 && cp.zfar > cp.znear, "cam %d: near %g far %g", ci, cp.znear, cp.zfar);
			if (!ortho) CHECK(cp.znear > 0 && cp.znear >= 0.5 * dmin, "cam %d: near %g not tight (dmin %g)", ci, cp.znear, dmin);
			CHECK(cp.zfar <= 1.1 * dmax + 0.01, "cam %d ortho %d: far %g not tight (dmax %g)", ci, ortho, cp.zfar, dmax);
			for (int k = 0; k < 3; k++) CHECK(fabs(cp.fwd[k] - f[k] / fl) < 1e-5, "fwd[%d]", k);
		}
	}
	/* Empty bounds: a usable default range. */
	struct rnd_aabb e;
	rnd_aabb_empty(&e);
	struct rnd_camera_plan cp;
	struct rnd_error err = {0};
	REQUIRE(rnd_camera_plan(&sc.camera, 512, 512, &e, &cp, &err) == RND_OK, "empty: %s", err.msg);
	CHECK(cp.znear > 0 && cp.zfar > cp.znear, "empty bounds: near %g far %g", cp.znear, cp.zfar);
	/* Position equal to target is an error. */
	struct rnd_camera bad = sc.camera;
	memcpy(bad.target, bad.position, sizeof bad.target);
	CHECK(rnd_camera_plan(&bad, 512, 512, &b, &cp, &err) == RND_ERR_INVALID, "position == target must fail");
}

TEST(plan_camera_reversed_z)
{
	struct rnd_scene sc;
	rnd_scene_defaults(&sc);
	for (int ortho = 0; ortho < 2; ortho++) {
		struct rnd_camera cam = sc.camera;
		camera_at(&cam, 1, 2, 3, -2, 0.5f, -4, 0.5f, 50.0f);
		if (ortho) { cam.type = RND_CAMERA_ORTHOGRAPHIC; cam.height = 6; }
		struct rnd_camera_plan cp;
		struct rnd_error err = {0};
		REQUIRE(rnd_camera_plan(&cam, 800, 600, NULL, &cp, &err) == RND_OK, "camera: %s", err.msg);
		CHECK(cp.znear == 0.5f && cp.zfar == 50.0f, "explicit near/far kept: %g %g", cp.znear, cp.zfar);
		CHECK(fabs(cp.aspect - 800.0 / 600.0) < 1e-6, "aspect %g", cp.aspect);
		double pn[3], pf[3], pm[3], pu[3], n[3];
		for (int k = 0; k < 3; k++) {
			pn[k] = cp.pos[k] + 0.5 * cp.fwd[k];
			pf[k] = cp.pos[k] + 50.0 * cp.fwd[k];
			pm[k] = cp.pos[k] + 5.0 * cp.fwd[k];
			pu[k] = cp.pos[k] + 5.0 * cp.fwd[k] + 1.0 * cp.up[k];
		}
		ndc3(cp.view_proj, pn, n);
		CHECK(fabs(n[2] - 1.0) < 1e-5, "ortho %d: near plane depth %.7f, want 1", ortho, n[2]);
		CHECK(fabs(n[0]) < 1e-5 && fabs(n[1]) < 1e-5, "forward axis off centre %g %g", n[0], n[1]);
		ndc3(cp.view_proj, pf, n);
		CHECK(fabs(n[2]) < 1e-5, "ortho %d: far plane depth %.7f, want 0", ortho, n[2]);
		ndc3(cp.view_proj, pm, n);
		CHECK(n[2] > 0 && n[2] < 1, "ortho %d: mid depth %g", ortho, n[2]);
		double dm = n[2];
		double p6[3];
		for (int k = 0; k < 3; k++) p6[k] = cp.pos[k] + 6.0 * cp.fwd[k];
		ndc3(cp.view_proj, p6, n);
		CHECK(n[2] < dm, "ortho %d: depth must fall with distance (%g then %g)", ortho, dm, n[2]);
		/* Vulkan clip: a point above the axis has negative clip y. */
		ndc3(cp.view_proj, pu, n);
		CHECK(n[1] < 0, "ortho %d: point above the axis at clip y %g", ortho, n[1]);
		/* Up is orthogonal to forward and unit length. */
		double dot = cp.up[0] * cp.fwd[0] + cp.up[1] * cp.fwd[1] + cp.up[2] * cp.fwd[2];
		double ul = sqrt(cp.up[0] * cp.up[0] + cp.up[1] * cp.up[1] + cp.up[2] * cp.up[2]);
		CHECK(fabs(dot) < 1e-5 && fabs(ul - 1) < 1e-5, "up not orthonormal: dot %g len %g", dot, ul);
	}
}

TEST(plan_camera_fit_frames_bounds)
{
	struct rnd_scene sc;
	rnd_scene_defaults(&sc);
	struct rnd_aabb b;
	set_box(&b, -1, 0, -2, 3, 2.5f, 1);
	static const uint32_t sizes[][2] = {{800, 600}, {600, 800}, {512, 512}};
	static const float dirs[][3] = {{-1, -0.5f, -1}, {0, 0, -1}, {0.3f, -1, 0.2f}};
	for (int si = 0; si < 3; si++)
		for (int di = 0; di < 3; di++) {
			struct rnd_camera cam = sc.camera;
			cam.fit = RND_FIT_SCENE;
			memcpy(cam.fit_direction, dirs[di], sizeof cam.fit_direction);
			cam.fit_margin = 0.1f;
			struct rnd_camera_plan cp;
			struct rnd_error err = {0};
			REQUIRE(rnd_camera_plan(&cam, sizes[si][0], sizes[si][1], &b, &cp, &err) == RND_OK, "fit: %s", err.msg);
			CHECK(!cp.ortho, "fit is perspective");
			double c[3], r = 0, dl = 0;
			for (int k = 0; k < 3; k++) {
				c[k] = 0.5 * (b.min[k] + b.max[k]);
				r += (b.max[k] - b.min[k]) * (b.max[k] - b.min[k]);
				dl += dirs[di][k] * dirs[di][k];
			}
			r = 0.5 * sqrt(r); dl = sqrt(dl);
			for (int k = 0; k < 3; k++)
				CHECK(fabs(cp.fwd[k] - dirs[di][k] / dl) < 1e-5, "size %d dir %d: fwd[%d] %g", si, di, k, cp.fwd[k]);
			/* The centre is on the axis. */
			double n[3];
			double w = ndc3(cp.view_proj, c, n);
			CHECK(w > 0 && fabs(n[0]) < 1e-5 && fabs(n[1]) < 1e-5, "centre at %g %g", n[0], n[1]);
			/* Every corner of the box stays within the frame less the margin on each side, and
			 * the widest one touches that limit (tight framing, contract: bounds fill the frame up
			 * to the margin). */
			double ext[2] = {0, 0};
			for (int i = 0; i < 8; i++) {
				double p[3] = {i & 1 ? b.max[0] : b.min[0], i & 2 ? b.max[1] : b.min[1], i & 4 ? b.max[2] : b.min[2]};
				w = ndc3(cp.view_proj, p, n);
				CHECK(w > 0, "corner behind the camera");
				for (int a = 0; a < 2; a++) ext[a] = fmax(ext[a], fabs(n[a]));
			}
			(void)r;
			double lim = 1.0 - 2.0 * 0.1;
			CHECK(ext[0] <= lim + 1e-4 && ext[1] <= lim + 1e-4, "size %d dir %d: box reaches ndc %.4f %.4f > %.2f", si, di,
			      ext[0], ext[1], lim);
			CHECK(fmax(ext[0], ext[1]) >= lim - 1e-3, "size %d dir %d: box reaches only %.4f %.4f", si, di, ext[0], ext[1]);
			/* The bounds are within the derived depth range. */
			for (int i = 0; i < 8; i++) {
				double p[3];
				corner(&b, i, p);
				ndc3(cp.view_proj, p, n);
				CHECK(n[2] >= 0 && n[2] <= 1, "fit: corner %d depth %g", i, n[2]);
			}
		}
	struct rnd_camera cam = sc.camera;
	cam.fit = RND_FIT_SCENE;
	set3(cam.fit_direction, 0, 0, 0);
	struct rnd_camera_plan cp;
	struct rnd_error err = {0};
	CHECK(rnd_camera_plan(&cam, 512, 512, &b, &cp, &err) == RND_ERR_INVALID, "zero fit direction must fail");
}

TEST(plan_light_importance_sets_tile_size)
{
	/* Two point lights without a resolution: one whose lit region fills the view, one small
	 * (range 0.3 m) far from the camera. The first gets the largest face, the second the least. */
	struct rnd_scene sc;
	rnd_scene_defaults(&sc);
	struct rnd_light lights[2];
	rnd_light_defaults(&lights[0], RND_LIGHT_POINT);
	rnd_light_defaults(&lights[1], RND_LIGHT_POINT);
	lights[0].position[0] = 0; lights[0].position[1] = 2; lights[0].position[2] = 0;
	lights[1].position[0] = 40; lights[1].position[1] = 1; lights[1].position[2] = -40;
	lights[1].range = 0.3f;
	sc.lights = lights;
	sc.light_count = 2;
	struct rnd_aabb b = {{-50, 0, -50}, {50, 5, 50}};
	struct rnd_camera cam = sc.camera;
	cam.position[0] = 0; cam.position[1] = 3; cam.position[2] = 8;
	cam.target[0] = 0; cam.target[1] = 0; cam.target[2] = 0;
	struct rnd_camera_plan cp;
	struct rnd_shadow_plan *sp = calloc(1, sizeof *sp);
	struct rnd_error err = {0};
	REQUIRE(sp && rnd_camera_plan(&cam, 512, 512, &b, &cp, &err) == RND_OK, "camera: %s", err.msg);
	REQUIRE(rnd_shadow_plan(&sc, &b, &cp, sp, &err) == RND_OK, "plan: %s", err.msg);
	/* Both are hard (no radius, PCF): the near one's faces double so that its 3-texel kernel
	 * stays within a pixel (cube faces stop at 1024); the small far one's reach (0.3 m) is
	 * seen from 56 m and needs no more than importance gives it. */
	CHECK(sp->lights[0].resolution == 1024, "near light face %u", sp->lights[0].resolution);
	CHECK(sp->lights[1].resolution == 256, "small far light face %u", sp->lights[1].resolution);
	/* With a radius (PCSS) importance alone decides. */
	lights[0].radius = lights[1].radius = 0.05f;
	REQUIRE(rnd_shadow_plan(&sc, &b, &cp, sp, &err) == RND_OK, "plan: %s", err.msg);
	CHECK(sp->lights[0].resolution == 512, "near soft light face %u", sp->lights[0].resolution);
	CHECK(sp->lights[1].resolution == 256, "small far soft light face %u", sp->lights[1].resolution);
	/* A server's cap bounds the renderer's choices (the power of two at or below it): the hard
	 * near light's 1024 and a sun's default 2048 come down to 512 under a cap of 700; an
	 * explicit resolution is the parser's to refuse, not the planner's to change. */
	lights[0].radius = lights[1].radius = 0;
	struct rnd_light sun;
	rnd_light_defaults(&sun, RND_LIGHT_DIRECTIONAL);
	struct rnd_light three[3] = {lights[0], lights[1], sun};
	sc.lights = three;
	sc.light_count = 3;
	sc.max_shadow_resolution = 700;
	REQUIRE(rnd_shadow_plan(&sc, &b, &cp, sp, &err) == RND_OK, "plan: %s", err.msg);
	CHECK(sp->lights[0].resolution == 512, "capped near light face %u", sp->lights[0].resolution);
	CHECK(sp->lights[1].resolution == 256, "capped small light face %u", sp->lights[1].resolution);
	CHECK(sp->lights[2].resolution == 512, "capped sun %u", sp->lights[2].resolution);
	sc.max_shadow_resolution = 0;
	REQUIRE(rnd_shadow_plan(&sc, &b, &cp, sp, &err) == RND_OK, "plan: %s", err.msg);
	CHECK(sp->lights[0].resolution == 1024 && sp->lights[2].resolution == 2048, "uncapped: near %u, sun %u",
	      sp->lights[0].resolution, sp->lights[2].resolution);
	three[0].shadow.resolution = 1024;
	sc.max_shadow_resolution = 700;
	REQUIRE(rnd_shadow_plan(&sc, &b, &cp, sp, &err) == RND_OK, "plan: %s", err.msg);
	CHECK(sp->lights[0].resolution == 1024, "explicit resolution under a cap %u", sp->lights[0].resolution);
	free(sp);
}

/* The map sides the planner draws (rnd_shadow_map_side): a resolution asked for rounds up to a
 * power of two (what the parser holds against a server's limit); one the renderer chooses
 * stays at or below the cap. */
TEST(plan_shadow_map_side)
{
	CHECK(rnd_shadow_map_side(1000, true, 0) == 1024, "asked 1000 -> %u", rnd_shadow_map_side(1000, true, 0));
	CHECK(rnd_shadow_map_side(1000, true, 512) == 1024, "an asked size ignores the cap");
	CHECK(rnd_shadow_map_side(0, false, 0) == RND_DEFAULT_SHADOW_RESOLUTION, "the default");
	CHECK(rnd_shadow_map_side(0, false, 1000) == 512, "default under a cap of 1000 -> %u", rnd_shadow_map_side(0, false, 1000));
	CHECK(rnd_shadow_map_side(0, false, 64) == 64, "default under a cap of 64");
	CHECK(rnd_shadow_map_side(100000, true, 0) == 8192 && rnd_shadow_map_side(10, true, 0) == 64, "the bounds 64..8192");
}

/* PCSS's blocker search stops at the first of its wide taps (the even entries of the frame's
 * Poisson table) that lies beyond what any blocker can reach (shaders/shading.glsl pcss): that
 * is exact only while those taps come in ascending length. And params.w, how far the taps
 * reach (pcss_bounds), is the longest of all 32. */
TEST(plan_poisson_wide_taps_ascend)
{
	float longest = 0;
	const float *t = rnd_frame_poisson(&longest);
	float prev = 0, worst = 0;
	for (int i = 0; i < 32; i++) {
		float len = sqrtf(t[2 * i] * t[2 * i] + t[2 * i + 1] * t[2 * i + 1]);
		if (len > worst) worst = len;
		if (i % 2 == 0) {
			CHECK(len >= prev, "wide tap %d (entry %d) is shorter than the one before: %g < %g", i / 2, i, len, prev);
			prev = len;
		}
	}
	CHECK(longest == worst && longest > 1.0f, "longest tap %g, table's %g", longest, worst);
}
