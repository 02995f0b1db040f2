/* tests/gpu — the glTF PBR extensions umbra draws (shaders/material_ext.glsl), each on the quad
 * of material_quad.h with its factors and its textures, the pixels against the extension's
 * maths done here: KHR_materials_specular and _ior (F0 and the specular weight),
 * KHR_materials_clearcoat (a second GGX lobe over the base, with its own roughness and
 * normal), KHR_materials_sheen (the Charlie lobe). Camera straight down, orthographic; the
 * base black, so the pixels are the specular lobes alone. Before, every one of these was
 * ignored: the quad drew 0.16 (specular test), 0.01 (clearcoat), ~0.007 (sheen). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "material_quad.h"
#include "models.h"
#include "test.h"
#include "util.h"

/* GGX (D x the height-correlated visibility) for alpha^2 = a2 at N.L = nl, N.V = nv, N.H = nh. */
static double ggx(double a2, double nl, double nv, double nh)
{
	double dd = nh * nh * (a2 - 1) + 1, D = a2 / (M_PI * dd * dd);
	double vis = 0.5 / (nl * sqrt(nv * nv * (1 - a2) + a2) + nv * sqrt(nl * nl * (1 - a2) + a2));
	return D * vis;
}

/* Texel t of a 2x2 texture: its centre's world point on the quad. */
static void texel_xz(int t, double *x, double *z)
{
	*x = -0.5 + (t & 1);
	*z = -0.5 + (t >> 1);
}

/* ---- KHR_materials_specular, KHR_materials_ior ---- */

/* Straight down, N = V = L = H: the GGX lobe is F0 x D x vis = F0 / (4 alpha^2), x pi (the
 * light) x 1/pi (D's): roughness 0.5 gives 4 F0. Factors: ior 2 (F0 1/9) x specular colour
 * (1, 0.5, 0.25) x specular 0.5. Textures (one image: specularColorTexture RGB, sRGB;
 * specularTexture A): ior 1.5 (0.04) x the texel's colour x its alpha. */
TEST(material_ext_specular_and_ior)
{
	static const uint8_t tex[16] = {255, 255, 255, 255, 255, 0, 0, 255, 255, 255, 255, 128, 0, 0, 255, 0};
	struct mglb f = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0,"
	                             "\"roughnessFactor\":0.5},\"extensions\":{\"KHR_materials_ior\":{\"ior\":2},"
	                             "\"KHR_materials_specular\":{\"specularFactor\":0.5,\"specularColorFactor\":[1,0.5,0.25]}}}",
	                 .extensions_used = "[\"KHR_materials_ior\",\"KHR_materials_specular\"]"};
	struct mglb t = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0,"
	                             "\"roughnessFactor\":0.5},\"extensions\":{\"KHR_materials_specular\":{"
	                             "\"specularTexture\":{\"index\":0},\"specularColorTexture\":{\"index\":0}}}}",
	                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
	                 .extensions_used = "[\"KHR_materials_specular\"]"};
	add_png(&t, tex, 2, 2);
	struct rnd_image fi, ti;
	bool ok = render_quad(__LINE__, &fi, &f, true, false);
	ok = ok && render_quad(__LINE__, &ti, &t, true, false);
	free_pngs(&t);
	if (!ok) return;
	static const double col[3] = {1, 0.5, 0.25};
	for (int c = 0; c < 3; c++) {
		double want = 4 * (1.0 / 9) * col[c] * 0.5, got = lin_at(&fi, false, 0.3, -0.4, c);
		printf("    factors, channel %d: %.4f (want %.4f)\n", c, got, want);
		CHECK(fabs(got - want) < 0.012, "factors: channel %d %.4f, want %.4f", c, got, want);
	}
	for (int k = 0; k < 4; k++) {
		double x, z;
		texel_xz(k, &x, &z);
		for (int c = 0; c < 3; c++) {
			double want = 4 * 0.04 * gpu_srgb_decode(tex[4 * k + c] / 255.0) * tex[4 * k + 3] / 255.0;
			double got = lin_at(&ti, false, x, z, c);
			CHECK(fabs(got - want) < 0.012, "texel %d channel %d: %.4f, want %.4f", k, c, got, want);
		}
	}
	rnd_image_release(&fi);
	rnd_image_release(&ti);
}

/* ---- KHR_materials_clearcoat ---- */

/* The coat over a black base of roughness 1 (its own lobe: 0.04 x 0.25 = 0.01), straight down:
 * coat x 0.04 / (4 alpha_c^2) + base x (1 - coat x 0.04). One image holds the coat (R) and its
 * roughness (G), linear: texels (1, 1), (0.502, 1), (0, 1), (1, 0.784), roughness factor 0.5.
 * A coat normal map tilted 45 degrees moves the coat's highlight away: N_c.L = N_c.V = 0.707. */
static double coat_straight(double coat, double rough)
{
	double a = rough * rough, a2 = a * a;
	return coat * 0.04 / (4 * a2) + 0.01 * (1 - coat * 0.04);
}

TEST(material_ext_clearcoat)
{
	static const uint8_t tex[16] = {255, 255, 0, 255, 128, 255, 0, 255, 0, 255, 0, 255, 255, 200, 0, 255};
	static const uint8_t tilted[4] = {218, 128, 218, 255}, flat[4] = {128, 128, 255, 255};
	const char *base = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0,\"roughnessFactor\":1},"
	                   "\"extensions\":{\"KHR_materials_clearcoat\":{\"clearcoatFactor\":1,\"clearcoatRoughnessFactor\":0.5%s}}}";
	char mats[3][400];
	snprintf(mats[0], sizeof mats[0], base, ",\"clearcoatTexture\":{\"index\":0},\"clearcoatRoughnessTexture\":{\"index\":0}");
	snprintf(mats[1], sizeof mats[1], base, ",\"clearcoatNormalTexture\":{\"index\":0}");
	snprintf(mats[2], sizeof mats[2], base, ",\"clearcoatNormalTexture\":{\"index\":0}");
	struct rnd_image img[3];
	int made = 0;
	for (; made < 3; made++) {
		struct mglb g = {.material = mats[made], .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
		                 .extensions_used = "[\"KHR_materials_clearcoat\"]"};
		if (made == 0) add_png(&g, tex, 2, 2);
		else add_png(&g, made == 1 ? flat : tilted, 1, 1);
		bool ok = render_quad(__LINE__, &img[made], &g, true, false);
		free_pngs(&g);
		if (!ok) break;
	}
	if (made == 3) {
		static const double coat[4] = {1, 128 / 255.0, 0, 1}, rough[4] = {0.5, 0.5, 0.5, 0.5 * 200 / 255.0};
		for (int k = 0; k < 4; k++) {
			double x, z;
			texel_xz(k, &x, &z);
			double want = coat_straight(coat[k], rough[k]), got = lin_at(&img[0], false, x, z, 1);
			printf("    texel %d: coat %.3f roughness %.3f: %.4f (want %.4f)\n", k, coat[k], rough[k], got, want);
			CHECK(fabs(got - want) < 0.012 + 0.03 * want, "texel %d: %.4f, want %.4f", k, got, want);
		}
		/* tilted 45 degrees: N_c.H = N_c.L = N_c.V = 0.707, V.H = 1; the base under a coat of
		 * Fresnel 0.04 + 0.96 (1 - 0.707)^5 */
		double c = sqrt(0.5), a2 = 0.0625, f = 0.04 + 0.96 * pow(1 - c, 5);
		double want_tilt = M_PI * 0.04 * ggx(a2, c, c, c) * c + 0.01 * (1 - f), want_flat = coat_straight(1, 0.5);
		double got_flat = lin_at(&img[1], false, 0.3, -0.4, 1), got_tilt = lin_at(&img[2], false, 0.3, -0.4, 1);
		printf("    coat normal map: flat %.4f (want %.4f), tilted 45 degrees %.4f (want %.4f)\n", got_flat, want_flat,
		       got_tilt, want_tilt);
		CHECK(fabs(got_flat - want_flat) < 0.015, "flat coat normal: %.4f, want %.4f", got_flat, want_flat);
		CHECK(fabs(got_tilt - want_tilt) < 0.006, "tilted coat normal: %.4f, want %.4f", got_tilt, want_tilt);
	}
	for (int k = 0; k < made; k++) rnd_image_release(&img[k]);
}

/* ---- KHR_materials_sheen ---- */

/* The sample viewer's sheen visibility: Estevez and Kulla's lambda, as its fit in alpha. */
static double lambda_fit(double x, double ag)
{
	double t = (1 - ag) * (1 - ag);
	double a = 21.5473 + (25.3245 - 21.5473) * t, b = 3.82987 + (3.32435 - 3.82987) * t;
	double c = 0.19823 + (0.16801 - 0.19823) * t, d = -1.97760 + (-1.27393 + 1.97760) * t;
	double e = -4.32054 + (-4.85967 + 4.32054) * t;
	return a / (1 + b * pow(x, c)) + d * x + e;
}

static double lambda(double c, double ag)
{
	return c < 0.5 ? exp(lambda_fit(c, ag)) : exp(2 * lambda_fit(0.5, ag) - lambda_fit(1 - c, ag));
}

/* The Charlie lobe (D x visibility) of roughness r at N.L = nl, N.V = nv, N.H = nh. */
static double charlie(double r, double nl, double nv, double nh)
{
	double ag = r * r, inv = 1 / ag;
	double D = (2 + inv) * pow(1 - nh * nh, 0.5 * inv) / (2 * M_PI);
	double vis = 1 / ((1 + lambda(nv, ag) + lambda(nl, ag)) * 4 * nv * nl);
	return D * fmin(fmax(vis, 0), 1);
}

/* Light at 60 degrees from the normal (N.L 0.5, N.H = V.H = 0.866: at N.H = 1 the Charlie
 * lobe is 0), intensity pi: sheen colour x lobe x pi x 0.5, plus the black base's GGX lobe
 * (0.0067) under a keep factor in 0..1 (its half is taken, within the tolerance). Factors:
 * colour (1, 0.5, 0.25), roughness 1; texture (sheenColorTexture RGB sRGB, roughness in A 255):
 * the colour x the texel. */
TEST(material_ext_sheen)
{
	static const uint8_t tex[16] = {255, 255, 255, 255, 255, 0, 0, 255, 0, 255, 0, 255, 128, 128, 128, 255};
	const char *light = "{'type':'directional','direction':[0.8660254,-0.5,0],'intensity':3.14159265}";
	struct mglb f = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0,"
	                             "\"roughnessFactor\":1},\"extensions\":{\"KHR_materials_sheen\":{"
	                             "\"sheenColorFactor\":[1,0.5,0.25],\"sheenRoughnessFactor\":1}}}",
	                 .extensions_used = "[\"KHR_materials_sheen\"]", .light = light};
	struct mglb t = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0,"
	                             "\"roughnessFactor\":1},\"extensions\":{\"KHR_materials_sheen\":{"
	                             "\"sheenColorFactor\":[1,1,1],\"sheenRoughnessFactor\":1,"
	                             "\"sheenColorTexture\":{\"index\":0},\"sheenRoughnessTexture\":{\"index\":0}}}}",
	                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
	                 .extensions_used = "[\"KHR_materials_sheen\"]", .light = light};
	add_png(&t, tex, 2, 2);
	struct rnd_image fi, ti;
	bool ok = render_quad(__LINE__, &fi, &f, true, false);
	ok = ok && render_quad(__LINE__, &ti, &t, true, false);
	free_pngs(&t);
	if (!ok) return;
	double nl = 0.5, nh = sqrt(0.75);
	double lobe = M_PI * nl * charlie(1, nl, 1, nh);
	double base = M_PI * nl * (0.04 + 0.96 * pow(1 - nh, 5)) * ggx(1, nl, 1, nh);
	static const double col[3] = {1, 0.5, 0.25};
	for (int c = 0; c < 3; c++) {
		double want = col[c] * lobe + 0.5 * base, got = lin_at(&fi, false, 0.3, -0.4, c);
		printf("    factors, channel %d: %.4f (want %.4f: lobe %.4f + base %.4f x keep)\n", c, got, want, col[c] * lobe, base);
		CHECK(fabs(got - want) < 0.01 + 0.5 * base, "factors: channel %d %.4f, want %.4f", c, got, want);
	}
	for (int k = 0; k < 4; k++) {
		double x, z;
		texel_xz(k, &x, &z);
		for (int c = 0; c < 3; c++) {
			double want = gpu_srgb_decode(tex[4 * k + c] / 255.0) * lobe + 0.5 * base, got = lin_at(&ti, false, x, z, c);
			CHECK(fabs(got - want) < 0.01 + 0.5 * base, "texel %d channel %d: %.4f, want %.4f", k, c, got, want);
		}
	}
	rnd_image_release(&fi);
	rnd_image_release(&ti);
}

/* ---- KHR_materials_pbrSpecularGlossiness ---- */

/* Drawn as the sample viewer draws it: F0 the specular colour, roughness 1 - glossiness, the
 * diffuse colour as the base. Straight down (N = V = L = H) a black diffuse gives the GGX lobe
 * alone, pi x F0 x D x vis. Factors: specular (1, 0.5, 0.25), glossiness 0.2 (roughness 0.8:
 * 0.61 F0). Texture (specularGlossinessTexture: RGB specular in sRGB, A glossiness 0.2, 0,
 * 0.3, 0.1): per texel. Under the ambient alone, a specular-glossiness metal (black diffuse,
 * that specular) is the metallic-roughness metal of that base colour: the ambient reflects
 * F0 as it does a metal's. Before, the specular colour and texture were ignored: the quad
 * drew the 0.04 dielectric's lobe, and the ambient none of it. */
#define SG_MAT(extra) "{\"extensions\":{\"KHR_materials_pbrSpecularGlossiness\":{\"diffuseFactor\":[0,0,0,1]," extra "}}}"
#define SG_USED "[\"KHR_materials_pbrSpecularGlossiness\"]"

static double sg_lobe(double f0, double rough)
{
	double a = rough * rough;
	return M_PI * f0 * ggx(a * a, 1, 1, 1);
}

TEST(material_ext_specular_glossiness)
{
	static const uint8_t tex[16] = {255, 255, 255, 51, 255, 128, 0, 0, 0, 200, 0, 77, 128, 128, 128, 26};
	struct mglb f = {.material = SG_MAT("\"specularFactor\":[1,0.5,0.25],\"glossinessFactor\":0.2"),
	                 .extensions_used = SG_USED};
	struct mglb t = {.material = SG_MAT("\"specularGlossinessTexture\":{\"index\":0}"),
	                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP, .extensions_used = SG_USED};
	add_png(&t, tex, 2, 2);
	struct mglb sa = f, ma = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0.5,0.25,1],"
	                                      "\"metallicFactor\":1,\"roughnessFactor\":0.8}}"};
	sa.ambient = ma.ambient = 1;
	struct rnd_image fi, ti, si, mi;
	bool ok = render_quad(__LINE__, &fi, &f, true, false);
	ok = ok && render_quad(__LINE__, &ti, &t, true, false);
	ok = ok && render_quad(__LINE__, &si, &sa, false, false) && render_quad(__LINE__, &mi, &ma, false, false);
	free_pngs(&t);
	if (!ok) return;
	static const double col[3] = {1, 0.5, 0.25};
	for (int c = 0; c < 3; c++) {
		double want = sg_lobe(col[c], 0.8), got = lin_at(&fi, false, 0.3, -0.4, c);
		double amb_sg = lin_at(&si, false, 0.3, -0.4, c), amb_mr = lin_at(&mi, false, 0.3, -0.4, c);
		printf("    factors, channel %d: %.4f (want %.4f); ambient alone: %.4f (metal %.4f)\n", c, got, want, amb_sg, amb_mr);
		CHECK(fabs(got - want) < 0.012 + 0.02 * want, "factors: channel %d %.4f, want %.4f", c, got, want);
		CHECK(amb_mr > 0.05 && fabs(amb_sg - amb_mr) < 0.01, "ambient: channel %d %.4f, the metal's %.4f", c, amb_sg, amb_mr);
	}
	for (int k = 0; k < 4; k++) {
		double x, z;
		texel_xz(k, &x, &z);
		double rough = fmax(1 - tex[4 * k + 3] / 255.0, 0.03);
		for (int c = 0; c < 3; c++) {
			double want = sg_lobe(gpu_srgb_decode(tex[4 * k + c] / 255.0), rough), got = lin_at(&ti, false, x, z, c);
			printf("    texel %d channel %d: %.4f (want %.4f)\n", k, c, got, want);
			CHECK(fabs(got - want) < 0.012 + 0.03 * want, "texel %d channel %d: %.4f, want %.4f", k, c, got, want);
		}
	}
	rnd_image_release(&fi);
	rnd_image_release(&ti);
	rnd_image_release(&si);
	rnd_image_release(&mi);
}
