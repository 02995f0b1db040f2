/*
 * renderer/casters.h — what casts shadows, and into which map: the render plan's decisions about
 * the shadow passes' draws (see casters.c). A plane with nothing on its shaded side, or whose
 * shadow falls only where no camera looks, is left out of every shadow pass; the box of what
 * casts sizes a `fit` sun map; a map draws the casters inside its frustum, back faces culled
 * where that changes nothing.
 *
 * Usage: render_plan.c calls rnd_casters_plan() once per render (the draws' `cast` and the
 * casters' box) and rnd_shadow_view_draws() per shadow map (what it draws: its triangle count
 * for the plan and the deadline's estimates; record_shadow.c draws the same). Pure: no Vulkan,
 * no allocation, thread-safe; unit-tested in tests/unit/test_lod.c and test_render_plan.c.
 */
#ifndef UMBRA_RENDERER_CASTERS_H
#define UMBRA_RENDERER_CASTERS_H

#include "draw.h"
#include "plan.h"

/* Why an object casts shadows or not (rnd_casters_plan; the plan shows it). */
enum rnd_cast_why {
	RND_CAST_YES,            /* it casts */
	RND_CAST_NOT_ASKED,      /* cast_shadows false */
	RND_CAST_CATCHER,        /* a shadow catcher receives shadows and casts none (contract §7) */
	RND_CAST_ALONE,          /* a plane with no other object to shadow */
	RND_CAST_LIT_SIDE,       /* a plane with every other object on its lit side */
	RND_CAST_UNSEEN,         /* a plane whose shadow falls only where no camera sees it */
	RND_CAST_FOR_MOMENTS,    /* a plane kept only for the moments' blur: out of the casters' box */
	RND_CAST_UNJUDGED,       /* a plane in a scene of more than RND_PLANES_JUDGED_MAX objects */
	RND_CAST_FOR_ENV,        /* a plane that shadows others only from the environment's directions:
	                            in their maps, left out of the casters' box */
	RND_CAST_WHY_COUNT
};
/* A reason in words ("" for none). */
const char *rnd_cast_why_text(unsigned why);

/* Whether plane object `plane` may cast a shadow of any shadowed light of sc onto the box b (an
 * object's world bounds): false when b lies wholly on the lit side of the plane for every such
 * light (a flat plane never shadows itself). rnd_casters_plan leaves a plane that shadows none
 * of the other objects out of the shadow pass: the ground under a thumbnail costs no depth fill. */
bool rnd_plane_may_shadow(const struct rnd_scene *sc, const struct rnd_object *plane, const struct rnd_aabb *b);

/* Planes are judged one against another (rnd_plane_may_shadow*, each plane against every other
 * object) only in scenes of at most this many objects: the test is quadratic (16,000 planes
 * took 107 s of planning before the first submit). In a bigger scene every plane that asks to
 * cast shadows casts: the level of detail's estimate (lod.c) and rnd_casters_plan both follow
 * rnd_planes_judged(). */
#define RND_PLANES_JUDGED_MAX 256
bool rnd_planes_judged(const struct rnd_scene *sc);

/* rnd_plane_may_shadow, less the shadows no camera of the render sees: where the part of b
 * behind an opaque plane (from a light) is hidden from every camera of cams[ncam] by the
 * plane's own quad, the plane's shadow on it cannot show (objects sunk into the ground: their
 * buried parts). Cameras: the render's views; none = rnd_plane_may_shadow. rnd_casters_plan
 * passes each other object's bounds as asked (rnd_object_bounds): a sphere resting on the ground
 * whose segments the level of detail lowered dips a fraction of a millimetre below the ground
 * as drawn, and had made the ground a caster (thumb-256: a 2048^2 map drawn for that). */
bool rnd_plane_may_shadow_seen(const struct rnd_scene *sc, const struct rnd_object *plane, const struct rnd_aabb *b,
                               const struct rnd_camera_plan *cams, uint32_t ncam);

/* Whether a light of sc filters with moments (VSM / EVSM): their blurred moments need what lies
 * behind a caster's edge, the ground, in the map (against the empty map's far depth light bled
 * into the penumbrae), so rnd_casters_plan keeps every plane in the shadow pass. */
bool rnd_moments_need_ground(const struct rnd_scene *sc);

/* The draws' `cast` after the plane rules (draws[i].cast as the upload set it: the object asks
 * and is no shadow catcher), why[i] for each object (NULL: not wanted), and the box of what
 * casts (*casters), which sizes a `fit` sun map. bounds: the whole scene's, obj_bounds what
 * `fit: objects` frames (the cameras of the plane rule are planned on them). esc: the scene as
 * the shadow passes see it (sc's lights, then the environment's directions; sc itself without
 * them): a plane that shadows others only from those directions casts into their maps. */
void rnd_casters_plan(const struct rnd_scene *sc, const struct rnd_scene *esc, struct draw *draws,
                      const struct rnd_aabb *bounds, const struct rnd_aabb *obj_bounds, struct rnd_aabb *casters,
                      uint8_t *why);

/* Whether shadow view v of sp draws draw i (a caster inside its frustum) and, if so, with back
 * faces culled (*cull). lights: the lights sp was planned for. */
bool rnd_shadow_view_draws(const struct rnd_shadow_plan *sp, const struct rnd_light *lights, const struct draw *draws,
                           uint32_t v, uint32_t i, int *cull);

#endif
