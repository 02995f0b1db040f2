/*
 * umbra renderer — the materials of a scene (struct rnd_material and its textures), part of the
 * public API: included by umbra/rnd.h where the scene description needs it; include that.
 * Ownership and threading: as umbra/rnd.h's scene (the caller's, read during a render).
 */
#ifndef UMBRA_RND_MATERIAL_H
#define UMBRA_RND_MATERIAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* BLEND is drawn dithered: an ordered 4x4 threshold pattern keeps a pixel when alpha is over
 * its threshold (deterministic: the same request gives the same bytes), and shadow maps use the
 * same test, so a surface of coverage a casts a shadow of about a once filtered. */
enum rnd_alpha_mode { RND_ALPHA_OPAQUE, RND_ALPHA_MASK, RND_ALPHA_BLEND };

/* Texture slots of a material (the order of rnd_material.textures): glTF's core five, then
 * those of the PBR extensions (read only where the material has that extension), then the
 * see-through share of the coverage (rnd_material.see_through). */
enum rnd_texture_slot { RND_TEX_BASE, RND_TEX_METAL_ROUGH, RND_TEX_NORMAL, RND_TEX_OCCLUSION, RND_TEX_EMISSIVE,
                        RND_TEX_CLEARCOAT, RND_TEX_CLEARCOAT_ROUGHNESS, RND_TEX_CLEARCOAT_NORMAL,
                        RND_TEX_SHEEN_COLOR, RND_TEX_SHEEN_ROUGHNESS, RND_TEX_SPECULAR, RND_TEX_SPECULAR_COLOR,
                        RND_TEX_TRANSMISSION, RND_TEX_SLOTS };
/* rnd_material.extensions: the glTF 2.0 PBR extensions a material has (0: none; the members
 * of the others are not read). */
enum rnd_material_ext {
	RND_EXT_CLEARCOAT = 1,   /* KHR_materials_clearcoat */
	RND_EXT_SHEEN = 2,       /* KHR_materials_sheen */
	RND_EXT_SPECULAR = 4,    /* KHR_materials_specular and / or KHR_materials_ior */
};
enum rnd_wrap { RND_WRAP_REPEAT, RND_WRAP_CLAMP, RND_WRAP_MIRROR };
/* Between mip levels (every texture gets its full chain, built at upload): linear (glTF's
 * *_MIPMAP_LINEAR and an absent minFilter), none (minFilter NEAREST or LINEAR: level 0 only),
 * nearest (*_MIPMAP_NEAREST). */
enum rnd_mip { RND_MIP_LINEAR, RND_MIP_NONE, RND_MIP_NEAREST };

/* A decoded texture: RGBA8, rows top to bottom, as stored in the file. The slot that uses it
 * says how it is read: base colour and emissive as sRGB (alpha linear), the others linear. */
struct rnd_texture {
	const uint8_t *rgba;
	uint32_t width, height;
	/* Optional: the mip chain's levels 1.. (level 0 is rgba) as rnd_texture_build_chain() writes
	 * them after level 0 for colour space chain_srgb, built once by the owner of a long-lived
	 * texture (a cached model) so that renders copy them instead of building them (a 2048^2
	 * chain is ~40 ms of CPU); 1/3 of rgba's bytes. NULL, or read by a slot of the other colour
	 * space: built at upload. */
	const uint8_t *chain;
	bool chain_srgb;
};
/* The colour space a slot reads its texture in: base colour, emissive, sheen colour and
 * specular colour sRGB, and the slots read in alpha (sheen roughness, specular) too (alpha is
 * linear either way: a texture holding colour and alpha is then one image); the others linear. */
bool rnd_texture_slot_srgb(enum rnd_texture_slot slot);
/* Bytes of the full RGBA8 chain of a w x h texture down to 1x1, levels packed one after the
 * other (level 0 first). */
uint64_t rnd_texture_chain_bytes(uint32_t w, uint32_t h);
/* Writes the chain of rgba (w x h RGBA8) to out (rnd_texture_chain_bytes() bytes): level 0 as
 * given, each further level the 2x2 box average of the one before (an odd last row or column
 * folds into its neighbour's box), in linear light when srgb (alpha is always linear). Pure;
 * any thread. */
void rnd_texture_build_chain(const uint8_t *rgba, uint32_t w, uint32_t h, bool srgb, uint8_t *out);
/* rgba (*w x *h) replaced, in place, by level `levels` of that chain (the same bytes), its size
 * in *w x *h: a texture decoded smaller than stored (api/image_decode.c). Pure; any thread. */
void rnd_texture_reduce(uint8_t *rgba, uint32_t *w, uint32_t *h, bool srgb, uint32_t levels);

/* Every rnd_*_defaults() below zeroes its whole struct before setting members: api/scene_hash.c
 * hashes a parsed scene by the bytes of these structs (padding included; pointers as set or
 * not), so a new pointer member needs its line there. */
struct rnd_material {
	float base_color[4];  /* linear RGBA, default 0.8 0.8 0.8 1 */
	float roughness;      /* 0.5 */
	float metallic;       /* 0 */
	float emissive[3];    /* 0 */
	enum rnd_alpha_mode alpha_mode;
	float alpha_cutoff;   /* 0.5 */
	bool shadow_catcher;  /* not drawn; only received shadows show */
	/* Textures, NULL = none, sampled with the uvs (glTF 2.0 meanings): base colour x base_color;
	 * metallic-roughness (B x metallic, G x roughness); normal (tangent space, xy x normal_scale);
	 * occlusion (R, mixed in by occlusion_strength, ambient light only); emissive x emissive. */
	union {
		struct {
			const struct rnd_texture *base_color_texture, *metal_rough_texture, *normal_texture,
			                         *occlusion_texture, *emissive_texture;
			const struct rnd_texture *clearcoat_texture, *clearcoat_roughness_texture, *clearcoat_normal_texture,
			                         *sheen_color_texture, *sheen_roughness_texture, *specular_texture,
			                         *specular_color_texture, *transmission_texture;
		};
		const struct rnd_texture *textures[RND_TEX_SLOTS];
	};
	float normal_scale;        /* 1 */
	float occlusion_strength;  /* 1 */
	/* With transmission_texture: the coverage (alpha, as MASK or BLEND draw it, shadows too) is
	 * alpha x (1 - see_through x the texture's R), per pixel (0..1; 0 default: none). api/
	 * draws KHR_materials_transmission's texture so (api_gltf_material_shading). */
	float see_through;
	/* How each slot's texture is sampled (zero = repeat, linear, untransformed). */
	struct rnd_texture_sampling {
		uint8_t wrap_s, wrap_t;             /* enum rnd_wrap */
		bool mag_nearest, min_nearest;
		uint8_t mip;                        /* enum rnd_mip */
		/* The uv set the slot samples: 0 the object's uvs, 1 its uvs1 (glTF texCoord 1;
		 * an object without uvs1 draws it with uvs). */
		uint8_t uv_set;
		bool transformed;                   /* KHR_texture_transform: uv' = M (u, v, 1) */
		float transform[6];                 /* rows of M: (m00 m01 m02), (m10 m11 m12) */
	} sampling[RND_TEX_SLOTS];
	/* The glTF PBR extensions, drawn as the Khronos sample viewer draws them under punctual
	 * lights (shaders/material_ext.glsl); each group is read only where `extensions` has its
	 * bit, so a zeroed material has none. Textures: the slots above, factor x texture. */
	uint32_t extensions;       /* RND_EXT_* */
	struct {
		float factor;          /* 0..1: how much of the coat (x clearcoat_texture R) */
		float roughness;       /* 0..1 (x clearcoat_roughness_texture G) */
		float normal_scale;    /* clearcoat_normal_texture's xy scale (no texture: the geometric normal) */
	} clearcoat;
	struct {
		float color[3];        /* linear, 0 = no sheen (x sheen_color_texture) */
		float roughness;       /* 0..1 (x sheen_roughness_texture A) */
	} sheen;
	struct {
		float factor;          /* 0..1 the specular weight (x specular_texture A); glTF default 1 */
		float color[3];        /* linear, multiplies the dielectric F0 (x specular_color_texture); default 1 */
		float ior;             /* >= 1 (KHR_materials_ior; 1.5 gives F0 0.04) */
		/* The specular-glossiness model (KHR_materials_pbrSpecularGlossiness, as the sample
		 * viewer draws it): F0 is the whole specular (the colour, ior ~infinite), the diffuse
		 * keeps 1 - max(F0) of the base colour, and the ambient light reflects F0 as it does a
		 * metal's base colour. false (default): a dielectric's F0, no ambient term (the core's). */
		bool spec_gloss;
	} specular;
};

#ifdef __cplusplus
}
#endif

#endif
