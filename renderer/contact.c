/*
 * renderer/contact.c — contact shadows (contract §3 `shadows.contact`): which lights march them,
 * their parameters, and the camera-view depth they march against.
 *
 * The fragment shaders (contact.glsl contact_visibility, in mesh.frag and aov.frag) walk from
 * the shaded point towards each light that asks for them, through this depth, and take the
 * smaller of the march's and the shadow map's visibility. The depth is a single-sample pass
 * of the view drawn once per view before the main pass (and before any band of it), with the
 * depth-only shadow pipelines, so contact shadows add no pipeline of their own beyond the
 * main/AOV variant with SC_CONTACT set: those pipelines store 0 near .. 1 far, so the camera's
 * reversed-Z view-projection is pushed with z flipped (z' = w - z) and the shader reads
 * 1 - depth. Renders without contact shadows record nothing here and bind a stand-in texture.
 */
#include <string.h>
#include "contact.h"
#include "record.h"

bool rnd_contact_on(const struct rnd_scene *sc, const struct rnd_shadow_plan *sp, uint32_t i)
{
	/* The atlas debug view draws no scene: nothing to march against. A light without shadow
	 * views (shadows off) gets no contact shadows either: the contract's `enabled: false`
	 * turns the light's shadows off as a whole. */
	return sc->output.debug != RND_DEBUG_ATLAS && sc->lights[i].shadow.contact_enabled &&
	       sc->lights[i].shadow.enabled && sp->lights[i].view_count > 0;
}

bool rnd_contact_any(const struct rnd_scene *sc, const struct rnd_shadow_plan *sp)
{
	for (uint32_t i = 0; i < sc->light_count; i++)
		if (rnd_contact_on(sc, sp, i)) return true;
	return false;
}

void rnd_contact_params(const struct rnd_shadow *sh, float out[4])
{
	/* 0 distance / thickness = the shader's defaults: 8 texels of the light's map at the
	 * point, 2 pixels' world size at the point (see contact.glsl contact_visibility). */
	out[0] = sh->contact_distance;
	out[1] = (float)(sh->contact_steps ? sh->contact_steps : 16);
	out[2] = sh->contact_thickness;
	out[3] = 1.0f;
}

void record_scene_depth(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv)
{
	VkCommandBuffer cmd = s->cmd;
	uint32_t w = rv->sc->width, h = rv->sc->height;
	record_begin_depth(cmd, s->scene_depth.img, s->scene_depth.view, w, h, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                   VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
	vkCmdSetDepthBias(cmd, 0.0f, 0.0f, 0.0f);
	record_bind_geometry(ctx, s);
	/* z' = w - z: the reversed-Z camera as the shadow pipelines' near-0 depth. */
	struct umbra_push push = {0};
	const float *m = rv->cam->view_proj;
	memcpy(push.view_proj, m, sizeof push.view_proj);
	for (int c = 0; c < 4; c++) push.view_proj[4 * c + 2] = m[4 * c + 3] - m[4 * c + 2];
	vkCmdPushConstants(cmd, ctx->pipes.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
	                   sizeof push, &push);
	VkPipeline bound = VK_NULL_HANDLE;
	for (uint32_t i = 0; i < rv->ndraw; i++) {
		const struct draw *d = &rv->draws[i];
		/* What the camera sees: shadow catchers and non-casters occlude contact rays too only
		 * when they are drawn, which every drawn object is. */
		if (!d->index_count) continue;
		record_depth_draw(ctx, s, d, d->cull_back, &push, &bound);
	}
	vkCmdEndRendering(cmd);
	record_image_barrier(cmd, s->scene_depth.img, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
	                     VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL,
	                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
	                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
	                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}
