/*
 * api/encode_avif — AVIF with libavif (Debian 12: 0.11, encoding through libaom).
 *
 * As the WebP: lossless by default (every 8-bit sample, alpha included, decodes exactly: RGB
 * coded as 4:4:4 with the identity matrix at quantizer 0), lossy with a quality 0..100
 * (output.quality), its alpha plane still lossless. A fully opaque image carries no alpha.
 * sRGB, full range, tagged so (CICP 1/13/6, or 1/13/0 lossless). One thread per encode (the
 * daemon's workers are the parallelism) and libaom's fixed speed SPEED: the same image gives
 * the same bytes on every run and machine of one build, which the ETag promises.
 * The bytes are malloc'd here: the caller free()s them like a PNG's.
 */
#include <stdlib.h>
#include <string.h>
#include <avif/avif.h>
#include "api.h"

/* libaom's speed (0 slowest .. 10 fastest), measured on ../shared/bench/thumb-256.json and
 * thumb-512.json as rendered (docs/performance.md has the thumbnails). */
#define SPEED 8
/* Lossy colour as 4:2:0 (WebP's lossy is 4:2:0 too); see docs/performance.md. */
#define LOSSY_YUV AVIF_PIXEL_FORMAT_YUV420

/* libavif 1.0's mapping of a quality 0..100 to AV1's quantizer 63..0. */
static int quantizer_of(float quality)
{
	int q = (int)(quality + 0.5f);
	q = q < 0 ? 0 : q > 100 ? 100 : q;
	return ((100 - q) * 63 + 50) / 100;
}

static bool opaque(const struct rnd_image *img)
{
	for (uint32_t y = 0; y < img->height; y++) {
		const uint8_t *row = (const uint8_t *)img->pixels + (size_t)y * img->stride;
		for (uint32_t x = 0; x < img->width; x++)
			if (row[4 * x + 3] != 255) return false;
	}
	return true;
}

static enum api_result check_image(const struct rnd_image *img, uint8_t **out, size_t *len, struct api_problem *p)
{
	if (!out || !len) return api_problem_set(p, 500, "", "AVIF encoder: no output pointer");
	*out = NULL;
	*len = 0;
	if (!img || !img->pixels || !img->width || !img->height)
		return api_problem_set(p, 500, "", "AVIF encoder: empty image");
	if (img->format != RND_PIXELS_RGBA8)
		return api_problem_set(p, 500, "", "AVIF encoder: the image is not RGBA8");
	if (img->stride < (size_t)img->width * 4 || img->stride > UINT32_MAX)
		return api_problem_set(p, 500, "", "AVIF encoder: stride %zu does not fit width %u", img->stride, img->width);
	if (img->width > API_AVIF_MAX_SIDE || img->height > API_AVIF_MAX_SIDE)
		return api_problem_set(p, 422, "", "an AVIF is at most %u pixels a side; this image is %ux%u",
		                       API_AVIF_MAX_SIDE, img->width, img->height);
	if (!avifCodecName(AVIF_CODEC_CHOICE_AOM, AVIF_CODEC_FLAG_CAN_ENCODE))
		return api_problem_set(p, 500, "", "AVIF encoder: this libavif has no AV1 encoder (libaom)");
	return API_OK;
}

enum api_result api_avif_encode(const struct rnd_image *img, float quality, uint8_t **out, size_t *len,
                                struct api_problem *p)
{
	struct api_problem scratch;
	if (!p) p = &scratch;
	if (check_image(img, out, len, p) != API_OK) return API_ERR;
	bool lossless = quality < 0;
	enum api_result r = API_OK;
	avifRWData data = AVIF_DATA_EMPTY;
	avifEncoder *enc = NULL;
	avifImage *image = avifImageCreate(img->width, img->height, 8, lossless ? AVIF_PIXEL_FORMAT_YUV444 : LOSSY_YUV);
	if (!image) return api_problem_set(p, 500, "", "AVIF encoder: out of memory");
	image->colorPrimaries = AVIF_COLOR_PRIMARIES_BT709;
	image->transferCharacteristics = AVIF_TRANSFER_CHARACTERISTICS_SRGB;
	image->matrixCoefficients = lossless ? AVIF_MATRIX_COEFFICIENTS_IDENTITY : AVIF_MATRIX_COEFFICIENTS_BT601;
	image->yuvRange = AVIF_RANGE_FULL;
	avifRGBImage rgb;
	avifRGBImageSetDefaults(&rgb, image);
	rgb.format = AVIF_RGB_FORMAT_RGBA;
	rgb.depth = 8;
	rgb.ignoreAlpha = opaque(img);
	rgb.pixels = (uint8_t *)img->pixels;
	rgb.rowBytes = (uint32_t)img->stride;
	avifResult ar = avifImageRGBToYUV(image, &rgb);
	if (ar != AVIF_RESULT_OK) {
		r = api_problem_set(p, 500, "", "AVIF encoder: converting to YUV: %s", avifResultToString(ar));
		goto done;
	}
	enc = avifEncoderCreate();
	if (!enc) {
		r = api_problem_set(p, 500, "", "AVIF encoder: out of memory");
		goto done;
	}
	enc->codecChoice = AVIF_CODEC_CHOICE_AOM;
	enc->maxThreads = 1;
	enc->speed = SPEED;
	enc->minQuantizer = enc->maxQuantizer = lossless ? AVIF_QUANTIZER_LOSSLESS : quantizer_of(quality);
	enc->minQuantizerAlpha = enc->maxQuantizerAlpha = AVIF_QUANTIZER_LOSSLESS;
	ar = avifEncoderWrite(enc, image, &data);
	if (ar != AVIF_RESULT_OK) {
		r = api_problem_set(p, 500, "", "AVIF encoder: %s%s%s", avifResultToString(ar), enc->diag.error[0] ? ": " : "",
		                    enc->diag.error);
		goto done;
	}
	*out = malloc(data.size);
	if (!*out) {
		r = api_problem_set(p, 500, "", "AVIF encoder: out of memory");
		goto done;
	}
	memcpy(*out, data.data, data.size);
	*len = data.size;
done:
	avifRWDataFree(&data);
	if (enc) avifEncoderDestroy(enc);   /* not NULL-safe in 0.11 */
	avifImageDestroy(image);
	return r;
}
