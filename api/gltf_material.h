/*
 * api/gltf_material — what of a glTF 2.0 material Assimp 5.2 does not hand over reliably,
 * read from the document's JSON itself: per texture slot the sampler (wrap and filter modes),
 * KHR_texture_transform, texCoord, normalTexture.scale and occlusionTexture.strength;
 * KHR_materials_emissive_strength; doubleSided. Also the list of what the renderer does not
 * do of the file (unknown extensions, a uv set past the second, skins, animations, morph
 * targets, points and lines), as warnings that travel with the model (api_model.warnings).
 *
 * Assimp 5.2's glTF importer numbers materials in the order it first meets them walking the
 * node tree (children before a node's own mesh), not the document's order. So the document is
 * handed to Assimp with each material renamed to a tag naming its index
 * (api_gltf_tag_materials), and each Assimp material is joined to its glTF material by that
 * name (api_gltf_material_of); the original names stay here, for the warnings.
 *
 * Usage (api/model_import.c, inside the sandboxed importer):
 *   struct api_gltf_info gi; api_gltf_info_read(root, &gi);   // root: the parsed JSON
 *   uint8_t *t = api_gltf_tag_materials(root, data, len, glb, changed, &tlen);  // import t (or data if NULL)
 *   ... i = api_gltf_material_of(assimp material name): gi.materials[i] when i >= 0 ...
 *   free(t); api_gltf_info_free(&gi);
 * Ownership: gi owns its materials array (malloc). Threading: no shared state.
 */
#ifndef UMBRA_API_GLTF_MATERIAL_H
#define UMBRA_API_GLTF_MATERIAL_H

#include <stdbool.h>
#include <stdint.h>
#include <jansson.h>
#include "model.h"

struct api_gltf_material {
	float emissive_strength;           /* 1 */
	bool unlit;                        /* KHR_materials_unlit */
	/* KHR_materials_pbrSpecularGlossiness on a material without pbrMetallicRoughness
	 * (api/gltf_material_ext.c): base colour diffuseFactor (x diffuseTexture, which Assimp
	 * hands over as the base colour's DIFFUSE texture), roughness 1 - glossinessFactor (x the
	 * specularGlossinessTexture's A), F0 the specular colour (the specular members below). */
	bool spec_gloss;
	float diffuse[4], glossiness;
	/* KHR_materials_transmission's factor (0): drawn as partial coverage, see shading; and
	 * KHR_materials_volume's medium: attenuation colour (1, 1, 1), distance (0: none),
	 * thicknessFactor, and its thicknessTexture's image (-1: none; drawn as the mean of its G
	 * over the texture, thickness_mean, which api/model_material.c sets once it is decoded). */
	float transmission, attenuation[3], attenuation_distance, thickness, thickness_mean;
	int32_t thickness_image;
	/* KHR_materials_clearcoat, _sheen, _specular and _ior as rnd_material has them
	 * (api/gltf_material_ext.c); ext_image: per extension texture slot, its image's index in
	 * api_gltf_info.images (-1: none). */
	uint32_t extensions;
	struct { float factor, roughness, normal_scale; } clearcoat;
	struct { float color[3], roughness; } sheen;
	struct { float factor, color[3], ior; bool spec_gloss; } specular;
	int32_t ext_image[RND_TEX_SLOTS];
	bool double_sided;                 /* false (glTF's default) */
	float normal_scale, occlusion_strength;    /* 1, 1 */
	struct rnd_texture_sampling sampling[RND_TEX_SLOTS];
};

/* An image the extensions' textures read, taken from the document before Assimp (which loads
 * only the images its own materials name): its file's uri, or its encoded bytes (a
 * bufferView, a data: URI); tex: decoded once, by the first slot that reads it. */
struct api_gltf_image {
	char *uri;
	uint8_t *bytes;
	size_t len;
	const struct rnd_texture *tex;
};

struct api_gltf_info {
	struct api_gltf_material *materials;
	uint32_t material_count;
	struct api_gltf_image *images;     /* per image of the document (image_count) */
	uint32_t image_count;
	char warnings[API_MODEL_MAX_WARNINGS + 1];   /* "" when none */
};

/* Reads root (a JSON object). Never fails: what cannot be read stays at glTF's defaults (a
 * materials array it cannot allocate leaves material_count 0). */
void api_gltf_info_read(json_t *root, struct api_gltf_info *out);
void api_gltf_info_free(struct api_gltf_info *gi);
/* The file's bytes with every material's name replaced by its index tag (malloc'd, you free
 * it), or NULL (no materials and root not `changed` otherwise, or out of memory: import the
 * original then). root is changed. */
uint8_t *api_gltf_tag_materials(json_t *root, const uint8_t *data, size_t len, bool glb, bool changed,
                                size_t *out_len);
/* The glTF material index an Assimp material name tags, or -1. */
int api_gltf_material_of(const char *name);
/* What material `index` of the document adds to m as Assimp read it: emissive x strength,
 * the samplings, normal scale, occlusion strength; *single_sided from doubleSided. Nothing
 * when index is past the document's materials. */
void api_gltf_material_apply(const struct api_gltf_info *gi, uint32_t index, struct rnd_material *m,
                             bool *single_sided);
/* What material `index` changes once its textures are known: KHR_materials_unlit drawn as its
 * base colour alone (moved to the emissive term, which no light or shadow changes: base
 * colour black, alpha kept; normal and occlusion maps dropped); specular-glossiness (metallic
 * 0, base colour diffuseFactor, roughness 1 - glossiness, or 1 under the metallic-roughness
 * slot made of the glossiness);
 * KHR_materials_transmission as dithered coverage (alpha mode BLEND, alpha x (1 - 0.8 x
 * transmission x the mean of the volume's transmittance), transmissionTexture's R a factor of
 * the transmission per pixel (the renderer's see_through slot): clear glass shows a fifth of its
 * surface and lets four fifths of the light through to its shadow; with KHR_materials_volume
 * the shown part is tinted by the transmittance and denser glass shows more of it), not
 * refraction. */
void api_gltf_material_shading(const struct api_gltf_info *gi, uint32_t index, struct rnd_material *m);
/* The name of texture slot k in a glTF material ("baseColorTexture", ..., "specularColorTexture"). */
const char *api_gltf_slot_name(uint32_t k);
/* Texture info `info` of material mi into gm->sampling[slot] (sampler, transform, uv set;
 * the normal scale and occlusion strength of those slots). */
void api_gltf_read_texinfo(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, uint32_t slot,
                           json_t *info, struct api_gltf_material *gm);
/* The PBR extensions of material mi (its "extensions" object ext) into gm
 * (api/gltf_material_ext.c; specular-glossiness only when spec_gloss: the material has no
 * pbrMetallicRoughness), and from gm into m (what api_gltf_material_apply adds). */
void api_gltf_read_material_ext(struct api_gltf_info *gi, json_t *root, uint32_t mi, const char *mname, json_t *ext,
                                bool spec_gloss, struct api_gltf_material *gm);
void api_gltf_material_ext_apply(const struct api_gltf_material *gm, struct rnd_material *m);
/* KHR_materials_volume's transmittance t per channel through thickness x thickness_mean:
 * attenuationColor ^ (thickness / attenuationDistance) (Beer's law, as the sample viewer
 * attenuates what it refracts); 1 without a distance or a thickness. */
void api_gltf_volume_transmittance(const struct api_gltf_material *gm, float t[3]);
/* Takes the uri or the bytes of every image an extension slot reads (b: the document's
 * buffers, api/gltf_buffers.h) into gi->images. Never fails: an image it cannot take is
 * warned and left out. */
struct api_gltf_bufs;
void api_gltf_ext_images(struct api_gltf_info *gi, struct api_gltf_bufs *b);
/* Vertex data: n RGBA float colours -> linear RGBA8 (clamped); n tangents, bitangents and
 * normals (xyz floats) -> xyzw tangents, w = the side of the bitangent (+1 / -1). */
void api_vertex_colors(const float *rgba, uint32_t n, uint8_t *out);
void api_vertex_tangents(const float *t, const float *b, const float *nrm, uint32_t n, float *out);
/* Adds a warning (once; dropped past the size limit, with "..."). */
void api_gltf_warn(struct api_gltf_info *gi, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
