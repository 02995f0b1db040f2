/*
 * renderer/env_shadow.c — the environment's shadows as lights the shadow machinery already
 * knows: each shadow direction of the map (env_analysis.h rnd_env_plan_dirs, a median-cut region of
 * its light) becomes a directional light appended after the scene's own, whose one map is
 * fitted to what casts (RND_DIR_CASTERS) and drawn, cached and reused like any sun's. They are
 * never shaded as lights: shaders/ibl.glsl env_visibility() reads their maps and weighs each by
 * its region's light on the surface's normal (frame.c gives the main pass only the scene's own
 * lights to shade).
 *
 * A ground: an opaque plane that casts, faces +Y and holds every other object above it, under
 * their whole footprint. The sky below its horizon is hidden from everything above it, so those
 * directions are weighed with visibility 0 and get no map (the light of a studio floor or of
 * the earth in an outdoor map then costs nothing), and the maps go where they show.
 */
#include <math.h>
#include <string.h>
#include "env_shadow.h"

#define PI_F 3.14159265358979f

bool rnd_env_ground(const struct rnd_scene *sc, const struct draw *draws, float n[3])
{
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		const struct draw *d = &draws[i];
		if (o->shape != RND_SHAPE_PLANE || !o->cast_shadows || !d->index_count) continue;
		if (sc->material_count) {
			const struct rnd_material *m = &sc->materials[o->material];
			if (m->shadow_catcher || m->alpha_mode != RND_ALPHA_OPAQUE) continue;
		}
		float nm[16], up[3] = {0, 1, 0}, pn[3];
		if (!rnd_mat4_normal_matrix(nm, o->model)) continue;
		rnd_mat4_mul_dir(pn, nm, up);
		if (!rnd_v3_normalize(pn, pn) || pn[1] < 0.999f) continue;
		/* the plane is flat in y (its normal is +Y): every other object above it and inside it */
		float y = 0.5f * (d->bounds.min[1] + d->bounds.max[1]), eps = 1e-3f;
		bool holds = true;
		for (uint32_t j = 0; j < sc->object_count && holds; j++) {
			const struct rnd_aabb *b = &draws[j].bounds;
			if (j == i || !draws[j].index_count) continue;
			holds = b->min[1] >= y - eps && b->min[0] >= d->bounds.min[0] && b->max[0] <= d->bounds.max[0] &&
			        b->min[2] >= d->bounds.min[2] && b->max[2] <= d->bounds.max[2];
		}
		if (!holds) continue;
		n[0] = 0.0f; n[1] = 1.0f; n[2] = 0.0f;
		return true;
	}
	return false;
}

bool rnd_env_pass_wanted(const struct rnd_scene *sc, uint32_t mapped, const struct draw *draws, uint32_t ndraw,
                         int force)
{
	if (!mapped || force == 0) return false;
	if (sc->output.debug != RND_DEBUG_NONE && sc->output.debug != RND_DEBUG_ENV_SHADOW &&
	    sc->output.debug != RND_DEBUG_CASCADES)
		return false;
	for (uint32_t i = 0; i < ndraw; i++)
		if (draws[i].index_count && draws[i].masked) return false;
	return true;
}

uint32_t rnd_env_lights(const struct rnd_env_plan *use, const struct rnd_environment *env, uint32_t room,
                        struct rnd_light *out)
{
	uint32_t n = use->mapped < room ? use->mapped : room;
	uint32_t top = env->shadow_resolution ? env->shadow_resolution : RND_DEFAULT_ENV_SHADOW_RESOLUTION;
	for (uint32_t k = 0; k < n; k++) {
		struct rnd_light *L = &out[k];
		/* A wide region's shadow is a wide penumbra: PCSS reaches a fixed number of texels
		 * (plan.c search_texels), so its map gets coarser texels (and costs less to draw): a
		 * sun-sized region the full resolution, a twelfth of the sky (sin r ~0.55) a quarter of
		 * it. Measured against Cycles (four scenes, 12 directions, ground RMSE): 6 here 0.026-
		 * 0.041, 14 0.031-0.046, 20 0.032-0.046; the full resolution everywhere showed the
		 * wide regions' shadows as a dozen distinct ones (0.031-0.049, models 0.09-0.11). */
		float want = (float)top / (1.0f + 6.0f * use->dirs[k].sin_radius);
		uint32_t res = top;
		while (res > RND_MIN_SHADOW_RESOLUTION && (float)res > want * 1.5f) res /= 2;
		rnd_light_defaults(L, RND_LIGHT_DIRECTIONAL);
		for (int c = 0; c < 3; c++) L->direction[c] = -use->dirs[k].dir[c];
		L->angular_diameter = 2.0f * asinf(fminf(use->dirs[k].sin_radius, 1.0f));
		L->intensity = 0.0f;
		L->shadow.filter = RND_FILTER_PCSS;
		L->shadow.dir_mode = RND_DIR_CASTERS;
		L->shadow.resolution = res;
	}
	return n;
}

const char *rnd_env_lights_size_text(void)
{
	return "the environment's shadow_resolution, coarser for a wider region (env_shadow.c)";
}
