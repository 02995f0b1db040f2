/*
 * api/encode_exr — OpenEXR (scanline, ZIP) through OpenEXR's C core into a memory buffer.
 *
 * Channels: R, G, B, A as HALF from the RGBA32F image (linear, scene-referred), then one FLOAT
 * channel per AOV plane under the renderer's name ("shadow.0", "Z", "N.X", "albedo.R", ...).
 * One view: a single-part file. Several views (a sheet, rnd_image.view_count > 1): a multi-part
 * file with one part per view, named "view0", "view1", ... in view order, each view_width x
 * view_height with the same channels, cut from the view's cell of the sheet (and of every AOV
 * plane, which has the sheet's layout); unused cells of the sheet are not written.
 * The library writes at explicit offsets (the chunk table is patched at the end), so the
 * write callback grows the buffer to offset + size and copies there.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <openexr.h>
#include "api.h"

struct exr_mem {
	uint8_t *data;
	size_t len, cap;
};

struct exr_job {
	struct exr_mem buf;
	char msg[200];        /* the first message of the library's error handler */
};

static int64_t mem_write(exr_const_context_t ctx, void *user, const void *src, uint64_t sz, uint64_t offset,
                         exr_stream_error_func_ptr_t error_cb)
{
	struct exr_job *job = user;
	struct exr_mem *b = &job->buf;
	if (offset > SIZE_MAX / 2 || sz > SIZE_MAX / 2) {
		error_cb(ctx, EXR_ERR_OUT_OF_MEMORY, "EXR too large");
		return -1;
	}
	size_t end = (size_t)offset + (size_t)sz;
	if (end > b->cap) {
		size_t cap = b->cap ? b->cap : 65536;
		while (cap < end) cap *= 2;
		uint8_t *d = realloc(b->data, cap);
		if (!d) {
			error_cb(ctx, EXR_ERR_OUT_OF_MEMORY, "out of memory");
			return -1;
		}
		/* Gaps (never expected) read as zeros rather than as old heap contents. */
		memset(d + b->cap, 0, cap - b->cap);
		b->data = d;
		b->cap = cap;
	}
	memcpy(b->data + offset, src, (size_t)sz);
	if (end > b->len) b->len = end;
	return (int64_t)sz;
}

static void on_error(exr_const_context_t ctx, exr_result_t code, const char *msg)
{
	struct exr_job *job = NULL;
	if (exr_get_user_data(ctx, (void **)&job) == EXR_ERR_SUCCESS && job && !job->msg[0])
		snprintf(job->msg, sizeof job->msg, "%s (%s)", msg ? msg : "", exr_get_error_code_as_string(code));
}

/* IEEE binary32 -> binary16, round to nearest even; overflow -> inf, NaN kept NaN. */
static uint16_t float_to_half(float f)
{
	uint32_t x;
	memcpy(&x, &f, 4);
	uint32_t sign = (x >> 16) & 0x8000u;
	uint32_t mag = x & 0x7fffffffu;
	if (mag >= 0x7f800000u) /* inf or NaN */
		return (uint16_t)(sign | 0x7c00u | (mag > 0x7f800000u ? 0x200u | ((mag >> 13) & 0x3ffu) : 0));
	if (mag >= 0x477ff000u) /* rounds to >= 65520: inf */
		return (uint16_t)(sign | 0x7c00u);
	if (mag < 0x38800000u) { /* below the smallest normal half: subnormal or zero */
		if (mag < 0x33000000u) return (uint16_t)sign; /* < half of the smallest subnormal */
		uint32_t e = mag >> 23;
		uint32_t m = (mag & 0x7fffffu) | 0x800000u;
		uint32_t shift = 126 - e; /* value m * 2^(e - 150) = h * 2^-24 */
		uint32_t h = m >> (shift);
		uint32_t rem = m & ((1u << shift) - 1);
		uint32_t halfway = 1u << (shift - 1);
		if (rem > halfway || (rem == halfway && (h & 1))) h++;
		return (uint16_t)(sign | h);
	}
	uint32_t h = ((mag - 0x38000000u) >> 13);
	uint32_t rem = mag & 0x1fffu;
	if (rem > 0x1000u || (rem == 0x1000u && (h & 1))) h++;
	return (uint16_t)(sign | h);
}

static const char *const RGBA_NAMES[4] = {"R", "G", "B", "A"};

/* 500 unless img is an RGBA32F image (one view or a sheet) whose AOV planes the EXR can hold. */
static enum api_result check_image(const struct rnd_image *img, uint32_t naov, struct api_problem *p)
{
	if (!img || !img->pixels || !img->width || !img->height)
		return api_problem_set(p, 500, "", "EXR encoder: empty image");
	if (img->format != RND_PIXELS_RGBA32F)
		return api_problem_set(p, 500, "", "EXR encoder: the image is not RGBA32F");
	if (img->width > INT32_MAX / 4 || img->height > INT32_MAX / 4 || img->stride < (size_t)img->width * 16)
		return api_problem_set(p, 500, "", "EXR encoder: bad image size or stride");
	for (uint32_t i = 0; i < naov; i++) {
		if (!img->aov[i] || !img->aov_names[i][0] || !memchr(img->aov_names[i], 0, sizeof img->aov_names[i]))
			return api_problem_set(p, 500, "", "EXR encoder: AOV plane %u has no data or no name", i);
		for (uint32_t k = 0; k < 4; k++)
			if (!strcmp(img->aov_names[i], RGBA_NAMES[k]))
				return api_problem_set(p, 500, "", "EXR encoder: AOV plane %u is named like a colour channel", i);
		for (uint32_t k = 0; k < i; k++)
			if (!strcmp(img->aov_names[i], img->aov_names[k]))
				return api_problem_set(p, 500, "", "EXR encoder: AOV name \"%s\" appears twice",
				                       img->aov_names[i]);
	}
	return API_OK;
}

/* The image's views: one part per view ("view0", "view1", ...), each the view's cell of the sheet. */
struct exr_views { uint32_t n, cols, w, h; };

static enum api_result views_of(const struct rnd_image *img, struct exr_views *v, struct api_problem *p)
{
	v->n = img->view_count ? img->view_count : 1;
	v->cols = img->view_columns ? img->view_columns : 1;
	v->w = img->view_width ? img->view_width : img->width;
	v->h = img->view_height ? img->view_height : img->height;
	if (v->n <= 1) {
		v->w = img->width;
		v->h = img->height;
		return API_OK;
	}
	uint32_t rows = (v->n + v->cols - 1) / v->cols;
	if (v->n > RND_MAX_VIEWS || !v->cols || (uint64_t)v->cols * v->w > img->width ||
	    (uint64_t)rows * v->h > img->height)
		return api_problem_set(p, 500, "", "EXR encoder: %u views of %ux%u in %u columns do not fit a %ux%u sheet",
		                       v->n, v->w, v->h, v->cols, img->width, img->height);
	return API_OK;
}

/* One part per view, each with R, G, B, A (half) and the AOV planes (float), then the header. */
static exr_result_t add_parts(exr_context_t ctx, const struct rnd_image *img, uint32_t naov,
                              const struct exr_views *v)
{
	exr_result_t rv = EXR_ERR_SUCCESS;
	for (uint32_t k = 0; rv == EXR_ERR_SUCCESS && k < v->n; k++) {
		char name[16] = "";
		if (v->n > 1) snprintf(name, sizeof name, "view%u", k);
		int part = 0;
		rv = exr_add_part(ctx, name, EXR_STORAGE_SCANLINE, &part);
		if (rv == EXR_ERR_SUCCESS)
			rv = exr_initialize_required_attr_simple(ctx, part, (int32_t)v->w, (int32_t)v->h, EXR_COMPRESSION_ZIP);
		for (int c = 0; rv == EXR_ERR_SUCCESS && c < 4; c++)
			rv = exr_add_channel(ctx, part, RGBA_NAMES[c], EXR_PIXEL_HALF, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
		for (uint32_t i = 0; rv == EXR_ERR_SUCCESS && i < naov; i++)
			rv = exr_add_channel(ctx, part, img->aov_names[i], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
	}
	if (rv == EXR_ERR_SUCCESS) rv = exr_write_header(ctx);
	return rv;
}

/* Points each channel of the chunk whose first pixel is sheet index `first` at its plane: the
 * planar half copies of R, G, B, A, or an AOV plane. The library lists channels sorted by name:
 * each is matched by name. */
static void bind_channels(exr_encode_pipeline_t *enc, const struct rnd_image *img, uint32_t naov,
                          const uint16_t *half, size_t first)
{
	const size_t W = img->width, H = img->height;
	for (int16_t c = 0; c < enc->channel_count; c++) {
		exr_coding_channel_info_t *ch = &enc->channels[c];
		const uint8_t *src = NULL;
		for (int k = 0; k < 4 && !src; k++)
			if (!strcmp(ch->channel_name, RGBA_NAMES[k]))
				src = (const uint8_t *)(half + (size_t)k * W * H + first);
		if (src) {
			ch->user_bytes_per_element = 2;
			ch->user_data_type = EXR_PIXEL_HALF;
			ch->user_pixel_stride = 2;
			ch->user_line_stride = (int32_t)(W * 2);
		} else {
			for (uint32_t i = 0; i < naov && !src; i++)
				if (!strcmp(ch->channel_name, img->aov_names[i]))
					src = (const uint8_t *)(img->aov[i] + first);
			ch->user_bytes_per_element = 4;
			ch->user_data_type = EXR_PIXEL_FLOAT;
			ch->user_pixel_stride = 4;
			ch->user_line_stride = (int32_t)(W * 4);
		}
		ch->encode_from_ptr = src;
	}
}

/* Writes part `part` (view `part` of the sheet) chunk by chunk; its pipeline is destroyed. */
static exr_result_t write_part(exr_context_t ctx, uint32_t part, const struct rnd_image *img, uint32_t naov,
                               const uint16_t *half, const struct exr_views *v)
{
	/* The cell's top-left pixel in the sheet. */
	const size_t x0 = (size_t)(part % v->cols) * v->w, y0 = (size_t)(part / v->cols) * v->h;
	exr_encode_pipeline_t enc = {0};
	bool enc_live = false;
	int32_t lines = 0;
	exr_result_t rv = exr_get_scanlines_per_chunk(ctx, (int)part, &lines);
	for (int32_t y = 0; rv == EXR_ERR_SUCCESS && y < (int32_t)v->h; y += lines) {
		exr_chunk_info_t ci;
		rv = exr_write_scanline_chunk_info(ctx, (int)part, y, &ci);
		if (rv != EXR_ERR_SUCCESS) break;
		rv = enc_live ? exr_encoding_update(ctx, (int)part, &ci, &enc)
		              : exr_encoding_initialize(ctx, (int)part, &ci, &enc);
		if (rv != EXR_ERR_SUCCESS) break;
		bind_channels(&enc, img, naov, half, (y0 + (size_t)ci.start_y) * img->width + x0);
		if (!enc_live) {
			enc_live = true;
			rv = exr_encoding_choose_default_routines(ctx, (int)part, &enc);
			if (rv != EXR_ERR_SUCCESS) break;
		}
		rv = exr_encoding_run(ctx, (int)part, &enc);
	}
	/* A pipeline belongs to one part. */
	if (enc_live) exr_encoding_destroy(ctx, &enc);
	return rv;
}

enum api_result api_exr_encode(const struct rnd_image *img, uint8_t **out, size_t *len, struct api_problem *p)
{
	struct api_problem scratch;
	if (!p) p = &scratch;
	if (!out || !len) return api_problem_set(p, 500, "", "EXR encoder: no output pointer");
	*out = NULL;
	*len = 0;
	uint32_t naov = img && img->aov_count > RND_MAX_AOV_PLANES ? RND_MAX_AOV_PLANES : img ? img->aov_count : 0;
	struct exr_views v;
	if (check_image(img, naov, p) != API_OK || views_of(img, &v, p) != API_OK) return API_ERR;
	const size_t W = img->width, H = img->height;
	/* Planar half copies of R, G, B, A: the core's packer then only copies rows. */
	uint16_t *half = malloc(W * H * 4 * sizeof(uint16_t));
	if (!half) return api_problem_set(p, 500, "", "EXR encoder: out of memory");
	for (size_t y = 0; y < H; y++) {
		const float *row = (const float *)(const void *)((const uint8_t *)img->pixels + y * img->stride);
		for (size_t x = 0; x < W; x++)
			for (size_t c = 0; c < 4; c++) half[c * W * H + y * W + x] = float_to_half(row[4 * x + c]);
	}

	struct exr_job job = {{0}};
	exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
	init.user_data = &job;
	init.write_fn = mem_write;
	init.error_handler_fn = on_error;
	init.zip_level = 3; /* 512x512: level 3 ~19 ms, 1 ~14 ms (+30% bytes), 6 ~34 ms (-25% bytes) */
	exr_context_t ctx = NULL;
	exr_result_t rv = exr_start_write(&ctx, "umbra.exr", EXR_WRITE_FILE_DIRECTLY, &init);
	if (rv == EXR_ERR_SUCCESS) rv = add_parts(ctx, img, naov, &v);
	for (uint32_t part = 0; rv == EXR_ERR_SUCCESS && part < v.n; part++) rv = write_part(ctx, part, img, naov, half, &v);
	exr_result_t fin = ctx ? exr_finish(&ctx) : EXR_ERR_SUCCESS;
	if (rv == EXR_ERR_SUCCESS) rv = fin;
	free(half);
	if (rv != EXR_ERR_SUCCESS) {
		free(job.buf.data);
		return api_problem_set(p, 500, "", "EXR encoder: %s", job.msg[0] ? job.msg : exr_get_default_error_message(rv));
	}
	*out = job.buf.data;
	*len = job.buf.len;
	return API_OK;
}
