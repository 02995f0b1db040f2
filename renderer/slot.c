/*
 * renderer/slot.c — render slots (see slot.h): creation, hand-out, growth, release.
 */
#include <stdlib.h>
#include <string.h>
#include "slot.h"
#include "env_pass.h"
#include "material.h"
#include "visibility_plan.h"

/* A descriptor pool (named "slot N <what> descriptor pool") holding exactly `count` sets, one
 * per layouts[i], all allocated into sets[]. On failure nothing is left. Descriptor sets stay
 * unnamed: lavapipe never frees a set's debug name with its pool. */
static enum rnd_result pool_with_sets(struct rnd_context *ctx, const VkDescriptorPoolSize *sizes, uint32_t nsizes,
                                      uint32_t count, const VkDescriptorSetLayout *layouts, const char *what,
                                      uint32_t index, VkDescriptorPool *pool, VkDescriptorSet *sets,
                                      struct rnd_error *err)
{
	VkResult vr;
	VkDescriptorPoolCreateInfo dpi = {
		.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, .maxSets = count, .poolSizeCount = nsizes,
		.pPoolSizes = sizes,
	};
	char call[64];
	snprintf(call, sizeof call, "vkCreateDescriptorPool%s%s%s", what[0] ? " (" : "", what, what[0] ? ")" : "");
	if ((vr = vkCreateDescriptorPool(ctx->device, &dpi, NULL, pool)) != VK_SUCCESS) return rnd_fail_vk(err, vr, call);
	RND_NAME(ctx, VK_OBJECT_TYPE_DESCRIPTOR_POOL, *pool, "slot %u %s%sdescriptor pool", index, what, what[0] ? " " : "");
	VkDescriptorSetAllocateInfo dai = {
		.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, .descriptorPool = *pool,
		.descriptorSetCount = count, .pSetLayouts = layouts,
	};
	if ((vr = vkAllocateDescriptorSets(ctx->device, &dai, sets)) != VK_SUCCESS) {
		vkDestroyDescriptorPool(ctx->device, *pool, NULL);
		*pool = VK_NULL_HANDLE;
		snprintf(call, sizeof call, "vkAllocateDescriptorSets%s%s%s", what[0] ? " (" : "", what, what[0] ? ")" : "");
		return rnd_fail_vk(err, vr, call);
	}
	return RND_OK;
}

/* A slot's command pool, its one command buffer, its fence and (with timestamps) its query
 * pool. On failure nothing of them is left. */
static enum rnd_result slot_commands(struct rnd_context *ctx, struct rnd_slot *s, struct rnd_error *err)
{
	VkResult vr;
	enum rnd_result r;
	uint32_t index = s->index;
	VkCommandPoolCreateInfo pci = {
		.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
		.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, .queueFamilyIndex = ctx->queue_family,
	};
	if ((vr = vkCreateCommandPool(ctx->device, &pci, NULL, &s->pool)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreateCommandPool");
	RND_NAME(ctx, VK_OBJECT_TYPE_COMMAND_POOL, s->pool, "slot %u command pool", index);
	VkCommandBufferAllocateInfo cai = {
		.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, .commandPool = s->pool,
		.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1,
	};
	if ((vr = vkAllocateCommandBuffers(ctx->device, &cai, &s->cmd)) != VK_SUCCESS) {
		r = rnd_fail_vk(err, vr, "vkAllocateCommandBuffers");
		goto fail_cmd;
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_COMMAND_BUFFER, s->cmd, "slot %u commands", index);
	VkFenceCreateInfo fci = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
	if ((vr = vkCreateFence(ctx->device, &fci, NULL, &s->fence)) != VK_SUCCESS) {
		r = rnd_fail_vk(err, vr, "vkCreateFence");
		goto fail_cmd;
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_FENCE, s->fence, "slot %u fence", index);
	if (ctx->timestamps) {
		VkQueryPoolCreateInfo qci = {
			.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO, .queryType = VK_QUERY_TYPE_TIMESTAMP, .queryCount = RND_TS_COUNT,
		};
		if ((vr = vkCreateQueryPool(ctx->device, &qci, NULL, &s->queries)) != VK_SUCCESS) {
			r = rnd_fail_vk(err, vr, "vkCreateQueryPool");
			goto fail_fence;
		}
		RND_NAME(ctx, VK_OBJECT_TYPE_QUERY_POOL, s->queries, "slot %u timestamps", index);
	}
	return RND_OK;

fail_fence:
	vkDestroyFence(ctx->device, s->fence, NULL);
	s->fence = VK_NULL_HANDLE;
fail_cmd:
	vkDestroyCommandPool(ctx->device, s->pool, NULL); /* frees the command buffer */
	s->pool = VK_NULL_HANDLE;
	s->cmd = VK_NULL_HANDLE;
	return r;
}

/* Undoes slot_commands(). */
static void slot_commands_release(struct rnd_context *ctx, struct rnd_slot *s)
{
	if (s->queries) vkDestroyQueryPool(ctx->device, s->queries, NULL);
	vkDestroyFence(ctx->device, s->fence, NULL);
	vkDestroyCommandPool(ctx->device, s->pool, NULL); /* frees the command buffer */
}

/* The slot's frame descriptor set and its texture sets (set 0: every binding the white texture,
 * then one per texture set the context allows), each in its own pool. On failure neither is left. */
static enum rnd_result slot_descriptor_pools(struct rnd_context *ctx, struct rnd_slot *s, uint32_t nsets,
                                             struct rnd_error *err)
{
	enum rnd_result r;
	VkDescriptorSetLayout *layouts = calloc(1 + nsets, sizeof *layouts);
	if (!layouts) return rnd_fail(err, RND_ERR_OOM, "out of memory for render slot %u", s->index);
	VkDescriptorPoolSize sizes[4] = {
		{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 4},
		{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
		{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16},
		{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
	};
	if ((r = pool_with_sets(ctx, sizes, 4, 1, &ctx->pipes.set_layout, "", s->index, &s->desc_pool, &s->set, err)) != RND_OK)
		goto done;
	VkDescriptorPoolSize tsize = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, (1 + nsets) * UMBRA_TEX_SLOTS};
	for (uint32_t i = 0; i < 1 + nsets; i++) layouts[i] = ctx->pipes.texture_layout;
	if ((r = pool_with_sets(ctx, &tsize, 1, 1 + nsets, layouts, "texture", s->index, &s->texture_pool, s->texture_sets,
	                        err)) != RND_OK) {
		vkDestroyDescriptorPool(ctx->device, s->desc_pool, NULL);
		s->desc_pool = VK_NULL_HANDLE;
	}
done:
	free(layouts);
	return r;
}

/* The slot's 1x1 white texture and white cube (what an absent texture or environment samples),
 * the white texture written into every binding of texture set 0. On failure neither is left. */
static enum rnd_result slot_white(struct rnd_context *ctx, struct rnd_slot *s, struct rnd_error *err)
{
	enum rnd_result r;
	char name[48];
	snprintf(name, sizeof name, "slot %u white texture", s->index);
	if ((r = rnd_image_create(ctx, VK_FORMAT_R8G8B8A8_SRGB, 1, 1, 1, 1, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
	                          VK_IMAGE_ASPECT_COLOR_BIT, name, &s->white, err)) != RND_OK)
		return r;
	snprintf(name, sizeof name, "slot %u white cube", s->index);
	if ((r = rnd_image_create_cube(ctx, VK_FORMAT_R8G8B8A8_UNORM, 1, 1, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
	                               name, &s->white_cube, err)) != RND_OK) {
		rnd_image_destroy(ctx, &s->white_cube);
		rnd_image_destroy(ctx, &s->white);
		return r;
	}
	VkDescriptorImageInfo wi = {ctx->pipes.texture_samplers[0], s->white.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
	VkWriteDescriptorSet ww[UMBRA_TEX_SLOTS];
	for (uint32_t b = 0; b < UMBRA_TEX_SLOTS; b++)
		ww[b] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->texture_sets[0], .dstBinding = b,
			.descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &wi,
		};
	vkUpdateDescriptorSets(ctx->device, UMBRA_TEX_SLOTS, ww, 0, NULL);
	return RND_OK;
}

/* One render slot: its parts in creation order (each part unwinds itself when it fails), the
 * parts made so far unwound in reverse by the goto chain at the end. */
static enum rnd_result slot_create(struct rnd_context *ctx, uint32_t index, struct rnd_slot **out, struct rnd_error *err)
{
	enum rnd_result r;
	struct rnd_slot *s = calloc(1, sizeof *s);
	if (!s) return rnd_fail(err, RND_ERR_OOM, "out of memory for render slot %u", index);
	s->index = index;
	uint32_t ntex = ctx->max_textures, nsets = rnd_texture_sets(ntex);
	s->textures = calloc(ntex, sizeof *s->textures);
	s->texture_sets = calloc(1 + nsets, sizeof *s->texture_sets);
	if (!s->textures || !s->texture_sets) {
		r = rnd_fail(err, RND_ERR_OOM, "out of memory for render slot %u", index);
		goto fail_alloc;
	}
	if ((r = slot_commands(ctx, s, err)) != RND_OK)
		goto fail_alloc;
	if ((r = slot_descriptor_pools(ctx, s, nsets, err)) != RND_OK)
		goto fail_commands;
	if ((r = slot_white(ctx, s, err)) != RND_OK)
		goto fail_pools;
	VkDescriptorPoolSize msizes[3] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
	                                  {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2}};
	VkDescriptorSetLayout mlayouts[2] = {ctx->moments.set_layout, ctx->moments.blur_set_layout};
	VkDescriptorSet msets[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
	if ((r = pool_with_sets(ctx, msizes, 3, ctx->moments.available ? 2 : 1, mlayouts, "moments", index, &s->moments_pool,
	                        msets, err)) != RND_OK)
		goto fail_white;
	s->moments_set = msets[0];
	s->blur_set = msets[1];
	*out = s;
	return RND_OK;

fail_white:
	rnd_image_destroy(ctx, &s->white_cube);
	rnd_image_destroy(ctx, &s->white);
fail_pools:
	vkDestroyDescriptorPool(ctx->device, s->texture_pool, NULL);
	vkDestroyDescriptorPool(ctx->device, s->desc_pool, NULL);
fail_commands:
	slot_commands_release(ctx, s);
fail_alloc:
	free(s->texture_sets);
	free(s->textures);
	free(s);
	return r;
}

static void slot_destroy(struct rnd_context *ctx, struct rnd_slot *s)
{
	if (!s) return;
	rnd_slot_drop_textures(ctx, s);
	rnd_image_destroy(ctx, &s->white);
	rnd_image_destroy(ctx, &s->white_cube);
	vkDestroyDescriptorPool(ctx->device, s->texture_pool, NULL);
	rnd_image_destroy(ctx, &s->moments_tmp);
	rnd_image_destroy(ctx, &s->shadow_scratch);
	rnd_buffer_destroy(ctx, &s->scratch_buf);
	vkDestroyDescriptorPool(ctx->device, s->moments_pool, NULL);
	for (int i = 0; i < UMBRA_AOV_ATTACHMENTS; i++) rnd_image_destroy(ctx, &s->aov[i]);
	rnd_image_destroy(ctx, &s->aov_depth);
	rnd_image_destroy(ctx, &s->scene_depth);
	rnd_image_destroy(ctx, &s->surfaces);
	rnd_image_destroy(ctx, &s->normals);
	rnd_image_destroy(ctx, &s->surfaces_depth);
	rnd_image_destroy(ctx, &s->visibility);
	rnd_image_destroy(ctx, &s->shading);
	rnd_image_destroy(ctx, &s->shaded);
	rnd_env_pass_release(ctx, s);
	rnd_buffer_destroy(ctx, &s->staging);
	rnd_image_destroy(ctx, &s->resolve);
	rnd_image_destroy(ctx, &s->depth);
	rnd_image_destroy(ctx, &s->color_ms);
	rnd_buffer_destroy(ctx, &s->readback);
	rnd_buffer_destroy(ctx, &s->params);
	rnd_buffer_destroy(ctx, &s->indices);
	rnd_buffer_destroy(ctx, &s->uvs1);
	rnd_buffer_destroy(ctx, &s->vertices);
	vkDestroyDescriptorPool(ctx->device, s->desc_pool, NULL);
	slot_commands_release(ctx, s);
	free(s->texture_sets);
	free(s->textures);
	free(s);
}

enum rnd_result rnd_slots_init(struct rnd_context *ctx, struct rnd_error *err)
{
	ctx->slot_count = ctx->desc.slots;
	ctx->slots = calloc(ctx->slot_count, sizeof *ctx->slots);
	ctx->slot_busy = calloc(ctx->slot_count, sizeof *ctx->slot_busy);
	if (!ctx->slots || !ctx->slot_busy) {
		free(ctx->slots); free(ctx->slot_busy);
		ctx->slots = NULL; ctx->slot_busy = NULL;
		return rnd_fail(err, RND_ERR_OOM, "out of memory for %u render slots", ctx->slot_count);
	}
	for (uint32_t i = 0; i < ctx->slot_count; i++) {
		enum rnd_result r = slot_create(ctx, i, &ctx->slots[i], err);
		if (r != RND_OK) {
			rnd_slots_release(ctx);
			return r;
		}
	}
	return RND_OK;
}

void rnd_slots_release(struct rnd_context *ctx)
{
	if (!ctx->slots) return;
	for (uint32_t i = 0; i < ctx->slot_count; i++) slot_destroy(ctx, ctx->slots[i]);
	free(ctx->slots);
	free(ctx->slot_busy);
	ctx->slots = NULL;
	ctx->slot_busy = NULL;
}

struct rnd_slot *rnd_slot_acquire(struct rnd_context *ctx)
{
	pthread_mutex_lock(&ctx->slot_mu);
	for (;;) {
		for (uint32_t i = 0; i < ctx->slot_count; i++) {
			if (!ctx->slot_busy[i]) {
				ctx->slot_busy[i] = true;
				ctx->slots[i]->epoch = ctx->slot_epoch;
				pthread_mutex_unlock(&ctx->slot_mu);
				return ctx->slots[i];
			}
		}
		pthread_cond_wait(&ctx->slot_cv, &ctx->slot_mu);
	}
}

uint64_t rnd_slot_epoch_advance(struct rnd_context *ctx)
{
	pthread_mutex_lock(&ctx->slot_mu);
	uint64_t e = ++ctx->slot_epoch;
	pthread_mutex_unlock(&ctx->slot_mu);
	return e;
}

uint64_t rnd_slot_oldest_busy_epoch(struct rnd_context *ctx)
{
	uint64_t oldest = UINT64_MAX;
	pthread_mutex_lock(&ctx->slot_mu);
	for (uint32_t i = 0; i < ctx->slot_count; i++)
		if (ctx->slot_busy[i] && ctx->slots[i]->epoch < oldest) oldest = ctx->slots[i]->epoch;
	pthread_mutex_unlock(&ctx->slot_mu);
	return oldest;
}

void rnd_context_trim_slots(struct rnd_context *ctx)
{
	for (uint32_t i = 0; i < ctx->slot_count; i++) {
		pthread_mutex_lock(&ctx->slot_mu);
		bool idle = !ctx->slot_busy[i];
		if (idle) ctx->slot_busy[i] = true;   /* held while its targets go */
		pthread_mutex_unlock(&ctx->slot_mu);
		if (!idle) continue;
		rnd_slot_trim_to(ctx, ctx->slots[i], 0);
		rnd_slot_release(ctx, ctx->slots[i]);
	}
}

void rnd_slot_release(struct rnd_context *ctx, struct rnd_slot *s)
{
	pthread_mutex_lock(&ctx->slot_mu);
	ctx->slot_busy[s->index] = false;
	pthread_cond_signal(&ctx->slot_cv);
	pthread_mutex_unlock(&ctx->slot_mu);
}

enum rnd_result rnd_slot_targets(struct rnd_context *ctx, struct rnd_slot *s, VkFormat color, uint32_t w, uint32_t h,
                                 uint32_t samples, struct rnd_error *err)
{
	enum rnd_result r;
	bool same = s->resolve.img && s->resolve.format == color && s->resolve.width == w && s->resolve.height == h &&
	            s->depth.samples == samples;
	if (same) return RND_OK;
	rnd_image_destroy(ctx, &s->color_ms);
	rnd_image_destroy(ctx, &s->depth);
	rnd_image_destroy(ctx, &s->resolve);
	char name[64];
	snprintf(name, sizeof name, "slot %u colour", s->index);
	if ((r = rnd_image_create(ctx, color, w, h, 1, 1, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
	                          VK_IMAGE_ASPECT_COLOR_BIT, name, &s->resolve, err)) != RND_OK)
		return r;
	if (samples > 1) {
		snprintf(name, sizeof name, "slot %u colour msaa", s->index);
		if ((r = rnd_image_create(ctx, color, w, h, 1, samples,
		                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT,
		                          VK_IMAGE_ASPECT_COLOR_BIT, name, &s->color_ms, err)) != RND_OK)
			goto fail;
	}
	snprintf(name, sizeof name, "slot %u depth", s->index);
	/* Sampled: pixel shading's resolve reads its samples (deferred.c). */
	if ((r = rnd_image_create(ctx, RND_DEPTH_FORMAT, w, h, 1, samples,
	                          VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
	                          VK_IMAGE_ASPECT_DEPTH_BIT, name, &s->depth, err)) != RND_OK)
		goto fail;
	return RND_OK;
fail:
	rnd_image_destroy(ctx, &s->color_ms);
	rnd_image_destroy(ctx, &s->resolve);
	return r;
}


void rnd_slot_drop_textures(struct rnd_context *ctx, struct rnd_slot *s)
{
	for (uint32_t i = 0; i < s->texture_count; i++) rnd_image_destroy(ctx, &s->textures[i]);
	s->texture_count = 0;
}

enum rnd_result rnd_slot_aov(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h, struct rnd_error *err)
{
	enum rnd_result r;
	if (s->aov_depth.img && s->aov_depth.width == w && s->aov_depth.height == h) return RND_OK;
	for (int i = 0; i < UMBRA_AOV_ATTACHMENTS; i++) rnd_image_destroy(ctx, &s->aov[i]);
	rnd_image_destroy(ctx, &s->aov_depth);
	char name[64];
	for (int i = 0; i < UMBRA_AOV_ATTACHMENTS; i++) {
		snprintf(name, sizeof name, "slot %u aov %d", s->index, i);
		if ((r = rnd_image_create(ctx, VK_FORMAT_R32G32B32A32_SFLOAT, w, h, 1, 1,
		                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
		                          VK_IMAGE_ASPECT_COLOR_BIT, name, &s->aov[i], err)) != RND_OK)
			goto fail;
	}
	snprintf(name, sizeof name, "slot %u aov depth", s->index);
	if ((r = rnd_image_create(ctx, RND_DEPTH_FORMAT, w, h, 1, 1, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
	                          VK_IMAGE_ASPECT_DEPTH_BIT, name, &s->aov_depth, err)) != RND_OK)
		goto fail;
	return RND_OK;
fail:
	for (int i = 0; i < UMBRA_AOV_ATTACHMENTS; i++) rnd_image_destroy(ctx, &s->aov[i]);
	return r;
}

enum rnd_result rnd_slot_moments_tmp(struct rnd_context *ctx, struct rnd_slot *s, uint32_t res, struct rnd_error *err)
{
	if (s->moments_tmp.img && s->moments_tmp.width >= res) return RND_OK;
	rnd_image_destroy(ctx, &s->moments_tmp);
	s->moments_initialised = false;
	char name[48];
	snprintf(name, sizeof name, "slot %u moments blur", s->index);
	return rnd_image_create(ctx, VK_FORMAT_R32G32_SFLOAT, res, res, 1, 1,
	                        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_ASPECT_COLOR_BIT, name,
	                        &s->moments_tmp, err);
}

enum rnd_result rnd_slot_shadow_scratch(struct rnd_context *ctx, struct rnd_slot *s, uint32_t res, struct rnd_error *err)
{
	enum rnd_result r = rnd_buffer_reserve(ctx, &s->scratch_buf, (VkDeviceSize)res * res * 4,
	                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
	                                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
	                                       "slot shadow scratch buffer", err);
	if (r != RND_OK) return r;
	if (s->shadow_scratch.img && s->shadow_scratch.width >= res) return RND_OK;
	rnd_image_destroy(ctx, &s->shadow_scratch);
	char name[48];
	snprintf(name, sizeof name, "slot %u shadow scratch", s->index);
	return rnd_image_create(ctx, RND_SHADOW_FORMAT, res, res, 1, 1,
	                        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
	                        VK_IMAGE_ASPECT_DEPTH_BIT, name, &s->shadow_scratch, err);
}

/* Bytes the image's memory takes (0 for none). */
static VkDeviceSize image_bytes(const struct rnd_context *ctx, const struct rnd_image_res *im)
{
	if (!im->img) return 0;
	VkMemoryRequirements mr;
	vkGetImageMemoryRequirements(ctx->device, im->img, &mr);
	return mr.size;
}

void rnd_slot_trim(struct rnd_context *ctx, struct rnd_slot *s)
{
	rnd_slot_trim_to(ctx, s, RND_SLOT_KEEP_BYTES);
}

void rnd_slot_trim_to(struct rnd_context *ctx, struct rnd_slot *s, VkDeviceSize keep)
{
	VkDeviceSize aov = image_bytes(ctx, &s->aov_depth);
	for (int i = 0; i < UMBRA_AOV_ATTACHMENTS; i++) aov += image_bytes(ctx, &s->aov[i]);
	if (aov > keep) {
		for (int i = 0; i < UMBRA_AOV_ATTACHMENTS; i++) rnd_image_destroy(ctx, &s->aov[i]);
		rnd_image_destroy(ctx, &s->aov_depth);
	}
	if (image_bytes(ctx, &s->resolve) + image_bytes(ctx, &s->color_ms) + image_bytes(ctx, &s->depth) > keep) {
		rnd_image_destroy(ctx, &s->color_ms);
		rnd_image_destroy(ctx, &s->depth);
		rnd_image_destroy(ctx, &s->resolve);
	}
	if (image_bytes(ctx, &s->scene_depth) > keep) rnd_image_destroy(ctx, &s->scene_depth);
	if (image_bytes(ctx, &s->surfaces) + image_bytes(ctx, &s->normals) + image_bytes(ctx, &s->surfaces_depth) +
	        image_bytes(ctx, &s->visibility) + image_bytes(ctx, &s->shading) + image_bytes(ctx, &s->shaded) > keep) {
		rnd_image_destroy(ctx, &s->shading);
		rnd_image_destroy(ctx, &s->shaded);
		rnd_image_destroy(ctx, &s->surfaces);
		rnd_image_destroy(ctx, &s->normals);
		rnd_image_destroy(ctx, &s->surfaces_depth);
		rnd_image_destroy(ctx, &s->visibility);
	}
	if (image_bytes(ctx, &s->env_surfaces) + image_bytes(ctx, &s->env_normals) + image_bytes(ctx, &s->env_depth) +
	        image_bytes(ctx, &s->env_vis) > keep)
		rnd_env_pass_release(ctx, s);
	if (image_bytes(ctx, &s->shadow_scratch) + s->scratch_buf.size > keep) {
		rnd_image_destroy(ctx, &s->shadow_scratch);
		rnd_buffer_destroy(ctx, &s->scratch_buf);
	}
	if (image_bytes(ctx, &s->moments_tmp) > keep) {
		rnd_image_destroy(ctx, &s->moments_tmp);
		s->moments_initialised = false;
	}
	struct rnd_buffer *bufs[] = {&s->readback, &s->vertices, &s->uvs1, &s->indices, &s->staging};
	for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++)
		if (bufs[i]->size > keep) rnd_buffer_destroy(ctx, bufs[i]);
}

enum rnd_result rnd_slot_scene_depth(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h,
                                     struct rnd_error *err)
{
	if (s->scene_depth.img && s->scene_depth.width == w && s->scene_depth.height == h) return RND_OK;
	rnd_image_destroy(ctx, &s->scene_depth);
	char name[48];
	snprintf(name, sizeof name, "slot %u scene depth", s->index);
	return rnd_image_create(ctx, RND_SHADOW_FORMAT, w, h, 1, 1,
	                        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
	                        VK_IMAGE_ASPECT_DEPTH_BIT, name, &s->scene_depth, err);
}

enum rnd_result rnd_slot_visibility(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h,
                                    uint32_t layers, struct rnd_error *err)
{
	enum rnd_result r;
	char name[48];
	if (!s->surfaces.img || s->surfaces.width != w || s->surfaces.height != h) {
		rnd_image_destroy(ctx, &s->surfaces);
		rnd_image_destroy(ctx, &s->normals);
		rnd_image_destroy(ctx, &s->surfaces_depth);
		struct rnd_image_res *img[2] = {&s->surfaces, &s->normals};
		for (int i = 0; i < 2; i++) {
			snprintf(name, sizeof name, "slot %u surface %s", s->index, i ? "normals" : "positions");
			if ((r = rnd_image_create(ctx, i ? RND_SURFACE_NORMALS_FORMAT : RND_SURFACES_FORMAT, w, h, 1, 1,
			                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
			                          VK_IMAGE_ASPECT_COLOR_BIT, name, img[i], err)) != RND_OK)
				return r;
		}
		snprintf(name, sizeof name, "slot %u surfaces depth", s->index);
		if ((r = rnd_image_create(ctx, RND_DEPTH_FORMAT, w, h, 1, 1, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
		                          VK_IMAGE_ASPECT_DEPTH_BIT, name, &s->surfaces_depth, err)) != RND_OK)
			return r;
	}
	/* Layers of the last render's count */
	if (layers < RND_VIS_MIN_LAYERS) layers = RND_VIS_MIN_LAYERS;
	if (s->visibility.img && s->visibility.width == w && s->visibility.height == h && s->visibility.layers == layers)
		return RND_OK;
	rnd_image_destroy(ctx, &s->visibility);
	snprintf(name, sizeof name, "slot %u visibility", s->index);
	return rnd_image_create(ctx, RND_VISIBILITY_FORMAT, w, h, layers, 1,
	                        VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_ASPECT_COLOR_BIT, name,
	                        &s->visibility, err);
}

enum rnd_result rnd_slot_pixel_shading(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h, VkFormat color,
                                       struct rnd_error *err)
{
	enum rnd_result r;
	char name[48];
	if (!s->shading.img || s->shading.width != w || s->shading.height != h) {
		rnd_image_destroy(ctx, &s->shading);
		snprintf(name, sizeof name, "slot %u surface shading", s->index);
		if ((r = rnd_image_create(ctx, RND_SURFACE_SHADING_FORMAT, w, h, 1, 1,
		                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
		                          VK_IMAGE_ASPECT_COLOR_BIT, name, &s->shading, err)) != RND_OK)
			return r;
	}
	if (s->shaded.img && s->shaded.width == w && s->shaded.height == h && s->shaded.format == color) return RND_OK;
	rnd_image_destroy(ctx, &s->shaded);
	snprintf(name, sizeof name, "slot %u shaded", s->index);
	return rnd_image_create(ctx, color, w, h, 1, 1, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
	                        VK_IMAGE_ASPECT_COLOR_BIT, name, &s->shaded, err);
}
