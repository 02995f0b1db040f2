/*
 * renderer/caster_level — where a mesh's coarse caster level (struct rnd_caster_level, built by
 * api/model_caster.c) is drawn: in the environment's shadow maps only (the directional lights
 * env_shadow.c appends, RND_DIR_CASTERS), and only into a map whose texel is no finer than
 * the level's error over RND_CASTER_MAX_TEXELS. The camera and the scene's own lights' maps
 * (whose shadows can be sharp) draw the camera's level.
 *
 * The bias: the level's surface lies within its error e of the mesh's, both ways, so a map
 * drawn from it can put its depth up to e in front of the full-detail receiver (along the
 * light, e / cos of the surface's angle to it). A map drawing a caster level therefore draws
 * it moved e away from the light (its view-projection's depth row, exact for an orthographic
 * map) with the slope-scaled bias raised by sqrt(2) e / texel (the depth slope the hardware
 * sees is the larger of two axes' over a texel: at least 1/sqrt(2) of the gradient), i.e. by
 * e tan(angle): the receiver never finds the coarse caster in front of itself. What is lost
 * is up to that much of the contact shadow where a receiver touches the mesh.
 *
 * Usage: the plan lays a level out (rnd_caster_level_wanted, its counts), the upload writes
 * it (rnd_caster_write), and the shadow recorder, the cost model and `explain` all ask
 * rnd_caster_view_draw which triangles a map draws. Pure, no Vulkan, thread-safe.
 */
#ifndef UMBRA_RENDERER_CASTER_LEVEL_H
#define UMBRA_RENDERER_CASTER_LEVEL_H

#include "draw.h"
#include "mesh.h"
#include "plan.h"

/* The largest error, in texels of a map, of a caster level that map draws. The environment's
 * maps are filtered with PCSS over wide regions of the sky: their narrowest penumbra reaches
 * several texels and the blocker search 24 (plan.c); a caster's edge moved by 4 texels sits
 * inside that. */
#define RND_CASTER_MAX_TEXELS 4.0f

/* Whether object o (as the camera draws it: index_count indices) gets its caster level laid out
 * for this scene: a mesh with one, casting, opaque (a masked or blended material's depth pass
 * reads its texture), and the level at most half its triangles. */
bool rnd_caster_level_wanted(const struct rnd_scene *sc, const struct rnd_object *o, uint32_t index_count);

/* The level's error in world units: its object-space error times o->model's largest scale. */
float rnd_caster_world_error(const struct rnd_object *o);

/* Whether a shadow view (of light L, sv, orthographic or not) draws d's caster level: L is one
 * of the environment's (RND_DIR_CASTERS), the view orthographic, and the level's error within
 * RND_CASTER_MAX_TEXELS of its texel (sv->params[0]). */
bool rnd_caster_level_used(const struct rnd_light *L, const struct umbra_shadow_view *sv, bool ortho,
                           const struct draw *d);

/* Draw d as shadow view v draws it: its caster level (its range, no culling: a coarse level's
 * winding is not to be trusted) when the view is one of the environment's and its texel
 * allows the level, with *raise its d->env_raise (its error, world units: the view's depth
 * bias raise); else d and *raise 0. */
struct draw rnd_caster_view_draw(const struct rnd_shadow_plan *sp, const struct rnd_light *lights, uint32_t v,
                                 const struct draw *d, int *cull, float *raise);

/* view_proj (an orthographic map's) with what it draws moved `raise` world units away from
 * the light: its depth row's constant raised by raise times that row's length. */
void rnd_caster_view_proj(const float view_proj[16], float raise, float out[16]);

/* Slope-scaled bias to add for a raise of `raise` world units in a map of texel world size
 * `texel`: sqrt(2) raise / texel, rounded UP to a ladder of 2^(k / RND_CASTER_BIAS_STEPS) for
 * |k| <= RND_CASTER_BIAS_RANGE (at most 19 % more; the lowest step, 1/256, where less is
 * asked). Why a ladder: lavapipe (llvmpipe) JIT-compiles a triangle-setup function for every
 * distinct depth bias it is given (Mesa 22.3 keys its setup variants by the bias floats,
 * lp_state_setup.h, and keeps 64). A bias that followed each map's texel exactly made every
 * environment map drawn from a caster level compile one: ~7 ms each, 12 a request (the 100k
 * vertex-coloured corpus PLY's new maps: ~95 ms, against ~23 ms for the knot STL's 12 maps of
 * its camera level, which keep the light's own bias). On the ladder a daemon compiles each
 * value once, ~43 in all. */
#define RND_CASTER_BIAS_STEPS 4.0f
#define RND_CASTER_BIAS_RANGE 32.0f
float rnd_caster_slope_bias(float raise, float texel);

/* Writes o's caster level at vtx / idx (indices offset by base): world positions, the rest 0. */
void rnd_caster_write(const struct rnd_object *o, struct rnd_vertex *vtx, uint32_t *idx, uint32_t base);

#endif
