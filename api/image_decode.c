/*
 * api/image_decode — PNG (libdeflate for the common ones, api/png_fast.h; libpng) and JPEG
 * (libjpeg-turbo) to RGBA8, for the textures of imported models (and of materials). See model.h.
 *
 * Both decoders check the header's size against max_pixels before allocating, so a small file
 * that claims to be 100000x100000 costs nothing. Both libraries report errors through longjmp;
 * the error handlers below turn that into an API_ERR with the library's message. Colour values
 * come out as stored: no gamma or colour-space conversion (glTF's rule, see decode_png).
 */
#include <setjmp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <png.h>
#include <jpeglib.h>
#include "model.h"
#include "png_fast.h"

#define DEFAULT_MAX_PIXELS (64ull << 20)

static enum api_result err_set(char *err, size_t n, const char *fmt, const char *arg)
{
	if (err && n) snprintf(err, n, fmt, arg);
	return API_ERR;
}

/* libpng's low-level reader over a memory buffer. Its simplified API (png_image) converts to
 * sRGB by the file's gAMA / cHRM / iCCP chunks, and there is no way to ask it not to; glTF
 * says a texture's values are used as stored ("any colorspace information (such as ICC
 * profiles, intents, gamma values, etc.) from PNG images MUST be ignored"), and so does a
 * material's base_color_texture here: no gamma transform is ever set up below. */
struct png_src {
	const uint8_t *data;
	size_t len, at;
	char msg[160];
};

static void png_read_mem(png_structp png, png_bytep out, size_t n)
{
	struct png_src *s = png_get_io_ptr(png);
	if (s->len - s->at < n) png_error(png, "the file is cut short");
	memcpy(out, s->data + s->at, n);
	s->at += n;
}

static void png_on_error(png_structp png, png_const_charp msg)
{
	struct png_src *s = png_get_error_ptr(png);
	snprintf(s->msg, sizeof s->msg, "%s", msg);
	png_longjmp(png, 1);
}

/* Warnings (a bad ancillary chunk, skipped) are not fatal and not printed on stderr. */
static void png_quiet(png_structp png, png_const_charp msg)
{
	(void)png;
	(void)msg;
}

/* Any PNG to 8-bit RGBA, values as stored: palette and low bit depths expanded, tRNS to alpha,
 * 16 bits scaled to 8, grey to RGB, alpha 255 where the file has none. */
static void png_to_rgba8(png_structp png, png_infop info)
{
	png_byte type = png_get_color_type(png, info);
	png_set_expand(png);
	png_set_scale_16(png);
	if (!(type & PNG_COLOR_MASK_COLOR)) png_set_gray_to_rgb(png);
	if (!(type & PNG_COLOR_MASK_ALPHA) && !png_get_valid(png, info, PNG_INFO_tRNS))
		png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
	png_set_interlace_handling(png);
	png_read_update_info(png, info);
}

static enum api_result decode_png(const uint8_t *data, size_t len, uint64_t max_pixels, uint8_t **rgba,
                                  uint32_t *w, uint32_t *h, char *err, size_t errsize)
{
	/* The common PNG without libpng (api/png_fast.h); the rest, and anything odd, with it. */
	int fast = api_png_decode_fast(data, len, max_pixels, rgba, w, h);
	if (fast == 0) return API_OK;
	if (fast == API_PNG_NO_MEMORY) return err_set(err, errsize, "PNG: %s", "out of memory");
	struct png_src src = {data, len, 0, ""};
	png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &src, png_on_error, png_quiet);
	png_infop info = png ? png_create_info_struct(png) : NULL;
	/* volatile: written after setjmp and read after a longjmp back to it. */
	uint8_t *volatile px = NULL;
	png_bytep *volatile rows = NULL;
	if (!info) {
		png_destroy_read_struct(&png, NULL, NULL);
		return err_set(err, errsize, "PNG: %s", "out of memory");
	}
	if (setjmp(png_jmpbuf(png))) {
		png_destroy_read_struct(&png, &info, NULL);
		free(px);
		free(rows);
		return err_set(err, errsize, "PNG: %s", src.msg[0] ? src.msg : "cannot be read");
	}
	png_set_read_fn(png, &src, png_read_mem);
	png_read_info(png, info);
	uint32_t width = png_get_image_width(png, info), height = png_get_image_height(png, info);
	if (!width || !height || (uint64_t)width * height > max_pixels)
		png_error(png, "the image is empty or over the texture size limit");
	png_to_rgba8(png, info);
	if (png_get_rowbytes(png, info) != (size_t)width * 4) png_error(png, "unexpected pixel layout");
	px = malloc((size_t)width * height * 4);
	rows = malloc((size_t)height * sizeof *rows);
	if (!px || !rows) png_error(png, "out of memory");
	for (uint32_t y = 0; y < height; y++) rows[y] = px + (size_t)y * width * 4;
	png_read_image(png, rows);
	/* The chunks after the pixels (and a missing IEND) do not matter: not read. */
	png_destroy_read_struct(&png, &info, NULL);
	free(rows);
	*w = width;
	*h = height;
	*rgba = px;
	return API_OK;
}

struct jpeg_err {
	struct jpeg_error_mgr mgr;
	jmp_buf jump;
	char msg[JMSG_LENGTH_MAX];
};

static void jpeg_error_exit(j_common_ptr cinfo)
{
	struct jpeg_err *e = (struct jpeg_err *)cinfo->err;
	(*cinfo->err->format_message)(cinfo, e->msg);
	longjmp(e->jump, 1);
}

/* Warnings (corrupt-data recoveries) are not fatal and not printed on stderr. */
static void jpeg_quiet(j_common_ptr cinfo, int level)
{
	(void)cinfo;
	(void)level;
}

static enum api_result decode_jpeg(const uint8_t *data, size_t len, uint64_t max_pixels, uint32_t min_side,
                                   uint8_t **rgba, uint32_t *w, uint32_t *h, uint32_t *stored_side, char *err,
                                   size_t errsize)
{
	struct jpeg_decompress_struct cinfo;
	struct jpeg_err jerr;
	/* volatile: written after setjmp and read after a longjmp back to it. */
	uint8_t *volatile px = NULL;
	uint8_t *volatile row = NULL;
	memset(&cinfo, 0, sizeof cinfo);
	cinfo.err = jpeg_std_error(&jerr.mgr);
	jerr.mgr.error_exit = jpeg_error_exit;
	jerr.mgr.emit_message = jpeg_quiet;
	jerr.msg[0] = 0;
	if (setjmp(jerr.jump)) {
		jpeg_destroy_decompress(&cinfo);
		free(px);
		free(row);
		return err_set(err, errsize, "JPEG: %s", jerr.msg);
	}
	jpeg_create_decompress(&cinfo);
	jpeg_mem_src(&cinfo, data, (unsigned long)len);
	jpeg_read_header(&cinfo, TRUE);
	/* CMYK comes out as-is; everything else as RGB. */
	int cmyk = cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK;
	cinfo.out_color_space = cmyk ? JCS_CMYK : JCS_RGB;
	uint64_t npx = (uint64_t)cinfo.image_width * cinfo.image_height;
	if (!npx || npx > max_pixels) {
		jpeg_destroy_decompress(&cinfo);
		return err_set(err, errsize, "JPEG: %s", "the image is empty or over the texture size limit");
	}
	/* libjpeg's scaled decode (the IDCT at 1/2, 1/4 or 1/8): a 2048^2 texture for a 256^2
	 * thumbnail costs the decode of a 512^2 one. */
	uint32_t side = cinfo.image_width > cinfo.image_height ? cinfo.image_width : cinfo.image_height;
	*stored_side = side;
	cinfo.scale_num = 1;
	cinfo.scale_denom = 1;
	while (min_side && cinfo.scale_denom < 8 && (side + cinfo.scale_denom * 2 - 1) / (cinfo.scale_denom * 2) >= min_side)
		cinfo.scale_denom *= 2;
	jpeg_start_decompress(&cinfo);
	uint32_t width = cinfo.output_width, height = cinfo.output_height;
	int comps = cinfo.output_components;
	px = malloc((size_t)width * height * 4);
	row = malloc((size_t)width * (size_t)comps);
	if (!px || !row) {
		jpeg_destroy_decompress(&cinfo);
		free(px);
		free(row);
		return err_set(err, errsize, "JPEG: %s", "out of memory");
	}
	while (cinfo.output_scanline < height) {
		uint32_t y = cinfo.output_scanline;
		JSAMPROW rows[1] = {row};
		if (jpeg_read_scanlines(&cinfo, rows, 1) != 1) break;
		uint8_t *d = px + (size_t)y * width * 4;
		for (uint32_t x = 0; x < width; x++, d += 4) {
			const uint8_t *s = row + (size_t)x * (size_t)comps;
			if (comps == 1) {
				d[0] = d[1] = d[2] = s[0];
			} else if (comps == 4) {
				/* Adobe CMYK JPEGs store inverted values: R = C*K/255 on the stored bytes. */
				d[0] = (uint8_t)(s[0] * s[3] / 255);
				d[1] = (uint8_t)(s[1] * s[3] / 255);
				d[2] = (uint8_t)(s[2] * s[3] / 255);
			} else {
				d[0] = s[0]; d[1] = s[1]; d[2] = s[2];
			}
			d[3] = 255;
		}
	}
	jpeg_finish_decompress(&cinfo);
	jpeg_destroy_decompress(&cinfo);
	free(row);
	*w = width;
	*h = height;
	*rgba = px;
	return API_OK;
}

enum api_result api_image_decode_fit(const uint8_t *data, size_t len, uint64_t max_pixels, uint32_t min_side,
                                     bool srgb, uint8_t **rgba, uint32_t *width, uint32_t *height,
                                     uint32_t *stored_side, char *err, size_t errsize)
{
	*rgba = NULL;
	*width = *height = 0;
	if (stored_side) *stored_side = 0;
	if (!max_pixels) max_pixels = DEFAULT_MAX_PIXELS;
	enum api_result r = API_ERR;
	uint32_t stored = 0;
	if (data && len >= 8 && !memcmp(data, "\x89PNG\r\n\x1a\n", 8)) {
		r = decode_png(data, len, max_pixels, rgba, width, height, err, errsize);
		stored = *width > *height ? *width : *height;
		/* the levels the renderer's mip chain would have had there (the same bytes) */
		uint32_t levels = 0;
		for (uint32_t s = stored; min_side && s / 2 >= min_side; s /= 2) levels++;
		if (r == API_OK) rnd_texture_reduce(*rgba, width, height, srgb, levels);
	} else if (data && len >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff) {
		r = decode_jpeg(data, len, max_pixels, min_side, rgba, width, height, &stored, err, errsize);
	} else {
		return err_set(err, errsize, "%s", "the image is neither PNG nor JPEG");
	}
	if (r == API_OK && stored_side) *stored_side = stored;
	return r;
}

enum api_result api_image_decode(const uint8_t *data, size_t len, uint64_t max_pixels, uint8_t **rgba,
                                 uint32_t *width, uint32_t *height, char *err, size_t errsize)
{
	return api_image_decode_fit(data, len, max_pixels, 0, false, rgba, width, height, NULL, err, errsize);
}

static uint32_t be32(const uint8_t *p) { return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]; }

bool api_image_header_size(const uint8_t *d, size_t len, uint32_t *w, uint32_t *h)
{
	if (len >= 24 && !memcmp(d, "\x89PNG\r\n\x1a\n", 8) && !memcmp(d + 12, "IHDR", 4)) {
		*w = be32(d + 16);
		*h = be32(d + 20);
		return *w && *h;
	}
	if (len < 4 || d[0] != 0xff || d[1] != 0xd8) return false;
	/* Markers after SOI: each FF xx with a 16-bit length, up to the first frame header. */
	size_t at = 2;
	while (at + 4 <= len) {
		if (d[at] != 0xff) return false;
		uint8_t m = d[at + 1];
		if (m == 0xff) { at++; continue; }                      /* fill byte */
		if (m == 0xd8 || m == 0x01 || (m >= 0xd0 && m <= 0xd7)) { at += 2; continue; }
		size_t seg = (size_t)d[at + 2] << 8 | d[at + 3];
		if (seg < 2) return false;
		bool sof = m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc;
		if (sof) {
			if (at + 9 > len) return false;
			*h = (uint32_t)d[at + 5] << 8 | d[at + 6];
			*w = (uint32_t)d[at + 7] << 8 | d[at + 8];
			return *w && *h;
		}
		if (m == 0xda || m == 0xd9) return false;              /* scan or end before a frame */
		at += 2 + seg;
	}
	return false;
}
