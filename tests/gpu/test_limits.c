/* tests/gpu — limits that tell the truth (issue 10): the shadow atlas plans every request's
 * tile sizes from the request alone, so a cached map never crowds out the request's other
 * lights and the same request gives the same bytes whatever the cache or other renders hold
 * (renders that do not fit next to each other wait); moment maps stay within the device's
 * storage-buffer range; a render whose single allocation is over the device's limit is refused
 * up front with the member at fault (rnd_error.at), before anything is allocated. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "estimate.h"
#include "gpu_util.h"
#include "test.h"

/* A context of our own (validation as the binary's). */
static struct rnd_context *limits_ctx(uint32_t atlas_size, uint32_t slots)
{
	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {0};
	cd.validation = v && strcmp(v, "1") == 0;
	cd.atlas_size = atlas_size;
	cd.slots = slots;
	struct rnd_context *ctx = NULL;
	struct rnd_error err = {0};
	CHECK(rnd_context_create(&cd, &ctx, &err) == RND_OK, "rnd_context_create: %s", err.msg);
	return ctx;
}

/* Parses doc (single quotes allowed) and renders it on ctx; the result, not a test failure, so
 * errors can be checked. *img is released by the caller (zeroed on failure). */
static enum rnd_result render_doc(struct rnd_context *ctx, const char *doc_in, struct rnd_image *img,
                                  struct rnd_error *err)
{
	memset(img, 0, sizeof *img);
	memset(err, 0, sizeof *err);
	char *doc = strdup(doc_in);
	if (!doc) return RND_ERR_OOM;
	for (char *p = doc; *p; p++) if (*p == '\'') *p = '"';
	struct api_limits lim;
	api_limits_defaults(&lim);
	struct api_scene *s = NULL;
	struct api_problem prob = {0};
	enum rnd_result r = RND_ERR_INVALID;
	if (api_scene_parse(doc, strlen(doc), &lim, &s, &prob) == API_OK) {
		r = rnd_render(ctx, &s->scene, img, NULL, err);
		api_scene_free(s);
	} else {
		snprintf(err->msg, sizeof err->msg, "parse: %d %.60s: %.160s", prob.status, prob.pointer, prob.detail);
	}
	free(doc);
	return r;
}

static bool same_pixels(const struct rnd_image *a, const struct rnd_image *b)
{
	return a->pixels && b->pixels && a->width == b->width && a->height == b->height && a->format == b->format &&
	       !memcmp(a->pixels, b->pixels, (size_t)a->width * a->height * 4);
}

#define SPOT(x, z, res) "{'type':'spot','position':[" #x ",5," #z "],'direction':[0,-1,0],'outer_angle':50," \
                        "'shadow':{'resolution':" #res "}}"
#define SCENE(lights) "{'width':96,'height':96,'camera':{'position':[5,6,7],'target':[0,0,0]}," \
	"'objects':[{'shape':'plane','size':[12,12]},{'shape':'box','transform':{'translation':[0,0.5,0]}}]," \
	"'lights':[" lights "]}"

/* A map cached at the whole atlas used to leave no room for the request's second light (422
 * "atlas full"); now both are planned together and drawn at half size, to the same bytes as
 * on a fresh context. */
TEST(limits_atlas_cached_map_never_refuses_the_others)
{
	struct rnd_context *warm = limits_ctx(1024, 1), *fresh = limits_ctx(1024, 1);
	if (!warm || !fresh) goto out;
	struct rnd_image one, two, two_fresh;
	struct rnd_error err;
	CHECK(render_doc(warm, SCENE(SPOT(-2, 0, 1024)), &one, &err) == RND_OK, "%s", err.msg);
	enum rnd_result r = render_doc(warm, SCENE(SPOT(-2, 0, 1024) "," SPOT(2, 0, 1024)), &two, &err);
	CHECK(r == RND_OK, "two lights after one filled the atlas: %s (%s)", rnd_result_str(r), err.msg);
	CHECK(render_doc(fresh, SCENE(SPOT(-2, 0, 1024) "," SPOT(2, 0, 1024)), &two_fresh, &err) == RND_OK, "%s", err.msg);
	CHECK(same_pixels(&two, &two_fresh), "the two-light render differs after the cache held a larger map");
	struct rnd_stats st;
	rnd_context_stats(warm, &st);
	CHECK(st.atlas_occupancy <= 1.0, "occupancy %.3f", st.atlas_occupancy);
	rnd_image_release(&one);
	rnd_image_release(&two);
	rnd_image_release(&two_fresh);
	CHECK(rnd_context_validation_messages(warm) == 0 && rnd_context_validation_messages(fresh) == 0);
out:
	rnd_context_destroy(warm);
	rnd_context_destroy(fresh);
}

/* Lights that cannot fit even at 64² tiles: 422-class with the lights named, before any work. */
TEST(limits_atlas_too_small_names_the_lights)
{
	struct rnd_context *ctx = limits_ctx(128, 1);
	if (!ctx) return;
	struct rnd_image img;
	struct rnd_error err;
	/* five spots of at least 64² do not fit in 128² (four do) */
	enum rnd_result r = render_doc(ctx, SCENE(SPOT(-2, -2, 64) "," SPOT(2, -2, 64) "," SPOT(-2, 2, 64) ","
	                                          SPOT(2, 2, 64) "," SPOT(0, 0, 64)), &img, &err);
	CHECK(r == RND_ERR_LIMIT && err.at == RND_AT_LIGHTS, "%s at %d: %s", rnd_result_str(r), (int)err.at, err.msg);
	rnd_image_release(&img);
	r = render_doc(ctx, SCENE(SPOT(-2, -2, 64) "," SPOT(2, -2, 64) "," SPOT(-2, 2, 64) "," SPOT(2, 2, 64)), &img, &err);
	CHECK(r == RND_OK, "four 64² spots in a 128² atlas: %s", err.msg);
	rnd_image_release(&img);
	rnd_context_destroy(ctx);
}

struct job {
	struct rnd_context *ctx;
	const char *doc;
	struct rnd_image img;
	enum rnd_result r;
	struct rnd_error err;
};

static void *job_main(void *arg)
{
	struct job *j = arg;
	j->r = render_doc(j->ctx, j->doc, &j->img, &j->err);
	return NULL;
}

/* Two renders that each need the whole atlas, at once: the second waits for the first instead
 * of drawing smaller maps (which would change its bytes) or failing. */
TEST(limits_atlas_concurrent_renders_wait_for_room)
{
	struct rnd_context *ctx = limits_ctx(1024, 2);
	if (!ctx) return;
	const char *a = SCENE(SPOT(-2, 0, 1024)), *b = SCENE(SPOT(2, 1, 1024)), *filler = SCENE(SPOT(0, 3, 1024));
	struct rnd_image ref_a, ref_b, fill;
	struct rnd_error err;
	CHECK(render_doc(ctx, a, &ref_a, &err) == RND_OK, "%s", err.msg);
	CHECK(render_doc(ctx, b, &ref_b, &err) == RND_OK, "%s", err.msg);
	int same = 0;
	for (int round = 0; round < 3; round++) {
		/* the filler's map evicts both, so both renders below draw their maps at once */
		CHECK(render_doc(ctx, filler, &fill, &err) == RND_OK, "%s", err.msg);
		rnd_image_release(&fill);
		struct job ja = {ctx, a}, jb = {ctx, b};
		pthread_t ta, tb;
		pthread_create(&ta, NULL, job_main, &ja);
		pthread_create(&tb, NULL, job_main, &jb);
		pthread_join(ta, NULL);
		pthread_join(tb, NULL);
		CHECK(ja.r == RND_OK && jb.r == RND_OK, "round %d: %s / %s", round, ja.err.msg, jb.err.msg);
		same += same_pixels(&ja.img, &ref_a) && same_pixels(&jb.img, &ref_b);
		rnd_image_release(&ja.img);
		rnd_image_release(&jb.img);
	}
	printf("    [atlas 1024, two whole-atlas renders at once] %d of 3 rounds byte-identical to the renders alone\n", same);
	CHECK(same == 3, "only %d of 3 concurrent rounds match the renders made alone", same);
	struct rnd_stats st;
	rnd_context_stats(ctx, &st);
	CHECK(st.atlas_occupancy <= 1.0);
	rnd_image_release(&ref_a);
	rnd_image_release(&ref_b);
	CHECK(rnd_context_validation_messages(ctx) == 0);
	rnd_context_destroy(ctx);
}

/* An 8192 VSM map would bind a 256 MiB storage buffer for its blur (over lavapipe's 128 MiB
 * range: a validation error); moment maps are capped to what the device can read. */
TEST(limits_vsm_8192_within_storage_range)
{
	struct rnd_context *ctx = limits_ctx(8192, 1);
	if (!ctx) return;
	struct rnd_image img;
	struct rnd_error err;
	enum rnd_result r = render_doc(ctx, "{'width':64,'height':64,'camera':{'position':[5,6,7],'target':[0,0,0]},"
	                               "'objects':[{'shape':'plane','size':[12,12]},{'shape':'box'}],"
	                               "'lights':[{'type':'spot','position':[0,5,0],'direction':[0,-1,0],"
	                               "'shadow':{'filter':'vsm','resolution':8192}}]}", &img, &err);
	CHECK(r == RND_OK, "%s", err.msg);
	CHECK(rnd_context_validation_messages(ctx) == 0, "%u validation messages", rnd_context_validation_messages(ctx));
	rnd_image_release(&img);
	rnd_context_destroy(ctx);
}

/* A render whose readback buffer is over the device's largest allocation is refused before it
 * allocates anything, naming the AOVs; the estimate says the same thing rnd_render does. */
TEST(limits_allocation_over_device_limit_names_aovs)
{
	struct rnd_context *ctx = gpu_ctx();
	if (!ctx) return;
	struct rnd_info info;
	rnd_context_info(ctx, &info);
	/* 33 shadow planes + depth, normal, albedo = 40 planes: 3 AOV passes of 4 RGBA32F targets */
	char doc[8192];
	int n = snprintf(doc, sizeof doc, "{'width':4096,'height':4096,'camera':{'position':[5,6,7],'target':[0,0,0]},"
	                 "'objects':[{'shape':'plane','size':[12,12]}],'output':{'format':'exr',"
	                 "'aovs':['shadow','depth','normal','albedo']},'lights':[");
	for (int i = 0; i < 33; i++)
		n += snprintf(doc + n, sizeof doc - (size_t)n, "%s{'type':'point','position':[%d,3,%d],'shadow':{'enabled':false}}",
		              i ? "," : "", i % 6 - 3, i / 6 - 3);
	snprintf(doc + n, sizeof doc - (size_t)n, "]}");
	for (char *p = doc; *p; p++) if (*p == '\'') *p = '"';
	struct api_limits lim;
	api_limits_defaults(&lim);
	struct api_scene *s = NULL;
	struct api_problem prob = {0};
	REQUIRE(api_scene_parse(doc, strlen(doc), &lim, &s, &prob) == API_OK, "%s %s", prob.pointer, prob.detail);
	struct rnd_estimate est;
	struct rnd_error err = {0};
	rnd_estimate_scene(&s->scene, 4096, &est);
	struct rnd_plan *plan = NULL;
	enum rnd_result re = rnd_plan_create(ctx, &s->scene, &plan, &err);
	rnd_plan_destroy(plan);
	printf("    [4096², 40 AOV planes] readback %.2f GB, largest allocation %.2f GB, device allows %.2f GB; "
	       "estimate %.2f GB device + %.2f GB host\n", est.readback_bytes / 1e9, est.largest_allocation / 1e9,
	       info.max_allocation / 1e9, est.device_bytes / 1e9, est.host_bytes / 1e9);
	/* readback: 16 B colour + 3 passes x 4 x 16 B per pixel */
	CHECK(est.readback_bytes == 4096ull * 4096 * (16 + 3 * 4 * 16), "readback %llu", (unsigned long long)est.readback_bytes);
	if (est.largest_allocation > info.max_allocation) {
		CHECK(re == RND_ERR_LIMIT && err.at == RND_AT_AOVS, "plan: %s at %d", rnd_result_str(re), (int)err.at);
		struct rnd_image img = {0};
		memset(&err, 0, sizeof err);
		enum rnd_result r = rnd_render(ctx, &s->scene, &img, NULL, &err);
		CHECK(r == RND_ERR_LIMIT && err.at == RND_AT_AOVS, "render: %s at %d: %s", rnd_result_str(r), (int)err.at, err.msg);
		struct api_problem p = {0};
		api_problem_from_render(&p, s, &err, 422);
		CHECK(p.status == 422 && !strcmp(p.pointer, "/output/aovs"), "%d %s", p.status, p.pointer);
		rnd_image_release(&img);
	} else {
		printf("    note: this device allows the allocation; nothing to refuse\n");
		CHECK(re == RND_OK, "%s", err.msg);
	}
	api_scene_free(s);
}

/* EXR shadow AOVs of PCSS lights: the AOV pass evaluates every light's filter; written out once
 * per light it made lavapipe's JIT take minutes (a request that held its worker). The AOV is the
 * debug view's visibility (contract §4): both agree within 1/255 on nearly every pixel. */
TEST(limits_aov_of_pcss_lights_matches_debug_view)
{
	static const char *const scene =
		"{'width':64,'height':64,'camera':{'position':[5,6,7],'target':[0,0,0]},"
		"'objects':[{'shape':'plane','size':[12,12]},{'shape':'box','transform':{'translation':[0,0.5,0]}}],"
		"'lights':[{'type':'spot','position':[1,5,0],'direction':[0,-1,0],'radius':0.3,'shadow':{'filter':'pcss'}},"
		"{'type':'point','position':[-1,4,1],'radius':0.2,'shadow':{'filter':'pcss'}}],"
		"'output':{'msaa':1,%s}}";
	char doc[1024];
	struct rnd_image aov, dbg;
	struct rnd_error err;
	struct rnd_context *ctx = gpu_ctx();
	if (!ctx) return;
	snprintf(doc, sizeof doc, scene, "'format':'exr','aovs':['shadow']");
	REQUIRE(render_doc(ctx, doc, &aov, &err) == RND_OK, "%s", err.msg);
	snprintf(doc, sizeof doc, scene, "'debug':'shadow','debug_light':1");
	enum rnd_result r = render_doc(ctx, doc, &dbg, &err);
	CHECK(r == RND_OK, "%s", err.msg);
	const float *s1 = NULL;
	for (uint32_t i = 0; i < aov.aov_count; i++)
		if (!strcmp(aov.aov_names[i], "shadow.1")) s1 = aov.aov[i];
	CHECK(s1, "no shadow.1 plane");
	if (s1 && r == RND_OK) {
		int agree = 0, n = 64 * 64;
		for (int j = 0; j < 64; j++)
			for (int i = 0; i < 64; i++) {
				int a = (int)lrintf(s1[j * 64 + i] * 255.0f), d = gpu_px8(&dbg, i, j)[0];
				agree += abs(a - d) <= 1;
			}
		CHECK(agree >= 0.99 * n, "shadow.1 agrees with the debug view on %d of %d pixels", agree, n);
	}
	rnd_image_release(&aov);
	rnd_image_release(&dbg);
	CHECK(rnd_context_validation_messages(ctx) == 0);
}

/* The shadow AOVs of ten lights take two AOV passes: lights 0..7 in the first pass's last two
 * targets, 8..9 in the second pass's first target (umbra_shared.h UMBRA_AOV_*: the one packing
 * that aov.frag writes, record.c draws and readback.c splits). Each light stands elsewhere, so
 * its plane is its own: shadow.6 (first pass) and shadow.9 (second pass) each agree with their
 * light's debug view, and differ from their neighbour's. */
TEST(limits_aov_shadow_planes_of_two_passes_match_debug_views)
{
	char doc[4096], lights[2048];
	size_t n = 0;
	for (int i = 0; i < 10; i++)
		n += (size_t)snprintf(lights + n, sizeof lights - n, "%s{'type':'spot','position':[%d,5,%d],'direction':[%d,-5,%d],"
		                      "'outer_angle':60,'shadow':{'filter':'hard'}}", i ? "," : "", (i % 5) * 2 - 4,
		                      i < 5 ? -3 : 3, 4 - (i % 5) * 2, i < 5 ? 3 : -3);
	static const char *const scene =
		"{'width':48,'height':48,'camera':{'position':[0,9,6],'target':[0,0,0]},"
		"'objects':[{'shape':'plane','size':[14,14]},{'shape':'box','size':[1.5,3,1.5],"
		"'transform':{'translation':[0,1.5,0]}}],'lights':[%s],'output':{'msaa':1,%s}}";
	struct rnd_context *ctx = gpu_ctx();
	if (!ctx) return;
	struct rnd_image aov;
	struct rnd_error err;
	snprintf(doc, sizeof doc, scene, lights, "'format':'exr','aovs':['shadow']");
	REQUIRE(render_doc(ctx, doc, &aov, &err) == RND_OK, "%s", err.msg);
	CHECK(aov.aov_count == 10, "%u planes", aov.aov_count);
	const uint32_t probe[2] = {6, 9};
	for (int k = 0; k < 2; k++) {
		uint32_t li = probe[k];
		char name[16], other[16];
		snprintf(name, sizeof name, "shadow.%u", li);
		snprintf(other, sizeof other, "shadow.%u", li - 1);
		const float *plane = NULL, *prev = NULL;
		for (uint32_t i = 0; i < aov.aov_count; i++) {
			if (!strcmp(aov.aov_names[i], name)) plane = aov.aov[i];
			if (!strcmp(aov.aov_names[i], other)) prev = aov.aov[i];
		}
		CHECK(plane && prev, "no %s or %s plane", name, other);
		char opts[64];
		snprintf(opts, sizeof opts, "'debug':'shadow','debug_light':%u", li);
		snprintf(doc, sizeof doc, scene, lights, opts);
		struct rnd_image dbg;
		enum rnd_result r = render_doc(ctx, doc, &dbg, &err);
		CHECK(r == RND_OK, "%s", err.msg);
		if (plane && prev && r == RND_OK) {
			int agree = 0, differ = 0, npx = 48 * 48;
			for (int j = 0; j < 48; j++)
				for (int i = 0; i < 48; i++) {
					int a = (int)lrintf(plane[j * 48 + i] * 255.0f), d = gpu_px8(&dbg, i, j)[0];
					agree += abs(a - d) <= 1;
					differ += fabsf(plane[j * 48 + i] - prev[j * 48 + i]) > 0.5f;
				}
			CHECK(agree >= 0.99 * npx, "%s agrees with its debug view on %d of %d pixels", name, agree, npx);
			CHECK(differ >= 20, "%s and %s differ on %d pixels only: the test cannot tell lights apart", name, other,
			      differ);
		}
		if (r == RND_OK) rnd_image_release(&dbg);
	}
	rnd_image_release(&aov);
	CHECK(rnd_context_validation_messages(ctx) == 0);
}

/* 150 textured materials over two textures (VC.glb has 147 over 20): materials that bind the
 * same images share a descriptor set, and the scene is bounded by its distinct textures, not
 * by the device's per-stage descriptor count (lavapipe's 128 refused this with "more than 126
 * textured materials"). Each material's own factor still tints its object. */
TEST(limits_many_materials_over_few_textures)
{
	static const uint8_t red[4] = {255, 0, 0, 255}, green[4] = {0, 255, 0, 255};
	struct rnd_texture tex[2] = {{.rgba = red, .width = 1, .height = 1}, {.rgba = green, .width = 1, .height = 1}};
	enum { N = 150, COLS = 15 };
	char *doc = malloc(64 * 1024);
	REQUIRE(doc);
	int n = snprintf(doc, 64 * 1024, "{\"width\":150,\"height\":100,\"camera\":{\"type\":\"orthographic\","
	                 "\"position\":[0,0,10],\"target\":[0,0,0],\"height\":10},\"materials\":{");
	for (int i = 0; i < N; i++) n += snprintf(doc + n, 64 * 1024 - n, "%s\"m%d\":{}", i ? "," : "", i);
	n += snprintf(doc + n, 64 * 1024 - n, "},\"objects\":[");
	for (int i = 0; i < N; i++)
		n += snprintf(doc + n, 64 * 1024 - n,
		              "%s{\"shape\":\"box\",\"size\":[0.8,0.8,0.8],\"material\":\"m%d\",\"transform\":{"
		              "\"translation\":[%g,%g,0]}}",
		              i ? "," : "", i, (i % COLS) - 7.0, 4.5 - (i / COLS));
	snprintf(doc + n, 64 * 1024 - n, "],\"lights\":[{\"type\":\"directional\",\"direction\":[0,0,-1]}],"
	         "\"environment\":{\"ambient\":{\"sky\":[1,1,1],\"ground\":[1,1,1],\"intensity\":0.3}}}");
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	struct api_scene *s = NULL;
	struct api_problem p;
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s", p.detail);
	free(doc);
	struct rnd_material *m = (struct rnd_material *)s->scene.materials;
	for (uint32_t o = 0; o < N; o++) {
		struct rnd_material *mo = &m[s->scene.objects[o].material];
		mo->base_color_texture = &tex[o % 2];
		/* Every third material at half its factor: same set, another tint. */
		if (o % 3 == 2) mo->base_color[0] = mo->base_color[1] = mo->base_color[2] = 0.5f;
	}
	struct rnd_image img = {0};
	struct rnd_error err = {0};
	enum rnd_result r = rnd_render(ctx, &s->scene, &img, NULL, &err);
	CHECK(r == RND_OK, "%s", err.msg);
	if (r == RND_OK) {
		/* The centre of object o's cell: 10 px a cell, 150 x 100 px for 15 x 10 cells. */
		for (int o = 0; o < N; o += 7) {
			const uint8_t *px = gpu_px8(&img, (o % COLS) * 10 + 5, (o / COLS) * 10 + 5);
			int lit = o % 2 ? px[1] : px[0], other = o % 2 ? px[0] : px[1];
			CHECK(lit > other + 80, "object %d: (%d,%d,%d), want %s", o, px[0], px[1], px[2],
			      o % 2 ? "green" : "red");
			if (o % 3 == 2) {
				int o2 = o - 2; /* same texture (o2 % 2 == o % 2), full factor */
				const uint8_t *q = gpu_px8(&img, (o2 % COLS) * 10 + 5, (o2 / COLS) * 10 + 5);
				int full = o % 2 ? q[1] : q[0];
				CHECK(lit + 10 < full, "object %d at half its factor (%d) not darker than %d (%d)", o, lit, o2, full);
			}
		}
		rnd_image_release(&img);
	}
	api_scene_free(s);
	CHECK(rnd_context_validation_messages(ctx) == 0);
}

/* Textures per scene come from the context (desc.max_textures, capped at the ceiling), not a
 * constant: three textured objects render under a limit of 3 and are refused under 2, the
 * error naming the object that brought the third (rnd_error.at / at_index). */
TEST(limits_textures_from_the_context_name_the_object)
{
	static const uint8_t px[3][4] = {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}};
	struct rnd_texture tex[3];
	for (int i = 0; i < 3; i++) tex[i] = (struct rnd_texture){.rgba = px[i], .width = 1, .height = 1};
	const char *doc = "{\"width\":32,\"height\":32,\"camera\":{\"position\":[0,0,8]},"
	                  "\"materials\":{\"a\":{},\"b\":{},\"c\":{}},\"objects\":["
	                  "{\"shape\":\"sphere\",\"material\":\"a\",\"transform\":{\"translation\":[-2,0,0]}},"
	                  "{\"shape\":\"sphere\",\"material\":\"b\"},"
	                  "{\"shape\":\"sphere\",\"material\":\"c\",\"transform\":{\"translation\":[2,0,0]}}],"
	                  "\"lights\":[{\"type\":\"directional\",\"direction\":[0,-1,-1]}]}";
	for (uint32_t max = 2; max <= 3; max++) {
		const char *v = getenv("UMBRA_VALIDATION");
		struct rnd_context_desc cd = {.validation = v && !strcmp(v, "1"), .max_textures = max};
		struct rnd_context *ctx = NULL;
		struct rnd_error err = {0};
		REQUIRE(rnd_context_create(&cd, &ctx, &err) == RND_OK, "%s", err.msg);
		struct rnd_info info;
		rnd_context_info(ctx, &info);
		CHECK(info.max_textures == max && info.device_max_textures >= max, "%u of %u", info.max_textures,
		      info.device_max_textures);
		struct api_scene *s = NULL;
		struct api_problem p;
		REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s", p.detail);
		struct rnd_material *m = (struct rnd_material *)s->scene.materials;
		for (uint32_t o = 0; o < 3; o++) m[s->scene.objects[o].material].base_color_texture = &tex[o];
		struct rnd_image img = {0};
		enum rnd_result r = rnd_render(ctx, &s->scene, &img, NULL, &err);
		if (max == 3) CHECK(r == RND_OK, "%s", err.msg);
		else CHECK(r == RND_ERR_LIMIT && err.at == RND_AT_OBJECT && err.at_index == 2, "%d %d %u %s", r, err.at,
		           err.at_index, err.msg);
		rnd_image_release(&img);
		api_scene_free(s);
		rnd_context_destroy(ctx);
	}
}
