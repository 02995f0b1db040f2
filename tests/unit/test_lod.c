/* tests — renderer/lod.c: the segment rule of spheres and cylinders (chord error of centred
 * chords against the bound, minimal and even), the world size of a pixel, the cap at the
 * segments asked for, a whole scene's choice, and the plane that shadows nothing. Expected
 * values are computed here independently in double. */
#include <math.h>
#include <string.h>
#include "test.h"
#include "thumb_scene.h"
#include "casters.h"
#include "lod.h"

#define PI_D 3.14159265358979323846

/* Largest distance of the centred polygon (radius from rnd_lod_radius) from the circle, in
 * double: vertices at R, chord middles at R cos(pi/S). */
static double centred_error(double r, uint32_t s)
{
	double R = rnd_lod_radius((float)r, s, s + 1);
	return fmax(fabs(R - r), fabs(r - R * cos(PI_D / s)));
}

TEST(lod_circle_segments_meet_bound_and_are_fewest)
{
	const double radii[] = {0.01, 1.0, 117.0, 5000.0};
	const double errs[] = {0.001, 0.03125, 0.125, 0.5};
	for (int a = 0; a < 4; a++)
		for (int b = 0; b < 4; b++) {
			double r = radii[a], e = errs[b];
			if (e < 1e-5 * r) continue; /* below float resolution of the radius */
			uint32_t s = rnd_lod_circle_segments((float)r, (float)e);
			if (e >= 0.5 * r) { CHECK(s == 4, "r %g e %g: %u", r, e, s); continue; }
			CHECK(s % 2 == 0 && s >= 4, "r %g e %g: %u segments (even, >= 4)", r, e, s);
			CHECK(centred_error(r, s) <= e * 1.0001 + 4e-7 * r, "r %g e %g: %u segments deviate %g", r, e, s,
			      centred_error(r, s));
			CHECK(fabs(rnd_lod_chord_error((float)r, s) - 0.5 * r * (1.0 - cos(PI_D / s))) <= 1e-3 * e,
			      "chord error of %u", s);
			/* two fewer (the next even count) would break the bound */
			if (s > 4) CHECK(0.5 * r * (1.0 - cos(PI_D / (s - 2))) > e * 0.9999, "r %g e %g: %u is not the fewest", r, e, s);
		}
	CHECK(rnd_lod_circle_segments(1.0f, 0.0f) == UINT32_MAX, "zero bound: no limit");
	CHECK(rnd_lod_circle_segments(INFINITY, 0.1f) == UINT32_MAX, "infinite radius: no limit");
}

TEST(lod_radius_centres_only_reduced_tessellations)
{
	CHECK(rnd_lod_radius(2.0f, 64, 64) == 2.0f, "as asked: exact radius");
	CHECK(rnd_lod_radius(2.0f, 64, 32) == 2.0f, "more than asked never happens; unchanged");
	float R = rnd_lod_radius(1.0f, 8, 64);
	double mid = R * cos(PI_D / 8);
	CHECK(fabs((R - 1.0) - (1.0 - mid)) < 1e-6, "vertices %g outside as far as chord middles %g inside", R - 1.0, 1.0 - mid);
}

TEST(lod_pixel_world_perspective_and_ortho)
{
	/* Perspective 90 degrees, 100 px high, looking down -Z from the origin: a pixel at depth d
	 * is 2 d / 100 wide. A sphere at depth 10 of radius 1: nearest depth 9. */
	float proj[16], view[16], vp[16];
	float eye[3] = {0, 0, 0}, at[3] = {0, 0, -1}, up[3] = {0, 1, 0};
	rnd_mat4_look_at(view, eye, at, up);
	rnd_mat4_perspective(proj, (float)(PI_D / 2), 1.0f, 0.1f, 100.0f);
	rnd_mat4_mul(vp, proj, view);
	float c[3] = {0, 0, -10};
	float pw = rnd_lod_pixel_world(vp, 100, 100, c, 1.0f, 0.1f);
	CHECK(fabsf(pw - 0.18f) < 1e-4f, "pixel at depth 9: %g (want 0.18)", pw);
	/* reaching behind the near plane: the size at near */
	pw = rnd_lod_pixel_world(vp, 100, 100, c, 20.0f, 0.1f);
	CHECK(fabsf(pw - 0.002f) < 1e-5f, "sphere around the eye: %g (want 0.002)", pw);
	/* orthographic 4 units high over 200 px: 0.02 everywhere */
	rnd_mat4_ortho(proj, -2, 2, -2, 2, 0.1f, 100.0f);
	rnd_mat4_mul(vp, proj, view);
	pw = rnd_lod_pixel_world(vp, 200, 200, c, 1.0f, 0.0f);
	CHECK(fabsf(pw - 0.02f) < 1e-5f, "ortho pixel %g (want 0.02)", pw);
}

TEST(lod_object_segments_never_exceed_what_was_asked)
{
	struct rnd_object o;
	rnd_object_defaults(&o);
	o.shape = RND_SHAPE_SPHERE;
	o.radius = 1.0f;
	o.segments = 8;
	CHECK(rnd_lod_object_segments(&o, 1e-6f, 0.03125f) == 8, "8 asked, tiny pixels: 8");
	o.segments = 316;
	uint32_t s = rnd_lod_object_segments(&o, 0.01f, 0.03125f); /* 100 px radius */
	CHECK(s < 316 && s == rnd_lod_circle_segments(1.0f, 0.01f * 0.03125f), "316 asked at 100 px: %u", s);
	o.model[0] = o.model[5] = o.model[10] = 3.0f; /* scaled: the world radius counts */
	CHECK(rnd_lod_object_segments(&o, 0.01f, 0.03125f) == rnd_lod_circle_segments(3.0f, 0.01f * 0.03125f), "scale 3");
	o.shape = RND_SHAPE_BOX;
	CHECK(rnd_lod_object_segments(&o, 0.01f, 0.03125f) == 316, "boxes are not touched");
}

TEST(lod_choose_thumbnail_sphere_meets_pixel_bound)
{
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light sun;
	static struct rnd_shadow_plan scratch;
	uint32_t seg[2], again[2], big[2];
	thumb_scene(&sc, obj, &sun, 512);
	rnd_lod_choose(&sc, 1, &scratch, seg);
	rnd_lod_choose(&sc, 1, &scratch, again);
	CHECK(seg[0] == obj[0].segments, "the plane keeps its segments (%u)", seg[0]);
	CHECK(seg[1] < 316 && seg[1] >= 8, "512 px: %u of 316 segments", seg[1]);
	CHECK(seg[1] == again[1], "deterministic: %u then %u", seg[1], again[1]);
	/* Independent bound: the sphere's nearest point is |(4,3,4) - (0,1,0)| - 1 from the eye; a
	 * pixel there is 2 d tan(20 deg) / 512; the centred chords must stay within 1/32 of it. */
	double d = sqrt(16.0 + 4.0 + 16.0) - 1.0, pw = 2.0 * d * tan(20 * PI_D / 180) / 512.0;
	CHECK(centred_error(1.0, seg[1]) <= pw / 32.0 * 1.01, "%u segments deviate %g > %g", seg[1],
	      centred_error(1.0, seg[1]), pw / 32.0);
	thumb_scene(&sc, obj, &sun, 2048);
	rnd_lod_choose(&sc, 1, &scratch, big);
	CHECK(big[1] > seg[1], "a larger image needs more: %u at 2048, %u at 512", big[1], seg[1]);
	sc.exact_segments = true;
	rnd_lod_choose(&sc, 1, &scratch, big);
	CHECK(big[1] == 316, "exact_segments: %u", big[1]);
}

TEST(lod_plane_under_objects_shadows_nothing)
{
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light sun;
	thumb_scene(&sc, obj, &sun, 256);
	struct rnd_aabb above = {{-1, 0, -1}, {1, 2, 1}}, through = {{-1, -0.5f, -1}, {1, 2, 1}};
	CHECK(!rnd_plane_may_shadow(&sc, &obj[0], &above), "sun from above, sphere resting on the plane");
	CHECK(rnd_plane_may_shadow(&sc, &obj[0], &through), "an object reaching below the plane");
	sun.direction[1] = 1.0f; /* from below: the plane is between the sun and the sphere */
	CHECK(rnd_plane_may_shadow(&sc, &obj[0], &above), "sun from below");
	sun.direction[1] = -1.0f;
	sun.shadow.enabled = false;
	CHECK(!rnd_plane_may_shadow(&sc, &obj[0], &through), "no shadowed light: nothing to shadow");
	struct rnd_light spot;
	rnd_light_defaults(&spot, RND_LIGHT_POINT);
	spot.position[1] = -3.0f; /* a point light under the ground */
	sc.lights = &spot;
	CHECK(rnd_plane_may_shadow(&sc, &obj[0], &above), "point light below the plane");
}

/* The ground under a thumbnail's sphere casts nothing, judged on the sphere as asked
 * (rnd_object_bounds): drawn with fewer segments, its radius is raised and it dips below the
 * ground, which made the ground a caster of a 2048^2 map (thumb-256: the shadow stage 5.4 of
 * 13 ms). It does cast under a sphere that reaches below it, and wherever a light filters with
 * moments (VSM needs the ground in the map behind the casters' edges). A mesh's bounds are
 * those it is drawn with. */
TEST(lod_plane_casts_judged_on_objects_as_asked)
{
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light sun;
	struct rnd_aabb b, dipping = {{-1.001f, -0.001f, -1.001f}, {1.001f, 2.001f, 1.001f}};
	thumb_scene(&sc, obj, &sun, 256);
	rnd_object_bounds(&sc, 1, &dipping, &b);
	CHECK(fabsf(b.min[1]) < 1e-6f && fabsf(b.max[1] - 2.0f) < 1e-6f && fabsf(b.min[0] + 1.0f) < 1e-6f,
	      "the sphere as asked: y %g..%g, x from %g", b.min[1], b.max[1], b.min[0]);
	CHECK(!rnd_plane_may_shadow(&sc, &obj[0], &b), "a sphere resting on the ground made the ground a caster");
	CHECK(rnd_plane_may_shadow(&sc, &obj[0], &dipping), "a box reaching below the ground: the ground must cast");
	obj[1].model[13] = 0.9f;
	rnd_object_bounds(&sc, 1, NULL, &b);
	CHECK(rnd_plane_may_shadow(&sc, &obj[0], &b), "a sphere reaching 0.1 below the ground: the ground must cast");
	obj[1].model[13] = 1.0f;
	rnd_object_bounds(&sc, 1, NULL, &b);
	CHECK(!rnd_moments_need_ground(&sc), "no moments filter: the ground need not be in the map");
	sun.shadow.filter = RND_FILTER_VSM;
	CHECK(rnd_moments_need_ground(&sc), "vsm: the ground must be in the map");
	sun.shadow.filter = RND_FILTER_EVSM;
	CHECK(rnd_moments_need_ground(&sc), "evsm: the ground must be in the map");
	float pos[9] = {0, -0.5f, 0, 1, 1, 0, 0, 1, 1};
	obj[1].shape = RND_SHAPE_MESH;
	obj[1].positions = pos;
	obj[1].vertex_count = 3;
	obj[1].model[13] = 0.0f;
	struct rnd_aabb drawn = {{0, 0, 0}, {1, 1, 1}};
	rnd_object_bounds(&sc, 1, &drawn, &b);
	CHECK(b.min[1] == 0.0f, "a mesh: the bounds it is drawn with, y from %g", b.min[1]);
	rnd_object_bounds(&sc, 1, NULL, &b);
	CHECK(b.min[1] == -0.5f, "a mesh without drawn bounds: its vertices, y from %g", b.min[1]);
}

/* The camera of sc looking from pos at target (orthographic when height > 0), planned. */
static struct rnd_camera_plan plan_from(struct rnd_scene *sc, float x, float y, float z, float tx, float ty, float tz,
                                        float height)
{
	float pos[3] = {x, y, z}, tgt[3] = {tx, ty, tz};
	memcpy(sc->camera.position, pos, sizeof pos);
	memcpy(sc->camera.target, tgt, sizeof tgt);
	sc->camera.type = height > 0 ? RND_CAMERA_ORTHOGRAPHIC : RND_CAMERA_PERSPECTIVE;
	sc->camera.height = height;
	struct rnd_aabb bounds = {{-5, -1, -5}, {5, 2, 5}};
	struct rnd_camera_plan cam;
	struct rnd_error err;
	memset(&cam, 0, sizeof cam);
	CHECK(rnd_camera_plan(&sc->camera, sc->width, sc->height, &bounds, &cam, &err) == RND_OK, "%s", err.msg);
	return cam;
}

/* The ground's shadow on the part of an object sunk into it shows to no camera above the ground
 * (studio-spots' boxes): the ground need not cast. It does where a camera can see that part:
 * from below, past the ground's edge, through an alpha-tested or one-sided ground, through the
 * ground where the camera's near plane cuts it, or when the object sticks out beyond the
 * ground; and with any one of several views. */
TEST(lod_plane_shadow_on_sunk_parts_is_seen_by_no_camera_above)
{
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light sun;
	thumb_scene(&sc, obj, &sun, 256);
	struct rnd_aabb sunk = {{-1, -0.5f, -1}, {1, 2, 1}}, edge = {{4.2f, -0.5f, -1}, {5.4f, 1, 1}};
	struct rnd_camera_plan cam[2];
	cam[0] = plan_from(&sc, 4, 3, 4, 0, 0.8f, 0, 0);
	CHECK(rnd_plane_may_shadow(&sc, &obj[0], &sunk), "geometry alone: the ground shadows the sunk part");
	CHECK(!rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam, 1), "camera above: the sunk part is hidden");
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam, 0), "no camera: judged on geometry");
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &edge, cam, 1), "an object beyond the ground's edge");
	cam[1] = plan_from(&sc, 4, -3, 4, 0, 0, 0, 0);
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam + 1, 1), "camera below the ground");
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam, 2), "two views, one below");
	cam[1] = plan_from(&sc, 30, 0.5f, 0, 0, 0, 0, 0);
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam + 1, 1), "a low camera sees under the ground's edge");
	cam[1] = plan_from(&sc, 0, 10, 0.01f, 0, 0, 0, 6);
	CHECK(!rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam + 1, 1), "orthographic from above: hidden");
	sc.camera.near = 0.5f;   /* the near plane cuts the ground: the camera sees under it */
	cam[1] = plan_from(&sc, 2, 0.2f, 2, 0, 0, 0, 0);
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam + 1, 1), "near plane through the ground");
	sc.camera.near = 0.0f;
	obj[0].double_sided = false;
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam, 1), "a one-sided ground hides nothing");
	obj[0].double_sided = true;
	struct rnd_material m;
	rnd_material_defaults(&m);
	m.alpha_mode = RND_ALPHA_MASK;
	sc.materials = &m;
	sc.material_count = 1;
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &sunk, cam, 1), "an alpha-tested ground hides nothing");
	sc.material_count = 0;
	sun.direction[1] = 1.0f;   /* from below: the shadow falls on the parts above the ground */
	struct rnd_aabb resting = {{-1, 0, -1}, {1, 2, 1}};
	CHECK(rnd_plane_may_shadow_seen(&sc, &obj[0], &resting, cam, 1), "sun from below, camera above");
}
