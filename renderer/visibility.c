/*
 * renderer/visibility.c — the visibility pass (shaders/surface.frag, shaders/vis.frag).
 *
 * Why: lavapipe shades whole 4x4 blocks per triangle, so a surface of small triangles runs the
 * fragment shader many times per pixel, and every run filtered every light's shadow map. In
 * studio-spots (seven soft lights) four spheres of 64 segments, ~1.6 % of the pixels, cost
 * 48 ms of the main pass's 166. Here the shadows are computed once per pixel instead:
 *  1. surfaces: the view's draws, single-sample, write what the main pass will shade at each
 *     pixel centre, world position and geometric normal (shaders/surface.frag);
 *  2. visibility: a fullscreen pass runs shading.glsl's shadow_visibility() for every shadowed
 *     light reaching that surface and writes the results, a layer per light of an R16 image
 *     array (umbra_shared.h UMBRA_BINDING_VISIBILITY; four lights per RGBA16 texel, one store
 *     and one fetch per four lights, measured no faster on studio-spots);
 *  3. the main pass (SC_VISIBILITY) reads a light's value instead of filtering: at its own
 *     pixel when the surface there is its own (within half a pixel of its plane, the same
 *     normal), else at the 4-neighbour that is (MSAA shades a surface at silhouette pixels whose
 *     centre shows another one).
 * Same numbers as the main pass computing them itself wherever a pixel centre shows the
 * surface, up to 16-bit storage (tests/gpu/test_visibility.c). A surface thinner than a pixel
 * that no centre shows takes its neighbour's shadow: it covers part of a pixel.
 *
 * When: scenes with lights with wide filters (PCSS, PCF of radius 4 or more) and enough small
 * triangles to pay for the passes (visibility_plan.c rnd_visibility_wanted: more for one such
 * light than for several; the render plan decides), no debug view (the views show the filters' own work) and no alpha-tested material
 * (the surfaces pass does not cut out texels, so what shows through them would take the
 * cut-out surface's shadow).
 * UMBRA_VISIBILITY=0 turns it off, =1 on where the device and the scene allow it.
 */
#include "visibility.h"

/* Pass 1: the surfaces of the band's rows, cleared to 0 (nothing drawn); their depth stays an
 * attachment for pass 2's test. */
void record_surfaces(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, VkRect2D area,
                     const struct rnd_surface_targets *t)
{
	VkCommandBuffer cmd = s->cmd;
	/* with pixel shading (deferred.c) its inputs too */
	const struct rnd_image_res *img[3] = {t->positions, t->normals, t->shading};
	const struct rnd_image_res *depth = t->depth;
	uint32_t nimg = t->shading ? 3 : 2;
	VkRenderingAttachmentInfo ca[3];
	for (uint32_t i = 0; i < nimg; i++) {
		record_image_barrier(cmd, img[i]->img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
		                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, 0,
		                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
		ca[i] = (VkRenderingAttachmentInfo){
			.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = img[i]->view,
			.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
			.storeOp = VK_ATTACHMENT_STORE_OP_STORE, .clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}},
		};
	}
	record_image_barrier(cmd, depth->img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, 0,
	                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
	VkRenderingAttachmentInfo da = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = depth->view,
		.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
		.storeOp = VK_ATTACHMENT_STORE_OP_STORE, .clearValue.depthStencil = {0.0f, 0}, /* reversed Z */
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1,
		.colorAttachmentCount = nimg, .pColorAttachments = ca, .pDepthAttachment = &da,
	};
	vkCmdBeginRendering(cmd, &ri);
	/* The main pass's viewport (the whole view, at the targets' scale) and the band's rows: the
	 * same pixels. */
	VkViewport vp = {0, 0, t->width, t->height, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
	/* surface.frag reads each draw's flags (a sphere's proxy), surface_shade.frag its material */
	record_camera_draws(ctx, s, rv, t->shading ? ctx->pipes.surfaces_shade : ctx->pipes.surfaces, true, false);
	vkCmdEndRendering(cmd);
	for (uint32_t i = 0; i < nimg; i++) record_color_to_sampled(cmd, img[i]->img);
	record_image_barrier(cmd, depth->img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	                     VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
}

/* The pass's pipeline: vis.frag with the scene's shadow constants only (the rest zeroed, so
 * that scenes differing in output, tone map or materials share one variant), or with pixel
 * shading (deferred.c) vis_shade.frag with the shading constants too, into the output's format. */
static enum rnd_result vis_pipeline(struct rnd_context *ctx, const struct record_view *rv, VkPipeline *pipe,
                                    struct rnd_error *err)
{
	struct rnd_main_key key;
	record_main_key(rv, rv->ndraw, &key);
	if (!rv->deferred) {
		key.sc[UMBRA_SC_LINEAR] = key.sc[UMBRA_SC_TONEMAP] = key.sc[UMBRA_SC_CATCHER] = 0;
		key.sc[UMBRA_SC_MASKED] = key.sc[UMBRA_SC_DEBUG] = key.sc[UMBRA_SC_ENV] = 0;
		key.format = 0;
	}
	/* vis.frag samples no texture; vis_shade.frag (plain draws only: no texture, no material
	 * extension) always multiplies by the vertex colour, white where a mesh has none: one
	 * variant with and without */
	key.sc[UMBRA_SC_TEXTURES] = key.sc[UMBRA_SC_MATERIAL_EXT] = 0;
	key.samples = 1;
	key.cull_back = key.prepass = key.aov = key.atlas_view = 0;
	key.vis_pass = 1;
	key.vis_shade = rv->deferred;
	return rnd_pipelines_main(ctx, &key, pipe, err);
}

enum rnd_result record_visibility(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                  struct rnd_error *err)
{
	const struct rnd_scene *sc = rv->sc;
	VkCommandBuffer cmd = s->cmd;
	VkPipeline pipe;
	enum rnd_result r = vis_pipeline(ctx, rv, &pipe, err);
	if (r != RND_OK) return r;
	/* The band's rows and one more on either side: the main pass may read a neighbour pixel's
	 * values (vis_pixel, resolve.frag), and nothing of an earlier band's passes is kept. */
	VkRect2D area = record_band_area(rv);
	uint32_t y0 = area.offset.y > 0 ? (uint32_t)area.offset.y - 1 : 0;
	uint32_t y1 = (uint32_t)area.offset.y + area.extent.height + 1;
	if (y1 > sc->height) y1 = sc->height;
	area.offset.y = (int32_t)y0;
	area.extent.height = y1 - y0;
	struct rnd_surface_targets t = {&s->surfaces, &s->normals, &s->surfaces_depth, (float)sc->width, (float)sc->height,
	                                rv->deferred ? &s->shading : NULL};
	record_surfaces(ctx, s, rv, area, &t);

	record_image_barrier(cmd, s->visibility.img, VK_IMAGE_ASPECT_COLOR_BIT, s->visibility.layers,
	                     VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, 0,
	                     VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
	/* Pixel shading: the colour of each pixel centre (an earlier band's resolve read it). */
	VkRenderingAttachmentInfo ca = {0};
	if (rv->deferred) ca = record_color_overwrite(cmd, &s->shaded, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
	VkRenderingAttachmentInfo da = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = s->surfaces_depth.view,
		.imageLayout = VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_LOAD,
		.storeOp = VK_ATTACHMENT_STORE_OP_NONE,
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1, .pDepthAttachment = &da,
		.colorAttachmentCount = rv->deferred ? 1 : 0, .pColorAttachments = &ca,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)sc->width, (float)sc->height, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
	/* shade.glsl names the material textures (set 1): the white ones, never read (no draw of a
	 * pixel-shaded view has a texture) */
	if (rv->deferred)
		vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx->pipes.layout, UMBRA_SET_MATERIAL, 1,
		                        &s->texture_sets[0], 0, NULL);
	vkCmdDraw(cmd, 3, 1, 0, 0);
	vkCmdEndRendering(cmd);
	record_image_barrier(cmd, s->visibility.img, VK_IMAGE_ASPECT_COLOR_BIT, s->visibility.layers, VK_IMAGE_LAYOUT_GENERAL,
	                     VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                     VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
	if (rv->deferred) record_color_to_sampled(cmd, s->shaded.img);
	return RND_OK;
}
