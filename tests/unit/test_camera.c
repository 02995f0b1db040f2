/* tests — renderer/camera.c: near and far derived around the bounds, reversed Z, `fit` framing;
 * and rnd_aabb_in_frustum (plan.c), checked against values computed here independently. */
#include <math.h>
#include <string.h>
#include "test.h"
#include "plan.h"
#include "plan_util.h"

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
