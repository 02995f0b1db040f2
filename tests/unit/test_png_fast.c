/* tests/unit — api/png_fast.h: the common PNG decoded with libdeflate is libpng's answer byte
 * for byte (every colour type it reads, every filter, the image data in many IDAT chunks), and
 * everything else is left to libpng (16 bits, a palette, interlace, tRNS, a bad CRC, a cut).
 * The PNGs are written here with libpng; the reference is libpng's simplified reader. */
#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
#include "model.h"
#include "png_fast.h"
#include "test.h"

struct out {
	uint8_t *d;
	size_t n, cap;
};

static void out_write(png_structp png, png_bytep b, size_t n)
{
	struct out *o = png_get_io_ptr(png);
	if (o->n + n > o->cap) {
		o->cap = (o->n + n) * 2;
		o->d = realloc(o->d, o->cap);
	}
	memcpy(o->d + o->n, b, n);
	o->n += n;
}

static void out_flush(png_structp png)
{
	(void)png;
}

struct spec {
	int type, depth, filter, interlace, trns;
	size_t idat;   /* libpng's compression buffer: how large each IDAT chunk is */
};

/* A w x h PNG of noise and gradients (so that each filter has something to do), as spec says. */
static uint8_t *make_png(const struct spec *s, int w, int h, size_t *len)
{
	struct out o = {0};
	png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
	png_infop info = png_create_info_struct(png);
	if (setjmp(png_jmpbuf(png))) {
		png_destroy_write_struct(&png, &info);
		free(o.d);
		return NULL;
	}
	png_set_write_fn(png, &o, out_write, out_flush);
	png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, s->depth, s->type, s->interlace, PNG_COMPRESSION_TYPE_DEFAULT,
	             PNG_FILTER_TYPE_DEFAULT);
	png_set_filter(png, 0, s->filter);
	png_set_compression_buffer_size(png, s->idat);
	if (s->type == PNG_COLOR_TYPE_PALETTE) {
		png_color pal[4] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {9, 9, 9}};
		png_set_PLTE(png, info, pal, 4);
	}
	if (s->trns) {
		png_color_16 t = {0, 10, 20, 30, 10};
		png_set_tRNS(png, info, NULL, 0, &t);
	}
	png_write_info(png, info);
	int ch = png_get_channels(png, info), bytes = s->depth / 8 * ch;
	uint8_t *row = malloc((size_t)w * (size_t)bytes);
	uint32_t x32 = 99;
	int passes = png_set_interlace_handling(png);
	for (int p = 0; p < passes; p++)
		for (int y = 0; y < h; y++) {
			for (int i = 0; i < w * bytes; i++) {
				x32 = x32 * 1103515245u + 12345u;
				row[i] = (uint8_t)(s->type == PNG_COLOR_TYPE_PALETTE ? (x32 >> 16) & 3 : (i + 3 * y) + ((x32 >> 16) & 15));
			}
			png_write_row(png, row);
		}
	png_write_end(png, info);
	png_destroy_write_struct(&png, &info);
	free(row);
	*len = o.n;
	return o.d;
}

/* libpng's own RGBA8 of d (the simplified reader: no gamma chunk is written, so values as stored). */
static uint8_t *libpng_rgba(const uint8_t *d, size_t len, uint32_t *w, uint32_t *h)
{
	png_image im;
	memset(&im, 0, sizeof im);
	im.version = PNG_IMAGE_VERSION;
	if (!png_image_begin_read_from_memory(&im, d, len)) return NULL;
	im.format = PNG_FORMAT_RGBA;
	uint8_t *px = malloc(PNG_IMAGE_SIZE(im));
	if (!png_image_finish_read(&im, NULL, px, 0, NULL)) {
		free(px);
		return NULL;
	}
	*w = im.width;
	*h = im.height;
	return px;
}

TEST(png_fast_is_libpngs_answer)
{
	static const int types[4] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
	                             PNG_COLOR_TYPE_RGB_ALPHA};
	static const int filters[6] = {PNG_FILTER_NONE, PNG_FILTER_SUB, PNG_FILTER_UP, PNG_FILTER_AVG, PNG_FILTER_PAETH,
	                               PNG_ALL_FILTERS};
	int bad = 0, runs = 0;
	for (int t = 0; t < 4; t++)
		for (int f = 0; f < 6; f++) {
			struct spec s = {types[t], 8, filters[f], PNG_INTERLACE_NONE, 0, f % 2 ? 257 : 8192};
			size_t len;
			uint8_t *d = make_png(&s, 37, 23, &len), *fast, *ref;
			uint32_t w, h, rw = 0, rh = 0;
			REQUIRE(d);
			int rc = api_png_decode_fast(d, len, 1u << 20, &fast, &w, &h);
			ref = libpng_rgba(d, len, &rw, &rh);
			REQUIRE(ref);
			runs++;
			if (rc != 0 || w != rw || h != rh || memcmp(fast, ref, (size_t)w * h * 4)) {
				bad++;
				CHECK(0, "colour type %d, filter %d: rc %d, %ux%u", types[t], filters[f], rc, w, h);
			}
			if (rc == 0) free(fast);
			free(ref);
			free(d);
		}
	CHECK(bad == 0 && runs == 24, "%d of %d differ", bad, runs);
}

/* What it leaves to libpng; through api_image_decode every one still decodes as libpng does. */
TEST(png_fast_leaves_the_rest_to_libpng)
{
	static const struct spec rest[4] = {
		{PNG_COLOR_TYPE_RGB, 16, PNG_ALL_FILTERS, PNG_INTERLACE_NONE, 0, 8192},
		{PNG_COLOR_TYPE_PALETTE, 8, PNG_FILTER_NONE, PNG_INTERLACE_NONE, 0, 8192},
		{PNG_COLOR_TYPE_RGB, 8, PNG_ALL_FILTERS, PNG_INTERLACE_ADAM7, 0, 8192},
		{PNG_COLOR_TYPE_RGB, 8, PNG_ALL_FILTERS, PNG_INTERLACE_NONE, 1, 8192},
	};
	static const char *const what[4] = {"16 bits", "a palette", "interlaced", "tRNS"};
	for (int k = 0; k < 4; k++) {
		size_t len;
		uint8_t *d = make_png(&rest[k], 19, 11, &len), *px = NULL, *ref;
		uint32_t w, h, rw, rh;
		REQUIRE(d);
		CHECK(api_png_decode_fast(d, len, 1u << 20, &px, &w, &h) == API_PNG_NOT_MINE, "%s: not read here", what[k]);
		char err[200];
		CHECK(api_image_decode(d, len, 1u << 20, &px, &w, &h, err, sizeof err) == API_OK, "%s: %s", what[k], err);
		/* (the simplified reader takes 16 bits for linear light: compared for the palette only) */
		if (k == 1 && (ref = libpng_rgba(d, len, &rw, &rh))) {
			CHECK(w == rw && h == rh && !memcmp(px, ref, (size_t)w * h * 4), "%s: libpng's pixels", what[k]);
			free(ref);
		}
		free(px);
		free(d);
	}
	/* A flipped bit in the image data (its CRC no longer matches), a cut in it, a claim larger
	 * than max_pixels: left to libpng, which refuses the first two and the limit's check the third. */
	struct spec s = {PNG_COLOR_TYPE_RGB, 8, PNG_ALL_FILTERS, PNG_INTERLACE_NONE, 0, 8192};
	size_t len;
	uint8_t *d = make_png(&s, 40, 40, &len), *px;
	uint32_t w, h;
	char err[200];
	REQUIRE(d && len > 200);
	CHECK(api_png_decode_fast(d, len, 1599, &px, &w, &h) == API_PNG_NOT_MINE, "over max_pixels");
	CHECK(api_image_decode(d, len, 1599, &px, &w, &h, err, sizeof err) == API_ERR, "over max_pixels: refused");
	d[len - 30] ^= 4;
	CHECK(api_png_decode_fast(d, len, 1u << 20, &px, &w, &h) == API_PNG_NOT_MINE, "a bad CRC");
	CHECK(api_image_decode(d, len, 1u << 20, &px, &w, &h, err, sizeof err) == API_ERR, "a bad CRC: libpng refuses");
	d[len - 30] ^= 4;
	CHECK(api_png_decode_fast(d, len / 2, 1u << 20, &px, &w, &h) == API_PNG_NOT_MINE, "cut in half");
	CHECK(api_image_decode(d, len / 2, 1u << 20, &px, &w, &h, err, sizeof err) == API_ERR, "cut: libpng refuses");
	free(d);
}
