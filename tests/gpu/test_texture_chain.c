/* A texture's precomputed mip chain (rnd_texture.chain, built once by a cached model's owner) is
 * what the render samples, and gives the same bytes as the chain built at upload; a chain built
 * for the other colour space is not used. The texture is minified (256^2 texels on ~40 pixels),
 * so the render reads the chain's small levels, not level 0. */
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"

#define TW 256

static bool render_with(struct api_scene *s, const struct rnd_texture *t, struct rnd_image *img)
{
	struct rnd_material *m = (struct rnd_material *)s->scene.materials;
	m[s->scene.objects[0].material].base_color_texture = t;
	struct rnd_error err = {0};
	memset(img, 0, sizeof *img);
	enum rnd_result r = rnd_render(gpu_ctx(), &s->scene, img, NULL, &err);
	CHECK(r == RND_OK, "%s", err.msg);
	return r == RND_OK;
}

static double mean_abs_diff(const struct rnd_image *a, const struct rnd_image *b)
{
	double d = 0;
	for (uint32_t j = 0; j < a->height; j++)
		for (uint32_t i = 0; i < a->width; i++)
			for (int c = 0; c < 3; c++) d += abs((int)gpu_px8(a, (int)i, (int)j)[c] - (int)gpu_px8(b, (int)i, (int)j)[c]);
	return d / (a->width * a->height * 3.0);
}

TEST(texture_precomputed_chain_is_sampled)
{
	/* Red and blue stripes one texel wide: their average (the small levels) is purple. */
	uint8_t *rgba = malloc(TW * TW * 4), *white = malloc(TW * TW * 4);
	uint64_t n = rnd_texture_chain_bytes(TW, TW);
	uint8_t *chain = malloc(n), *white_chain = malloc(n);
	REQUIRE(rgba && white && chain && white_chain);
	for (int k = 0; k < TW * TW; k++) {
		bool red = (k % TW) % 2 == 0;
		uint8_t px[4] = {red ? 255 : 0, 0, red ? 0 : 255, 255};
		memcpy(rgba + 4 * k, px, 4);
		memset(white + 4 * k, 255, 4);
	}
	rnd_texture_build_chain(rgba, TW, TW, true, chain);
	rnd_texture_build_chain(white, TW, TW, true, white_chain);
	const char *doc = "{\"width\":48,\"height\":48,"
	                  "\"camera\":{\"type\":\"orthographic\",\"position\":[0,5,0],\"target\":[0,0,0],\"up\":[0,0,-1],"
	                  "\"height\":2.4},\"materials\":{\"m\":{\"base_color\":[1,1,1]}},"
	                  "\"objects\":[{\"shape\":\"plane\",\"size\":[2,2],\"material\":\"m\"}],"
	                  "\"lights\":[{\"type\":\"directional\",\"direction\":[0,-1,0]}],\"output\":{\"msaa\":1}}";
	struct api_scene *s = NULL;
	struct api_problem p;
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s", p.detail);
	struct rnd_texture built = {.rgba = rgba, .width = TW, .height = TW};
	/* rnd_texture.chain holds levels 1.. (level 0 is rgba). */
	const size_t base = (size_t)TW * TW * 4;
	struct rnd_texture given = {.rgba = rgba, .width = TW, .height = TW, .chain = chain + base, .chain_srgb = true};
	struct rnd_texture other = {.rgba = rgba, .width = TW, .height = TW, .chain = white_chain + base, .chain_srgb = true};
	struct rnd_texture linear = {.rgba = rgba, .width = TW, .height = TW, .chain = white_chain + base,
	                             .chain_srgb = false};
	struct rnd_image a, b, c, d;
	if (render_with(s, &built, &a)) {
		if (render_with(s, &given, &b)) {
			CHECK(!memcmp(a.pixels, b.pixels, (size_t)a.stride * a.height), "a precomputed chain changes the image");
			rnd_image_release(&b);
		}
		if (render_with(s, &other, &c)) {
			double diff = mean_abs_diff(&a, &c);
			CHECK(diff > 40, "the precomputed chain is not what is sampled (mean difference %.1f)", diff);
			rnd_image_release(&c);
		}
		if (render_with(s, &linear, &d)) {
			CHECK(!memcmp(a.pixels, d.pixels, (size_t)a.stride * a.height), "a linear chain was used for sRGB");
			rnd_image_release(&d);
		}
		rnd_image_release(&a);
	}
	api_scene_free(s);
	free(rgba);
	free(white);
	free(chain);
	free(white_chain);
	CHECK(rnd_context_validation_messages(gpu_ctx()) == 0);
}
