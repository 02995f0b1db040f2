/* tests — api/ground.c (the plane that places itself) and api/preset.c ("preset": "thumbnail"):
 * the ground's height is checked against bounds computed here from first principles (the
 * transformed corners of a box, the transformed vertices of a mesh, the lowest point of a
 * scaled sphere), through api_ground_place and through the scene parser. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "ground.h"
#include "test.h"
#include "util.h"
#include "umbra/rnd_math.h"

static bool near_d(double a, double b)
{
	return fabs(a - b) <= 1e-4 * (1.0 + fabs(b));
}

/* The ground's height y for objects whose lowest point is lo and largest extent e: just below. */
static bool ground_at(double y, double lo, double e)
{
	return near_d(y + API_GROUND_GAP * e, lo) && y < lo;
}

/* Column-major T * R(angle about unit axis) * S. */
static void trs(float m[16], const float t[3], const float axis[3], float angle, const float s[3])
{
	float c = cosf(angle), sn = sinf(angle), x = axis[0], y = axis[1], z = axis[2];
	float r[9] = {c + x * x * (1 - c),     y * x * (1 - c) + z * sn, z * x * (1 - c) - y * sn,
	              x * y * (1 - c) - z * sn, c + y * y * (1 - c),     z * y * (1 - c) + x * sn,
	              x * z * (1 - c) + y * sn, y * z * (1 - c) - x * sn, c + z * z * (1 - c)};
	memset(m, 0, 16 * sizeof *m);
	for (int col = 0; col < 3; col++)
		for (int row = 0; row < 3; row++) m[col * 4 + row] = r[col * 3 + row] * s[col];
	m[12] = t[0]; m[13] = t[1]; m[14] = t[2]; m[15] = 1;
}

static double world_y(const float m[16], double x, double y, double z)
{
	return m[1] * x + m[5] * y + m[9] * z + m[13];
}

static void plane_object(struct rnd_object *g)
{
	rnd_object_defaults(g);
	g->shape = RND_SHAPE_PLANE;
	g->size[0] = g->size[2] = 1;
}

TEST(ground_sits_at_min_y_of_rotated_scaled_box)
{
	struct rnd_object o[2];
	rnd_object_defaults(&o[0]);
	o[0].shape = RND_SHAPE_BOX;
	o[0].size[0] = 1; o[0].size[1] = 2; o[0].size[2] = 0.5f;
	const float t[3] = {0.3f, 4, -1}, axis[3] = {0.48f, 0.6f, 0.64f}, s[3] = {2, 0.5f, 3};
	trs(o[0].model, t, axis, 0.7f, s);
	plane_object(&o[1]);
	/* First principles: the lowest of the eight transformed corners. */
	double lo = INFINITY, xlo = INFINITY, xhi = -INFINITY;
	for (int i = 0; i < 8; i++) {
		double p[3] = {(i & 1 ? 0.5 : -0.5) * 1, (i & 2 ? 0.5 : -0.5) * 2, (i & 4 ? 0.5 : -0.5) * 0.5};
		lo = fmin(lo, world_y(o[0].model, p[0], p[1], p[2]));
		double x = o[0].model[0] * p[0] + o[0].model[4] * p[1] + o[0].model[8] * p[2] + o[0].model[12];
		xlo = fmin(xlo, x); xhi = fmax(xhi, x);
	}
	float margin[2] = {0, 2};
	api_ground_place(o, 2, NULL, margin);
	CHECK(o[1].model[13] < lo && near_d(o[1].model[13], lo), "ground at y=%g, just under the box's lowest corner at %g",
	      o[1].model[13], lo);
	CHECK(near_d(o[1].model[12], 0.5 * (xlo + xhi)), "centred under the box in x: %g vs %g", o[1].model[12],
	      0.5 * (xlo + xhi));
	CHECK(o[1].size[0] >= 2 * (xhi - xlo) - 1e-4 && o[1].size[0] == o[1].size[2],
	      "square, at least margin x the box's x extent: %g (extent %g)", o[1].size[0], xhi - xlo);
	CHECK(o[1].model[0] == 1 && o[1].model[5] == 1 && o[1].model[10] == 1 && o[1].model[1] == 0,
	      "the ground is not rotated or scaled");
	/* The box itself is not moved. */
	CHECK(near_d(o[0].model[13], 4), "the box stays where it was");
}

TEST(ground_sits_at_lowest_vertex_of_rotated_mesh)
{
	/* A tetrahedron whose vertex (0, 0, 2) ends lowest after a 90° turn about +X (z -> -y). */
	static const float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 2};
	static const uint32_t idx[] = {0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3};
	struct rnd_object o[3];
	rnd_object_defaults(&o[0]);
	o[0].shape = RND_SHAPE_MESH;
	o[0].positions = pos; o[0].vertex_count = 4; o[0].indices = idx; o[0].index_count = 12;
	const float t[3] = {0, 1, 0}, axis[3] = {1, 0, 0}, s[3] = {1, 1, 1};
	trs(o[0].model, t, axis, (float)M_PI / 2, s);
	plane_object(&o[1]);
	plane_object(&o[2]);  /* a second, ordinary plane: neither placed nor counted */
	o[2].model[13] = -50;
	float margin[3] = {0, 3, 0};
	api_ground_place(o, 3, NULL, margin);
	CHECK(ground_at(o[1].model[13], -1.0, 2.0), "ground at y=%g, expected just under 1 - 2 = -1", o[1].model[13]);
	CHECK(near_d(o[2].model[13], -50), "the ordinary plane is left alone");
	/* Extent: x 0..1, y -1..1, z 0..1 -> largest 2, side 3 x 2. */
	CHECK(near_d(o[1].size[0], 6), "side %g, expected margin 3 x extent 2", o[1].size[0]);
}

TEST(ground_under_scaled_sphere_and_rotated_mesh_through_the_parser)
{
	/* A sphere of radius 1 scaled by 0.5 in y at height 3: lowest point 3 - 0.5 = 2.5 (a shadow
	 * catcher far below does not count). Then an inline mesh turned 90° about +X whose (0, 0, 2)
	 * vertex ends at 1 - 2 = -1. */
	const char *doc =
		"{\"camera\":{\"position\":[0,2,8],\"target\":[0,0,0]},"
		"\"objects\":[{\"shape\":\"sphere\",\"transform\":{\"translation\":[0,3,0],\"scale\":[1,0.5,1]}},"
		"{\"shape\":\"plane\",\"placement\":\"ground\",\"margin\":2},"
		"{\"shape\":\"box\",\"material\":{\"shadow_catcher\":true},\"transform\":{\"translation\":[0,-9,0]}}]}";
	struct api_problem p;
	struct api_scene *s = NULL;
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s: %s", p.pointer, p.detail);
	CHECK(near_d(s->scene.objects[1].model[13], 2.5), "ground at %g, expected 2.5", s->scene.objects[1].model[13]);
	CHECK(near_d(s->scene.objects[1].size[0], 4), "side %g, expected 2 x 2", s->scene.objects[1].size[0]);
	api_scene_free(s);

	const char *doc2 =
		"{\"camera\":{\"position\":[0,2,8],\"target\":[0,0,0]},"
		"\"objects\":[{\"shape\":\"plane\",\"placement\":\"ground\"},"
		"{\"shape\":\"mesh\",\"positions\":[0,0,0, 1,0,0, 0,1,0, 0,0,2],\"indices\":[0,1,2, 0,1,3, 0,2,3, 1,2,3],"
		"\"transform\":{\"translation\":[0,1,0],\"rotation\":[0.70710678,0,0,0.70710678]}}]}";
	REQUIRE(api_scene_parse(doc2, strlen(doc2), NULL, &s, &p) == API_OK, "%s: %s", p.pointer, p.detail);
	CHECK(ground_at(s->scene.objects[0].model[13], -1.0, 2.0), "ground at %g, expected just under -1",
	      s->scene.objects[0].model[13]);
	CHECK(near_d(s->scene.objects[0].size[0], 6), "default margin 3 x extent 2 = 6, got %g",
	      s->scene.objects[0].size[0]);
	api_scene_free(s);
}

static void expect_problem(const char *doc, int status, const char *pointer)
{
	struct api_problem p;
	struct api_scene *s = NULL;
	CHECK(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_ERR && p.status == status &&
	      !strcmp(p.pointer, pointer), "%s: expected %d at %s, got %d at %s (%s)", doc, status, pointer,
	      p.status, p.pointer, p.detail);
	api_scene_free(s);
}

TEST(ground_placement_problems_name_the_member)
{
	expect_problem("{\"camera\":{\"position\":[0,0,5]},\"objects\":[{\"shape\":\"plane\",\"placement\":\"ground\","
	               "\"transform\":{\"translation\":[0,1,0]}}]}", 400, "/objects/0/transform");
	expect_problem("{\"camera\":{\"position\":[0,0,5]},\"objects\":[{\"shape\":\"plane\",\"placement\":\"ground\","
	               "\"size\":[2,2]}]}", 400, "/objects/0/size");
	expect_problem("{\"camera\":{\"position\":[0,0,5]},\"objects\":[{\"shape\":\"plane\",\"placement\":\"wall\"}]}",
	               400, "/objects/0/placement");
	expect_problem("{\"camera\":{\"position\":[0,0,5]},\"objects\":[{\"shape\":\"plane\",\"margin\":2}]}", 400,
	               "/objects/0/margin");
	expect_problem("{\"camera\":{\"position\":[0,0,5]},\"objects\":[{\"shape\":\"box\",\"placement\":\"ground\"}]}",
	               400, "/objects/0/placement");
}

TEST(preset_thumbnail_gives_camera_studio_and_ground)
{
	const char *doc = "{\"preset\":\"thumbnail\",\"objects\":[{\"shape\":\"box\",\"transform\":{\"translation\":[0,5,0]}}]}";
	struct api_problem p;
	struct api_scene *s = NULL;
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s: %s", p.pointer, p.detail);
	const struct rnd_scene *sc = &s->scene;
	CHECK(sc->width == 512 && sc->height == 512, "%ux%u", sc->width, sc->height);
	CHECK(sc->camera.fit == RND_FIT_OBJECTS, "the camera is fitted to the objects");
	CHECK(sc->light_count == 0, "no sun: the studio's key casts the shadow, got %u lights", sc->light_count);
	CHECK(sc->environment.source == RND_ENV_STUDIO && sc->environment.shadow_directions == RND_DEFAULT_ENV_DIRECTIONS,
	      "the built-in studio with its shadows");
	REQUIRE(sc->object_count == 2, "the box and the preset's ground, got %u", sc->object_count);
	const struct rnd_object *g = &sc->objects[1];
	CHECK(g->shape == RND_SHAPE_PLANE && sc->materials[g->material].shadow_catcher, "a shadow-catcher ground");
	CHECK(near_d(g->model[13], 4.5), "the ground under the box (y 4.5), got %g", g->model[13]);
	CHECK(sc->environment.ambient_intensity == 0, "no hemisphere ambient: the studio is the ambient");
	api_scene_free(s);
}

TEST(preset_members_are_overridden_by_the_scene)
{
	const char *doc = "{\"preset\":\"thumbnail\",\"width\":96,\"height\":64,\"shadows\":null,\"environment\":{\"map\":null},"
	                  "\"camera\":{\"fov_y\":50},"
	                  "\"lights\":[{\"type\":\"point\",\"position\":[0,3,0]},{\"type\":\"point\",\"position\":[1,3,0]}],"
	                  "\"output\":{\"transparent\":true},"
	                  "\"objects\":[{\"shape\":\"sphere\"},{\"shape\":\"plane\",\"placement\":\"ground\",\"margin\":5}]}";
	struct api_problem p;
	struct api_scene *s = NULL;
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s: %s", p.pointer, p.detail);
	const struct rnd_scene *sc = &s->scene;
	CHECK(sc->width == 96 && sc->height == 64, "size from the scene: %ux%u", sc->width, sc->height);
	CHECK(sc->light_count == 2 && sc->lights[0].type == RND_LIGHT_POINT, "the scene's lights replace the sun");
	CHECK(sc->lights[0].shadow.filter != RND_FILTER_PCSS, "shadows: null: the renderer's defaults");
	CHECK(sc->environment.source == RND_ENV_AMBIENT, "environment.map: null drops the preset's studio");
	CHECK(sc->camera.fit == RND_FIT_OBJECTS && near_d(sc->camera.fov_y, 50 * M_PI / 180),
	      "camera merged: fit kept, fov_y %g", sc->camera.fov_y);
	CHECK(sc->output.transparent, "output merged");
	CHECK(sc->object_count == 2, "the scene's own ground replaces the preset's: %u objects", sc->object_count);
	CHECK(near_d(sc->objects[1].size[0], 10), "margin 5 x extent 2, got %g", sc->objects[1].size[0]);
	api_scene_free(s);

	/* A placed camera replaces the fitted one as a whole. */
	const char *doc2 = "{\"preset\":\"thumbnail\",\"camera\":{\"position\":[0,1,6],\"target\":[0,0,0]},"
	                   "\"objects\":[{\"shape\":\"sphere\"}]}";
	REQUIRE(api_scene_parse(doc2, strlen(doc2), NULL, &s, &p) == API_OK, "%s: %s", p.pointer, p.detail);
	CHECK(s->scene.camera.fit == RND_FIT_NONE && near_d(s->scene.camera.position[2], 6), "the scene's camera");
	api_scene_free(s);
}

TEST(preset_problems_keep_the_scene_pointers)
{
	expect_problem("{\"preset\":\"thumbnale\",\"objects\":[]}", 400, "/preset");
	expect_problem("{\"preset\":3,\"objects\":[]}", 400, "/preset");
	expect_problem("{\"preset\":\"thumbnail\",\"objects\":[{\"shape\":\"box\",\"size\":[1,-1,1]}]}", 400,
	               "/objects/0/size");
	expect_problem("{\"preset\":\"thumbnail\",\"objects\":[{\"shape\":\"box\"}],\"camera\":{\"fov_y\":-3}}", 400,
	               "/camera/fov_y");
}


TEST(ground_under_an_imported_model_with_two_meshes)
{
	/* An OBJ of two separate triangles (two objects: the model expands into two mesh objects,
	 * so the ground, after it in the document, moves in the scene's object list). Scaled by 2
	 * and lifted by 1: its lowest vertex y = -0.5 becomes 2 x -0.5 + 1 = 0. */
	static const char two[] = "o a\nv 0 -0.5 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nv 2 0 0\nv 3 0 0\nv 2 2 1\nf 4 5 6\n";
	char *data = test_b64(two, sizeof two - 1);
	char doc[1024];
	snprintf(doc, sizeof doc,
	         "{\"camera\":{\"position\":[0,2,8],\"target\":[0,0,0]},\"objects\":["
	         "{\"shape\":\"model\",\"format\":\"obj\",\"data\":\"%s\",\"transform\":{\"translation\":[0,1,0],"
	         "\"scale\":[2,2,2]}},{\"shape\":\"plane\",\"placement\":\"ground\",\"margin\":1}]}", data);
	free(data);
	struct api_problem p;
	struct api_scene *s = NULL;
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s: %s", p.pointer, p.detail);
	const struct rnd_scene *sc = &s->scene;
	REQUIRE(sc->object_count >= 3, "two meshes and the ground, got %u objects", sc->object_count);
	const struct rnd_object *g = &sc->objects[sc->object_count - 1];
	CHECK(g->shape == RND_SHAPE_PLANE, "the ground is last");
	CHECK(ground_at(g->model[13], 0.0, 6.0), "ground at %g, expected just under 2 x -0.5 + 1 = 0", g->model[13]);
	/* x spans 0..6 after the scale: centre 3, largest extent 6 (y: 0..5). */
	CHECK(near_d(g->model[12], 3.0) && near_d(g->size[0], 6.0), "centre x %g (3), side %g (6)", g->model[12],
	      g->size[0]);
	for (uint32_t i = 0; i + 1 < sc->object_count; i++)
		CHECK(sc->objects[i].shape == RND_SHAPE_MESH, "object %u is one of the model's meshes", i);
	/* The model's meshes carry their local bounds (api_model_mesh.bounds): mesh a's vertices
	 * span x 0..1, y -0.5..1, z 0..0. */
	const float *mb = sc->objects[0].mesh_bounds;
	CHECK(mb && mb[0] == 0.0f && mb[1] == -0.5f && mb[2] == 0.0f && mb[3] == 1.0f && mb[4] == 1.0f && mb[5] == 0.0f,
	      "mesh a's bounds %g %g %g .. %g %g %g", mb ? mb[0] : -1, mb ? mb[1] : -1, mb ? mb[2] : -1, mb ? mb[3] : -1,
	      mb ? mb[4] : -1, mb ? mb[5] : -1);
	api_scene_free(s);
}

/* api_object_bounds of o alone (from empty bounds). */
static void bounds_of(const struct rnd_object *o, double lo[3], double hi[3])
{
	for (int k = 0; k < 3; k++) { lo[k] = DBL_MAX; hi[k] = -DBL_MAX; }
	api_object_bounds(o, lo, hi);
}

/* Whether mesh a's world bounds are the same with `given` as its known local bounds as from
 * its vertices alone; the bounds found from the vertices in lo, hi. */
static bool same_with_known(const struct rnd_object *a, const float given[6], double lo[3], double hi[3])
{
	struct rnd_object b = *a;
	b.mesh_bounds = given;
	double lo_b[3], hi_b[3];
	bounds_of(a, lo, hi);
	bounds_of(&b, lo_b, hi_b);
	bool same = true;
	for (int k = 0; k < 3; k++) {
		if (lo[k] == lo_b[k] && hi[k] == hi_b[k]) continue;
		printf("    axis %d: %g..%g from the vertices, %g..%g given bounds\n", k, lo[k], hi[k], lo_b[k], hi_b[k]);
		same = false;
	}
	return same;
}

/* A mesh's known local bounds stand in for its vertices under a matrix without rotation (a
 * negative scale included), with the very same result; under a rotation the vertices decide
 * (the bounds are then deliberately wrong here, and must not be used). */
TEST(object_bounds_of_a_mesh_with_known_bounds)
{
	static const float pos[] = {0, -0.5f, 0, 1, 0, 0.25f, 0, 1, 1, 0.5f, 0.5f, -2};
	static const float known[6] = {0, -0.5f, -2, 1, 1, 1}, wrong[6] = {-9, -9, -9, 9, 9, 9};
	struct rnd_object a;
	rnd_object_defaults(&a);
	a.shape = RND_SHAPE_MESH;
	a.positions = pos;
	a.vertex_count = 4;
	const float t[3] = {1, 2, 3}, axis[3] = {0, 1, 0}, sc[3] = {2, -3, 0.5f};
	double lo[3], hi[3];
	trs(a.model, t, axis, 0.0f, sc);
	CHECK(same_with_known(&a, known, lo, hi), "known bounds changed the world bounds");
	CHECK(near_d(lo[1], 2.0 - 3.0) && near_d(hi[1], 2.0 + 1.5), "y %g..%g, expected -1..3.5", lo[1], hi[1]);
	trs(a.model, t, axis, (float)M_PI / 4, sc);
	CHECK(same_with_known(&a, wrong, lo, hi), "rotated: wrong given bounds were used");
}

/* A flat model lying at its lowest point (TwoSidedPlane: a quad at y = 0) coplanar with the
 * ground z-fought with it: the ground now sits API_GROUND_GAP x the extent below it. */
TEST(ground_sits_just_below_a_flat_model)
{
	static const float pos[] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
	static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	struct rnd_object o[2];
	memset(o, 0, sizeof o);
	o[0].shape = RND_SHAPE_MESH;
	o[0].positions = pos;
	o[0].vertex_count = 4;
	o[0].indices = idx;
	o[0].index_count = 6;
	for (int k = 0; k < 16; k++) o[0].model[k] = (k % 5 == 0) ? 1.0f : 0.0f;
	plane_object(&o[1]);
	float margin[2] = {0, 3};
	api_ground_place(o, 2, NULL, margin);
	CHECK(o[1].model[13] < 0.0f && fabs(o[1].model[13] + API_GROUND_GAP * 2) < 1e-7, "ground at %g, want %g",
	      o[1].model[13], -API_GROUND_GAP * 2);
}
