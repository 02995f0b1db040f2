/*
 * renderer/slot.h — a render slot: everything one render in flight needs, kept between
 * renders so that a steady stream of similar requests allocates nothing.
 *
 * Ownership: the context owns its slots (slot.c creates them at context create). A slot is
 * handed to one thread by rnd_slot_acquire() and returned by rnd_slot_release(). Buffers and
 * images grow to fit (targets are recreated when size, format or sample count change) only
 * after the slot's fence has signalled, so the GPU never sees a resource freed under it.
 */
#ifndef UMBRA_RENDERER_SLOT_H
#define UMBRA_RENDERER_SLOT_H

#include "internal.h"

enum { RND_TS_START, RND_TS_SHADOW_END, RND_TS_VIS_END, RND_TS_MAIN_END, RND_TS_COPY_END,
       RND_TS_COUNT };

struct rnd_slot {
	uint32_t index;
	uint64_t epoch;               /* ctx->slot_epoch when this render took the slot */
	VkCommandPool pool;
	VkCommandBuffer cmd;
	VkFence fence;
	VkQueryPool queries;
	VkDescriptorPool desc_pool;
	VkDescriptorSet set;

	struct rnd_buffer vertices, indices, params, readback, staging;
	/* the second uv set (float2 per vertex of `vertices`), reserved only for a scene with an
	 * object that has one (upload.c); has_uv1 says whether this render's scene filled it */
	struct rnd_buffer uvs1;
	bool has_uv1;
	/* this render's material textures (destroyed when the next render starts) */
	struct rnd_image_res *textures;   /* ctx->max_textures */
	uint32_t texture_count;
	/* set 1: [0] the white 1x1 in every slot (untextured draws), [1 + i] the i-th textured
	 * material's textures (render.c textures()) */
	VkDescriptorPool texture_pool;
	VkDescriptorSet *texture_sets;    /* 1 + rnd_texture_sets(ctx->max_textures) */
	struct rnd_image_res white;
	struct rnd_image_res white_cube;  /* 1x1 cube: the environment's stand-in in renders without a map */
	bool white_ready;             /* both cleared to white and in SHADER_READ_ONLY layout */
	/* AOV pass targets: UMBRA_AOV_ATTACHMENTS x RGBA32F + a single-sample depth */
	struct rnd_image_res aov[UMBRA_AOV_ATTACHMENTS], aov_depth;
	/* moment maps (VSM / EVSM) are blurred through this tile-sized temporary (GENERAL layout) */
	struct rnd_image_res moments_tmp;
	/* shadow maps are drawn here at the origin, then copied into their atlas tile */
	struct rnd_image_res shadow_scratch;
	struct rnd_buffer scratch_buf;    /* the scratch map as floats, read by minmax.comp */
	bool moments_initialised;     /* moments_tmp is in GENERAL layout */
	VkDescriptorPool moments_pool;
	VkDescriptorSet moments_set;  /* minmax.comp's: the scratch buffer, the depth bounds */
	VkDescriptorSet blur_set;     /* moments.frag's: the depth atlas, moments_tmp (none without moments) */
	struct rnd_image_res color_ms, depth, resolve;
	/* the camera view's depth, single-sample, drawn before the main pass for contact shadows */
	struct rnd_image_res scene_depth;
	/* the visibility pass (visibility.c): the view's surface positions and normals, their
	 * depth, the visibility image */
	struct rnd_image_res surfaces, normals, surfaces_depth, visibility;
	/* pixel shading (deferred.c): the surface-shading inputs, the colour shaded per pixel */
	struct rnd_image_res shading, shaded;
	/* the environment pass (env_pass.c): the surfaces at its scale, their depth, its visibility */
	struct rnd_image_res env_surfaces, env_normals, env_depth, env_vis;
	/* What those images hold (rnd_env_pass_key of the view that drew them), set only once the
	 * submit that drew them completed; 0: nothing to reuse (never drawn, being redrawn, a
	 * failed render, the images made again). */
	uint64_t env_pass_key;
	VkDeviceSize params_used;     /* bytes of `params` this render's rnd_frame_write wrote */
};

/* Makes the colour/depth targets match (format, w, h, samples). */
enum rnd_result rnd_slot_targets(struct rnd_context *ctx, struct rnd_slot *s, VkFormat color, uint32_t w, uint32_t h,
                                 uint32_t samples, struct rnd_error *err);
/* Makes the AOV targets match w x h. */
enum rnd_result rnd_slot_aov(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h, struct rnd_error *err);
/* Makes the shadow scratch depth image at least res x res. */
enum rnd_result rnd_slot_shadow_scratch(struct rnd_context *ctx, struct rnd_slot *s, uint32_t res, struct rnd_error *err);
/* Makes the moment blur temporary at least res x res. */
enum rnd_result rnd_slot_moments_tmp(struct rnd_context *ctx, struct rnd_slot *s, uint32_t res, struct rnd_error *err);
/* Makes the contact-shadow scene depth image match w x h. */
enum rnd_result rnd_slot_scene_depth(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h,
                                     struct rnd_error *err);
/* Makes the visibility pass's images match a w x h view with `layers` lights (at least 2). */
enum rnd_result rnd_slot_visibility(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h,
                                    uint32_t layers, struct rnd_error *err);
/* Makes pixel shading's images (deferred.c) match a w x h view whose colour format is color. */
enum rnd_result rnd_slot_pixel_shading(struct rnd_context *ctx, struct rnd_slot *s, uint32_t w, uint32_t h, VkFormat color,
                                       struct rnd_error *err);
/* Destroys the previous render's textures. */
void rnd_slot_drop_textures(struct rnd_context *ctx, struct rnd_slot *s);

/* What a slot keeps for the next render: each group of targets or buffer over this is freed
 * when its render ends, so one enormous request does not hold its memory for the life of the
 * process, while the targets of ordinary renders stay (a 1024² output with MSAA 4: colour,
 * depth and resolve 36 MiB; a 2048² shadow scratch map 16 MiB). 64 MiB kept two slots' buffers
 * of 48,000 planes (~40 MB) after the request. */
#define RND_SLOT_KEEP_BYTES (40ull << 20)
/* Frees what is over RND_SLOT_KEEP_BYTES. Only after the slot's work has completed. */
void rnd_slot_trim(struct rnd_context *ctx, struct rnd_slot *s);
/* The same with a bound of keep bytes (0: every target and buffer goes). */
void rnd_slot_trim_to(struct rnd_context *ctx, struct rnd_slot *s, VkDeviceSize keep);

#endif
