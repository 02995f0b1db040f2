/*
 * renderer/readback.c — the copy of a finished render out of the slot's readback buffer (see
 * readback.h): colour pixels (un-premultiplied where PNG expects straight
 * alpha) and the AOV attachments split into named float planes; and the recorded copy of a
 * band's resolved colour into that buffer (record_readback).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "estimate.h"
#include "readback.h"
#include "record.h"

/* Turns the AOV attachments in the readback buffer (RGBA32F, sheet-sized each) into named
 * float planes. */
static enum rnd_result split_aovs(const struct rnd_scene *sc, const float *rb, size_t att_floats, uint32_t npix,
                                  struct rnd_image *out, struct rnd_error *err)
{
	uint32_t aovs = sc->output.aovs;
	struct { char name[24]; uint32_t att, comp; } plan[RND_MAX_AOV_PLANES];
	uint32_t n = 0;
	if (aovs & RND_AOV_SHADOW) {
		for (uint32_t i = 0; i < sc->light_count; i++) {
			uint32_t att = UMBRA_AOV_LIGHT_TARGET(i), comp = UMBRA_AOV_LIGHT_COMPONENT(i);
			snprintf(plan[n].name, sizeof plan[n].name, "shadow.%u", i);
			plan[n].att = att; plan[n].comp = comp; n++;
		}
	}
	if (aovs & RND_AOV_DEPTH) { snprintf(plan[n].name, 24, "Z"); plan[n].att = 0; plan[n].comp = 0; n++; }
	if (aovs & RND_AOV_NORMAL) {
		const char *nm[3] = {"N.X", "N.Y", "N.Z"};
		for (int k = 0; k < 3; k++) { snprintf(plan[n].name, 24, "%s", nm[k]); plan[n].att = 0; plan[n].comp = 1 + k; n++; }
	}
	if (aovs & RND_AOV_ALBEDO) {
		const char *nm[3] = {"albedo.R", "albedo.G", "albedo.B"};
		for (int k = 0; k < 3; k++) { snprintf(plan[n].name, 24, "%s", nm[k]); plan[n].att = 1; plan[n].comp = k; n++; }
	}
	for (uint32_t p = 0; p < n; p++) {
		float *plane = malloc((size_t)npix * sizeof(float));
		if (!plane) return rnd_fail(err, RND_ERR_OOM, "out of memory for AOV '%s'", plan[p].name);
		const float *src = rb + plan[p].att * att_floats + plan[p].comp;
		for (uint32_t i = 0; i < npix; i++) plane[i] = src[(size_t)i * 4];
		out->aov[p] = plane;
		memcpy(out->aov_names[p], plan[p].name, sizeof out->aov_names[p]);
		out->aov_count = p + 1;
	}
	return RND_OK;
}

/* One pixel (c[3] alpha, max = the format's 1.0) from premultiplied to straight, rounded. */
static void straight_alpha(uint32_t c[4], uint32_t max)
{
	uint32_t a = c[3];
	if (a == 0 || a == max) return;
	for (int k = 0; k < 3; k++) {
		uint32_t v = (c[k] * max + a / 2) / a;
		c[k] = v > max ? max : v;
	}
}

/* 8/16-bit outputs with transparency: straight alpha (PNG's convention) from the premultiplied
 * resolve. RGBA32F (EXR) stays premultiplied, as EXR expects. */
static void unpremultiply(void *pixels, uint64_t n, enum rnd_pixel_format f)
{
	uint32_t c[4];
	if (f == RND_PIXELS_RGBA8) {
		uint8_t *p = pixels;
		for (uint64_t i = 0; i < n; i++, p += 4) {
			for (int k = 0; k < 4; k++) c[k] = p[k];
			straight_alpha(c, 255u);
			for (int k = 0; k < 3; k++) p[k] = (uint8_t)c[k];
		}
	} else if (f == RND_PIXELS_RGBA16) {
		uint16_t *p = pixels;
		for (uint64_t i = 0; i < n; i++, p += 4) {
			for (int k = 0; k < 4; k++) c[k] = p[k];
			straight_alpha(c, 65535u);
			for (int k = 0; k < 3; k++) p[k] = (uint16_t)c[k];
		}
	}
}

enum rnd_result rnd_readback_image(const struct rnd_slot *s, const struct rnd_scene *sc, const struct rnd_sheet *sh,
                                   struct rnd_image *out, struct rnd_error *err)
{
	uint64_t sheet_w = sh->width, sheet_h = sh->height;
	size_t px = sh->px;
	VkDeviceSize color_bytes = sh->color_bytes;
	out->pixels = malloc(color_bytes);
	if (!out->pixels) return rnd_fail(err, RND_ERR_OOM, "out of memory for a %llux%llu image",
	                                 (unsigned long long)sheet_w, (unsigned long long)sheet_h);
	memcpy(out->pixels, s->readback.map, color_bytes);
	if (sc->output.transparent && sc->output.debug == RND_DEBUG_NONE) unpremultiply(out->pixels, sheet_w * sheet_h, sc->output.pixels);
	out->width = (uint32_t)sheet_w;
	out->height = (uint32_t)sheet_h;
	out->format = sc->output.pixels;
	out->stride = sheet_w * px;
	out->view_count = sh->views;
	out->view_columns = sh->cols;
	out->view_width = sc->width;
	out->view_height = sc->height;
	enum rnd_result r;
	if (sh->passes && (r = split_aovs(sc, (const float *)((const uint8_t *)s->readback.map + color_bytes), sh->att_bytes / 4,
	                                  (uint32_t)(sheet_w * sheet_h), out, err)) != RND_OK) {
		rnd_image_release(out);
		return r;
	}
	return RND_OK;
}

void record_readback(struct rnd_slot *s, const struct record_view *rv)
{
	const struct rnd_scene *sc = rv->sc;
	VkCommandBuffer cmd = s->cmd;
	record_image_barrier(cmd, s->resolve.img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
	              VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
	              VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
	VkRect2D area = record_band_area(rv);
	VkBufferImageCopy region = {
		.bufferOffset = rv->color_offset + (VkDeviceSize)area.offset.y * rv->sheet_width * rv->pixel_bytes,
		.bufferRowLength = rv->sheet_width,
		.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
		.imageOffset = {0, area.offset.y, 0}, .imageExtent = {sc->width, area.extent.height, 1},
	};
	vkCmdCopyImageToBuffer(cmd, s->resolve.img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s->readback.buf, 1, &region);
	VkBufferMemoryBarrier2 bb = {
		.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_TRANSFER_BIT,
		.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT, .dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT,
		.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT, .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
		.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .buffer = s->readback.buf, .size = VK_WHOLE_SIZE,
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .bufferMemoryBarrierCount = 1, .pBufferMemoryBarriers = &bb};
	vkCmdPipelineBarrier2(cmd, &di);
}
