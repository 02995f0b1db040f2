/*
 * api/model_material.c — an aiScene's materials as rnd_materials (see model_conv.h): glTF's core
 * material model (every texture slot for glTF, the base colour for the other formats; what
 * Assimp 5.2 does not hand over reliably comes from api/gltf_material.c), and the textures they
 * name, embedded or among the files the model refers to, decoded into the import's arena.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <assimp/cimport.h>
#include "errmsg.h"
#include "model_conv.h"
#include "model_io.h"

#define MAX_TEXTURE_PIXELS (64ull << 20)

static float clampf(float v, float lo, float hi)
{
	return !(v >= lo) ? lo : v > hi ? hi : v;  /* NaN -> lo */
}

/* The texture that `path` names: an embedded one ("*N" or the embedded file's name), then a
 * file the model refers to (index mNumTextures + k); -1 when none. */
static int find_texture(const struct api_conv *c, const char *path)
{
	const struct aiScene *sc = c->sc;
	if (path[0] == '*') {
		char *end;
		unsigned long n = strtoul(path + 1, &end, 10);
		if (*end || end == path + 1 || n >= sc->mNumTextures) return -1;
		return (int)n;
	}
	for (unsigned i = 0; i < sc->mNumTextures; i++) {
		const char *fn = sc->mTextures[i]->mFilename.data;
		if (fn[0] && !strcmp(fn, path)) return (int)i;
	}
	long k = api_model_file_index(c->files, c->nfiles, path);
	return k < 0 ? -1 : (int)(sc->mNumTextures + (unsigned)k);
}

static const struct rnd_texture *oom(struct api_conv *c)
{
	api_err_set(c->err, c->errsize, "out of memory importing the model");
	return NULL;
}

/* A PNG or JPEG file's bytes decoded into the arena: for a sampler with mip levels no larger
 * than the request's images need (api_image_decode_fit), else as stored (a minFilter without
 * mipmaps reads level 0, aliasing and all, as the file asks). what: the error's subject. */
static const struct rnd_texture *decode(struct api_conv *c, const uint8_t *bytes, size_t len, const char *what,
                                        enum rnd_texture_slot slot, bool mipmapped)
{
	struct rnd_texture *t = api_conv_alloc(c, 1, sizeof *t);
	if (!t) return oom(c);
	uint8_t *px;
	uint32_t w, h, stored;
	char e[200];
	double t0 = api_clock_ms();
	enum api_result r = api_image_decode_fit(bytes, len, MAX_TEXTURE_PIXELS,
	                                         mipmapped ? c->texture_side * API_TEXTURE_SIDE_PER_PIXEL : 0,
	                                         rnd_texture_slot_srgb(slot), &px, &w, &h, &stored, e, sizeof e);
	c->texture_ms += api_clock_ms() - t0;
	if (r != API_OK) return api_err_set(c->err, c->errsize, "%s: %s", what, e), NULL;
	if (stored > c->texture_max) c->texture_max = stored;
	uint8_t *copy = api_conv_alloc(c, (size_t)w * h, 4);
	if (copy) memcpy(copy, px, (size_t)w * h * 4);
	free(px);
	if (!copy) return oom(c);
	t->rgba = copy;
	t->width = w;
	t->height = h;
	return t;
}

/* Texture ti (decoded once; the first slot that reads it decides the mip levels kept). */
static const struct rnd_texture *texture(struct api_conv *c, int ti, enum rnd_texture_slot slot, bool mipmapped)
{
	if (c->tex[ti]) return c->tex[ti];
	unsigned nemb = c->sc->mNumTextures;
	const struct aiTexture *at = (unsigned)ti < nemb ? c->sc->mTextures[ti] : NULL;
	const struct api_model_file *file = at ? NULL : &c->files[(unsigned)ti - nemb];
	const struct rnd_texture *done = NULL;
	if (file || at->mHeight == 0) {
		/* Compressed: mWidth bytes of a PNG or JPEG file, or a whole file beside the model. */
		char what[160];
		if (file) snprintf(what, sizeof what, "texture \"%.128s\"", file->name);
		else snprintf(what, sizeof what, "embedded texture %d", ti);
		done = decode(c, file ? file->data : (const uint8_t *)at->pcData, file ? file->len : at->mWidth, what, slot,
		              mipmapped);
	} else {
		uint64_t n = (uint64_t)at->mWidth * at->mHeight;
		if (n > MAX_TEXTURE_PIXELS)
			return api_err_set(c->err, c->errsize, "embedded texture %d is over the texture size limit", ti), NULL;
		struct rnd_texture *t = api_conv_alloc(c, 1, sizeof *t);
		uint8_t *px = api_conv_alloc(c, (size_t)n, 4);
		if (!t || !px) return oom(c);
		for (size_t i = 0; i < n; i++) { /* aiTexel is BGRA */
			px[4 * i] = at->pcData[i].r;
			px[4 * i + 1] = at->pcData[i].g;
			px[4 * i + 2] = at->pcData[i].b;
			px[4 * i + 3] = at->pcData[i].a;
		}
		t->rgba = px;
		t->width = at->mWidth;
		t->height = at->mHeight;
		done = t;
	}
	return c->tex[ti] = (struct rnd_texture *)done;
}

/* Assimp's texture types per slot, in the order tried (glTF: base colour also as DIFFUSE;
 * metallic-roughness as UNKNOWN, 5.2's name for it; occlusion as LIGHTMAP). */
static const enum aiTextureType SLOT_TYPES[RND_TEX_CLEARCOAT][3] = {
	{aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE, aiTextureType_NONE},
	{aiTextureType_UNKNOWN, aiTextureType_METALNESS, aiTextureType_DIFFUSE_ROUGHNESS},
	{aiTextureType_NORMALS, aiTextureType_NONE, aiTextureType_NONE},
	{aiTextureType_LIGHTMAP, aiTextureType_AMBIENT_OCCLUSION, aiTextureType_NONE},
	{aiTextureType_EMISSIVE, aiTextureType_NONE, aiTextureType_NONE},
};

/* KHR_materials_volume's thicknessTexture of glTF material gi as one number, the mean of its G
 * over the texture, into its thickness_mean (drawn per material: the coverage it changes is a
 * material's, see api_gltf_material_shading). An image that is a file beside the model or
 * cannot be decoded leaves 1 (thicknessFactor alone). */
static int thickness_mean(struct api_conv *c, int gi)
{
	struct api_gltf_material *gm = &c->gi.materials[gi];
	int32_t i = gm->thickness_image;
	struct api_gltf_image *im = i >= 0 && (uint32_t)i < c->gi.image_count ? &c->gi.images[i] : NULL;
	const struct rnd_texture *t = NULL;
	if (im && im->uri) {
		int ti = find_texture(c, im->uri);
		if (ti >= 0 && !(t = texture(c, ti, RND_TEX_METAL_ROUGH, false))) return -1;
	} else if (im && im->bytes) {
		if (!im->tex && !(im->tex = decode(c, im->bytes, im->len, "thicknessTexture", RND_TEX_METAL_ROUGH, false)))
			return -1;
		t = im->tex;
	}
	if (!t || !t->width || !t->height) return 0;
	double sum = 0;
	size_t n = (size_t)t->width * t->height;
	for (size_t p = 0; p < n; p++) sum += t->rgba[4 * p + 1];
	gm->thickness_mean = (float)(sum / (255.0 * (double)n));
	api_gltf_warn(&c->gi, "material %d: KHR_materials_volume's thicknessTexture drawn as its mean, %.2f", gi,
	              gm->thickness_mean);
	return 0;
}

/* The PBR extensions' textures of glTF material gi: their images as taken from the document
 * (api_gltf_ext_images), a file beside the model by its uri, else their bytes. */
static int extension_textures(struct api_conv *c, int gi, struct rnd_material *m)
{
	if (gi < 0 || (uint32_t)gi >= c->gi.material_count) return 0;
	const struct api_gltf_material *gm = &c->gi.materials[gi];
	for (uint32_t k = RND_TEX_CLEARCOAT; k < RND_TEX_SLOTS; k++) {
		int32_t i = gm->ext_image[k];
		struct api_gltf_image *im = i >= 0 && (uint32_t)i < c->gi.image_count ? &c->gi.images[i] : NULL;
		bool mip = m->sampling[k].mip != RND_MIP_NONE;
		if (im && im->uri) {
			int ti = find_texture(c, im->uri);
			if (ti < 0) api_gltf_warn(&c->gi, "material %d: %s \"%.60s\" is not in the file (not drawn)", gi,
			                          api_gltf_slot_name(k), im->uri);
			else if (!(m->textures[k] = texture(c, ti, (enum rnd_texture_slot)k, mip))) return -1;
		} else if (im && im->bytes) {
			char what[48];
			snprintf(what, sizeof what, "image %d", i);
			if (!im->tex && !(im->tex = decode(c, im->bytes, im->len, what, (enum rnd_texture_slot)k, mip))) return -1;
			m->textures[k] = im->tex;
		}
	}
	return thickness_mean(c, gi);
}

/* KHR_materials_pbrSpecularGlossiness's glossiness, where it has a specularGlossinessTexture
 * (decoded into the specular colour slot by extension_textures): the metallic-roughness slot
 * made of its alpha, G = 1 - glossinessFactor x A, sampled the same way (the renderer
 * multiplies roughness by G and cannot take 1 - x; roughness factor 1, api_gltf_material_shading). */
static int spec_gloss_roughness(struct api_conv *c, int gi, struct rnd_material *m)
{
	const struct api_gltf_material *gm = gi >= 0 && (uint32_t)gi < c->gi.material_count ? &c->gi.materials[gi] : NULL;
	if (!gm || !gm->spec_gloss) return 0;
	const struct rnd_texture *sg = m->textures[RND_TEX_SPECULAR_COLOR];
	m->metal_rough_texture = NULL;
	if (!sg || !sg->width || !sg->height) return 0;
	size_t n = (size_t)sg->width * sg->height;
	struct rnd_texture *t = api_conv_alloc(c, 1, sizeof *t);
	uint8_t *px = api_conv_alloc(c, n, 4);
	if (!t || !px) return oom(c) ? 0 : -1;
	for (size_t p = 0; p < n; p++) {
		px[4 * p + 1] = (uint8_t)lrintf(255.0f - gm->glossiness * (float)sg->rgba[4 * p + 3]);
		px[4 * p + 3] = 255;
	}
	t->rgba = px;
	t->width = sg->width;
	t->height = sg->height;
	m->metal_rough_texture = t;
	m->sampling[RND_TEX_METAL_ROUGH] = m->sampling[RND_TEX_SPECULAR_COLOR];
	return 0;
}

static int material_textures(struct api_conv *c, const struct aiMaterial *am, uint32_t index, struct rnd_material *m)
{
	struct aiString s;
	for (uint32_t k = 0; k < (c->gltf ? RND_TEX_CLEARCOAT : 1u); k++) {
		for (int j = 0; j < 3 && SLOT_TYPES[k][j] != aiTextureType_NONE; j++) {
			if (aiGetMaterialTexture(am, SLOT_TYPES[k][j], 0, &s, NULL, NULL, NULL, NULL, NULL, NULL) != aiReturn_SUCCESS)
				continue;
			int ti = find_texture(c, s.data);
			if (ti < 0) {
				/* Neither embedded nor among the files the daemon sent with the model. */
				if (c->gltf) api_gltf_warn(&c->gi, "material %u: texture \"%.60s\" is not in the file (not drawn)", index, s.data);
				break;
			}
			if (!(m->textures[k] = texture(c, ti, (enum rnd_texture_slot)k, m->sampling[k].mip != RND_MIP_NONE)))
				return -1;
			break;
		}
	}
	return 0;
}

int api_conv_material(struct api_conv *c, const struct aiMaterial *am, uint32_t index, struct rnd_material *m,
                      bool *single_sided)
{
	rnd_material_defaults(m);
	*single_sided = false;
	struct aiString s;
	/* Formats without materials (stl, ply, obj without mtl) get Assimp's default material:
	 * the contract's default grey stands in for it, as for every other shape. */
	if (aiGetMaterialString(am, AI_MATKEY_NAME, &s) != aiReturn_SUCCESS) s.data[0] = 0, s.length = 0;
	else if (!strcmp(s.data, AI_DEFAULT_MATERIAL_NAME)) return 0;
	int gi = c->gltf ? api_gltf_material_of(s.data) : -1;
	struct aiColor4D col;
	if (aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &col) == aiReturn_SUCCESS ||
	    aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &col) == aiReturn_SUCCESS) {
		const float v[4] = {col.r, col.g, col.b, col.a};
		for (int k = 0; k < 4; k++) m->base_color[k] = clampf(v[k], 0, k < 3 ? 1e6f : 1);
	}
	ai_real f;
	if (aiGetMaterialFloatArray(am, AI_MATKEY_METALLIC_FACTOR, &f, NULL) == aiReturn_SUCCESS)
		m->metallic = clampf(f, 0, 1);
	if (aiGetMaterialFloatArray(am, AI_MATKEY_ROUGHNESS_FACTOR, &f, NULL) == aiReturn_SUCCESS)
		m->roughness = clampf(f, 0, 1);
	if (aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &col) == aiReturn_SUCCESS) {
		const float v[3] = {col.r, col.g, col.b};
		for (int k = 0; k < 3; k++) m->emissive[k] = clampf(v[k], 0, 1e6f);
	}
	if (aiGetMaterialString(am, "$mat.gltf.alphaMode", 0, 0, &s) == aiReturn_SUCCESS) {
		if (!strcmp(s.data, "MASK")) m->alpha_mode = RND_ALPHA_MASK;
		if (!strcmp(s.data, "BLEND")) m->alpha_mode = RND_ALPHA_BLEND;   /* drawn dithered */
		if (aiGetMaterialFloatArray(am, "$mat.gltf.alphaCutoff", 0, 0, &f, NULL) == aiReturn_SUCCESS)
			m->alpha_cutoff = clampf(f, 0, 1);
	}
	if (gi >= 0) api_gltf_material_apply(&c->gi, (uint32_t)gi, m, single_sided);
	if (material_textures(c, am, gi >= 0 ? (uint32_t)gi : index, m) != 0 || extension_textures(c, gi, m) != 0 ||
	    spec_gloss_roughness(c, gi, m) != 0)
		return -1;
	if (gi >= 0) api_gltf_material_shading(&c->gi, (uint32_t)gi, m);
	return 0;
}
