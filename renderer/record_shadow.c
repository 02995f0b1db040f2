/*
 * renderer/record_shadow.c — the shadow passes' commands (see record.h): each map drawn into
 * the slot's scratch depth image, then copied into its atlas tile, with its PCSS depth bounds
 * and VSM / EVSM moments; a map whose casters would run past a submit's share of the deadline
 * drawn in parts, one submit each (record_shadow_part, sized by renderer/submit.c).
 */
#include <string.h>
#include "caster_level.h"
#include "casters.h"
#include "moments.h"
#include "record.h"

bool record_shadow_draws(const struct record_view *rv, uint32_t v, uint32_t i, int *cull)
{
	return rnd_shadow_view_draws(rv->sp, rv->shadow_lights ? rv->shadow_lights : rv->sc->lights, rv->draws, v, i, cull);
}

/* Begins a later part of a map: the earlier part's depth (an earlier submit) loaded. */
static void begin_depth_load(VkCommandBuffer cmd, VkImage img, VkImageView view, uint32_t w, uint32_t h)
{
	VkPipelineStageFlags2 tests = VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
	record_image_barrier(cmd, img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, tests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
	                     tests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
	record_depth_rendering(cmd, view, w, h, true);
}

/* The depth bias for draws of a caster level with error `raise` (0: the light's own): the draws
 * moved raise away from the light and the slope bias raised to match (caster_level.h). */
static void raise_bias(struct rnd_context *ctx, VkCommandBuffer cmd, const struct rnd_shadow_plan *sp, uint32_t v,
                       const struct rnd_light_plan *lp, float raise, struct umbra_push *push)
{
	rnd_caster_view_proj(sp->views[v].view_proj, raise, push->view_proj);
	vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
	                   sizeof *push, push);
	vkCmdSetDepthBias(cmd, lp->bias_constant, 0.0f, lp->bias_slope + rnd_caster_slope_bias(raise, sp->views[v].params[0]));
}

/* Triangles [lo, hi) of shadow view v's casters (in draw order, those record_shadow_draws
 * says it draws) drawn into the slot's scratch depth image, at its origin: rasterisation snaps
 * to a grid relative to the framebuffer, so drawing at the tile's own offset would make a map
 * (and the image) depend on where the atlas happened to place it; the same request then gives
 * the same bytes whatever the cache held before. lo 0 clears the map; a part that ends the
 * map (last) leaves it ready to be copied, an earlier one as a depth attachment to load. */
static void draw_shadow_map(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, uint32_t v,
                            uint64_t lo, uint64_t hi, bool last)
{
	const struct rnd_shadow_plan *sp = rv->sp;
	VkCommandBuffer cmd = s->cmd;
	const struct rnd_light_plan *lp = &sp->lights[sp->view_light[v]];
	uint32_t res = (uint32_t)sp->views[v].rect[2];
	if (lo == 0)
		record_begin_depth(cmd, s->shadow_scratch.img, s->shadow_scratch.view, res, res, VK_PIPELINE_STAGE_2_COPY_BIT,
		                   VK_ACCESS_2_TRANSFER_READ_BIT);
	else
		begin_depth_load(cmd, s->shadow_scratch.img, s->shadow_scratch.view, res, res);
	vkCmdSetDepthBias(cmd, lp->bias_constant, 0.0f, lp->bias_slope);
	/* Masked casters read materials and textures; the set's shadow-map binding is not
	 * used by the alpha-test shader while the map is a render target. */
	record_bind_geometry(ctx, s);
	struct umbra_push push = {0};
	memcpy(push.view_proj, sp->views[v].view_proj, sizeof push.view_proj);
	vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
	                   sizeof push, &push);
	VkPipeline bound = VK_NULL_HANDLE;
	uint64_t at = 0;   /* casters' triangles before draw i */
	float raised = 0.0f;   /* the caster level's bias in force (caster_level.h) */
	for (uint32_t i = 0; i < rv->ndraw && at < hi; i++) {
		int cull;
		float raise;
		if (!record_shadow_draws(rv, v, i, &cull)) continue;
		struct draw d = rnd_caster_view_draw(sp, rv->shadow_lights ? rv->shadow_lights : rv->sc->lights, v, &rv->draws[i],
		                                     &cull, &raise);
		uint64_t n = d.index_count / 3, a = lo > at ? lo - at : 0, b = hi - at < n ? hi - at : n;
		at += n;
		if (a >= b) continue;
		if (rv->drawn_shadow) *rv->drawn_shadow += b - a;
		if (raise != raised) {
			raise_bias(ctx, cmd, sp, v, lp, raise, &push);
			raised = raise;
		}
		d.first_index += (uint32_t)(3 * a);
		d.index_count = (uint32_t)(3 * (b - a));
		record_depth_draw(ctx, s, &d, cull, &push, &bound);
	}
	vkCmdEndRendering(cmd);
	if (!last) return;
	record_image_barrier(cmd, s->shadow_scratch.img, VK_IMAGE_ASPECT_DEPTH_BIT, 1,
	                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
	                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
	                     VK_ACCESS_2_TRANSFER_READ_BIT);
}

/* PCSS: the map as floats for the depth bounds (compute shaders cannot read a depth image on
 * lavapipe without it copying the image on every dispatch). The previous view's compute
 * passes must be done reading the buffer. */
static void copy_for_bounds(struct rnd_slot *s, uint32_t res)
{
	VkCommandBuffer cmd = s->cmd;
	VkBufferMemoryBarrier2 bb = {
		.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2,
		.srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
		.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
		.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
		.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT, .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
		.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .buffer = s->scratch_buf.buf, .size = VK_WHOLE_SIZE,
	};
	VkDependencyInfo bdi = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .bufferMemoryBarrierCount = 1, .pBufferMemoryBarriers = &bb};
	vkCmdPipelineBarrier2(cmd, &bdi);
	VkBufferImageCopy region = {
		.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1}, .imageExtent = {res, res, 1},
	};
	vkCmdCopyImageToBuffer(cmd, s->shadow_scratch.img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s->scratch_buf.buf, 1,
	                       &region);
	bb.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
	bb.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
	bb.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
	bb.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT;
	vkCmdPipelineBarrier2(cmd, &bdi);
}

/* The atlas stays in GENERAL layout. Earlier submissions (other renders) may still sample or
 * write other tiles; this render writes only its own tiles, so an execution and memory
 * dependency on what came before is all that is needed (in). The atlas tiles (depth copied
 * in, moments drawn, bounds from compute) are then read by the main and AOV passes (out). */
static void atlas_barrier(VkCommandBuffer cmd, bool in)
{
	VkMemoryBarrier2 mb = {
		.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
		.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, .srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT,
		.dstStageMask = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
		                VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
		.dstAccessMask = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
		                 VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
		                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
	};
	if (!in) {
		mb.srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT |
		                  VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
		mb.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
		                   VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;
		mb.dstStageMask = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
		mb.dstAccessMask = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;
	}
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1, .pMemoryBarriers = &mb};
	vkCmdPipelineBarrier2(cmd, &di);
}

/* The drawn map of view v into its atlas tile, with what its filter reads beside it. */
static void finish_view(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, uint32_t v)
{
	const struct rnd_shadow_plan *sp = rv->sp;
	const struct rnd_light_plan *lp = &sp->lights[sp->view_light[v]];
	uint32_t res = (uint32_t)sp->views[v].rect[2];
	/* Into the depth atlas: a same-format image copy, which lavapipe does as a memcpy. */
	VkImageCopy copy = {
		.srcSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1},
		.dstSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1},
		.dstOffset = {(int32_t)sp->views[v].rect[0], (int32_t)sp->views[v].rect[1], 0}, .extent = {res, res, 1},
	};
	vkCmdCopyImage(s->cmd, s->shadow_scratch.img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, ctx->atlas_depth.img,
	               VK_IMAGE_LAYOUT_GENERAL, 1, &copy);
	/* PCSS: the tile's depth bounds, drawn with every map drawn, so a cached map has them
	 * whenever it is reused (the cache key holds the filter and the resolution). */
	if (rnd_bounds_wanted(ctx, lp, res)) {
		copy_for_bounds(s, res);
		rnd_bounds_record_view(ctx, s, sp, v);
	}
	/* VSM / EVSM: from the tile just copied into the depth atlas */
	rnd_moments_record_view(ctx, s, sp, v, rv->sc);
}

void record_shadows(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, uint32_t first,
                    uint32_t end)
{
	const struct rnd_shadow_plan *sp = rv->sp;
	atlas_barrier(s->cmd, true);
	for (uint32_t v = first; v < end && v < sp->view_count; v++) {
		if (sp->view_skip[v]) continue;
		draw_shadow_map(ctx, s, rv, v, 0, UINT64_MAX, true);
		finish_view(ctx, s, rv, v);
	}
	atlas_barrier(s->cmd, false);
}

void record_shadow_part(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, uint32_t v,
                        uint64_t lo, uint64_t hi, uint64_t total)
{
	bool last = hi >= total;
	if (lo == 0) atlas_barrier(s->cmd, true);
	draw_shadow_map(ctx, s, rv, v, lo, hi, last);
	if (!last) return;
	finish_view(ctx, s, rv, v);
	atlas_barrier(s->cmd, false);
}
