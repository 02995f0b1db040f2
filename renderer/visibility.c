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
 * triangles to pay for the passes (rnd_visibility_wanted: more for one such light than for
 * several), no debug view (the views show the filters' own work) and no alpha-tested material
 * (the surfaces pass does not cut out texels, so what shows through them would take the
 * cut-out surface's shadow).
 * UMBRA_VISIBILITY=0 turns it off, =1 on where the device and the scene allow it.
 */
#include <stdlib.h>
#include <string.h>
#include "visibility.h"

/* When the pass pays (measured on lavapipe, studio-spots' objects under its seven lights, 768 x
 * 512): it runs the filters once per block of 4x4 pixels where the main pass ran them once per
 * block per triangle touching it, and costs a surfaces pass and a main pass of its own. A floor
 * alone: 15 % slower; spheres of 16 segments (~600 triangles facing the camera): 4 % faster; of
 * 32 (~2,200): 11 %; of 64 (~8,300): 20 % (4 and 16 spot lights: 23 %, 18 %). So: at least one
 * such triangle per 512 pixels. One wide light: one per 16 pixels (below).
 * Only wide filters pay for it: studio-spots' seven lights all hard made the main pass 49 ms
 * without the pass and 65 with it; PCF radius 1: 57 / 68, 2: 81 / 84, 3: 97 / 97, 5: 143 /
 * 134; PCSS: 136 / 119. A hard or moment-map lookup is one fetch, cheaper than the passes. */
#define RND_VIS_MIN_PCF_RADIUS 4u
#define RND_VIS_PIXELS_PER_FACE 512u
/* One wide light pays for the passes only over dense meshes. Measured, the thumbnail preset
 * with its one PCSS sun, 512², whole render without / with the pass: the 124k-triangle ogre
 * OBJ's 49k level 115 / 101 ms, nefertiti 113 / 86, beast 88 / 73, a 100k-triangle STL sphere's
 * level 60 / 55 (main pass alone: ogre 97 / 80, nefertiti 95 / 69); about even: a sphere of
 * 128 segments (one face towards the camera per 32 pixels) 49.1 / 48.6, a 10k-triangle STL
 * (one per 52) 46.7 / 44.6 and 43.6 / 44.0, 64 segments (one per 130) 39.7 / 39.5; worse: 16
 * segments (one per 500) 31.9 / 35.1, thumb-512's tessellated sphere (one per 47) main pass
 * 17.3 / 19.4. So one per 16 pixels, where it clearly pays; and only with MSAA, which shades
 * a pixel once per triangle touching it: at MSAA 1 one triangle shades each pixel, and the
 * ogre's thumbnail took 53-57 ms without the pass, 59-60 with it. */
#define RND_VIS_PIXELS_PER_FACE_ONE_LIGHT 16u
/* The largest visibility image (bytes) a render may take: 16 lights of a 1024² view. */
#define RND_VIS_MAX_BYTES (32ull << 20)

/* A filter costly enough per pixel that running it once per pixel pays for the passes. */
static bool wide_filter(const struct rnd_light_plan *lp)
{
	return lp->filter == UMBRA_FILTER_PCSS || (lp->filter == UMBRA_FILTER_PCF && lp->pcf_radius >= RND_VIS_MIN_PCF_RADIUS);
}

uint64_t rnd_visibility_bytes(const struct rnd_scene *sc)
{
	if (sc->output.debug != RND_DEBUG_NONE) return 0;
	bool shadowed = false;
	for (uint32_t i = 0; i < sc->light_count; i++) shadowed |= sc->lights[i].shadow.enabled;
	uint64_t px = (uint64_t)sc->width * sc->height;
	if (!shadowed || px * sc->light_count * 2 > RND_VIS_MAX_BYTES) return 0;
	/* rnd_slot_visibility's images: surfaces RGBA32F, normals RGBA16 SNORM, their depth D32,
	 * an R16 layer per light, at least RND_VIS_MIN_LAYERS (internal.h) */
	uint32_t layers = sc->light_count < RND_VIS_MIN_LAYERS ? RND_VIS_MIN_LAYERS : sc->light_count;
	return px * (16 + 8 + 4 + 2ull * layers);
}

bool rnd_visibility_wanted(const struct rnd_context *ctx, const struct rnd_scene *sc, const struct rnd_shadow_plan *sp,
                           const struct draw *draws, uint32_t ndraw)
{
	if (!ctx->visibility_pass || sc->output.debug != RND_DEBUG_NONE) return false;
	uint32_t shadowed = 0, wide = 0;
	for (uint32_t i = 0; i < sc->light_count; i++)
		if (sp->lights[i].view_count) {
			shadowed++;
			if (wide_filter(&sp->lights[i])) wide++;
		}
	if (!shadowed) return false;
	for (uint32_t i = 0; i < ndraw; i++)
		if (draws[i].index_count && draws[i].masked) return false;
	if (!rnd_visibility_bytes(sc)) return false;   /* over the size cap */
	const char *env = getenv("UMBRA_VISIBILITY");
	if (env && strcmp(env, "0") == 0) return false;
	if (env && strcmp(env, "1") == 0) return true;
	/* Faces the camera may see: a back-face culled closed shape shows about half its triangles,
	 * a sphere's proxy all of its own. */
	uint64_t faces = 0;
	for (uint32_t i = 0; i < ndraw; i++)
		faces += draws[i].cam_index_count / 3 / (draws[i].cull_back ? 2 : 1);
	uint64_t px = (uint64_t)sc->width * sc->height;
	if (wide >= 2) return faces * RND_VIS_PIXELS_PER_FACE >= px;
	return wide == 1 && sc->output.msaa > 1 && faces * RND_VIS_PIXELS_PER_FACE_ONE_LIGHT >= px;
}

/* Pass 1: the surfaces of the band's rows, cleared to 0 (nothing drawn); their depth stays an
 * attachment for pass 2's test. */
void record_surfaces(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, VkRect2D area,
                     const struct rnd_surface_targets *t)
{
	VkCommandBuffer cmd = s->cmd;
	const struct rnd_image_res *img[2] = {t->positions, t->normals};
	const struct rnd_image_res *depth = t->depth;
	VkRenderingAttachmentInfo ca[2];
	for (int i = 0; i < 2; i++) {
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
		.colorAttachmentCount = 2, .pColorAttachments = ca, .pDepthAttachment = &da,
	};
	vkCmdBeginRendering(cmd, &ri);
	/* The main pass's viewport (the whole view, at the targets' scale) and the band's rows: the
	 * same pixels. */
	VkViewport vp = {0, 0, t->width, t->height, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
	record_bind_geometry(ctx, s);
	VkPipeline bound = VK_NULL_HANDLE;
	for (uint32_t i = 0; i < rv->ndraw; i++) {
		const struct draw *d = &rv->draws[i];
		if (!d->index_count) continue;
		VkPipeline p = ctx->pipes.surfaces[d->cull_back];
		if (p != bound) { vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p); bound = p; }
		/* surface.frag reads the draw's flags (a sphere's proxy). */
		struct umbra_push push = {.info = {d->material, d->flags, 0, 0}};
		vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
		                   sizeof push, &push);
		record_draw_camera(cmd, d);
	}
	vkCmdEndRendering(cmd);
	for (int i = 0; i < 2; i++)
		record_image_barrier(cmd, img[i]->img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
		                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
		                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
		                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
	record_image_barrier(cmd, depth->img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	                     VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
}

enum rnd_result record_visibility(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                  struct rnd_error *err)
{
	const struct rnd_scene *sc = rv->sc;
	VkCommandBuffer cmd = s->cmd;
	struct rnd_main_key key;
	record_main_key(rv, rv->ndraw, &key);
	/* Only the shadow constants shape vis.frag: the rest are zeroed so that scenes differing in
	 * output, tone map or materials share one variant. */
	key.sc[UMBRA_SC_LINEAR] = key.sc[UMBRA_SC_TONEMAP] = key.sc[UMBRA_SC_CATCHER] = 0;
	key.sc[UMBRA_SC_TEXTURES] = key.sc[UMBRA_SC_MASKED] = key.sc[UMBRA_SC_DEBUG] = key.sc[UMBRA_SC_ENV] = 0;
	key.sc[UMBRA_SC_MATERIAL_EXT] = 0;
	key.format = 0;
	key.samples = 1;
	key.cull_back = key.prepass = key.aov = key.atlas_view = 0;
	key.vis_pass = 1;
	VkPipeline pipe;
	enum rnd_result r = rnd_pipelines_main(ctx, &key, &pipe, err);
	if (r != RND_OK) return r;
	/* The band's rows and one more on either side: the main pass may read a neighbour pixel's
	 * values (vis_pixel), and nothing of an earlier band's passes is kept. */
	VkRect2D area = record_band_area(rv);
	uint32_t y0 = area.offset.y > 0 ? (uint32_t)area.offset.y - 1 : 0;
	uint32_t y1 = (uint32_t)area.offset.y + area.extent.height + 1;
	if (y1 > sc->height) y1 = sc->height;
	area.offset.y = (int32_t)y0;
	area.extent.height = y1 - y0;
	struct rnd_surface_targets t = {&s->surfaces, &s->normals, &s->surfaces_depth, (float)sc->width, (float)sc->height};
	record_surfaces(ctx, s, rv, area, &t);

	record_image_barrier(cmd, s->visibility.img, VK_IMAGE_ASPECT_COLOR_BIT, s->visibility.layers,
	                     VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, 0,
	                     VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
	VkRenderingAttachmentInfo da = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = s->surfaces_depth.view,
		.imageLayout = VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_LOAD,
		.storeOp = VK_ATTACHMENT_STORE_OP_NONE,
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1, .pDepthAttachment = &da,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)sc->width, (float)sc->height, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
	vkCmdDraw(cmd, 3, 1, 0, 0);
	vkCmdEndRendering(cmd);
	record_image_barrier(cmd, s->visibility.img, VK_IMAGE_ASPECT_COLOR_BIT, s->visibility.layers, VK_IMAGE_LAYOUT_GENERAL,
	                     VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                     VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
	return RND_OK;
}
