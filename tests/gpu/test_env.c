/* tests/gpu — the environment map (issue 31): its light against closed forms (a white sky on a
 * white Lambert sphere, a mirror reflecting a patch), the map's orientation in the background,
 * the cache (one prefilter per map; the shadow directions' maps reused), the counts a request
 * reports, and its shadows against Blender Cycles references stored in tests/gpu/truth_env/
 * (README there: made once by ../shared/truth-cycles, never by the code under test). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "api.h"
#include "envmaps.h"
#include "util.h"
#include "gpu_util.h"
#include "test.h"

#define TRUTH_ENV "tests/gpu/truth_env/"

/* An asset root holding white.hdr (radiance 1) and patch.hdr (a 24° patch of 4 at azimuth 180,
 * the map's -X, on 0.02). */
static const char *env_root(void)
{
	static char root[64];
	if (root[0]) return root;
	snprintf(root, sizeof root, "/tmp/umbra_gpu_env_XXXXXX");
	if (!mkdtemp(root)) return NULL;
	const char *names[2] = {"white.hdr", "patch.hdr"};
	float *maps[2] = {test_patch_map(128, 64, 0, 0, 1, 1.0f, 1.0f), test_patch_map(128, 64, 180, 0, 24, 4.0f, 0.02f)};
	for (int i = 0; i < 2; i++) {
		size_t n;
		uint8_t *b = test_hdr_bytes(maps[i], 128, 64, true, &n);
		char p[128];
		snprintf(p, sizeof p, "%s/%s", root, names[i]);
		FILE *f = fopen(p, "wb");
		if (f) {
			fwrite(b, 1, n, f);
			fclose(f);
		}
		free(b);
		free(maps[i]);
	}
	return root;
}

/* Linear RGB of pixel (i, j) of an RGBA32F image. */
static const float *px32(const struct rnd_image *img, int i, int j)
{
	return (const float *)((const uint8_t *)img->pixels + (size_t)j * img->stride) + 4 * i;
}

TEST(env_white_sky_gives_a_white_lambert_sphere_its_radiance)
{
	gpu_asset_root = env_root();
	struct rnd_image img;
	/* E / pi = 1 everywhere under a sky of radiance 1: a white Lambert surface leaves 1, and
	 * the specular lobe of f0 0.04 adds its share (A f0 + B of the split sum, 0.04-0.1) */
	if (!gpu_render(&img, "{'width': 64, 'height': 64, 'camera': {'position': [0, 0, 4], 'target': [0, 0, 0], 'fov_y': 30},"
	                      "'environment': {'map': 'white.hdr', 'shadow': false},"
	                      "'objects': [{'shape': 'sphere', 'radius': 0.8, 'material': {'base_color': [1, 1, 1],"
	                      " 'roughness': 1, 'metallic': 0}}], 'output': {'format': 'exr', 'msaa': 1}}"))
		goto out;
	const float *c = px32(&img, 32, 32), *edge = px32(&img, 32, 8);
	printf("  white sky, white Lambert sphere: centre %.4f, near the top %.4f\n", c[1], edge[1]);
	CHECK(c[1] > 0.99f && c[1] < 1.12f, "centre radiance %g (want 1 + the specular lobe)", c[1]);
	CHECK(fabsf(c[0] - c[2]) < 1e-3f, "neutral: %g %g", c[0], c[2]);
	CHECK(edge[1] > 0.95f && edge[1] < 1.3f, "towards the rim %g", edge[1]);
	CHECK(gpu_last_timings.env_directions == 0, "shadow false: no directions (%u)", gpu_last_timings.env_directions);
out:
	rnd_image_release(&img);
	gpu_asset_root = NULL;
}

/* The background and the mirror read the map where the documented convention says:
 * scene d reads u = 0.5 + atan2(z, x) / 2pi, turned by R_y(rotation). */
TEST(env_map_orientation_background_and_mirror)
{
	gpu_asset_root = env_root();
	struct { const char *target; float rot; bool bright; } bg[] = {
		{"[-1, 0, 0]", 0, true}, {"[1, 0, 0]", 0, false}, {"[0, 0, 1]", 90, true}, {"[-1, 0, 0]", 90, false},
	};
	for (int k = 0; k < 4; k++) {
		struct rnd_image img;
		if (!gpu_render(&img, "{'width': 32, 'height': 32, 'camera': {'position': [0, 0, 0], 'target': %s, 'fov_y': 10},"
		                      "'environment': {'map': {'path': 'patch.hdr', 'rotation': %g}, 'background': 'map'},"
		                      "'objects': [], 'output': {'format': 'exr', 'msaa': 1}}",
		                bg[k].target, bg[k].rot))
			continue;
		float v = px32(&img, 16, 16)[0];
		CHECK(bg[k].bright ? fabsf(v - 4.0f) < 0.2f : v < 0.1f, "looking at %s, rotation %g: %g", bg[k].target, bg[k].rot, v);
		rnd_image_release(&img);
	}
	/* a mirror sphere seen from -X reflects -X at its centre: the patch (f0 = base colour 1) */
	for (int k = 0; k < 2; k++) {
		struct rnd_image img;
		if (!gpu_render(&img, "{'width': 32, 'height': 32, 'camera': {'position': [-5, 0, 0], 'target': [0, 0, 0], 'fov_y': 20},"
		                      "'environment': {'map': {'path': 'patch.hdr', 'rotation': %d}, 'shadow': false},"
		                      "'objects': [{'shape': 'sphere', 'radius': 1, 'material': {'base_color': [1, 1, 1],"
		                      " 'metallic': 1, 'roughness': 0}}], 'output': {'format': 'exr', 'msaa': 1}}", k ? 180 : 0))
			continue;
		float v = px32(&img, 16, 16)[1];
		CHECK(k ? v < 0.15f : v > 3.0f, "mirror, rotation %d: %g", k ? 180 : 0, v);
		rnd_image_release(&img);
	}
	gpu_asset_root = NULL;
}

/* One prefilter per map however many renders use it; the shadow directions' maps are kept and
 * reused like any sun's; each render says how many directions it drew. */
TEST(env_map_built_once_and_its_shadow_maps_reused)
{
	gpu_asset_root = env_root();
	struct rnd_stats s0, s1;
	rnd_context_stats(gpu_ctx(), &s0);
	const char *doc = "{'width': 48, 'height': 48, 'camera': {'position': [3, 2, 3], 'target': [0, 0.3, 0]},"
	                  "'environment': {'map': {'path': 'patch.hdr', 'rotation': 17}, 'shadow': {'directions': 6}},"
	                  "'objects': [{'shape': 'plane', 'size': [4, 4]}, {'shape': 'box', 'size': [0.6, 0.6, 0.6],"
	                  " 'transform': {'translation': [0, 0.3, 0]}}], 'output': {'msaa': 1}}";
	struct rnd_image a, b;
	bool ok = gpu_render(&a, doc, 0);
	struct rnd_timings t0 = gpu_last_timings;
	ok = gpu_render(&b, doc, 0) && ok;
	struct rnd_timings t1 = gpu_last_timings;
	rnd_context_stats(gpu_ctx(), &s1);
	if (ok) {
		printf("  first render: %u directions, %u maps drawn; second: %u drawn, %u reused; builds %llu -> %llu\n",
		       t0.env_directions, t0.shadow_maps_rendered, t1.shadow_maps_rendered, t1.shadow_maps_reused,
		       (unsigned long long)s0.env_builds, (unsigned long long)s1.env_builds);
		CHECK(t0.env_directions == 6 && t1.env_directions == 6, "6 directions asked: %u, %u", t0.env_directions,
		      t1.env_directions);
		CHECK(t1.shadow_maps_rendered == 0 && t1.shadow_maps_reused == 6, "the same scene again: %u drawn, %u reused",
		      t1.shadow_maps_rendered, t1.shadow_maps_reused);
		CHECK(s1.env_builds - s0.env_builds <= 1, "one map, at most one build: %llu",
		      (unsigned long long)(s1.env_builds - s0.env_builds));
		CHECK(gpu_bytes_differ(&a, &b, NULL) == 0, "the same request, the same bytes");
	}
	rnd_image_release(&a);
	rnd_image_release(&b);
	gpu_asset_root = NULL;
}

/* The environment pass's images are reused by a request that comes back with the same inputs
 * (env_pass.h rnd_env_pass_key), never by one whose geometry or camera moved, and a reused pass
 * gives the bytes a drawn one gives. */
static bool env_pass_render(struct rnd_image *img, const char *box, const char *cam, uint32_t *reused)
{
	bool ok = gpu_render(img, "{'width': 48, 'height': 48, 'camera': {'position': %s, 'target': [0, 0.3, 0]},"
	                          "'environment': {'map': {'path': 'patch.hdr', 'rotation': 17}, 'shadow': {'directions': 6}},"
	                          "'objects': [{'shape': 'plane', 'size': [4, 4]}, {'shape': 'box', 'size': [0.6, 0.6, 0.6],"
	                          " 'transform': {'translation': %s}}], 'output': {'msaa': 1}}", cam, box);
	*reused = ok ? gpu_last_timings.env_passes_reused : 99;
	return ok;
}

TEST(env_pass_reused_only_for_the_same_inputs)
{
	gpu_asset_root = env_root();
	const char *box = "[0, 0.3, 0]", *moved = "[0.05, 0.3, 0]", *cam = "[3, 2, 3]", *cam2 = "[3, 2.1, 3]";
	struct rnd_image a1, a2, b, c, a3, a4;
	uint32_t r[6];
	bool ok = env_pass_render(&a1, box, cam, &r[0]);
	ok = env_pass_render(&a2, box, cam, &r[1]) && ok;
	ok = env_pass_render(&b, moved, cam, &r[2]) && ok;
	ok = env_pass_render(&c, moved, cam2, &r[3]) && ok;
	ok = env_pass_render(&a3, box, cam, &r[4]) && ok;
	setenv("UMBRA_ENV_PASS_REUSE", "0", 1);
	ok = env_pass_render(&a4, box, cam, &r[5]) && ok;
	unsetenv("UMBRA_ENV_PASS_REUSE");
	if (ok) {
		printf("  passes reused: %u %u %u %u %u %u\n", r[0], r[1], r[2], r[3], r[4], r[5]);
		CHECK(r[1] == 1, "the same request again: its pass reused (%u)", r[1]);
		CHECK(r[2] == 0 && r[3] == 0, "the box moved, then the camera: drawn (%u, %u)", r[2], r[3]);
		CHECK(r[4] == 0 && r[5] == 0, "after another scene, and with reuse off: drawn (%u, %u)", r[4], r[5]);
		CHECK(gpu_bytes_differ(&a1, &a2, NULL) == 0, "reused: the bytes of the drawn pass");
		CHECK(gpu_bytes_differ(&a1, &a3, NULL) == 0 && gpu_bytes_differ(&a1, &a4, NULL) == 0,
		      "drawn again, with and without reuse: the same bytes");
		CHECK(gpu_bytes_differ(&a1, &b, NULL) > 0 && gpu_bytes_differ(&b, &c, NULL) > 0, "the moves show");
	}
	struct rnd_image *all[6] = {&a1, &a2, &b, &c, &a3, &a4};
	for (int i = 0; i < 6; i++) rnd_image_release(all[i]);
	gpu_asset_root = NULL;
}

/* ---- shadows against Cycles ---- */

struct env_score {
	double ground_rmse, model_rmse;
	long ground_px, model_px;
	double inner, rim;    /* cup_white: mean visibility inside the cup / on its rim and outer wall */
};

/* Scores candidate c against the stored reference NAME (vis, mask, objid: 0 ground, 1.. objects,
 * 255 background) over the valid pixels. */
static bool score_env(const char *name, const struct rnd_image *img, struct env_score *s)
{
	char p[3][160];
	snprintf(p[0], sizeof p[0], TRUTH_ENV "%s.vis.png", name);
	snprintf(p[1], sizeof p[1], TRUTH_ENV "%s.mask.png", name);
	snprintf(p[2], sizeof p[2], TRUTH_ENV "%s.obj.png", name);
	uint32_t w = img->width, h = img->height;
	float *t = gpu_read_grey(p[0], w, h), *m = gpu_read_grey(p[1], w, h), *o = gpu_read_grey(p[2], w, h);
	memset(s, 0, sizeof *s);
	bool ok = t && m && o;
	double se[2] = {0, 0};
	for (uint32_t i = 0; ok && i < w * h; i++) {
		if (m[i] < 0.5f) continue;
		int obj = (int)lroundf(o[i] * 255.0f);
		double c = gpu_chan(img, (int)(i % w), (int)(i / w), 0), d = c - t[i];
		int k = obj == 0 ? 0 : 1;
		se[k] += d * d;
		if (k) s->model_px++;
		else s->ground_px++;
	}
	s->ground_rmse = s->ground_px ? sqrt(se[0] / (double)s->ground_px) : 1;
	s->model_rmse = s->model_px ? sqrt(se[1] / (double)s->model_px) : 1;
	free(t);
	free(m);
	free(o);
	return ok;
}

static void render_truth_scene(const char *name, struct rnd_image *img, bool per_fragment)
{
	char path[160];
	snprintf(path, sizeof path, TRUTH_ENV "%s.json", name);
	size_t len;
	char *doc = (char *)test_read_file(path, &len);
	REQUIRE(doc, "%s is missing", path);
	/* the stored scene with the environment's debug view, one sample a pixel */
	char *brace = strrchr(doc, '}');
	REQUIRE(brace, "%s", path);
	*brace = 0;
	char *full;
	REQUIRE(asprintf(&full, "%s,\"output\":{\"debug\":\"environment_shadow\",\"msaa\":1}}", doc) > 0);
	free(doc);
	if (per_fragment) setenv("UMBRA_ENV_PASS", "0", 1);
	gpu_asset_root = TRUTH_ENV;
	gpu_render(img, "%s", full);
	gpu_asset_root = NULL;
	unsetenv("UMBRA_ENV_PASS");
	free(full);
}

/* The target: the ground's share of the sky under and around a model within 0.05 RMSE
 * of Cycles; models looser (their facets' own shading differs from ours). The environment pass
 * (half resolution, bilateral) against the lookups made per fragment: close. */
TEST(env_shadows_match_cycles)
{
	static const char *const scenes[2] = {"cup_white", "shapes_sky"};
	for (int k = 0; k < 2; k++) {
		struct rnd_image img, direct;
		render_truth_scene(scenes[k], &img, false);
		render_truth_scene(scenes[k], &direct, true);
		struct env_score s, sd;
		if (img.pixels && direct.pixels && score_env(scenes[k], &img, &s) && score_env(scenes[k], &direct, &sd)) {
			printf("  %s vs Cycles: ground rmse %.4f (%ld px), model %.4f (%ld px); per fragment: ground %.4f, model %.4f; "
			       "%u directions\n", scenes[k], s.ground_rmse, s.ground_px, s.model_rmse, s.model_px, sd.ground_rmse,
			       sd.model_rmse, gpu_last_timings.env_directions);
			CHECK(s.ground_rmse <= 0.05, "%s: ground rmse %.4f over 0.05", scenes[k], s.ground_rmse);
			CHECK(s.model_rmse <= 0.12, "%s: model rmse %.4f", scenes[k], s.model_rmse);
			CHECK(sd.ground_rmse <= 0.05, "%s per fragment: ground rmse %.4f", scenes[k], sd.ground_rmse);
		} else {
			CHECK(0, "%s: references missing or render failed", scenes[k]);
		}
		rnd_image_release(&img);
		rnd_image_release(&direct);
	}
}

/* A cup under a white sky: its inside is darker than its rim (the sky it sees is a disc). */
TEST(env_cup_inside_darker_than_its_rim)
{
	struct rnd_image img;
	render_truth_scene("cup_white", &img, false);
	if (!img.pixels) return;
	/* the cup's opening: pixels whose reference object is the cup and whose visibility is under
	 * 0.55 in Cycles (the inside) against those over 0.75 (rim, outer wall facing the sky) */
	uint32_t w = img.width, h = img.height;
	float *t = gpu_read_grey(TRUTH_ENV "cup_white.vis.png", w, h), *o = gpu_read_grey(TRUTH_ENV "cup_white.obj.png", w, h);
	double in = 0, out = 0;
	long nin = 0, nout = 0;
	for (uint32_t i = 0; t && o && i < w * h; i++) {
		if (lroundf(o[i] * 255.0f) != 1) continue;
		double c = gpu_chan(&img, (int)(i % w), (int)(i / w), 0);
		if (t[i] < 0.55f) { in += c; nin++; }
		if (t[i] > 0.75f) { out += c; nout++; }
	}
	CHECK(nin > 20 && nout > 20, "cup pixels: %ld inside, %ld outside", nin, nout);
	if (nin && nout) {
		printf("  cup: inside %.3f (%ld px), rim and sky-facing wall %.3f (%ld px)\n", in / nin, nin, out / nout, nout);
		CHECK(in / nin < out / nout - 0.2, "inside %.3f is not darker than the rim %.3f", in / nin, out / nout);
	}
	free(t);
	free(o);
	rnd_image_release(&img);
}
