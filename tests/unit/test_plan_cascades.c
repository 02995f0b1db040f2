/* tests — renderer/plan.c: a sun's cascades (the practical split scheme, stable under the camera's
 * rotation and translation, each slice covered) and the `auto` choice between cascades and one
 * `fit` map, checked against values computed here independently. */
#include <math.h>
#include <string.h>
#include "test.h"
#include "plan.h"
#include "plan_util.h"

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
