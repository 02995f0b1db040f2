/*
 * renderer/texture — mip chains of material textures, built on the CPU at upload.
 *
 * Usage: rnd_material_textures() sizes the staging buffer with rnd_texture_chain_bytes(),
 * creates each image with rnd_texture_levels() levels and writes its chain into the staging
 * memory with rnd_texture_build_chain(); record_textures() then calls rnd_texture_record_upload()
 * per image, in the same order, which copies every level and leaves the image ready to sample.
 * Ownership: nothing here allocates; the caller owns every buffer and image.
 * Threading: pure functions, and command recording into the caller's command buffer.
 *
 * Why the CPU and not vkCmdBlitImage level by level: the same bytes on every device (a blit's
 * filter is the implementation's, and needs BLIT_SRC/DST and FILTER_LINEAR on the format), a
 * box filter in linear light for sRGB images written out here, and no extra barriers per
 * level; the cost is one pass over the texels (a 2048^2 chain: see tests/unit/test_texture.c).
 */
#ifndef UMBRA_RENDERER_TEXTURE_H
#define UMBRA_RENDERER_TEXTURE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <vulkan/vulkan.h>
#include "umbra/rnd.h"

/* Levels of the full chain of a w x h image, down to 1x1: floor(log2(max(w, h))) + 1. */
uint32_t rnd_texture_levels(uint32_t w, uint32_t h);

/* rnd_texture_chain_bytes(), rnd_texture_build_chain() and rnd_texture_slot_srgb() are public
 * (umbra/rnd.h): a model's owner may build its chains once (rnd_texture.chain). */

/* Records the copy of one chain from buf at offset into img (created with
 * rnd_texture_levels() levels, layout undefined) and its transition to shader-read; returns
 * the chain's bytes, so the caller can advance the offset. */
uint64_t rnd_texture_record_upload(VkCommandBuffer cmd, VkBuffer buf, VkDeviceSize offset, VkImage img, uint32_t w,
                                   uint32_t h);

#endif
