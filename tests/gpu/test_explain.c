/* tests/gpu — `explain` (umbra/rnd_plan.h, api/plan_json.c): the plan's counts are what the
 * render does. The render counts what it records as it records it (record.c, record_shadow.c:
 * the camera's triangles of the main pass, the casters' triangles of each shadow map) and what
 * the shadow cache grants (maps drawn, their texels); the plan predicts them before anything
 * is allocated. A second render of the same scene: the plan says every fixed map is cached and
 * the render draws none. A bigger output: the hard light's map grows in the plan and in what
 * the render draws. The JSON document carries the same figures. */
#include <jansson.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"
#include "umbra/rnd_plan.h"
#include "models.h"
#include "util.h"

/* A soft sun (PCSS), a hard spot (its map follows the output's size) and a point light's cube over
 * a ground, a box and a sphere (drawn by the camera as a proxy); W x W pixels; the salt moves the
 * box, so that each test's maps are its own in the cache. */
#define EXPLAIN_SCENE                                                                                               \
	"{'width': %d, 'height': %d, 'camera': {'type': 'perspective', 'position': [4, 3, 4], 'target': [0, 0.8, 0], " \
	"'up': [0, 1, 0], 'fov_y': 40},"                                                                \
	" 'materials': {'grey': {'base_color': [0.7, 0.7, 0.7], 'roughness': 0.8}},"                                    \
	" 'objects': [{'shape': 'plane', 'size': [10, 10], 'material': 'grey'},"                                         \
	" {'shape': 'box', 'size': [1, 1, 1], 'material': 'grey', 'transform': {'translation': [1.5, 0.5, 0.%d]}},"          \
	" {'shape': 'sphere', 'radius': 1, 'segments': 96, 'material': 'grey', 'transform': {'translation': [0, 1, 0]}}]," \
	" 'lights': [{'type': 'directional', 'direction': [-0.5, -1, -0.3], 'intensity': 2, 'angular_diameter': 2},"  \
	" {'type': 'spot', 'position': [2, 4, 2], 'direction': [-0.4, -1, -0.4], 'intensity': 40}," \
	" {'type': 'point', 'position': [-2, 2.5, 1], 'intensity': 20, 'shadow': {'filter': 'pcf'}}]}"

static struct api_scene *explain_scene(int size, int salt)
{
	char doc[2048];
	snprintf(doc, sizeof doc, EXPLAIN_SCENE, size, size, salt);
	return gpu_parse(doc);
}

/* Plans and renders s; *info is the plan's, after the render (analyzed). */
static bool plan_and_render(struct api_scene *s, struct rnd_plan_info *info, struct rnd_timings *tm, char **json)
{
	struct rnd_plan *plan = NULL;
	struct rnd_image img = {0};
	struct rnd_error err = {0};
	uint32_t before = rnd_context_validation_messages(gpu_ctx());
	enum rnd_result r = rnd_plan_create(gpu_ctx(), &s->scene, &plan, &err);
	CHECK(r == RND_OK, "plan: %s", err.msg);
	if (r == RND_OK) {
		rnd_plan_info(plan, info);
		CHECK(!info->analyzed, "a plan not yet rendered says it is analyzed");
		r = rnd_render_plan(gpu_ctx(), plan, &img, tm, &err);
		CHECK(r == RND_OK, "render: %s", err.msg);
	}
	if (r == RND_OK) {
		rnd_plan_info(plan, info);
		if (json) *json = api_plan_json(s, plan, NULL, NULL);
	}
	rnd_image_release(&img);
	rnd_plan_destroy(plan);
	CHECK(rnd_context_validation_messages(gpu_ctx()) == before, "validation messages");
	return r == RND_OK;
}

static void check_counts(const struct rnd_plan_info *in, const struct rnd_timings *tm)
{
	CHECK(in->analyzed, "the rendered plan is not analyzed");
	CHECK(in->maps_drawn == tm->shadow_maps_rendered, "maps drawn: plan %u, render %u", in->maps_drawn,
	      tm->shadow_maps_rendered);
	CHECK(in->maps_cached == tm->shadow_maps_reused, "maps cached: plan %u, render reused %u", in->maps_cached,
	      tm->shadow_maps_reused);
	CHECK(in->texels_drawn == tm->shadow_texels, "texels: plan %llu, render %llu", (unsigned long long)in->texels_drawn,
	      (unsigned long long)tm->shadow_texels);
	CHECK(in->shadow_triangles == tm->shadow_triangles, "casters' triangles: plan %llu, recorded %llu",
	      (unsigned long long)in->shadow_triangles, (unsigned long long)tm->shadow_triangles);
	CHECK(in->camera_triangles == tm->camera_triangles, "camera triangles: plan %llu, recorded %llu",
	      (unsigned long long)in->camera_triangles, (unsigned long long)tm->camera_triangles);
	CHECK(in->sphere_proxies == tm->sphere_proxies, "proxies: plan %u, render %u", in->sphere_proxies, tm->sphere_proxies);
	CHECK(in->visibility_views == tm->visibility_views && in->pixel_shaded_views == tm->pixel_shaded_views,
	      "visibility pass: plan %u, render %u; pixel shading: plan %u, render %u", in->visibility_views,
	      tm->visibility_views, in->pixel_shaded_views, tm->pixel_shaded_views);
}

TEST(explain_plan_counts_are_what_the_render_draws)
{
	if (!gpu_ctx()) return;
	struct api_scene *s = explain_scene(128, 1);
	if (!s) return;
	struct rnd_plan_info first, again;
	struct rnd_timings tm;
	char *json = NULL;
	if (plan_and_render(s, &first, &tm, &json)) {
		check_counts(&first, &tm);
		/* A sun, a spot, a cube of six: eight shadow views, all drawn by a fresh scene. */
		CHECK(first.maps == 3 && first.maps_drawn == 8 && first.maps_cached == 0, "%u maps, %u drawn, %u cached",
		      first.maps, first.maps_drawn, first.maps_cached);
		CHECK(first.camera_triangles > 0 && first.shadow_triangles > 0 && first.sphere_proxies == 1, "counts");
		/* The document says the same. */
		json_error_t je;
		json_t *doc = json ? json_loads(json, 0, &je) : NULL;
		CHECK(doc != NULL, "the plan's JSON does not parse");
		json_t *tot = json_object_get(doc, "totals"), *act = json_object_get(doc, "actual");
		CHECK(json_is_true(json_object_get(doc, "analyzed")), "analyzed");
		CHECK(json_integer_value(json_object_get(tot, "shadow_maps_drawn")) == first.maps_drawn &&
		      json_integer_value(json_object_get(act, "shadow_maps_drawn")) == tm.shadow_maps_rendered &&
		      json_integer_value(json_object_get(tot, "camera_triangles")) == (json_int_t)first.camera_triangles &&
		      json_integer_value(json_object_get(act, "shadow_triangles")) == (json_int_t)tm.shadow_triangles,
		      "the document's totals and actuals");
		CHECK(json_array_size(json_object_get(doc, "shadow_maps")) == 3 &&
		      json_array_size(json_object_get(doc, "objects")) == 3, "maps and objects listed");
		json_decref(doc);
	}
	free(json);
	/* The same request again: its fixed maps are in the cache; the plan says so, the render
	 * draws none of them. */
	if (plan_and_render(s, &again, &tm, NULL)) {
		check_counts(&again, &tm);
		CHECK(again.maps_drawn == 0 && again.maps_cached == 8 && tm.shadow_texels == 0, "second render: %u drawn, %u cached",
		      again.maps_drawn, again.maps_cached);
		CHECK(again.camera_triangles == first.camera_triangles, "the camera draws the same");
	}
	api_scene_free(s);
}

TEST(explain_bigger_output_bigger_hard_light_map)
{
	if (!gpu_ctx()) return;
	struct api_scene *small = explain_scene(24, 2), *big = explain_scene(192, 2);
	struct rnd_plan_info a, b;
	struct rnd_timings ta, tb;
	if (small && big && plan_and_render(small, &a, &ta, NULL) && plan_and_render(big, &b, &tb, NULL)) {
		check_counts(&a, &ta);
		check_counts(&b, &tb);
		/* The hard spot's map is sized to the output (docs/renderer.md): 64x the pixels, a bigger map. */
		struct rnd_plan_map_info ma, mb;
		struct rnd_plan *pa = NULL, *pb = NULL;
		struct rnd_error err;
		if (rnd_plan_create(gpu_ctx(), &small->scene, &pa, &err) == RND_OK &&
		    rnd_plan_create(gpu_ctx(), &big->scene, &pb, &err) == RND_OK) {
			rnd_plan_map(pa, 1, &ma);
			rnd_plan_map(pb, 1, &mb);
			CHECK(!strcmp(ma.kind, "spot") && mb.resolution > ma.resolution, "spot map %u (%s) -> %u (%s)",
			      ma.resolution, ma.size, mb.resolution, mb.size);
			/* Its bigger map is a new key: the big render drew it (the others the cache held). */
			CHECK(tb.shadow_texels >= (uint64_t)mb.resolution * mb.resolution && tb.shadow_maps_rendered >= 1,
			      "the big render drew %llu texels", (unsigned long long)tb.shadow_texels);
		}
		rnd_plan_destroy(pa);
		rnd_plan_destroy(pb);
	}
	api_scene_free(small);
	api_scene_free(big);
}

/* The studio environment's shadow directions are the plan's: each a map the render draws (its
 * counts equal the plan's), the directions below the plane ground only weighed, the
 * environment pass planned and run, and a dense model under the map shaded once per pixel. */
TEST(explain_environment_directions_are_planned_and_drawn)
{
	if (!gpu_ctx()) return;
	size_t n = 0;
	uint8_t *stl = test_bumpy_stl(64, &n);
	char *b64 = stl ? test_b64(stl, n) : NULL, *doc = b64 ? malloc(strlen(b64) + 1024) : NULL;
	free(stl);
	if (!doc) { CHECK(0, "out of memory"); free(b64); return; }
	sprintf(doc, "{'width': 96, 'height': 96, 'camera': {'position': [4, 3, 4], 'target': [0, 0.8, 0]},"
	        " 'environment': {'map': {'preset': 'studio', 'rotation': 17}, 'shadow': {'directions': 8}},"
	        " 'objects': [{'shape': 'plane', 'size': [10, 10]},"
	        " {'shape': 'box', 'size': [1, 1, 1], 'transform': {'translation': [-1.2, 0.5, 0.03]}},"
	        " {'shape': 'model', 'format': 'stl', 'data': '%s', 'transform': {'translation': [0.6, 1.2, 0]}}]}", b64);
	struct api_scene *s = gpu_parse(doc);
	free(b64);
	free(doc);
	if (!s) return;
	struct rnd_plan_info in;
	struct rnd_timings tm;
	if (plan_and_render(s, &in, &tm, NULL)) {
		check_counts(&in, &tm);
		CHECK(in.env_directions == 8 && in.env_weighed == 4 && in.env_ground, "%u directions, %u weighed, ground %d",
		      in.env_directions, in.env_weighed, in.env_ground);
		CHECK(tm.env_directions == 8 && in.maps == 8 && in.maps_drawn + in.maps_cached == 8, "render %u directions, %u maps",
		      tm.env_directions, in.maps);
		/* dense plain draws lit by the map: shaded once per pixel (the plan's decision, the render's count) */
		CHECK(in.pixel_shaded_views == 1 && tm.pixel_shaded_views == 1, "pixel shading: plan %u, render %u",
		      in.pixel_shaded_views, tm.pixel_shaded_views);
		struct rnd_plan *plan = NULL;
		struct rnd_error err;
		if (rnd_plan_create(gpu_ctx(), &s->scene, &plan, &err) == RND_OK) {
			struct rnd_plan_view_info v;
			struct rnd_plan_map_info m;
			rnd_plan_view(plan, 0, &v);
			rnd_plan_map(plan, 0, &m);
			CHECK(v.env_pass, "no environment pass");
			CHECK(m.environment == 0 && !strcmp(m.light_type, "environment") && !strcmp(m.kind, "casters") &&
			      m.direction[1] > 0, "map 0: %s %s, direction y %g", m.light_type, m.kind, m.direction[1]);
			/* made after the render: the cache holds every direction's map now */
			struct rnd_plan_info again;
			rnd_plan_info(plan, &again);
			CHECK(again.maps_cached == 8 && again.maps_drawn == 0, "%u cached, %u drawn", again.maps_cached, again.maps_drawn);
		}
		rnd_plan_destroy(plan);
	}
	api_scene_free(s);
}
