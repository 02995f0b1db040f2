/*
 * renderer/moments.c — moment shadow maps (VSM and EVSM2) for every light type: two fullscreen
 * passes (shaders/moments.frag) that turn a map just copied into the depth atlas into blurred
 * moments in its tile of the moment atlas, through the slot's blur temporary. Created once per
 * context; the temporary and the descriptor sets belong to the render slots (slot.c, frame.c).
 * Also PCSS's depth bounds (shaders/minmax.comp): a compute pass over the slot's scratch copy
 * of a map just drawn.
 *
 * Format: R32G32_SFLOAT where the device can filter it linearly and render to it, else
 * R16G16_SFLOAT (the EVSM exponent is then clamped so exp(2cd) fits in a half).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "moments.h"
#include "record.h"
#include "moments.frag.spv.h"
#include "minmax.comp.spv.h"

/* The moment atlas is sampled linearly by the main pass and drawn by moments.frag's pass 1. */
static bool format_ok(const struct rnd_context *ctx, VkFormat f)
{
	VkFormatProperties fp;
	vkGetPhysicalDeviceFormatProperties(ctx->phys, f, &fp);
	VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
	                            VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
	return (fp.optimalTilingFeatures & need) == need;
}

/* A set layout of the two bindings b and a pipeline layout with it and the push constants
 * (struct rnd_moments_push) for `stage`; `what` names them. */
static enum rnd_result make_layouts(struct rnd_context *ctx, const VkDescriptorSetLayoutBinding b[2], VkShaderStageFlags stage,
                                    const char *what, VkDescriptorSetLayout *set, VkPipelineLayout *layout,
                                    struct rnd_error *err)
{
	VkResult vr;
	char call[80];
	VkDescriptorSetLayoutCreateInfo dci = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, .bindingCount = 2, .pBindings = b};
	if ((vr = vkCreateDescriptorSetLayout(ctx->device, &dci, NULL, set)) != VK_SUCCESS) {
		snprintf(call, sizeof call, "vkCreateDescriptorSetLayout (%s)", what);
		return rnd_fail_vk(err, vr, call);
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, *set, "%s set layout", what);
	VkPushConstantRange pcr = {stage, 0, sizeof(struct rnd_moments_push)};
	VkPipelineLayoutCreateInfo lci = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, .setLayoutCount = 1, .pSetLayouts = set,
		.pushConstantRangeCount = 1, .pPushConstantRanges = &pcr,
	};
	if ((vr = vkCreatePipelineLayout(ctx->device, &lci, NULL, layout)) != VK_SUCCESS) {
		snprintf(call, sizeof call, "vkCreatePipelineLayout (%s)", what);
		return rnd_fail_vk(err, vr, call);
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE_LAYOUT, *layout, "%s pipeline layout", what);
	return RND_OK;
}

/* minmax.comp: its set (the scratch map, the depth bounds), layout and pipeline. */
static enum rnd_result init_bounds(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_moments *m = &ctx->moments;
	const VkDescriptorSetLayoutBinding b[2] = {
		{UMBRA_MINMAX_BINDING_DEPTH, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
		{UMBRA_MINMAX_BINDING_BOUNDS, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
	};
	VkShaderModule mod;
	enum rnd_result r;
	if ((r = make_layouts(ctx, b, VK_SHADER_STAGE_COMPUTE_BIT, "depth bounds", &m->set_layout, &m->layout, err)) != RND_OK ||
	    (r = rnd_shader_module(ctx, spv_minmax_comp, sizeof spv_minmax_comp, "minmax.comp", &mod, err)) != RND_OK)
		return r;
	VkComputePipelineCreateInfo cci = {
		.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
		.stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_COMPUTE_BIT, .module = mod, .pName = "main"},
		.layout = m->layout,
	};
	VkResult vr = vkCreateComputePipelines(ctx->device, ctx->pipeline_cache, 1, &cci, NULL, &m->bounds);
	vkDestroyShaderModule(ctx->device, mod, NULL);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkCreateComputePipelines (minmax.comp)");
	RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE, m->bounds, "pcss depth bounds");
	return RND_OK;
}

/* moments.frag: its set (the depth atlas, the blur temporary), layout and the pipelines of its
 * two passes (into the temporary, RG32F; into the moment atlas, its format). */
static enum rnd_result init_blur(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_moments *m = &ctx->moments;
	const VkDescriptorSetLayoutBinding b[2] = {
		{UMBRA_MOMENTS_BINDING_DEPTH, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, NULL},
		{UMBRA_MOMENTS_BINDING_BLUR, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, NULL},
	};
	VkShaderModule fs;
	enum rnd_result r;
	if ((r = make_layouts(ctx, b, VK_SHADER_STAGE_FRAGMENT_BIT, "moments", &m->blur_set_layout, &m->blur_layout, err)) !=
	        RND_OK ||
	    (r = rnd_shader_module(ctx, spv_moments_frag, sizeof spv_moments_frag, "moments.frag", &fs, err)) != RND_OK)
		return r;
	VkSpecializationMapEntry e[3] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}};
	for (uint32_t v = 0; v < 5 && r == RND_OK; v++) {
		uint32_t pass = v == 4, warp = v & 1, persp = v >> 1 & 1, data[3] = {pass, pass ? 0 : warp, pass ? 0 : persp};
		VkSpecializationInfo si = {3, e, sizeof data, data};
		char name[64];
		snprintf(name, sizeof name, pass ? "moments blur (y, into the atlas)" : "moments blur (x, %s, %s)",
		         warp ? "evsm" : "vsm", persp ? "perspective" : "orthographic");
		r = rnd_pipeline_fullscreen(ctx, fs, pass ? rnd_moments_format(ctx, false) : VK_FORMAT_R32G32_SFLOAT,
		                            m->blur_layout, &si, name, pass ? &m->blur_y : &m->blur_x[warp][persp], err);
	}
	vkDestroyShaderModule(ctx->device, fs, NULL);
	return r;
}

enum rnd_result rnd_moments_init(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_moments *m = &ctx->moments;
	VkResult vr;
	enum rnd_result r;
	m->fp32 = format_ok(ctx, VK_FORMAT_R32G32_SFLOAT);
	VkFormatProperties tmp;
	vkGetPhysicalDeviceFormatProperties(ctx->phys, VK_FORMAT_R32G32_SFLOAT, &tmp);
	VkFormatFeatureFlags tmp_need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
	m->available = (tmp.optimalTilingFeatures & tmp_need) == tmp_need &&
	               (m->fp32 || format_ok(ctx, VK_FORMAT_R16G16_SFLOAT));
	if ((r = init_bounds(ctx, err)) != RND_OK) goto fail;
	if (m->available && (r = init_blur(ctx, err)) != RND_OK) goto fail;
	VkSamplerCreateInfo sci = {
		.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO, .magFilter = VK_FILTER_LINEAR, .minFilter = VK_FILTER_LINEAR,
		.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST, .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
		.addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
	};
	if ((vr = vkCreateSampler(ctx->device, &sci, NULL, &m->sampler)) != VK_SUCCESS) {
		r = rnd_fail_vk(err, vr, "vkCreateSampler (moments)");
		goto fail;
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_SAMPLER, m->sampler, "moments sampler");
	/* moments.frag only fetches texels; a depth format takes no linear filter on lavapipe */
	sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
	if ((vr = vkCreateSampler(ctx->device, &sci, NULL, &m->nearest)) != VK_SUCCESS) {
		r = rnd_fail_vk(err, vr, "vkCreateSampler (moments, nearest)");
		goto fail;
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_SAMPLER, m->nearest, "moments blur sampler");
	return RND_OK;
fail:
	rnd_moments_release(ctx);
	return r;
}

void rnd_moments_release(struct rnd_context *ctx)
{
	struct rnd_moments *m = &ctx->moments;
	if (!ctx->device) return;
	if (m->nearest) vkDestroySampler(ctx->device, m->nearest, NULL);
	if (m->sampler) vkDestroySampler(ctx->device, m->sampler, NULL);
	for (int i = 0; i < 4; i++)
		if (m->blur_x[i / 2][i % 2]) vkDestroyPipeline(ctx->device, m->blur_x[i / 2][i % 2], NULL);
	if (m->blur_y) vkDestroyPipeline(ctx->device, m->blur_y, NULL);
	if (m->blur_layout) vkDestroyPipelineLayout(ctx->device, m->blur_layout, NULL);
	if (m->blur_set_layout) vkDestroyDescriptorSetLayout(ctx->device, m->blur_set_layout, NULL);
	if (m->bounds) vkDestroyPipeline(ctx->device, m->bounds, NULL);
	if (m->layout) vkDestroyPipelineLayout(ctx->device, m->layout, NULL);
	if (m->set_layout) vkDestroyDescriptorSetLayout(ctx->device, m->set_layout, NULL);
	memset(m, 0, sizeof *m);
}

VkFormat rnd_moments_format(const struct rnd_context *ctx, bool want_fp16)
{
	return ctx->moments.fp32 && !want_fp16 ? VK_FORMAT_R32G32_SFLOAT : VK_FORMAT_R16G16_SFLOAT;
}

float rnd_moments_max_exponent(VkFormat f)
{
	/* exp(2 c) must stay finite: half max 65504 -> c <= 5.54; float -> c <= 44. */
	return f == VK_FORMAT_R32G32_SFLOAT ? 42.0f : 5.54f;
}

/* One blur pass over a res x res area at (x, y) of `target` (GENERAL layout). */
static void blur_pass(struct rnd_context *ctx, struct rnd_slot *s, VkPipeline pipe, const struct rnd_image_res *target,
                      int32_t x, int32_t y, uint32_t res, const struct rnd_moments_push *push)
{
	struct rnd_moments *m = &ctx->moments;
	VkCommandBuffer cmd = s->cmd;
	VkRect2D area = {{x, y}, {res, res}};
	VkRenderingAttachmentInfo ca = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = target->view,
		.imageLayout = VK_IMAGE_LAYOUT_GENERAL, .loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
		.storeOp = VK_ATTACHMENT_STORE_OP_STORE,
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1,
		.colorAttachmentCount = 1, .pColorAttachments = &ca,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {(float)x, (float)y, (float)res, (float)res, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
	vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m->blur_layout, 0, 1, &s->blur_set, 0, NULL);
	vkCmdPushConstants(cmd, m->blur_layout, VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof *push, push);
	vkCmdDraw(cmd, 3, 1, 0, 0);
	vkCmdEndRendering(cmd);
}

void rnd_moments_record_view(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_shadow_plan *sp,
                             uint32_t v, const struct rnd_scene *sc)
{
	VkCommandBuffer cmd = s->cmd;
	const struct rnd_light_plan *lp = &sp->lights[sp->view_light[v]];
	if (!lp->moments) return;
	const float *rect = sp->views[v].rect;
	uint32_t res = (uint32_t)rect[2];
	float blur = sc->lights[sp->view_light[v]].shadow.vsm_blur;
	struct rnd_moments_push push = {
		.info = {(uint32_t)rect[0], (uint32_t)rect[1], 0, (uint32_t)ceilf(fmaxf(blur, 0.0f))},
		.params = {lp->evsm ? lp->evsm_exponent : 0.0f, fmaxf(blur * 0.5f, 0.5f), (float)res, 0},
		.proj = {sp->views[v].params[2], sp->views[v].params[3], sp->views[v].params[1], 0},
	};
	/* Pass 0 reads the tile just copied into the depth atlas and overwrites the temporary that
	 * the last view's pass 1 read; pass 1 reads the temporary and draws this view's tile of the
	 * moment atlas (no other pass of this render touches that tile). */
	VkMemoryBarrier2 mb = {
		.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
		.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
		.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
		.dstStageMask = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
		.dstAccessMask = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1, .pMemoryBarriers = &mb};
	vkCmdPipelineBarrier2(cmd, &di);
	bool persp = sp->views[v].params[1] > 0.5f;
	blur_pass(ctx, s, ctx->moments.blur_x[lp->evsm][persp], &s->moments_tmp, 0, 0, res, &push);
	mb.srcStageMask = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
	mb.srcAccessMask = VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;
	vkCmdPipelineBarrier2(cmd, &di);
	push.info[2] = 1;
	blur_pass(ctx, s, ctx->moments.blur_y, &ctx->atlas_moments, (int32_t)rect[0], (int32_t)rect[1], res, &push);
}

uint32_t rnd_moments_max_res(const struct rnd_context *ctx)
{
	uint64_t range = ctx->props.limits.maxStorageBufferRange;
	uint32_t r = 16384;
	while (r > 64 && (uint64_t)r * r * 4 > range) r /= 2;
	return r;
}

bool rnd_bounds_rule(const struct rnd_light_plan *lp, bool bounds_atlas, uint32_t max_res, uint32_t res)
{
	return lp->filter == UMBRA_FILTER_PCSS && bounds_atlas && res <= max_res;
}

bool rnd_bounds_wanted(const struct rnd_context *ctx, const struct rnd_light_plan *lp, uint32_t res)
{
	return rnd_bounds_rule(lp, ctx->atlas_bounds.img != VK_NULL_HANDLE, rnd_moments_max_res(ctx), res);
}

void rnd_bounds_record_view(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_shadow_plan *sp, uint32_t v)
{
	struct rnd_moments *m = &ctx->moments;
	VkCommandBuffer cmd = s->cmd;
	const float *rect = sp->views[v].rect;
	uint32_t res = (uint32_t)rect[2], blocks = res / UMBRA_BOUNDS_BLOCK;
	struct rnd_moments_push push = {.info = {(uint32_t)rect[0], (uint32_t)rect[1], 0, 0}, .params = {0, 0, (float)res, 0}};
	vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m->layout, 0, 1, &s->moments_set, 0, NULL);
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m->bounds);
	/* Pass 1 reads the planes of pass 0's neighbouring blocks. This view's tile is its own:
	 * no other pass of this render touches these blocks. */
	VkMemoryBarrier2 mb = {
		.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
		.srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, .srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
		.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, .dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1, .pMemoryBarriers = &mb};
	for (uint32_t pass = 0; pass < 2; pass++) {
		if (pass) vkCmdPipelineBarrier2(cmd, &di);
		push.info[2] = pass;
		vkCmdPushConstants(cmd, m->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
		vkCmdDispatch(cmd, (blocks + 7) / 8, (blocks + 7) / 8, 1);   /* 8x8 invocations of one block each */
	}
}
