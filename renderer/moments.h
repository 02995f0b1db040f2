/*
 * renderer/moments.h — VSM / EVSM2 moment maps (see moments.c). The context owns the compute
 * pipeline; each slot owns its moment images (slot.c). Recording happens after the shadow
 * passes of a render, for every shadow view of a light whose filter is vsm or evsm.
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
/* Records both blur passes for every rendered moment view of the plan into s->cmd: depth
 * tile -> moments -> the same tile of the moment atlas. s->moments_set must point at the
 * atlases and a blur temporary as large as the largest tile. */
void rnd_moments_record(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_shadow_plan *sp,
                        const struct rnd_scene *sc);

#endif
