/*
 * api/gltf_material_ext — the glTF 2.0 PBR extensions of a material, read from the document's
 * JSON (see gltf_material.h): KHR_materials_clearcoat, _sheen, _specular, _ior (drawn by the
 * renderer's extension lobes, shaders/material_ext.glsl), _transmission and _volume (drawn as
 * see-through coverage), each with its textures where the renderer has a slot for them (the
 * volume's thicknessTexture as its mean over the texture).
 *
 * Assimp 5.2 hands over some of these (clearcoat, sheen, transmission, volume; not specular),
 * and only when their factor is not zero, and loads only the images its own materials name:
 * all of them come from the JSON here, and their images' bytes (or the uri of a file beside
 * the model) are taken from the document before Assimp reads it (api_gltf_ext_images), to be
 * decoded like the core slots' (api/model_material.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base64.h"
#include "gltf_buffers.h"
#include "gltf_material.h"

static float num(json_t *o, const char *key, float dflt, float lo, float hi)
{
	json_t *v = json_object_get(o, key);
	double d = json_is_number(v) ? json_number_value(v) : dflt;
	return !isfinite(d) ? dflt : d < lo ? lo : d > hi ? hi : (float)d;
}

static void color3(json_t *o, const char *key, float dflt, float out[3])
{
	json_t *a = json_object_get(o, key);
	for (int k = 0; k < 3; k++) {
		json_t *e = json_array_get(a, (size_t)k);
		double d = json_is_number(e) && json_array_size(a) == 3 ? json_number_value(e) : dflt;
		out[k] = isfinite(d) ? (float)fmin(fmax(d, 0), 1e6) : dflt;
	}
}

/* Texture info `key` of extension object `e` into slot `slot` of gm: its sampling and its
 * image's index. */
static void ext_texture(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, json_t *e,
                        const char *key, uint32_t slot, struct api_gltf_material *gm)
{
	json_t *info = json_object_get(e, key);
	if (!json_is_object(info)) return;
	api_gltf_read_texinfo(gi, root, mi, mname, slot, info, gm);
	json_t *tex = json_array_get(json_object_get(root, "textures"), (size_t)json_integer_value(json_object_get(info, "index")));
	json_t *src = json_object_get(tex, "source");
	json_int_t n = (json_int_t)json_array_size(json_object_get(root, "images"));
	if (json_is_integer(src) && json_integer_value(src) >= 0 && json_integer_value(src) < n)
		gm->ext_image[slot] = (int32_t)json_integer_value(src);
}

static void read_clearcoat(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, json_t *e,
                           struct api_gltf_material *gm)
{
	gm->extensions |= RND_EXT_CLEARCOAT;
	gm->clearcoat.factor = num(e, "clearcoatFactor", 0, 0, 1);
	gm->clearcoat.roughness = num(e, "clearcoatRoughnessFactor", 0, 0, 1);
	gm->clearcoat.normal_scale = num(json_object_get(e, "clearcoatNormalTexture"), "scale", 1, -1e3f, 1e3f);
	ext_texture(gi, root, mi, mname, e, "clearcoatTexture", RND_TEX_CLEARCOAT, gm);
	ext_texture(gi, root, mi, mname, e, "clearcoatRoughnessTexture", RND_TEX_CLEARCOAT_ROUGHNESS, gm);
	ext_texture(gi, root, mi, mname, e, "clearcoatNormalTexture", RND_TEX_CLEARCOAT_NORMAL, gm);
}

static void read_sheen(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, json_t *e,
                       struct api_gltf_material *gm)
{
	gm->extensions |= RND_EXT_SHEEN;
	color3(e, "sheenColorFactor", 0, gm->sheen.color);
	for (int k = 0; k < 3; k++) gm->sheen.color[k] = fminf(gm->sheen.color[k], 1);
	gm->sheen.roughness = num(e, "sheenRoughnessFactor", 0, 0, 1);
	ext_texture(gi, root, mi, mname, e, "sheenColorTexture", RND_TEX_SHEEN_COLOR, gm);
	ext_texture(gi, root, mi, mname, e, "sheenRoughnessTexture", RND_TEX_SHEEN_ROUGHNESS, gm);
}

static void read_specular(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, json_t *e,
                          struct api_gltf_material *gm)
{
	gm->extensions |= RND_EXT_SPECULAR;
	gm->specular.factor = num(e, "specularFactor", 1, 0, 1);
	color3(e, "specularColorFactor", 1, gm->specular.color);
	ext_texture(gi, root, mi, mname, e, "specularTexture", RND_TEX_SPECULAR, gm);
	ext_texture(gi, root, mi, mname, e, "specularColorTexture", RND_TEX_SPECULAR_COLOR, gm);
}

/* KHR_materials_pbrSpecularGlossiness, as the Khronos sample viewer draws it: the diffuse
 * colour as the base colour (diffuseTexture: Assimp hands it over as the base colour's), a
 * dielectric whose F0 is the specular colour (specularFactor x specularGlossinessTexture's
 * RGB, read in the specular colour slot, sRGB) with specular weight 1 (F90 1), roughness 1 -
 * glossinessFactor (x the texture's A: api/model_material.c makes the metallic-roughness
 * slot of it). The renderer keeps 1 - max(F0) of the diffuse and reflects F0 under the ambient
 * (rnd_material specular.spec_gloss). */
static void read_spec_gloss(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, json_t *e,
                            struct api_gltf_material *gm)
{
	gm->spec_gloss = true;
	json_t *d = json_object_get(e, "diffuseFactor");
	for (int k = 0; k < 4; k++) {
		json_t *x = json_array_get(d, (size_t)k);
		gm->diffuse[k] = json_is_number(x) && json_array_size(d) == 4 ? (float)fmin(fmax(json_number_value(x), 0), 1) : 1;
	}
	gm->glossiness = num(e, "glossinessFactor", 1, 0, 1);
	gm->extensions |= RND_EXT_SPECULAR;
	color3(e, "specularFactor", 1, gm->specular.color);
	for (int k = 0; k < 3; k++) gm->specular.color[k] = fminf(gm->specular.color[k], 1);
	gm->specular.factor = 1;
	gm->specular.ior = 1e6f;   /* ((ior - 1) / (ior + 1))^2 within 4e-6 of 1: F0 = the colour */
	gm->specular.spec_gloss = true;
	ext_texture(gi, root, mi, mname, e, "specularGlossinessTexture", RND_TEX_SPECULAR_COLOR, gm);
}

/* KHR_materials_volume: the medium (its transmittance: api_gltf_volume_transmittance). */
static void read_volume(struct api_gltf_info *gi, json_t *root, json_t *e, struct api_gltf_material *gm)
{
	gm->thickness = num(e, "thicknessFactor", 0, 0, 1e6f);
	gm->attenuation_distance = num(e, "attenuationDistance", 0, 0, 1e30f);
	color3(e, "attenuationColor", 1, gm->attenuation);
	json_t *info = json_object_get(e, "thicknessTexture");
	if (!json_is_object(info)) return;
	json_t *tex = json_array_get(json_object_get(root, "textures"), (size_t)json_integer_value(json_object_get(info, "index")));
	json_t *src = json_object_get(tex, "source");
	json_int_t n = (json_int_t)json_array_size(json_object_get(root, "images"));
	if (json_is_integer(src) && json_integer_value(src) >= 0 && json_integer_value(src) < n)
		gm->thickness_image = (int32_t)json_integer_value(src);
	(void)gi;
}

void api_gltf_volume_transmittance(const struct api_gltf_material *gm, float t[3])
{
	float thick = gm->thickness * gm->thickness_mean, dist = gm->attenuation_distance;
	for (int k = 0; k < 3; k++)
		t[k] = dist > 0 && thick > 0 ? powf(fminf(fmaxf(gm->attenuation[k], 1e-6f), 1), thick / dist) : 1;
}

/* gm holds the defaults (api/gltf_material.c read_material): specular 1 x white, ior 1.5,
 * transmittance 1. */
void api_gltf_read_material_ext(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, json_t *ext,
                                bool spec_gloss, struct api_gltf_material *gm)
{
	json_t *v;
	const char *key;
	json_object_foreach(ext, key, v) {
		if (!json_is_object(v)) continue;
		if (!strcmp(key, "KHR_materials_pbrSpecularGlossiness") && spec_gloss) read_spec_gloss(gi, root, mi, mname, v, gm);
		if (!strcmp(key, "KHR_materials_clearcoat")) read_clearcoat(gi, root, mi, mname, v, gm);
		if (!strcmp(key, "KHR_materials_sheen")) read_sheen(gi, root, mi, mname, v, gm);
		if (!strcmp(key, "KHR_materials_specular")) read_specular(gi, root, mi, mname, v, gm);
		if (!strcmp(key, "KHR_materials_volume")) read_volume(gi, root, v, gm);
		if (!strcmp(key, "KHR_materials_transmission")) {
			gm->transmission = num(v, "transmissionFactor", 0, 0, 1);
			ext_texture(gi, root, mi, mname, v, "transmissionTexture", RND_TEX_TRANSMISSION, gm);
		}
		if (!strcmp(key, "KHR_materials_ior")) {
			gm->extensions |= RND_EXT_SPECULAR;
			/* ior 0 is the spec's "infinite": F0 1, which ior 1e6 comes within 4e-6 of */
			float ior = num(v, "ior", 1.5f, 0, 1e6f);
			gm->specular.ior = ior == 0 ? 1e6f : fmaxf(ior, 1);
		}
	}
}

void api_gltf_material_ext_apply(const struct api_gltf_material *gm, struct rnd_material *m)
{
	m->extensions = gm->extensions;
	m->clearcoat.factor = gm->clearcoat.factor;
	m->clearcoat.roughness = gm->clearcoat.roughness;
	m->clearcoat.normal_scale = gm->clearcoat.normal_scale;
	memcpy(m->sheen.color, gm->sheen.color, sizeof m->sheen.color);
	m->sheen.roughness = gm->sheen.roughness;
	m->specular.factor = gm->specular.factor;
	memcpy(m->specular.color, gm->specular.color, sizeof m->specular.color);
	m->specular.ior = gm->specular.ior;
	m->specular.spec_gloss = gm->specular.spec_gloss;
}

/* Image i's uri, or its bytes (a bufferView, a data: URI), into im. 0, or -1 with err. */
static int take_image(struct api_gltf_bufs *b, json_t *img, struct api_gltf_image *im, char *err, size_t errsize)
{
	const char *uri = json_string_value(json_object_get(img, "uri"));
	if (uri && strncmp(uri, "data:", 5)) return (im->uri = strdup(uri)) ? 0 : -1;
	const uint8_t *p = NULL;
	size_t n = 0;
	if (uri) {
		const char *comma = strchr(uri, ',');
		if (!comma || !strstr(uri, ";base64,")) return snprintf(err, errsize, "a data: URI that is not base64"), -1;
		size_t sl = strlen(comma + 1), cap = api_base64_decoded_max(sl);
		if (!(im->bytes = malloc(cap ? cap : 1))) return snprintf(err, errsize, "out of memory"), -1;
		if (api_base64_decode(comma + 1, sl, im->bytes, cap, &im->len, NULL) != API_OK)
			return snprintf(err, errsize, "a data: URI that is not base64"), -1;
		return 0;
	}
	json_t *views = json_object_get(b->root, "bufferViews");
	json_t *view = json_array_get(views, (size_t)json_integer_value(json_object_get(img, "bufferView")));
	if (api_gltf_view_bytes(b, view, "image", &p, &n, err, errsize) != 0) return -1;
	if (!(im->bytes = malloc(n ? n : 1))) return snprintf(err, errsize, "out of memory"), -1;
	memcpy(im->bytes, p, n);
	im->len = n;
	return 0;
}

void api_gltf_ext_images(struct api_gltf_info *gi, struct api_gltf_bufs *b)
{
	json_t *images = json_object_get(b->root, "images");
	size_t n = json_array_size(images);
	if (!n || n > 65536 || !(gi->images = calloc(n, sizeof *gi->images))) return;
	gi->image_count = (uint32_t)n;
	for (uint32_t m = 0; m < gi->material_count; m++)
		for (uint32_t k = RND_TEX_CLEARCOAT; k <= RND_TEX_SLOTS; k++) {   /* k == RND_TEX_SLOTS: the thickness */
			int32_t *slot_image = k < RND_TEX_SLOTS ? &gi->materials[m].ext_image[k] : &gi->materials[m].thickness_image;
			int32_t i = *slot_image;
			struct api_gltf_image *im = i >= 0 ? &gi->images[i] : NULL;
			if (!im || im->uri || im->bytes) continue;
			char e[160];
			if (take_image(b, json_array_get(images, (size_t)i), im, e, sizeof e) != 0) {
				api_gltf_warn(gi, "image %d (%s): %s (not drawn)", i, k < RND_TEX_SLOTS ? api_gltf_slot_name(k) : "thicknessTexture", e);
				free(im->bytes);
				im->bytes = NULL;
				*slot_image = -1;
			}
		}
}
