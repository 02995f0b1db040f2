/* tests — api/image_decode.c and the model textures: PNG and JPEG decoding (JPEG scaled at
 * decode), and a model's texture decoded at the size the output needs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>
#include <png.h>
#include <pthread.h>
#include <jpeglib.h>
#include "api.h"
#include "model.h"
#include "models.h"
#include "test.h"
#include "util.h"
#include "umbra/rnd_math.h"
#include "model_util.h"

TEST(model_image_decode)
{
	size_t n;
	uint8_t *png = png_2x2(&n);
	REQUIRE(png);
	uint8_t *px;
	uint32_t w, h;
	char err[128];
	CHECK(api_image_decode(png, n, 0, &px, &w, &h, err, sizeof err) == API_OK && w == 2 && h == 2 &&
	      !memcmp(px, TEX, 16));
	free(px);
	CHECK(api_image_decode(png, n, 3, &px, &w, &h, err, sizeof err) == API_ERR);
	CHECK(api_image_decode(png, n / 2, 0, &px, &w, &h, err, sizeof err) == API_ERR && px == NULL);
	free(png);
	static const uint8_t bad_jpeg[] = {0xff, 0xd8, 0xff, 0xe0, 0, 0x10, 'J', 'F', 'I', 'F', 0, 1, 2, 3};
	CHECK(api_image_decode(bad_jpeg, sizeof bad_jpeg, 0, &px, &w, &h, err, sizeof err) == API_ERR && px == NULL,
	      "%s", err);
}

/* A w x h JPEG of one colour (quality 100), encoded here; *n its bytes (the caller frees it). */
static unsigned char *jpeg_of(uint32_t w, uint32_t h, const uint8_t rgb[3], unsigned long *n)
{
	struct jpeg_compress_struct ci;
	struct jpeg_error_mgr je;
	ci.err = jpeg_std_error(&je);
	jpeg_create_compress(&ci);
	unsigned char *buf = NULL;
	*n = 0;
	jpeg_mem_dest(&ci, &buf, n);
	ci.image_width = w;
	ci.image_height = h;
	ci.input_components = 3;
	ci.in_color_space = JCS_RGB;
	jpeg_set_defaults(&ci);
	jpeg_set_quality(&ci, 100, TRUE);
	jpeg_start_compress(&ci, TRUE);
	uint8_t *row = malloc((size_t)w * 3);
	for (uint32_t i = 0; row && i < w; i++) memcpy(row + 3 * i, rgb, 3);
	while (row && ci.next_scanline < ci.image_height) {
		JSAMPROW r[1] = {row};
		jpeg_write_scanlines(&ci, r, 1);
	}
	free(row);
	jpeg_finish_compress(&ci);
	jpeg_destroy_compress(&ci);
	return buf;
}

TEST(model_image_decode_jpeg)
{
	/* An 8x4 JPEG of one colour, encoded here. */
	static const uint8_t rgb[3] = {200, 100, 50};
	unsigned long n;
	unsigned char *buf = jpeg_of(8, 4, rgb, &n);
	uint8_t *px;
	uint32_t w, h;
	char err[128];
	CHECK(api_image_decode(buf, n, 0, &px, &w, &h, err, sizeof err) == API_OK && w == 8 && h == 4, "%s", err);
	if (px) CHECK(abs(px[0] - 200) <= 2 && abs(px[1] - 100) <= 2 && abs(px[2] - 50) <= 2 && px[3] == 255,
	              "%d %d %d %d", px[0], px[1], px[2], px[3]);
	free(px);
	/* cut short: libjpeg warns and pads; never a crash */
	px = NULL;
	if (api_image_decode(buf, n / 2, 0, &px, &w, &h, err, sizeof err) == API_OK) CHECK(w == 8 && h == 4);
	free(px);
	free(buf);
}

/* libjpeg's scaled decode: a 1000x600 JPEG for a larger side of at least 200 comes back at
 * 1/4 (250x150: 1/8 would be 125 < 200), its colour kept; at least 0: as stored. */
TEST(model_image_decode_jpeg_scaled)
{
	static const uint8_t rgb[3] = {30, 160, 90};
	unsigned long n;
	unsigned char *buf = jpeg_of(1000, 600, rgb, &n);
	uint8_t *px = NULL;
	uint32_t w, h, stored;
	char err[128];
	CHECK(api_image_decode_fit(buf, n, 0, 200, false, &px, &w, &h, &stored, err, sizeof err) == API_OK && w == 250 && h == 150 &&
	      stored == 1000, "%ux%u of %u: %s", w, h, stored, err);
	if (px) CHECK(abs(px[0] - 30) <= 3 && abs(px[1] - 160) <= 3 && abs(px[2] - 90) <= 3, "%d %d %d", px[0], px[1], px[2]);
	free(px);
	px = NULL;
	CHECK(api_image_decode_fit(buf, n, 0, 0, false, &px, &w, &h, &stored, err, sizeof err) == API_OK && w == 1000 && h == 600);
	free(px);
	free(buf);
}

/* A 512^2 checker PNG texture (texels alternating black and white). */
static uint8_t *checker_png(size_t *len)
{
	uint8_t *px = malloc(512 * 512 * 4);
	if (!px) return NULL;
	for (int y = 0; y < 512; y++)
		for (int x = 0; x < 512; x++) {
			uint8_t v = (uint8_t)(((x ^ y) & 1) * 255);
			uint8_t *p = px + 4 * ((size_t)y * 512 + x);
			p[0] = p[1] = p[2] = v;
			p[3] = 255;
		}
	uint8_t *png = test_png_rgba(px, 512, 512, len);
	free(px);
	return png;
}

static struct api_model *get_for(const uint8_t *d, size_t len, uint32_t side)
{
	return model_get_for(d, len, API_MODEL_GLB, side, 0);
}

/* A texture is decoded no larger than the request's images need (API_TEXTURE_SIDE_PER_PIXEL
 * texels a pixel of its size class, halved from the stored size): the 512^2 checker for 64^2
 * images comes back 128^2 and grey, the level the renderer's mip chain has there (boxes of black
 * and white averaged in linear light for the base colour: sRGB 188). The cache serves it to
 * requests of the same class only: they would decode it alike (the same request, the same
 * bytes); 1024^2 images import again with it as stored, which serves 700^2 ones too. */
TEST(model_texture_decoded_at_the_size_the_output_needs)
{
	api_model_cache_clear();
	size_t pnglen, len;
	uint8_t *png = checker_png(&pnglen);
	REQUIRE(png != NULL);
	uint8_t *g = quad_glb_png(png, pnglen, "", "", &len);
	REQUIRE(g != NULL);
	struct api_model *small = get_for(g, len, 64);
	REQUIRE(small && small->materials[0].textures[RND_TEX_BASE]);
	const struct rnd_texture *t = small->materials[0].textures[RND_TEX_BASE];
	CHECK(t->width == 128 && t->height == 128 && small->texture_side == 64 && small->texture_max == 512,
	      "%ux%u for class %u (stored %u)", t->width, t->height, small->texture_side, small->texture_max);
	int grey = 0;
	for (size_t i = 0; i < (size_t)t->width * t->height; i++) grey += t->rgba[4 * i] >= 186 && t->rgba[4 * i] <= 190;
	CHECK(grey == (int)(t->width * t->height), "%d of %u texels grey (%d)", grey, t->width * t->height, t->rgba[0]);
	struct api_model *same = get_for(g, len, 48), *other = get_for(g, len, 32);
	CHECK(same == small, "48^2 images: the same class, the same entry");
	CHECK(other && other != small && other->materials[0].textures[RND_TEX_BASE]->width == 64, "32^2 images: 64^2 texels");
	struct api_model *big = get_for(g, len, 1024), *near = get_for(g, len, 700), *again = get_for(g, len, 64);
	REQUIRE(big != NULL);
	CHECK(big != small && big->materials[0].textures[RND_TEX_BASE]->width == 512, "1024^2 images: as stored");
	CHECK(near == big, "700^2 images reduce nothing either: the same entry");
	CHECK(again == small, "64^2 images still get the 128^2 texels");
	struct api_model *list[] = {small, same, other, big, near, again};
	for (int i = 0; i < 6; i++) api_model_release(list[i]);
	api_model_cache_clear();
	free(g);
}
