/*
 * renderer/moments.c — moment shadow maps (VSM and EVSM2) for every light type: a compute
 * pipeline (shaders/moments.comp) that turns a depth layer into blurred moments, and the
 * recording of its two passes per shadow view. Created once per context; the moment images
 * themselves belong to the render slots (slot.c).
 * Also PCSS's depth bounds (shaders/minmax.comp): the same kind of pass over the same scratch
 * copy of a map just drawn, with the same descriptor set and pipeline layout.
 *
 * Format: R32G32_SFLOAT where the device can filter it linearly and store to it, else
 * R16G16_SFLOAT (the EVSM exponent is then clamped so exp(2cd) fits in a half).
 */
#include <math.h>
#include <string.h>
#include "moments.h"
#include "record.h"
#include "moments.comp.spv.h"
#include "minmax.comp.spv.h"

/* moments.comp holds a blur's whole reach in workgroup memory: every radius a scene may ask. */
_Static_assert(RND_MAX_VSM_BLUR <= UMBRA_MOMENTS_MAX_RADIUS, "moments.comp's workgroup rows hold the widest blur");

static bool format_ok(const struct rnd_context *ctx, VkFormat f)
{
	VkFormatProperties fp;
	vkGetPhysicalDeviceFormatProperties(ctx->phys, f, &fp);
	VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
	                            VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT;
	return (fp.optimalTilingFeatures & need) == need;
}

enum rnd_result rnd_moments_init(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_moments *m = &ctx->moments;
	VkResult vr;
	VkPhysicalDeviceFeatures f;
	vkGetPhysicalDeviceFeatures(ctx->phys, &f);
	m->fp32 = format_ok(ctx, VK_FORMAT_R32G32_SFLOAT) && f.shaderStorageImageExtendedFormats;
	m->available = f.shaderStorageImageWriteWithoutFormat && f.shaderStorageImageExtendedFormats &&
	               (format_ok(ctx, VK_FORMAT_R32G32_SFLOAT) || format_ok(ctx, VK_FORMAT_R16G16_SFLOAT));
	VkDescriptorSetLayoutBinding b[4] = {
		{UMBRA_MOMENTS_BINDING_DEPTH, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
		{UMBRA_MOMENTS_BINDING_TMP, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
		{UMBRA_MOMENTS_BINDING_OUT, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
		{UMBRA_MOMENTS_BINDING_BOUNDS, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
	};
	VkDescriptorSetLayoutCreateInfo dci = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, .bindingCount = 4, .pBindings = b};
	if ((vr = vkCreateDescriptorSetLayout(ctx->device, &dci, NULL, &m->set_layout)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreateDescriptorSetLayout (moments)");
	RND_NAME(ctx, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, m->set_layout, "moments set layout");
	VkPushConstantRange pcr = {VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(struct rnd_moments_push)};
	VkPipelineLayoutCreateInfo lci = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, .setLayoutCount = 1, .pSetLayouts = &m->set_layout,
		.pushConstantRangeCount = 1, .pPushConstantRanges = &pcr,
	};
	if ((vr = vkCreatePipelineLayout(ctx->device, &lci, NULL, &m->layout)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkCreatePipelineLayout (moments)");
		goto fail;
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE_LAYOUT, m->layout, "moments pipeline layout");
	const struct { const uint32_t *code; size_t size; VkPipeline *out; const char *name; } progs[2] = {
		{spv_moments_comp, sizeof spv_moments_comp, &m->pipeline, "moments blur"},
		{spv_minmax_comp, sizeof spv_minmax_comp, &m->bounds, "pcss depth bounds"},
	};
	for (int i = 0; i < 2; i++) {
		VkShaderModule mod;
		VkShaderModuleCreateInfo mci = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, .codeSize = progs[i].size, .pCode = progs[i].code};
		if ((vr = vkCreateShaderModule(ctx->device, &mci, NULL, &mod)) != VK_SUCCESS) {
			rnd_fail_vk(err, vr, "vkCreateShaderModule (compute)");
			goto fail;
		}
		VkComputePipelineCreateInfo cci = {
			.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
			.stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_COMPUTE_BIT, .module = mod, .pName = "main"},
			.layout = m->layout,
		};
		vr = vkCreateComputePipelines(ctx->device, ctx->pipeline_cache, 1, &cci, NULL, progs[i].out);
		vkDestroyShaderModule(ctx->device, mod, NULL);
		if (vr != VK_SUCCESS) {
			rnd_fail_vk(err, vr, "vkCreateComputePipelines");
			goto fail;
		}
		RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE, *progs[i].out, "%s", progs[i].name);
	}
	VkSamplerCreateInfo sci = {
		.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO, .magFilter = VK_FILTER_LINEAR, .minFilter = VK_FILTER_LINEAR,
		.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST, .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
		.addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
	};
	if ((vr = vkCreateSampler(ctx->device, &sci, NULL, &m->sampler)) != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkCreateSampler (moments)");
		goto fail;
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_SAMPLER, m->sampler, "moments sampler");
	return RND_OK;
fail:
	rnd_moments_release(ctx);
	return err->code;
}

void rnd_moments_release(struct rnd_context *ctx)
{
	struct rnd_moments *m = &ctx->moments;
	if (!ctx->device) return;
	if (m->sampler) vkDestroySampler(ctx->device, m->sampler, NULL);
	if (m->bounds) vkDestroyPipeline(ctx->device, m->bounds, NULL);
	if (m->pipeline) vkDestroyPipeline(ctx->device, m->pipeline, NULL);
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

void rnd_moments_record_view(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_shadow_plan *sp,
                             uint32_t v, const struct rnd_scene *sc)
{
	struct rnd_moments *m = &ctx->moments;
	VkCommandBuffer cmd = s->cmd;
	const struct rnd_light_plan *lp = &sp->lights[sp->view_light[v]];
	const float *rect = sp->views[v].rect;
	/* Tiles are powers of two of at least 64 texels: whole workgroups of UMBRA_MOMENTS_ROWS rows
	 * of UMBRA_MOMENTS_SPAN texels (moments.comp). */
	uint32_t res = (uint32_t)rect[2];
	float blur = sc->lights[sp->view_light[v]].shadow.vsm_blur;
	/* api/ rejects a blur over RND_MAX_VSM_BLUR; a library caller asking more gets the widest */
	uint32_t radius = (uint32_t)ceilf(fmaxf(blur, 0.0f));
	if (radius > UMBRA_MOMENTS_MAX_RADIUS) radius = UMBRA_MOMENTS_MAX_RADIUS;
	struct rnd_moments_push push = {
		.info = {(uint32_t)rect[0], (uint32_t)rect[1], 0, radius},
		.params = {lp->evsm ? lp->evsm_exponent : 0.0f, fmaxf(blur * 0.5f, 0.5f), (float)res, 0},
		.proj = {sp->views[v].params[2], sp->views[v].params[3], sp->views[v].params[1], 0},
	};
	if (!lp->moments) return;
	vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m->layout, 0, 1, &s->moments_set, 0, NULL);
	VkMemoryBarrier2 mb = {
		.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
		.srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
		.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
		.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
		.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1, .pMemoryBarriers = &mb};
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m->pipeline);
	for (uint32_t pass = 0; pass < 2; pass++) {
		/* The blur temporary is shared by every view: each pass waits for the last use. */
		vkCmdPipelineBarrier2(cmd, &di);
		push.info[2] = pass;
		vkCmdPushConstants(cmd, m->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
		vkCmdDispatch(cmd, res / UMBRA_MOMENTS_SPAN, res / UMBRA_MOMENTS_ROWS, 1);
	}
}

uint32_t rnd_moments_max_res(const struct rnd_context *ctx)
{
	uint64_t range = ctx->props.limits.maxStorageBufferRange;
	uint32_t r = 16384;
	while (r > 64 && (uint64_t)r * r * 4 > range) r /= 2;
	return r;
}

bool rnd_bounds_wanted(const struct rnd_context *ctx, const struct rnd_light_plan *lp, uint32_t res)
{
	return lp->filter == UMBRA_FILTER_PCSS && ctx->atlas_bounds.img && res <= rnd_moments_max_res(ctx);
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
