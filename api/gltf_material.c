/*
 * api/gltf_material — glTF 2.0 material details from the document's JSON (see the header).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gltf_buffers.h"
#include "gltf_material.h"
#include "gltf_variants.h"

/* glTF sampler enums (OpenGL's) */
#define GL_NEAREST 9728
#define GL_LINEAR 9729
#define GL_LINEAR_MIPMAP_NEAREST 9985
#define GL_NEAREST_MIPMAP_NEAREST 9984
#define GL_NEAREST_MIPMAP_LINEAR 9986
#define GL_CLAMP_TO_EDGE 33071
#define GL_MIRRORED_REPEAT 33648

static const char *const SLOT_NAMES[RND_TEX_SLOTS] = {
	"baseColorTexture", "metallicRoughnessTexture", "normalTexture", "occlusionTexture", "emissiveTexture",
	"clearcoatTexture", "clearcoatRoughnessTexture", "clearcoatNormalTexture", "sheenColorTexture",
	"sheenRoughnessTexture", "specularTexture", "specularColorTexture", "transmissionTexture"};
static const char *const SUPPORTED_EXT[] = {"KHR_materials_emissive_strength", "KHR_texture_transform",
                                             "KHR_materials_unlit", "KHR_materials_pbrSpecularGlossiness",
                                             "KHR_materials_clearcoat", "KHR_materials_sheen",
                                             "KHR_materials_specular", "KHR_materials_ior",
                                             "EXT_mesh_gpu_instancing", "EXT_meshopt_compression",
                                             "KHR_mesh_quantization", "KHR_draco_mesh_compression", NULL};
/* Extensions known and not drawn (or drawn in part): what the picture lacks. */
static const char *const LACKS[][2] = {
	{"KHR_materials_transmission", "transmission drawn as see-through coverage (dithered), not refraction"},
	{"KHR_materials_volume", "volume drawn as the coverage's tint and density (its attenuation through "
	                         "thicknessFactor x its texture's mean), no refraction"},
	{"KHR_materials_iridescence", "iridescence not drawn"},
	{"KHR_materials_anisotropy", "anisotropy not drawn (isotropic highlights)"},
	{"KHR_texture_basisu", "KTX2/Basis textures not decoded: those materials drawn without their textures"},
	{"EXT_texture_webp", "WebP textures not decoded: those materials drawn without their textures (or with a PNG/JPEG fallback)"},
	{"KHR_lights_punctual", "the file's lights not used (the scene's lights are)"},
	{NULL, NULL},
};

void api_gltf_warn(struct api_gltf_info *gi, const char *fmt, ...)
{
	size_t n = strlen(gi->warnings), cap = sizeof gi->warnings;
	if (n + 8 >= cap) return;
	char line[300];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(line, sizeof line, fmt, ap);
	va_end(ap);
	if (strstr(gi->warnings, line)) return;   /* once each */
	if (n + (n ? 2 : 0) + strlen(line) >= cap) {
		if (n + 5 < cap) snprintf(gi->warnings + n, cap - n, "%s...", n ? "; " : "");
		return;
	}
	snprintf(gi->warnings + n, cap - n, "%s%s", n ? "; " : "", line);
	/* A header value: printable ASCII only (names come from the file). */
	for (char *p = gi->warnings + n; *p; p++)
		if (*p < 0x20 || *p > 0x7e) *p = '?';
}

static float num(json_t *o, const char *key, float dflt)
{
	json_t *v = json_object_get(o, key);
	double d = json_is_number(v) ? json_number_value(v) : dflt;
	return isfinite(d) && fabs(d) < 1e6 ? (float)d : dflt;
}

static uint8_t wrap_of(json_t *sampler, const char *key)
{
	json_int_t w = json_integer_value(json_object_get(sampler, key));
	return w == GL_CLAMP_TO_EDGE ? RND_WRAP_CLAMP : w == GL_MIRRORED_REPEAT ? RND_WRAP_MIRROR : RND_WRAP_REPEAT;
}

/* KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv, in glTF's uv space. */
static void transform_of(json_t *tt, struct rnd_texture_sampling *ts)
{
	json_t *off = json_object_get(tt, "offset"), *sc = json_object_get(tt, "scale");
	float ox = 0, oy = 0, sx = 1, sy = 1, r = num(tt, "rotation", 0);
	if (json_array_size(off) == 2) {
		ox = json_is_number(json_array_get(off, 0)) ? (float)json_number_value(json_array_get(off, 0)) : 0;
		oy = json_is_number(json_array_get(off, 1)) ? (float)json_number_value(json_array_get(off, 1)) : 0;
	}
	if (json_array_size(sc) == 2) {
		sx = json_is_number(json_array_get(sc, 0)) ? (float)json_number_value(json_array_get(sc, 0)) : 1;
		sy = json_is_number(json_array_get(sc, 1)) ? (float)json_number_value(json_array_get(sc, 1)) : 1;
	}
	float c = cosf(r), s = sinf(r);
	float m[6] = {c * sx, s * sy, ox, -s * sx, c * sy, oy};
	for (int i = 0; i < 6; i++)
		if (!isfinite(m[i]) || fabsf(m[i]) > 1e6f) return;
	memcpy(ts->transform, m, sizeof m);
	ts->transformed = true;
}

const char *api_gltf_slot_name(uint32_t k)
{
	return k < RND_TEX_SLOTS ? SLOT_NAMES[k] : "texture";
}

void api_gltf_read_texinfo(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, uint32_t slot,
                           json_t *info, struct api_gltf_material *gm)
{
	if (!json_is_object(info)) return;
	struct rnd_texture_sampling *ts = &gm->sampling[slot];
	json_t *tex = json_array_get(json_object_get(root, "textures"), (size_t)json_integer_value(json_object_get(info, "index")));
	json_t *sampler = json_array_get(json_object_get(root, "samplers"),
	                                 (size_t)json_integer_value(json_object_get(tex, "sampler")));
	if (json_is_object(sampler) && json_is_integer(json_object_get(tex, "sampler"))) {
		ts->wrap_s = wrap_of(sampler, "wrapS");
		ts->wrap_t = wrap_of(sampler, "wrapT");
		ts->mag_nearest = json_integer_value(json_object_get(sampler, "magFilter")) == GL_NEAREST;
		json_int_t mf = json_integer_value(json_object_get(sampler, "minFilter"));
		ts->min_nearest = mf == GL_NEAREST || mf == GL_NEAREST_MIPMAP_NEAREST || mf == GL_NEAREST_MIPMAP_LINEAR;
		ts->mip = mf == GL_NEAREST || mf == GL_LINEAR ? RND_MIP_NONE
		        : mf == GL_NEAREST_MIPMAP_NEAREST || mf == GL_LINEAR_MIPMAP_NEAREST ? RND_MIP_NEAREST : RND_MIP_LINEAR;
	}
	json_int_t tc = json_integer_value(json_object_get(info, "texCoord"));
	json_t *tt = json_object_get(json_object_get(info, "extensions"), "KHR_texture_transform");
	if (json_is_object(tt)) {
		transform_of(tt, ts);
		if (json_is_integer(json_object_get(tt, "texCoord"))) tc = json_integer_value(json_object_get(tt, "texCoord"));
	}
	/* Sets 0 and 1 are drawn (a mesh without set 1 draws it with set 0: api/model_import.c
	 * says so per mesh); the renderer has no third. */
	ts->uv_set = tc == 1 ? 1 : 0;
	if (tc != 0 && tc != 1)
		api_gltf_warn(gi, "material %u (\"%.40s\"): %s reads TEXCOORD_%lld, drawn with TEXCOORD_0", mi, mname, SLOT_NAMES[slot],
		     (long long)tc);
	if (slot == RND_TEX_NORMAL) gm->normal_scale = num(info, "scale", 1);
	if (slot == RND_TEX_OCCLUSION) gm->occlusion_strength = fminf(fmaxf(num(info, "strength", 1), 0), 1);
}

static void read_material(struct api_gltf_info *gi, json_t *root, uint32_t mi, json_t *mat, struct api_gltf_material *gm)
{
	memset(gm, 0, sizeof *gm);
	gm->emissive_strength = 1;
	gm->normal_scale = 1;
	gm->occlusion_strength = 1;
	for (int k = 0; k < 3; k++) gm->specular.color[k] = gm->attenuation[k] = 1;
	gm->thickness_mean = 1;
	gm->thickness_image = -1;
	gm->specular.factor = 1;
	gm->specular.ior = 1.5f;
	for (uint32_t k = 0; k < RND_TEX_SLOTS; k++) gm->ext_image[k] = -1;
	if (!json_is_object(mat)) return;
	const char *name = json_string_value(json_object_get(mat, "name"));
	name = name ? name : "";
	gm->double_sided = json_is_true(json_object_get(mat, "doubleSided"));
	json_t *pbr = json_object_get(mat, "pbrMetallicRoughness");
	json_t *infos[RND_TEX_EMISSIVE + 1] = {json_object_get(pbr, SLOT_NAMES[0]), json_object_get(pbr, SLOT_NAMES[1]),
	                                json_object_get(mat, SLOT_NAMES[2]), json_object_get(mat, SLOT_NAMES[3]),
	                                json_object_get(mat, SLOT_NAMES[4])};
	for (uint32_t k = 0; k <= RND_TEX_EMISSIVE; k++) api_gltf_read_texinfo(gi, root, mi, name, k, infos[k], gm);
	json_t *ext = json_object_get(mat, "extensions"), *v;
	const char *key;
	json_object_foreach(ext, key, v) {
		if (!strcmp(key, "KHR_materials_emissive_strength")) {
			float s = num(v, "emissiveStrength", 1);
			gm->emissive_strength = s >= 0 ? s : 1;
		}
		if (!strcmp(key, "KHR_materials_unlit")) gm->unlit = true;
	}
	/* Specular-glossiness where the file has no metallic-roughness fallback. */
	api_gltf_read_material_ext(gi, root, mi, name, ext, !pbr, gm);
}

/* Extensions the renderer does not know, and parts of a scene it does not draw. */
static void scene_warnings(struct api_gltf_info *gi, json_t *root)
{
	json_t *used = json_object_get(root, "extensionsUsed"), *e;
	size_t i;
	json_array_foreach(used, i, e) {
		const char *s = json_string_value(e);
		bool known = false;
		if (s && !strcmp(s, "KHR_materials_variants")) {   /* a variant picked leaves no name here */
			char names[200];
			api_gltf_variant_names(root, names, sizeof names);
			api_gltf_warn(gi, "KHR_materials_variants: the default materials drawn (the model object's \"variant\" "
			              "picks one of %s)", names[0] ? names : "none");
			continue;
		}
		for (int k = 0; s && SUPPORTED_EXT[k]; k++) known = known || !strcmp(s, SUPPORTED_EXT[k]);
		for (int k = 0; s && !known && LACKS[k][0]; k++)
			if (!strcmp(s, LACKS[k][0])) {
				api_gltf_warn(gi, "%s: %s", s, LACKS[k][1]);
				known = true;
			}
		if (s && !known) api_gltf_warn(gi, "extension %.60s is not supported (ignored)", s);
	}
	if (json_array_size(json_object_get(root, "skins"))) api_gltf_warn(gi, "skins are not applied (drawn in the bind pose)");
	if (json_array_size(json_object_get(root, "animations"))) api_gltf_warn(gi, "animations are not played");
	json_t *meshes = json_object_get(root, "meshes"), *m, *p;
	size_t j;
	json_array_foreach(meshes, i, m) {
		json_array_foreach(json_object_get(m, "primitives"), j, p) {
			if (json_array_size(json_object_get(p, "targets")))
				api_gltf_warn(gi, "morph targets are not applied (drawn in the base shape)");
			json_t *mode = json_object_get(p, "mode");
			if (json_is_integer(mode) && json_integer_value(mode) < 4)
				api_gltf_warn(gi, "points and lines drawn as thin prisms and dots 1/250 and 1/100 of the model's size "
				              "wide (not one pixel wide)");
		}
	}
}

void api_gltf_info_read(json_t *root, struct api_gltf_info *out)
{
	memset(out, 0, sizeof *out);
	if (!json_is_object(root)) return;
	scene_warnings(out, root);
	json_t *mats = json_object_get(root, "materials");
	size_t n = json_array_size(mats);
	if (!n || n > 65536 || !(out->materials = calloc(n, sizeof *out->materials))) return;
	out->material_count = (uint32_t)n;
	for (size_t i = 0; i < n; i++) read_material(out, root, (uint32_t)i, json_array_get(mats, i), &out->materials[i]);
}

void api_gltf_material_apply(const struct api_gltf_info *gi, uint32_t index, struct rnd_material *m,
                             bool *single_sided)
{
	if (index >= gi->material_count) return;
	const struct api_gltf_material *gm = &gi->materials[index];
	for (int k = 0; k < 3; k++) m->emissive[k] = fminf(m->emissive[k] * gm->emissive_strength, 1e6f);
	memcpy(m->sampling, gm->sampling, sizeof m->sampling);
	m->normal_scale = fminf(fmaxf(gm->normal_scale, -1e3f), 1e3f);
	m->occlusion_strength = gm->occlusion_strength;   /* clamped to 0..1 when read */
	api_gltf_material_ext_apply(gm, m);
	*single_sided = !gm->double_sided;
}

void api_gltf_material_shading(const struct api_gltf_info *gi, uint32_t index, struct rnd_material *m)
{
	if (index >= gi->material_count) return;
	const struct api_gltf_material *gm = &gi->materials[index];
	if (gm->spec_gloss) {
		/* F0 is the specular colour (api_gltf_read_material_ext); the metallic-roughness
		 * slot, when there is a specularGlossinessTexture, is made of its alpha
		 * (api/model_material.c): roughness 1 - glossiness x A. */
		memcpy(m->base_color, gm->diffuse, sizeof gm->diffuse);
		m->metallic = 0;
		m->roughness = m->metal_rough_texture ? 1 : 1 - gm->glossiness;
	}
	if (gm->transmission > 0 && m->alpha_mode != RND_ALPHA_MASK) {
		float t[3];
		api_gltf_volume_transmittance(gm, t);
		float see = 0.8f * gm->transmission * (t[0] + t[1] + t[2]) / 3;
		m->alpha_mode = RND_ALPHA_BLEND;
		/* transmissionTexture R scales the factor per pixel: the renderer's see-through slot */
		if (m->transmission_texture) m->see_through = see;
		else m->base_color[3] *= 1 - see;
		for (int k = 0; k < 3; k++) m->base_color[k] *= t[k];
	} else {
		m->transmission_texture = NULL;
	}
	if (gm->unlit) {
		for (int k = 0; k < 3; k++) {
			m->emissive[k] = m->base_color[k];
			m->base_color[k] = 0;
		}
		m->emissive_texture = m->base_color_texture;
		m->sampling[RND_TEX_EMISSIVE] = m->sampling[RND_TEX_BASE];
		m->metallic = 0;
		m->roughness = 1;
		m->metal_rough_texture = m->normal_texture = m->occlusion_texture = NULL;
	}
}

void api_vertex_colors(const float *rgba, uint32_t n, uint8_t *out)
{
	for (size_t i = 0; i < (size_t)n * 4; i++) {
		float f = rgba[i];
		out[i] = (uint8_t)lrintf(!(f >= 0.0f) ? 0.0f : f > 1.0f ? 255.0f : f * 255.0f);   /* NaN -> 0 */
	}
}

void api_vertex_tangents(const float *t, const float *b, const float *nrm, uint32_t n, float *out)
{
	for (size_t v = 0; v < n; v++) {
		const float *tv = t + 3 * v, *bv = b + 3 * v, *nv = nrm + 3 * v;
		float cx = nv[1] * tv[2] - nv[2] * tv[1], cy = nv[2] * tv[0] - nv[0] * tv[2], cz = nv[0] * tv[1] - nv[1] * tv[0];
		bool ok = isfinite(tv[0]) && isfinite(tv[1]) && isfinite(tv[2]);
		out[4 * v] = ok ? tv[0] : 1;
		out[4 * v + 1] = ok ? tv[1] : 0;
		out[4 * v + 2] = ok ? tv[2] : 0;
		out[4 * v + 3] = cx * bv[0] + cy * bv[1] + cz * bv[2] < 0 ? -1.0f : 1.0f;
	}
}

void api_gltf_info_free(struct api_gltf_info *gi)
{
	if (!gi) return;
	for (uint32_t i = 0; i < gi->image_count; i++) {
		free(gi->images[i].uri);
		free(gi->images[i].bytes);
	}
	free(gi->images);
	gi->images = NULL;
	gi->image_count = 0;
	free(gi->materials);
	gi->materials = NULL;
	gi->material_count = 0;
}

#define TAG "umbra-gltf-material-"

uint8_t *api_gltf_tag_materials(json_t *root, const uint8_t *data, size_t len, bool glb, bool changed,
                                size_t *out_len)
{
	json_t *mats = json_object_get(root, "materials"), *m;
	size_t i;
	if (!json_array_size(mats) && !changed) return NULL;
	json_array_foreach(mats, i, m) {
		char tag[48];
		snprintf(tag, sizeof tag, TAG "%zu", i);
		if (json_is_object(m) && json_object_set_new(m, "name", json_string(tag)) < 0) return NULL;
	}
	char *js = json_dumps(root, JSON_COMPACT);
	if (!js) return NULL;
	uint8_t *out = api_gltf_with_json(data, len, glb, js, strlen(js), out_len);
	free(js);
	return out;
}

int api_gltf_material_of(const char *name)
{
	if (!name || strncmp(name, TAG, strlen(TAG))) return -1;
	char *end;
	long v = strtol(name + strlen(TAG), &end, 10);
	return *end || end == name + strlen(TAG) || v < 0 || v > 65535 ? -1 : (int)v;
}
