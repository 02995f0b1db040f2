/*
 * renderer/material_bits.h — what a material draws, from the material alone: which texture
 * slots it samples and which extension lobes it has. Pure (static inline): the render plan
 * (render_plan.c, visibility_plan.c: pixel shading draws plain materials only) and material.c
 * (its records and texture sets) read the same rule.
 */
#ifndef UMBRA_RENDERER_MATERIAL_BITS_H
#define UMBRA_RENDERER_MATERIAL_BITS_H

#include <stddef.h>
#include "umbra/rnd.h"
#include "umbra_shared.h"

/* The extension lobe (RND_EXT_*) a texture slot belongs to; 0 for the core slots. */
static inline uint32_t rnd_material_slot_extension(uint32_t k)
{
	if (k >= RND_TEX_CLEARCOAT && k <= RND_TEX_CLEARCOAT_NORMAL) return RND_EXT_CLEARCOAT;
	if (k == RND_TEX_SHEEN_COLOR || k == RND_TEX_SHEEN_ROUGHNESS) return RND_EXT_SHEEN;
	if (k == RND_TEX_SPECULAR || k == RND_TEX_SPECULAR_COLOR) return RND_EXT_SPECULAR;
	return 0;
}

/* Slot k's texture as drawn: NULL where the material lacks the slot's extension. */
static inline const struct rnd_texture *rnd_material_slot_texture(const struct rnd_material *m, uint32_t k)
{
	uint32_t e = rnd_material_slot_extension(k);
	return e && !(m->extensions & e) ? NULL : m->textures[k];
}

/* The slots m samples, (1 << k) each (struct draw.tex_bits' low bits). */
static inline uint32_t rnd_material_slot_bits(const struct rnd_material *m)
{
	uint32_t bits = 0;
	for (uint32_t k = 0; k < RND_TEX_SLOTS; k++)
		if (rnd_material_slot_texture(m, k)) bits |= 1u << k;
	return bits;
}

/* The UMBRA_EXT_* lobes material m draws (a coat of factor 0 or a black sheen: none); their
 * union over the drawn materials is UMBRA_SC_MATERIAL_EXT. */
static inline uint32_t rnd_material_ext_bits(const struct rnd_material *m)
{
	uint32_t bits = 0;
	if ((m->extensions & RND_EXT_CLEARCOAT) && m->clearcoat.factor > 0) bits |= UMBRA_EXT_CLEARCOAT;
	if ((m->extensions & RND_EXT_SHEEN) && (m->sheen.color[0] > 0 || m->sheen.color[1] > 0 || m->sheen.color[2] > 0))
		bits |= UMBRA_EXT_SHEEN;
	if (m->extensions & RND_EXT_SPECULAR) bits |= UMBRA_EXT_SPECULAR;
	return bits;
}

#endif
