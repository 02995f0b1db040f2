/* tests/gpu — the glTF 2.0 material model of imported models: .glb files built here (one 2x2
 * quad, its material and textures given as JSON text), rendered through api_scene_parse and
 * the renderer, and their pixels compared with the material maths done here: emissive texture
 * and strength, COLOR_0, metallic-roughness texture, normal map (file and generated tangents,
 * scale), sampler wrap modes, KHR_texture_transform, a second uv set (TEXCOORD_1, in the
 * camera pass), doubleSided culling (alpha modes, transmission and mipmaps:
 * test_material_alpha.c; the PBR extensions: test_material_ext.c; the quad: material_quad.h).
 * Camera straight down (orthographic), light straight down: N·V = N·L = 1 on the
 * flat quad, so Lambert + GGX reduce to numbers written out in each test. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "material_quad.h"
#include "models.h"
#include "test.h"
#include "util.h"

/* ---- emissive ---- */

/* Emissive factor x texture (sRGB texels) x KHR_materials_emissive_strength, on a black base
 * under no light: the pixels are the texels (the sRGB encoding of the output undoes the
 * texture's). factor 0.5 x strength 2 gives the same picture as factor 1. */
TEST(materials_emissive_texture_and_strength)
{
	static const uint8_t tex[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 128, 128, 128, 255};
	const char *mats[2] = {
		"{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0},\"emissiveFactor\":[1,1,1],"
		"\"emissiveTexture\":{\"index\":0}}",
		"{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0},"
		"\"emissiveFactor\":[0.5,0.5,0.5],\"emissiveTexture\":{\"index\":0},"
		"\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":2}}}",
	};
	for (int m = 0; m < 2; m++) {
		struct mglb g = {.material = mats[m], .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
		                 .extensions_used = m ? "[\"KHR_materials_emissive_strength\"]" : NULL};
		add_png(&g, tex, 2, 2);
		struct rnd_image img;
		bool ok = render_quad(__LINE__, &img, &g, false, false);
		free_pngs(&g);
		if (!ok) return;
		/* texel (col, row) covers x in [-1 + col, col], z in [-1 + row, row] */
		for (int t = 0; t < 4; t++) {
			double x = -0.5 + (t & 1), z = -0.5 + (t >> 1);
			struct rnd_image *im = &img;
			for (int c = 0; c < 3; c++) {
				double want = gpu_srgb_decode(tex[4 * t + c] / 255.0), got = lin_at(im, false, x, z, c);
				CHECK(fabs(got - want) < 0.02, "material %d texel %d channel %d: %.3f, want %.3f", m, t, c, got, want);
			}
		}
		rnd_image_release(&img);
	}
}

/* ---- KHR_materials_unlit, KHR_materials_pbrSpecularGlossiness ---- */

/* Unlit: the pixels are base colour factor x texture whatever the light (a light of intensity
 * pi straight down leaves only the dielectric's F0 0.04 x 1/4 = 0.01 over the no-light
 * picture). Before, the extension was ignored: the quad was shaded, the texel x Lambert. */
TEST(materials_unlit_is_its_base_colour)
{
	static const uint8_t tex[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 128, 128, 128, 255};
	static const double factor[3] = {0.5, 0.25, 1};
	struct mglb g = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,1,1],"
	                             "\"baseColorTexture\":{\"index\":0}},\"extensions\":{\"KHR_materials_unlit\":{}}}",
	                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
	                 .extensions_used = "[\"KHR_materials_unlit\"]"};
	add_png(&g, tex, 2, 2);
	struct rnd_image lit, dark;
	bool ok = render_quad(__LINE__, &lit, &g, true, false);
	ok = ok && render_quad(__LINE__, &dark, &g, false, false);
	free_pngs(&g);
	if (!ok) return;
	for (int t = 0; t < 4; t++) {
		double x = -0.5 + (t & 1), z = -0.5 + (t >> 1);
		for (int c = 0; c < 3; c++) {
			double want = factor[c] * gpu_srgb_decode(tex[4 * t + c] / 255.0);
			double got = lin_at(&dark, false, x, z, c), got_lit = lin_at(&lit, false, x, z, c);
			CHECK(fabs(got - want) < 0.02, "no light: texel %d channel %d: %.3f, want %.3f", t, c, got, want);
			CHECK(fabs(got_lit - want) < 0.03, "lit: texel %d channel %d: %.3f, want %.3f", t, c, got_lit, want);
		}
	}
	rnd_image_release(&lit);
	rnd_image_release(&dark);
}

/* Specular-glossiness only (no pbrMetallicRoughness): base colour diffuseFactor x
 * diffuseTexture, roughness 1 - glossiness, F0 the specular colour 0.04, the diffuse x (1 -
 * max(F0)) as the sample viewer has it. Glossiness 0 under the light of intensity pi: Lambert
 * radiance = 0.96 x the albedo, + 0.01 of F0 in every channel. Before the extension was read,
 * glTF's default metallic 1 made it near black. */
TEST(materials_specular_glossiness_drawn_as_its_diffuse)
{
	static const uint8_t tex[16] = {255, 255, 255, 255, 255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255};
	struct mglb g = {.material = "{\"extensions\":{\"KHR_materials_pbrSpecularGlossiness\":{"
	                             "\"diffuseFactor\":[1,1,0.5,1],\"glossinessFactor\":0,\"specularFactor\":[0.04,0.04,0.04],"
	                             "\"diffuseTexture\":{\"index\":0}}}}",
	                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
	                 .extensions_used = "[\"KHR_materials_pbrSpecularGlossiness\"]"};
	add_png(&g, tex, 2, 2);
	struct rnd_image img;
	bool ok = render_quad(__LINE__, &img, &g, true, false);
	free_pngs(&g);
	if (!ok) return;
	static const double factor[3] = {1, 1, 0.5};
	for (int t = 0; t < 4; t++) {
		double x = -0.5 + (t & 1), z = -0.5 + (t >> 1);
		for (int c = 0; c < 3; c++) {
			double want = 0.96 * factor[c] * gpu_srgb_decode(tex[4 * t + c] / 255.0) + 0.01;
			double got = lin_at(&img, false, x, z, c);
			CHECK(fabs(got - want) < 0.03, "texel %d channel %d: %.3f, want %.3f", t, c, got, want);
		}
	}
	rnd_image_release(&img);
}

/* ---- vertex colour ---- */

/* COLOR_0 multiplies the base colour: white x red vertices = red (Lambert radiance 1 under
 * the light of intensity pi, plus GGX's F0 0.04 x 1/4 = 0.01 in every channel). */
TEST(materials_vertex_color_multiplies_base)
{
	static const float red[16] = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
	struct mglb g = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],\"metallicFactor\":0,"
	                             "\"roughnessFactor\":1}}",
	                 .color = red};
	struct rnd_image img;
	if (!render_quad(__LINE__, &img, &g, true, false)) return;
	double r = lin_at(&img, false, 0.3, 0.2, 0), gr = lin_at(&img, false, 0.3, 0.2, 1), b = lin_at(&img, false, 0.3, 0.2, 2);
	printf("    vertex colour red x white base: %.3f %.3f %.3f\n", r, gr, b);
	CHECK(r > 0.95 && gr < 0.03 && b < 0.03, "%.3f %.3f %.3f, want 1.01 0.01 0.01", r, gr, b);
	rnd_image_release(&img);
}

/* Vertex colours need no pipeline of their own: the main pass multiplies by the vertex colour
 * always (white where a mesh has none, renderer/mesh.c). The same quad drawn with and without
 * COLOR_0 uses the same variants: the coloured one compiles nothing and adds none. Before, a
 * scene's first vertex-coloured mesh compiled a main-pass variant (~190 ms on lavapipe, and
 * ~14 MB kept): a farm's first coloured PLY waited for it. */
TEST(materials_vertex_color_compiles_no_variant_of_its_own)
{
	static const float red[16] = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
	const char *mat = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],\"metallicFactor\":0,"
	                  "\"roughnessFactor\":0.7}}";
	struct mglb plain = {.material = mat, .uscale = 3}, coloured = {.material = mat, .uscale = 3, .color = red};
	struct rnd_image img;
	if (!render_quad(__LINE__, &img, &plain, true, false)) return;
	rnd_image_release(&img);
	struct rnd_stats before, after;
	rnd_context_stats(gpu_ctx(), &before);
	if (!render_quad(__LINE__, &img, &coloured, true, false)) return;
	rnd_context_stats(gpu_ctx(), &after);
	double r = lin_at(&img, false, 0.3, 0.2, 0), gr = lin_at(&img, false, 0.3, 0.2, 1);
	CHECK(r > 0.9 && gr < 0.05, "the colour is drawn: %.3f %.3f", r, gr);
	CHECK(after.pipeline_variants == before.pipeline_variants, "variants %u -> %u", before.pipeline_variants,
	      after.pipeline_variants);
	rnd_image_release(&img);
}

/* ---- metallic-roughness texture ---- */

/* A 2x1 MR texture: left texel B 255 (metallic 1), right B 0 (metallic 0); G 255 (roughness
 * 1) in both. Base grey 0.5. Straight down, roughness 1: D = 1/pi, V = 1/4, F = F0, so
 * radiance = c_diff + F0/4: metal 0 + 0.5/4 = 0.125; dielectric 0.5 + 0.04/4 = 0.51. */
TEST(materials_metal_rough_texture_blue_is_metal)
{
	static const uint8_t tex[8] = {0, 255, 255, 255, 0, 255, 0, 255};
	struct mglb g = {.material = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1],\"metallicFactor\":1,"
	                             "\"roughnessFactor\":1,\"metallicRoughnessTexture\":{\"index\":0}}}",
	                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP};
	add_png(&g, tex, 2, 1);
	struct rnd_image img;
	bool ok = render_quad(__LINE__, &img, &g, true, false);
	free_pngs(&g);
	if (!ok) return;
	double metal = lin_at(&img, false, -0.5, 0, 0), diel = lin_at(&img, false, 0.5, 0, 0);
	printf("    metal half %.4f (want 0.125), dielectric half %.4f (want 0.51)\n", metal, diel);
	CHECK(fabs(metal - 0.125) < 0.015, "metal %.4f", metal);
	CHECK(fabs(diel - 0.51) < 0.03, "dielectric %.4f", diel);
	rnd_image_release(&img);
}

/* ---- normal map ---- */

/* A uniform normal map tilting the normal 45 degrees towards the tangent (+x): texel
 * (218, 128, 218). Base 0.5, roughness 1, light and view straight down. Flat: 0.5 + 0.01 =
 * 0.51. Tilted: N.L = N.V = cos 45: Lambert 0.5 x 0.7071 = 0.3536, GGX F0 x D x V x pi x N.L =
 * 0.04 x (0.5 / (2 x 0.7071)) x 0.7071 = 0.0100: 0.3636. With tangents from the file and
 * generated from the uvs (u along +x either way); normalTexture.scale 0 is flat again. */
TEST(materials_normal_map_tilts_n_dot_l)
{
	static const uint8_t tex[4] = {218, 128, 218, 255};
	static const float tan[16] = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
	const char *mat = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1],\"metallicFactor\":0,"
	                  "\"roughnessFactor\":1},\"normalTexture\":{\"index\":0%s}}";
	struct { const float *tangent; const char *scale; double want; const char *label; } cases[3] = {
		{tan, "", 0.3636, "file tangents"},
		{NULL, "", 0.3636, "generated tangents"},
		{tan, ",\"scale\":0", 0.51, "scale 0"},
	};
	for (int k = 0; k < 3; k++) {
		char m[400];
		snprintf(m, sizeof m, mat, cases[k].scale);
		struct mglb g = {.material = m, .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
		                 .tangent = cases[k].tangent};
		add_png(&g, tex, 1, 1);
		struct rnd_image img;
		bool ok = render_quad(__LINE__, &img, &g, true, false);
		free_pngs(&g);
		if (!ok) return;
		double got = lin_at(&img, false, 0.2, 0.3, 0);
		printf("    %s: %.4f (want %.4f)\n", cases[k].label, got, cases[k].want);
		CHECK(fabs(got - cases[k].want) < 0.02, "%s: %.4f, want %.4f", cases[k].label, got, cases[k].want);
		rnd_image_release(&img);
	}
}

/* The AOV normal (N.X/Y/Z) is the mapped normal the beauty pass shades with: the texel
 * (218, 128, 218) is (0.7071, 0.0039, 0.7071) in tangent space; with u along +x the frame is
 * t = +x, b = -z, n = +y, so N = (0.7071, 0.7071, -0.0039) — not the quad's (0, 1, 0). */
TEST(materials_normal_map_in_the_normal_aov)
{
	static const uint8_t tex[4] = {218, 128, 218, 255};
	struct mglb g = {.material = "{\"pbrMetallicRoughness\":{\"metallicFactor\":0},\"normalTexture\":{\"index\":0}}",
	                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
	                 .output = "'format':'exr','aovs':['normal'],'msaa':1"};
	add_png(&g, tex, 1, 1);
	struct rnd_image img;
	bool ok = render_quad(__LINE__, &img, &g, true, false);
	free_pngs(&g);
	if (!ok) return;
	const float *n[3] = {NULL, NULL, NULL};
	for (uint32_t i = 0; i < img.aov_count; i++)
		for (int c = 0; c < 3; c++)
			if (!strcmp(img.aov_names[i], (const char *[]){"N.X", "N.Y", "N.Z"}[c])) n[c] = img.aov[i];
	if (!n[0] || !n[1] || !n[2]) {
		CHECK(0, "no N.X/Y/Z planes (%u AOVs)", img.aov_count);
		rnd_image_release(&img);
		return;
	}
	size_t k = (size_t)(MH / 2 + 5) * MW + MW / 2 + 7;
	printf("    N at the quad: %.4f %.4f %.4f (want 0.7071 0.7071 -0.0039)\n", n[0][k], n[1][k], n[2][k]);
	CHECK(fabs(n[0][k] - 0.7071) < 0.01 && fabs(n[1][k] - 0.7071) < 0.01 && fabs(n[2][k] + 0.0039) < 0.01,
	      "N %.4f %.4f %.4f, want the mapped (0.7071, 0.7071, -0.0039)", n[0][k], n[1][k], n[2][k]);
	rnd_image_release(&img);
}

/* ---- occlusion ---- */

/* occlusionTexture R = 64 (0.2510 linear), base 0.5. Under a white hemisphere ambient of
 * intensity 1 alone: 0.5 x (1 + strength x (0.2510 - 1)) = 0.1255 (strength 1), 0.3127
 * (strength 0.5). Under the direct light alone it changes nothing: 0.51. */
static bool render_ambient(int line, struct rnd_image *img, const struct mglb *g, bool ambient)
{
	char *enc = quad_data(g);
	bool ok = gpu_render_at(__FILE__, line, img,
	                        "{'width':%d,'height':%d,"
	                        "'camera':{'type':'orthographic','position':[0,5,0],'target':[0,0,0],'up':[0,0,-1],"
	                        "'height':%.9g},"
	                        "'environment':{'background':[0,0,0],'ambient':{'sky':[1,1,1],'ground':[1,1,1],"
	                        "'intensity':%d}},"
	                        "'objects':[{'shape':'model','format':'glb','data':'%s'}],"
	                        "'lights':[%s],'output':{'tonemap':'none','msaa':1}}",
	                        MW, MH, MORTHO, ambient ? 1 : 0, enc,
	                        ambient ? "" : "{'type':'directional','direction':[0,-1,0],'intensity':3.14159265}");
	free(enc);
	return ok;
}

TEST(materials_occlusion_darkens_ambient_only)
{
	static const uint8_t tex[4] = {64, 255, 255, 255};
	struct { const char *strength; bool ambient; double want; } cases[3] = {
		{"", true, 0.1255}, {",\"strength\":0.5", true, 0.3127}, {"", false, 0.51},
	};
	for (int k = 0; k < 3; k++) {
		char mat[300];
		snprintf(mat, sizeof mat,
		         "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1],\"metallicFactor\":0,"
		         "\"roughnessFactor\":1},\"occlusionTexture\":{\"index\":0%s}}", cases[k].strength);
		struct mglb g = {.material = mat, .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP};
		add_png(&g, tex, 1, 1);
		struct rnd_image img;
		bool ok = render_ambient(__LINE__, &img, &g, cases[k].ambient);
		free_pngs(&g);
		if (!ok) return;
		double got = lin_at(&img, false, 0.2, -0.3, 0);
		printf("    %s%s: %.4f (want %.4f)\n", cases[k].ambient ? "ambient" : "direct light", cases[k].strength, got,
		       cases[k].want);
		CHECK(fabs(got - cases[k].want) < 0.015, "case %d: %.4f, want %.4f", k, got, cases[k].want);
		rnd_image_release(&img);
	}
}

/* ---- sampler wrap modes ---- */

/* u runs 0..2 over the quad; the texture is red | blue (2x1, nearest). At u = 1.25 repeat
 * reads 0.25 (red), clamp the edge (blue), mirror 0.75 (blue); at u = 1.75 repeat reads 0.75
 * (blue), clamp blue, mirror 0.25 (red). */
TEST(materials_sampler_wrap_modes)
{
	static const uint8_t tex[8] = {255, 0, 0, 255, 0, 0, 255, 255};
	static const char *const wraps[3] = {"10497", "33071", "33648"};
	static const char want125[3] = {'r', 'b', 'b'}, want175[3] = {'b', 'b', 'r'};
	for (int w = 0; w < 3; w++) {
		char samplers[128];
		snprintf(samplers, sizeof samplers, "[{\"magFilter\":9728,\"minFilter\":9728,\"wrapS\":%s}]", wraps[w]);
		struct mglb g = {.material = "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0},"
		                             "\"metallicFactor\":0,\"roughnessFactor\":1}}",
		                 .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = samplers, .uscale = 2};
		add_png(&g, tex, 2, 1);
		struct rnd_image img;
		bool ok = render_quad(__LINE__, &img, &g, true, false);
		free_pngs(&g);
		if (!ok) return;
		/* u = 1.25 at x = 0.25, u = 1.75 at x = 0.75 */
		double r1 = lin_at(&img, false, 0.25, 0, 0), b1 = lin_at(&img, false, 0.25, 0, 2);
		double r2 = lin_at(&img, false, 0.75, 0, 0), b2 = lin_at(&img, false, 0.75, 0, 2);
		char c1 = r1 > 0.8 && b1 < 0.1 ? 'r' : b1 > 0.8 && r1 < 0.1 ? 'b' : '?';
		char c2 = r2 > 0.8 && b2 < 0.1 ? 'r' : b2 > 0.8 && r2 < 0.1 ? 'b' : '?';
		printf("    wrapS %s: u 1.25 -> %c, u 1.75 -> %c\n", wraps[w], c1, c2);
		CHECK(c1 == want125[w] && c2 == want175[w], "wrapS %s: u 1.25 %c (want %c), u 1.75 %c (want %c)", wraps[w], c1,
		      want125[w], c2, want175[w]);
		rnd_image_release(&img);
	}
}

/* ---- KHR_texture_transform ---- */

/* red | blue texture (nearest, repeat). offset [0.5, 0] moves u = 0.25 to 0.75 (blue where
 * red was); scale [0.5, 1] moves u = 0.75 to 0.375 (red where blue was). */
TEST(materials_texture_transform_offset_and_scale)
{
	static const uint8_t tex[8] = {255, 0, 0, 255, 0, 0, 255, 255};
	static const char *const tt[2] = {"{\"offset\":[0.5,0]}", "{\"scale\":[0.5,1]}"};
	static const double x[2] = {-0.5, 0.5};   /* u 0.25, u 0.75 */
	for (int k = 0; k < 2; k++) {
		char mat[300];
		snprintf(mat, sizeof mat,
		         "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"extensions\":"
		         "{\"KHR_texture_transform\":%s}},\"metallicFactor\":0,\"roughnessFactor\":1}}", tt[k]);
		struct mglb g = {.material = mat, .textures = "[{\"source\":0,\"sampler\":0}]",
		                 .samplers = "[{\"magFilter\":9728,\"minFilter\":9728}]",
		                 .extensions_used = "[\"KHR_texture_transform\"]"};
		add_png(&g, tex, 2, 1);
		struct rnd_image img;
		bool ok = render_quad(__LINE__, &img, &g, true, false);
		free_pngs(&g);
		if (!ok) return;
		double r = lin_at(&img, false, x[k], 0, 0), b = lin_at(&img, false, x[k], 0, 2);
		printf("    %s at x %.1f: r %.3f b %.3f\n", tt[k], x[k], r, b);
		if (k == 0) CHECK(b > 0.8 && r < 0.1, "offset: want blue, got r %.3f b %.3f", r, b);
		else CHECK(r > 0.8 && b < 0.1, "scale: want red, got r %.3f b %.3f", r, b);
		rnd_image_release(&img);
	}
}

/* ---- a second uv set (TEXCOORD_1) ---- */

/* A 2x2 texture (red green / blue white, nearest, clamped) on a quad whose TEXCOORD_0 puts
 * every vertex on the red texel and whose TEXCOORD_1 spans the whole texture. A slot that
 * reads set 1 (textureInfo.texCoord, or KHR_texture_transform's texCoord over it) shows the
 * four texels in the four quarters; set 0 shows red everywhere, and so does set 1 on a quad
 * without TEXCOORD_1 (drawn with TEXCOORD_0). Base colour (light straight down: a white
 * Lambert surface gives the texel) and emissive (no light). */
TEST(materials_second_uv_set)
{
	static const uint8_t tex[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
	static const float uv0[8] = {0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f};
	static const float uv1[8] = {0, 0, 1, 0, 1, 1, 0, 1};   /* u = (x + 1) / 2, v = (z + 1) / 2 */
	static const char *const mats[5] = {
		"{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"texCoord\":1},\"metallicFactor\":0,"
		"\"roughnessFactor\":1}}",
		"{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":"
		"{\"texCoord\":1}}},\"metallicFactor\":0,\"roughnessFactor\":1}}",
		"{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0},\"emissiveFactor\":[1,1,1],"
		"\"emissiveTexture\":{\"index\":0,\"texCoord\":1}}",
		"{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0,\"roughnessFactor\":1}}",
		"{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"texCoord\":1},\"metallicFactor\":0,"
		"\"roughnessFactor\":1}}",
	};
	static const char *const what[5] = {"base texCoord 1", "base KHR_texture_transform texCoord 1",
	                                    "emissive texCoord 1", "base texCoord 0", "base texCoord 1, no TEXCOORD_1"};
	static const double qx[4] = {-0.5, 0.5, -0.5, 0.5}, qz[4] = {-0.5, -0.5, 0.5, 0.5};
	for (int m = 0; m < 5; m++) {
		struct mglb g = {.material = mats[m], .textures = "[{\"source\":0,\"sampler\":0}]", .samplers = NEAREST_CLAMP,
		                 .uv0 = uv0, .uv1 = m == 4 ? NULL : uv1,
		                 .extensions_used = m == 1 ? "[\"KHR_texture_transform\"]" : NULL};
		add_png(&g, tex, 2, 2);
		struct rnd_image img;
		bool ok = render_quad(__LINE__, &img, &g, m != 2, false);
		free_pngs(&g);
		if (!ok) return;
		for (int q = 0; q < 4; q++) {
			const uint8_t *t = m >= 3 ? tex : tex + 4 * q;   /* set 0: the red texel everywhere */
			double got[3];
			for (int c = 0; c < 3; c++) got[c] = lin_at(&img, false, qx[q], qz[q], c);
			printf("    %s, quarter %d: %.3f %.3f %.3f\n", what[m], q, got[0], got[1], got[2]);
			for (int c = 0; c < 3; c++)
				CHECK(fabs(got[c] - t[c] / 255.0) < 0.05, "%s: quarter %d channel %d is %.3f, want %.3f", what[m], q, c,
				      got[c], t[c] / 255.0);
		}
		rnd_image_release(&img);
	}
}

/* ---- doubleSided ---- */

/* Seen from below (its back), the quad is hidden when doubleSided is false (glTF's default)
 * and drawn (emissive white) when true. */
TEST(materials_single_sided_hides_back_face)
{
	for (int ds = 0; ds < 2; ds++) {
		char mat[200];
		snprintf(mat, sizeof mat,
		         "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]},\"emissiveFactor\":[1,1,1],"
		         "\"doubleSided\":%s}", ds ? "true" : "false");
		struct mglb g = {.material = mat};
		struct rnd_image img;
		if (!render_quad(__LINE__, &img, &g, false, true)) return;
		double v = lin_at(&img, true, 0.1, 0.1, 0);
		printf("    doubleSided %s, from below: %.3f\n", ds ? "true" : "false", v);
		if (ds) CHECK(v > 0.9, "double-sided back face not drawn: %.3f", v);
		else CHECK(v < 0.05, "single-sided back face drawn: %.3f", v);
		rnd_image_release(&img);
	}
}
