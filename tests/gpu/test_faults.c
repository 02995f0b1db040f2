/* tests/gpu — the bad day: renders cut into bands give the same bytes, a deadline or a cancel
 * stops a render between submits and gives its atlas tiles back, an injected out-of-memory
 * submit gives them back too (the atlas does not shrink), an injected device loss fails only
 * its own context. Fault tests that fail a context use a private one. Run: gpu_tests faults */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"

/* Spot, point and sun lights over a sphere and a box, every AOV: all passes are exercised. */
#define FAULT_SCENE(res)                                                                                 \
	"{'width':96,'height':80,'camera':{'position':[4,3,4],'target':[0,0.6,0]},"                           \
	"'objects':[{'shape':'plane','size':[8,8]},"                                                         \
	"{'shape':'sphere','radius':0.7,'segments':24,'transform':{'translation':[0,0.7,0]}},"               \
	"{'shape':'box','size':[0.6,1.2,0.6],'transform':{'translation':[1.4,0.6,-0.5]}}],"                  \
	"'lights':[{'type':'spot','position':[2,4,1],'direction':[-2,-4,-1],'radius':0.1,"                    \
	"'shadow':{'resolution':" res "}},"                                                                  \
	"{'type':'point','position':[-1.5,2.5,1],'intensity':20,'shadow':{'resolution':" res "}},"           \
	"{'type':'directional','direction':[-0.5,-1,-0.3],'angular_diameter':0.53}],"                         \
	"'output':{'format':'exr','aovs':['shadow','depth','normal','albedo']}}"

static uint64_t mono_ns(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (uint64_t)t.tv_sec * 1000000000ull + (uint64_t)t.tv_nsec;
}

static bool same_image(const struct rnd_image *a, const struct rnd_image *b)
{
	if (a->width != b->width || a->height != b->height || a->stride != b->stride || a->aov_count != b->aov_count)
		return false;
	if (memcmp(a->pixels, b->pixels, a->stride * a->height) != 0) return false;
	for (uint32_t i = 0; i < a->aov_count; i++)
		if (strcmp(a->aov_names[i], b->aov_names[i]) || memcmp(a->aov[i], b->aov[i], (size_t)a->width * a->height * 4))
			return false;
	return true;
}

TEST(faults_bands_give_the_same_bytes)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	struct api_scene *s = gpu_parse(FAULT_SCENE("256"));
	REQUIRE(s);
	uint32_t before = rnd_context_validation_messages(ctx);
	struct rnd_image whole = {0}, bands = {0}, paced = {0};
	struct rnd_error err = {0};
	enum rnd_result r = rnd_render(ctx, &s->scene, &whole, NULL, &err);
	CHECK(r == RND_OK, "one submit: %s", err.msg);
	s->scene.band_rows = 13;   /* 7 bands, the last one short */
	r = rnd_render(ctx, &s->scene, &bands, NULL, &err);
	CHECK(r == RND_OK, "bands of 13 rows: %s", err.msg);
	/* A deadline far away: shadow views in groups and bands sized by the renderer. */
	s->scene.band_rows = 0;
	s->scene.deadline_ns = mono_ns() + 600ull * 1000000000ull;
	r = rnd_render(ctx, &s->scene, &paced, NULL, &err);
	CHECK(r == RND_OK, "paced: %s", err.msg);
	CHECK(whole.pixels && bands.pixels && same_image(&whole, &bands), "13-row bands changed the image or its AOVs");
	CHECK(whole.pixels && paced.pixels && same_image(&whole, &paced), "paced submits changed the image or its AOVs");
	CHECK(rnd_context_validation_messages(ctx) == before, "validation messages");
	rnd_image_release(&whole);
	rnd_image_release(&bands);
	rnd_image_release(&paced);
	api_scene_free(s);
}

struct cancel_after { int calls, at; };

static bool cancel_at(void *user)
{
	struct cancel_after *c = user;
	return ++c->calls >= c->at;
}

TEST(faults_deadline_and_cancel_stop_between_submits)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	struct api_scene *s = gpu_parse(FAULT_SCENE("512"));
	REQUIRE(s);
	struct rnd_stats base, after;
	rnd_context_stats(ctx, &base);
	struct rnd_image img = {0};
	struct rnd_error err = {0};
	/* Already past: nothing is rendered. */
	s->scene.deadline_ns = mono_ns() - 1;
	enum rnd_result r = rnd_render(ctx, &s->scene, &img, NULL, &err);
	CHECK(r == RND_ERR_TIMEOUT, "past deadline: %s (%s)", rnd_result_str(r), err.msg);
	CHECK(!img.pixels, "an image came back from a timed-out render");
	/* Cancelled in the middle: after some submits (bands of 8 rows: 10 of them). */
	s->scene.deadline_ns = 0;
	s->scene.band_rows = 8;
	struct cancel_after c = {0, 6};
	s->scene.cancel = cancel_at;
	s->scene.cancel_user = &c;
	r = rnd_render(ctx, &s->scene, &img, NULL, &err);
	CHECK(r == RND_ERR_TIMEOUT, "cancelled: %s (%s)", rnd_result_str(r), err.msg);
	CHECK(c.calls == 6, "the callback was polled %d times after it said stop", c.calls);
	CHECK(strstr(err.msg, "after") && !strstr(err.msg, "after 0 submits"), "stopped before any submit: %s", err.msg);
	rnd_context_stats(ctx, &after);
	CHECK(after.atlas_tiles == base.atlas_tiles && after.atlas_occupancy == base.atlas_occupancy,
	      "atlas tiles %u -> %u after a cancelled render", base.atlas_tiles, after.atlas_tiles);
	/* The slot is fine afterwards. */
	s->scene.cancel = NULL;
	r = rnd_render(ctx, &s->scene, &img, NULL, &err);
	CHECK(r == RND_OK && img.pixels, "render after a cancel: %s", err.msg);
	rnd_image_release(&img);
	api_scene_free(s);
}

TEST(faults_injected_oom_gives_atlas_tiles_back)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	/* A resolution no other test asks for: these maps are not in the cache yet. */
	struct api_scene *s = gpu_parse(FAULT_SCENE("128"));
	REQUIRE(s);
	struct rnd_stats base, after;
	rnd_context_stats(ctx, &base);
	struct rnd_image img = {0};
	struct rnd_error err = {0};
	rnd_context_inject_fault(ctx, RND_FAULT_OUT_OF_MEMORY, 1);
	enum rnd_result r = rnd_render(ctx, &s->scene, &img, NULL, &err);
	CHECK(r == RND_ERR_OOM, "injected OOM: %s (%s)", rnd_result_str(r), err.msg);
	rnd_context_stats(ctx, &after);
	CHECK(after.atlas_tiles == base.atlas_tiles && after.atlas_occupancy == base.atlas_occupancy,
	      "atlas tiles %u -> %u (occupancy %.6f -> %.6f) after a failed submit", base.atlas_tiles, after.atlas_tiles,
	      base.atlas_occupancy, after.atlas_occupancy);
	/* The context and the slot still work, and the maps are cached this time. */
	r = rnd_render(ctx, &s->scene, &img, NULL, &err);
	CHECK(r == RND_OK && img.pixels, "render after the fault: %s", err.msg);
	rnd_context_stats(ctx, &after);
	CHECK(after.atlas_tiles > base.atlas_tiles, "no tiles held by the successful render (%u)", after.atlas_tiles);
	rnd_image_release(&img);
	api_scene_free(s);
}

TEST(faults_injected_device_loss_fails_the_context)
{
	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {0};
	cd.validation = v && strcmp(v, "1") == 0;
	cd.atlas_size = 1024;
	struct rnd_context *ctx = NULL;
	struct rnd_error err = {0};
	REQUIRE(rnd_context_create(&cd, &ctx, &err) == RND_OK, "%s", err.msg);
	struct api_scene *s = gpu_parse(FAULT_SCENE("128"));
	struct rnd_image img = {0};
	if (s) {
		rnd_context_inject_fault(ctx, RND_FAULT_DEVICE_LOST, 1);
		enum rnd_result r = rnd_render(ctx, &s->scene, &img, NULL, &err);
		CHECK(r == RND_ERR_DEVICE_LOST, "injected loss: %s (%s)", rnd_result_str(r), err.msg);
		r = rnd_render(ctx, &s->scene, &img, NULL, &err);
		CHECK(r == RND_ERR_DEVICE_LOST, "the context still renders after a loss: %s", rnd_result_str(r));
		CHECK(!img.pixels, "an image from a failed context");
	}
	CHECK(rnd_context_validation_messages(ctx) == 0, "%u validation messages", rnd_context_validation_messages(ctx));
	rnd_context_destroy(ctx);
	/* A new context renders the same scene (what umbrad does after a loss). */
	REQUIRE(rnd_context_create(&cd, &ctx, &err) == RND_OK, "%s", err.msg);
	if (s) {
		enum rnd_result r = rnd_render(ctx, &s->scene, &img, NULL, &err);
		CHECK(r == RND_OK && img.pixels, "render on the new context: %s", err.msg);
	}
	CHECK(rnd_context_validation_messages(ctx) == 0, "%u validation messages", rnd_context_validation_messages(ctx));
	rnd_image_release(&img);
	api_scene_free(s);
	rnd_context_destroy(ctx);
}
