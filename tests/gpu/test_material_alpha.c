/* tests/gpu — imported glTF materials that cover part of a surface: alpha BLEND (dithered
 * coverage and shadow), MASK on the second uv set in the camera and shadow passes,
 * KHR_materials_transmission (and _volume's tint) as partial coverage, and the mip chain of a
 * fine texture. The quad and its renders: material_quad.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "material_quad.h"
#include "models.h"
#include "test.h"
#include "util.h"

TEST(materials_blend_dithered_half_coverage_half_shadow)
{
	struct rnd_image op, bl, bl2;
	if (!blend_render(__LINE__, &op, false)) return;
	if (!blend_render(__LINE__, &bl, true)) { rnd_image_release(&op); return; }
	if (!blend_render(__LINE__, &bl2, true)) { rnd_image_release(&op); rnd_image_release(&bl); return; }
	/* the shadow alone: x in [1.1, 1.7] (the quad ends at x = 1 from above, its shadow at 1.8), lit: x in [2, 2.35] */
	double lit = mean_rect(&op, 2.0, 2.35, -0.6, 0.6, 0, 2);
	double sh_op = mean_rect(&op, 1.1, 1.7, -0.6, 0.6, 0, 2) , sh_bl = mean_rect(&bl, 1.1, 1.7, -0.6, 0.6, 0, 2);
	double share = (lit - sh_bl) / (lit - sh_op);
	/* the quad from above: red over [-0.9, 0.9]^2 (blue ground where dithered away) */
	double red_op = mean_rect(&op, -0.8, 0.8, -0.8, 0.8, 1, 0), red_bl = mean_rect(&bl, -0.8, 0.8, -0.8, 0.8, 1, 0);
	printf("    ground lit %.3f, under the opaque quad's shadow %.3f, under the blend quad's %.3f: shadow share %.2f\n",
	       lit, sh_op, sh_bl, share);
	printf("    quad red: opaque %.3f, blend %.3f (coverage %.2f)\n", red_op, red_bl, red_bl / red_op);
	CHECK(lit > 0.5 && sh_op < 0.1 * lit, "lit %.3f, opaque shadow %.3f", lit, sh_op);
	CHECK(share > 0.35 && share < 0.65, "a 50%% BLEND quad takes %.2f of the light", share);
	CHECK(red_bl / red_op > 0.4 && red_bl / red_op < 0.6, "blend coverage %.2f", red_bl / red_op);
	CHECK(bl.width == bl2.width && !memcmp(bl.pixels, bl2.pixels, bl.stride * bl.height),
	      "the dither differs between two renders of the same request");
	rnd_image_release(&op);
	rnd_image_release(&bl);
	rnd_image_release(&bl2);
}

/* alphaMode MASK with the base colour's alpha on TEXCOORD_1: a 2x1 texture, opaque | clear
 * (red), TEXCOORD_0 on the opaque texel everywhere, TEXCOORD_1 across (u = (x + 1) / 2). On
 * set 1 the quad's right half is cut in the camera pass (the blue ground shows) and in the
 * shadow pass (its shadow, x in [1.1, 1.7], is lit); on set 0 both are whole. */
TEST(materials_mask_alpha_on_the_second_uv_set)
{
	static const uint8_t tex[8] = {255, 0, 0, 255, 255, 0, 0, 0};
	static const float uv0[8] = {0.25f, 0.5f, 0.25f, 0.5f, 0.25f, 0.5f, 0.25f, 0.5f};
	static const float uv1[8] = {0, 0, 1, 0, 1, 1, 0, 1};
	for (int set = 0; set < 2; set++) {
		char mat[300];
		snprintf(mat, sizeof mat, "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"texCoord\":%d},"
		         "\"metallicFactor\":0,\"roughnessFactor\":1},\"alphaMode\":\"MASK\"}", set);
		struct mglb g = {.material = mat, .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
		                 .uv0 = uv0, .uv1 = uv1, .y = 1};
		add_png(&g, tex, 2, 1);
		struct rnd_image img;
		bool ok = quad_over_ground(__LINE__, &img, &g);
		free_pngs(&g);
		if (!ok) return;
		double left = mean_rect(&img, -0.8, -0.2, -0.6, 0.6, 1, 0), right = mean_rect(&img, 0.2, 0.8, -0.6, 0.6, 1, 0);
		double lit = mean_rect(&img, 2.0, 2.35, -0.6, 0.6, 0, 2), shadow = mean_rect(&img, 1.1, 1.7, -0.6, 0.6, 0, 2);
		printf("    texCoord %d: red left %.3f right %.3f; ground lit %.3f, under the right half %.3f\n", set, left,
		       right, lit, shadow);
		CHECK(left > 0.5, "texCoord %d: the left half is drawn (red %.3f)", set, left);
		if (set == 1) {
			CHECK(right < 0.05 && shadow > 0.9 * lit, "texCoord 1: right half red %.3f, its shadow %.3f of %.3f lit",
			      right, shadow, lit);
		} else {
			CHECK(right > 0.5 && shadow < 0.1 * lit, "texCoord 0: right half red %.3f, its shadow %.3f of %.3f lit",
			      right, shadow, lit);
		}
		rnd_image_release(&img);
	}
}

/* KHR_materials_transmission 1 on an opaque red quad: drawn as coverage 0.2 (dithered) that
 * lets 0.8 of the light through to its shadow; before, the glass was drawn opaque (coverage
 * 1, a full shadow). */
/* The red quad of `material` against the opaque red quad: the share of its red (the coverage
 * with the drawn pixels' colour) and the share of the light its shadow takes. */
static bool red_and_shadow(int line, const char *material, const char *extensions_used, double *red, double *share)
{
	struct rnd_image op, q;
	if (!blend_render(line, &op, false)) return false;
	if (!material_render(line, &q, material, extensions_used)) {
		rnd_image_release(&op);
		return false;
	}
	double lit = mean_rect(&op, 2.0, 2.35, -0.6, 0.6, 0, 2);
	double sh_op = mean_rect(&op, 1.1, 1.7, -0.6, 0.6, 0, 2), sh_q = mean_rect(&q, 1.1, 1.7, -0.6, 0.6, 0, 2);
	*share = (lit - sh_q) / (lit - sh_op);
	*red = mean_rect(&q, -0.8, 0.8, -0.8, 0.8, 1, 0) / mean_rect(&op, -0.8, 0.8, -0.8, 0.8, 1, 0);
	rnd_image_release(&op);
	rnd_image_release(&q);
	return true;
}

TEST(materials_transmission_as_partial_coverage)
{
	double red, share;
	if (!red_and_shadow(__LINE__,
	                    "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1],\"metallicFactor\":0,"
	                    "\"roughnessFactor\":1},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1}}}",
	                    "[\"KHR_materials_transmission\"]", &red, &share))
		return;
	printf("    transmission 1: coverage %.2f, shadow share %.2f\n", red, share);
	CHECK(red > 0.1 && red < 0.3, "transmission 1 coverage %.2f, want ~0.2", red);
	CHECK(share > 0.1 && share < 0.3, "transmission 1 takes %.2f of the light, want ~0.2", share);
}

/* transmissionTexture (R) times transmissionFactor 1, per pixel: a 1x2 texture, R 255 over
 * the quad's z < 0 half (coverage 0.2, 0.2 of the light stopped) and R 0 over the z > 0 half
 * (no transmission: opaque, a full shadow). Before, the texture was not read: both halves 0.2. */
TEST(materials_transmission_texture_per_pixel)
{
	static const uint8_t tex[8] = {255, 0, 0, 255, 0, 0, 0, 255};
	struct mglb g = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1],\"metallicFactor\":0,"
	                             "\"roughnessFactor\":1},\"extensions\":{\"KHR_materials_transmission\":{"
	                             "\"transmissionFactor\":1,\"transmissionTexture\":{\"index\":0}}}}",
	                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
	                 .extensions_used = "[\"KHR_materials_transmission\"]", .y = 1};
	add_png(&g, tex, 1, 2);
	struct rnd_image op, q;
	bool ok = blend_render(__LINE__, &op, false);
	ok = ok && quad_over_ground(__LINE__, &q, &g);
	free_pngs(&g);
	if (!ok) return;
	double lit = mean_rect(&op, 2.0, 2.35, -0.6, 0.6, 0, 2);
	for (int half = 0; half < 2; half++) {
		double z0 = half ? 0.2 : -0.8, z1 = half ? 0.8 : -0.2;
		double red = mean_rect(&q, -0.8, 0.8, z0, z1, 1, 0) / mean_rect(&op, -0.8, 0.8, z0, z1, 1, 0);
		double share = (lit - mean_rect(&q, 1.1, 1.7, z0, z1, 0, 2)) / (lit - mean_rect(&op, 1.1, 1.7, z0, z1, 0, 2));
		double want = half ? 1 : 0.2;
		printf("    R %d: coverage %.2f, shadow share %.2f (want %.1f)\n", half ? 0 : 255, red, share, want);
		CHECK(fabs(red - want) < 0.1, "R %d: coverage %.2f, want %.1f", half ? 0 : 255, red, want);
		CHECK(fabs(share - want) < 0.1, "R %d: shadow share %.2f, want %.1f", half ? 0 : 255, share, want);
	}
	rnd_image_release(&op);
	rnd_image_release(&q);
}

/* ---- mipmaps ---- */

/* A 256^2 black/white checker of single texels (sRGB 0 and 255: linear 0 and 1) as the
 * emissive texture of the quad, unlit: ~58 pixels show 256 texels, 4.4 texels a pixel. With
 * the mip chain every pixel reads a level where the checker has averaged out: linear 0.5
 * (sRGB 188) everywhere. Read from level 0 only (minFilter LINEAR, no mipmaps: what every
 * sampler did before), the pixels alias between black and white: the same mean over the
 * quad, but single pixels far from it. Two renders give the same bytes. */
TEST(materials_mipmaps_average_a_fine_checker)
{
	enum { CW = 256 };
	uint8_t *tex = malloc((size_t)CW * CW * 4);
	for (int y = 0; y < CW; y++)
		for (int x = 0; x < CW; x++) {
			uint8_t v = (x + y) & 1 ? 255 : 0, *p = tex + ((size_t)y * CW + x) * 4;
			p[0] = p[1] = p[2] = v;
			p[3] = 255;
		}
	static const char *const samplers[3] = {"[{\"wrapS\":33071,\"wrapT\":33071}]",
	                                        "[{\"wrapS\":33071,\"wrapT\":33071}]",
	                                        "[{\"minFilter\":9729,\"wrapS\":33071,\"wrapT\":33071}]"};
	struct rnd_image img[3];
	int made = 0;
	for (; made < 3; made++) {
		struct mglb g = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0},"
		                             "\"emissiveFactor\":[1,1,1],\"emissiveTexture\":{\"index\":0}}",
		                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = samplers[made]};
		add_png(&g, tex, CW, CW);
		bool ok = render_quad(__LINE__, &img[made], &g, false, false);
		free_pngs(&g);
		if (!ok) break;
	}
	free(tex);
	if (made == 3) {
		double mean[3] = {0, 0, 0}, dev[3] = {0, 0, 0};
		for (int k = 0; k < 3; k++) {
			int n = 0;
			for (int j = 0; j < 35; j++)
				for (int i = 0; i < 35; i++, n++) {
					double v = lin_at(&img[k], false, -0.85 + 0.05 * i, -0.85 + 0.05 * j, 1);
					mean[k] += v;
					dev[k] = fmax(dev[k], fabs(v - 0.5));
				}
			mean[k] /= n;
		}
		printf("    mipmapped: mean %.3f, largest |pixel - 0.5| %.3f; level 0 only: mean %.3f, largest %.3f\n",
		       mean[0], dev[0], mean[2], dev[2]);
		CHECK(fabs(mean[0] - 0.5) < 0.03, "mipmapped checker mean %.3f, want 0.5 (linear)", mean[0]);
		CHECK(dev[0] < 0.06, "a mipmapped pixel is %.3f from the checker's average", dev[0]);
		CHECK(dev[2] > 0.2, "minFilter LINEAR (no mipmaps) should read level 0 and alias; largest deviation %.3f",
		      dev[2]);
		CHECK(!memcmp(img[0].pixels, img[1].pixels, img[0].stride * img[0].height), "two renders differ");
	}
	for (int k = 0; k < made; k++) rnd_image_release(&img[k]);
}

/* KHR_materials_volume under transmission 1: attenuationColor 0.5 over attenuationDistance 1
 * through thicknessFactor 1 transmits T = 0.5, so the see-through share is 0.8 x 0.5: coverage
 * 0.6 (and 0.6 of the light stopped), the drawn pixels tinted by T, red 0.5: the quad's mean
 * red 0.3 of the opaque quad's. Before, the volume was ignored: 0.2 and 0.2. */
TEST(materials_volume_tints_and_thickens_transmission)
{
	double red, share;
	if (!red_and_shadow(__LINE__,
	                    "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1],\"metallicFactor\":0,"
	                    "\"roughnessFactor\":1},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
	                    "\"KHR_materials_volume\":{\"thicknessFactor\":1,\"attenuationDistance\":1,"
	                    "\"attenuationColor\":[0.5,0.5,0.5]}}}",
	                    "[\"KHR_materials_transmission\",\"KHR_materials_volume\"]", &red, &share))
		return;
	printf("    volume T 0.5: the quad's red %.2f of the opaque one's (want 0.3), shadow share %.2f (want 0.6)\n", red,
	       share);
	CHECK(red > 0.22 && red < 0.38, "volume: red %.2f of the opaque quad's, want ~0.3", red);
	CHECK(share > 0.48 && share < 0.72, "volume: takes %.2f of the light, want ~0.6", share);
}
