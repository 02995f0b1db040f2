/*
 * renderer/env_pass.c — the environment pass (see env_pass.h).
 *
 * Why: the environment's shadows are a PCSS lookup per shadow direction, a dozen per pixel. In
 * the main pass they ran for every fragment of every triangle lavapipe shades (whole 4x4 blocks
 * per triangle, MSAA), and cost more than the rest of a thumbnail's render together (the spot
 * OBJ under the studio at 256²: main pass 85 ms without, ~230 ms with 12 directions). Soft
 * shadows of the whole sky vary slowly, so they are computed once per texel of a grid half the
 * view's size a side (a quarter of its pixels): the view's surfaces drawn there (visibility.c's
 * surfaces pass at that scale), a fullscreen pass of shaders/env_vis.frag, and the main pass
 * reads the four texels around each fragment, weighed by how well their surface agrees with it.
 * Where no texel's surface does (a surface thinner than a texel) it takes their plain mean.
 */
#include <stdlib.h>
#include <string.h>
#include "env.h"
#include "env_pass.h"
#include "visibility.h"

#define ENV_VIS_FORMAT VK_FORMAT_R16_UNORM

uint32_t rnd_env_pass_scale(uint32_t w, uint32_t h)
{
	uint32_t side = w > h ? w : h, s = (side + RND_ENV_PASS_GRID - 1) / RND_ENV_PASS_GRID;
	return s < UMBRA_ENV_PASS_SCALE ? UMBRA_ENV_PASS_SCALE : s > RND_ENV_PASS_MAX_SCALE ? RND_ENV_PASS_MAX_SCALE : s;
}

void rnd_env_pass_size(uint32_t w, uint32_t h, uint32_t *pw, uint32_t *ph)
{
	uint32_t s = rnd_env_pass_scale(w, h);
	*pw = (w + s - 1) / s;
	*ph = (h + s - 1) / s;
}

void rnd_env_pass_release(struct rnd_context *ctx, struct rnd_slot *s)
{
	s->env_pass_key = 0;
	rnd_image_destroy(ctx, &s->env_surfaces);
	rnd_image_destroy(ctx, &s->env_normals);
	rnd_image_destroy(ctx, &s->env_depth);
	rnd_image_destroy(ctx, &s->env_vis);
}

enum rnd_result rnd_slot_env_pass(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h,
                                  struct rnd_error *err)
{
	uint32_t pw, ph;
	rnd_env_pass_size(w, h, &pw, &ph);
	if (s->env_vis.img && s->env_vis.width == pw && s->env_vis.height == ph) return RND_OK;
	rnd_env_pass_release(ctx, s);
	static const char *const what[4] = {"positions", "normals", "depth", "visibility"};
	const VkFormat formats[4] = {RND_SURFACES_FORMAT, RND_SURFACE_NORMALS_FORMAT, RND_DEPTH_FORMAT, ENV_VIS_FORMAT};
	struct rnd_image_res *img[4] = {&s->env_surfaces, &s->env_normals, &s->env_depth, &s->env_vis};
	for (int i = 0; i < 4; i++) {
		char name[48];
		snprintf(name, sizeof name, "slot %u environment %s", s->index, what[i]);
		bool depth = i == 2;
		VkImageUsageFlags usage = depth ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT
		                                : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
		enum rnd_result r = rnd_image_create(ctx, formats[i], pw, ph, 1, 1, usage,
		                                     depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT, name, img[i], err);
		if (r != RND_OK) {
			rnd_env_pass_release(ctx, s);
			return r;
		}
	}
	return RND_OK;
}

uint64_t rnd_env_pass_key(const struct rnd_slot *s, const struct record_view *rv, const uint64_t *map_keys,
                          uint32_t nmaps, uint64_t vertex_bytes, uint64_t index_bytes)
{
	uint32_t size[3];
	rnd_env_pass_size(rv->sc->width, rv->sc->height, &size[0], &size[1]);
	size[2] = rnd_env_pass_scale(rv->sc->width, rv->sc->height);
	uint64_t h = rnd_hash(0x656e762070617373ull, size, sizeof size);
	h = rnd_hash(h, s->params.map, (size_t)s->params_used);
	h = rnd_hash(h, map_keys, nmaps * sizeof *map_keys);
	h = rnd_hash(h, rv->draws, rv->ndraw * sizeof *rv->draws);
	h = rnd_hash(h, s->vertices.cpu, (size_t)vertex_bytes);
	h = rnd_hash(h, s->indices.cpu, (size_t)index_bytes);
	return h ? h : 1;
}

/* The visibility over the whole grid into env_vis, from the surfaces just drawn. */
static void record_vis(struct rnd_context *ctx, struct rnd_slot *s, VkPipeline pipe, uint32_t pw, uint32_t ph)
{
	VkCommandBuffer cmd = s->cmd;
	VkRenderingAttachmentInfo ca = record_color_overwrite(cmd, &s->env_vis, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
	VkRect2D area = {{0, 0}, {pw, ph}};
	VkRenderingInfo ri = {
		.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = area, .layerCount = 1,
		.colorAttachmentCount = 1, .pColorAttachments = &ca,
	};
	vkCmdBeginRendering(cmd, &ri);
	VkViewport vp = {0, 0, (float)pw, (float)ph, 0, 1};
	vkCmdSetViewport(cmd, 0, 1, &vp);
	vkCmdSetScissor(cmd, 0, 1, &area);
	record_bind_geometry(ctx, s);
	vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
	vkCmdDraw(cmd, 3, 1, 0, 0);
	vkCmdEndRendering(cmd);
	record_color_to_sampled(cmd, s->env_vis.img);
}

enum rnd_result record_env_pass(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                struct rnd_error *err)
{
	/* Only what the lookups need shapes the pass: sun-only light types, the environment's
	 * shadows; every other constant zeroed so that scenes share one variant. */
	struct rnd_main_key key;
	memset(&key, 0, sizeof key);
	key.env_pass = 1;
	key.samples = 1;
	key.sc[UMBRA_SC_LIGHT_TYPES] = 1u << UMBRA_LIGHT_DIRECTIONAL;
	key.sc[UMBRA_SC_ENV] = UMBRA_ENV_LIGHT | UMBRA_ENV_SHADOWS;
	VkPipeline pipe;
	enum rnd_result r = rnd_pipelines_main(ctx, &key, &pipe, err);
	if (r != RND_OK) return r;
	uint32_t pw, ph;
	rnd_env_pass_size(rv->sc->width, rv->sc->height, &pw, &ph);
	/* The surfaces: the view's projection over a viewport of 1 / scale of the view's size (a
	 * fraction of a texel beyond it where the scale does not divide the size), so that texel
	 * t's centre is at the view's (t + 0.5) scale, as env_pass_read reads it. */
	float scale = (float)rnd_env_pass_scale(rv->sc->width, rv->sc->height);
	struct rnd_surface_targets grid = {&s->env_surfaces, &s->env_normals, &s->env_depth, (float)rv->sc->width / scale,
	                                   (float)rv->sc->height / scale};
	record_surfaces(ctx, s, rv, (VkRect2D){{0, 0}, {pw, ph}}, &grid);
	record_vis(ctx, s, pipe, pw, ph);
	return RND_OK;
}
