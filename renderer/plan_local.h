/*
 * renderer/plan_local.h — the shadow views of spot and point lights (plan_local.c), for plan.c:
 * their tile size by importance or a hard edge's need, then the spot's cone cut down to where
 * its casters are and both sized for where the camera sees them. Pure math, as plan.c.
 */
#ifndef UMBRA_RENDERER_PLAN_LOCAL_H
#define UMBRA_RENDERER_PLAN_LOCAL_H

#include "plan.h"

/* Farthest distance from p to the box. */
float rnd_plan_max_dist(const float p[3], const struct rnd_aabb *b);

/* Width in texels of the narrowest footprint lp's filter blurs an edge over (plan.c). */
float rnd_plan_kernel_texels(const struct rnd_light_plan *lp);

/* The next shadow view of light i in out (plan.c). */
struct umbra_shadow_view *rnd_plan_next_view(struct rnd_shadow_plan *out, uint32_t i, bool ortho);

/* Tile size a spot or point light without a resolution of its own asks for before its casters
 * are known: its share of the view, or what a hard edge needs; *rule says which. */
uint32_t rnd_plan_local_want(const struct rnd_light *L, const struct rnd_light_plan *lp, const struct rnd_aabb *bounds,
                             const struct rnd_camera_plan *cam, uint32_t height, uint8_t *rule);

/* Where the camera and the casters are, for rnd_plan_local (casters NULL or cam NULL: the
 * light's whole cone or cube at lp->resolution, as before). */
/* With more shadowed spot and point lights than this, their maps keep the whole cone / cube
 * face at the importance size (no fit to the casters): finer texels on many lights cost the
 * main pass (16 shadowed lights 405 -> 627 ms on lavapipe) and their growth over-filled the
 * atlas, which then cut another light's map (studio-spots: its sun 2048 -> 512). The fit is for
 * the one or two lights a picture's shadows come from. */
#define RND_LOCAL_FIT_LIGHTS_MAX 2u

struct rnd_local_need {
	const struct rnd_aabb *bounds, *casters; /* casters NULL: no fit (RND_LOCAL_FIT_LIGHTS_MAX) */
	const struct rnd_camera_plan *cam;
	uint32_t height;     /* output image height (0: no camera need) */
	uint32_t cap;        /* the scene's max_shadow_resolution (0: none) */
	uint32_t default_res; /* this light's tile without an asked resolution (rnd_plan_local_want) */
};

/* Light i's views: a spot's one perspective map, a point light's six cube faces; may change
 * lp->resolution and lp->size_rule (see plan_local.c). */
enum rnd_result rnd_plan_local(const struct rnd_light *L, uint32_t i, const struct rnd_local_need *need,
                               struct rnd_light_plan *lp, struct rnd_shadow_plan *out, struct rnd_error *err);

/* A perspective view v (a spot's, a cube face's; planned at v->rect[2] texels) drawn into a
 * smaller tile than planned (rnd_atlas_fit: the atlas full): widened about its centre so that
 * what it covered still lies the filter's margin of *granted* texels inside (six 4096 faces
 * granted 1024 kept a quarter of PCSS's 27-texel margin). Call before the texel's world size
 * is scaled to the grant (render_plan.c). */
void rnd_plan_local_regrant(struct umbra_shadow_view *v, const struct rnd_light_plan *lp, float granted);

#endif
