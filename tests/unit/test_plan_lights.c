/* tests — renderer/plan.c: spot and point lights' shadow views (the cone inside its frustum, the
 * cube's faces as the shader picks them), the plan's limits and errors, map sizes (a light's
 * importance, the sides drawn) and PCSS's tap order (frame.c). */
#include <math.h>
#include <stdlib.h>
#include "test.h"
#include "frame.h"
#include "plan.h"
#include "plan_util.h"

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

/* PCSS filters with the taps as (tap - centre) * scale (umbra_frame.filter_taps): they stand for a
 * uniform disk of the penumbra's half-width, so they must average at its centre and have its
 * mean squared radius, 1/2, and stay within the longest tap (the reach pcss_bounds and the
 * views' margins allow). The table as it is averages at (-0.061, -0.030) with mean squared
 * radius 0.663: every penumbra 15 % too wide and off centre (issue 31). */
TEST(plan_pcss_filter_taps_are_a_uniform_disk)
{
	float longest = 0;
	const float *t = rnd_frame_poisson(&longest);
	/* the lights' filter: all 32 taps; the environment's (ibl.glsl env_pcss): the 16 odd ones */
	for (int set = 0; set < 2; set++) {
		float ft[3] = {0, 0, 0};
		int first = set, step = set ? 2 : 1, n = 32 / step;
		rnd_frame_filter_taps(ft, first, step);
		double mx = 0, my = 0, r2 = 0, far = 0;
		for (int i = first; i < 32; i += step) {
			double x = (t[2 * i] - ft[0]) * ft[2], y = (t[2 * i + 1] - ft[1]) * ft[2];
			mx += x / n;
			my += y / n;
			r2 += (x * x + y * y) / n;
			if (sqrt(x * x + y * y) > far) far = sqrt(x * x + y * y);
		}
		CHECK(fabs(mx) < 1e-5 && fabs(my) < 1e-5, "set %d: filter taps average at (%g, %g), not the centre", set, mx, my);
		CHECK(fabs(r2 - 0.5) < 1e-4, "set %d: filter taps' mean squared radius %g, a uniform disk's is 0.5", set, r2);
		CHECK(far <= longest, "set %d: a filter tap reaches %g, beyond the longest tap %g", set, far, (double)longest);
	}
}
