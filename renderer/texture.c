/*
 * renderer/texture — mip chains of material textures (see texture.h for why on the CPU).
 */
#include <math.h>
#include <pthread.h>
#include <string.h>
#include "texture.h"

uint32_t rnd_texture_levels(uint32_t w, uint32_t h)
{
	uint32_t m = w > h ? w : h, n = 1;
	while (m > 1) {
		m >>= 1;
		n++;
	}
	return n;
}

static uint32_t half(uint32_t v) { return v > 1 ? v / 2 : 1; }

uint64_t rnd_texture_chain_bytes(uint32_t w, uint32_t h)
{
	uint64_t b = 0;
	for (uint32_t l = rnd_texture_levels(w, h); l; l--, w = half(w), h = half(h)) b += (uint64_t)w * h * 4;
	return b;
}

/* sRGB <-> linear for the averaging, in integers: dec maps an sRGB byte to linear light in
 * 16 bits; enc maps linear light in 14 bits (the average's top bits) back to the byte. 2^14
 * steps keep the darkest sRGB steps apart (1/255 encoded is 3.0e-4 linear; a step is 6.1e-5). */
#define ENC_BITS 14
struct srgb_tables {
	uint16_t dec[256];
	uint8_t enc[1 << ENC_BITS];
};

static struct srgb_tables tables;
static pthread_once_t tables_once = PTHREAD_ONCE_INIT;

static void tables_once_init(void)
{
	struct srgb_tables *t = &tables;
	for (int i = 0; i < 256; i++) {
		float c = (float)i / 255.0f;
		float l = c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
		t->dec[i] = (uint16_t)lrintf(l * 65535.0f);
	}
	for (int i = 0; i < (1 << ENC_BITS); i++) {
		float l = ((float)i + 0.5f) / (float)(1 << ENC_BITS);
		float c = l <= 0.0031308f ? l * 12.92f : 1.055f * powf(l, 1.0f / 2.4f) - 0.055f;
		t->enc[i] = (uint8_t)lrintf(c * 255.0f);
	}
}

/* One level from the one above it (sw x sh -> dw x dh). Each destination texel averages the
 * source texels it covers: 2x2, or 3 wide/tall at the last column/row of an odd size, or 1
 * along a side already at 1. Integer sums, rounded: the same bytes on every machine. */
static void downsample(const uint8_t *src, uint32_t sw, uint32_t sh, uint8_t *dst, uint32_t dw, uint32_t dh,
                       const struct srgb_tables *t)
{
	for (uint32_t y = 0; y < dh; y++) {
		uint32_t y0 = sh == 1 ? 0 : 2 * y, y1 = sh == 1 ? 0 : (y == dh - 1 ? sh - 1 : 2 * y + 1);
		for (uint32_t x = 0; x < dw; x++) {
			uint32_t x0 = sw == 1 ? 0 : 2 * x, x1 = sw == 1 ? 0 : (x == dw - 1 ? sw - 1 : 2 * x + 1);
			uint8_t *o = dst + ((size_t)y * dw + x) * 4;
			if (x1 == x0 + 1 && y1 == y0 + 1) {   /* the common 2x2 box, unrolled */
				const uint8_t *a = src + ((size_t)y0 * sw + x0) * 4, *b = a + (size_t)sw * 4;
				for (int c = 0; c < 3; c++)
					o[c] = t ? t->enc[(t->dec[a[c]] + t->dec[a[c + 4]] + t->dec[b[c]] + t->dec[b[c + 4]] + 2u) >>
					                  (2 + 16 - ENC_BITS)]
					         : (uint8_t)((a[c] + a[c + 4] + b[c] + b[c + 4] + 2u) >> 2);
				o[3] = (uint8_t)((a[3] + a[7] + b[3] + b[7] + 2u) >> 2);
				continue;
			}
			uint32_t acc[4] = {0, 0, 0, 0}, n = (y1 - y0 + 1) * (x1 - x0 + 1);
			for (uint32_t yy = y0; yy <= y1; yy++) {
				const uint8_t *p = src + ((size_t)yy * sw + x0) * 4;
				for (uint32_t xx = x0; xx <= x1; xx++, p += 4) {
					for (int c = 0; c < 3; c++) acc[c] += t ? t->dec[p[c]] : p[c];
					acc[3] += p[3];
				}
			}
			for (int c = 0; c < 4; c++) {
				uint32_t v = (acc[c] + n / 2) / n;
				o[c] = t && c < 3 ? t->enc[v >> (16 - ENC_BITS)] : (uint8_t)v;
			}
		}
	}
}

void rnd_texture_reduce(uint8_t *rgba, uint32_t *w, uint32_t *h, bool srgb, uint32_t levels)
{
	if (srgb && levels) pthread_once(&tables_once, tables_once_init);
	/* in place: a texel is written at or before where its box is read */
	for (; levels && (*w > 1 || *h > 1); levels--) {
		uint32_t dw = half(*w), dh = half(*h);
		downsample(rgba, *w, *h, rgba, dw, dh, srgb ? &tables : NULL);
		*w = dw;
		*h = dh;
	}
}

void rnd_texture_build_chain(const uint8_t *rgba, uint32_t w, uint32_t h, bool srgb, uint8_t *out)
{
	if (srgb) pthread_once(&tables_once, tables_once_init);
	memcpy(out, rgba, (size_t)w * h * 4);
	uint8_t *src = out;
	for (uint32_t l = rnd_texture_levels(w, h); l > 1; l--) {
		uint32_t dw = half(w), dh = half(h);
		uint8_t *dst = src + (size_t)w * h * 4;
		downsample(src, w, h, dst, dw, dh, srgb ? &tables : NULL);
		src = dst;
		w = dw;
		h = dh;
	}
}

static void barrier(VkCommandBuffer cmd, VkImage img, VkImageLayout from, VkImageLayout to, VkPipelineStageFlags2 ss,
                    VkAccessFlags2 sa, VkPipelineStageFlags2 ds, VkAccessFlags2 da)
{
	VkImageMemoryBarrier2 b = {
		.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = ss, .srcAccessMask = sa,
		.dstStageMask = ds, .dstAccessMask = da, .oldLayout = from, .newLayout = to,
		.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = img,
		.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, 1},
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1, .pImageMemoryBarriers = &b};
	vkCmdPipelineBarrier2(cmd, &di);
}

uint64_t rnd_texture_record_upload(VkCommandBuffer cmd, VkBuffer buf, VkDeviceSize offset, VkImage img, uint32_t w,
                                   uint32_t h)
{
	VkBufferImageCopy regions[32];   /* 16384^2 has 15 levels; the side is capped well below 2^31 */
	uint32_t n = rnd_texture_levels(w, h);
	VkDeviceSize off = offset;
	for (uint32_t l = 0; l < n; l++, w = half(w), h = half(h)) {
		regions[l] = (VkBufferImageCopy){
			.bufferOffset = off, .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1}, .imageExtent = {w, h, 1},
		};
		off += (VkDeviceSize)w * h * 4;
	}
	barrier(cmd, img, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
	        VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
	vkCmdCopyBufferToImage(cmd, buf, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, n, regions);
	barrier(cmd, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
	        VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	        VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
	return off - offset;
}
