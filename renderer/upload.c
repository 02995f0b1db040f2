/*
 * renderer/upload.c — the scene's geometry into the slot (see upload.h): every object
 * tessellated (at its level of detail) straight into the slot's mapped vertex and index
 * buffers, where the plan's draws say (render_plan.c made them: ranges, bounds, material,
 * flags, culling); and the recorded copy of the staged textures into their images
 * (record_textures).
 */
#include <stdio.h>
#include <string.h>
#include "caster_level.h"
#include "lod.h"
#include "mesh.h"
#include "proxy.h"
#include "texture.h"
#include "upload.h"

/* The slot's second-uv-set buffer, reserved (nv float2) only when an object of the scene has
 * one: a scene without keeps its memory and binds the vertices there (record.c). */
static enum rnd_result reserve_uv1(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc, uint64_t nv,
                                   struct rnd_error *err)
{
	s->has_uv1 = false;
	for (uint32_t i = 0; i < sc->object_count && !s->has_uv1; i++)
		s->has_uv1 = sc->objects[i].shape == RND_SHAPE_MESH && sc->objects[i].uvs1;
	if (!s->has_uv1) return RND_OK;
	return rnd_buffer_reserve(ctx, &s->uvs1, (nv ? nv : 1) * 8, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "slot uvs1", err);
}

/* Object i at its draw's place: copied where the plan kept it, else written (the plan checked
 * its arrays and measured its bounds: rnd_mesh_write_measured). */
static enum rnd_result write_object(const struct rnd_plan *plan, uint32_t i, struct rnd_vertex *vtx, uint32_t *idx,
                                    float *uv1, struct rnd_error *err)
{
	struct rnd_object o = plan->sc->objects[i];
	const struct draw *d = &plan->draws[i];
	rnd_lod_apply(&o, plan->lod[i]); /* renderer/lod.h: no finer than the output can show */
	if (plan->kept_vertices[i]) {
		/* written by the plan as rnd_mesh_write writes it at base 0: its indices moved to base */
		memcpy(vtx + d->first_vertex, plan->kept_vertices[i], (size_t)d->vertex_count * sizeof *vtx);
		for (uint32_t k = 0; k < d->index_count; k++) idx[d->first_index + k] = plan->kept_indices[i][k] + d->first_vertex;
	} else {
		enum rnd_result r = rnd_mesh_write_measured(&o, vtx + d->first_vertex, idx + d->first_index, d->first_vertex, err);
		if (r != RND_OK) {
			char m[sizeof err->msg];
			snprintf(m, sizeof m, "%s", err->msg);
			return rnd_fail(err, r, "object %u: %s", i, m);
		}
	}
	if (uv1) rnd_mesh_write_uv1(&o, vtx + d->first_vertex, d->vertex_count, uv1 + 2 * (size_t)d->first_vertex);
	return RND_OK;
}

enum rnd_result rnd_upload_scene(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_plan *plan,
                                 const struct rnd_pacer *pacer, struct rnd_error *err)
{
	const struct rnd_scene *sc = plan->sc;
	uint64_t nv = plan->vertices, ni = plan->indices;
	enum rnd_result r;
	VkDeviceSize vbytes = (nv ? nv : 1) * sizeof(struct rnd_vertex), ibytes = (ni ? ni : 1) * sizeof(uint32_t);
	if ((r = rnd_buffer_reserve(ctx, &s->vertices, vbytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "slot vertices", err)) != RND_OK)
		return r;
	if ((r = rnd_buffer_reserve(ctx, &s->indices, ibytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, "slot indices", err)) != RND_OK)
		return r;
	if ((r = reserve_uv1(ctx, s, sc, nv, err)) != RND_OK) return r;
	/* Written and read back (transforms, areas) in `cpu`: memory.c says why not in the mapping. */
	float *uv1 = s->has_uv1 ? s->uvs1.cpu : NULL;
	struct rnd_vertex *vtx = s->vertices.cpu;
	uint32_t *idx = s->indices.cpu;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		/* Tessellating millions of triangles takes seconds: the deadline holds here too. */
		if (((i & 15) == 0 || plan->draws[i].index_count > (1u << 20)) && (r = rnd_pacer_check(pacer, err)) != RND_OK)
			return r;
		if ((r = write_object(plan, i, vtx, idx, uv1, err)) != RND_OK) return r;
	}
	/* The camera's proxies of spheres, after every mesh (plan_layout). */
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct draw *d = &plan->draws[i];
		uint32_t v, x;
		rnd_proxy_counts(&plan->proxies[i], &v, &x);
		if (!x) continue;
		rnd_proxy_write(&plan->proxies[i], vtx + d->cam_first_vertex, idx + d->cam_first_index, d->cam_first_vertex);
		if (uv1) memset(uv1 + 2 * (size_t)d->cam_first_vertex, 0, (size_t)v * 8);   /* a sphere's proxy: no texture uvs */
	}
	/* The environment's maps' caster levels, after the proxies (caster_level.h). */
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct draw *d = &plan->draws[i];
		if (!d->env_index_count) continue;
		rnd_caster_write(&sc->objects[i], vtx + d->env_first_vertex, idx + d->env_first_index, d->env_first_vertex);
		if (uv1) memset(uv1 + 2 * (size_t)d->env_first_vertex, 0, (size_t)d->env_vertex_count * 8);
	}
	rnd_buffer_publish(&s->vertices, 0, (VkDeviceSize)nv * sizeof(struct rnd_vertex));
	rnd_buffer_publish(&s->indices, 0, (VkDeviceSize)ni * sizeof(uint32_t));
	if (uv1) rnd_buffer_publish(&s->uvs1, 0, (VkDeviceSize)nv * 8);
	return RND_OK;
}

void record_textures(struct rnd_slot *s, const struct rnd_texture *const *tex, uint32_t n)
{
	VkCommandBuffer cmd = s->cmd;
	VkDeviceSize off = 0;
	if (!s->white_ready) {   /* set by render.c once this command buffer has run */
		/* The slot's 1x1 white texture, bound for untextured draws. */
		record_image_barrier(cmd, s->white.img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
		                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
		                     VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
		record_image_barrier(cmd, s->white_cube.img, VK_IMAGE_ASPECT_COLOR_BIT, 6, VK_IMAGE_LAYOUT_UNDEFINED,
		                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
		                     VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
		VkClearColorValue white = {{1.0f, 1.0f, 1.0f, 1.0f}};
		VkImageSubresourceRange range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1}, cube = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 6};
		vkCmdClearColorImage(cmd, s->white.img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &white, 1, &range);
		vkCmdClearColorImage(cmd, s->white_cube.img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &white, 1, &cube);
		record_image_barrier(cmd, s->white.img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
		                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
		                     VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
		                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
		record_image_barrier(cmd, s->white_cube.img, VK_IMAGE_ASPECT_COLOR_BIT, 6, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
		                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
		                     VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
		                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
	}
	for (uint32_t i = 0; i < n; i++)   /* each image's full mip chain, staged by material.c */
		off += rnd_texture_record_upload(cmd, s->staging.buf, off, s->textures[i].img, tex[i]->width, tex[i]->height);
}
