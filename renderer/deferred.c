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

/* A draw shade.glsl can shade from the surfaces pass alone: no texture (the fullscreen pass has
 * no uv derivatives and binds no material's set), no material extension's lobe (their textures
 * and coat normal), opaque (no alpha test or dither: the surfaces pass cuts no texel out), not a
 * sphere's proxy (it shades the true sphere, not the mesh the surfaces pass keeps). */
static bool plain(const struct rnd_scene *sc, const struct draw *d)
{
	return !d->masked && !(d->tex_bits & ((1u << UMBRA_TEX_SLOTS) - 1u)) && !(d->flags & UMBRA_DRAW_SPHERE) &&
	       !(sc->material_count && rnd_material_ext_bits(&sc->materials[d->material]));
}

/* Without the visibility pass (no light with a wide shadow filter), pixel shading runs the
 * surfaces pass for itself where an environment map lights the view: its shading (the map's
 * light and the environment pass's bilateral read, ibl.glsl) is what lavapipe would otherwise run
 * per triangle per 4x4 block. It pays over dense meshes, as the visibility pass does for one wide
 * light: at least one face towards the camera per RND_DEFERRED_PIXELS_PER_FACE pixels. */
#define RND_DEFERRED_PIXELS_PER_FACE 16u

bool rnd_deferred_wanted(const struct rnd_context *ctx, const struct rnd_scene *sc, const struct draw *draws,
                         uint32_t ndraw, bool vis, bool env_lit)
{
	if (!ctx->pixel_shading || sc->output.msaa != 4 || sc->output.debug != RND_DEBUG_NONE) return false;
	/* An environment map behind the scene is drawn where the main pass left the far plane
	 * (record.c, env_background.frag); the resolve writes the clear colour there. */
	if (sc->environment.source != RND_ENV_AMBIENT && sc->environment.background_map && !sc->output.transparent)
		return false;
	for (uint32_t i = 0; i < ndraw; i++)
		if (draws[i].index_count && !plain(sc, &draws[i])) return false;
	if (!vis) {
		if (!ctx->visibility_pass || !env_lit || !rnd_surfaces_bytes(sc, 0)) return false;
		if (rnd_camera_faces(draws, ndraw) * RND_DEFERRED_PIXELS_PER_FACE < (uint64_t)sc->width * sc->height)
			return false;
	}
	const char *env = getenv("UMBRA_PIXEL_SHADING");
	return !(env && strcmp(env, "0") == 0);
}

uint64_t rnd_deferred_bytes(const struct rnd_scene *sc)
{
	if (sc->output.msaa != 4 || sc->output.debug != RND_DEBUG_NONE) return 0;
	/* the surfaces pass's images where the visibility pass has none (an environment map's view) */
	uint64_t surfaces = 0;
	if (!rnd_visibility_bytes(sc)) {
		if (sc->environment.source == RND_ENV_AMBIENT || !(surfaces = rnd_surfaces_bytes(sc, 0))) return 0;
	}
	/* the shading inputs (RGBA32UI) and the shaded colour (at most RGBA32F) */
	return surfaces + (uint64_t)sc->width * sc->height * (16 + 16);
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
	record_bind_geometry(ctx, s);
	VkPipeline bound = VK_NULL_HANDLE;
	for (uint32_t i = 0; i < rv->ndraw; i++) {
		const struct draw *d = &rv->draws[i];
		if (!d->index_count) continue;
		VkPipeline p = ctx->pipes.prepass[1][d->cull_back];
		if (p != bound) { vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p); bound = p; }
		record_draw_camera(cmd, d);
	}
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
