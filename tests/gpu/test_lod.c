/* tests/gpu — renderer/lod.h: a dense sphere (thumb-512: 316 segments over a plane, one sun,
 * MSAA 4, PCF) rendered with the level of detail against the same scene at exactly 316
 * segments. The chords stay within 1/32 pixel of the surface, so no pixel may change by more
 * than a quarter (what a 1/32-pixel edge shift can do, with margin for the shadow-map texels
 * and shading the coarser normals move) and the mean must stay far below 1/255; and the same
 * request gives the same bytes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"

static const char *THUMB =
	"{\"width\": 512, \"height\": 512, \"camera\": {\"type\": \"perspective\", \"position\": [4, 3, 4],"
	" \"target\": [0, 0.8, 0], \"up\": [0, 1, 0], \"fov_y\": 40},"
	" \"environment\": {\"background\": [0.5, 0.5, 0.5]},"
	" \"materials\": {\"grey\": {\"base_color\": [0.7, 0.7, 0.7], \"roughness\": 0.8, \"metallic\": 0}},"
	" \"objects\": [{\"shape\": \"plane\", \"size\": [10, 10], \"material\": \"grey\"},"
	" {\"shape\": \"sphere\", \"radius\": 1, \"segments\": 316, \"material\": \"grey\","
	" \"transform\": {\"translation\": [0, 1, 0]}}],"
	" \"lights\": [{\"type\": \"directional\", \"direction\": [-0.5, -1, -0.3], \"color\": [1, 1, 1], \"intensity\": 3}]}";

static bool render_thumb(struct rnd_image *img, bool exact)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	struct api_scene *s = NULL;
	struct api_problem p;
	memset(img, 0, sizeof *img);
	if (!gpu_ctx()) { CHECK(0, "no context"); return false; }
	if (api_scene_parse(THUMB, strlen(THUMB), &lim, &s, &p) != API_OK) {
		CHECK(0, "parse: %s %s", p.pointer, p.detail);
		return false;
	}
	s->scene.exact_segments = exact;
	struct rnd_timings t;
	struct rnd_error err = {0};
	uint32_t before = rnd_context_validation_messages(gpu_ctx());
	enum rnd_result r = rnd_render(gpu_ctx(), &s->scene, img, &t, &err);
	api_scene_free(s);
	CHECK(rnd_context_validation_messages(gpu_ctx()) == before, "validation messages");
	CHECK(r == RND_OK, "render: %s", err.msg);
	return r == RND_OK;
}

TEST(lod_dense_sphere_within_bound_of_full_detail)
{
	struct rnd_image lod, exact, again;
	if (!render_thumb(&lod, false)) return;
	if (!render_thumb(&exact, true)) { rnd_image_release(&lod); return; }
	if (!render_thumb(&again, false)) { rnd_image_release(&lod); rnd_image_release(&exact); return; }
	double sum = 0, worst = 0;
	int changed = 0;
	for (uint32_t j = 0; j < lod.height; j++)
		for (uint32_t i = 0; i < lod.width; i++)
			for (int c = 0; c < 3; c++) {
				double d = fabs(gpu_chan(&lod, (int)i, (int)j, c) - gpu_chan(&exact, (int)i, (int)j, c));
				sum += d;
				if (d > worst) worst = d;
				if (d > 2.5 / 255.0) changed++;
			}
	double mean = sum / (3.0 * lod.width * lod.height);
	printf("  lod vs exact: mean abs diff %.6f, max %.4f, %d channel values differ by > 2/255\n", mean, worst, changed);
	CHECK(mean < 0.25 / 255.0, "mean abs difference %.6f", mean);
	CHECK(worst <= 0.25, "largest difference %.4f", worst);
	bool same = lod.height == again.height;
	for (uint32_t j = 0; same && j < lod.height; j++)
		same = !memcmp((const char *)lod.pixels + j * lod.stride, (const char *)again.pixels + j * again.stride,
		               (size_t)lod.width * 4);
	CHECK(same, "the same request rendered twice differs");
	rnd_image_release(&lod);
	rnd_image_release(&exact);
	rnd_image_release(&again);
}
