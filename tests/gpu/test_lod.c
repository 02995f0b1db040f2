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

static const char *const MODEL_DOC =
	"{\"width\": 256, \"height\": 256, \"camera\": {\"fit\": \"objects\", \"direction\": [-1, -0.6, -1], \"margin\": 0.1},"
	" \"objects\": [{\"shape\": \"plane\", \"size\": [20, 20], \"transform\": {\"translation\": [0, -1, 0]}},"
	" {\"shape\": \"model\", \"path\": \"sphere.stl\"}],"
	" \"lights\": [{\"type\": \"directional\", \"direction\": [-0.5, -1, -0.3]}]}";

static struct api_scene *parse_model(const char *root)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = root;
	struct api_scene *s = NULL;
	struct api_problem p;
	if (api_scene_parse(MODEL_DOC, strlen(MODEL_DOC), &lim, &s, &p) != API_OK) {
		CHECK(0, "parse: %s %s", p.pointer, p.detail);
		return NULL;
	}
	return s;
}

/* A new model's first render already has the one level its size needs (built at import, in
 * the sandbox: api/model_lod.h). */
static bool model_has_level(const char *root)
{
	struct api_scene *s = parse_model(root);
	if (!s) return false;
	CHECK(s->scene.object_count == 2 && s->scene.objects[1].lod_count == 1 && s->scene.objects[1].closed,
	      "a new 45k-triangle model: the import's one level at its first render, closed");
	api_scene_free(s);
	return true;
}

static bool render_model(struct rnd_image *img, const char *root, bool exact)
{
	memset(img, 0, sizeof *img);
	if (!gpu_ctx()) { CHECK(0, "no context"); return false; }
	struct api_scene *s = parse_model(root);
	if (!s) return false;
	CHECK(s->scene.object_count == 2 && s->scene.objects[1].lod_count == 1 && s->scene.objects[1].closed,
	      "the 45k-triangle sphere has its level and is closed");
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
	bool ok = model_has_level(dir) && render_model(&lod, dir, false);
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

/* A sphere drawn with fewer segments than asked (thumb-256: 316 asked) is a polyhedron whose
 * facets lean up to half a facet's angle from the interpolated normal. The shadow filters
 * must take their receiver plane from the facet the shadow map holds: with the interpolated
 * normal, where the sun falls straight on, PCF compared the taps downhill on a facet with a
 * plane square to the light and left dark specks on the lit top (MSAA 4: 14 pixels, the
 * darkest 169). Every pixel of the sphere facing the sun (n.l > 0.3, away from its silhouette)
 * must read fully lit in the shadow debug view, for PCF and PCSS at MSAA 1 and 4; except, with
 * PCF at MSAA 4, a pixel or two a little darker (1, at 242; 3 at up to 213 before the lookups
 * of partly covered fragments moved to their covered samples, facet.glsl). */
/* Over the sun-facing pixels of thumb-256's sphere well inside its outline (the ray meets it at
 * more than 1/4 rad), the visibility img shows (the shadow debug view's 8 bits, or the AOV
 * plane `plane`): how many pixels (*facing), how many below `lit` (returned), the lowest. */
static int shadowed_facing(const struct rnd_image *img, const float *plane, double lit, int *facing, double *lowest)
{
	v3 sun = v3_norm(v3_make(0.5, 1, 0.3)), centre = v3_make(0, 1, 0);
	struct gpu_cam cam;
	gpu_cam_persp(&cam, v3_make(4, 3, 4), v3_make(0, 0.8, 0), v3_make(0, 1, 0), 40, 256, 256);
	int dark = 0;
	*facing = 0;
	*lowest = 1.0;
	for (int j = 0; j < 256; j++)
		for (int i = 0; i < 256; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			double t = gpu_ray_sphere(o, d, centre, 1.0, 1e-6);
			if (t < 0 || gpu_ray_sphere(o, d, centre, 0.97, 1e-6) < 0) continue;
			v3 n = v3_norm(v3_sub(v3_add(o, v3_scale(d, t)), centre));
			if (v3_dot(n, sun) <= 0.3) continue;
			(*facing)++;
			double v = plane ? plane[(size_t)j * 256 + i] : gpu_px8(img, i, j)[0] / 255.0;
			if (v < lit) dark++;
			if (v < *lowest) *lowest = v;
		}
	return dark;
}

TEST(lod_sphere_facets_cast_no_specks_on_themselves)
{
	static const char *filters[][2] = {{"pcf", ""}, {"pcss", ", 'angular_diameter': 1"}};
	static const char *fmt =
		"{'width': 256, 'height': 256, 'camera': {'type': 'perspective', 'position': [4, 3, 4],"
		" 'target': [0, 0.8, 0], 'up': [0, 1, 0], 'fov_y': 40},"
		" 'objects': [{'shape': 'plane', 'size': [10, 10]},"
		" {'shape': 'sphere', 'radius': 1, 'segments': 316, 'transform': {'translation': [0, 1, 0]}}],"
		" 'lights': [{'type': 'directional', 'direction': [-0.5, -1, -0.3]%s}],"
		" 'shadows': {'filter': '%s'}, 'output': %s}";
	for (int f = 0; f < 2; f++)
		for (int msaa = 1; msaa <= 4; msaa += 3) {
			struct rnd_image img;
			char out[64];
			snprintf(out, sizeof out, "{'debug': 'shadow', 'msaa': %d}", msaa);
			if (!gpu_render(&img, fmt, filters[f][1], filters[f][0], out)) continue;
			int facing;
			double lowest;
			int dark = shadowed_facing(&img, NULL, 250 / 255.0, &facing, &lowest);
			printf("  %s, msaa %d: %d sun-facing sphere pixels, %d darker than 250 (darkest %.0f)\n", filters[f][0], msaa,
			       facing, dark, lowest * 255);
			CHECK(facing > 3000 && dark == 0, "%s msaa %d: %d of %d sun-facing sphere pixels read shadowed (darkest %.0f)",
			      filters[f][0], msaa, dark, facing, lowest * 255);
			rnd_image_release(&img);
		}
	/* The shadow AOV looks where the beauty pass looks: a sphere's proxy raised by its mesh's
	 * lift (facet.glsl surface_at), not the true surface inside the facets. */
	for (int f = 0; f < 2; f++) {
		struct rnd_image img;
		if (!gpu_render(&img, fmt, filters[f][1], filters[f][0], "{'format': 'exr', 'aovs': ['shadow'], 'msaa': 1}"))
			continue;
		CHECK(gpu_last_timings.sphere_proxies == 1, "%s: the sphere is a proxy", filters[f][0]);
		const float *vis = NULL;
		for (uint32_t k = 0; k < img.aov_count; k++)
			if (!strcmp(img.aov_names[k], "shadow.0")) vis = img.aov[k];
		int facing = 0, dark = -1;
		double lowest = 0.0;
		if (vis) dark = shadowed_facing(&img, vis, 0.98, &facing, &lowest);
		printf("  %s, shadow AOV: %d sun-facing sphere pixels, %d below 0.98 (lowest %.3f)\n", filters[f][0], facing, dark,
		       lowest);
		CHECK(facing > 3000 && dark == 0, "%s shadow AOV: %d of %d sun-facing sphere pixels shadowed (lowest %.3f)",
		      filters[f][0], dark, facing, lowest);
		rnd_image_release(&img);
	}
}

/* Sum of absolute channel differences of two images of one size. */
static long image_distance(const struct rnd_image *a, const struct rnd_image *b)
{
	long sum = 0;
	for (uint32_t j = 0; j < a->height; j++)
		for (uint32_t i = 0; i < a->width; i++)
			for (int c = 0; c < 3; c++)
				sum += abs((int)gpu_px8(a, (int)i, (int)j)[c] - (int)gpu_px8(b, (int)i, (int)j)[c]);
	return sum;
}

/* A sun map fitted to what casts (renderer/plan.c): a sphere on a 40 m ground that casts
 * nothing gets a small tile with texels no coarser than the map around the whole scene's. The
 * same scene with a small box far out of view at the ground's corner (the casters' box is then
 * the whole scene, and the tile the default 2048) draws at least 4x the texels; against that
 * scene's map at 8192 (the finest), the casters' tile must be closer than the whole scene's
 * 2048 (PCF, PCSS; before issue 31's camera texel: the same image, as near), and change only
 * shadow edges (every filter: under 1 % of values). */
TEST(sun_map_fitted_to_the_casters_is_cheaper_and_no_coarser)
{
	static const char *doc =
		"{\"width\": 256, \"height\": 256, \"camera\": {\"type\": \"perspective\", \"position\": [4, 3, 4],"
		" \"target\": [0, 0.8, 0], \"up\": [0, 1, 0], \"fov_y\": 40},"
		" \"objects\": [{\"shape\": \"plane\", \"size\": [40, 40]},"
		" {\"shape\": \"sphere\", \"radius\": 1, \"segments\": 64, \"transform\": {\"translation\": [0, 1, 0]}},"
		" {\"shape\": \"box\", \"size\": [1, 2, 0.5], \"transform\": {\"translation\": [1.8, 1, -1.2]}}%s],"
		" \"lights\": [{\"type\": \"directional\", \"direction\": [-0.5, -1, -0.3], \"angular_diameter\": %s}],"
		" \"shadows\": {\"filter\": \"%s\", \"directional\": {\"mode\": \"fit\"}%s}}";
	static const char *far_box =
		", {\"shape\": \"box\", \"size\": [0.2, 0.2, 0.2], \"transform\": {\"translation\": [-19.8, 0.1, 19.8]}}";
	/* vsm / evsm: the ground is drawn into their maps (their moments blur with it) but sizes
	 * no map: only the casters do. */
	static const char *filters[][2] = {{"pcf", "0"}, {"pcss", "2"}, {"vsm", "0"}, {"evsm", "0"}};
	for (int f = 0; f < 4; f++) {
		struct rnd_image small, whole, fine;
		if (!gpu_render(&small, doc, "", filters[f][1], filters[f][0], "")) continue;
		double small_ms = gpu_last_timings.shadow_ms;
		uint64_t small_texels = gpu_last_timings.shadow_texels;
		if (gpu_render(&whole, doc, far_box, filters[f][1], filters[f][0], "")) {
			CHECK(small_texels * 4 <= gpu_last_timings.shadow_texels,
			      "%s: the casters' map has %llu texels, the whole scene's %llu", filters[f][0],
			      (unsigned long long)small_texels, (unsigned long long)gpu_last_timings.shadow_texels);
			long differ = 0;
			for (uint32_t j = 0; j < small.height; j++)
				for (uint32_t i = 0; i < small.width; i++)
					for (int c = 0; c < 3; c++)
						differ += abs((int)gpu_px8(&small, (int)i, (int)j)[c] - (int)gpu_px8(&whole, (int)i, (int)j)[c]) > 1;
			printf("  %s: %ld channel values differ by more than 1 step; shadow stage %.2f ms (casters' tile) vs %.2f "
			       "ms (whole scene)\n", filters[f][0], differ, small_ms, gpu_last_timings.shadow_ms);
			CHECK(differ < (long)(small.width * small.height * 3 / 100), "%s: the casters' map changed %ld channel values",
			      filters[f][0], differ);
			if (f < 2 && gpu_render(&fine, doc, far_box, filters[f][1], filters[f][0], ", \"resolution\": 8192")) {
				long ds = image_distance(&small, &fine), dw = image_distance(&whole, &fine);
				printf("  %s: distance to the whole scene at 8192: casters' tile %ld, whole scene at 2048 %ld\n",
				       filters[f][0], ds, dw);
				CHECK(ds < dw, "%s: the casters' tile is no closer to the 8192 map (%ld) than the whole scene's 2048 (%ld)",
				      filters[f][0], ds, dw);
				rnd_image_release(&fine);
			}
			rnd_image_release(&whole);
		}
		rnd_image_release(&small);
	}
}

/* Boxes standing 30 cm deep in the ground, seen from above: the ground's shadow on their buried
 * parts shows nowhere, so it stays out of the sun's map, which fits the boxes as it does boxes
 * resting on the ground (the same texels drawn; with the ground in it, the whole scene's), and
 * the picture is theirs. */
TEST(ground_under_sunk_objects_casts_nothing)
{
	static const char *doc =
		"{\"width\": 192, \"height\": 128, \"camera\": {\"type\": \"perspective\", \"position\": [5, 4, 6],"
		" \"target\": [0, 0.5, 0], \"up\": [0, 1, 0], \"fov_y\": 40},"
		" \"objects\": [{\"shape\": \"plane\", \"size\": [20, 20]},"
		" {\"shape\": \"box\", \"size\": [1, %s, 1], \"transform\": {\"translation\": [0, %s, 0]}},"
		" {\"shape\": \"box\", \"size\": [0.6, %s, 0.6], \"transform\": {\"translation\": [1.5, %s, -1]}}],"
		" \"lights\": [{\"type\": \"directional\", \"direction\": [-0.5, -1, -0.3], \"angular_diameter\": 1}],"
		" \"shadows\": {\"directional\": {\"mode\": \"fit\"}}}";
	struct rnd_image resting, sunk;
	if (!gpu_render(&resting, doc, "1", "0.5", "2", "1")) return;
	uint64_t resting_texels = gpu_last_timings.shadow_texels;
	if (gpu_render(&sunk, doc, "1.3", "0.35", "2.3", "0.85")) {
		CHECK(gpu_last_timings.shadow_texels == resting_texels, "sunk: %llu shadow texels, resting: %llu",
		      (unsigned long long)gpu_last_timings.shadow_texels, (unsigned long long)resting_texels);
		/* The lines where the boxes meet the ground differ: a face cut by the depth test there
		 * versus a face ending there (8 pixels, as many with the ground in the map). */
		long differ = 0;
		for (uint32_t j = 0; j < sunk.height; j++)
			for (uint32_t i = 0; i < sunk.width; i++)
				for (int c = 0; c < 3; c++)
					if (abs((int)gpu_px8(&sunk, (int)i, (int)j)[c] - (int)gpu_px8(&resting, (int)i, (int)j)[c]) > 2) {
						differ++;
						break;
					}
		CHECK(differ * 1000 <= (long)sunk.width * sunk.height, "%ld pixels of sunk boxes differ from resting ones", differ);
		rnd_image_release(&sunk);
	}
	rnd_image_release(&resting);
}

/* Whether a ray through some point within `reach` pixels of pixel (i, j)'s centre grazes past
 * the sphere while another meets it: the pixel lies on the sphere's outline. */
static bool near_outline(const struct gpu_cam *cam, int i, int j, v3 c, double r, double reach)
{
	int hits = 0;
	for (int k = 0; k < 9; k++) {
		v3 o, d;
		gpu_cam_ray(cam, i + 0.5 + reach * (k % 3 - 1), j + 0.5 + reach * (k / 3 - 1), &o, &d);
		hits += gpu_ray_sphere(o, d, c, r, 1e-6) >= 0;
	}
	return hits != 0 && hits != 9;
}

/* A sphere's proxy (renderer/proxy.h): the camera draws a cap of a few hundred triangles and
 * shades the true sphere under it. Against the tessellated sphere (the level of detail's,
 * within 1/32 pixel), a glossy sphere under a soft sun and a soft spot (MSAA 4): pixels off its outline
 * differ by at most a few levels (the true surface against chords within 1/32 pixel: a
 * highlight moves a little), only outline pixels by more (which samples a 1/32-pixel outline
 * covers), and few of those. */
/* proxy vs mesh of the sphere (centre c, radius r) in the scene doc seen by cam: returns the
 * largest difference off the outline, and counts outline pixels and those changed by > 8. */
static int compare_proxy(const char *doc, const struct gpu_cam *cam, v3 c, double r, int *on_count, int *on_changed,
                         int *sphere_px)
{
	struct rnd_image proxy, full;
	*on_count = *on_changed = *sphere_px = 0;
	if (!gpu_render(&proxy, doc, 0)) return 255;
	CHECK(gpu_last_timings.sphere_proxies == 1, "the sphere is drawn as a proxy (%u)", gpu_last_timings.sphere_proxies);
	uint64_t proxy_tris = gpu_last_timings.camera_triangles;
	setenv("UMBRA_SPHERE_PROXY", "0", 1);
	bool ok = gpu_render(&full, doc, 0);
	unsetenv("UMBRA_SPHERE_PROXY");
	if (!ok) { rnd_image_release(&proxy); return 255; }
	CHECK(gpu_last_timings.sphere_proxies == 0, "UMBRA_SPHERE_PROXY=0: no proxy (%u)", gpu_last_timings.sphere_proxies);
	/* What the camera's passes drew: the proxy (a few hundred triangles), not the mesh. */
	CHECK(proxy_tris < 2000 && proxy_tris * 4 < gpu_last_timings.camera_triangles,
	      "the camera drew %llu triangles with the proxy, %llu with the mesh", (unsigned long long)proxy_tris,
	      (unsigned long long)gpu_last_timings.camera_triangles);
	int off_worst = 0;
	for (int j = 0; j < (int)proxy.height; j++)
		for (int i = 0; i < (int)proxy.width; i++) {
			int d = 0;
			for (int k = 0; k < 3; k++) {
				int e = abs((int)gpu_px8(&proxy, i, j)[k] - (int)gpu_px8(&full, i, j)[k]);
				if (e > d) d = e;
			}
			if (near_outline(cam, i, j, c, r, 1.0)) {
				(*on_count)++;
				if (d > 8) (*on_changed)++;
			} else {
				v3 o, dir;
				gpu_cam_ray(cam, i + 0.5, j + 0.5, &o, &dir);
				*sphere_px += gpu_ray_sphere(o, dir, c, r, 1e-6) >= 0;
				if (d > off_worst) off_worst = d;
			}
		}
	rnd_image_release(&proxy);
	rnd_image_release(&full);
	return off_worst;
}

TEST(sphere_proxy_shades_the_true_sphere)
{
	/* %s: the camera; %d: MSAA samples */
	static const char *fmt =
		"{'width': 256, 'height': 256, 'camera': %s,"
		" 'materials': {'glossy': {'base_color': [0.8, 0.25, 0.2], 'roughness': 0.25}},"
		" 'objects': [{'shape': 'plane', 'size': [10, 10]},"
		" {'shape': 'sphere', 'radius': 1, 'segments': 316, 'material': 'glossy', 'transform': {'translation': [0, 1, 0]}}],"
		" 'lights': [{'type': 'directional', 'direction': [-0.5, -1, -0.3], 'angular_diameter': 2},"
		" {'type': 'spot', 'position': [1.5, 3.5, -1], 'direction': [-1.5, -3.5, 1], 'intensity': 30, 'radius': 0.1,"
		" 'outer_angle': 40}], 'output': {'msaa': %d}}";
	static const char *persp = "{'type': 'perspective', 'position': [3.2, 2.2, 3.0], 'target': [0, 0.9, 0], 'fov_y': 40}";
	static const char *ortho = "{'type': 'orthographic', 'position': [3.2, 2.2, 3.0], 'target': [0, 0.9, 0], 'height': 3}";
	/* two soft lights: the visibility pass computes the shadows (surface.frag's sphere), or
	 * with it off the main pass does (mesh_main.glsl's); and an orthographic camera at MSAA 1 */
	static const struct { bool ortho; int msaa; const char *vis; } runs[] = {{false, 4, NULL}, {false, 4, "0"}, {true, 1, NULL}};
	for (int k = 0; k < 3; k++) {
		char doc[2048];
		snprintf(doc, sizeof doc, fmt, runs[k].ortho ? ortho : persp, runs[k].msaa);
		struct gpu_cam cam;
		if (runs[k].ortho)
			gpu_cam_ortho(&cam, v3_make(3.2, 2.2, 3.0), v3_make(0, 0.9, 0), v3_make(0, 1, 0), 3, 256, 256);
		else
			gpu_cam_persp(&cam, v3_make(3.2, 2.2, 3.0), v3_make(0, 0.9, 0), v3_make(0, 1, 0), 40, 256, 256);
		if (runs[k].vis) setenv("UMBRA_VISIBILITY", runs[k].vis, 1);
		int on_count, on_changed, sphere_px;
		int off_worst = compare_proxy(doc, &cam, v3_make(0, 1, 0), 1.0, &on_count, &on_changed, &sphere_px);
		unsetenv("UMBRA_VISIBILITY");
		if (!runs[k].ortho)
			CHECK(gpu_last_timings.visibility_views == (runs[k].vis ? 0u : 1u), "run %d: visibility pass %u", k,
			      gpu_last_timings.visibility_views);
		printf("  %s msaa %d%s, proxy vs mesh: %d sphere pixels off the outline, all pixels off it within %d; %d outline"
		       " pixels, %d by > 8\n", runs[k].ortho ? "orthographic" : "perspective", runs[k].msaa,
		       runs[k].vis ? ", no visibility pass" : "", sphere_px, off_worst, on_count, on_changed);
		CHECK(sphere_px > 8000, "run %d: the sphere covers %d pixels", k, sphere_px);
		CHECK(off_worst <= 3, "run %d: off the outline a pixel differs by %d", k, off_worst);
		CHECK(on_changed * 10 <= on_count, "run %d: %d of %d outline pixels differ by more than 8", k, on_changed, on_count);
	}
}

/* The thumbnail preset frames the objects (`fit`): the proxy is planned with the camera placed
 * from the shapes as asked, the render places it from the tessellated ones and keeps the proxy
 * only where the two agree (rnd_proxy_fits). They do for a sphere, whose mesh straddles it. */
TEST(sphere_proxy_under_the_thumbnail_presets_fitted_camera)
{
	static const char *doc = "{'preset': 'thumbnail', 'width': 256, 'height': 256,"
	                         " 'objects': [{'shape': 'sphere', 'segments': 256}]}";
	struct rnd_image proxy, full;
	if (!gpu_render(&proxy, doc, 0)) return;
	CHECK(gpu_last_timings.sphere_proxies == 1, "the fitted camera keeps the proxy (%u)", gpu_last_timings.sphere_proxies);
	setenv("UMBRA_SPHERE_PROXY", "0", 1);
	bool ok = gpu_render(&full, doc, 0);
	unsetenv("UMBRA_SPHERE_PROXY");
	if (!ok) { rnd_image_release(&proxy); return; }
	/* The sphere's outline is ~400 pixels long: left where lod.c's estimated camera put it
	 * (0.02 pixel off here) it would stay within the bound, but a proxy placed for a camera
	 * 1 cm away moves it by a quarter of a pixel, a band of changed pixels all along it; and
	 * shading the wrong sphere changes the whole disc. */
	int worst = 0, changed = 0, grey = 0;
	for (int j = 0; j < 256; j++)
		for (int i = 0; i < 256; i++) {
			int d = 0;
			for (int k = 0; k < 3; k++) {
				int e = abs((int)gpu_px8(&proxy, i, j)[k] - (int)gpu_px8(&full, i, j)[k]);
				if (e > d) d = e;
			}
			if (d > worst) worst = d;
			if (d > 3) changed++;
			grey += gpu_px8(&proxy, i, j)[0] < 250;
		}
	printf("  thumbnail preset, proxy vs mesh: %d pixels not white, %d differ by > 3 (largest %d)\n", grey, changed, worst);
	CHECK(grey > 10000, "the sphere's shaded side and its shadow cover %d pixels", grey);
	CHECK(changed <= 120, "%d pixels differ by more than 3 steps", changed);
	rnd_image_release(&proxy);
	rnd_image_release(&full);
}
