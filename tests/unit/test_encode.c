/* tests — api/encode_png.c and api/encode_exr.c: round trips through libpng and OpenEXR's C core. */
#include <math.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
#include <openexr.h>
#include <png.h>
#include "api.h"
#include "test.h"

/* ---- PNG decoding (classic libpng API, raw samples, no transforms) ---- */

struct png_in {
	const uint8_t *data;
	size_t len, pos;
};

static void png_mem_read(png_structp png, png_bytep out, size_t n)
{
	struct png_in *in = png_get_io_ptr(png);
	if (n > in->len - in->pos) png_error(png, "read past end");
	memcpy(out, in->data + in->pos, n);
	in->pos += n;
}

struct decoded {
	uint32_t w, h;
	int depth, color_type, channels;
	uint8_t *pixels; /* raw PNG samples: 16-bit ones big-endian */
	size_t rowbytes;
};

static int png_decode(const uint8_t *data, size_t len, struct decoded *d)
{
	struct png_in in = {data, len, 0};
	memset(d, 0, sizeof *d);
	png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
	png_infop info = png_create_info_struct(png);
	png_bytep *volatile rows = NULL;
	if (setjmp(png_jmpbuf(png))) {
		png_destroy_read_struct(&png, &info, NULL);
		free(rows);
		free(d->pixels);
		d->pixels = NULL;
		return -1;
	}
	png_set_read_fn(png, &in, png_mem_read);
	png_read_info(png, info);
	d->w = png_get_image_width(png, info);
	d->h = png_get_image_height(png, info);
	d->depth = png_get_bit_depth(png, info);
	d->color_type = png_get_color_type(png, info);
	d->channels = png_get_channels(png, info);
	d->rowbytes = png_get_rowbytes(png, info);
	d->pixels = malloc(d->rowbytes * d->h);
	rows = malloc(sizeof(png_bytep) * d->h);
	for (uint32_t y = 0; y < d->h; y++) rows[y] = d->pixels + y * d->rowbytes;
	png_read_image(png, rows);
	png_read_end(png, NULL);
	png_destroy_read_struct(&png, &info, NULL);
	free(rows);
	return 0;
}

static uint32_t sample(const struct decoded *d, uint32_t x, uint32_t y, int c)
{
	const uint8_t *row = d->pixels + y * d->rowbytes;
	if (d->depth == 8) return row[x * (uint32_t)d->channels + (uint32_t)c];
	const uint8_t *s = row + 2 * (x * (uint32_t)d->channels + (uint32_t)c);
	return (uint32_t)s[0] << 8 | s[1];
}

static struct rnd_image make_image(uint32_t w, uint32_t h, enum rnd_pixel_format f, bool opaque)
{
	struct rnd_image img = {0};
	img.width = w;
	img.height = h;
	img.format = f;
	size_t bpc = f == RND_PIXELS_RGBA8 ? 1 : f == RND_PIXELS_RGBA16 ? 2 : 4;
	img.stride = (size_t)w * 4 * bpc + 8 * bpc; /* padded rows: the stride is honoured */
	img.pixels = calloc(h, img.stride);
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++)
			for (uint32_t c = 0; c < 4; c++) {
				uint32_t v = (x * 7 + y * 13 + c * 101) & 0xff;
				if (c == 3) v = opaque ? 255 : (x + y) & 0xff;
				uint8_t *row = (uint8_t *)img.pixels + y * img.stride;
				if (f == RND_PIXELS_RGBA8) row[4 * x + c] = (uint8_t)v;
				else if (f == RND_PIXELS_RGBA16)
					((uint16_t *)(void *)row)[4 * x + c] = (uint16_t)(c == 3 && opaque ? 65535 : v * 257 + x);
				else ((float *)(void *)row)[4 * x + c] = c == 3 ? (opaque ? 1.0f : 0.5f) : (float)v / 64.0f;
			}
	return img;
}

static void check_png_roundtrip(enum rnd_pixel_format f, bool opaque, int level)
{
	struct rnd_image img = make_image(37, 23, f, opaque);
	uint8_t *out = NULL;
	size_t len = 0;
	struct api_problem p;
	REQUIRE(api_png_encode(&img, level, &out, &len, &p) == API_OK, "%s", p.detail);
	REQUIRE(out && len > 8 && !memcmp(out, "\x89PNG\r\n\x1a\n", 8));
	struct decoded d;
	REQUIRE(png_decode(out, len, &d) == 0, "libpng could not read the PNG back");
	int depth = f == RND_PIXELS_RGBA16 ? 16 : 8;
	CHECK(d.w == 37 && d.h == 23 && d.depth == depth, "%ux%u depth %d", d.w, d.h, d.depth);
	CHECK(d.color_type == (opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA), "colour type %d", d.color_type);
	int bad = 0;
	for (uint32_t y = 0; y < img.height; y++)
		for (uint32_t x = 0; x < img.width; x++)
			for (int c = 0; c < d.channels; c++) {
				const uint8_t *row = (const uint8_t *)img.pixels + y * img.stride;
				uint32_t want = depth == 8 ? row[4 * x + (uint32_t)c]
				                           : ((const uint16_t *)(const void *)row)[4 * x + (uint32_t)c];
				if (sample(&d, x, y, c) != want && bad++ < 3)
					CHECK(0, "pixel %u,%u channel %d: %u, want %u", x, y, c, sample(&d, x, y, c), want);
			}
	CHECK(bad == 0, "%d samples differ", bad);
	free(d.pixels);
	free(out);
	rnd_image_release(&img);
}

TEST(png_roundtrip_8bit_rgba)  { check_png_roundtrip(RND_PIXELS_RGBA8, false, -1); }
TEST(png_roundtrip_8bit_rgb)   { check_png_roundtrip(RND_PIXELS_RGBA8, true, -1); }
TEST(png_roundtrip_16bit_rgba) { check_png_roundtrip(RND_PIXELS_RGBA16, false, 6); }
TEST(png_roundtrip_16bit_rgb)  { check_png_roundtrip(RND_PIXELS_RGBA16, true, 0); }

TEST(png_encode_dispatch_keeps_alpha_when_transparent)
{
	struct api_problem p;
	struct api_scene *s = NULL;
	const char *doc = "{\"camera\":{},\"objects\":[],\"output\":{\"transparent\":true,\"bit_depth\":16}}";
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s", p.detail);
	struct rnd_image img = make_image(8, 4, RND_PIXELS_RGBA16, true);
	uint8_t *out = NULL;
	size_t len = 0;
	REQUIRE(api_encode(s, &img, &out, &len, &p) == API_OK, "%s", p.detail);
	struct decoded d;
	REQUIRE(png_decode(out, len, &d) == 0);
	CHECK(d.color_type == PNG_COLOR_TYPE_RGBA && d.depth == 16, "transparent output keeps alpha");
	CHECK(sample(&d, 3, 2, 3) == 65535);
	free(d.pixels);
	free(out);
	/* A format the encoder cannot take is a 500, never a crash. */
	struct rnd_image f32 = make_image(4, 4, RND_PIXELS_RGBA32F, true);
	CHECK(api_png_encode(&f32, -1, &out, &len, &p) == API_ERR && p.status == 500 && out == NULL);
	rnd_image_release(&f32);
	rnd_image_release(&img);
	api_scene_free(s);
}

/* ---- EXR decoding ---- */

struct exr_in {
	const uint8_t *data;
	size_t len;
};

static int64_t exr_mem_read(exr_const_context_t ctx, void *user, void *buf, uint64_t sz, uint64_t off,
                            exr_stream_error_func_ptr_t err)
{
	(void)ctx;
	(void)err;
	struct exr_in *in = user;
	if (off >= in->len) return 0;
	if (sz > in->len - off) sz = in->len - off;
	memcpy(buf, in->data + off, sz);
	return (int64_t)sz;
}

static int64_t exr_mem_size(exr_const_context_t ctx, void *user)
{
	(void)ctx;
	return (int64_t)((struct exr_in *)user)->len;
}

static void exr_quiet(exr_const_context_t ctx, exr_result_t code, const char *msg)
{
	(void)ctx;
	(void)code;
	(void)msg;
}

/* Reads every channel of part `part` as float planes (names[i], planes[i]); returns the channel
 * count, or a negative value. *nparts gets the file's part count, pname the part's name ("" when
 * it has none), *comp its compression. */
static int exr_decode_part(const uint8_t *data, size_t len, int part, int *nparts, char pname[32],
                           exr_compression_t *comp, int *w, int *h, char names[48][32], int types[48],
                           float *planes[48])
{
	struct exr_in in = {data, len};
	exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
	init.user_data = &in;
	init.read_fn = exr_mem_read;
	init.size_fn = exr_mem_size;
	init.error_handler_fn = exr_quiet;
	exr_context_t ctx;
	if (exr_start_read(&ctx, "mem.exr", &init) != EXR_ERR_SUCCESS) return -1;
	*nparts = 0;
	exr_get_count(ctx, nparts);
	if (part >= *nparts) {
		exr_finish(&ctx);
		return -1;
	}
	const char *nm = NULL;
	pname[0] = 0;
	if (exr_get_name(ctx, part, &nm) == EXR_ERR_SUCCESS && nm) snprintf(pname, 32, "%s", nm);
	exr_get_compression(ctx, part, comp);
	exr_attr_box2i_t dw;
	exr_get_data_window(ctx, part, &dw);
	*w = dw.max.x - dw.min.x + 1;
	*h = dw.max.y - dw.min.y + 1;
	const exr_attr_chlist_t *chl;
	exr_get_channels(ctx, part, &chl);
	int n = chl->num_channels;
	for (int i = 0; i < n && i < 48; i++) {
		snprintf(names[i], 32, "%s", chl->entries[i].name.str);
		types[i] = chl->entries[i].pixel_type;
		planes[i] = calloc((size_t)*w * (size_t)*h, sizeof(float));
	}
	int32_t lines = 0;
	exr_get_scanlines_per_chunk(ctx, part, &lines);
	exr_decode_pipeline_t dec = {0};
	bool live = false;
	exr_result_t rv = EXR_ERR_SUCCESS;
	for (int y = dw.min.y; rv == EXR_ERR_SUCCESS && y <= dw.max.y; y += lines) {
		exr_chunk_info_t ci;
		rv = exr_read_scanline_chunk_info(ctx, part, y, &ci);
		if (rv) break;
		rv = live ? exr_decoding_update(ctx, part, &ci, &dec) : exr_decoding_initialize(ctx, part, &ci, &dec);
		if (rv) break;
		for (int c = 0; c < dec.channel_count; c++) {
			exr_coding_channel_info_t *ch = &dec.channels[c];
			int k = 0;
			while (k < n && strcmp(names[k], ch->channel_name)) k++;
			ch->decode_to_ptr = (uint8_t *)(planes[k] + (size_t)(ci.start_y - dw.min.y) * (size_t)*w);
			ch->user_pixel_stride = 4;
			ch->user_line_stride = 4 * *w;
			ch->user_bytes_per_element = 4;
			ch->user_data_type = EXR_PIXEL_FLOAT;
		}
		if (!live) {
			live = true;
			rv = exr_decoding_choose_default_routines(ctx, part, &dec);
			if (rv) break;
		}
		rv = exr_decoding_run(ctx, part, &dec);
	}
	if (live) exr_decoding_destroy(ctx, &dec);
	exr_finish(&ctx);
	if (rv != EXR_ERR_SUCCESS) n = -(int)rv - 2;
	return n;
}

/* Part 0 of a single-part ZIP file (anything else is an error). */
static int exr_decode(const uint8_t *data, size_t len, int *w, int *h, char names[48][32], int types[48],
                      float *planes[48])
{
	int nparts = 0;
	char pname[32];
	exr_compression_t comp = EXR_COMPRESSION_NONE;
	int n = exr_decode_part(data, len, 0, &nparts, pname, &comp, w, h, names, types, planes);
	if (n >= 0 && (nparts != 1 || comp != EXR_COMPRESSION_ZIP)) n = -1;
	return n;
}

TEST(exr_roundtrip_rgba_and_aovs)
{
	const uint32_t W = 19, H = 37; /* several 16-line ZIP chunks, the last one partial */
	struct rnd_image img = make_image(W, H, RND_PIXELS_RGBA32F, false);
	const char *aov_names[] = {"shadow.0", "Z", "N.X", "albedo.R"};
	img.aov_count = 4;
	for (int a = 0; a < 4; a++) {
		snprintf(img.aov_names[a], sizeof img.aov_names[a], "%s", aov_names[a]);
		img.aov[a] = malloc(sizeof(float) * W * H);
		for (uint32_t i = 0; i < W * H; i++) img.aov[a][i] = (float)a * 1000.0f + (float)i * 0.125f;
	}
	img.aov[1][5] = INFINITY; /* Z where there is no geometry */
	/* Values half can hold exactly, rounding, overflow and subnormals. */
	float *px = img.pixels;
	px[0] = 1.0f; px[1] = 65504.0f; px[2] = 1e6f; px[3] = 0.0f;
	px[4] = 1.0f / 3.0f; px[5] = -2.5f; px[6] = 6.0e-8f; px[7] = 1.0f;

	uint8_t *out = NULL;
	size_t len = 0;
	struct api_problem p;
	REQUIRE(api_exr_encode(&img, &out, &len, &p) == API_OK, "%s", p.detail);
	REQUIRE(len > 4 && out[0] == 0x76 && out[1] == 0x2f && out[2] == 0x31 && out[3] == 0x01, "EXR magic");
	int w = 0, h = 0, types[48];
	char names[48][32];
	float *planes[48] = {0};
	int n = exr_decode(out, len, &w, &h, names, types, planes);
	REQUIRE(n == 8, "channels %d", n);
	CHECK(w == (int)W && h == (int)H);
	/* Channel list is sorted by name. */
	const char *sorted[] = {"A", "B", "G", "N.X", "R", "Z", "albedo.R", "shadow.0"};
	for (int i = 0; i < 8; i++) {
		CHECK(!strcmp(names[i], sorted[i]), "channel %d is %s, want %s", i, names[i], sorted[i]);
		bool colour = strlen(names[i]) == 1 && strchr("RGBA", names[i][0]);
		CHECK(types[i] == (colour ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT), "%s type %d", names[i], types[i]);
	}
	const float *R = planes[4], *G = planes[2], *B = planes[1], *A = planes[0], *Z = planes[5], *S = planes[7];
	CHECK(R[0] == 1.0f && G[0] == 65504.0f && isinf(B[0]) && A[0] == 0.0f, "%g %g %g %g", (double)R[0],
	      (double)G[0], (double)B[0], (double)A[0]);
	CHECK(fabsf(R[1] - 1.0f / 3.0f) < 1e-3f && G[1] == -2.5f && A[1] == 1.0f);
	CHECK(fabsf(B[1] - 5.96e-8f) < 1e-9f, "subnormal %g", (double)B[1]);
	/* Pixel (x=5, y=30) of the generated pattern, in the last partial chunk. */
	uint32_t x = 5, y = 30;
	for (int c = 0; c < 3; c++) {
		float want = (float)((x * 7 + y * 13 + (uint32_t)c * 101) & 0xff) / 64.0f;
		const float *plane = c == 0 ? R : c == 1 ? G : B;
		CHECK(fabsf(plane[y * W + x] - want) <= want * 1e-3f, "c%d %g want %g", c, (double)plane[y * W + x],
		      (double)want);
	}
	CHECK(A[y * W + x] == 0.5f);
	CHECK(S[y * W + x] == img.aov[0][y * W + x] && Z[7] == img.aov[1][7] && isinf(Z[5]), "float AOVs are exact");
	CHECK(planes[3][H * W - 1] == img.aov[2][H * W - 1] && planes[6][0] == img.aov[3][0]);
	for (int i = 0; i < 8; i++) free(planes[i]);
	free(out);

	/* Duplicate AOV names and a wrong pixel format are refused. */
	snprintf(img.aov_names[3], sizeof img.aov_names[3], "Z");
	CHECK(api_exr_encode(&img, &out, &len, &p) == API_ERR && p.status == 500 && !out);
	img.aov_count = 0;
	img.format = RND_PIXELS_RGBA8;
	CHECK(api_exr_encode(&img, &out, &len, &p) == API_ERR && !out);
	img.format = RND_PIXELS_RGBA32F;
	rnd_image_release(&img);
}

TEST(exr_encode_dispatch)
{
	struct api_problem p;
	struct api_scene *s = NULL;
	const char *doc = "{\"camera\":{},\"objects\":[],\"output\":{\"format\":\"exr\"}}";
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK, "%s", p.detail);
	struct rnd_image img = make_image(64, 64, RND_PIXELS_RGBA32F, true);
	uint8_t *out = NULL;
	size_t len = 0;
	REQUIRE(api_encode(s, &img, &out, &len, &p) == API_OK, "%s", p.detail);
	int w, h, types[48];
	char names[48][32];
	float *planes[48] = {0};
	int n = exr_decode(out, len, &w, &h, names, types, planes);
	CHECK(n == 4 && w == 64 && h == 64, "n %d", n);
	for (int i = 0; i < n && i < 48; i++) free(planes[i]);
	free(out);
	rnd_image_release(&img);
	api_scene_free(s);
}

/* A sheet of 5 views (3 columns, 2 rows, one unused cell) with two AOV planes: a multi-part
 * EXR whose part k ("view<k>") holds exactly cell k of the sheet and of every AOV plane. */
TEST(exr_multipart_views)
{
	const uint32_t VW = 7, VH = 21, COLS = 3, ROWS = 2, NV = 5; /* 21 lines: a partial 16-line chunk */
	struct rnd_image img = make_image(VW * COLS, VH * ROWS, RND_PIXELS_RGBA32F, false);
	img.view_count = NV;
	img.view_columns = COLS;
	img.view_width = VW;
	img.view_height = VH;
	const uint32_t W = img.width, H = img.height;
	/* Tag every pixel with its view and position: R = view, G = x in cell, B = y in cell. */
	for (uint32_t y = 0; y < H; y++)
		for (uint32_t x = 0; x < W; x++) {
			float *px = (float *)(void *)((uint8_t *)img.pixels + y * img.stride) + 4 * x;
			uint32_t v = (y / VH) * COLS + x / VW;
			px[0] = (float)v; px[1] = (float)(x % VW); px[2] = (float)(y % VH); px[3] = v < NV ? 1.0f : 0.0f;
		}
	const char *aov_names[] = {"Z", "shadow.0"};
	img.aov_count = 2;
	for (int a = 0; a < 2; a++) {
		snprintf(img.aov_names[a], sizeof img.aov_names[a], "%s", aov_names[a]);
		img.aov[a] = malloc(sizeof(float) * W * H);
		for (uint32_t i = 0; i < W * H; i++) img.aov[a][i] = (float)a * 100000.0f + (float)i + 0.25f;
	}
	img.aov[0][VW + 2] = INFINITY; /* view 1, pixel (2, 0) */

	uint8_t *out = NULL;
	size_t len = 0;
	struct api_problem p;
	REQUIRE(api_exr_encode(&img, &out, &len, &p) == API_OK, "%s", p.detail);
	for (int part = 0; part < (int)NV; part++) {
		int nparts = 0, w = 0, h = 0, types[48];
		char pname[32], names[48][32], want[32];
		exr_compression_t comp = EXR_COMPRESSION_NONE;
		float *planes[48] = {0};
		int n = exr_decode_part(out, len, part, &nparts, pname, &comp, &w, &h, names, types, planes);
		REQUIRE(n == 6, "part %d: channels %d", part, n);
		CHECK(nparts == (int)NV, "parts %d", nparts);
		snprintf(want, sizeof want, "view%d", part);
		CHECK(!strcmp(pname, want), "part %d is named \"%s\"", part, pname);
		CHECK(w == (int)VW && h == (int)VH && comp == EXR_COMPRESSION_ZIP, "part %d: %dx%d", part, w, h);
		const char *sorted[] = {"A", "B", "G", "R", "Z", "shadow.0"};
		for (int i = 0; i < 6; i++) CHECK(!strcmp(names[i], sorted[i]), "part %d channel %d %s", part, i, names[i]);
		const float *A = planes[0], *B = planes[1], *G = planes[2], *R = planes[3], *Z = planes[4], *S = planes[5];
		uint32_t x0 = (uint32_t)part % COLS * VW, y0 = (uint32_t)part / COLS * VH;
		int bad = 0;
		for (uint32_t y = 0; y < VH; y++)
			for (uint32_t x = 0; x < VW; x++) {
				size_t i = (size_t)y * VW + x, si = (size_t)(y0 + y) * W + x0 + x;
				if (R[i] != (float)part || G[i] != (float)x || B[i] != (float)y || A[i] != 1.0f) bad++;
				if (!(Z[i] == img.aov[0][si] || (isinf(Z[i]) && isinf(img.aov[0][si]))) || S[i] != img.aov[1][si]) bad++;
			}
		CHECK(bad == 0, "part %d: %d pixels differ from its cell", part, bad);
		if (part == 1) CHECK(isinf(Z[2]), "Z = +inf survives");
		for (int i = 0; i < n; i++) free(planes[i]);
	}
	free(out);

	/* One view: single part, unnamed, the whole image. */
	img.view_count = 1;
	img.view_columns = 1;
	img.view_width = W;
	img.view_height = H;
	REQUIRE(api_exr_encode(&img, &out, &len, &p) == API_OK, "%s", p.detail);
	int w, h, types[48];
	char names[48][32];
	float *planes[48] = {0};
	int n = exr_decode(out, len, &w, &h, names, types, planes);
	CHECK(n == 6 && w == (int)W && h == (int)H, "n %d %dx%d", n, w, h);
	for (int i = 0; i < n && i < 48; i++) free(planes[i]);
	free(out);

	/* A view layout that does not fit the image is refused. */
	img.view_count = 7;
	img.view_columns = 3;
	img.view_width = VW;
	img.view_height = VH;
	out = NULL;
	CHECK(api_exr_encode(&img, &out, &len, &p) == API_ERR && p.status == 500 && !out);
	rnd_image_release(&img);
}
