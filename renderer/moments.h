/*
 * renderer/moments.h — VSM / EVSM2 moment maps (see moments.c), computed from each map just
 * drawn in a slot's scratch image. The context owns the compute pipelines; each
 * slot owns its scratch and blur images (slot.c).
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
/* Largest moment-map side the blur can read: the depth scratch (res² floats) is bound as one
 * storage buffer, at most maxStorageBufferRange bytes (128 MiB on lavapipe: 4096). */
uint32_t rnd_moments_max_res(const struct rnd_context *ctx);
/* After shadow view v (of a VSM / EVSM light) was drawn in s->shadow_scratch and copied to
 * s->scratch_buf: blurs its moments into the view's tile of the moment atlas. s->moments_set
 * must point at the scratch buffer, the blur temporary and the moment atlas. */
void rnd_moments_record_view(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_shadow_plan *sp,
                             uint32_t v, const struct rnd_scene *sc);

/* PCSS depth bounds (UMBRA_BOUNDS_BLOCK in umbra_shared.h) for a light's maps of resolution
 * res: only PCSS lights get them, and only maps the scratch buffer's storage-buffer range can
 * hold (the same cap as moment maps). record.c draws them, frame.c tells the shader. */
bool rnd_bounds_wanted(const struct rnd_context *ctx, const struct rnd_light_plan *lp, uint32_t res);
/* After shadow view v was drawn and copied to s->scratch_buf (as for moments): its tile's
 * depth bounds into ctx->atlas_bounds. s->moments_set must point at both. Tiles are
 * UMBRA_BOUNDS_BLOCK-aligned (at least 64 texels, aligned to their size). */
void rnd_bounds_record_view(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_shadow_plan *sp, uint32_t v);

#endif
