/*
 * renderer/env_build.c — the environment's device objects (see env.h): the compute pipelines
 * and samplers (made on the first map a context sees), one map's images with the staged mip
 * chain, and the commands that upload and prefilter it and make the split-sum table.
 *
 * The map's mip chain is built on the CPU in float (box filter, an odd edge folded in) and
 * stored as RGBA16F (a value over 65504, a sun's core, is clamped there: the diffuse light and
 * the shadow directions come from the float map, only the sun's mirror image is capped).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "env.h"
#include "record.h"
#include "env_prefilter.comp.spv.h"
#include "env_brdf.comp.spv.h"

#define ENV_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT

struct prefilter_push {
	uint32_t info[4];     /* x face side, y samples (0: the mirror lookup), z map width, w map height */
	float params[4];      /* x roughness, y the mirror lookup's map level, z the map's last level */
};

static enum rnd_result compute_pipeline(struct rnd_context *ctx, const uint32_t *code, size_t size, const char *name,
                                        VkPipelineLayout layout, VkPipeline *out, struct rnd_error *err)
{
	VkShaderModule mod;
	enum rnd_result r = rnd_shader_module(ctx, code, size, name, &mod, err);
	if (r != RND_OK) return r;
	VkComputePipelineCreateInfo cci = {
		.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
		.stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_COMPUTE_BIT,
		          .module = mod, .pName = "main"},
		.layout = layout,
	};
	VkResult vr = vkCreateComputePipelines(ctx->device, ctx->pipeline_cache, 1, &cci, NULL, out);
	vkDestroyShaderModule(ctx->device, mod, NULL);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkCreateComputePipelines (environment)");
	RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE, *out, "%s", name);
	return RND_OK;
}

static enum rnd_result make_sampler(struct rnd_context *ctx, VkSamplerAddressMode u, bool mips, const char *name,
                                    VkSampler *out, struct rnd_error *err)
{
	VkSamplerCreateInfo sci = {
		.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO, .magFilter = VK_FILTER_LINEAR, .minFilter = VK_FILTER_LINEAR,
		.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR, .addressModeU = u,
		.addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
		.maxLod = mips ? VK_LOD_CLAMP_NONE : 0.0f,
	};
	VkResult vr = vkCreateSampler(ctx->device, &sci, NULL, out);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkCreateSampler (environment)");
	RND_NAME(ctx, VK_OBJECT_TYPE_SAMPLER, *out, "%s", name);
	return RND_OK;
}

/* A pool for n sets of the compute layout and the sets. */
static enum rnd_result make_sets(struct rnd_context *ctx, const struct rnd_env_gpu *g, uint32_t n, const char *name,
                                 VkDescriptorPool *pool, VkDescriptorSet *sets, struct rnd_error *err)
{
	VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, n}, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, n}};
	VkDescriptorPoolCreateInfo pci = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, .maxSets = n,
	                                  .poolSizeCount = 2, .pPoolSizes = sizes};
	VkResult vr = vkCreateDescriptorPool(ctx->device, &pci, NULL, pool);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkCreateDescriptorPool (environment)");
	RND_NAME(ctx, VK_OBJECT_TYPE_DESCRIPTOR_POOL, *pool, "%s sets", name);
	VkDescriptorSetLayout layouts[RND_ENV_MAX_LEVELS];
	for (uint32_t i = 0; i < n; i++) layouts[i] = g->set_layout;
	VkDescriptorSetAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, .descriptorPool = *pool,
	                                  .descriptorSetCount = n, .pSetLayouts = layouts};
	if ((vr = vkAllocateDescriptorSets(ctx->device, &ai, sets)) != VK_SUCCESS) {
		vkDestroyDescriptorPool(ctx->device, *pool, NULL);
		*pool = VK_NULL_HANDLE;
		return rnd_fail_vk(err, vr, "vkAllocateDescriptorSets (environment)");
	}
	return RND_OK;
}

static enum rnd_result make_layouts(struct rnd_context *ctx, struct rnd_env_gpu *g, struct rnd_error *err)
{
	VkDescriptorSetLayoutBinding b[2] = {
		{UMBRA_ENVC_BINDING_SOURCE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
		{UMBRA_ENVC_BINDING_OUT, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
	};
	VkDescriptorSetLayoutCreateInfo dci = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
	                                       .bindingCount = 2, .pBindings = b};
	VkResult vr = vkCreateDescriptorSetLayout(ctx->device, &dci, NULL, &g->set_layout);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkCreateDescriptorSetLayout (environment)");
	RND_NAME(ctx, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, g->set_layout, "environment prefilter set layout");
	VkPushConstantRange pcr = {VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(struct prefilter_push)};
	VkPipelineLayoutCreateInfo lci = {.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, .setLayoutCount = 1,
	                                  .pSetLayouts = &g->set_layout, .pushConstantRangeCount = 1,
	                                  .pPushConstantRanges = &pcr};
	if ((vr = vkCreatePipelineLayout(ctx->device, &lci, NULL, &g->layout)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreatePipelineLayout (environment)");
	RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE_LAYOUT, g->layout, "environment prefilter layout");
	return RND_OK;
}

/* The split-sum table's image and set (its contents: rnd_env_record_brdf). */
static enum rnd_result make_brdf(struct rnd_context *ctx, struct rnd_env_gpu *g, struct rnd_error *err)
{
	enum rnd_result r = rnd_image_create(ctx, ENV_FORMAT, UMBRA_ENV_BRDF_SIZE, UMBRA_ENV_BRDF_SIZE, 1, 1,
	                                     VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
	                                     "environment split-sum table", &g->brdf, err);
	if (r != RND_OK || (r = make_sets(ctx, g, 1, "split-sum table", &g->brdf_pool, &g->brdf_set, err)) != RND_OK)
		return r;
	/* The table's pass reads no source, but lavapipe reads every descriptor of a bound set: the
	 * table itself (GENERAL while it is written) stands in. */
	VkDescriptorImageInfo ii = {VK_NULL_HANDLE, g->brdf.view, VK_IMAGE_LAYOUT_GENERAL};
	VkDescriptorImageInfo si = {g->lut_sampler, g->brdf.view, VK_IMAGE_LAYOUT_GENERAL};
	VkWriteDescriptorSet w[2] = {
		{.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = g->brdf_set, .dstBinding = UMBRA_ENVC_BINDING_OUT,
		 .descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, .pImageInfo = &ii},
		{.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = g->brdf_set, .dstBinding = UMBRA_ENVC_BINDING_SOURCE,
		 .descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &si},
	};
	vkUpdateDescriptorSets(ctx->device, 2, w, 0, NULL);
	return RND_OK;
}

enum rnd_result rnd_env_gpu_init(struct rnd_context *ctx, struct rnd_env_gpu *g, struct rnd_error *err)
{
	enum rnd_result r;
	if (g->ready) return RND_OK;
	if ((r = make_layouts(ctx, g, err)) != RND_OK ||
	    (r = compute_pipeline(ctx, spv_env_prefilter_comp, sizeof spv_env_prefilter_comp, "env_prefilter.comp", g->layout,
	                          &g->prefilter, err)) != RND_OK ||
	    (r = compute_pipeline(ctx, spv_env_brdf_comp, sizeof spv_env_brdf_comp, "env_brdf.comp", g->layout,
	                          &g->brdf_pipe, err)) != RND_OK ||
	    (r = make_sampler(ctx, VK_SAMPLER_ADDRESS_MODE_REPEAT, true, "environment map sampler", &g->map_sampler, err)) != RND_OK ||
	    (r = make_sampler(ctx, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, true, "environment cube sampler", &g->cube_sampler,
	                      err)) != RND_OK ||
	    (r = make_sampler(ctx, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, false, "environment table sampler", &g->lut_sampler,
	                      err)) != RND_OK ||
	    (r = make_brdf(ctx, g, err)) != RND_OK) {
		rnd_env_gpu_release(ctx, g);
		return r;
	}
	g->ready = true;
	return RND_OK;
}

void rnd_env_gpu_release(struct rnd_context *ctx, struct rnd_env_gpu *g)
{
	if (g->brdf_pool) vkDestroyDescriptorPool(ctx->device, g->brdf_pool, NULL);
	rnd_image_destroy(ctx, &g->brdf);
	if (g->lut_sampler) vkDestroySampler(ctx->device, g->lut_sampler, NULL);
	if (g->cube_sampler) vkDestroySampler(ctx->device, g->cube_sampler, NULL);
	if (g->map_sampler) vkDestroySampler(ctx->device, g->map_sampler, NULL);
	if (g->brdf_pipe) vkDestroyPipeline(ctx->device, g->brdf_pipe, NULL);
	if (g->prefilter) vkDestroyPipeline(ctx->device, g->prefilter, NULL);
	if (g->layout) vkDestroyPipelineLayout(ctx->device, g->layout, NULL);
	if (g->set_layout) vkDestroyDescriptorSetLayout(ctx->device, g->set_layout, NULL);
	memset(g, 0, sizeof *g);
}

/* ---- one map ---- */

static uint16_t to_half(float f)
{
	uint32_t x;
	if (!(f > 0.0f)) return 0;            /* negatives and NaN: no light */
	if (f >= 65504.0f) return 0x7bff;     /* the largest half */
	memcpy(&x, &f, 4);
	int32_t e = (int32_t)((x >> 23) & 0xff) - 127 + 15;
	uint32_t m = x & 0x7fffff;
	if (e <= 0) {                          /* subnormal half (or zero) */
		if (e < -10) return 0;
		m |= 0x800000;
		uint32_t shift = (uint32_t)(14 - e);
		uint32_t h = m >> shift;
		if ((m >> (shift - 1)) & 1) h++;   /* round half up */
		return (uint16_t)h;
	}
	uint32_t h = ((uint32_t)e << 10) | (m >> 13);
	if (m & 0x1000) h++;                   /* round half up (a carry into the exponent is right) */
	return (uint16_t)(h > 0x7bff ? 0x7bff : h);
}

/* Levels of a w x h chain down to 1 x 1 (both sides halved, rounded down, at least 1). */
static uint32_t chain_levels(uint32_t w, uint32_t h)
{
	uint32_t n = 1;
	while (w > 1 || h > 1) { w = w > 1 ? w / 2 : 1; h = h > 1 ? h / 2 : 1; n++; }
	return n;
}

/* The next level of a chain (sw x sh floats, rgb) into dst: 2 x 2 boxes, an odd last row or
 * column folded into its neighbour's box. */
static void halve(const float *src, uint32_t sw, uint32_t sh, float *dst, uint32_t dw, uint32_t dh)
{
	for (uint32_t y = 0; y < dh; y++)
		for (uint32_t x = 0; x < dw; x++) {
			uint32_t x0 = sw > 1 ? 2 * x : 0, y0 = sh > 1 ? 2 * y : 0;
			uint32_t x1 = sw > 1 ? (x + 1 == dw ? sw : 2 * x + 2) : 1, y1 = sh > 1 ? (y + 1 == dh ? sh : 2 * y + 2) : 1;
			float s[3] = {0, 0, 0};
			for (uint32_t yy = y0; yy < y1; yy++)
				for (uint32_t xx = x0; xx < x1; xx++)
					for (int k = 0; k < 3; k++) s[k] += src[((size_t)yy * sw + xx) * 3 + k];
			float n = (float)((x1 - x0) * (y1 - y0));
			for (int k = 0; k < 3; k++) dst[((size_t)y * dw + x) * 3 + k] = s[k] / n;
		}
}

/* The chain of rgb (w x h) as RGBA16F, level after level, into half (sized by the caller). */
static bool stage_chain(const float *rgb, uint32_t w, uint32_t h, uint32_t levels, uint16_t *half)
{
	float *a = malloc((size_t)w * h * 3 * sizeof(float)), *b = malloc((size_t)w * h * 3 * sizeof(float));
	if (!a || !b) {
		free(a);
		free(b);
		return false;
	}
	memcpy(a, rgb, (size_t)w * h * 3 * sizeof(float));
	for (uint32_t l = 0; l < levels; l++) {
		for (size_t i = 0; i < (size_t)w * h; i++) {
			for (int k = 0; k < 3; k++) half[4 * i + k] = to_half(a[3 * i + k]);
			half[4 * i + 3] = 0x3c00;   /* 1.0 */
		}
		half += (size_t)w * h * 4;
		uint32_t nw = w > 1 ? w / 2 : 1, nh = h > 1 ? h / 2 : 1;
		if (l + 1 < levels) {
			halve(a, w, h, b, nw, nh);
			float *t = a; a = b; b = t;
		}
		w = nw; h = nh;
	}
	free(a);
	free(b);
	return true;
}

/* The prefilter's sets: the map, and level i of the cube as a 2D array. */
static void write_sets(struct rnd_context *ctx, const struct rnd_env_gpu *g, struct rnd_env_maps *m)
{
	VkDescriptorImageInfo src = {g->map_sampler, m->map.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
	VkDescriptorImageInfo out[RND_ENV_MAX_LEVELS];
	VkWriteDescriptorSet w[2 * RND_ENV_MAX_LEVELS];
	for (uint32_t i = 0; i < m->spec_levels; i++) {
		out[i] = (VkDescriptorImageInfo){VK_NULL_HANDLE, m->level_views[i], VK_IMAGE_LAYOUT_GENERAL};
		w[2 * i] = (VkWriteDescriptorSet){.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = m->sets[i],
		                                  .dstBinding = UMBRA_ENVC_BINDING_SOURCE, .descriptorCount = 1,
		                                  .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &src};
		w[2 * i + 1] = (VkWriteDescriptorSet){.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = m->sets[i],
		                                      .dstBinding = UMBRA_ENVC_BINDING_OUT, .descriptorCount = 1,
		                                      .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, .pImageInfo = &out[i]};
	}
	vkUpdateDescriptorSets(ctx->device, 2 * m->spec_levels, w, 0, NULL);
}

static enum rnd_result level_views(struct rnd_context *ctx, struct rnd_env_maps *m, const char *name, struct rnd_error *err)
{
	for (uint32_t i = 0; i < m->spec_levels; i++) {
		VkImageViewCreateInfo vci = {
			.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, .image = m->spec.img, .viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY,
			.format = ENV_FORMAT, .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, i, 1, 0, 6},
		};
		VkResult vr = vkCreateImageView(ctx->device, &vci, NULL, &m->level_views[i]);
		if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkCreateImageView (environment level)");
		RND_NAME(ctx, VK_OBJECT_TYPE_IMAGE_VIEW, m->level_views[i], "%s specular level %u", name, i);
	}
	return RND_OK;
}

enum rnd_result rnd_env_maps_create(struct rnd_context *ctx, const struct rnd_env_gpu *g, const float *rgb, uint32_t w,
                                    uint32_t h, const char *name, struct rnd_env_maps *m, struct rnd_error *err)
{
	enum rnd_result r;
	char label[96];
	memset(m, 0, sizeof *m);
	m->map_w = w; m->map_h = h;
	m->map_levels = chain_levels(w, h);
	/* Faces of about a quarter of the map's width (its texels at the equator), 16..256. */
	m->spec_side = 16;
	while (m->spec_side < 256 && m->spec_side * 2 <= w / 4) m->spec_side *= 2;
	m->spec_levels = 1;
	while (m->spec_levels < RND_ENV_MAX_LEVELS && (m->spec_side >> m->spec_levels) >= 4) m->spec_levels++;
	snprintf(label, sizeof label, "%s map", name);
	if ((r = rnd_image_create_levels(ctx, ENV_FORMAT, w, h, 1, 1, m->map_levels,
	                                 VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
	                                 label, &m->map, err)) != RND_OK)
		goto fail;
	snprintf(label, sizeof label, "%s specular", name);
	if ((r = rnd_image_create_cube(ctx, ENV_FORMAT, m->spec_side, m->spec_levels,
	                               VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT, label, &m->spec, err)) != RND_OK ||
	    (r = level_views(ctx, m, name, err)) != RND_OK)
		goto fail;
	uint64_t texels = 0;
	for (uint32_t l = 0, lw = w, lh = h; l < m->map_levels; l++, lw = lw > 1 ? lw / 2 : 1, lh = lh > 1 ? lh / 2 : 1)
		texels += (uint64_t)lw * lh;
	snprintf(label, sizeof label, "%s staging", name);
	if ((r = rnd_buffer_create(ctx, texels * 8, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, label, &m->staging, err)) != RND_OK)
		goto fail;
	if (!stage_chain(rgb, w, h, m->map_levels, m->staging.map)) {
		r = rnd_fail(err, RND_ERR_OOM, "out of memory for the environment map's mip chain (%ux%u)", w, h);
		goto fail;
	}
	if ((r = make_sets(ctx, g, m->spec_levels, name, &m->pool, m->sets, err)) != RND_OK) goto fail;
	write_sets(ctx, g, m);
	return RND_OK;
fail:
	rnd_env_maps_destroy(ctx, m);
	return r;
}

void rnd_env_maps_built(struct rnd_context *ctx, struct rnd_env_maps *m)
{
	rnd_buffer_destroy(ctx, &m->staging);
	if (m->pool) vkDestroyDescriptorPool(ctx->device, m->pool, NULL);
	m->pool = VK_NULL_HANDLE;
	for (uint32_t i = 0; i < RND_ENV_MAX_LEVELS; i++) {
		if (m->level_views[i]) vkDestroyImageView(ctx->device, m->level_views[i], NULL);
		m->level_views[i] = VK_NULL_HANDLE;
	}
}

void rnd_env_maps_destroy(struct rnd_context *ctx, struct rnd_env_maps *m)
{
	rnd_env_maps_built(ctx, m);
	rnd_image_destroy(ctx, &m->spec);
	rnd_image_destroy(ctx, &m->map);
	memset(m, 0, sizeof *m);
}

uint64_t rnd_env_maps_bytes(const struct rnd_env_maps *m)
{
	uint64_t b = 0;
	for (uint32_t l = 0, w = m->map_w, h = m->map_h; l < m->map_levels; l++, w = w > 1 ? w / 2 : 1, h = h > 1 ? h / 2 : 1)
		b += (uint64_t)w * h * 8;
	for (uint32_t l = 0; l < m->spec_levels; l++) b += 6ull * (m->spec_side >> l) * (m->spec_side >> l) * 8;
	return b;
}

/* ---- commands ---- */

static void barrier(VkCommandBuffer cmd, VkImage img, uint32_t levels, uint32_t layers, VkImageLayout from, VkImageLayout to,
                    VkPipelineStageFlags2 src, VkAccessFlags2 src_access, VkPipelineStageFlags2 dst, VkAccessFlags2 dst_access)
{
	VkImageMemoryBarrier2 b = {
		.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = src, .srcAccessMask = src_access,
		.dstStageMask = dst, .dstAccessMask = dst_access, .oldLayout = from, .newLayout = to,
		.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = img,
		.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, levels, 0, layers},
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1, .pImageMemoryBarriers = &b};
	vkCmdPipelineBarrier2(cmd, &di);
}

static void upload_map(VkCommandBuffer cmd, const struct rnd_env_maps *m)
{
	barrier(cmd, m->map.img, m->map_levels, 1, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
	        VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
	VkBufferImageCopy regions[16];
	VkDeviceSize off = 0;
	uint32_t w = m->map_w, h = m->map_h;
	for (uint32_t l = 0; l < m->map_levels && l < 16; l++) {
		regions[l] = (VkBufferImageCopy){.bufferOffset = off, .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1},
		                                 .imageExtent = {w, h, 1}};
		off += (VkDeviceSize)w * h * 8;
		w = w > 1 ? w / 2 : 1;
		h = h > 1 ? h / 2 : 1;
	}
	vkCmdCopyBufferToImage(cmd, m->staging.buf, m->map.img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, m->map_levels, regions);
	barrier(cmd, m->map.img, m->map_levels, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
	        VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
	        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

void rnd_env_record_maps(VkCommandBuffer cmd, const struct rnd_env_gpu *g, const struct rnd_env_maps *m)
{
	upload_map(cmd, m);
	barrier(cmd, m->spec.img, m->spec_levels, 6, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
	        VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, g->prefilter);
	/* the map texel's size against a mirror face texel's: the level the mirror lookup reads */
	float mirror_lod = log2f(fmaxf((float)m->map_w / (4.0f * (float)m->spec_side), 1.0f));
	for (uint32_t l = 0; l < m->spec_levels; l++) {
		uint32_t side = m->spec_side >> l;
		struct prefilter_push push = {
			.info = {side, l == 0 ? 0u : 64u, m->map_w, m->map_h},
			.params = {(float)l / (float)(m->spec_levels - 1), mirror_lod, (float)(m->map_levels - 1), 0},
		};
		vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, g->layout, 0, 1, &m->sets[l], 0, NULL);
		vkCmdPushConstants(cmd, g->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
		vkCmdDispatch(cmd, (side + 7) / 8, (side + 7) / 8, 6);
	}
	barrier(cmd, m->spec.img, m->spec_levels, 6, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
	        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
	        VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

void rnd_env_record_brdf(VkCommandBuffer cmd, const struct rnd_env_gpu *g)
{
	barrier(cmd, g->brdf.img, 1, 1, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, 0,
	        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, g->brdf_pipe);
	vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, g->layout, 0, 1, &g->brdf_set, 0, NULL);
	struct prefilter_push push = {.info = {UMBRA_ENV_BRDF_SIZE, 256, 0, 0}};
	vkCmdPushConstants(cmd, g->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
	vkCmdDispatch(cmd, UMBRA_ENV_BRDF_SIZE / 8, UMBRA_ENV_BRDF_SIZE / 8, 1);
	barrier(cmd, g->brdf.img, 1, 1, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
	        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
	        VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}
