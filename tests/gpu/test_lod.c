/* tests/gpu — renderer/lod.h: a dense sphere (thumb-512: 316 segments over a plane, one sun,
 * MSAA 4, PCF) rendered with the level of detail against the same scene at exactly 316
 * segments. The chords stay within 1/32 pixel of the surface, so no pixel may change by more
 * than a quarter (what a 1/32-pixel edge shift can do, with margin for the shadow-map texels
 * and shading the coarser normals move) and the mean must stay far below 1/255; and the same
 * request gives the same bytes. */
#include <math.h>
#include <stdio.h>
#include <unistd.h>
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

/* Writes a binary STL of a unit UV sphere (seg x seg quads, 2 triangles each, facets wound
 * outward, as tests/bench/variants.py writes them) to path. */
static bool write_sphere_stl(const char *path, int seg)
{
	FILE *f = fopen(path, "wb");
	if (!f) return false;
	char head[80] = {0};
	uint32_t n = (uint32_t)(2 * seg * seg);
	bool ok = fwrite(head, 1, 80, f) == 80 && fwrite(&n, 4, 1, f) == 1;
	for (int i = 0; ok && i < seg; i++)
		for (int j = 0; ok && j < seg; j++) {
			float q[4][3];
			for (int c = 0; c < 4; c++) {
				double th = GPU_PI * (i + (c >> 1)) / seg, ph = 2 * GPU_PI * (j + (c & 1)) / seg;
				q[c][0] = (float)(sin(th) * cos(ph)); q[c][1] = (float)cos(th); q[c][2] = (float)(sin(th) * sin(ph));
			}
			static const int tri[2][3] = {{0, 1, 2}, {1, 3, 2}};
			for (int t = 0; ok && t < 2; t++) {
				float rec[12] = {0};
				for (int c = 0; c < 3; c++) memcpy(rec + 3 + 3 * c, q[tri[t][c]], 12);
				uint16_t attr = 0;
				ok = fwrite(rec, 4, 12, f) == 12 && fwrite(&attr, 2, 1, f) == 1;
			}
		}
	return fclose(f) == 0 && ok;
}

static bool render_model(struct rnd_image *img, const char *root, bool exact)
{
	static const char *doc =
		"{\"width\": 256, \"height\": 256, \"camera\": {\"fit\": \"objects\", \"direction\": [-1, -0.6, -1], \"margin\": 0.1},"
		" \"objects\": [{\"shape\": \"plane\", \"size\": [20, 20], \"transform\": {\"translation\": [0, -1, 0]}},"
		" {\"shape\": \"model\", \"path\": \"sphere.stl\"}],"
		" \"lights\": [{\"type\": \"directional\", \"direction\": [-0.5, -1, -0.3]}]}";
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = root;
	struct api_scene *s = NULL;
	struct api_problem p;
	memset(img, 0, sizeof *img);
	if (!gpu_ctx()) { CHECK(0, "no context"); return false; }
	if (api_scene_parse(doc, strlen(doc), &lim, &s, &p) != API_OK) {
		CHECK(0, "parse: %s %s", p.pointer, p.detail);
		return false;
	}
	CHECK(s->scene.object_count == 2 && s->scene.objects[1].lod_count > 0 && s->scene.objects[1].closed,
	      "the 45k-triangle sphere has levels and is closed");
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

/* An imported 45k-triangle STL sphere drawn with its simplified level (within 1/2 pixel) and in
 * full: silhouettes and the ground shadow stay put (few pixels change by more than a quarter),
 * and the shading barely moves (the level's smooth normals against the file's flat facets). */
TEST(lod_model_level_within_bound_of_full_mesh)
{
	char dir[] = "/tmp/umbra-lod-XXXXXX", path[64];
	REQUIRE(mkdtemp(dir) != NULL, "mkdtemp");
	snprintf(path, sizeof path, "%s/sphere.stl", dir);
	REQUIRE(write_sphere_stl(path, 150), "writing %s", path);
	struct rnd_image lod, full;
	bool ok = render_model(&lod, dir, false);
	if (ok && !render_model(&full, dir, true)) { rnd_image_release(&lod); ok = false; }
	remove(path);
	rmdir(dir);
	if (!ok) return;
	double sum = 0;
	int big = 0;
	for (uint32_t j = 0; j < lod.height; j++)
		for (uint32_t i = 0; i < lod.width; i++) {
			double d = 0;
			for (int c = 0; c < 3; c++) d = fmax(d, fabs(gpu_chan(&lod, (int)i, (int)j, c) - gpu_chan(&full, (int)i, (int)j, c)));
			sum += d;
			if (d > 0.25) big++;
		}
	double mean = sum / ((double)lod.width * lod.height);
	printf("  model level vs full: mean abs diff %.5f, %d pixels over 1/4\n", mean, big);
	CHECK(mean < 2.0 / 255.0, "mean difference %.5f", mean);
	CHECK(big <= 20, "%d pixels changed by more than a quarter", big);
	rnd_image_release(&lod);
	rnd_image_release(&full);
}
