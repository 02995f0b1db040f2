/* tests/gpu — work the deadline can stop (issue 29): a shadow map drawn in parts, a submit
 * each, gives the same bytes as in one; geometry stacked hundreds of layers deep is cut into
 * many submits by the cost model (renderer/cost.h) instead of one that runs past any deadline
 * (400 stacked boxes had run their main pass as one 10 s submit past a 3 s deadline).
 * Run: gpu_tests pacing */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"

static uint64_t mono_ns(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (uint64_t)t.tv_sec * 1000000000ull + (uint64_t)t.tv_nsec;
}

static bool same_pixels(const struct rnd_image *a, const struct rnd_image *b)
{
	return a->pixels && b->pixels && a->width == b->width && a->height == b->height && a->stride == b->stride &&
	       memcmp(a->pixels, b->pixels, a->stride * a->height) == 0;
}

/* n boxes stacked in one place under a soft spot light (a fixed 2048^2 map), a VSM point light
 * and a soft sun, w x w pixels. */
static char *stacked_scene(int n, int w, int res)
{
	size_t cap = 4096 + (size_t)n * 160;
	char *j = malloc(cap);
	if (!j) return NULL;
	int at = snprintf(j, cap,
	                  "{'width':%d,'height':%d,'camera':{'position':[0,5,14],'target':[0,4,0]},"
	                  "'lights':[{'type':'spot','position':[3,12,4],'direction':[-3,-8,-4],'radius':0.3,"
	                  "'outer_angle':60,'shadow':{'resolution':%d}},"
	                  "{'type':'point','position':[-6,9,6],'intensity':40,'shadow':{'filter':'vsm','resolution':256}},"
	                  "{'type':'directional','direction':[-0.4,-1,-0.3],'angular_diameter':1}],"
	                  "'objects':[{'shape':'plane','size':[40,40]}",
	                  w, w, res);
	for (int i = 0; i < n && at > 0 && (size_t)at < cap; i++)
		at += snprintf(j + at, cap - (size_t)at,
		               ",{'shape':'box','size':[8,8,8],'transform':{'translation':[%.3f,%.3f,0]}}", 0.001 * i,
		               4 + 0.001 * i);
	if (at > 0 && (size_t)at + 3 < cap) memcpy(j + at, "]}", 3);
	return j;
}

static struct api_scene *stacked(int n, int w, int res)
{
	char *json = stacked_scene(n, w, res);
	struct api_scene *s = json ? gpu_parse(json) : NULL;
	free(json);
	return s;
}

/* A render with no cached map: every map drawn (rnd_context_trim drops them). */
static enum rnd_result render_uncached(struct rnd_context *ctx, struct api_scene *s, struct rnd_image *img,
                                       struct rnd_timings *t, struct rnd_error *err)
{
	rnd_context_trim(ctx, 0);
	return rnd_render(ctx, &s->scene, img, t, err);
}

TEST(pacing_shadow_map_parts_give_the_same_bytes)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	struct api_scene *s = stacked(6, 64, 512);
	REQUIRE(s);
	uint32_t before = rnd_context_validation_messages(ctx);
	struct rnd_image whole = {0}, parts = {0};
	struct rnd_timings t1 = {0}, t2 = {0};
	struct rnd_error err = {0};
	CHECK(render_uncached(ctx, s, &whole, &t1, &err) == RND_OK, "one submit: %s", err.msg);
	/* 6 boxes and a plane: 74 caster triangles in parts of 5, across box boundaries. */
	s->scene.shadow_part_triangles = 5;
	CHECK(render_uncached(ctx, s, &parts, &t2, &err) == RND_OK, "in parts: %s", err.msg);
	CHECK(t1.shadow_parts == 0, "unasked parts: %u", t1.shadow_parts);
	CHECK(t2.shadow_parts > t2.shadow_maps_rendered, "maps in parts of 5 triangles: %u submits for %u maps",
	      t2.shadow_parts, t2.shadow_maps_rendered);
	CHECK(same_pixels(&whole, &parts), "shadow maps drawn in parts changed the image");
	CHECK(rnd_context_validation_messages(ctx) == before, "validation messages");
	rnd_image_release(&whole);
	rnd_image_release(&parts);
	api_scene_free(s);
}

TEST(pacing_stacked_layers_are_cut_into_submits)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	struct api_scene *s = stacked(400, 224, 2048);
	REQUIRE(s);
	uint32_t before = rnd_context_validation_messages(ctx);
	struct rnd_image whole = {0}, paced = {0};
	struct rnd_timings t = {0};
	struct rnd_error err = {0};
	CHECK(render_uncached(ctx, s, &whole, NULL, &err) == RND_OK, "unpaced: %s", err.msg);
	/* A deadline ten minutes away: slices of 1 s. The cost model counts ~750 layers over the
	 * image and ~400 over the spot light's 2048^2 map, each estimated past half a slice (~2 s
	 * each on lavapipe): the map in parts and the main pass in bands (before, one submit each). */
	s->scene.deadline_ns = mono_ns() + 600ull * 1000000000ull;
	CHECK(render_uncached(ctx, s, &paced, &t, &err) == RND_OK, "paced: %s", err.msg);
	CHECK(t.shadow_parts >= 2, "the spot light's map in %u parts", t.shadow_parts);
	CHECK(t.submits >= t.shadow_parts + 2, "%u submits (%u of them shadow parts): the main pass in bands", t.submits,
	      t.shadow_parts);
	CHECK(same_pixels(&whole, &paced), "paced submits changed the image");
	CHECK(rnd_context_validation_messages(ctx) == before, "validation messages");
	rnd_image_release(&whole);
	rnd_image_release(&paced);
	api_scene_free(s);
}

/* Eight spot lights over 30 boxes stacked in one place: ~280 ms of maps by the cost model (30
 * layers of fill each), under half a slice (0.5 s of a deadline ten minutes away). They went in
 * one submit, and a group runs whole before the deadline is checked: 32 spot maps estimated at
 * 0.4 s ran 11 s in one submit on a machine at load 15. Now the first group is an eighth of a
 * slice by estimate and the next ones are sized by what it measured: at least two submits of
 * maps, the same bytes. */
TEST(pacing_first_shadow_group_is_small)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	char json[8192];
	int at = snprintf(json, sizeof json, "{'width':48,'height':48,'camera':{'position':[0,5,14],'target':[0,4,0]},'lights':[");
	for (int i = 0; i < 8; i++)
		at += snprintf(json + at, sizeof json - (size_t)at,
		               "%s{'type':'spot','position':[%d,12,4],'direction':[%d,-8,-4],'outer_angle':60,'intensity':5,"
		               "'shadow':{'filter':'pcf','resolution':1024}}",
		               i ? "," : "", i - 4, 4 - i);
	at += snprintf(json + at, sizeof json - (size_t)at, "],'objects':[{'shape':'plane','size':[40,40]}");
	for (int i = 0; i < 30; i++)
		at += snprintf(json + at, sizeof json - (size_t)at,
		               ",{'shape':'box','size':[8,8,8],'transform':{'translation':[%.3f,%.3f,0]}}", 0.001 * i,
		               4 + 0.001 * i);
	REQUIRE(at > 0 && (size_t)at + 3 < sizeof json);
	memcpy(json + at, "]}", 3);
	struct api_scene *s = gpu_parse(json);
	REQUIRE(s);
	uint32_t before = rnd_context_validation_messages(ctx);
	struct rnd_image whole = {0}, paced = {0};
	struct rnd_timings t0 = {0}, t = {0};
	struct rnd_error err = {0};
	CHECK(render_uncached(ctx, s, &whole, &t0, &err) == RND_OK, "unpaced: %s", err.msg);
	CHECK(t0.shadow_submits == 0 && t0.submits == 1, "unpaced: %u submits, %u of maps", t0.submits, t0.shadow_submits);
	s->scene.deadline_ns = mono_ns() + 600ull * 1000000000ull;
	CHECK(render_uncached(ctx, s, &paced, &t, &err) == RND_OK, "paced: %s", err.msg);
	CHECK(t.shadow_maps_rendered == 8, "%u maps drawn", t.shadow_maps_rendered);
	CHECK(t.shadow_submits >= 2, "8 maps in %u submit(s): the first group is not kept small", t.shadow_submits);
	CHECK(t.submits > t.shadow_submits, "%u submits, %u of maps", t.submits, t.shadow_submits);
	CHECK(same_pixels(&whole, &paced), "the maps in groups changed the image");
	CHECK(rnd_context_validation_messages(ctx) == before, "validation messages");
	rnd_image_release(&whole);
	rnd_image_release(&paced);
	api_scene_free(s);
}

/* 16,000 planes side by side with a sphere above them: judging each plane against every other
 * (does it shadow it?) was quadratic and ran before the first submit, where no deadline is
 * checked: 107 s of planning on lavapipe (issue 29). Past RND_PLANES_JUDGED_MAX objects every
 * plane that asks to cast does: linear, ~1.5 s for the whole render. The deadline is a minute,
 * 40 times what the render needs: before, it ran out during planning. */
TEST(pacing_many_planes_plan_in_linear_time)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	const int n = 16000;
	size_t cap = 512 + (size_t)n * 96;
	char *j = malloc(cap);
	REQUIRE(j);
	int at = snprintf(j, cap,
	                  "{'width':64,'height':64,'camera':{'position':[30,40,80],'target':[30,0,30]},"
	                  "'lights':[{'type':'directional','direction':[-0.3,-1,-0.2]}],"
	                  "'objects':[{'shape':'sphere','radius':0.5,'segments':16,'transform':{'translation':[0,1,0]}}");
	for (int i = 0; i < n && at > 0 && (size_t)at < cap; i++)
		at += snprintf(j + at, cap - (size_t)at,
		               ",{'shape':'plane','size':[0.5,0.5],'transform':{'translation':[%.1f,0,%.1f]}}",
		               (i % 100) * 0.6, (i / 100) * 0.6);
	if (at > 0 && (size_t)at + 3 < cap) memcpy(j + at, "]}", 3);
	struct api_scene *s = gpu_parse(j);
	free(j);
	REQUIRE(s);
	struct rnd_image img = {0};
	struct rnd_error err = {0};
	s->scene.deadline_ns = mono_ns() + 60ull * 1000000000ull;
	enum rnd_result r = rnd_render(ctx, &s->scene, &img, NULL, &err);
	CHECK(r == RND_OK && img.pixels, "16,000 planes: %s (%s)", rnd_result_str(r), err.msg);
	rnd_image_release(&img);
	api_scene_free(s);
}
