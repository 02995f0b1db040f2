/* tests — AVIF output (and both 8-bit encoders' refusals): api/encode_avif.c decoded back by libavif's decoder (lossless: every
 * sample; lossy: a PSNR bound, alpha exact), the same bytes on every encode, api_encode()'s
 * dispatch, and the output members (format "avif", quality) as the parser takes or refuses them. */
#include <avif/avif.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "models.h"
#include "test.h"
#include "util.h"

/* The decoded image as packed RGBA8 (malloc'd), its size and whether it has an alpha plane;
 * NULL when libavif cannot decode it. */
static uint8_t *avif_decode(const uint8_t *data, size_t len, uint32_t *w, uint32_t *h, bool *alpha)
{
	avifDecoder *dec = avifDecoderCreate();
	avifImage *image = avifImageCreateEmpty();
	uint8_t *out = NULL;
	if (!dec || !image || avifDecoderReadMemory(dec, image, data, len) != AVIF_RESULT_OK) goto done;
	avifRGBImage rgb;
	avifRGBImageSetDefaults(&rgb, image);
	rgb.format = AVIF_RGB_FORMAT_RGBA;
	rgb.depth = 8;
	rgb.rowBytes = image->width * 4;
	out = malloc((size_t)rgb.rowBytes * image->height);
	rgb.pixels = out;
	if (!out || avifImageYUVToRGB(image, &rgb) != AVIF_RESULT_OK) {
		free(out);
		out = NULL;
		goto done;
	}
	*w = image->width;
	*h = image->height;
	*alpha = image->alphaPlane != NULL;
done:
	if (image) avifImageDestroy(image);
	if (dec) avifDecoderDestroy(dec);
	return out;
}

static void check_lossless(bool opaque)
{
	struct rnd_image img = test_rgba8_image(61, 37, opaque);
	uint8_t *out = NULL, *again = NULL;
	size_t len = 0, again_len = 0;
	struct api_problem p;
	REQUIRE(api_avif_encode(&img, -1, &out, &len, &p) == API_OK, "%s", p.detail);
	REQUIRE(len > 12 && !memcmp(out + 4, "ftypavif", 8), "no ftyp avif box");
	REQUIRE(api_avif_encode(&img, -1, &again, &again_len, &p) == API_OK, "%s", p.detail);
	CHECK(again_len == len && !memcmp(out, again, len), "the same image gives the same bytes");
	uint32_t w = 0, h = 0;
	bool alpha = false;
	uint8_t *rgba = avif_decode(out, len, &w, &h, &alpha);
	REQUIRE(rgba, "libavif could not decode it");
	CHECK(w == 61 && h == 37, "%ux%u", w, h);
	CHECK(alpha == !opaque, "alpha plane %d", alpha);
	int alpha_diff = 0;
	double db = test_psnr_rgb(&img, rgba, &alpha_diff);
	CHECK(db == INFINITY && alpha_diff == 0, "lossless: PSNR %.1f dB, largest alpha error %d", db, alpha_diff);
	free(rgba);
	free(out);
	free(again);
	rnd_image_release(&img);
}

TEST(avif_lossless_rgba_exact) { check_lossless(false); }
TEST(avif_lossless_opaque_exact_without_alpha) { check_lossless(true); }

TEST(avif_lossy_q80_psnr_and_exact_alpha)
{
	struct rnd_image img = test_rgba8_image(128, 96, false);
	uint8_t *lossy = NULL, *lossless = NULL, *low = NULL;
	size_t len = 0, lossless_len = 0, low_len = 0;
	struct api_problem p;
	REQUIRE(api_avif_encode(&img, 80, &lossy, &len, &p) == API_OK, "%s", p.detail);
	REQUIRE(api_avif_encode(&img, 30, &low, &low_len, &p) == API_OK, "%s", p.detail);
	REQUIRE(api_avif_encode(&img, -1, &lossless, &lossless_len, &p) == API_OK, "%s", p.detail);
	uint32_t w = 0, h = 0;
	bool alpha = false;
	int alpha_diff = 0;
	uint8_t *rgba = avif_decode(lossy, len, &w, &h, &alpha);
	REQUIRE(rgba && w == 128 && h == 96, "decoded %ux%u", w, h);
	CHECK(alpha, "the alpha plane is kept");
	double db = test_psnr_rgb(&img, rgba, &alpha_diff);
	CHECK(db > 30, "PSNR %.1f dB at quality 80", db);
	CHECK(alpha_diff == 0, "the alpha plane is lossless (largest error %d)", alpha_diff);
	CHECK(low_len < len && len < lossless_len, "quality 30 %zu bytes, 80 %zu, lossless %zu", low_len, len, lossless_len);
	free(rgba);
	free(lossy);
	free(low);
	free(lossless);
	rnd_image_release(&img);
}

/* Both 8-bit encoders refuse another pixel format (500) and a side over their format's bound (422). */
TEST(webp_and_avif_refuse_what_they_cannot_write)
{
	static const struct {
		enum api_result (*encode)(const struct rnd_image *, float, uint8_t **, size_t *, struct api_problem *);
		uint32_t max_side;
	} enc[] = {{api_webp_encode, API_WEBP_MAX_SIDE}, {api_avif_encode, API_AVIF_MAX_SIDE}};
	for (size_t i = 0; i < sizeof enc / sizeof enc[0]; i++) {
		struct rnd_image img = test_rgba8_image(4, 4, true);
		uint8_t *out = NULL;
		size_t len = 0;
		struct api_problem p;
		img.format = RND_PIXELS_RGBA16;
		CHECK(enc[i].encode(&img, -1, &out, &len, &p) == API_ERR && p.status == 500 && !out, "encoder %zu", i);
		img.format = RND_PIXELS_RGBA8;
		img.width = enc[i].max_side + 1;   /* the check comes before any pixel is read */
		img.stride = (size_t)img.width * 4;
		CHECK(enc[i].encode(&img, -1, &out, &len, &p) == API_ERR && p.status == 422 && !out, "encoder %zu: %d", i,
		      p.status);
		rnd_image_release(&img);
	}
}

#define DOC(output) "{\"camera\":{},\"objects\":[],\"output\":" output "}"

TEST(avif_dispatch_and_members)
{
	struct api_problem p;
	struct api_scene *s = test_parse_scene(DOC("{\"format\":\"avif\",\"quality\":60,\"bit_depth\":16}"), &p);
	REQUIRE(s, "%s", p.detail);
	CHECK(s->format == API_FORMAT_AVIF && s->quality == 60 && s->scene.output.pixels == RND_PIXELS_RGBA8);
	CHECK(!strcmp(api_format_mime(s->format), "image/avif") && !strcmp(api_format_name(s->format), "avif"));
	CHECK(strstr(s->warnings, "/output/bit_depth: not used, the answer is AVIF"), "%s", s->warnings);
	struct rnd_image img = test_rgba8_image(16, 8, true);
	uint8_t *out = NULL;
	size_t len = 0;
	REQUIRE(api_encode(s, &img, &out, &len, &p) == API_OK, "%s", p.detail);
	CHECK(len > 12 && !memcmp(out + 4, "ftypavif", 8));
	free(out);
	rnd_image_release(&img);
	api_scene_free(s);

	s = test_parse_scene(DOC("{\"format\":\"avif\",\"aovs\":[\"depth\"]}"), &p);
	CHECK(!s && p.status == 400 && !strcmp(p.pointer, "/output/aovs") && strstr(p.detail, "an AVIF has no room"),
	      "%s %s", p.pointer, p.detail);
	api_scene_free(s);
	s = test_parse_scene(DOC("{\"format\":\"png\",\"quality\":80}"), &p);
	CHECK(!s && !strcmp(p.pointer, "/output/quality") && strstr(p.detail, "\"avif\""), "%s", p.detail);
	api_scene_free(s);

	/* quality without a format waits for Accept or the output name. */
	s = test_parse_scene(DOC("{\"quality\":50}"), &p);
	REQUIRE(s, "%s", p.detail);
	CHECK(api_scene_set_format(s, API_FORMAT_AVIF, &p) == API_OK && api_scene_check_output(s, &p) == API_OK);
	api_scene_free(s);

	enum api_format f = API_FORMAT_PNG;
	CHECK(api_format_from_name("thumbs/a.AVIF", &f) && f == API_FORMAT_AVIF);
}
