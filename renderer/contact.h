/*
 * renderer/contact.h — contact shadows: which lights march them, their parameters, and the
 * camera-view depth pass they march against (see contact.c). The first two are the render
 * plan's (render_plan.c: whether a view draws its depth for them); no Vulkan in this header,
 * no state of its own.
 */
#ifndef UMBRA_RENDERER_CONTACT_H
#define UMBRA_RENDERER_CONTACT_H

#include "plan.h"

struct rnd_context;
struct rnd_slot;
struct record_view;

/* Light i marches contact shadows (asked for, shadows on, and the light has shadow views). */
bool rnd_contact_on(const struct rnd_scene *sc, const struct rnd_shadow_plan *sp, uint32_t i);
bool rnd_contact_any(const struct rnd_scene *sc, const struct rnd_shadow_plan *sp);
/* umbra_light.contact for a light's settings (0 distance / thickness: the view-scaled defaults). */
void rnd_contact_params(const struct rnd_shadow *sh, float out[4]);
/* Draws the view's depth into slot->scene_depth (sized by rnd_slot_scene_depth) and leaves it
 * ready for sampling by the main and AOV passes. */
void record_scene_depth(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv);

#endif
