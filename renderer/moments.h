/*
 * renderer/moments.h — VSM / EVSM2 moment maps (see moments.c), drawn from each map just
 * copied into the depth atlas, and PCSS's depth bounds, computed from the slot's scratch copy
 * of it. The context owns the pipelines; each slot owns its scratch buffer, blur temporary and
 * descriptor sets (slot.c, frame.c).
 */
#ifndef UMBRA_RENDERER_MOMENTS_H
#define UMBRA_RENDERER_MOMENTS_H

#include "plan.h"
#include "slot.h"

struct rnd_moments_push {
	uint32_t info[4];   /* tile x, tile y, pass, blur radius */
	float params[4];    /* EVSM exponent (0 = VSM), Gaussian sigma, tile size */
	float proj[4];      /* near, far, 1 = perspective */
};

enum rnd_result rnd_moments_init(struct rnd_context *ctx, struct rnd_error *err);
void rnd_moments_release(struct rnd_context *ctx);
/* The moment format for a request (fp16 when asked or when fp32 cannot be filtered). */
VkFormat rnd_moments_format(const struct rnd_context *ctx, bool want_fp16);
float rnd_moments_max_exponent(VkFormat f);
/* Largest side of a moment map and of a map with depth bounds: the bounds read the scratch
 * (res² floats) as one storage buffer, at most maxStorageBufferRange bytes (128 MiB on
 * lavapipe: 4096); moment maps keep the same cap, for their blur temporary's memory (res² x 8
 * bytes per render slot). */
uint32_t rnd_moments_max_res(const struct rnd_context *ctx);
/* After shadow view v was drawn and copied into its tile of the depth atlas: for a VSM / EVSM
 * light, its moments blurred into the view's tile of the moment atlas (nothing for others).
 * s->blur_set must point at the depth atlas and s->moments_tmp, which must hold the tile. */
void rnd_moments_record_view(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_shadow_plan *sp,
                             uint32_t v, const struct rnd_scene *sc);

/* PCSS depth bounds (UMBRA_BOUNDS_BLOCK in umbra_shared.h) for a light's maps of resolution
 * res: only PCSS lights get them, and only maps the scratch buffer's storage-buffer range can
 * hold (the same cap as moment maps). record.c draws them, frame.c tells the shader. */
bool rnd_bounds_wanted(const struct rnd_context *ctx, const struct rnd_light_plan *lp, uint32_t res);
/* The same rule from what the plan knows of the context (struct rnd_plan_device: whether the
 * bounds' atlas exists, rnd_moments_max_res): what `explain` shows. */
bool rnd_bounds_rule(const struct rnd_light_plan *lp, bool bounds_atlas, uint32_t max_res, uint32_t res);
/* After shadow view v was drawn and copied to s->scratch_buf: its tile's
 * depth bounds into ctx->atlas_bounds. s->moments_set must point at both. Tiles are
 * UMBRA_BOUNDS_BLOCK-aligned (at least 64 texels, aligned to their size). */
void rnd_bounds_record_view(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_shadow_plan *sp, uint32_t v);

#endif
