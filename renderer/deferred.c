/*
 * renderer/deferred.c — pixel shading (see deferred.h): when a view is shaded once per pixel
 * centre, and its main pass, depth only, with the resolve that gives each sample its colour.
 * The shading itself is the visibility pass's (visibility.c, vis_shade.frag).
 */
#include <stdlib.h>
#include <string.h>
#include "deferred.h"
#include "material.h"
#include "visibility.h"

bool rnd_deferred_supported(struct rnd_context *ctx)
{
	VkFormatProperties fp, dp;
	vkGetPhysicalDeviceFormatProperties(ctx->phys, RND_SURFACE_SHADING_FORMAT, &fp);
	vkGetPhysicalDeviceFormatProperties(ctx->phys, RND_DEPTH_FORMAT, &dp);
	VkFormatFeatureFlags need = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
	return ctx->visibility_pass && ctx->props.limits.standardSampleLocations &&
	       (ctx->props.limits.sampledImageDepthSampleCounts & VK_SAMPLE_COUNT_4_BIT) &&
	       (fp.optimalTilingFeatures & need) == need &&
	       (dp.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT);
}

/* The view's depth, every sample, of the band's rows: every draw with the depth pre-pass's
 * pipelines (no fragment shader), kept for the resolve. */
static void draw_depth(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, VkRect2D area)
{
	VkCommandBuffer cmd = s->cmd;
	const VkPipelineStageFlags2 tests = VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
	                                    VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
	/* An earlier band's resolve read it. */
	record_image_barrier(cmd, s->depth.img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, tests,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
	VkRenderingAttachmentInfo da = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = s->depth.view,
		.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
		.storeOp = VK_ATTACHMENT_STORE_OP_STORE, .clearValue.depthStencil = {0.0f, 0}, /* reversed Z */
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1, .pDepthAttachment = &da,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)rv->sc->width, (float)rv->sc->height, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
	record_camera_draws(ctx, s, rv, ctx->pipes.prepass[1], false, true);
	vkCmdEndRendering(cmd);
	record_image_barrier(cmd, s->depth.img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	                     VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

enum rnd_result record_deferred_main(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                     struct rnd_error *err)
{
	struct rnd_main_key key;
	memset(&key, 0, sizeof key);
	key.format = (uint32_t)rv->sc->output.pixels;
	key.samples = 1;
	key.resolve = 1;
	VkPipeline resolve;
	enum rnd_result r = rnd_pipelines_main(ctx, &key, &resolve, err);
	if (r != RND_OK) return r;
	VkCommandBuffer cmd = s->cmd;
	VkRect2D area = record_band_area(rv);
	draw_depth(ctx, s, rv, area);
	/* The single-sample target, as record_main leaves it (the readback copies it). */
	VkRenderingAttachmentInfo ca = record_color_overwrite(cmd, &s->resolve, VK_PIPELINE_STAGE_2_TRANSFER_BIT);
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1,
		.colorAttachmentCount = 1, .pColorAttachments = &ca,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)rv->sc->width, (float)rv->sc->height, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, resolve);
	vkCmdDraw(cmd, 3, 1, 0, 0);
	vkCmdEndRendering(cmd);
	return RND_OK;
}
