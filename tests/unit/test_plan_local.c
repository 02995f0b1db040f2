/* tests/unit — spot and point lights' shadow views fitted to their casters (renderer/plan_local.c):
 * a spot's map cut down to the part of its cone the casters cover, both kinds sized for where the
 * camera sees the casters, PCSS's search reach respected. Pure math, no GPU. */
#include <math.h>
#include <string.h>
#include "test.h"
#include "plan.h"

/* A 14 m ground and a small caster's box (0.3 m, 0.2 m up) under one light; the camera 1.2 m
 * from the caster, 256^2. */
struct local_scene {
	struct rnd_scene scene;
	struct rnd_material mat;
	struct rnd_object obj;
	struct rnd_light light;
	struct rnd_aabb bounds, casters;
	struct rnd_camera_plan cam;
};

static void local_scene_init(struct local_scene *s, enum rnd_light_type type, float radius)
{
	memset(s, 0, sizeof *s);
	rnd_scene_defaults(&s->scene);
	rnd_material_defaults(&s->mat);
	rnd_object_defaults(&s->obj);
	rnd_light_defaults(&s->light, type);
	s->scene.materials = &s->mat; s->scene.material_count = 1;
	s->scene.objects = &s->obj; s->scene.object_count = 1;
	s->scene.lights = &s->light; s->scene.light_count = 1;
	s->scene.width = s->scene.height = 256;
	float pos[3] = {0.8f, 4.0f, 0.6f}, dir[3] = {-0.2f, -1.0f, -0.15f};
	memcpy(s->light.position, pos, sizeof pos);
	memcpy(s->light.direction, dir, sizeof dir);
	s->light.outer_angle = 70.0f * (float)M_PI / 180.0f;
	s->light.radius = radius;
	float cp[3] = {0.5f, 0.6f, 1.0f}, ct[3] = {0, 0.1f, 0};
	memcpy(s->scene.camera.position, cp, sizeof cp);
	memcpy(s->scene.camera.target, ct, sizeof ct);
	s->bounds = (struct rnd_aabb){{-7, 0, -7}, {7, 0.4f, 7}};
	s->casters = (struct rnd_aabb){{-0.15f, 0, -0.1f}, {0.15f, 0.3f, 0.1f}};
}

/* The light moved to (x, y, z). */
static void light_at(struct local_scene *s, float x, float y, float z)
{
	s->light.position[0] = x;
	s->light.position[1] = y;
	s->light.position[2] = z;
}

static enum rnd_result local_plan_atlas(struct local_scene *s, const struct rnd_aabb *casters, uint32_t atlas,
                                        struct rnd_shadow_plan *sp)
{
	struct rnd_error err = {0};
	if (rnd_camera_plan(&s->scene.camera, s->scene.width, s->scene.height, &s->bounds, &s->cam, &err) != RND_OK)
		return RND_ERR_INVALID;
	return rnd_shadow_plan_with(&s->scene, &s->bounds, casters, &s->cam, NULL, atlas, sp, &err);
}

static enum rnd_result local_plan(struct local_scene *s, const struct rnd_aabb *casters, struct rnd_shadow_plan *sp)
{
	return local_plan_atlas(s, casters, 0, sp);
}

/* Clip coordinates of p under m (column-major). */
static void clip_of(const float m[16], const float p[3], float c[4])
{
	for (int r = 0; r < 4; r++) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

/* Every corner of the casters' box lies inside the view, the filter's margin of texels in. */
static void check_casters_inside(const struct umbra_shadow_view *v, const struct rnd_aabb *c, float margin)
{
	for (int i = 0; i < 8; i++) {
		float p[3] = {i & 1 ? c->max[0] : c->min[0], i & 2 ? c->max[1] : c->min[1], i & 4 ? c->max[2] : c->min[2]}, q[4];
		clip_of(v->view_proj, p, q);
		float lim = 1.0f - 2.0f * margin / v->rect[2];
		CHECK(q[3] > 0 && fabsf(q[0] / q[3]) <= lim + 1e-4f && fabsf(q[1] / q[3]) <= lim + 1e-4f,
		      "corner %d at ndc %.4f %.4f (w %.3f), limit %.4f", i, q[0] / q[3], q[1] / q[3], q[3], lim);
	}
}

/* A small caster under a wide spot 4 m up, seen close: before, the whole 140-degree cone in a
 * 1024 tile (texels 2 cm on the ground under a 4 mm camera pixel). Now the map covers the
 * casters with their filter's margin, in no bigger a tile than twice the cone's, with texels
 * several times finer; the view still along the light's axis (same depth), so a texel is
 * params[0] per unit of depth as before. Without casters known: the whole cone as before. */
TEST(plan_local_spot_fitted_to_casters)
{
	static struct local_scene s;
	static struct rnd_shadow_plan cone, fit;
	local_scene_init(&s, RND_LIGHT_SPOT, 0.03f);
	REQUIRE(local_plan(&s, NULL, &cone) == RND_OK, "cone plan");
	REQUIRE(local_plan(&s, &s.casters, &fit) == RND_OK, "fitted plan");
	const struct rnd_light_plan *lc = &cone.lights[0], *lf = &fit.lights[0];
	CHECK(lc->size_rule == RND_SIZE_IMPORTANCE && lc->resolution == 1024, "cone: %u by rule %u", lc->resolution,
	      lc->size_rule);
	CHECK(lf->size_rule == RND_SIZE_CASTERS, "fitted: rule %u", lf->size_rule);
	CHECK(lf->resolution <= 2 * lc->resolution, "fitted tile %u, the cone's %u", lf->resolution, lc->resolution);
	CHECK(fit.views[0].params[0] < 0.25f * cone.views[0].params[0], "texel %.6f, the cone's %.6f",
	      fit.views[0].params[0], cone.views[0].params[0]);
	CHECK(fit.views[0].params[2] == cone.views[0].params[2] && fit.views[0].params[3] == cone.views[0].params[3],
	      "depth range changed");
	check_casters_inside(&fit.views[0], &s.casters, (float)(lf->pcf_radius + 2) + lf->search_texels);
	/* An asked resolution keeps its tile, on the casters. */
	s.light.shadow.resolution = 4096;
	REQUIRE(local_plan(&s, &s.casters, &fit) == RND_OK, "asked plan");
	CHECK(fit.lights[0].resolution == 4096, "asked 4096: %u", fit.lights[0].resolution);
	CHECK(fit.views[0].params[0] < cone.views[0].params[0] / 4.0f, "asked 4096: texel %.6f", fit.views[0].params[0]);
	check_casters_inside(&fit.views[0], &s.casters, (float)(lf->pcf_radius + 2) + lf->search_texels);
}

/* A hard spot (PCF, no radius) too, and casters outside the cone: the smallest tile. */
TEST(plan_local_spot_casters_outside_cone)
{
	static struct local_scene s;
	static struct rnd_shadow_plan sp;
	local_scene_init(&s, RND_LIGHT_SPOT, 0.0f);
	REQUIRE(local_plan(&s, &s.casters, &sp) == RND_OK, "plan");
	CHECK(sp.lights[0].filter == UMBRA_FILTER_PCF, "filter %u", sp.lights[0].filter);
	check_casters_inside(&sp.views[0], &s.casters, (float)(sp.lights[0].pcf_radius + 2));
	s.light.outer_angle = 5.0f * (float)M_PI / 180.0f;
	float dir[3] = {1, -1, 0};
	memcpy(s.light.direction, dir, sizeof dir);
	REQUIRE(local_plan(&s, &s.casters, &sp) == RND_OK, "plan");
	CHECK(sp.lights[0].resolution == RND_MIN_SHADOW_RESOLUTION && sp.lights[0].size_rule == RND_SIZE_CASTERS,
	      "nothing in the cone: %u by rule %u", sp.lights[0].resolution, sp.lights[0].size_rule);
}

/* A big soft spot close above the caster: PCSS's 24-texel search must reach the widest
 * penumbra, radius (1/zb - 1/zr) / 24 in texels per unit of depth: the camera's need (finer)
 * gives way to it, never coarser than the whole cone's texels. */
TEST(plan_local_spot_pcss_search_reach)
{
	static struct local_scene s;
	static struct rnd_shadow_plan cone, fit;
	local_scene_init(&s, RND_LIGHT_SPOT, 0.3f);
	light_at(&s, 0.3f, 1.2f, 0.2f);
	REQUIRE(local_plan(&s, NULL, &cone) == RND_OK, "cone plan");
	REQUIRE(local_plan(&s, &s.casters, &fit) == RND_OK, "fitted plan");
	CHECK(fit.lights[0].filter == UMBRA_FILTER_PCSS, "filter %u", fit.lights[0].filter);
	CHECK(fit.lights[0].size_rule == RND_SIZE_SEARCH, "rule %u", fit.lights[0].size_rule);
	float zb = 0.8f;   /* the casters' top is 0.9 m below the light, their nearest depth at least 0.8 */
	float reach = 0.3f * (1.0f / zb - 1.0f / 20.0f) / fit.lights[0].search_texels;
	float texel = fit.views[0].params[0];
	CHECK(texel >= fminf(reach, cone.views[0].params[0]) * 0.5f, "texel %.5f under the search's %.5f", texel, reach);
	CHECK(texel <= cone.views[0].params[0] * 1.0001f, "texel %.5f coarser than the cone's %.5f", texel,
	      cone.views[0].params[0]);
	check_casters_inside(&fit.views[0], &s.casters, (float)(fit.lights[0].pcf_radius + 2) + fit.lights[0].search_texels);
}

/* A point light's faces sized for where the camera sees its casters: finer than importance's
 * 512, at most twice it, at most 1024; an asked size stays. */
TEST(plan_local_point_faces_sized_for_camera)
{
	static struct local_scene s;
	static struct rnd_shadow_plan sp;
	local_scene_init(&s, RND_LIGHT_POINT, 0.02f);
	light_at(&s, 1.0f, 2.0f, 0.8f);
	REQUIRE(local_plan(&s, NULL, &sp) == RND_OK, "plan");
	uint32_t before = sp.lights[0].resolution;
	REQUIRE(local_plan(&s, &s.casters, &sp) == RND_OK, "plan");
	CHECK(sp.view_count == 6, "%u views", sp.view_count);
	CHECK(sp.lights[0].resolution > before && sp.lights[0].resolution <= 2 * before && sp.lights[0].resolution <= 1024,
	      "faces %u, importance %u", sp.lights[0].resolution, before);
	CHECK(sp.lights[0].size_rule == RND_SIZE_CASTERS, "rule %u", sp.lights[0].size_rule);
	for (uint32_t v = 0; v < 6; v++) CHECK(sp.views[v].rect[2] == (float)sp.lights[0].resolution, "face %u", v);
	s.light.shadow.resolution = 256;
	REQUIRE(local_plan(&s, &s.casters, &sp) == RND_OK, "plan");
	CHECK(sp.lights[0].resolution == 256 && sp.lights[0].size_rule == RND_SIZE_ASKED, "asked 256: %u",
	      sp.lights[0].resolution);
}

/* A point light asked for 4096 with a 4096 atlas: six 4096 faces do not fit, so they are planned
 * at the 1024 the atlas holds, each cut to its casters at that size. Before, they were planned at
 * 4096 (the casters' face at PCSS's search floor, wider than the casters), granted 1024 and drawn
 * with the planned view, texels coarser than the default size's (the duck under a 2 cm point
 * light: rmse .0098 at the default, .0125 at 4096). A spot's one 4096 tile fits: it stays. */
TEST(plan_local_asked_size_within_atlas)
{
	static struct local_scene s;
	static struct rnd_shadow_plan def, big;
	local_scene_init(&s, RND_LIGHT_POINT, 0.02f);
	light_at(&s, 0.5f, 1.0f, 0.4f);
	REQUIRE(local_plan_atlas(&s, &s.casters, 4096, &def) == RND_OK, "default plan");
	s.light.shadow.resolution = 4096;
	REQUIRE(local_plan_atlas(&s, &s.casters, 4096, &big) == RND_OK, "4096 plan");
	CHECK(big.lights[0].resolution == 1024 && big.lights[0].size_rule == RND_SIZE_ATLAS, "asked 4096: %u, rule %u",
	      big.lights[0].resolution, big.lights[0].size_rule);
	for (uint32_t v = 0; v < 6; v++)
		CHECK(big.views[v].params[0] <= def.views[v].params[0] * 1.0001f, "face %u: texel %.6f, default %.6f", v,
		      big.views[v].params[0], def.views[v].params[0]);
	REQUIRE(local_plan_atlas(&s, &s.casters, 0, &big) == RND_OK, "4096 plan, no atlas");
	CHECK(big.lights[0].resolution == 4096, "no atlas: %u", big.lights[0].resolution);
	local_scene_init(&s, RND_LIGHT_SPOT, 0.02f);
	s.light.shadow.resolution = 4096;
	REQUIRE(local_plan_atlas(&s, NULL, 4096, &big) == RND_OK, "spot plan");
	CHECK(big.lights[0].resolution == 4096 && big.lights[0].size_rule == RND_SIZE_ASKED, "spot: %u",
	      big.lights[0].resolution);
}
