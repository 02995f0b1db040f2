/*
 * renderer/render.c — rnd_render(): one scene, start to finish, on one render slot.
 *
 *   validate -> tessellate straight into the slot's mapped vertex/index buffers (upload)
 *   -> plan camera and shadow views -> write uniforms -> record: shadow pass per view,
 *   main pass (MSAA + resolve), copy to the readback buffer -> submit, wait on the slot's
 *   fence -> copy pixels out.
 *
 * The slot is waited on before rnd_render() returns, so nothing of this render is in flight
 * afterwards and the slot's resources may be reused or grown by the next render.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "mesh.h"
#include "plan.h"
#include "slot.h"

/* How long a submitted render may take before the device is considered hung. */
#define RND_FENCE_TIMEOUT_NS (120ull * 1000 * 1000 * 1000)

struct draw {
	uint32_t first_index, index_count;
	struct rnd_aabb bounds;
	uint32_t material;
	uint32_t flags;
	bool cast, cull_back;
	bool closed;        /* sphere / box / cylinder: back faces never show from outside */
	bool single_sided;  /* double_sided: false */
};

/* Culling back faces of a closed primitive changes nothing in the picture as long as the
 * viewer is outside it and it lies wholly beyond the near plane; it halves the triangles
 * lavapipe rasterises and shades. */
static bool camera_outside(const struct rnd_camera_plan *cam, const struct rnd_aabb *b)
{
	for (int i = 0; i < 8; i++) {
		float p[3] = {i & 1 ? b->max[0] : b->min[0], i & 2 ? b->max[1] : b->min[1], i & 4 ? b->max[2] : b->min[2]};
		float d[3];
		rnd_v3_sub(d, p, cam->pos);
		if (rnd_v3_dot(d, cam->fwd) <= cam->znear * 1.01f) return false;
	}
	return true;
}

static bool point_outside(const float p[3], const struct rnd_aabb *b, float pad)
{
	for (int k = 0; k < 3; k++)
		if (p[k] < b->min[k] - pad || p[k] > b->max[k] + pad) return true;
	return false;
}

static double now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static enum rnd_result validate(const struct rnd_context *ctx, const struct rnd_scene *sc, struct rnd_error *err)
{
	if (sc->width < 1 || sc->height < 1 || sc->width > ctx->desc.max_width || sc->height > ctx->desc.max_height ||
	    sc->width > ctx->props.limits.maxImageDimension2D || sc->height > ctx->props.limits.maxImageDimension2D)
		return rnd_fail(err, RND_ERR_LIMIT, "image %ux%u is outside 1..%u x 1..%u", sc->width, sc->height,
		                ctx->desc.max_width, ctx->desc.max_height);
	if (sc->output.msaa != 1 && sc->output.msaa != 4)
		return rnd_fail(err, RND_ERR_INVALID, "msaa %u: must be 1 or 4", sc->output.msaa);
	if ((unsigned)sc->output.pixels >= RND_COLOR_FORMAT_COUNT)
		return rnd_fail(err, RND_ERR_INVALID, "unknown pixel format %d", (int)sc->output.pixels);
	if (sc->material_count > UMBRA_MAX_MATERIALS)
		return rnd_fail(err, RND_ERR_LIMIT, "%u materials: at most %d", sc->material_count, UMBRA_MAX_MATERIALS);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (sc->objects[i].material >= sc->material_count && sc->material_count > 0)
			return rnd_fail(err, RND_ERR_INVALID, "object %u: material %u does not exist", i, sc->objects[i].material);
	if (sc->output.debug == RND_DEBUG_SHADOW && sc->output.debug_light >= sc->light_count && sc->light_count > 0)
		return rnd_fail(err, RND_ERR_INVALID, "debug_light %u names no light", sc->output.debug_light);
	if (sc->output.debug == RND_DEBUG_ATLAS)
		return rnd_fail(err, RND_ERR_INVALID, "debug view 'atlas' is not implemented by this renderer yet");
	if (sc->output.aovs)
		return rnd_fail(err, RND_ERR_INVALID, "AOVs are not implemented by this renderer yet");
	return RND_OK;
}

static void image_barrier(VkCommandBuffer cmd, VkImage img, VkImageAspectFlags aspect, uint32_t layers,
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

static float srgb_encode(float c)
{
	c = c < 0 ? 0 : c > 1 ? 1 : c;
	return c <= 0.0031308f ? c * 12.92f : 1.055f * powf(c, 1.0f / 2.4f) - 0.055f;
}

/* 32 Poisson-disk taps in the unit disk (PCSS blocker search and filtering). */
static const float POISSON[64] = {
	-0.975402f, -0.0711386f, -0.920347f, -0.41142f, -0.883908f, 0.217872f, -0.884518f, 0.568041f,
	-0.811945f, 0.90521f, -0.792474f, -0.779962f, -0.614856f, 0.386578f, -0.580859f, -0.208777f,
	-0.53795f, 0.716666f, -0.515427f, 0.0899991f, -0.454634f, -0.707938f, -0.420942f, 0.991272f,
	-0.261147f, 0.588488f, -0.211219f, 0.114841f, -0.146336f, -0.259194f, -0.139439f, -0.888668f,
	0.0116886f, 0.326395f, 0.0380566f, 0.625477f, 0.0625935f, -0.50853f, 0.125584f, 0.0469069f,
	0.169469f, -0.997253f, 0.320597f, 0.291055f, 0.359172f, -0.633717f, 0.435713f, -0.250832f,
	0.507797f, -0.916562f, 0.545763f, 0.730216f, 0.56859f, 0.11655f, 0.743156f, -0.505173f,
	0.736442f, -0.189734f, 0.843562f, 0.357036f, 0.865413f, -0.763726f, 0.872005f, 0.0483851f,
};

static VkDeviceSize align_up(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

/* Fills the uniform/storage regions and points the slot's descriptor set at them. */
static enum rnd_result write_params(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                    const struct rnd_camera_plan *cam, const struct rnd_shadow_plan *sp,
                                    struct rnd_error *err)
{
	VkDeviceSize al = ctx->props.limits.minStorageBufferOffsetAlignment;
	if (ctx->props.limits.minUniformBufferOffsetAlignment > al) al = ctx->props.limits.minUniformBufferOffsetAlignment;
	uint32_t nmat = sc->material_count ? sc->material_count : 1;
	uint32_t nlight = sc->light_count ? sc->light_count : 1;
	uint32_t nview = sp->view_count ? sp->view_count : 1;
	VkDeviceSize off_frame = 0;
	VkDeviceSize off_mat = align_up(sizeof(struct umbra_frame), al);
	VkDeviceSize off_light = align_up(off_mat + nmat * sizeof(struct umbra_material), al);
	VkDeviceSize off_view = align_up(off_light + nlight * sizeof(struct umbra_light), al);
	VkDeviceSize total = off_view + nview * sizeof(struct umbra_shadow_view);
	enum rnd_result r = rnd_buffer_reserve(ctx, &s->params, total,
	                                       VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
	                                       "slot params", err);
	if (r != RND_OK) return r;
	uint8_t *base = s->params.map;
	memset(base, 0, total);

	struct umbra_frame *f = (struct umbra_frame *)(base + off_frame);
	memcpy(f->view_proj, cam->view_proj, sizeof f->view_proj);
	memcpy(f->view, cam->view, sizeof f->view);
	memcpy(f->camera_pos, cam->pos, sizeof cam->pos);
	f->camera_pos[3] = cam->ortho ? 1.0f : 0.0f;
	memcpy(f->camera_fwd, cam->fwd, sizeof cam->fwd);
	memcpy(f->background, sc->environment.background, sizeof f->background);
	for (int k = 0; k < 3; k++) {
		f->ambient_sky[k] = sc->environment.ambient_sky[k] * sc->environment.ambient_intensity;
		f->ambient_ground[k] = sc->environment.ambient_ground[k] * sc->environment.ambient_intensity;
	}
	f->params[0] = exp2f(sc->camera.exposure);
	f->params[1] = cam->znear;
	f->params[2] = cam->zfar;
	f->mode[0] = sc->output.tonemap == RND_TONEMAP_ACES ? UMBRA_TONEMAP_ACES
	           : sc->output.tonemap == RND_TONEMAP_NONE ? UMBRA_TONEMAP_NONE : UMBRA_TONEMAP_NEUTRAL;
	switch (sc->output.debug) {
	case RND_DEBUG_SHADOW: f->mode[1] = UMBRA_DEBUG_SHADOW; break;
	case RND_DEBUG_CASCADES: f->mode[1] = UMBRA_DEBUG_CASCADES; break;
	case RND_DEBUG_NORMALS: f->mode[1] = UMBRA_DEBUG_NORMALS; break;
	case RND_DEBUG_DEPTH: f->mode[1] = UMBRA_DEBUG_DEPTH; break;
	default: f->mode[1] = UMBRA_DEBUG_NONE; break;
	}
	f->mode[2] = sc->output.debug_light;
	f->mode[3] = sc->light_count;
	f->mode2[0] = sc->output.pixels == RND_PIXELS_RGBA32F ? 1u : 0u;
	f->mode2[1] = sc->output.transparent ? 1u : 0u;
	memcpy(f->poisson, POISSON, sizeof f->poisson);

	struct umbra_material *m = (struct umbra_material *)(base + off_mat);
	if (!sc->material_count) {
		struct rnd_material d;
		rnd_material_defaults(&d);
		memcpy(m[0].base_color, d.base_color, sizeof d.base_color);
		m[0].emissive[3] = d.roughness;
	}
	for (uint32_t i = 0; i < sc->material_count; i++) {
		const struct rnd_material *in = &sc->materials[i];
		memcpy(m[i].base_color, in->base_color, sizeof in->base_color);
		memcpy(m[i].emissive, in->emissive, sizeof in->emissive);
		m[i].emissive[3] = in->roughness;
		m[i].params[0] = in->metallic;
		m[i].params[1] = in->alpha_cutoff;
	}

	struct umbra_light *l = (struct umbra_light *)(base + off_light);
	for (uint32_t i = 0; i < sc->light_count; i++) {
		const struct rnd_light *in = &sc->lights[i];
		const struct rnd_light_plan *lp = &sp->lights[i];
		for (int k = 0; k < 3; k++) l[i].color[k] = in->color[k] * in->intensity;
		l[i].color[3] = in->type == RND_LIGHT_DIRECTIONAL ? UMBRA_LIGHT_DIRECTIONAL
		              : in->type == RND_LIGHT_SPOT ? UMBRA_LIGHT_SPOT : UMBRA_LIGHT_POINT;
		memcpy(l[i].position, in->position, sizeof in->position);
		l[i].position[3] = in->range;
		float d[3] = {0, -1, 0};
		if (in->type != RND_LIGHT_POINT) rnd_v3_normalize(d, in->direction);
		memcpy(l[i].direction, d, sizeof d);
		l[i].direction[3] = cosf(in->outer_angle);
		l[i].params[0] = cosf(in->inner_angle);
		l[i].params[1] = in->type == RND_LIGHT_DIRECTIONAL ? tanf(in->angular_diameter * 0.5f) : in->radius;
		l[i].shadow[0] = lp->first_view;
		l[i].shadow[1] = lp->view_count;
		l[i].shadow[2] = lp->filter;
		l[i].shadow[3] = lp->pcf_radius;
		l[i].shadow_params[0] = lp->bias_normal;
		l[i].shadow_params[1] = lp->search_texels;
		l[i].shadow_params[2] = in->shadow.blend;
		memcpy(l[i].splits, lp->splits, sizeof lp->splits);
	}
	memcpy(base + off_view, sp->views, sp->view_count * sizeof(struct umbra_shadow_view));

	VkDescriptorBufferInfo bi[4] = {
		{s->params.buf, off_frame, sizeof(struct umbra_frame)},
		{s->params.buf, off_mat, nmat * sizeof(struct umbra_material)},
		{s->params.buf, off_light, nlight * sizeof(struct umbra_light)},
		{s->params.buf, off_view, nview * sizeof(struct umbra_shadow_view)},
	};
	VkDescriptorImageInfo ii = {ctx->pipes.shadow_sampler, s->shadow.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
	VkWriteDescriptorSet w[5];
	for (int i = 0; i < 5; i++) {
		w[i] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->set, .dstBinding = (uint32_t)i,
			.descriptorCount = 1,
			.descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER
			                : i == 4 ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
			.pBufferInfo = i < 4 ? &bi[i] : NULL, .pImageInfo = i == 4 ? &ii : NULL,
		};
	}
	vkUpdateDescriptorSets(ctx->device, 5, w, 0, NULL);
	return RND_OK;
}

static void record_shadows(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                           const struct rnd_shadow_plan *sp, const struct draw *draws, uint32_t ndraw,
                           uint32_t *casters_drawn)
{
	VkCommandBuffer cmd = s->cmd;
	uint32_t layers = s->shadow.layers;
	/* Old contents are never needed: every used layer is cleared. */
	image_barrier(cmd, s->shadow.img, VK_IMAGE_ASPECT_DEPTH_BIT, layers,
	              VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	              VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, 0,
	              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
	uint32_t res = sp->resolution;
	VkDeviceSize zero = 0;
	for (uint32_t v = 0; v < sp->view_count; v++) {
		const struct rnd_light_plan *lp = &sp->lights[sp->view_light[v]];
		VkRenderingAttachmentInfo da = {
			.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = s->shadow_layers[v],
			.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
			.storeOp = VK_ATTACHMENT_STORE_OP_STORE, .clearValue.depthStencil = {1.0f, 0},
		};
		VkRenderingInfo ri = {
			.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = {{0, 0}, {res, res}}, .layerCount = 1,
			.pDepthAttachment = &da,
		};
		vkCmdBeginRendering(cmd, &ri);
		VkViewport vp = {0, 0, (float)res, (float)res, 0, 1};
		VkRect2D scissor = {{0, 0}, {res, res}};
		vkCmdSetViewport(cmd, 0, 1, &vp);
		vkCmdSetScissor(cmd, 0, 1, &scissor);
		vkCmdSetDepthBias(cmd, lp->bias_constant, 0.0f, lp->bias_slope);
		vkCmdBindVertexBuffers(cmd, 0, 1, &s->vertices.buf, &zero);
		vkCmdBindIndexBuffer(cmd, s->indices.buf, 0, VK_INDEX_TYPE_UINT32);
		struct umbra_push push = {0};
		memcpy(push.view_proj, sp->views[v].view_proj, sizeof push.view_proj);
		vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
		                   sizeof push, &push);
		int bound = -1;
		const struct rnd_light *L = &sc->lights[sp->view_light[v]];
		for (uint32_t i = 0; i < ndraw; i++) {
			const struct draw *d = &draws[i];
			if (!d->cast || !d->index_count) continue;
			if (!rnd_aabb_in_frustum(&d->bounds, sp->views[v].view_proj, sp->view_ortho[v])) continue;
			int cull = d->single_sided ||
			           (d->closed && (L->type == RND_LIGHT_DIRECTIONAL || point_outside(L->position, &d->bounds, 0.05f)));
			if (bound != cull) {
				vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx->pipes.shadow[cull]);
				bound = cull;
			}
			vkCmdDrawIndexed(cmd, d->index_count, 1, d->first_index, 0, 0);
			(*casters_drawn)++;
		}
		vkCmdEndRendering(cmd);
	}
	image_barrier(cmd, s->shadow.img, VK_IMAGE_ASPECT_DEPTH_BIT, layers,
	              sp->view_count ? VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_UNDEFINED,
	              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
	              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
	              VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

/* The specialization key of this scene's main pass (see mesh.frag). */
static void main_key(const struct rnd_scene *sc, const struct rnd_shadow_plan *sp, const struct draw *draws,
                     uint32_t ndraw, struct rnd_main_key *k)
{
	memset(k, 0, sizeof *k);
	k->format = (uint32_t)sc->output.pixels;
	k->samples = sc->output.msaa > 1 ? 4 : 1;
	for (uint32_t i = 0; i < sc->light_count; i++) {
		const struct rnd_light_plan *lp = &sp->lights[i];
		uint32_t type = sc->lights[i].type == RND_LIGHT_DIRECTIONAL ? UMBRA_LIGHT_DIRECTIONAL
		              : sc->lights[i].type == RND_LIGHT_SPOT ? UMBRA_LIGHT_SPOT : UMBRA_LIGHT_POINT;
		k->sc[UMBRA_SC_LIGHT_TYPES] |= 1u << type;
		if (lp->view_count) k->sc[UMBRA_SC_FILTERS] |= 1u << lp->filter;
		if (type == UMBRA_LIGHT_DIRECTIONAL && lp->view_count > 1) k->sc[UMBRA_SC_CASCADES] = 1;
	}
	switch (sc->output.debug) {
	case RND_DEBUG_SHADOW: k->sc[UMBRA_SC_DEBUG] = UMBRA_DEBUG_SHADOW; break;
	case RND_DEBUG_CASCADES: k->sc[UMBRA_SC_DEBUG] = UMBRA_DEBUG_CASCADES; break;
	case RND_DEBUG_NORMALS: k->sc[UMBRA_SC_DEBUG] = UMBRA_DEBUG_NORMALS; break;
	case RND_DEBUG_DEPTH: k->sc[UMBRA_SC_DEBUG] = UMBRA_DEBUG_DEPTH; break;
	default: break;
	}
	k->sc[UMBRA_SC_LINEAR] = sc->output.pixels == RND_PIXELS_RGBA32F;
	k->sc[UMBRA_SC_TONEMAP] = k->sc[UMBRA_SC_LINEAR] ? 0
	                        : sc->output.tonemap == RND_TONEMAP_ACES ? UMBRA_TONEMAP_ACES
	                        : sc->output.tonemap == RND_TONEMAP_NONE ? UMBRA_TONEMAP_NONE : UMBRA_TONEMAP_NEUTRAL;
	for (uint32_t i = 0; i < ndraw; i++)
		if (draws[i].flags & UMBRA_DRAW_SHADOW_CATCHER) k->sc[UMBRA_SC_CATCHER] = 1;
}

static enum rnd_result record_main(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                   const struct rnd_shadow_plan *sp, const struct draw *draws, uint32_t ndraw,
                                   struct rnd_error *err)
{
	struct rnd_main_key key;
	VkPipeline pipes[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
	main_key(sc, sp, draws, ndraw, &key);
	for (uint32_t i = 0; i < ndraw; i++) {
		uint32_t c = draws[i].cull_back;
		if (!draws[i].index_count || pipes[c]) continue;
		key.cull_back = c;
		enum rnd_result r = rnd_pipelines_main(ctx, &key, &pipes[c], err);
		if (r != RND_OK) return r;
	}
	VkCommandBuffer cmd = s->cmd;
	uint32_t w = sc->width, h = sc->height;
	bool ms = sc->output.msaa > 1;
	VkImage target = ms ? s->color_ms.img : s->resolve.img;
	image_barrier(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0,
	              VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
	if (ms)
		image_barrier(cmd, s->resolve.img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
		              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0,
		              VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
	image_barrier(cmd, s->depth.img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
	              VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, 0,
	              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);

	/* The background is the requested colour itself (sRGB-encoded for display outputs), not
	 * tone mapped: a caller asking for white gets 255. */
	VkClearColorValue clear;
	const float *bg = sc->environment.background;
	bool linear = sc->output.pixels == RND_PIXELS_RGBA32F;
	for (int k = 0; k < 3; k++) clear.float32[k] = linear ? bg[k] : srgb_encode(bg[k]);
	clear.float32[3] = sc->output.transparent ? 0.0f : bg[3];
	if (sc->output.debug == RND_DEBUG_SHADOW) clear.float32[0] = clear.float32[1] = clear.float32[2] = clear.float32[3] = 1.0f;

	VkRenderingAttachmentInfo ca = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = ms ? s->color_ms.view : s->resolve.view,
		.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
		.resolveMode = ms ? VK_RESOLVE_MODE_AVERAGE_BIT : VK_RESOLVE_MODE_NONE,
		.resolveImageView = ms ? s->resolve.view : VK_NULL_HANDLE,
		.resolveImageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
		.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
		.storeOp = ms ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE,
		.clearValue.color = clear,
	};
	VkRenderingAttachmentInfo da = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, .imageView = s->depth.view,
		.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
		.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE, .clearValue.depthStencil = {0.0f, 0}, /* reversed Z */
	};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = {{0, 0}, {w, h}}, .layerCount = 1,
		.colorAttachmentCount = 1, .pColorAttachments = &ca, .pDepthAttachment = &da,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)w, (float)h, 0, 1};
	VkRect2D scissor = {{0, 0}, {w, h}};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &scissor);
	VkDeviceSize zero = 0;
	vkCmdBindVertexBuffers(cmd, 0, 1, &s->vertices.buf, &zero);
	vkCmdBindIndexBuffer(cmd, s->indices.buf, 0, VK_INDEX_TYPE_UINT32);
	vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx->pipes.layout, 0, 1, &s->set, 0, NULL);
	VkPipeline bound = VK_NULL_HANDLE;
	for (uint32_t i = 0; i < ndraw; i++) {
		const struct draw *d = &draws[i];
		if (!d->index_count) continue;
		VkPipeline p = ctx->pipes.prepass[ms][d->cull_back];
		if (p != bound) { vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p); bound = p; }
		vkCmdDrawIndexed(cmd, d->index_count, 1, d->first_index, 0, 0);
	}
	for (uint32_t i = 0; i < ndraw; i++) {
		const struct draw *d = &draws[i];
		if (!d->index_count) continue;
		VkPipeline p = pipes[d->cull_back];
		if (p != bound) { vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p); bound = p; }
		struct umbra_push push = {.info = {d->material, d->flags, 0, 0}};
		vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
		                   sizeof push, &push);
		vkCmdDrawIndexed(cmd, d->index_count, 1, d->first_index, 0, 0);
	}
	vkCmdEndRendering(cmd);
	return RND_OK;
}

static void record_readback(struct rnd_slot *s, const struct rnd_scene *sc)
{
	VkCommandBuffer cmd = s->cmd;
	image_barrier(cmd, s->resolve.img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
	              VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
	              VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
	VkBufferImageCopy region = {
		.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, .imageExtent = {sc->width, sc->height, 1},
	};
	vkCmdCopyImageToBuffer(cmd, s->resolve.img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s->readback.buf, 1, &region);
	VkBufferMemoryBarrier2 bb = {
		.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_TRANSFER_BIT,
		.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT, .dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT,
		.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT, .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
		.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .buffer = s->readback.buf, .size = VK_WHOLE_SIZE,
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .bufferMemoryBarrierCount = 1, .pBufferMemoryBarriers = &bb};
	vkCmdPipelineBarrier2(cmd, &di);
}

static size_t pixel_size(enum rnd_pixel_format f)
{
	return f == RND_PIXELS_RGBA8 ? 4 : f == RND_PIXELS_RGBA16 ? 8 : 16;
}

/* Tessellates every object into the slot's buffers; fills draws and the scene bounds. */
static enum rnd_result upload(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                              struct draw *draws, struct rnd_aabb *bounds, struct rnd_error *err)
{
	uint64_t nv = 0, ni = 0;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		uint32_t v, x;
		rnd_mesh_counts(&sc->objects[i], &v, &x);
		nv += v; ni += x;
	}
	if (nv > UINT32_MAX || ni > UINT32_MAX)
		return rnd_fail(err, RND_ERR_LIMIT, "scene too large: %llu vertices, %llu indices",
		                (unsigned long long)nv, (unsigned long long)ni);
	enum rnd_result r;
	VkDeviceSize vbytes = (nv ? nv : 1) * sizeof(struct rnd_vertex), ibytes = (ni ? ni : 1) * sizeof(uint32_t);
	if ((r = rnd_buffer_reserve(ctx, &s->vertices, vbytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "slot vertices", err)) != RND_OK)
		return r;
	if ((r = rnd_buffer_reserve(ctx, &s->indices, ibytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, "slot indices", err)) != RND_OK)
		return r;
	struct rnd_vertex *vtx = s->vertices.map;
	uint32_t *idx = s->indices.map;
	uint32_t vbase = 0, ibase = 0;
	rnd_aabb_empty(bounds);
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		struct draw *d = &draws[i];
		uint32_t v, x;
		rnd_mesh_counts(o, &v, &x);
		rnd_aabb_empty(&d->bounds);
		if ((r = rnd_mesh_write(o, vtx + vbase, idx + ibase, vbase, &d->bounds, err)) != RND_OK) {
			char m[sizeof err->msg];
			snprintf(m, sizeof m, "%s", err->msg);
			return rnd_fail(err, r, "object %u: %s", i, m);
		}
		d->first_index = ibase;
		d->index_count = x;
		d->material = sc->material_count ? o->material : 0;
		bool catcher = sc->material_count && sc->materials[o->material].shadow_catcher;
		d->flags = (o->receive_shadows ? UMBRA_DRAW_RECEIVE_SHADOWS : 0) | (catcher ? UMBRA_DRAW_SHADOW_CATCHER : 0);
		/* A shadow catcher receives shadows and casts none (contract §7). */
		d->cast = o->cast_shadows && !catcher;
		d->single_sided = !o->double_sided;
		d->closed = o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_BOX || o->shape == RND_SHAPE_CYLINDER;
		d->cull_back = d->single_sided;
		rnd_aabb_union(bounds, &d->bounds);
		vbase += v; ibase += x;
	}
	return RND_OK;
}

enum rnd_result rnd_render(struct rnd_context *ctx, const struct rnd_scene *sc, struct rnd_image *out,
                           struct rnd_timings *timings, struct rnd_error *err)
{
	enum rnd_result r;
	VkResult vr;
	struct rnd_timings tm = {0};
	memset(out, 0, sizeof *out);
	if (err) memset(err, 0, sizeof *err);
	if (__atomic_load_n(&ctx->failed, __ATOMIC_RELAXED))
		return rnd_fail(err, RND_ERR_DEVICE_LOST, "the Vulkan device was lost earlier; the context must be recreated");
	if ((r = validate(ctx, sc, err)) != RND_OK) return r;

	/* Per-request memory: one block for the draw list and the shadow plan. */
	size_t draws_bytes = (sc->object_count ? sc->object_count : 1) * sizeof(struct draw);
	void *arena = malloc(draws_bytes + sizeof(struct rnd_shadow_plan));
	if (!arena) return rnd_fail(err, RND_ERR_OOM, "out of memory for %u objects", sc->object_count);
	struct draw *draws = arena;
	struct rnd_shadow_plan *sp = (struct rnd_shadow_plan *)((char *)arena + draws_bytes);

	struct rnd_slot *s = rnd_slot_acquire(ctx);
	double t0 = now_ms();
	struct rnd_aabb bounds;
	struct rnd_camera_plan cam;
	if ((r = upload(ctx, s, sc, draws, &bounds, err)) != RND_OK) goto done;
	tm.upload_ms = now_ms() - t0;
	if ((r = rnd_camera_plan(&sc->camera, sc->width, sc->height, &bounds, &cam, err)) != RND_OK) goto done;
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (draws[i].closed && !draws[i].single_sided) draws[i].cull_back = camera_outside(&cam, &draws[i].bounds);
	if ((r = rnd_shadow_plan(sc, &bounds, &cam, sp, err)) != RND_OK) goto done;
	uint32_t layers = sp->view_count ? sp->view_count : 1;
	uint32_t res = sp->view_count ? sp->resolution : (s->shadow.img ? s->shadow.width : 64);
	if ((r = rnd_slot_shadow(ctx, s, res, layers, err)) != RND_OK) goto done;
	VkFormat fmt = ctx->color_formats[sc->output.pixels];
	if ((r = rnd_slot_targets(ctx, s, fmt, sc->width, sc->height, sc->output.msaa, err)) != RND_OK) goto done;
	size_t px = pixel_size(sc->output.pixels);
	VkDeviceSize rb = (VkDeviceSize)sc->width * sc->height * px;
	if ((r = rnd_buffer_reserve(ctx, &s->readback, rb, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "slot readback", err)) != RND_OK)
		goto done;
	if ((r = write_params(ctx, s, sc, &cam, sp, err)) != RND_OK) goto done;

	if ((vr = vkResetCommandBuffer(s->cmd, 0)) != VK_SUCCESS) { r = rnd_fail_vk(err, vr, "vkResetCommandBuffer"); goto done; }
	VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
	if ((vr = vkBeginCommandBuffer(s->cmd, &bi)) != VK_SUCCESS) { r = rnd_fail_vk(err, vr, "vkBeginCommandBuffer"); goto done; }
	if (s->queries) {
		vkCmdResetQueryPool(s->cmd, s->queries, 0, RND_TS_COUNT);
		vkCmdWriteTimestamp2(s->cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, s->queries, RND_TS_START);
	}
	uint32_t casters = 0;
	record_shadows(ctx, s, sc, sp, draws, sc->object_count, &casters);
	if (s->queries) vkCmdWriteTimestamp2(s->cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, s->queries, RND_TS_SHADOW_END);
	if ((r = record_main(ctx, s, sc, sp, draws, sc->object_count, err)) != RND_OK) {
		vkEndCommandBuffer(s->cmd);
		goto done;
	}
	if (s->queries) vkCmdWriteTimestamp2(s->cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, s->queries, RND_TS_MAIN_END);
	record_readback(s, sc);
	if (s->queries) vkCmdWriteTimestamp2(s->cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, s->queries, RND_TS_COPY_END);
	if ((vr = vkEndCommandBuffer(s->cmd)) != VK_SUCCESS) { r = rnd_fail_vk(err, vr, "vkEndCommandBuffer"); goto done; }

	double t_submit = now_ms();
	VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &s->cmd};
	pthread_mutex_lock(&ctx->queue_mu);
	vr = vkQueueSubmit(ctx->queue, 1, &si, s->fence);
	pthread_mutex_unlock(&ctx->queue_mu);
	if (vr != VK_SUCCESS) { r = rnd_fail_vk(err, vr, "vkQueueSubmit"); goto lost_check; }
	vr = vkWaitForFences(ctx->device, 1, &s->fence, VK_TRUE, RND_FENCE_TIMEOUT_NS);
	if (vr != VK_SUCCESS) {
		/* A render that does not finish in minutes means a hung or lost device. */
		r = rnd_fail_vk(err, vr == VK_TIMEOUT ? VK_ERROR_DEVICE_LOST : vr, "vkWaitForFences (render)");
		goto lost_check;
	}
	vkResetFences(ctx->device, 1, &s->fence);
	double t_done = now_ms();

	if (s->queries) {
		uint64_t ts[RND_TS_COUNT];
		if (vkGetQueryPoolResults(ctx->device, s->queries, 0, RND_TS_COUNT, sizeof ts, ts, sizeof ts[0],
		                          VK_QUERY_RESULT_64_BIT) == VK_SUCCESS) {
			double k = ctx->timestamp_period / 1e6;
			tm.shadow_ms = (double)(ts[RND_TS_SHADOW_END] - ts[RND_TS_START]) * k;
			tm.main_ms = (double)(ts[RND_TS_MAIN_END] - ts[RND_TS_SHADOW_END]) * k;
			tm.readback_ms = (double)(ts[RND_TS_COPY_END] - ts[RND_TS_MAIN_END]) * k;
		}
	} else {
		tm.main_ms = t_done - t_submit;
	}
	tm.shadow_maps_rendered = sp->view_count;

	double t_copy = now_ms();
	out->pixels = malloc(rb);
	if (!out->pixels) { r = rnd_fail(err, RND_ERR_OOM, "out of memory for a %ux%u image", sc->width, sc->height); goto done; }
	memcpy(out->pixels, s->readback.map, rb);
	out->width = sc->width;
	out->height = sc->height;
	out->format = sc->output.pixels;
	out->stride = sc->width * px;
	tm.readback_ms += now_ms() - t_copy;
	r = RND_OK;
	goto done;

lost_check:
	if (r == RND_ERR_DEVICE_LOST) {
		__atomic_store_n(&ctx->failed, 1, __ATOMIC_RELAXED);
		rnd_log(ctx, 0, "device lost: %s", err ? err->msg : "");
	}
done:
	rnd_slot_release(ctx, s);
	free(arena);
	if (timings) *timings = tm;
	return r;
}
