/*
 * api/env_decode — an environment map file to reduced linear RGB floats (see env_map.h):
 * Radiance .hdr written here (the header, the new RLE scanlines and the flat ones with their
 * old run-length repeats; RGBE to float as Radiance and Blender read it, (m + 0.5) 2^(e - 136);
 * EXPOSURE lines are ignored, as Blender does) and OpenEXR through its C core (scanline parts:
 * part 0's R, G, B, or Y, in any pixel type and compression the core decodes). Both feed their
 * rows to the reducer as they come, so an 8k map never exists at full size in memory.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <openexr.h>
#include "env_map.h"

static enum api_result fail(char *err, size_t n, const char *msg)
{
	snprintf(err, n, "%s", msg);
	return API_ERR;
}

bool api_env_reducer_init(struct api_env_reducer *r, uint32_t w, uint32_t h)
{
	memset(r, 0, sizeof *r);
	r->w = w; r->h = h; r->f = 1;
	while (w / r->f > API_ENV_MAX_WIDTH && h / (2 * r->f) >= 1) r->f *= 2;
	r->ow = w / r->f; r->oh = h / r->f;
	if (!r->ow || !r->oh) return false;
	r->out = calloc((size_t)r->ow * r->oh * 3, sizeof(float));
	return r->out != NULL;
}

void api_env_reducer_row(struct api_env_reducer *r, uint32_t y, const float *rgb)
{
	uint32_t oy = y / r->f;
	if (oy >= r->oh) return;
	float k = 1.0f / (float)(r->f * r->f);
	float *o = r->out + (size_t)oy * r->ow * 3;
	for (uint32_t x = 0; x < r->ow * r->f; x++) {
		float *t = o + (x / r->f) * 3;
		for (int c = 0; c < 3; c++) {
			float v = rgb[3 * x + c];
			t[c] += (isfinite(v) && v > 0.0f ? v : 0.0f) * k;   /* no negative or infinite light */
		}
	}
}

/* ---- Radiance .hdr ---- */

bool api_env_is_hdr(const uint8_t *b, size_t len) { return len >= 2 && b[0] == '#' && b[1] == '?'; }

/* The line at *at (without its newline) into line; false at the end of the data. */
static bool next_line(const uint8_t *b, size_t len, size_t *at, char *line, size_t cap)
{
	size_t n = 0;
	if (*at >= len) return false;
	while (*at < len && b[*at] != '\n') {
		if (n + 1 < cap) line[n++] = (char)b[*at];
		(*at)++;
	}
	if (*at < len) (*at)++;
	line[n] = 0;
	return true;
}

/* The header up to the resolution line: sizes and the orientation (flip_y: rows from the
 * bottom, flip_x: columns from the right). */
static enum api_result hdr_header(const uint8_t *b, size_t len, size_t *at, uint32_t *w, uint32_t *h, bool *flip_y,
                                  bool *flip_x, char *err, size_t n)
{
	char line[256], ya[3], xa[3];
	for (bool first = true;; first = false) {
		if (!next_line(b, len, at, line, sizeof line)) return fail(err, n, "the Radiance header has no end");
		if (first) continue;   /* "#?RADIANCE" */
		if (!line[0]) break;
		if (!strncmp(line, "FORMAT=", 7) && strcmp(line + 7, "32-bit_rle_rgbe"))
			return fail(err, n, "only the RGBE format of Radiance .hdr is read (this file is 32-bit_rle_xyze)");
	}
	unsigned hh, ww;
	if (!next_line(b, len, at, line, sizeof line) || sscanf(line, "%2s %u %2s %u", ya, &hh, xa, &ww) != 4 ||
	    (ya[1] != 'Y' && ya[1] != 'y') || (xa[1] != 'X' && xa[1] != 'x'))
		return fail(err, n, "the Radiance resolution line is not \"-Y height +X width\"");
	if (!ww || !hh || ww > API_ENV_MAX_SIDE || hh > API_ENV_MAX_SIDE) {
		snprintf(err, n, "a %ux%u map: each side must be 1..%u", ww, hh, API_ENV_MAX_SIDE);
		return API_ERR;
	}
	*w = ww; *h = hh;
	*flip_y = ya[0] == '+';
	*flip_x = xa[0] == '-';
	return API_OK;
}

/* One scanline of w RGBE texels into rgbe. */
static enum api_result hdr_scanline(const uint8_t *b, size_t len, size_t *at, uint32_t w, uint8_t *rgbe, char *err,
                                    size_t n)
{
	size_t p = *at;
	if (w >= 8 && w < 0x8000 && p + 4 <= len && b[p] == 2 && b[p + 1] == 2 && !(b[p + 2] & 0x80)) {
		if ((uint32_t)(b[p + 2] << 8 | b[p + 3]) != w) return fail(err, n, "a Radiance scanline has the wrong width");
		p += 4;
		for (int c = 0; c < 4; c++)
			for (uint32_t x = 0; x < w;) {
				if (p >= len) return fail(err, n, "the Radiance data is cut short");
				uint32_t k = b[p++];
				bool run = k > 128;
				if (run) k -= 128;
				if (!k || x + k > w || p + (run ? 1 : k) > len) return fail(err, n, "a Radiance run is broken");
				for (uint32_t i = 0; i < k; i++) rgbe[4 * (x + i) + c] = run ? b[p] : b[p + i];
				p += run ? 1 : k;
				x += k;
			}
	} else {
		uint32_t shift = 0;
		for (uint32_t x = 0; x < w;) {
			if (p + 4 > len) return fail(err, n, "the Radiance data is cut short");
			const uint8_t *q = b + p;
			p += 4;
			if (q[0] == 1 && q[1] == 1 && q[2] == 1) {   /* old run-length: repeat the last texel */
				uint32_t k = (uint32_t)q[3] << shift;
				if (!x || shift > 16 || x + k > w) return fail(err, n, "a Radiance run is broken");
				for (uint32_t i = 0; i < k; i++) memcpy(rgbe + 4 * (x + i), rgbe + 4 * (x - 1), 4);
				x += k;
				shift += 8;
			} else {
				memcpy(rgbe + 4 * x, q, 4);
				x++;
				shift = 0;
			}
		}
	}
	*at = p;
	return API_OK;
}

enum api_result api_env_decode_hdr(const uint8_t *b, size_t len, struct api_env_reducer *r, char *err, size_t errsize)
{
	size_t at = 0;
	uint32_t w, h;
	bool flip_y, flip_x;
	if (hdr_header(b, len, &at, &w, &h, &flip_y, &flip_x, err, errsize) != API_OK) return API_ERR;
	uint8_t *rgbe = malloc((size_t)w * 4);
	float *row = malloc((size_t)w * 3 * sizeof(float));
	if (!rgbe || !row || !api_env_reducer_init(r, w, h)) {
		free(rgbe);
		free(row);
		return fail(err, errsize, "out of memory decoding the map");
	}
	enum api_result rc = API_OK;
	for (uint32_t y = 0; y < h && rc == API_OK; y++) {
		if ((rc = hdr_scanline(b, len, &at, w, rgbe, err, errsize)) != API_OK) break;
		for (uint32_t x = 0; x < w; x++) {
			const uint8_t *t = rgbe + 4 * (flip_x ? w - 1 - x : x);
			float f = t[3] ? ldexpf(1.0f, (int)t[3] - 136) : 0.0f;
			for (int c = 0; c < 3; c++) row[3 * x + c] = t[3] ? ((float)t[c] + 0.5f) * f : 0.0f;
		}
		api_env_reducer_row(r, flip_y ? h - 1 - y : y, row);
	}
	free(rgbe);
	free(row);
	return rc;
}

/* ---- OpenEXR ---- */

bool api_env_is_exr(const uint8_t *b, size_t len)
{
	return len >= 4 && b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01;
}

struct exr_src {
	const uint8_t *data;
	size_t len;
	char msg[160];
};

static int64_t exr_read(exr_const_context_t ctx, void *user, void *buf, uint64_t sz, uint64_t off,
                        exr_stream_error_func_ptr_t error_cb)
{
	struct exr_src *s = user;
	if (off >= s->len) return error_cb(ctx, EXR_ERR_READ_IO, "past the end"), -1;
	uint64_t n = s->len - off < sz ? s->len - off : sz;
	memcpy(buf, s->data + off, n);
	return (int64_t)n;
}

static int64_t exr_size(exr_const_context_t ctx, void *user)
{
	(void)ctx;
	return (int64_t)((struct exr_src *)user)->len;
}

static void exr_error(exr_const_context_t ctx, exr_result_t code, const char *msg)
{
	struct exr_src *s = NULL;
	(void)code;
	if (exr_get_user_data(ctx, (void **)&s) == EXR_ERR_SUCCESS && s && !s->msg[0]) snprintf(s->msg, sizeof s->msg, "%s", msg);
}

/* Which of the part's channels give R, G, B (Y: all three); false when it has neither. */
static bool exr_channels(const exr_attr_chlist_t *chl, int idx[3])
{
	idx[0] = idx[1] = idx[2] = -1;
	int y = -1;
	for (int i = 0; i < chl->num_channels; i++) {
		const char *nm = chl->entries[i].name.str;
		if (!strcmp(nm, "R")) idx[0] = i;
		else if (!strcmp(nm, "G")) idx[1] = i;
		else if (!strcmp(nm, "B")) idx[2] = i;
		else if (!strcmp(nm, "Y")) y = i;
	}
	if (idx[0] >= 0 && idx[1] >= 0 && idx[2] >= 0) return true;
	if (y < 0) return false;
	idx[0] = idx[1] = idx[2] = y;
	return true;
}

/* The chunks of part 0, one after the other, their rows into r; planes: a plane of lines x w per
 * channel of the part, idx the planes of R, G, B. */
static exr_result_t exr_rows(exr_context_t ctx, int w, int32_t y0, int32_t y1, int32_t lines, const int idx[3],
                             struct api_env_reducer *r, float *planes, float *row)
{
	exr_decode_pipeline_t dec = {0};
	bool live = false;
	exr_result_t rv = EXR_ERR_SUCCESS;
	for (int32_t y = y0; rv == EXR_ERR_SUCCESS && y <= y1; y += lines) {
		exr_chunk_info_t ci;
		if ((rv = exr_read_scanline_chunk_info(ctx, 0, y, &ci)) != EXR_ERR_SUCCESS) break;
		rv = live ? exr_decoding_update(ctx, 0, &ci, &dec) : exr_decoding_initialize(ctx, 0, &ci, &dec);
		if (rv != EXR_ERR_SUCCESS) break;
		/* every channel into its own plane (OpenEXR 3.1's routines cannot skip one) */
		for (int c = 0; c < dec.channel_count; c++) {
			exr_coding_channel_info_t *ch = &dec.channels[c];
			ch->decode_to_ptr = (uint8_t *)(planes + (size_t)c * lines * w);
			ch->user_pixel_stride = 4;
			ch->user_line_stride = 4 * w;
			ch->user_bytes_per_element = 4;
			ch->user_data_type = EXR_PIXEL_FLOAT;
		}
		if (!live && (rv = exr_decoding_choose_default_routines(ctx, 0, &dec)) != EXR_ERR_SUCCESS) break;
		live = true;
		if ((rv = exr_decoding_run(ctx, 0, &dec)) != EXR_ERR_SUCCESS) break;
		for (int32_t l = 0; l < ci.height; l++) {
			for (int x = 0; x < w; x++)
				for (int c = 0; c < 3; c++) row[3 * x + c] = planes[((size_t)idx[c] * lines + l) * w + x];
			api_env_reducer_row(r, (uint32_t)(ci.start_y + l - y0), row);
		}
	}
	if (live) exr_decoding_destroy(ctx, &dec);
	return rv;
}

enum api_result api_env_decode_exr(const uint8_t *b, size_t len, struct api_env_reducer *r, char *err, size_t errsize)
{
	struct exr_src src = {b, len, ""};
	exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
	init.user_data = &src;
	init.read_fn = exr_read;
	init.size_fn = exr_size;
	init.error_handler_fn = exr_error;
	exr_context_t ctx;
	if (exr_start_read(&ctx, "map.exr", &init) != EXR_ERR_SUCCESS) {
		snprintf(err, errsize, "not a readable OpenEXR file (%s)", src.msg[0] ? src.msg : "bad header");
		return API_ERR;
	}
	exr_storage_t storage;
	exr_attr_box2i_t dw;
	const exr_attr_chlist_t *chl = NULL;
	int32_t lines = 0;
	int idx[3];
	enum api_result rc = API_ERR;
	if (exr_get_storage(ctx, 0, &storage) != EXR_ERR_SUCCESS || storage != EXR_STORAGE_SCANLINE) {
		fail(err, errsize, "only scanline OpenEXR files are read (this one is tiled or deep): save it as scanline");
		goto out;
	}
	if (exr_get_data_window(ctx, 0, &dw) != EXR_ERR_SUCCESS || exr_get_channels(ctx, 0, &chl) != EXR_ERR_SUCCESS ||
	    exr_get_scanlines_per_chunk(ctx, 0, &lines) != EXR_ERR_SUCCESS || lines < 1) {
		snprintf(err, errsize, "a broken OpenEXR header (%s)", src.msg);
		goto out;
	}
	int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
	if (w < 1 || h < 1 || w > API_ENV_MAX_SIDE || h > API_ENV_MAX_SIDE) {
		snprintf(err, errsize, "a %lldx%lld map: each side must be 1..%u", (long long)w, (long long)h, API_ENV_MAX_SIDE);
		goto out;
	}
	if (!exr_channels(chl, idx)) {
		fail(err, errsize, "the OpenEXR file has no R, G, B (or Y) channels");
		goto out;
	}
	if (chl->num_channels > 64) {
		fail(err, errsize, "the OpenEXR file has more than 64 channels: an environment map needs R, G, B");
		goto out;
	}
	float *planes = malloc((size_t)chl->num_channels * lines * w * sizeof(float)), *row = malloc((size_t)w * 3 * sizeof(float));
	if (!planes || !row || !api_env_reducer_init(r, (uint32_t)w, (uint32_t)h)) {
		fail(err, errsize, "out of memory decoding the map");
	} else if (exr_rows(ctx, (int)w, dw.min.y, dw.max.y, lines, idx, r, planes, row) != EXR_ERR_SUCCESS) {
		snprintf(err, errsize, "the OpenEXR data cannot be decoded (%s)", src.msg[0] ? src.msg : "broken chunk");
	} else {
		rc = API_OK;
	}
	free(planes);
	free(row);
out:
	exr_finish(&ctx);
	return rc;
}
