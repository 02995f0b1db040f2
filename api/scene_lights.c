/*
 * api/scene_lights.c — `lights` (directional, spot, point; each with its shadow settings over
 * the root's). See scene_internal.h.
 */
#include <stdio.h>
#include <string.h>
#include "scene_internal.h"


static const char *const LIGHT_COMMON[] = {"type", "name", "color", "intensity", "shadow", NULL};
static const char *const LIGHT_TYPES[] = {"directional", "spot", "point", NULL};
static const char *const LIGHT_MEMBERS[][7] = {
	{"direction", "angular_diameter", NULL},
	{"position", "direction", "range", "inner_angle", "outer_angle", "radius", NULL},
	{"position", "range", "radius", NULL},
};

static int parse_light(struct pctx *c, json_t *j, struct rnd_light *l, const struct rnd_shadow *root_shadow)
{
	if (api_require_object(c, j, "each entry of lights") < 0) return -1;
	if (!json_object_get(j, "type"))
		return api_fail_at(c, "type", "type is required (one of \"directional\", \"spot\", \"point\")");
	int type;
	if (api_get_enum(c, j, "type", LIGHT_TYPES, &type) < 0) return -1;
	char what[32];
	snprintf(what, sizeof what, "a %s light", LIGHT_TYPES[type]);
	if (api_check_members(c, j, LIGHT_COMMON, LIGHT_MEMBERS[type], what) < 0) return -1;
	static const enum rnd_light_type types[] = {RND_LIGHT_DIRECTIONAL, RND_LIGHT_SPOT, RND_LIGHT_POINT};
	rnd_light_defaults(l, types[type]);
	const char *name;
	if (api_get_string(c, j, "name", &name) < 0) return -1;
	if (type != 2) {
		int rc = api_get_vec(c, j, "direction", l->direction, 3, 3, V_NONZERO);
		if (rc < 0) return -1;
		if (!rc) return api_fail_at(c, "direction", "direction is required for %s", what);
	}
	if (type != 0) {
		int rc = api_get_vec(c, j, "position", l->position, 3, 3, 0);
		if (rc < 0) return -1;
		if (!rc) return api_fail_at(c, "position", "position is required for %s", what);
	}
	if (api_get_vec(c, j, "color", l->color, 3, 3, V_NONNEG) < 0 ||
	    api_get_float(c, j, "intensity", &R_NONNEG, &l->intensity) < 0)
		return -1;
	static const struct range diameter = {0, 90, false, true}, inner = {0, 90, false, true},
	                          outer = {0, 90, true, true};
	if (type == 0 && api_get_angle(c, j, "angular_diameter", &diameter, &l->angular_diameter) < 0) return -1;
	if (type != 0 && (api_get_float(c, j, "range", &R_NONNEG, &l->range) < 0 ||
	                  api_get_float(c, j, "radius", &R_NONNEG, &l->radius) < 0))
		return -1;
	if (type == 1) {
		double in = 0, out = 45;
		if (api_get_num(c, j, "inner_angle", &inner, &in) < 0 || api_get_num(c, j, "outer_angle", &outer, &out) < 0)
			return -1;
		if (in > out) {
			const char *key = json_object_get(j, "inner_angle") ? "inner_angle" : "outer_angle";
			return api_fail_at(c, key, "inner_angle (%g) must not be greater than outer_angle (%g)", in, out);
		}
		l->inner_angle = (float)(in * DEG2RAD);
		l->outer_angle = (float)(out * DEG2RAD);
	}
	l->shadow = *root_shadow;
	json_t *sh = json_object_get(j, "shadow");
	if (json_is_boolean(sh)) {
		l->shadow.enabled = json_is_true(sh);
		api_member_read(c, j, "shadow");
	} else if (sh) {
		size_t old = api_ptr_push(c, "shadow");
		int rc = json_is_object(sh) ? api_parse_shadow(c, sh, &l->shadow, "shadow")
		         : api_fail(c, "shadow must be an object of shadow settings or a boolean, not %s", api_type_name(sh));
		api_ptr_pop(c, old);
		if (rc < 0) return -1;
	}
	return 0;
}


int api_parse_lights(struct pctx *c, json_t *root, struct rnd_scene *sc, const struct rnd_shadow *root_shadow)
{
	json_t *lights = json_object_get(root, "lights");
	if (!lights) return api_check_shadow_use(c, root, sc);
	if (!json_is_array(lights))
		return api_fail_at(c, "lights", "lights must be an array, not %s", api_type_name(lights));
	size_t n = json_array_size(lights);
	if (n > UINT32_MAX / 2) return api_fail_at(c, "lights", "too many lights");
	struct rnd_light *ls = api_arena_calloc(c->arena, n ? n : 1, sizeof *ls);
	if (!ls) return api_fail(c, "out of memory");
	size_t old = api_ptr_push(c, "lights");
	int rc = 0;
	for (size_t i = 0; !rc && i < n; i++) {
		size_t o2 = api_ptr_index(c, i);
		rc = parse_light(c, json_array_get(lights, i), &ls[i], root_shadow);
		api_ptr_pop(c, o2);
	}
	if (!rc && c->lim->max_lights && n > c->lim->max_lights)
		api_defer(c, false, NULL, "the scene has %zu lights, over this server's limit of %u", n,
		      c->lim->max_lights);
	api_ptr_pop(c, old);
	if (rc) return -1;
	sc->lights = ls;
	sc->light_count = (uint32_t)n;
	return api_check_shadow_use(c, root, sc);
}
