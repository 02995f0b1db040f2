/* tests/unit — mip chains built on the CPU (renderer/texture.c): level count and bytes, a
 * black/white checker averaged in linear light for sRGB (188, not 128) and in the stored
 * values for linear data (128), an odd side folding its last texel in, the memory estimate
 * counting each texture's chain twice (image and staging), and the time to build a 2048^2
 * chain (printed, not asserted). */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "test.h"
#include "texture.h"
#include "estimate.h"

TEST(texture_levels_and_chain_bytes)
{
	CHECK(rnd_texture_levels(1, 1) == 1, "1x1: %u levels", rnd_texture_levels(1, 1));
	CHECK(rnd_texture_levels(2048, 2048) == 12, "2048^2: %u levels", rnd_texture_levels(2048, 2048));
	CHECK(rnd_texture_levels(5, 3) == 3, "5x3: %u levels", rnd_texture_levels(5, 3));
	/* 4x2 + 2x1 + 1x1 texels */
	CHECK(rnd_texture_chain_bytes(4, 2) == (8 + 2 + 1) * 4, "4x2 chain %llu bytes",
	      (unsigned long long)rnd_texture_chain_bytes(4, 2));
}

TEST(texture_checker_averages_in_linear_light)
{
	uint8_t in[4 * 4 * 4], out[(16 + 4 + 1) * 4];
	for (int i = 0; i < 16; i++) {
		uint8_t v = ((i & 3) + (i >> 2)) & 1 ? 255 : 0;
		in[4 * i] = in[4 * i + 1] = in[4 * i + 2] = v;
		in[4 * i + 3] = v;   /* alpha averages linearly in both */
	}
	rnd_texture_build_chain(in, 4, 4, true, out);
	CHECK(!memcmp(out, in, sizeof in), "level 0 is not the image");
	/* linear 0.5 encodes to sRGB 0.7354 = 187.5 -> 188 */
	for (int i = 16; i < 21; i++)
		CHECK(abs(out[4 * i] - 188) <= 1 && abs(out[4 * i + 3] - 128) <= 1, "sRGB texel %d: %u alpha %u (want 188, 128)",
		      i, out[4 * i], out[4 * i + 3]);
	rnd_texture_build_chain(in, 4, 4, false, out);
	for (int i = 16; i < 21; i++) CHECK(abs(out[4 * i] - 128) <= 1, "linear texel %d: %u (want 128)", i, out[4 * i]);
}

TEST(texture_odd_side_folds_last_texel_in)
{
	/* 3x1: 0, 0, 255 (linear data) -> one texel of the three: 85 */
	uint8_t in[12] = {0, 0, 0, 0, 0, 0, 0, 0, 255, 255, 255, 255}, out[16];
	rnd_texture_build_chain(in, 3, 1, false, out);
	CHECK(rnd_texture_levels(3, 1) == 2 && out[12] == 85, "3x1 -> %u (want 85)", out[12]);
}

TEST(texture_chain_of_2048_timing)
{
	uint32_t w = 2048;
	uint8_t *in = malloc((size_t)w * w * 4), *out = malloc(rnd_texture_chain_bytes(w, w));
	if (!in || !out) { free(in); free(out); CHECK(0, "out of memory"); return; }
	for (size_t i = 0; i < (size_t)w * w * 4; i++) in[i] = (uint8_t)(i * 2654435761u >> 24);
	struct timespec a, b;
	clock_gettime(CLOCK_MONOTONIC, &a);
	rnd_texture_build_chain(in, w, w, true, out);
	clock_gettime(CLOCK_MONOTONIC, &b);
	printf("    2048^2 sRGB chain: %.1f ms, %llu bytes (%.3f x the image)\n",
	       (b.tv_sec - a.tv_sec) * 1e3 + (b.tv_nsec - a.tv_nsec) / 1e6, (unsigned long long)rnd_texture_chain_bytes(w, w),
	       (double)rnd_texture_chain_bytes(w, w) / ((double)w * w * 4));
	CHECK(out[(size_t)w * w * 4] != 0 || out[(size_t)w * w * 4 + 1] != 0, "level 1 is empty");
	free(in);
	free(out);
}

TEST(texture_estimate_counts_mip_chains)
{
	static uint8_t texels[4];
	struct rnd_texture t = {.rgba = texels, .width = 1024, .height = 512};
	struct rnd_material m[2];
	rnd_material_defaults(&m[0]);
	rnd_material_defaults(&m[1]);
	m[1].base_color_texture = &t;
	struct rnd_scene sc;
	memset(&sc, 0, sizeof sc);
	sc.width = sc.height = 64;
	sc.materials = m;
	sc.material_count = 1;
	struct rnd_estimate a, b;
	rnd_estimate_scene(&sc, 2048, &a);
	sc.material_count = 2;
	rnd_estimate_scene(&sc, 2048, &b);
	uint64_t chain = rnd_texture_chain_bytes(1024, 512), image = 1024 * 512 * 4;
	/* 1024x512, 512x256, ... 2x1, 1x1: 4 bytes a texel */
	CHECK(chain == 2796204 && image == 2097152, "chain %llu", (unsigned long long)chain);
	CHECK(b.device_bytes - a.device_bytes == 2 * chain, "a 1024x512 texture adds %llu bytes, want 2 x %llu",
	      (unsigned long long)(b.device_bytes - a.device_bytes), (unsigned long long)chain);
}
