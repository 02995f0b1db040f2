/*
 * renderer/plan.h — per-render CPU planning: the camera (camera.c: view, reversed-Z projection,
 * derived near/far) and the shadow views of every light (plan.c: fit, cascades, spot cone,
 * point cube faces).
 *
 * Pure math: no Vulkan calls, no allocation; unit-tested in tests/unit/test_plan_*.c.
 */
#ifndef UMBRA_RENDERER_PLAN_H
#define UMBRA_RENDERER_PLAN_H

#include "umbra/rnd.h"
#include "umbra/rnd_math.h"
#include "umbra_shared.h"

struct rnd_camera_plan {
	float view[16], proj[16], view_proj[16];   /* proj is reversed-Z: near -> 1, far -> 0 */
	float pos[3], fwd[3], up[3];
	float znear, zfar;
	float user_near, user_far;                 /* as the caller gave them (0 = derived) */
	float fov_y, aspect;                       /* perspective */
	float ortho_height;                        /* orthographic */
	bool ortho;
};

/* Resolves the camera against the scene bounds (fit, derived near/far). bounds may be empty. */
enum rnd_result rnd_camera_plan(const struct rnd_camera *cam, uint32_t width, uint32_t height,
                                const struct rnd_aabb *bounds, struct rnd_camera_plan *out, struct rnd_error *err);

struct rnd_light_plan {
	uint32_t first_view, view_count;           /* view_count 0 = unshadowed */
	uint32_t filter;                           /* UMBRA_FILTER_* */
	uint32_t pcf_radius;
	float bias_constant, bias_slope, bias_normal;
	float splits[4];                           /* cascades: far view depth of each */
	float search_texels;                       /* PCSS blocker search cap */
	bool clipmap;                              /* views are clipmap levels (else cascades / one map) */
	bool follows_camera;                       /* a sun's cascades or clipmap levels, however many:
	                                              drawn for every view, never kept (render.c) */
	float max_distance;                        /* view depth where shadows end (0 = never) */
	float fade_start;                          /* view depth where the fade to unshadowed starts */
	bool moments;                              /* VSM / EVSM: moment maps are built from the depth */
	bool evsm;
	float evsm_exponent;                       /* 0 = by precision (render.c decides) */
	float moment_edge;                         /* texels along a `fit` sun map's edge read as lit: a
	                                              moment map fitted to the casters (plan.c) */
	bool fp16;                                 /* vsm.precision fp16 asked for */
	uint32_t resolution;                       /* tile size asked for (power of two) */
	uint8_t size_rule;                         /* enum rnd_size_rule: what chose the resolution */
};

/* What chose a light's map size (rnd_light_plan.size_rule; the render plan shows it). */
enum rnd_size_rule {
	RND_SIZE_ASKED,        /* the light's shadow.resolution (a power of two at or above it) */
	RND_SIZE_DEFAULT,      /* a sun's default (RND_DEFAULT_SHADOW_RESOLUTION) */
	RND_SIZE_IMPORTANCE,   /* a spot or point light's share of the view (light_importance_res) */
	RND_SIZE_HARD_EDGE,    /* a hard light's kernel within a pixel (hard_light_res) */
	RND_SIZE_CASTERS,      /* a `fit` sun map or a spot's cone cut to the casters' box, or a point light's
	                          faces, texels for where the camera sees the casters (fit_casters, plan_local.c) */
	RND_SIZE_CAPPED,       /* the scene's max_shadow_resolution (a server's cap) */
	RND_SIZE_SEARCH,       /* a PCSS map on the casters: texels no finer than its blocker search reaches
	                          the widest penumbra its casters cast (plan_local.c; a sun's, fit_casters,
	                          where that is coarser than the whole scene's) */
	RND_SIZE_ATLAS,        /* a spot or point light's tiles as large as the atlas holds them alone */
	RND_SIZE_RULE_COUNT
};
/* A rule in words ("" for none). */
const char *rnd_size_rule_text(unsigned rule);
/* A limit written once, as a plain integer (no suffix), in the words that show it: "more than "
 * RND_NUMBER_WORDS(RND_PLANES_JUDGED_MAX) " objects" is "more than 256 objects". */
#define RND_NUMBER_WORDS(x) RND_NUMBER_WORDS_(x)
#define RND_NUMBER_WORDS_(x) #x
/* What kind of map light L's plan lp draws: "casters", "spot", "cube", "clipmap", "cascades", "fit". */
const char *rnd_light_plan_kind(const struct rnd_light *L, const struct rnd_light_plan *lp);

struct rnd_shadow_plan {
	uint32_t resolution;                       /* the largest tile any light asks for */
	uint32_t view_count;
	struct umbra_shadow_view views[UMBRA_MAX_SHADOW_VIEWS];
	uint32_t view_light[UMBRA_MAX_SHADOW_VIEWS]; /* light index of each view */
	bool view_ortho[UMBRA_MAX_SHADOW_VIEWS];     /* skip near-plane culling (depth clamp) */
	bool view_skip[UMBRA_MAX_SHADOW_VIEWS];      /* tile already holds this map (render.c sets) */
	struct rnd_light_plan lights[UMBRA_MAX_LIGHTS];
};

/* Plans every light's shadow views. Fails (RND_ERR_INVALID / RND_ERR_LIMIT) for settings the
 * renderer cannot honour, saying which light and why. */
enum rnd_result rnd_shadow_plan(const struct rnd_scene *scene, const struct rnd_aabb *bounds,
                                const struct rnd_camera_plan *cam, struct rnd_shadow_plan *out, struct rnd_error *err);
/* The same, with the `auto` directional choice made by the caller: cascades[i] 1 = cascades,
 * 0 = fit (later views of a request keep view 0's choice, so they need the same tiles); and
 * with the bounds of what casts shadows (casters, within bounds; empty: nothing casts), which
 * a `fit` sun map covers instead of the whole scene, in a smaller tile, with texels no coarser
 * than the whole scene's and finer where cam sees the casters close (plan.c fit_casters; a
 * light asking for a resolution gets that tile on the casters) (NULL: the whole
 * scene, as rnd_shadow_plan); atlas: the shadow atlas's side in texels (0: unknown), which
 * caps a spot or point light's tiles at what the atlas holds of them alone (RND_SIZE_ATLAS). */
enum rnd_result rnd_shadow_plan_with(const struct rnd_scene *scene, const struct rnd_aabb *bounds,
                                     const struct rnd_aabb *casters, const struct rnd_camera_plan *cam,
                                     const uint8_t *cascades, uint32_t atlas,
                                     struct rnd_shadow_plan *out, struct rnd_error *err);

/* Practical split scheme: far distance of each of n cascades between znear and zfar,
 * lambda 0 = uniform, 1 = logarithmic. */
void rnd_cascade_splits(float znear, float zfar, uint32_t n, float lambda, float out[4]);

/* True when the box is (conservatively) at least partly inside the clip volume of m.
 * With no_near the near plane is ignored (depth clamp catches casters in front of it). */
bool rnd_aabb_in_frustum(const struct rnd_aabb *b, const float m[16], bool no_near);

#endif
