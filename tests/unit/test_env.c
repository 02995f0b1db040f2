/* tests — the environment map without a GPU: renderer/env_analysis.c (bins, harmonics, median
 * cut), renderer/env_studio.c, api/env_decode.c (.hdr and .exr to floats) and the
 * `environment` members of api/scene_environment.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "api.h"
#include "env.h"
#include "env_analysis.h"
#include "env_map.h"
#include "envmaps.h"
#include "test.h"
#include "util.h"

/* E(n) / pi of harmonics sh at unit normal n */
static float sh_eval(float sh[9][3], const float n[3], int c)
{
	float y[9], e = 0;
	rnd_env_sh_basis(n, y);
	for (int i = 0; i < 9; i++) e += sh[i][c] * y[i];
	return e;
}

/* E(n) / pi by summation over the bins (the clamped cosine exactly). */
static float direct_irradiance(const struct rnd_env_bins *b, const float n[3])
{
	double e = 0;
	for (uint32_t y = 0; y < RND_ENV_BINS_H; y++)
		for (uint32_t x = 0; x < RND_ENV_BINS_W; x++) {
			float d[3];
			rnd_env_bin_dir((float)x + 0.5f, (float)y + 0.5f, d);
			float el = asinf(d[1]);
			double om = (2 * M_PI / RND_ENV_BINS_W) * (M_PI / RND_ENV_BINS_H) * cos(el);
			double c = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
			if (c > 0) e += b->rgb[y][x][1] * c * om;
		}
	return (float)(e / M_PI);
}

TEST(env_sh_of_a_white_sky_is_one_everywhere)
{
	static struct rnd_env_bins b;
	float *m = test_patch_map(64, 32, 0, 0, 1, 1.0f, 1.0f);
	rnd_env_bin(m, 64, 32, &b);
	free(m);
	float sh[9][3];
	rnd_env_sh(&b, sh);
	const float ns[4][3] = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {0.6f, 0, 0.8f}};
	for (int i = 0; i < 4; i++) CHECK(fabsf(sh_eval(sh, ns[i], 0) - 1.0f) < 0.01f, "n %d: %g", i, sh_eval(sh, ns[i], 0));
}

TEST(env_sh_matches_the_clamped_cosine_of_a_sky)
{
	/* a sky brighter above than below: smooth enough for order 2 (within a few % of its range) */
	static struct rnd_env_bins b;
	float *m = malloc(128 * 64 * 3 * sizeof(float));
	for (int y = 0; y < 64; y++)
		for (int x = 0; x < 128; x++)
			for (int c = 0; c < 3; c++) m[(y * 128 + x) * 3 + c] = y < 32 ? 1.0f + 0.5f * (float)(31 - y) / 31.0f : 0.2f;
	rnd_env_bin(m, 128, 64, &b);
	free(m);
	float sh[9][3];
	rnd_env_sh(&b, sh);
	const float ns[5][3] = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {0, 0.7071f, 0.7071f}, {0.5f, -0.5f, 0.7071f}};
	for (int i = 0; i < 5; i++) {
		float a = sh_eval(sh, ns[i], 1), d = direct_irradiance(&b, ns[i]);
		CHECK(fabsf(a - d) < 0.05f * 1.5f, "n %d: harmonics %g, summed %g", i, a, d);
	}
}

TEST(env_directions_find_a_bright_patch_and_share_the_light)
{
	static struct rnd_env_bins b;
	/* a patch 8 degrees wide at azimuth 30, elevation 40 on a faint sky: ~98 % of the light (0.75 of 0.763) */
	float *m = test_patch_map(256, 128, 30, 40, 8, 50.0f, 0.001f);
	rnd_env_bin(m, 256, 128, &b);
	free(m);
	struct rnd_env_dir d[40];
	uint32_t upper, n = rnd_env_directions(&b, 12, false, d, &upper);
	CHECK(n == 12 && upper == 12, "%u directions (%u upper)", n, upper);
	float want[3] = {cosf(40 * (float)M_PI / 180) * cosf(30 * (float)M_PI / 180), sinf(40 * (float)M_PI / 180),
	                 cosf(40 * (float)M_PI / 180) * sinf(30 * (float)M_PI / 180)};
	float sum = 0, on_patch = 0;
	for (uint32_t i = 0; i < n; i++) {
		sum += d[i].share;
		float c = d[i].dir[0] * want[0] + d[i].dir[1] * want[1] + d[i].dir[2] * want[2];
		if (c > cosf(8 * (float)M_PI / 180)) on_patch += d[i].share;
		CHECK(d[i].sin_radius > 0 && d[i].sin_radius <= 1, "radius %g", d[i].sin_radius);
	}
	CHECK(fabsf(sum - 1) < 1e-4f, "shares sum to %g", sum);
	CHECK(on_patch > 0.9f, "the patch's directions carry %g of the light", on_patch);
	/* a ground: the 12 above the horizon first, then 4 below it */
	n = rnd_env_directions(&b, 12, true, d, &upper);
	CHECK(upper == 12 && n == 16, "%u directions, %u upper", n, upper);
	for (uint32_t i = 0; i < n; i++) CHECK(i < upper ? d[i].dir[1] > 0 : d[i].dir[1] < 0, "dir %u y %g", i, d[i].dir[1]);
	/* a black map: none */
	memset(&b, 0, sizeof b);
	CHECK(rnd_env_directions(&b, 12, false, d, &upper) == 0, "a black map has no directions");
}

TEST(env_studio_lights_an_upward_surface_with_about_pi)
{
	static struct rnd_env_bins b;
	float *m = malloc(RND_ENV_STUDIO_W * RND_ENV_STUDIO_H * 3 * sizeof(float));
	rnd_env_studio(m, RND_ENV_STUDIO_W, RND_ENV_STUDIO_H);
	rnd_env_bin(m, RND_ENV_STUDIO_W, RND_ENV_STUDIO_H, &b);
	free(m);
	float up[3] = {0, 1, 0}, down[3] = {0, -1, 0};
	float e_up = direct_irradiance(&b, up), e_down = direct_irradiance(&b, down);
	CHECK(e_up > 0.8f && e_up < 1.3f, "E/pi facing up %g", e_up);
	CHECK(e_down > 0.1f && e_down < 0.4f, "E/pi facing down %g (the floor)", e_down);
	CHECK(b.rgb[10][10][0] == b.rgb[10][10][1] && b.rgb[10][10][1] == b.rgb[10][10][2], "neutral: no tint");
}

/* decode through the api, compare with the floats */
static void check_decoded(const float *m, uint32_t w, uint32_t h, const uint8_t *file, size_t n, float tol, const char *what)
{
	struct api_env_map *e;
	int status;
	char err[240];
	REQUIRE(api_env_map_get(file, n, &e, &status, err, sizeof err) == API_OK, "%s: %s", what, err);
	CHECK(e->width == w && e->height == h, "%s: %ux%u", what, e->width, e->height);
	float worst = 0;
	for (size_t i = 0; i < (size_t)w * h * 3 && e->width == w && e->height == h; i++) {
		float d = fabsf(e->rgb[i] - m[i]) / fmaxf(m[i], 1e-3f);
		if (d > worst) worst = d;
	}
	CHECK(worst < tol, "%s: relative error %g", what, worst);
	api_env_map_release(e);
}

TEST(env_hdr_decodes_flat_and_rle_scanlines)
{
	float *m = test_patch_map(64, 32, -40, 20, 30, 7.5f, 0.25f);
	m[3] = m[4] = m[5] = 1000.0f;   /* one bright texel: its own exponent (RGBE shares one per texel) */
	size_t n1, n2;
	uint8_t *flat = test_hdr_bytes(m, 64, 32, false, &n1), *rle = test_hdr_bytes(m, 64, 32, true, &n2);
	CHECK(n2 < n1, "run-length scanlines are smaller (%zu < %zu)", n2, n1);
	check_decoded(m, 64, 32, flat, n1, 0.01f, "flat");
	check_decoded(m, 64, 32, rle, n2, 0.01f, "rle");
	/* broken files: a 400 with a sentence, never a crash */
	struct api_env_map *e;
	int status;
	char err[240];
	rle[n2 - 40] = 0;   /* a run of length 0 */
	CHECK(api_env_map_get(rle, n2 - 20, &e, &status, err, sizeof err) == API_ERR && status == 400, "a cut file");
	CHECK(api_env_map_get((const uint8_t *)"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 2 +X 2\n", 44, &e, &status, err,
	                      sizeof err) == API_ERR && strstr(err, "RGBE"), "xyze: %s", err);
	CHECK(api_env_map_get((const uint8_t *)"PNG", 3, &e, &status, err, sizeof err) == API_ERR &&
	      strstr(err, "Radiance"), "not a map: %s", err);
	free(flat);
	free(rle);
	free(m);
}

TEST(env_exr_decodes_the_rgb_channels)
{
	const uint32_t w = 32, h = 16;
	float *m = test_patch_map(w, h, 100, -10, 40, 3.0f, 0.5f);
	float *rgba = malloc((size_t)w * h * 16);
	for (size_t i = 0; i < (size_t)w * h; i++) {
		memcpy(rgba + 4 * i, m + 3 * i, 12);
		rgba[4 * i + 3] = 1;
	}
	struct rnd_image img = {.width = w, .height = h, .view_count = 1, .view_columns = 1, .view_width = w,
	                        .view_height = h, .format = RND_PIXELS_RGBA32F, .stride = w * 16, .pixels = rgba};
	uint8_t *exr;
	size_t n;
	struct api_problem p;
	REQUIRE(api_exr_encode(&img, &exr, &n, &p) == API_OK, "%s", p.detail);
	check_decoded(m, w, h, exr, n, 0.002f, "exr (half)");
	free(exr);
	free(rgba);
	free(m);
}

TEST(env_wide_maps_are_reduced_to_2048)
{
	float *m = test_patch_map(4096, 8, 0, 0, 360, 2.0f, 2.0f);
	size_t n;
	uint8_t *f = test_hdr_bytes(m, 4096, 8, true, &n);
	struct api_env_map *e;
	int status;
	char err[240];
	REQUIRE(api_env_map_get(f, n, &e, &status, err, sizeof err) == API_OK, "%s", err);
	CHECK(e->width == 2048 && e->height == 4 && e->file_width == 4096, "%ux%u from %u", e->width, e->height, e->file_width);
	CHECK(fabsf(e->rgb[0] - 2.0f) < 0.02f, "a 2x2 box of 2.0 is %g", e->rgb[0]);
	api_env_map_release(e);
	free(f);
	free(m);
}
