/* tests — WebP output: api/encode_webp.c decoded back by libwebp's decoder (lossless: every
 * sample; lossy: a PSNR bound, alpha exact), api_encode()'s dispatch, and the output members
 * (format "webp", quality) as the parser takes or refuses them. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <webp/decode.h>
#include "api.h"
#include "models.h"
#include "test.h"
#include "util.h"

static uint8_t *webp_decode(const uint8_t *data, size_t len, int *w, int *h, WebPBitstreamFeatures *f)
{
	if (WebPGetFeatures(data, len, f) != VP8_STATUS_OK) return NULL;
	return WebPDecodeRGBA(data, len, w, h);
}

static void check_lossless(bool opaque)
{
	struct rnd_image img = test_rgba8_image(61, 37, opaque);
	uint8_t *out = NULL;
	size_t len = 0;
	struct api_problem p;
	REQUIRE(api_webp_encode(&img, -1, &out, &len, &p) == API_OK, "%s", p.detail);
	REQUIRE(len > 12 && !memcmp(out, "RIFF", 4) && !memcmp(out + 8, "WEBP", 4), "no RIFF/WEBP magic");
	int w = 0, h = 0;
	WebPBitstreamFeatures f;
	uint8_t *rgba = webp_decode(out, len, &w, &h, &f);
	REQUIRE(rgba, "libwebp could not decode it");
	CHECK(w == 61 && h == 37, "%dx%d", w, h);
	CHECK(f.format == 2, "lossless bitstream (format %d)", f.format);
	CHECK(f.has_alpha == !opaque, "has_alpha %d", f.has_alpha);
	int bad = 0;
	for (uint32_t y = 0; y < img.height; y++)
		for (uint32_t x = 0; x < img.width; x++)
			for (int c = 0; c < 4; c++) {
				uint8_t want = ((const uint8_t *)img.pixels)[y * img.stride + 4 * x + (uint32_t)c];
				uint8_t got = rgba[4 * ((size_t)y * img.width + x) + (uint32_t)c];
				if (got != want && bad++ < 3) CHECK(0, "pixel %u,%u channel %d: %u, want %u", x, y, c, got, want);
			}
	CHECK(bad == 0, "%d samples differ", bad);
	WebPFree(rgba);
	free(out);
	rnd_image_release(&img);
}

TEST(webp_lossless_rgba_exact) { check_lossless(false); }
TEST(webp_lossless_opaque_exact_without_alpha) { check_lossless(true); }

TEST(webp_lossy_q80_psnr_and_exact_alpha)
{
	struct rnd_image img = test_rgba8_image(128, 96, false);
	uint8_t *lossy = NULL, *lossless = NULL;
	size_t len = 0, lossless_len = 0;
	struct api_problem p;
	REQUIRE(api_webp_encode(&img, 80, &lossy, &len, &p) == API_OK, "%s", p.detail);
	REQUIRE(api_webp_encode(&img, -1, &lossless, &lossless_len, &p) == API_OK, "%s", p.detail);
	int w = 0, h = 0, alpha_diff = 0;
	WebPBitstreamFeatures f;
	uint8_t *rgba = webp_decode(lossy, len, &w, &h, &f);
	REQUIRE(rgba && w == 128 && h == 96, "decoded %dx%d", w, h);
	CHECK(f.format == 1 && f.has_alpha, "lossy with alpha (format %d, alpha %d)", f.format, f.has_alpha);
	double db = test_psnr_rgb(&img, rgba, &alpha_diff);
	/* Fully transparent pixels may be given any colour by a lossy encoder: the border is
	 * 2 pixels wide, so its share of the error stays small. */
	CHECK(db > 30, "PSNR %.1f dB at quality 80", db);
	CHECK(alpha_diff == 0, "the alpha plane is lossless (largest error %d)", alpha_diff);
	CHECK(len < lossless_len, "lossy %zu bytes, lossless %zu", len, lossless_len);
	WebPFree(rgba);
	free(lossy);
	free(lossless);
	rnd_image_release(&img);
}

#define DOC(output) "{\"camera\":{},\"objects\":[],\"output\":" output "}"

TEST(webp_dispatch_from_output_format)
{
	struct api_problem p;
	struct api_scene *s = test_parse_scene(DOC("{\"format\":\"webp\",\"transparent\":true,\"bit_depth\":16}"), &p);
	REQUIRE(s, "%s", p.detail);
	CHECK(s->format == API_FORMAT_WEBP && s->quality < 0 && s->scene.output.pixels == RND_PIXELS_RGBA8);
	CHECK(!strcmp(api_format_mime(s->format), "image/webp"));
	CHECK(strstr(s->warnings, "/output/bit_depth: not used, the answer is WebP"), "%s", s->warnings);
	struct rnd_image img = test_rgba8_image(16, 8, false);
	uint8_t *out = NULL;
	size_t len = 0;
	REQUIRE(api_encode(s, &img, &out, &len, &p) == API_OK, "%s", p.detail);
	WebPBitstreamFeatures f;
	CHECK(WebPGetFeatures(out, len, &f) == VP8_STATUS_OK && f.format == 2 && f.has_alpha);
	free(out);
	rnd_image_release(&img);
	api_scene_free(s);

	s = test_parse_scene(DOC("{\"format\":\"webp\",\"quality\":80}"), &p);
	REQUIRE(s, "%s", p.detail);
	CHECK(s->quality == 80);
	img = test_rgba8_image(16, 8, true);
	REQUIRE(api_encode(s, &img, &out, &len, &p) == API_OK, "%s", p.detail);
	CHECK(WebPGetFeatures(out, len, &f) == VP8_STATUS_OK && f.format == 1 && !f.has_alpha);
	free(out);
	rnd_image_release(&img);
	api_scene_free(s);
}

TEST(webp_output_members_refused)
{
	static const struct {
		const char *doc, *pointer, *detail;
	} bad[] = {
		{DOC("{\"format\":\"webp\",\"quality\":101}"), "/output/quality", "100"},
		{DOC("{\"format\":\"webp\",\"quality\":-1}"), "/output/quality", "0"},
		{DOC("{\"format\":\"webp\",\"quality\":\"80\"}"), "/output/quality", "number"},
		{DOC("{\"format\":\"png\",\"quality\":80}"), "/output/quality", "needs format \"webp\""},
		{DOC("{\"quality\":80,\"format\":\"exr\"}"), "/output/quality", "needs format \"webp\""},
		{DOC("{\"format\":\"webp\",\"aovs\":[\"depth\"]}"), "/output/aovs", "WebP has no room"},
		{DOC("{\"format\":\"webp\",\"lossless\":false}"), "/output/lossless", "unknown"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		struct api_problem p;
		struct api_scene *s = test_parse_scene(bad[i].doc, &p);
		CHECK(!s && p.status == 400 && !strcmp(p.pointer, bad[i].pointer) && strstr(p.detail, bad[i].detail),
		      "%s: %d %s %s", bad[i].doc, p.status, p.pointer, p.detail);
		api_scene_free(s);
	}
}

/* No format in the document: Accept or the CLI's output name chooses it later, and quality is
 * then refused unless that choice is WebP. */
TEST(webp_quality_waits_for_the_format)
{
	struct api_problem p;
	struct api_scene *s = test_parse_scene(DOC("{\"quality\":50}"), &p);
	REQUIRE(s, "%s", p.detail);
	CHECK(api_scene_check_output(s, &p) == API_ERR && p.status == 400 && !strcmp(p.pointer, "/output/quality"),
	      "%d %s", p.status, p.pointer);
	CHECK(api_scene_set_format(s, API_FORMAT_WEBP, &p) == API_OK && api_scene_check_output(s, &p) == API_OK);
	CHECK(s->scene.output.pixels == RND_PIXELS_RGBA8);
	CHECK(api_scene_set_format(s, API_FORMAT_EXR, &p) == API_OK && api_scene_check_output(s, &p) == API_ERR);
	api_scene_free(s);

	/* A sheet of views wider than WebP's 16383 pixels: 422 at /views once the answer is WebP. */
	const char *wide = "{\"width\":8192,\"height\":64,\"views\":[{},{}],\"objects\":[]}";
	s = test_parse_scene(wide, &p);
	REQUIRE(s, "%s", p.detail);
	CHECK(api_scene_check_output(s, &p) == API_OK);
	CHECK(api_scene_set_format(s, API_FORMAT_WEBP, &p) == API_OK);
	CHECK(api_scene_check_output(s, &p) == API_ERR && p.status == 422 && !strcmp(p.pointer, "/views"),
	      "%d %s %s", p.status, p.pointer, p.detail);
	api_scene_free(s);
}

TEST(webp_format_from_file_name)
{
	enum api_format f = API_FORMAT_PNG;
	CHECK(api_format_from_name("out/thumb.WebP", &f) && f == API_FORMAT_WEBP);
	CHECK(api_format_from_name("a.exr", &f) && f == API_FORMAT_EXR);
	CHECK(api_format_from_name("a.png", &f) && f == API_FORMAT_PNG);
	CHECK(!api_format_from_name("a.jpg", &f) && !api_format_from_name("dir.webp/a", &f) &&
	      !api_format_from_name("noext", &f) && f == API_FORMAT_PNG);
	CHECK(!strcmp(api_format_name(API_FORMAT_WEBP), "webp"));
}
