/*
 * renderer/material — glTF 2.0 materials on the GPU (see material.h).
 *
 * A material samples only the textures it has: umbra_material.tex.x carries one bit per slot
 * and the scene's union of those bits specialises mesh.frag (UMBRA_SC_TEXTURES), so an
 * untextured scene runs no texture code at all. Slots a textured material lacks are bound to
 * the slot's white 1x1, which is the neutral value of every multiply (base, metal-rough,
 * occlusion, emissive); the normal map's bit gates its use. Every image carries its full mip
 * chain (renderer/texture.c), so a texture far smaller on screen than in the file is averaged,
 * not aliased; the sampler's rnd_mip decides whether the chain is read. A slot whose sampling
 * says uv_set 1 has its bit (1 << (UMBRA_TEX_UV1_SHIFT + slot)) in tex.x, and the scene's
 * UMBRA_TEXBIT_UV1 turns on the shaders' second-uv path only where the slot has that set.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "material.h"
#include "texture.h"

bool rnd_texture_slot_srgb(enum rnd_texture_slot slot)
{
	return slot == RND_TEX_BASE || slot == RND_TEX_EMISSIVE || slot == RND_TEX_SHEEN_COLOR ||
	       slot == RND_TEX_SHEEN_ROUGHNESS || slot == RND_TEX_SPECULAR || slot == RND_TEX_SPECULAR_COLOR;
}

void rnd_material_record(const struct rnd_scene *sc, uint32_t index, struct umbra_material *out)
{
	if (sc->material_count) {
		rnd_material_write(&sc->materials[index], out);
		return;
	}
	struct rnd_material d;
	rnd_material_defaults(&d);
	memset(out, 0, sizeof *out);
	memcpy(out->base_color, d.base_color, sizeof d.base_color);
	out->emissive[3] = d.roughness;
}

static const struct rnd_texture *slot_texture(const struct rnd_material *m, uint32_t k)
{
	return rnd_material_slot_texture(m, k);
}

static float clamp01(float v)
{
	return !(v >= 0) ? 0 : v > 1 ? 1 : v;   /* NaN -> 0 */
}

/* The extensions' members of the record (umbra_shared.h): F0 from the ior as the sample
 * viewer has it, ((ior - 1) / (ior + 1))^2, for the base layer's dielectric and the coat. */
static void write_extensions(const struct rnd_material *in, struct umbra_material *out)
{
	uint32_t bits = rnd_material_ext_bits(in);
	out->ext[0] = bits;
	float ior = (in->extensions & RND_EXT_SPECULAR) && in->specular.ior >= 1 ? in->specular.ior : 1.5f;
	float r = (ior - 1) / (ior + 1), f0 = r * r;
	out->clearcoat[0] = clamp01(in->clearcoat.factor);
	out->clearcoat[1] = clamp01(in->clearcoat.roughness);
	out->clearcoat[2] = in->clearcoat.normal_scale;
	out->clearcoat[3] = f0;
	for (int k = 0; k < 3; k++) {
		out->sheen[k] = clamp01(in->sheen.color[k]);
		out->specular[k] = bits & UMBRA_EXT_SPECULAR ? f0 * fmaxf(in->specular.color[k], 0) : 0.04f;
	}
	out->sheen[3] = clamp01(in->sheen.roughness);
	out->specular[3] = bits & UMBRA_EXT_SPECULAR ? clamp01(in->specular.factor) : 1;
	out->ext[1] = (bits & UMBRA_EXT_SPECULAR) && in->specular.spec_gloss;
	float see = clamp01(in->see_through);
	memcpy(&out->ext[2], &see, sizeof see);
}

void rnd_material_write(const struct rnd_material *in, struct umbra_material *out)
{
	memset(out, 0, sizeof *out);
	memcpy(out->base_color, in->base_color, sizeof in->base_color);
	memcpy(out->emissive, in->emissive, sizeof in->emissive);
	out->emissive[3] = in->roughness;
	out->params[0] = in->metallic;
	out->params[1] = in->alpha_mode == RND_ALPHA_MASK ? in->alpha_cutoff : -1.0f;
	out->params[2] = in->normal_scale;
	out->params[3] = in->occlusion_strength;
	out->tex[1] = in->alpha_mode == RND_ALPHA_MASK ? UMBRA_ALPHA_MASK
	            : in->alpha_mode == RND_ALPHA_BLEND ? UMBRA_ALPHA_BLEND : UMBRA_ALPHA_OPAQUE;
	write_extensions(in, out);
	for (uint32_t k = 0; k < RND_TEX_SLOTS; k++) {
		const struct rnd_texture_sampling *ts = &in->sampling[k];
		const struct rnd_texture *t = slot_texture(in, k);
		if (t) out->tex[0] |= 1u << k;
		if (t && ts->uv_set == 1) out->tex[0] |= 1u << (UMBRA_TEX_UV1_SHIFT + k);
		float *r0 = out->uvx[2 * k], *r1 = out->uvx[2 * k + 1];
		if (ts->transformed) {
			memcpy(r0, ts->transform, 3 * sizeof(float));
			memcpy(r1, ts->transform + 3, 3 * sizeof(float));
		} else {
			r0[0] = 1.0f;
			r1[1] = 1.0f;
		}
	}
}

/* Distinct images up to ctx->max_textures; descriptor sets (one per distinct combination of
 * images and samplers a textured material binds, however many materials share it) up to
 * rnd_texture_sets(ctx->max_textures). */
struct tex_plan {
	uint32_t max, max_sets;
	uint32_t n;                                /* distinct images */
	const struct rnd_texture **tex;
	bool *srgb;
	uint32_t nsets;
	int16_t (*img)[UMBRA_TEX_SLOTS];          /* -1: white */
	uint8_t (*smp)[UMBRA_TEX_SLOTS];
};

/* The image index of texture t read in colour space srgb, added when new; -1 past the limit. */
static int image_of(struct tex_plan *p, const struct rnd_texture *t, bool srgb)
{
	for (uint32_t k = 0; k < p->n; k++)
		if (p->tex[k] == t && p->srgb[k] == srgb) return (int)k;
	if (p->n == p->max) return -1;
	p->tex[p->n] = t;
	p->srgb[p->n] = srgb;
	return (int)p->n++;
}

/* Gives material mi, first met on object o, its set (its images and samplers); 0 when it has
 * no texture. Materials that bind the same images with the same samplers share one set (their
 * factors are in the material buffer, not in the set): VC.glb's 147 materials use 20 images.
 * The limit's error names o: the object that brought one too many. */
static enum rnd_result plan_material(struct tex_plan *p, const struct rnd_scene *sc, uint32_t mi, uint32_t o,
                                     uint32_t *set, struct rnd_error *err)
{
	const struct rnd_material *m = &sc->materials[mi];
	bool any = false;
	for (uint32_t k = 0; k < RND_TEX_SLOTS; k++) any = any || slot_texture(m, k);
	*set = 0;
	if (!any) return RND_OK;
	int16_t img[UMBRA_TEX_SLOTS];
	uint8_t smp[UMBRA_TEX_SLOTS];
	for (uint32_t k = 0; k < UMBRA_TEX_SLOTS; k++) {
		img[k] = -1;
		smp[k] = 0;
	}
	for (uint32_t k = 0; k < RND_TEX_SLOTS; k++) {
		const struct rnd_texture *t = slot_texture(m, k);
		if (!t) continue;
		if (!t->rgba || !t->width || !t->height || t->width > RND_MAX_TEXTURE_SIDE || t->height > RND_MAX_TEXTURE_SIDE)
			return rnd_fail(err, RND_ERR_INVALID, "material %u: texture of %ux%u", mi, t->width, t->height);
		int ii = image_of(p, t, rnd_texture_slot_srgb((enum rnd_texture_slot)k));
		if (ii < 0)
			return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_OBJECT, o, "more than %u distinct textures in one scene "
			                   "(the limit: --max-textures)", p->max);
		img[k] = (int16_t)ii;
		smp[k] = (uint8_t)rnd_texture_sampler_index(&m->sampling[k]);
	}
	for (uint32_t si = 0; si < p->nsets; si++)
		if (!memcmp(p->img[si], img, sizeof img) && !memcmp(p->smp[si], smp, sizeof smp)) {
			*set = 1 + si;
			return RND_OK;
		}
	if (p->nsets == p->max_sets)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_OBJECT, o, "more than %u different combinations of textures "
		                   "and samplers in one scene (the limit: twice --max-textures)", p->max_sets);
	memcpy(p->img[p->nsets], img, sizeof img);
	memcpy(p->smp[p->nsets], smp, sizeof smp);
	*set = 1 + p->nsets++;
	return RND_OK;
}

static void write_sets(struct rnd_context *ctx, struct rnd_slot *s, const struct tex_plan *p)
{
	VkDescriptorImageInfo ii[UMBRA_TEX_SLOTS];
	VkWriteDescriptorSet w[UMBRA_TEX_SLOTS];
	for (uint32_t si = 0; si < p->nsets; si++) {
		for (uint32_t k = 0; k < UMBRA_TEX_SLOTS; k++) {
			int img = p->img[si][k];
			ii[k] = (VkDescriptorImageInfo){ctx->pipes.texture_samplers[img < 0 ? 0 : p->smp[si][k]],
			                                img < 0 ? s->white.view : s->textures[img].view,
			                                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
			w[k] = (VkWriteDescriptorSet){
				.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->texture_sets[1 + si], .dstBinding = k,
				.descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &ii[k],
			};
		}
		vkUpdateDescriptorSets(ctx->device, UMBRA_TEX_SLOTS, w, 0, NULL);
	}
}

enum rnd_result rnd_material_textures(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                      struct draw *draws, const struct rnd_texture **tex, uint32_t *ntex,
                                      struct rnd_error *err)
{
	enum rnd_result r = RND_OK;
	rnd_slot_drop_textures(ctx, s);
	*ntex = 0;
	uint32_t max = ctx->max_textures, max_sets = rnd_texture_sets(max);
	struct tex_plan *p = calloc(1, sizeof *p);
	if (p) {
		p->max = max;
		p->max_sets = max_sets;
		p->srgb = calloc(max, sizeof *p->srgb);
		p->img = calloc(max_sets, sizeof *p->img);
		p->smp = calloc(max_sets, sizeof *p->smp);
	}
	/* material -> its set + 1 (0 = not planned yet) */
	uint32_t *set_of = calloc(sc->material_count ? sc->material_count : 1, sizeof *set_of);
	if (!p || !p->srgb || !p->img || !p->smp || !set_of) {
		r = rnd_fail(err, RND_ERR_OOM, "out of memory planning textures");
		goto done;
	}
	p->tex = tex;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		draws[i].texture_set = 0;
		draws[i].tex_bits = 0;
		if (!sc->material_count) continue;
		uint32_t mi = sc->objects[i].material, set;
		if (!set_of[mi]) {
			if ((r = plan_material(p, sc, mi, i, &set, err)) != RND_OK) goto done;
			set_of[mi] = set + 1;
		}
		draws[i].texture_set = set_of[mi] - 1;
		for (uint32_t k = 0; k < RND_TEX_SLOTS; k++)
			if (slot_texture(&sc->materials[mi], k)) {
				draws[i].tex_bits |= 1u << k;
				/* the uv1 path only where the scene has the set (else binding 1 is uv0) */
				if (sc->materials[mi].sampling[k].uv_set == 1 && s->has_uv1) draws[i].tex_bits |= UMBRA_TEXBIT_UV1;
			}
	}
	VkDeviceSize bytes = 0, off = 0;
	for (uint32_t i = 0; i < p->n; i++) bytes += rnd_texture_chain_bytes(tex[i]->width, tex[i]->height);
	if (p->n && (r = rnd_buffer_reserve(ctx, &s->staging, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "slot staging", err)) != RND_OK)
		goto done;
	for (uint32_t i = 0; i < p->n; i++) {
		char name[48];
		snprintf(name, sizeof name, "slot %u texture %u", s->index, i);
		uint32_t w = tex[i]->width, h = tex[i]->height;
		if ((r = rnd_image_create_levels(ctx, p->srgb[i] ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM, w, h, 1,
		                                 1, rnd_texture_levels(w, h),
		                                 VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
		                                 VK_IMAGE_ASPECT_COLOR_BIT, name, &s->textures[i], err)) != RND_OK)
			goto done;
		s->texture_count = i + 1;
		uint8_t *dst = (uint8_t *)s->staging.map + off;
		if (tex[i]->chain && tex[i]->chain_srgb == p->srgb[i]) {
			size_t base = (size_t)w * h * 4;
			memcpy(dst, tex[i]->rgba, base);
			memcpy(dst + base, tex[i]->chain, rnd_texture_chain_bytes(w, h) - base);
		} else {
			rnd_texture_build_chain(tex[i]->rgba, w, h, p->srgb[i], dst);
		}
		off += rnd_texture_chain_bytes(w, h);
	}
	write_sets(ctx, s, p);
	*ntex = p->n;
done:
	free(set_of);
	if (p) {
		free(p->srgb);
		free(p->img);
		free(p->smp);
	}
	free(p);
	return r;
}
