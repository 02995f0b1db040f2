/*
 * renderer/record.c — command recording for one view (see record.h): the main pass (with its
 * depth pre-pass) and the AOV passes, and the helpers the depth-only passes share with
 * contact.c and record_shadow.c (the shadow passes). The texture and readback copies live with their jobs (upload.c,
 * readback.c).
 */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "moments.h"
#include "contact.h"
#include "env.h"
#include "material.h"
#include "mesh.h"
#include "record.h"

void record_image_barrier(VkCommandBuffer cmd, VkImage img, VkImageAspectFlags aspect, uint32_t layers,
                          VkImageLayout from, VkImageLayout to, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                          VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access)
{
	VkImageMemoryBarrier2 b = {
		.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
		.srcStageMask = src_stage, .srcAccessMask = src_access, .dstStageMask = dst_stage, .dstAccessMask = dst_access,
		.oldLayout = from, .newLayout = to, .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
		.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = img, .subresourceRange = {aspect, 0, 1, 0, layers},
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1, .pImageMemoryBarriers = &b};
	vkCmdPipelineBarrier2(cmd, &di);
}

VkRenderingAttachmentInfo record_color_overwrite(VkCommandBuffer cmd, const struct rnd_image_res *img,
                                                 VkPipelineStageFlags2 src_stage)
{
	record_image_barrier(cmd, img->img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, src_stage, 0,
	                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
	return (VkRenderingAttachmentInfo){
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = img->view,
		.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
		.storeOp = VK_ATTACHMENT_STORE_OP_STORE,
	};
}

/* The rows of the view this submit draws. */
VkRect2D record_band_area(const struct record_view *rv)
{
	uint32_t h = rv->sc->height;
	uint32_t y = rv->band_y < h ? rv->band_y : h - 1;
	uint32_t n = rv->band_h && rv->band_h <= h - y ? rv->band_h : h - y;
	return (VkRect2D){{0, (int32_t)y}, {rv->sc->width, n}};
}

static float srgb_encode(float c)
{
	c = c < 0 ? 0 : c > 1 ? 1 : c;
	return c <= 0.0031308f ? c * 12.92f : 1.055f * powf(c, 1.0f / 2.4f) - 0.055f;
}

void record_depth_rendering(VkCommandBuffer cmd, VkImageView view, uint32_t w, uint32_t h, bool load)
{
	VkRenderingAttachmentInfo da = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = view,
		.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
		.loadOp = load ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR,
		.storeOp = VK_ATTACHMENT_STORE_OP_STORE, .clearValue.depthStencil = {1.0f, 0},
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = {{0, 0}, {w, h}}, .layerCount = 1,
		.pDepthAttachment = &da,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)w, (float)h, 0, 1};
	VkRect2D scissor = {{0, 0}, {w, h}};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &scissor);
}

/* Makes img a depth attachment (after src_stage / src_access of its previous use) and begins a
 * depth-only pass over (0, 0, w, h) of its view, cleared to 1 (the shadow pipelines' far),
 * with that viewport and scissor. */
void record_begin_depth(VkCommandBuffer cmd, VkImage img, VkImageView view, uint32_t w, uint32_t h,
                        VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access)
{
	record_image_barrier(cmd, img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, src_stage, src_access,
	                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
	record_depth_rendering(cmd, view, w, h, false);
}

void record_bind_geometry(struct rnd_context *ctx, struct rnd_slot *s)
{
	/* Binding 1, the second uv set: its own buffer, or (a scene without one) the vertices'
	 * own uvs at their stride, so a slot that asks for set 1 reads set 0 (the strides are
	 * dynamic state, renderer/pipelines.c). */
	VkBuffer bufs[2] = {s->vertices.buf, s->has_uv1 ? s->uvs1.buf : s->vertices.buf};
	VkDeviceSize offs[2] = {0, s->has_uv1 ? 0 : offsetof(struct rnd_vertex, uv)};
	VkDeviceSize strides[2] = {sizeof(struct rnd_vertex), s->has_uv1 ? 8 : sizeof(struct rnd_vertex)};
	vkCmdBindVertexBuffers2(s->cmd, 0, 2, bufs, offs, NULL, strides);
	vkCmdBindIndexBuffer(s->cmd, s->indices.buf, 0, VK_INDEX_TYPE_UINT32);
	vkCmdBindDescriptorSets(s->cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx->pipes.layout, 0, 1, &s->set, 0, NULL);
}

void record_camera_draws(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                         const VkPipeline pipes[2], bool push, bool count)
{
	VkCommandBuffer cmd = s->cmd;
	record_bind_geometry(ctx, s);
	VkPipeline bound = VK_NULL_HANDLE;
	for (uint32_t i = 0; i < rv->ndraw; i++) {
		const struct draw *d = &rv->draws[i];
		if (!d->index_count) continue;
		if (count && rv->drawn_camera && rv->band_y == 0) *rv->drawn_camera += d->cam_index_count / 3;   /* record.h */
		VkPipeline p = pipes[d->cull_back];
		if (p != bound) { vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p); bound = p; }
		if (push) {
			struct umbra_push pc = {.info = {d->material, d->flags, 0, 0}};
			vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
			                   sizeof pc, &pc);
		}
		record_draw_camera(cmd, d);
	}
}

void record_color_to_sampled(VkCommandBuffer cmd, VkImage img)
{
	record_image_barrier(cmd, img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
	                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
	                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

void record_depth_draw(struct rnd_context *ctx, struct rnd_slot *s, const struct draw *d, int cull,
                       struct umbra_push *push, VkPipeline *bound)
{
	VkCommandBuffer cmd = s->cmd;
	VkPipeline p = d->masked ? ctx->pipes.shadow_masked[cull] : ctx->pipes.shadow[cull];
	if (*bound != p) {
		vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
		*bound = p;
	}
	if (d->masked) {
		push->info[0] = d->material;
		vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
		                   0, sizeof *push, push);
		vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx->pipes.layout, UMBRA_SET_MATERIAL, 1,
		                        &s->texture_sets[d->texture_set], 0, NULL);
	}
	vkCmdDrawIndexed(cmd, d->index_count, 1, d->first_index, 0, 0);
}

uint32_t record_light_type(enum rnd_light_type t)
{
	return t == RND_LIGHT_DIRECTIONAL ? UMBRA_LIGHT_DIRECTIONAL : t == RND_LIGHT_SPOT ? UMBRA_LIGHT_SPOT : UMBRA_LIGHT_POINT;
}

uint32_t record_tonemap(enum rnd_tonemap t)
{
	return t == RND_TONEMAP_ACES ? UMBRA_TONEMAP_ACES : t == RND_TONEMAP_NONE ? UMBRA_TONEMAP_NONE : UMBRA_TONEMAP_NEUTRAL;
}

/* `atlas` is not a mode of mesh.frag (it has its own pipeline): NONE here. */
uint32_t record_debug(enum rnd_debug d)
{
	switch (d) {
	case RND_DEBUG_SHADOW: return UMBRA_DEBUG_SHADOW;
	case RND_DEBUG_CASCADES: return UMBRA_DEBUG_CASCADES;
	case RND_DEBUG_NORMALS: return UMBRA_DEBUG_NORMALS;
	case RND_DEBUG_DEPTH: return UMBRA_DEBUG_DEPTH;
	case RND_DEBUG_ENV_SHADOW: return UMBRA_DEBUG_ENV_SHADOW;
	default: return UMBRA_DEBUG_NONE;
	}
}

/* UMBRA_SC_ENV: what the view takes from its environment map. */
static uint32_t env_bits(const struct record_view *rv)
{
	const struct rnd_scene *sc = rv->sc;
	if (!rv->env || !rv->env->entry) return 0;
	uint32_t bits = UMBRA_ENV_LIGHT;
	if (rv->env->mapped) bits |= UMBRA_ENV_SHADOWS;
	if (rv->env->mapped && rv->env_pass) bits |= UMBRA_ENV_PASS;
	if (sc->environment.background_map && !sc->output.transparent &&
	    (sc->output.debug == RND_DEBUG_NONE || sc->output.debug == RND_DEBUG_CASCADES))
		bits |= UMBRA_ENV_BACKGROUND;
	return bits;
}

void record_main_key(const struct record_view *rv, uint32_t ndraw, struct rnd_main_key *k)
{
	const struct rnd_scene *sc = rv->sc;
	const struct rnd_shadow_plan *sp = rv->sp;
	const struct draw *draws = rv->draws;
	memset(k, 0, sizeof *k);
	k->format = (uint32_t)sc->output.pixels;
	k->samples = sc->output.msaa > 1 ? 4 : 1;
	bool radii_differ = false;
	for (uint32_t i = 0; i < sc->light_count; i++) {
		const struct rnd_light_plan *lp = &sp->lights[i];
		uint32_t type = record_light_type(sc->lights[i].type);
		k->sc[UMBRA_SC_LIGHT_TYPES] |= 1u << type;
		if (lp->view_count) k->sc[UMBRA_SC_FILTERS] |= 1u << lp->filter;
		if (type == UMBRA_LIGHT_DIRECTIONAL && lp->view_count > 1) k->sc[UMBRA_SC_CASCADES] = 1;
		if (rnd_contact_on(sc, sp, i)) k->sc[UMBRA_SC_CONTACT] = 1;
		if (lp->view_count && lp->filter == UMBRA_FILTER_PCF) {
			if (k->sc[UMBRA_SC_PCF_RADIUS] && k->sc[UMBRA_SC_PCF_RADIUS] != lp->pcf_radius + 1) radii_differ = true;
			k->sc[UMBRA_SC_PCF_RADIUS] = lp->pcf_radius + 1;
		}
	}
	/* Only the contract's default radius is folded: pcf_radius is a request member (0..5), and
	 * each value folded would be one more main-pass variant (~14 MB that lavapipe keeps, and
	 * RND_MAX_VARIANTS in all). Other radii take the shader's per-light path. */
	if (radii_differ || k->sc[UMBRA_SC_PCF_RADIUS] != RND_DEFAULT_PCF_RADIUS + 1) k->sc[UMBRA_SC_PCF_RADIUS] = 0;
	/* UMBRA_SPECIALIZE=0 (read per render): every light type and a PCF radius read per light,
	 * the shader's general path, for the test that the folded one draws the same bytes. */
	const char *spec = getenv("UMBRA_SPECIALIZE");
	if (spec && strcmp(spec, "0") == 0) {
		k->sc[UMBRA_SC_LIGHT_TYPES] = (1u << UMBRA_LIGHT_DIRECTIONAL) | (1u << UMBRA_LIGHT_SPOT) | (1u << UMBRA_LIGHT_POINT);
		k->sc[UMBRA_SC_PCF_RADIUS] = 0;
	}
	k->sc[UMBRA_SC_DEBUG] = record_debug(sc->output.debug);
	k->sc[UMBRA_SC_LINEAR] = sc->output.pixels == RND_PIXELS_RGBA32F;
	k->sc[UMBRA_SC_TONEMAP] = k->sc[UMBRA_SC_LINEAR] ? 0 : record_tonemap(sc->output.tonemap);
	k->sc[UMBRA_SC_ENV] = env_bits(rv);
	uint64_t dense = 0;
	for (uint32_t i = 0; i < ndraw; i++) {
		if (draws[i].flags & UMBRA_DRAW_SHADOW_CATCHER) k->sc[UMBRA_SC_CATCHER] = 1;
		k->sc[UMBRA_SC_TEXTURES] |= draws[i].tex_bits;
		if (sc->material_count) k->sc[UMBRA_SC_MATERIAL_EXT] |= rnd_material_ext_bits(&sc->materials[draws[i].material]);
		if (draws[i].masked) k->sc[UMBRA_SC_MASKED] |= 1u << (uint32_t)sc->materials[draws[i].material].alpha_mode;
		if (!draws[i].cull_back) dense += draws[i].cam_index_count / 3;
	}
	/* A depth pre-pass pays off where many small two-sided triangles would each shade whole
	 * 4x4 blocks only to be hidden (lavapipe shades per triangle); closed primitives seen from
	 * outside are back-face culled instead and need none. */
	k->prepass = dense > 20000;
	if (sc->output.debug == RND_DEBUG_ATLAS) {
		memset(k->sc, 0, sizeof k->sc);
		k->prepass = 0;
		k->atlas_view = 1;
	}
}

/* The main-pass pipeline key k needs, for both culling modes: its cull mode is dynamic state,
 * set per draw (record_cull), so one variant serves closed and open draws alike (on lavapipe
 * each pipeline JIT-compiles its shaders: a variant per mode was twice the ~14 MB). */
static enum rnd_result cull_pipelines(struct rnd_context *ctx, struct rnd_main_key *key, const struct draw *draws,
                                      uint32_t ndraw, VkPipeline pipes[2], struct rnd_error *err)
{
	(void)draws; (void)ndraw;
	key->cull_back = 0;
	enum rnd_result r = rnd_pipelines_main(ctx, key, &pipes[0], err);
	pipes[1] = pipes[0];
	return r;
}

/* The cull mode of draw d, for the main-pass and AOV variants (dynamic state). */
static void record_cull(VkCommandBuffer cmd, const struct draw *d)
{
	vkCmdSetCullMode(cmd, d->cull_back ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE);
}

/* The colour (and resolve) and depth targets of the main pass, ready to be drawn. */
static void main_barriers(VkCommandBuffer cmd, struct rnd_slot *s, bool ms)
{
	/* The atlas tiles may have been written by an earlier submit of this render (or another
	 * render's): make them visible to this pass's shadow lookups. */
	VkMemoryBarrier2 mb = {
		.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
		.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, .srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT,
		.dstStageMask = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, .dstAccessMask = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1, .pMemoryBarriers = &mb};
	vkCmdPipelineBarrier2(cmd, &di);
	VkImage target = ms ? s->color_ms.img : s->resolve.img;
	record_image_barrier(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0,
	              VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
	if (ms)
		record_image_barrier(cmd, s->resolve.img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
		              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0,
		              VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
	record_image_barrier(cmd, s->depth.img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	              VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, 0,
	              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
}

void record_clear_color(const struct rnd_scene *sc, float out[4])
{
	const float *bg = sc->environment.background;
	bool linear = sc->output.pixels == RND_PIXELS_RGBA32F;
	for (int k = 0; k < 3; k++) out[k] = linear ? bg[k] : srgb_encode(bg[k]);
	out[3] = sc->output.transparent ? 0.0f : bg[3];
	/* Transparent: the background is (0,0,0,0), so the MSAA resolve yields premultiplied
	 * colour at edges (readback.c turns 8/16-bit outputs into straight alpha, as PNG wants). */
	if (sc->output.transparent) out[0] = out[1] = out[2] = 0.0f;
	if (sc->output.debug == RND_DEBUG_SHADOW || sc->output.debug == RND_DEBUG_ENV_SHADOW)
		out[0] = out[1] = out[2] = out[3] = 1.0f;
}

static VkClearColorValue main_clear(const struct rnd_scene *sc)
{
	VkClearColorValue clear;
	record_clear_color(sc, clear.float32);
	return clear;
}

static void begin_main(VkCommandBuffer cmd, struct rnd_slot *s, const struct rnd_scene *sc, VkRect2D area, bool ms)
{
	VkRenderingAttachmentInfo ca = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = ms ? s->color_ms.view : s->resolve.view,
		.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
		.resolveMode = ms ? VK_RESOLVE_MODE_AVERAGE_BIT : VK_RESOLVE_MODE_NONE,
		.resolveImageView = ms ? s->resolve.view : VK_NULL_HANDLE,
		.resolveImageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
		.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
		.storeOp = ms ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE,
		.clearValue.color = main_clear(sc),
	};
	VkRenderingAttachmentInfo da = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = s->depth.view,
		.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
		.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE, .clearValue.depthStencil = {0.0f, 0}, /* reversed Z */
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1,
		.colorAttachmentCount = 1, .pColorAttachments = &ca, .pDepthAttachment = &da,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)sc->width, (float)sc->height, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
}

/* The main pass's push constants of draw d: its material head and its flags (mesh.frag). */
static void main_push(const struct rnd_scene *sc, const struct draw *d, struct umbra_push_main *push)
{
	_Static_assert(sizeof(struct umbra_push_main) == sizeof(struct umbra_push), "one push range for every pipeline");
	struct umbra_material m;
	rnd_material_record(sc, d->material, &m);
	memcpy(push->base_color, m.base_color, sizeof m.base_color);
	memcpy(push->emissive, m.emissive, sizeof m.emissive);
	memcpy(push->params, m.params, sizeof m.params);
	memcpy(push->tex, m.tex, sizeof m.tex);
	push->info[0] = d->material;
	push->info[1] = d->flags;
	push->info[2] = push->info[3] = 0;
}

/* The depth pre-pass (when the key asks for one), then every draw. */
static void draw_main(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv, uint32_t ndraw,
                      bool prepass, const VkPipeline pipes[2], bool ms)
{
	VkCommandBuffer cmd = s->cmd;
	const struct draw *draws = rv->draws;
	VkPipeline bound = VK_NULL_HANDLE;
	for (uint32_t i = 0; i < ndraw && prepass; i++) {
		const struct draw *d = &draws[i];
		if (!d->index_count) continue;
		VkPipeline p = d->masked ? ctx->pipes.prepass_masked[ms][d->cull_back] : ctx->pipes.prepass[ms][d->cull_back];
		if (p != bound) { vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p); bound = p; }
		if (d->masked) {
			struct umbra_push push = {.info = {d->material, d->flags, 0, 0}};
			memcpy(push.view_proj, rv->cam->view_proj, sizeof push.view_proj);
			vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
			                   sizeof push, &push);
		}
		vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx->pipes.layout, UMBRA_SET_MATERIAL, 1,
		                        &s->texture_sets[d->texture_set], 0, NULL);
		record_draw_camera(cmd, d);
	}
	/* Closed primitives first, open surfaces (planes, meshes) after: what a ground plane
	 * hides behind objects then fails the early depth test instead of being shaded. */
	for (uint32_t k = 0; k < 2 * ndraw; k++) {
		uint32_t i = k % ndraw;
		const struct draw *d = &draws[i];
		if (!d->index_count || d->closed != (k < ndraw)) continue;
		if (rv->drawn_camera && rv->band_y == 0) *rv->drawn_camera += d->cam_index_count / 3;
		VkPipeline p = pipes[d->cull_back];
		if (p != bound) { vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p); bound = p; }
		record_cull(cmd, d);
		struct umbra_push_main push;
		main_push(rv->sc, d, &push);
		vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
		                   sizeof push, &push);
		vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx->pipes.layout, UMBRA_SET_MATERIAL, 1,
		                        &s->texture_sets[d->texture_set], 0, NULL);
		record_draw_camera(cmd, d);
	}
}

enum rnd_result record_main(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                            struct rnd_error *err)
{
	const struct rnd_scene *sc = rv->sc;
	uint32_t ndraw = rv->ndraw;
	struct rnd_main_key key;
	VkPipeline pipes[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
	record_main_key(rv, ndraw, &key);
	key.vis_read = rv->vis;
	/* Reading the visibility pass, a fragment no longer filters: shading a hidden one costs about
	 * what drawing every triangle twice does, or less on real models. Measured (main pass, 512²,
	 * MSAA 4, without / with the pre-pass): the 124k-triangle ogre OBJ under the thumbnail
	 * preset 74 / 82 ms, under three soft lights 125 / 149; five stacked two-sided sheets of 20k
	 * triangles each, drawn back to front (depth complexity few models have), under one soft sun
	 * 187 / 204, under three 274 / 265. Without the visibility pass the pre-pass stays: the same
	 * sheets under three PCF lights of radius 3, 524 / 290. */
	if (key.vis_read) key.prepass = 0;
	VkPipeline atlas_pipe = VK_NULL_HANDLE;
	if (key.atlas_view) {
		enum rnd_result r = rnd_pipelines_main(ctx, &key, &atlas_pipe, err);
		if (r != RND_OK) return r;
		ndraw = 0;   /* the picture is the atlas, not the scene */
	}
	enum rnd_result r = cull_pipelines(ctx, &key, rv->draws, ndraw, pipes, err);
	if (r != RND_OK) return r;
	VkCommandBuffer cmd = s->cmd;
	bool ms = sc->output.msaa > 1;
	main_barriers(cmd, s, ms);
	begin_main(cmd, s, sc, record_band_area(rv), ms);
	record_bind_geometry(ctx, s);
	if (atlas_pipe) {
		vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, atlas_pipe);
		vkCmdDraw(cmd, 3, 1, 0, 0);
	}
	draw_main(ctx, s, rv, ndraw, key.prepass, pipes, ms);
	if (!atlas_pipe && (key.sc[UMBRA_SC_ENV] & UMBRA_ENV_BACKGROUND)) {
		/* The map behind the scene: a fullscreen triangle at the far plane (depth 0 of the
		 * reversed Z) where nothing was drawn (env_background.frag). */
		struct rnd_main_key bk = key;
		bk.background = 1;
		bk.cull_back = 0;
		bk.prepass = 0;
		VkPipeline bg;
		if ((r = rnd_pipelines_main(ctx, &bk, &bg, err)) != RND_OK) {
			vkCmdEndRendering(cmd);
			return r;
		}
		vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, bg);
		vkCmdDraw(cmd, 3, 1, 0, 0);
	}
	vkCmdEndRendering(cmd);
	return RND_OK;
}

/* Pass `pass`'s targets cleared (no geometry: Z = +inf, normal and albedo 0, visibility 1)
 * and the pass begun over area. */
static void begin_aov_pass(VkCommandBuffer cmd, struct rnd_slot *s, const struct rnd_scene *sc, VkRect2D area,
                           uint32_t pass)
{
	VkRenderingAttachmentInfo ca[UMBRA_AOV_ATTACHMENTS];
	for (uint32_t a = 0; a < UMBRA_AOV_ATTACHMENTS; a++) {
		record_image_barrier(cmd, s->aov[a].img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
		                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
		                     VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
		                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
		VkClearColorValue c = {{1.0f, 1.0f, 1.0f, 1.0f}};
		if (pass == 0 && a == 0) c = (VkClearColorValue){{INFINITY, 0.0f, 0.0f, 0.0f}};
		if (pass == 0 && a == 1) c = (VkClearColorValue){{0.0f, 0.0f, 0.0f, 0.0f}};
		ca[a] = (VkRenderingAttachmentInfo){
			.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = s->aov[a].view,
			.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
			.storeOp = VK_ATTACHMENT_STORE_OP_STORE, .clearValue.color = c,
		};
	}
	record_image_barrier(cmd, s->aov_depth.img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
	                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
	VkRenderingAttachmentInfo da = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = s->aov_depth.view,
		.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
		.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE, .clearValue.depthStencil = {0.0f, 0},
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1,
		.colorAttachmentCount = UMBRA_AOV_ATTACHMENTS, .pColorAttachments = ca, .pDepthAttachment = &da,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)sc->width, (float)sc->height, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
}

/* Copy this pass's targets out before the next pass clears them. */
static void copy_aov_pass(VkCommandBuffer cmd, struct rnd_slot *s, const struct record_view *rv, VkRect2D area,
                          uint32_t pass)
{
	for (uint32_t a = 0; a < UMBRA_AOV_ATTACHMENTS; a++) {
		record_image_barrier(cmd, s->aov[a].img, VK_IMAGE_ASPECT_COLOR_BIT, 1,
		                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
		                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
		                     VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
		VkBufferImageCopy region = {
			.bufferOffset = rv->aov_offset + (VkDeviceSize)(pass * UMBRA_AOV_ATTACHMENTS + a) * rv->aov_stride +
			                (VkDeviceSize)area.offset.y * rv->sheet_width * 16,
			.bufferRowLength = rv->sheet_width,
			.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
			.imageOffset = {0, area.offset.y, 0}, .imageExtent = {rv->sc->width, area.extent.height, 1},
		};
		vkCmdCopyImageToBuffer(cmd, s->aov[a].img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s->readback.buf, 1, &region);
	}
}

enum rnd_result record_aov(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                           struct rnd_error *err)
{
	const struct rnd_scene *sc = rv->sc;
	VkCommandBuffer cmd = s->cmd;
	VkRect2D area = record_band_area(rv);
	struct rnd_main_key key;
	VkPipeline pipes[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
	record_main_key(rv, rv->ndraw, &key);
	memset(&key.sc[UMBRA_SC_DEBUG], 0, sizeof key.sc[0]);
	key.sc[UMBRA_SC_DEBUG] = 0;
	key.sc[UMBRA_SC_LINEAR] = 1;
	key.sc[UMBRA_SC_TONEMAP] = 0;
	key.sc[UMBRA_SC_CATCHER] = 0;
	key.sc[UMBRA_SC_ENV] = 0;
	key.sc[UMBRA_SC_MATERIAL_EXT] = 0;   /* the AOVs hold no lobe */
	key.format = RND_PIXELS_RGBA32F;
	key.samples = 1;
	key.aov = 1;
	key.atlas_view = 0;
	key.prepass = 0;
	enum rnd_result r = cull_pipelines(ctx, &key, rv->draws, rv->ndraw, pipes, err);
	if (r != RND_OK) return r;
	for (uint32_t pass = 0; pass < rv->aov_passes; pass++) {
		begin_aov_pass(cmd, s, sc, area, pass);
		record_bind_geometry(ctx, s);
		VkPipeline bound = VK_NULL_HANDLE;
		uint32_t first_light = UMBRA_AOV_PASS_FIRST_LIGHT(pass);
		for (uint32_t i = 0; i < rv->ndraw; i++) {
			const struct draw *d = &rv->draws[i];
			if (!d->index_count) continue;
			/* A shadow catcher is geometry for the AOVs (contract §7). */
			VkPipeline p = pipes[d->cull_back];
			if (p != bound) { vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p); bound = p; }
			record_cull(cmd, d);
			struct umbra_push push = {.info = {d->material, d->flags, first_light, 0}};
			vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
			                   sizeof push, &push);
			vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx->pipes.layout, UMBRA_SET_MATERIAL, 1,
			                        &s->texture_sets[d->texture_set], 0, NULL);
			record_draw_camera(cmd, d);
		}
		vkCmdEndRendering(cmd);
		copy_aov_pass(cmd, s, rv, area, pass);
	}
	return RND_OK;
}
