/*
 * renderer/env_shadow.h — the environment's shadow directions as the scene's extra lights (see
 * env_shadow.c). Pure: no Vulkan calls.
 */
#ifndef UMBRA_RENDERER_ENV_SHADOW_H
#define UMBRA_RENDERER_ENV_SHADOW_H

#include "env.h"
#include "record.h"

/* Whether the scene stands on a ground (env_shadow.c says what counts): true with its normal. */
bool rnd_env_ground(const struct rnd_scene *sc, const struct draw *draws, float n[3]);
/* The directional lights of use's mapped directions, at most room of them, into out: their
 * count. Each: a map fitted to the casters at env->shadow_resolution (0: the default), PCF, no
 * light of its own (intensity 0). */
uint32_t rnd_env_lights(const struct rnd_env_use *use, const struct rnd_environment *env, uint32_t room,
                        struct rnd_light *out);

#endif
