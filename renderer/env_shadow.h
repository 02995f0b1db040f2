/*
 * renderer/env_shadow.h — the environment's shadow directions as the scene's extra lights (see
 * env_shadow.c). Pure: no Vulkan calls.
 */
#ifndef UMBRA_RENDERER_ENV_SHADOW_H
#define UMBRA_RENDERER_ENV_SHADOW_H

#include "draw.h"
#include "env_analysis.h"

/* Whether the scene stands on a ground (env_shadow.c says what counts): true with its normal. */
bool rnd_env_ground(const struct rnd_scene *sc, const struct draw *draws, float n[3]);
/* The directional lights of the plan's mapped directions, at most room of them, into out: their
 * count. Each: a map fitted to the casters at env->shadow_resolution (0: the default), PCSS, no
 * light of its own (intensity 0). */
uint32_t rnd_env_lights(const struct rnd_env_plan *dirs, const struct rnd_environment *env, uint32_t room,
                        struct rnd_light *out);
/* How rnd_env_lights sizes their maps, in words (the plan shows it). */
const char *rnd_env_lights_size_text(void);
/* Whether a view's environment shadows come from the environment pass (env_pass.h): it has
 * mapped directions, no alpha-tested draw (the surfaces pass does not cut texels out) and no
 * debug view but environment_shadow's (or cascades'). force: UMBRA_ENV_PASS, 0 computes them
 * per fragment instead (tests); -1 unset. */
bool rnd_env_pass_wanted(const struct rnd_scene *sc, uint32_t mapped, const struct draw *draws, uint32_t ndraw,
                         int force);

#endif
