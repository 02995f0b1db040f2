/*
 * renderer/upload.c — the scene's geometry into the slot (see upload.h): every object
 * tessellated (at its level of detail) straight into the slot's mapped vertex and index
 * buffers, with its draw: ranges, bounds, material, flags, culling; and the recorded copy of
 * the staged textures into their images (record_textures).
 */
#include <stdio.h>
#include <string.h>
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

enum rnd_result rnd_upload_scene(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                 const struct rnd_pacer *pacer, const uint32_t *lod, const struct rnd_proxy *proxies,
                                 struct draw *draws, struct rnd_aabb *bounds, struct rnd_error *err)
{
	uint64_t nv = 0, ni = 0;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		uint32_t v, x;
		struct rnd_object o = sc->objects[i];
		rnd_lod_apply(&o, lod[i]); /* renderer/lod.h: no finer than the output can show */
		rnd_mesh_counts(&o, &v, &x);
		nv += v; ni += x;
		rnd_proxy_counts(&proxies[i], &v, &x);
		nv += v; ni += x;
	}
	if (nv > UINT32_MAX || ni > UINT32_MAX)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_OBJECTS, 0, "scene too large: %llu vertices, %llu indices",
		                (unsigned long long)nv, (unsigned long long)ni);
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
	uint32_t vbase = 0, ibase = 0;
	rnd_aabb_empty(bounds);
	for (uint32_t i = 0; i < sc->object_count; i++) {
		struct rnd_object lo = sc->objects[i];
		rnd_lod_apply(&lo, lod[i]);
		const struct rnd_object *o = &lo;
		struct draw *d = &draws[i];
		uint32_t v, x;
		rnd_mesh_counts(o, &v, &x);
		/* Tessellating millions of triangles takes seconds: the deadline holds here too. */
		if (((i & 15) == 0 || x > (1u << 20)) && (r = rnd_pacer_check(pacer, err)) != RND_OK) return r;
		rnd_aabb_empty(&d->bounds);
		if ((r = rnd_mesh_write(o, vtx + vbase, idx + ibase, vbase, &d->bounds, err)) != RND_OK) {
			char m[sizeof err->msg];
			snprintf(m, sizeof m, "%s", err->msg);
			return rnd_fail(err, r, "object %u: %s", i, m);
		}
		if (uv1) rnd_mesh_write_uv1(o, vtx + vbase, v, uv1 + 2 * (size_t)vbase);
		d->area = rnd_mesh_area(vtx, idx + ibase, x);
		d->first_index = d->cam_first_index = ibase;
		d->index_count = d->cam_index_count = x;
		d->first_vertex = vbase;
		d->vertex_count = v;
		vbase += v; ibase += x;
		bool proxy = proxies[i].outline > 0;
		d->material = sc->material_count ? o->material : 0;
		bool catcher = sc->material_count && sc->materials[o->material].shadow_catcher;
		d->flags = (o->receive_shadows ? UMBRA_DRAW_RECEIVE_SHADOWS : 0) | (catcher ? UMBRA_DRAW_SHADOW_CATCHER : 0) |
		           (proxy ? UMBRA_DRAW_SPHERE : 0);
		/* A shadow catcher receives shadows and casts none (contract §7). */
		d->cast = o->cast_shadows && !catcher;
		/* MASK and dithered BLEND both take the alpha-tested depth passes. */
		d->masked = sc->material_count && sc->materials[o->material].alpha_mode != RND_ALPHA_OPAQUE;
		d->texture_set = 0; /* set by rnd_material_textures() */
		d->single_sided = !o->double_sided;
		d->closed = o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_BOX || o->shape == RND_SHAPE_CYLINDER ||
		            (o->shape == RND_SHAPE_MESH && o->closed);
		d->cull_back = d->single_sided;
		rnd_aabb_union(bounds, &d->bounds);
	}
	/* The camera's proxies of spheres after every mesh: where the meshes lie in the buffers (which
	 * the shadow cache's keys hash, render.c caster_key) does not depend on the camera. */
	for (uint32_t i = 0; i < sc->object_count; i++) {
		uint32_t v, x;
		rnd_proxy_counts(&proxies[i], &v, &x);
		if (!x) continue;
		rnd_proxy_write(&proxies[i], vtx + vbase, idx + ibase, vbase);
		if (uv1) memset(uv1 + 2 * (size_t)vbase, 0, (size_t)v * 8);   /* a sphere's proxy: no texture uvs */
		draws[i].cam_first_index = ibase;
		draws[i].cam_index_count = x;
		draws[i].cam_first_vertex = vbase;
		vbase += v; ibase += x;
	}
	rnd_buffer_publish(&s->vertices, 0, (VkDeviceSize)vbase * sizeof(struct rnd_vertex));
	rnd_buffer_publish(&s->indices, 0, (VkDeviceSize)ibase * sizeof(uint32_t));
	if (uv1) rnd_buffer_publish(&s->uvs1, 0, (VkDeviceSize)vbase * 8);
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
