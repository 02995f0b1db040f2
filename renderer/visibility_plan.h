/*
 * renderer/visibility_plan.h — when the visibility pass runs (see visibility_plan.c; the pass
 * itself: visibility.h). Pure: no Vulkan; thread-safe.
 */
#ifndef UMBRA_RENDERER_VISIBILITY_PLAN_H
#define UMBRA_RENDERER_VISIBILITY_PLAN_H

#include "draw.h"
#include "plan.h"

/* Layers of the visibility image: at least 2, so that its view is an array (layers beyond a
 * render's lights are not read). */
#define RND_VIS_MIN_LAYERS 2u

/* Whether a view of sc (its draws, its shadow plan sp) takes its shadows from the visibility
 * pass, and why (*why: enum rnd_vis_why; NULL: not wanted). device: the device can run it at all; force: -1 by the rule, 0 off, 1 on where the
 * device and the scene allow it (UMBRA_VISIBILITY, read by the plan's caller: tests,
 * comparisons). */
bool rnd_visibility_wanted(bool device, int force, const struct rnd_scene *sc, const struct rnd_shadow_plan *sp,
                           const struct draw *draws, uint32_t ndraw, uint8_t *why);
/* Why (rnd_visibility_wanted's *why; the plan shows it). */
enum rnd_vis_why {
	RND_VIS_DENSE,          /* on: enough small triangles under wide filters to pay for it */
	RND_VIS_FORCED_ON,      /* on: UMBRA_VISIBILITY=1 */
	RND_VIS_NO_DEVICE,      /* off: the device cannot run it */
	RND_VIS_DEBUG,          /* off: a debug view shows the filters' own work */
	RND_VIS_NO_SHADOWS,     /* off: no light has shadow maps */
	RND_VIS_MASKED,         /* off: an alpha-tested material (the surfaces pass cuts out nothing) */
	RND_VIS_TOO_LARGE,      /* off: its images would be over RND_VIS_MAX_BYTES */
	RND_VIS_FORCED_OFF,     /* off: UMBRA_VISIBILITY=0 */
	RND_VIS_NARROW,         /* off: no light filters widely enough (PCSS, PCF radius 4+) */
	RND_VIS_SPARSE,         /* off: too few triangles for its passes to pay */
	RND_VIS_WHY_COUNT
};
/* The bytes of the slot's images the pass would take for a view of sc, 0 where it cannot run
 * at all (no shadowed light, a debug view, a view too large): what a render may need beyond
 * its targets (estimate.c counts it, before the plan says whether the pass runs). */
uint64_t rnd_visibility_bytes(const struct rnd_scene *sc);

#endif
