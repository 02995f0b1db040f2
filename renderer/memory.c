/*
 * renderer/memory.c — buffers and images with their own device memory.
 *
 * A render uses a handful of long-lived allocations per slot (they grow and are kept), so one
 * vkAllocateMemory per resource is within every driver's allocation count limit.
 * Buffers are host-visible and persistently mapped: on lavapipe all memory is, and on a GPU
 * the buffers the GPU reads while drawing prefer HOST_VISIBLE|DEVICE_LOCAL (resizable BAR),
 * falling back to plain HOST_VISIBLE; those the CPU reads (readback) or builds in place
 * (texture staging: each mip level is made from the one before) prefer HOST_CACHED. BAR memory
 * is uncached: a CPU read of it crosses the bus at a few MB/s (an H200 in a VM: tessellating and
 * hashing a mesh in place took ~400 ms a render), so vertex and index buffers there get a heap
 * mirror for the CPU (`cpu`), published in one sequential write.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "internal.h"

static int find_memory_type(const struct rnd_context *ctx, uint32_t bits, VkMemoryPropertyFlags want)
{
	for (uint32_t i = 0; i < ctx->mem_props.memoryTypeCount; i++)
		if ((bits & (1u << i)) && (ctx->mem_props.memoryTypes[i].propertyFlags & want) == want) return (int)i;
	return -1;
}

enum rnd_result rnd_buffer_create(struct rnd_context *ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                                  const char *name, struct rnd_buffer *out, struct rnd_error *err)
{
	VkResult vr;
	memset(out, 0, sizeof *out);
	VkBufferCreateInfo bci = {
		.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, .size = size, .usage = usage,
		.sharingMode = VK_SHARING_MODE_EXCLUSIVE,
	};
	if ((vr = vkCreateBuffer(ctx->device, &bci, NULL, &out->buf)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreateBuffer");
	VkMemoryRequirements req;
	vkGetBufferMemoryRequirements(ctx->device, out->buf, &req);
	VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
	int type = -1;
	/* Copy sources and targets only (staging, readback): the CPU reads them. */
	const VkBufferUsageFlags drawn = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT |
	                                 VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
	bool cpu_reads = !(usage & drawn);
	if (cpu_reads) type = find_memory_type(ctx, req.memoryTypeBits, host | VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
	else type = find_memory_type(ctx, req.memoryTypeBits, host | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
	if (type < 0) type = find_memory_type(ctx, req.memoryTypeBits, host);
	if (type < 0) {
		vkDestroyBuffer(ctx->device, out->buf, NULL);
		out->buf = VK_NULL_HANDLE;
		return rnd_fail(err, RND_ERR_VULKAN, "no host-visible memory type for buffer '%s'", name);
	}
	VkMemoryAllocateInfo mai = {
		.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, .allocationSize = req.size, .memoryTypeIndex = (uint32_t)type,
	};
	if ((vr = vkAllocateMemory(ctx->device, &mai, NULL, &out->mem)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkAllocateMemory (buffer)");
		goto fail_buffer;
	}
	if ((vr = vkBindBufferMemory(ctx->device, out->buf, out->mem, 0)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkBindBufferMemory");
		goto fail_memory;
	}
	if ((vr = vkMapMemory(ctx->device, out->mem, 0, VK_WHOLE_SIZE, 0, &out->map)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkMapMemory");
		goto fail_memory;
	}
	out->cpu = out->map;
	bool cached = ctx->mem_props.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
	if ((!cached || ctx->desc.mirror_buffers) && (usage & (VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT)) &&
	    !(out->cpu = malloc(size))) {
		rnd_fail(err, RND_ERR_OOM, "out of memory for the CPU copy of buffer '%s' (%llu bytes)", name,
		         (unsigned long long)size);
		goto fail_memory;
	}
	out->size = size;
	RND_NAME(ctx, VK_OBJECT_TYPE_BUFFER, out->buf, "%s", name);
	RND_NAME(ctx, VK_OBJECT_TYPE_DEVICE_MEMORY, out->mem, "%s memory", name);
	return RND_OK;

fail_memory:
	vkFreeMemory(ctx->device, out->mem, NULL);
fail_buffer:
	vkDestroyBuffer(ctx->device, out->buf, NULL);
	memset(out, 0, sizeof *out);
	return err ? err->code : RND_ERR_VULKAN;
}

void rnd_buffer_destroy(struct rnd_context *ctx, struct rnd_buffer *b)
{
	if (!b) return;
	if (b->cpu != b->map) free(b->cpu);
	if (b->buf) vkDestroyBuffer(ctx->device, b->buf, NULL);
	if (b->mem) vkFreeMemory(ctx->device, b->mem, NULL); /* unmaps implicitly */
	memset(b, 0, sizeof *b);
}

void rnd_buffer_publish(struct rnd_buffer *b, VkDeviceSize off, VkDeviceSize n)
{
	if (b->cpu != b->map && n) memcpy((uint8_t *)b->map + off, (const uint8_t *)b->cpu + off, n);
}

enum rnd_result rnd_buffer_reserve(struct rnd_context *ctx, struct rnd_buffer *b, VkDeviceSize size,
                                   VkBufferUsageFlags usage, const char *name, struct rnd_error *err)
{
	if (b->buf && b->size >= size) return RND_OK;
	VkDeviceSize n = 64 * 1024;
	while (n < size) n *= 2;
	/* The slot's previous render has completed (its fence was waited), so the old buffer is
	 * no longer in use by the GPU and can go now. */
	rnd_buffer_destroy(ctx, b);
	return rnd_buffer_create(ctx, n, usage, name, b, err);
}

enum rnd_result rnd_image_create(struct rnd_context *ctx, VkFormat format, uint32_t w, uint32_t h, uint32_t layers,
                                 uint32_t samples, VkImageUsageFlags usage, VkImageAspectFlags aspect,
                                 const char *name, struct rnd_image_res *out, struct rnd_error *err)
{
	return rnd_image_create_levels(ctx, format, w, h, layers, samples, 1, usage, aspect, name, out, err);
}

/* An image with `levels` mip levels and a view of all of it: a cube (6 layers, cube-compatible)
 * when cube is set, else 2D or a 2D array by its layers. */
static enum rnd_result image_create(struct rnd_context *ctx, VkFormat format, uint32_t w, uint32_t h, uint32_t layers,
                                    uint32_t samples, uint32_t levels, VkImageUsageFlags usage, VkImageAspectFlags aspect,
                                    bool cube, const char *name, struct rnd_image_res *out, struct rnd_error *err)
{
	VkResult vr;
	memset(out, 0, sizeof *out);
	VkImageCreateInfo ici = {
		.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, .flags = cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0,
		.imageType = VK_IMAGE_TYPE_2D, .format = format,
		.extent = {w, h, 1}, .mipLevels = levels, .arrayLayers = layers, .samples = (VkSampleCountFlagBits)samples,
		.tiling = VK_IMAGE_TILING_OPTIMAL, .usage = usage, .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
		.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
	};
	if ((vr = vkCreateImage(ctx->device, &ici, NULL, &out->img)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkCreateImage");
		snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg), " (%s %ux%ux%u)", name, w, h, layers);
		return err->code;
	}
	VkMemoryRequirements req;
	vkGetImageMemoryRequirements(ctx->device, out->img, &req);
	int type = find_memory_type(ctx, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
	if (type < 0) type = find_memory_type(ctx, req.memoryTypeBits, 0);
	VkMemoryAllocateInfo mai = {
		.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, .allocationSize = req.size, .memoryTypeIndex = (uint32_t)type,
	};
	if ((vr = vkAllocateMemory(ctx->device, &mai, NULL, &out->mem)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkAllocateMemory (image)");
		snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg), " (%s, %llu bytes)", name, (unsigned long long)req.size);
		goto fail_image;
	}
	if ((vr = vkBindImageMemory(ctx->device, out->img, out->mem, 0)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkBindImageMemory");
		goto fail_memory;
	}
	VkImageViewCreateInfo vci = {
		.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, .image = out->img,
		.viewType = cube ? VK_IMAGE_VIEW_TYPE_CUBE : layers > 1 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D,
		.format = format, .subresourceRange = {aspect, 0, levels, 0, layers},
	};
	if ((vr = vkCreateImageView(ctx->device, &vci, NULL, &out->view)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkCreateImageView");
		goto fail_memory;
	}
	out->format = format;
	out->width = w; out->height = h; out->layers = layers; out->samples = samples;
	RND_NAME(ctx, VK_OBJECT_TYPE_IMAGE, out->img, "%s", name);
	RND_NAME(ctx, VK_OBJECT_TYPE_IMAGE_VIEW, out->view, "%s view", name);
	RND_NAME(ctx, VK_OBJECT_TYPE_DEVICE_MEMORY, out->mem, "%s memory", name);
	return RND_OK;

fail_memory:
	vkFreeMemory(ctx->device, out->mem, NULL);
fail_image:
	vkDestroyImage(ctx->device, out->img, NULL);
	memset(out, 0, sizeof *out);
	return err->code;
}

enum rnd_result rnd_image_create_levels(struct rnd_context *ctx, VkFormat format, uint32_t w, uint32_t h,
                                        uint32_t layers, uint32_t samples, uint32_t levels, VkImageUsageFlags usage,
                                        VkImageAspectFlags aspect, const char *name, struct rnd_image_res *out,
                                        struct rnd_error *err)
{
	return image_create(ctx, format, w, h, layers, samples, levels, usage, aspect, false, name, out, err);
}

enum rnd_result rnd_image_create_cube(struct rnd_context *ctx, VkFormat format, uint32_t side, uint32_t levels,
                                      VkImageUsageFlags usage, const char *name, struct rnd_image_res *out,
                                      struct rnd_error *err)
{
	return image_create(ctx, format, side, side, 6, 1, levels, usage, VK_IMAGE_ASPECT_COLOR_BIT, true, name, out, err);
}

void rnd_image_destroy(struct rnd_context *ctx, struct rnd_image_res *im)
{
	if (!im) return;
	if (im->view) vkDestroyImageView(ctx->device, im->view, NULL);
	if (im->img) vkDestroyImage(ctx->device, im->img, NULL);
	if (im->mem) vkFreeMemory(ctx->device, im->mem, NULL);
	memset(im, 0, sizeof *im);
}
