/*
 * renderer/material — glTF 2.0 materials on the GPU: the umbra_material record of each
 * rnd_material, and the render's material textures (images, samplers, set-1 descriptor sets).
 *
 * Usage (render.c): rnd_material_textures() once per render after upload() (it sets each
 * draw's texture_set and tex_bits, creates the images and stages their texels for
 * record_textures()); rnd_material_write() for every material when the parameters are written.
 * Ownership: images live in the slot (dropped when its next render starts).
 * Threading: one render per slot at a time, as for everything in a slot.
 */
#ifndef UMBRA_RENDERER_MATERIAL_H
#define UMBRA_RENDERER_MATERIAL_H

#include "material_bits.h"
#include "record.h"

/* The GPU record of one material (umbra_shared.h). */
void rnd_material_write(const struct rnd_material *in, struct umbra_material *out);

/* The record of material `index` of sc as the materials buffer holds it (a scene without
 * materials has one: the defaults, index 0). The main pass pushes its head per draw. */
void rnd_material_record(const struct rnd_scene *sc, uint32_t index, struct umbra_material *out);

/* Creates the scene's distinct textures (per colour space: base colour and emissive read
 * sRGB, the others linear) in the slot, stages their texels (tex[] in staging order,
 * *ntex of them), writes one set-1 descriptor set per distinct combination of images and
 * samplers that a draw uses and points draws at it. RND_ERR_LIMIT at the object that brought
 * one too many, past ctx->max_textures images or rnd_texture_sets() combinations. */
/* Descriptor sets of textured materials a slot holds for max_textures distinct images (besides
 * the white set 0): twice as many, since materials combine the same images differently. */
static inline uint32_t rnd_texture_sets(uint32_t max_textures) { return 2 * max_textures; }

enum rnd_result rnd_material_textures(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                      struct draw *draws, const struct rnd_texture **tex, uint32_t *ntex,
                                      struct rnd_error *err);

#endif
