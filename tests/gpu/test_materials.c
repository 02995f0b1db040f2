/* tests/gpu — the glTF 2.0 material model of imported models: .glb files built here (one 2x2
 * quad, its material and textures given as JSON text), rendered through api_scene_parse and
 * the renderer, and their pixels compared with the material maths done here: emissive texture
 * and strength, COLOR_0, metallic-roughness texture, normal map (file and generated tangents,
 * scale), sampler wrap modes, KHR_texture_transform, a second uv set (TEXCOORD_1, in the
 * camera and the alpha-tested shadow passes), doubleSided culling, alpha BLEND coverage and
 * shadow. Camera straight down (orthographic), light straight down: N·V = N·L = 1 on the
 * flat quad, so Lambert + GGX reduce to numbers written out in each test. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "models.h"
#include "test.h"
#include "util.h"

/* ---- one quad in a .glb ---- */

/* The quad: 2x2 in XZ at height y, front face +Y, u = (x + 1) / 2 * uscale, v = (z + 1) / 2
 * (texel row 0 at z = -1, the top of the image of the camera below). */
static const uint32_t QIDX[6] = {0, 2, 1, 0, 3, 2};

struct mglb {
	const char *material;        /* JSON object: materials[0] */
	const char *textures;        /* JSON array, or NULL */
	const char *samplers;        /* JSON array, or NULL */
	const char *extensions_used; /* JSON array, or NULL */
	const uint8_t *png[3];
	size_t png_len[3];
	int npng;
	float uscale;                /* 0 = 1 */
	float y;                     /* node translation */
	const float *color;          /* COLOR_0 RGBA float per vertex, or NULL */
	const float *tangent;        /* TANGENT xyzw per vertex, or NULL */
	const char *output;          /* the scene's output members, or NULL: no tone map, no MSAA */
	const float *uv0;            /* TEXCOORD_0 uv per vertex instead of the one above, or NULL */
	const float *uv1;            /* TEXCOORD_1 uv per vertex, or NULL: none */
};

static uint8_t *glb_of(const struct mglb *in, size_t *len)
{
	float us = in->uscale > 0 ? in->uscale : 1;
	float pos[12] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1}, nrm[12], uv[8];
	for (int v = 0; v < 4; v++) {
		nrm[3 * v] = 0; nrm[3 * v + 1] = 1; nrm[3 * v + 2] = 0;
		uv[2 * v] = (pos[3 * v] + 1) / 2 * us;
		uv[2 * v + 1] = (pos[3 * v + 2] + 1) / 2;
	}
	if (in->uv0) memcpy(uv, in->uv0, sizeof uv);
	/* bin: pos 48, nrm 48, uv 32, [color 64], [tangent 64], [uv1 32], idx 24, pngs (4-aligned) */
	size_t off[16], n = 0, k = 0;
	const void *src[16];
	size_t sz[16];
	src[k] = pos; sz[k++] = 48;
	src[k] = nrm; sz[k++] = 48;
	src[k] = uv; sz[k++] = 32;
	if (in->color) { src[k] = in->color; sz[k++] = 64; }
	if (in->tangent) { src[k] = in->tangent; sz[k++] = 64; }
	if (in->uv1) { src[k] = in->uv1; sz[k++] = 32; }
	src[k] = QIDX; sz[k++] = 24;
	for (int i = 0; i < in->npng; i++) { src[k] = in->png[i]; sz[k++] = in->png_len[i]; }
	for (size_t i = 0; i < k; i++) { off[i] = n; n += (sz[i] + 3) & ~(size_t)3; }
	char views[2048], accs[1024], attrs[256], imgs[512] = "";
	int vl = 0;
	for (size_t i = 0; i < k; i++)
		vl += snprintf(views + vl, sizeof views - (size_t)vl, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}",
		               i ? "," : "", off[i], sz[i]);
	int al = snprintf(accs, sizeof accs,
	                  "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[-1,0,-1],"
	                  "\"max\":[1,0,1]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
	                  "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}");
	int tl = snprintf(attrs, sizeof attrs, "\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2");
	int view = 3, acc = 3;
	if (in->color) {
		al += snprintf(accs + al, sizeof accs - (size_t)al,
		               ",{\"bufferView\":%d,\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"}", view++);
		tl += snprintf(attrs + tl, sizeof attrs - (size_t)tl, ",\"COLOR_0\":%d", acc++);
	}
	if (in->tangent) {
		al += snprintf(accs + al, sizeof accs - (size_t)al,
		               ",{\"bufferView\":%d,\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"}", view++);
		tl += snprintf(attrs + tl, sizeof attrs - (size_t)tl, ",\"TANGENT\":%d", acc++);
	}
	if (in->uv1) {
		al += snprintf(accs + al, sizeof accs - (size_t)al,
		               ",{\"bufferView\":%d,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}", view++);
		tl += snprintf(attrs + tl, sizeof attrs - (size_t)tl, ",\"TEXCOORD_1\":%d", acc++);
	}
	al += snprintf(accs + al, sizeof accs - (size_t)al,
	               ",{\"bufferView\":%d,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"}", view++);
	int idx_acc = acc++;
	if (in->npng) {
		int il = snprintf(imgs, sizeof imgs, ",\"images\":[");
		for (int i = 0; i < in->npng; i++)
			il += snprintf(imgs + il, sizeof imgs - (size_t)il, "%s{\"bufferView\":%d,\"mimeType\":\"image/png\"}",
			               i ? "," : "", view++);
		snprintf(imgs + il, sizeof imgs - (size_t)il, "]");
	}
	char json[8192];
	int jn = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
		"\"nodes\":[{\"mesh\":0,\"translation\":[0,%.9g,0]}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{%s},\"indices\":%d,\"material\":0}]}],"
		"\"materials\":[%s]%s%s%s%s%s%s%s%s,"
		"\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[%s],\"accessors\":[%s]}",
		in->y, attrs, idx_acc, in->material, in->textures ? ",\"textures\":" : "", in->textures ? in->textures : "",
		in->samplers ? ",\"samplers\":" : "", in->samplers ? in->samplers : "",
		in->extensions_used ? ",\"extensionsUsed\":" : "", in->extensions_used ? in->extensions_used : "", imgs, "",
		n, views, accs);
	uint8_t *bin = calloc(1, n ? n : 1);
	if (!bin) return NULL;
	for (size_t i = 0; i < k; i++) memcpy(bin + off[i], src[i], sz[i]);
	uint8_t *g = test_glb_pack(json, (size_t)jn, bin, n, n, len);
	free(bin);
	return g;
}

/* ---- rendering ---- */

#define MW 64
#define MH 64
#define MORTHO 2.2   /* orthographic height: the quad (2 wide) fills most of the image */

static void cam_of(struct gpu_cam *cam, bool below)
{
	if (below) gpu_cam_ortho(cam, v3_make(0, -5, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), MORTHO, MW, MH);
	else gpu_cam_ortho(cam, v3_make(0, 5, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), MORTHO, MW, MH);
}

/* Renders the quad model: `light` "none" or a directional light straight down of intensity pi
 * (so a white Lambert surface facing it has radiance 1); no ambient; no tone map. */
static bool render_quad(int line, struct rnd_image *img, const struct mglb *g, bool light, bool below)
{
	size_t n;
	uint8_t *glb = glb_of(g, &n);
	char *enc = test_b64(glb, n);
	free(glb);
	bool ok = gpu_render_at(__FILE__, line, img,
	                        "{'width':%d,'height':%d,"
	                        "'camera':{'type':'orthographic','position':[0,%d,0],'target':[0,0,0],'up':[0,0,-1],"
	                        "'height':%.9g},"
	                        "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	                        "'objects':[{'shape':'model','format':'glb','data':'%s'}],"
	                        "'lights':[%s],'output':{%s}}",
	                        MW, MH, below ? -5 : 5, MORTHO, enc,
	                        light ? "{'type':'directional','direction':[0,-1,0],'intensity':3.14159265}" : "",
	                        g->output ? g->output : "'tonemap':'none','msaa':1");
	free(enc);
	return ok;
}

/* Linear radiance of channel c at world point (x, 0, z) seen from the camera. */
static double lin_at(const struct rnd_image *img, bool below, double x, double z, int c)
{
	struct gpu_cam cam;
	cam_of(&cam, below);
	double px, py;
	gpu_cam_project(&cam, v3_make(x, 0, z), &px, &py);
	return gpu_srgb_decode(gpu_chan(img, (int)floor(px), (int)floor(py), c));
}

/* A w x h texture of RGBA texels as PNG bytes into g->png[g->npng++]. */
static void add_png(struct mglb *g, const uint8_t *texels, int w, int h)
{
	g->png[g->npng] = test_png_rgba(texels, w, h, &g->png_len[g->npng]);
	g->npng++;
}

static void free_pngs(struct mglb *g)
{
	for (int i = 0; i < g->npng; i++) free((void *)g->png[i]);
	g->npng = 0;
}

#define NEAREST_CLAMP "[{\"magFilter\":9728,\"minFilter\":9728,\"wrapS\":33071,\"wrapT\":33071}]"

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

/* Specular-glossiness only (no pbrMetallicRoughness): a dielectric of base colour
 * diffuseFactor x diffuseTexture, roughness 1 - glossiness. Glossiness 0 under the light of
 * intensity pi: Lambert radiance = the albedo, + 0.01 of F0 in every channel. Before, the
 * extension was ignored and glTF's default metallic 1 made it near black. */
TEST(materials_specular_glossiness_drawn_as_its_diffuse)
{
	static const uint8_t tex[16] = {255, 255, 255, 255, 255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255};
	struct mglb g = {.material = "{\"extensions\":{\"KHR_materials_pbrSpecularGlossiness\":{"
	                             "\"diffuseFactor\":[1,1,0.5,1],\"glossinessFactor\":0,"
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
			double want = factor[c] * gpu_srgb_decode(tex[4 * t + c] / 255.0) + 0.01, got = lin_at(&img, false, x, z, c);
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
	size_t n;
	uint8_t *glb = glb_of(g, &n);
	char *enc = test_b64(glb, n);
	free(glb);
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

/* ---- alpha BLEND ---- */

#define BW 96
#define BH 96

/* A red quad at y = 1 (alpha 0.5 BLEND, or OPAQUE) over a blue ground, sun along (0.8, -1, 0):
 * its shadow is the quad moved 0.8 along +x. Seen from above (orthographic), the quad itself
 * covers about half its pixels (dithered) and its shadow takes about half the light. */
static bool quad_over_ground(int line, struct rnd_image *img, const struct mglb *g)
{
	size_t n;
	uint8_t *glb = glb_of(g, &n);
	char *enc = test_b64(glb, n);
	free(glb);
	bool ok = gpu_render_at(__FILE__, line, img,
	                        "{'width':%d,'height':%d,"
	                        "'camera':{'type':'orthographic','position':[0.6,5,0],'target':[0.6,0,0],'up':[0,0,-1],"
	                        "'height':3.6},"
	                        "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	                        "'objects':[{'shape':'plane','size':[8,8],'material':{'base_color':[0,0,1],'roughness':1}},"
	                        "{'shape':'model','format':'glb','data':'%s'}],"
	                        "'lights':[{'type':'directional','direction':[0.8,-1,0],'intensity':3}],"
	                        "'output':{'tonemap':'none','msaa':1}}",
	                        BW, BH, enc);
	free(enc);
	return ok;
}

static bool material_render(int line, struct rnd_image *img, const char *material, const char *extensions_used)
{
	struct mglb g = {.material = material, .extensions_used = extensions_used, .y = 1};
	return quad_over_ground(line, img, &g);
}

static bool blend_render(int line, struct rnd_image *img, bool blend)
{
	return material_render(line, img,
	                       blend ? "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,0.5],"
	                               "\"metallicFactor\":0,\"roughnessFactor\":1},\"alphaMode\":\"BLEND\"}"
	                             : "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1],"
	                               "\"metallicFactor\":0,\"roughnessFactor\":1}}",
	                       NULL);
}

/* Mean of channel c over the world rectangle [x0, x1] x [z0, z1] at height y. */
static double mean_rect(const struct rnd_image *img, double x0, double x1, double z0, double z1, double y, int c)
{
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(0.6, 5, 0), v3_make(0.6, 0, 0), v3_make(0, 0, -1), 3.6, BW, BH);
	double a0, b0, a1, b1, sum = 0;
	gpu_cam_project(&cam, v3_make(x0, y, z0), &a0, &b0);
	gpu_cam_project(&cam, v3_make(x1, y, z1), &a1, &b1);
	int n = 0;
	for (int j = (int)ceil(fmin(b0, b1)); j < (int)floor(fmax(b0, b1)); j++)
		for (int i = (int)ceil(fmin(a0, a1)); i < (int)floor(fmax(a0, a1)); i++, n++)
			sum += gpu_srgb_decode(gpu_chan(img, i, j, c));
	return n ? sum / n : -1;
}

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
TEST(materials_transmission_as_partial_coverage)
{
	struct rnd_image op, tr;
	if (!blend_render(__LINE__, &op, false)) return;
	if (!material_render(__LINE__, &tr,
	                     "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1],\"metallicFactor\":0,"
	                     "\"roughnessFactor\":1},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1}}}",
	                     "[\"KHR_materials_transmission\"]")) {
		rnd_image_release(&op);
		return;
	}
	double lit = mean_rect(&op, 2.0, 2.35, -0.6, 0.6, 0, 2);
	double sh_op = mean_rect(&op, 1.1, 1.7, -0.6, 0.6, 0, 2), sh_tr = mean_rect(&tr, 1.1, 1.7, -0.6, 0.6, 0, 2);
	double share = (lit - sh_tr) / (lit - sh_op);
	double red_op = mean_rect(&op, -0.8, 0.8, -0.8, 0.8, 1, 0), red_tr = mean_rect(&tr, -0.8, 0.8, -0.8, 0.8, 1, 0);
	printf("    transmission 1: coverage %.2f, shadow share %.2f\n", red_tr / red_op, share);
	CHECK(red_tr / red_op > 0.1 && red_tr / red_op < 0.3, "transmission 1 coverage %.2f, want ~0.2", red_tr / red_op);
	CHECK(share > 0.1 && share < 0.3, "transmission 1 takes %.2f of the light, want ~0.2", share);
	rnd_image_release(&op);
	rnd_image_release(&tr);
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
