/*
 * renderer/visibility_plan.h — when the visibility pass runs, and when pixel shading does (see
 * visibility_plan.c; the passes themselves: visibility.h, deferred.h). Pure: no Vulkan;
 * thread-safe.
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
/* A reason in words ("" for none). */
const char *rnd_vis_why_text(unsigned why);
/* The bytes of the slot's images the pass would take for a view of sc, 0 where it cannot run
 * at all (no shadowed light, a debug view, a view too large): what a render may need beyond
 * its targets (estimate.c counts it, before the plan says whether the pass runs). */
uint64_t rnd_visibility_bytes(const struct rnd_scene *sc);
/* The bytes of the slot's images for the surfaces pass of sc's view with `lights` layers of
 * visibility; 0 over the size the pass may take. */
uint64_t rnd_surfaces_bytes(const struct rnd_scene *sc, uint32_t lights);
/* The triangles of draws the camera may see (what pays for the passes: one per N pixels). */
uint64_t rnd_camera_faces(const struct draw *draws, uint32_t ndraw);

/* Whether a view of sc is shaded once per pixel centre (pixel shading, deferred.h), and why
 * (*why: enum rnd_pixel_why; NULL: not wanted): the view runs the visibility pass (vis), or an
 * environment map lights it (env_lit) over dense triangles (then pixel shading runs the
 * surfaces pass for itself: the caller runs the visibility pass's passes wherever this says
 * yes); MSAA 4, no debug view, no environment map as the background, every draw plain (opaque,
 * untextured, no material extension lobe, no sphere proxy; draws' tex_bits from the plan).
 * device: the device can (deferred.c rnd_deferred_supported); vis_device: it can run the
 * visibility pass; force: UMBRA_PIXEL_SHADING, 0 off, else -1. */
bool rnd_pixel_shading_wanted(bool device, bool vis_device, int force, const struct rnd_scene *sc,
                              const struct draw *draws, uint32_t ndraw, bool vis, bool env_lit, uint8_t *why);
enum rnd_pixel_why {
	RND_PIXEL_VISIBILITY,   /* on: the visibility pass's surfaces shaded once per pixel centre */
	RND_PIXEL_ENVIRONMENT,  /* on: an environment map over dense triangles, its own surfaces pass */
	RND_PIXEL_NO_DEVICE,    /* off: the device cannot */
	RND_PIXEL_OUTPUT,       /* off: not MSAA 4, or a debug view */
	RND_PIXEL_BACKGROUND,   /* off: the environment map behind the scene */
	RND_PIXEL_NOT_PLAIN,    /* off: a textured, alpha-tested or extension material, or a sphere proxy */
	RND_PIXEL_NO_PASS,      /* off: no visibility pass and no environment map */
	RND_PIXEL_TOO_LARGE,    /* off: the surfaces pass's images would be too large */
	RND_PIXEL_SPARSE,       /* off: too few triangles for its passes to pay */
	RND_PIXEL_FORCED_OFF,   /* off: UMBRA_PIXEL_SHADING=0 */
	RND_PIXEL_WHY_COUNT
};
/* A reason in words ("" for none). */
const char *rnd_pixel_why_text(unsigned why);
/* The bytes of pixel shading's images for a view of sc (estimate.c: beside the visibility pass's). */
uint64_t rnd_deferred_bytes(const struct rnd_scene *sc);

#endif
