/*
 * api/scene_environment.c — `environment`: the background (a colour, or "map"), the hemisphere
 * ambient, the map (a Radiance .hdr or OpenEXR file by `path` under the asset root or by
 * multipart `part`, or the built-in `"preset": "studio"`; its `rotation` about +Y in degrees and
 * `intensity`) and its shadows. See scene_internal.h.
 *
 *   "environment": {"map": "sky.hdr"}                                 a path (the short form)
 *   "environment": {"map": {"part": "sky", "rotation": 90, "intensity": 0.5},
 *                   "background": "map", "shadow": {"directions": 16, "resolution": 512}}
 *
 * With a map the ambient defaults to none (the map is the ambient); one given adds to it.
 */
#include <stdlib.h>
#include <string.h>
#include "asset.h"
#include "env_map.h"
#include "scene_internal.h"

static const char *const ENV_MEMBERS[] = {"background", "ambient", "map", "shadow", NULL};
static const char *const AMBIENT_MEMBERS[] = {"sky", "ground", "intensity", NULL};
static const char *const MAP_MEMBERS[] = {"path", "part", "preset", "rotation", "intensity", NULL};
static const char *const SHADOW_MEMBERS[] = {"directions", "resolution", NULL};
static const char *const MAP_PRESETS[] = {"studio", NULL};

/* The map file's bytes from its source member `key` (value v, the pointer at it), decoded. */
static int map_file(struct pctx *c, const char *key, json_t *v, struct rnd_environment *env)
{
	unsigned char *owned = NULL;
	const uint8_t *b = NULL;
	size_t len = 0;
	int rc;
	if (!strcmp(key, "part")) {
		rc = api_part_bytes(c, v, &b, &len);
	} else if (!json_is_string(v)) {
		rc = api_fail(c, "path must be a string, not %s", api_type_name(v));
	} else {
		struct api_asset_stamp stamp;
		rc = api_path_bytes(c, json_string_value(v), &owned, &len, &stamp);
		b = owned;
		/* the answer depends on the file: the ETag and the caches must too */
		if (!rc) api_asset_hash(&c->asset_hash, json_string_value(v), b, len);
	}
	if (rc) return rc;
	struct api_env_map *m;
	int status;
	char err[240];
	if (api_env_map_get(b, len, &m, &status, err, sizeof err) != API_OK) {
		api_problem_set(c->p, status, c->ptr, "the environment map cannot be read: %s", err);
		free(owned);
		return -1;
	}
	free(owned);
	api_env_map_release(c->env_map);   /* one map a scene */
	c->env_map = m;
	env->source = RND_ENV_MAP;
	env->map = (struct rnd_env_map){m->rgb, m->width, m->height, m->key};
	if (m->file_width != 2 * m->file_height)
		api_warn(c, "%s: the map is %ux%u, not 2:1: it is read as equirectangular all the same", c->ptr, m->file_width,
		         m->file_height);
	return 0;
}

/* `map`: a path, or {path | part | preset, rotation, intensity}. */
static int parse_map(struct pctx *c, json_t *j, struct rnd_environment *env)
{
	if (json_is_string(j)) return map_file(c, "path", j, env);
	if (!json_is_object(j))
		return api_fail(c, "map must be a file's path or an object (path, part or preset; rotation, intensity), not %s",
		                api_type_name(j));
	if (api_check_members(c, j, MAP_MEMBERS, NULL, "an environment map") < 0) return -1;
	static const char *const sources[] = {"path", "part", "preset"};
	const char *first = NULL;
	for (int i = 0; i < 3; i++) {
		if (!json_object_get(j, sources[i])) continue;
		if (first)
			return api_fail_at(c, sources[i], "%s cannot be combined with %s: a map has one source", sources[i], first);
		first = sources[i];
	}
	if (!first) return api_fail(c, "a map needs one of path (a .hdr or .exr under the asset root), part or preset");
	static const struct range any = {-1e6, 1e6, false, false};
	if (api_get_angle(c, j, "rotation", &any, &env->rotation) < 0 ||
	    api_get_float(c, j, "intensity", &R_NONNEG, &env->intensity) < 0)
		return -1;
	if (!strcmp(first, "preset")) {
		int p;
		if (api_get_enum(c, j, "preset", MAP_PRESETS, &p) < 0) return -1;
		env->source = RND_ENV_STUDIO;
		return 0;
	}
	size_t old = api_ptr_push(c, first);
	int rc = map_file(c, first, json_object_get(j, first), env);
	api_ptr_pop(c, old);
	return rc;
}

/* `shadow`: a boolean, or {directions, resolution}. */
static int parse_shadow(struct pctx *c, json_t *j, struct rnd_environment *env)
{
	c->env_shadow_given = true;
	if (json_is_boolean(j)) {
		env->shadow_directions = json_is_true(j) ? RND_DEFAULT_ENV_DIRECTIONS : 0;
		return 0;
	}
	if (!json_is_object(j))
		return api_fail(c, "shadow must be a boolean or an object (directions, resolution), not %s", api_type_name(j));
	if (api_check_members(c, j, SHADOW_MEMBERS, NULL, "the environment's shadow") < 0 ||
	    api_get_u32(c, j, "directions", 0, RND_MAX_ENV_DIRECTIONS, &env->shadow_directions) < 0 ||
	    api_get_u32(c, j, "resolution", RND_MIN_SHADOW_RESOLUTION, 4096, &env->shadow_resolution) < 0)
		return -1;
	if (env->shadow_resolution && c->lim->max_shadow_resolution && env->shadow_resolution > c->lim->max_shadow_resolution)
		api_defer(c, false, "resolution", "resolution %u is over this server's limit of %u", env->shadow_resolution,
		          c->lim->max_shadow_resolution);
	return 0;
}

static int parse_ambient(struct pctx *c, json_t *j, struct rnd_environment *env, bool *given)
{
	json_t *sub;
	size_t old;
	int rc = api_enter(c, j, "ambient", AMBIENT_MEMBERS, "the ambient light", &sub, &old);
	*given = rc > 0;
	if (rc <= 0) return rc;
	rc = api_get_vec(c, sub, "sky", env->ambient_sky, 3, 3, V_NONNEG) < 0 ||
	     api_get_vec(c, sub, "ground", env->ambient_ground, 3, 3, V_NONNEG) < 0 ||
	     api_get_float(c, sub, "intensity", &R_NONNEG, &env->ambient_intensity) < 0;
	api_ptr_pop(c, old);
	return rc ? -1 : 0;
}

/* A member that is an object or a value parsed by fn with the pointer at it; 0 when absent. */
static int member(struct pctx *c, json_t *j, const char *key, int (*fn)(struct pctx *, json_t *, struct rnd_environment *),
                  struct rnd_environment *env)
{
	json_t *v = json_object_get(j, key);
	if (!v) return 0;
	size_t old = api_ptr_push(c, key);
	int rc = fn(c, v, env);
	api_ptr_pop(c, old);
	return rc;
}

int api_parse_environment(struct pctx *c, json_t *j, struct rnd_environment *env)
{
	if (api_require_object(c, j, "environment") < 0 ||
	    api_check_members(c, j, ENV_MEMBERS, NULL, "the environment") < 0)
		return -1;
	json_t *bgv = json_object_get(j, "background");
	if (json_is_string(bgv)) {
		if (strcmp(json_string_value(bgv), "map"))
			return api_fail_at(c, "background", "background must be a colour [r, g, b(, a)] or \"map\", not \"%.32s\"",
			                   json_string_value(bgv));
		env->background_map = true;
	} else {
		float bg[4] = {0, 0, 0, 1};
		int n = api_get_vec(c, j, "background", bg, 3, 4, V_NONNEG | V_ALPHA01);
		if (n < 0) return -1;
		if (n) memcpy(env->background, bg, sizeof bg);
	}
	bool ambient;
	if (parse_ambient(c, j, env, &ambient) < 0 || member(c, j, "map", parse_map, env) < 0 ||
	    member(c, j, "shadow", parse_shadow, env) < 0)
		return -1;
	if (env->background_map && env->source == RND_ENV_AMBIENT)
		return api_fail_at(c, "background", "background \"map\" shows the environment map: give environment.map");
	if (env->source != RND_ENV_AMBIENT && !ambient) env->ambient_intensity = 0.0f;   /* the map is the ambient */
	return 0;
}

int api_check_environment(struct pctx *c, const struct rnd_shadow *root_shadow, struct rnd_scene *sc)
{
	struct rnd_environment *env = &sc->environment;
	if (!root_shadow->enabled && !c->env_shadow_given) env->shadow_directions = 0;
	if (sc->output.debug == RND_DEBUG_ENV_SHADOW && env->source == RND_ENV_AMBIENT) {
		api_problem_set(c->p, 400, "/output/debug", "debug \"environment_shadow\" shows the share of the environment "
		                "map's light that reaches each pixel: give environment.map");
		return -1;
	}
	if (env->background_map && sc->output.transparent) {
		api_problem_set(c->p, 400, "/environment/background", "background \"map\" draws the map behind the scene; "
		                "output.transparent asks for no background: choose one");
		return -1;
	}
	return 0;
}
