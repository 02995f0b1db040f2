/*
 * api/encode_webp — WebP with libwebp's advanced API into a growable memory buffer.
 *
 * Lossless by default (every 8-bit sample, alpha included, comes back exactly); lossy with a
 * quality 0..100 (output.quality), its alpha plane still lossless. Speed over size, as for the
 * PNG: lossless runs libwebp's preset level LOSSLESS_LEVEL and lossy method LOSSY_METHOD
 * (measurements there). The bytes are malloc'd here (not WebPMalloc'd): the caller free()s them
 * like a PNG's.
 */
#include <stdlib.h>
#include <string.h>
#include <webp/encode.h>
#include "api.h"

/* libwebp's lossless preset (0 fastest .. 9 smallest), measured on ../shared/bench/thumb-512.json
 * as rendered (best of 5 on a busy 2-core machine; the PNG at its default level 1 is 4.6 ms,
 * 49.7 KB):
 *   preset 0: 11 ms 48.6 KB; preset 1: 32 ms 19.1 KB; preset 3: 94 ms 16.8 KB; preset 6 (libwebp's
 *   default): 106 ms 16.9 KB.
 * Preset 1: most of the saving for a third of the default's time. docs/performance.md has the
 * 256x256 thumbnails. */
#define LOSSLESS_LEVEL 1
/* libwebp's lossy method (0 fastest .. 6 smallest; 4 the default), same image at quality 80:
 * method 2: 9.5 ms 2.6 KB; method 4: 22 ms 2.3 KB. */
#define LOSSY_METHOD 2

struct webp_buf {
	uint8_t *data;
	size_t len, cap;
	bool oom;
};

static int buf_write(const uint8_t *bytes, size_t n, const WebPPicture *pic)
{
	struct webp_buf *b = pic->custom_ptr;
	if (n > b->cap - b->len) {
		size_t cap = b->cap ? b->cap : 65536;
		while (cap - b->len < n) {
			if (cap > SIZE_MAX / 2) return b->oom = true, 0;
			cap *= 2;
		}
		uint8_t *d = realloc(b->data, cap);
		if (!d) return b->oom = true, 0;
		b->data = d;
		b->cap = cap;
	}
	memcpy(b->data + b->len, bytes, n);
	b->len += n;
	return 1;
}

static const char *webp_error(WebPEncodingError e)
{
	switch (e) {
	case VP8_ENC_ERROR_OUT_OF_MEMORY:
	case VP8_ENC_ERROR_BITSTREAM_OUT_OF_MEMORY: return "out of memory";
	case VP8_ENC_ERROR_BAD_DIMENSION: return "the image is over WebP's 16383 pixels a side";
	case VP8_ENC_ERROR_PARTITION0_OVERFLOW:
	case VP8_ENC_ERROR_PARTITION_OVERFLOW: return "a partition is over 512 KB (lower the quality)";
	case VP8_ENC_ERROR_FILE_TOO_BIG: return "the file would be over 4 GiB";
	default: return "libwebp failed";
	}
}

enum api_result api_webp_encode(const struct rnd_image *img, float quality, uint8_t **out, size_t *len,
                                struct api_problem *p)
{
	struct api_problem scratch;
	if (!p) p = &scratch;
	if (!out || !len) return api_problem_set(p, 500, "", "WebP encoder: no output pointer");
	*out = NULL;
	*len = 0;
	if (!img || !img->pixels || !img->width || !img->height)
		return api_problem_set(p, 500, "", "WebP encoder: empty image");
	if (img->format != RND_PIXELS_RGBA8)
		return api_problem_set(p, 500, "", "WebP encoder: the image is not RGBA8");
	if (img->stride < (size_t)img->width * 4 || img->stride > INT32_MAX)
		return api_problem_set(p, 500, "", "WebP encoder: stride %zu does not fit width %u", img->stride, img->width);
	if (img->width > API_WEBP_MAX_SIDE || img->height > API_WEBP_MAX_SIDE)
		return api_problem_set(p, 422, "", "a WebP is at most %u pixels a side; this image is %ux%u",
		                       API_WEBP_MAX_SIDE, img->width, img->height);

	WebPConfig config;
	WebPPicture pic;
	struct webp_buf buf = {0};
	enum api_result r = API_OK;
	if (!WebPConfigInit(&config) || !WebPPictureInit(&pic))
		return api_problem_set(p, 500, "", "WebP encoder: libwebp version mismatch");
	bool lossless = quality < 0;
	if (lossless) {
		WebPConfigLosslessPreset(&config, LOSSLESS_LEVEL);
		/* Exact: RGB under alpha 0 kept too (a straight-alpha image, as the PNG writes it). */
		config.exact = 1;
	} else {
		config.quality = quality > 100 ? 100 : quality;
		config.method = LOSSY_METHOD;
	}
	pic.use_argb = lossless;
	pic.width = (int)img->width;
	pic.height = (int)img->height;
	pic.writer = buf_write;
	pic.custom_ptr = &buf;
	if (!WebPPictureImportRGBA(&pic, img->pixels, (int)img->stride)) {
		r = api_problem_set(p, 500, "", "WebP encoder: out of memory importing the image");
		goto free_picture;
	}
	if (!WebPEncode(&config, &pic)) {
		r = api_problem_set(p, 500, "", "WebP encoder: %s", buf.oom ? "out of memory" : webp_error(pic.error_code));
		goto free_buffer;
	}
	*out = buf.data;
	*len = buf.len;
	goto free_picture;
free_buffer:
	free(buf.data);
free_picture:
	WebPPictureFree(&pic);
	return r;
}
