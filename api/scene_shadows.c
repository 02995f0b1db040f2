/*
 * api/scene_shadows.c — shadow settings: the root `shadows` (object or boolean) over the
 * renderer's defaults, and each light's `shadow` over the root's (scene_lights.c); then, once
 * every light is known, which of the settings given are used (api_check_shadow_use).
 * See scene_internal.h.
 */
#include <stdio.h>
#include <string.h>
#include "scene_internal.h"

static const char *const SHADOW_MEMBERS[] = {"enabled", "filter", "resolution", "pcf_radius", "bias",
                                             "directional", "vsm", "contact", NULL};
static const char *const BIAS_MEMBERS[] = {"constant", "slope", "normal", NULL};
static const char *const DIRECTIONAL_MEMBERS[] = {"mode", "cascades", "split_lambda", "max_distance", "blend",
                                                  "fade", "clipmap_levels", "clipmap_extent", NULL};
static const char *const VSM_MEMBERS[] = {"precision", "blur", "light_bleed_reduction", "exponent", NULL};
static const char *const CONTACT_MEMBERS[] = {"enabled", "distance", "steps", "thickness", NULL};

/* Applies the members present in j over *s (root settings, then a light's own). */
int api_parse_shadow(struct pctx *c, json_t *j, struct rnd_shadow *s, const char *what)
{
	if (api_require_object(c, j, what) < 0 || api_check_members(c, j, SHADOW_MEMBERS, NULL, "shadow settings") < 0)
		return -1;
	static const char *const filters[] = {"auto", "hard", "pcf", "pcss", "vsm", "evsm", NULL};
	static const enum rnd_filter filter_values[] = {RND_FILTER_AUTO, RND_FILTER_HARD, RND_FILTER_PCF,
	                                                RND_FILTER_PCSS, RND_FILTER_VSM, RND_FILTER_EVSM};
	int e, rc;
	if (api_get_bool(c, j, "enabled", &s->enabled) < 0) return -1;
	if ((rc = api_get_enum(c, j, "filter", filters, &e)) < 0) return -1;
	if (rc) s->filter = filter_values[e];
	if ((rc = api_get_u32(c, j, "resolution", RND_MIN_SHADOW_RESOLUTION, RND_MAX_SHADOW_RESOLUTION, &s->resolution)) < 0) return -1;
	/* What is drawn is the power of two at or above it (an atlas tile). */
	uint32_t side = rc ? rnd_shadow_map_side(s->resolution, true, 0) : 0;
	if (rc && c->lim->max_shadow_resolution && side > c->lim->max_shadow_resolution) {
		char drawn[64] = "";
		if (side != s->resolution) snprintf(drawn, sizeof drawn, " (drawn as %u: maps are powers of two)", side);
		api_defer(c, false, "resolution", "shadow resolution %u%s is over this server's limit of %u", s->resolution,
		          drawn, c->lim->max_shadow_resolution);
	}
	if (api_get_u32(c, j, "pcf_radius", 0, 5, &s->pcf_radius) < 0) return -1;

	json_t *sub;
	size_t old;
	if ((rc = api_enter(c, j, "bias", BIAS_MEMBERS, "bias", &sub, &old)) < 0) return -1;
	if (rc) {
		rc = api_get_float(c, sub, "constant", &R_NONNEG, &s->bias_constant) < 0 ||
		     api_get_float(c, sub, "slope", &R_NONNEG, &s->bias_slope) < 0 ||
		     api_get_float(c, sub, "normal", &R_NONNEG, &s->bias_normal) < 0;
		api_ptr_pop(c, old);
		if (rc) return -1;
		s->bias_set = true;
	}
	if ((rc = api_enter(c, j, "directional", DIRECTIONAL_MEMBERS, "directional shadow settings", &sub, &old)) < 0)
		return -1;
	if (rc) {
		static const char *const modes[] = {"auto", "fit", "cascades", "clipmap", NULL};
		static const enum rnd_dir_mode mode_values[] = {RND_DIR_AUTO, RND_DIR_FIT, RND_DIR_CASCADES,
		                                                RND_DIR_CLIPMAP};
		int m = -1;
		rc = api_get_enum(c, sub, "mode", modes, &m) < 0 ||
		     api_get_u32(c, sub, "cascades", 1, 4, &s->cascades) < 0 ||
		     api_get_float(c, sub, "split_lambda", &R_UNIT, &s->split_lambda) < 0 ||
		     api_get_float(c, sub, "max_distance", &R_POS, &s->max_distance) < 0 ||
		     api_get_float(c, sub, "blend", &R_UNIT, &s->blend) < 0 ||
		     api_get_float(c, sub, "fade", &R_UNIT, &s->fade) < 0 ||
		     api_get_u32(c, sub, "clipmap_levels", 1, 8, &s->clipmap_levels) < 0 ||
		     api_get_float(c, sub, "clipmap_extent", &R_POS, &s->clipmap_extent) < 0;
		api_ptr_pop(c, old);
		if (rc) return -1;
		if (m >= 0) s->dir_mode = mode_values[m];
	}
	if ((rc = api_enter(c, j, "vsm", VSM_MEMBERS, "vsm settings", &sub, &old)) < 0) return -1;
	if (rc) {
		static const char *const precisions[] = {"auto", "fp32", "fp16", NULL};
		static const enum rnd_vsm_precision prec_values[] = {RND_VSM_AUTO, RND_VSM_FP32, RND_VSM_FP16};
		static const struct range blur = {0, RND_MAX_VSM_BLUR, false, false}, expo = {0, 42, true, false};
		int pr = -1;
		rc = api_get_enum(c, sub, "precision", precisions, &pr) < 0 ||
		     api_get_float(c, sub, "blur", &blur, &s->vsm_blur) < 0 ||
		     api_get_float(c, sub, "light_bleed_reduction", &R_UNIT, &s->vsm_light_bleed) < 0 ||
		     api_get_float(c, sub, "exponent", &expo, &s->vsm_exponent) < 0;
		api_ptr_pop(c, old);
		if (rc) return -1;
		if (pr >= 0) s->vsm_precision = prec_values[pr];
	}
	if ((rc = api_enter(c, j, "contact", CONTACT_MEMBERS, "contact shadow settings", &sub, &old)) < 0) return -1;
	if (rc) {
		rc = api_get_bool(c, sub, "enabled", &s->contact_enabled) < 0 ||
		     api_get_float(c, sub, "distance", &R_POS, &s->contact_distance) < 0 ||
		     api_get_u32(c, sub, "steps", 1, 256, &s->contact_steps) < 0 ||
		     api_get_float(c, sub, "thickness", &R_POS, &s->contact_thickness) < 0;
		api_ptr_pop(c, old);
		if (rc) return -1;
	}
	return 0;
}


int api_parse_root_shadow(struct pctx *c, json_t *root, struct rnd_shadow *s)
{
	rnd_shadow_defaults(s);
	json_t *shj = json_object_get(root, "shadows");
	if (json_is_boolean(shj)) {
		s->enabled = json_is_true(shj);
		api_member_read(c, root, "shadows");
	} else if (shj) {
		size_t old = api_ptr_push(c, "shadows");
		int rc = api_parse_shadow(c, shj, s, "shadows");
		api_ptr_pop(c, old);
		if (rc < 0) return -1;
	}
	return 0;
}


/* ---- which settings a light uses ---- */

static const char *const FILTER_NAMES[] = {"auto", "hard", "pcf", "pcss", "vsm", "evsm"};

/* The filter the renderer draws light l with (renderer/plan.c plan_filter: auto is pcss for a
 * light with a size, else pcf). */
static enum rnd_filter light_filter(const struct rnd_light *l)
{
	float size = l->type == RND_LIGHT_DIRECTIONAL ? l->angular_diameter : l->radius;
	if (l->shadow.filter != RND_FILTER_AUTO) return l->shadow.filter;
	return size > 0 ? RND_FILTER_PCSS : RND_FILTER_PCF;
}

static const char SHADOWS_OFF[] = "shadows are off";

/* NULL when light l uses the shadow setting group/key (group NULL: a top-level member), else
 * why not ("the light's ..." follows), into buf or a constant. */
static const char *unused_why(const struct rnd_light *l, const char *group, const char *key, char *buf, size_t n)
{
	const struct rnd_shadow *s = &l->shadow;
	enum rnd_filter f = light_filter(l);
	bool moments = f == RND_FILTER_VSM || f == RND_FILTER_EVSM;
	if (!group && !strcmp(key, "enabled")) return NULL;
	if (!s->enabled) return SHADOWS_OFF;
	if (!group && !strcmp(key, "pcf_radius") && f != RND_FILTER_PCF) {
		snprintf(buf, n, "filter is \"%s\" (pcf_radius is for \"pcf\")", FILTER_NAMES[f]);
		return buf;
	}
	if (group && !strcmp(group, "vsm")) {
		if (!moments) {
			snprintf(buf, n, "filter is \"%s\" (vsm settings are for \"vsm\" and \"evsm\")", FILTER_NAMES[f]);
			return buf;
		}
		if (!strcmp(key, "exponent") && f != RND_FILTER_EVSM) return "filter is \"vsm\" (exponent is for \"evsm\")";
	}
	if (group && !strcmp(group, "directional")) {
		if (l->type != RND_LIGHT_DIRECTIONAL) return "type is not directional";
		bool casc = !strcmp(key, "cascades") || !strcmp(key, "split_lambda") || !strcmp(key, "blend");
		bool clip = !strncmp(key, "clipmap_", 8);
		if ((casc && (s->dir_mode == RND_DIR_FIT || s->dir_mode == RND_DIR_CLIPMAP)) ||
		    (clip && (s->dir_mode == RND_DIR_FIT || s->dir_mode == RND_DIR_CASCADES))) {
			static const char *const modes[] = {"auto", "fit", "cascades", "clipmap"};
			snprintf(buf, n, "directional mode is \"%s\"", modes[s->dir_mode]);
			return buf;
		}
	}
	if (group && !strcmp(group, "contact") && strcmp(key, "enabled") && !s->contact_enabled)
		return "contact shadows are off (contact.enabled)";
	return NULL;
}

/* Calls fn for every setting given in the shadow settings object j: group NULL for top-level
 * members, else the sub-object's name. Stops at the first nonzero return. */
static int each_setting(json_t *j, int (*fn)(void *ctx, const char *group, const char *key), void *ctx)
{
	const char *k;
	json_t *v;
	json_object_foreach(j, k, v) {
		if (api_free_member(k)) continue;
		int rc = 0;
		if (json_is_object(v)) {
			const char *k2;
			json_t *v2;
			json_object_foreach(v, k2, v2)
				if (!api_free_member(k2) && (rc = fn(ctx, k, k2)) != 0) break;
		} else {
			rc = fn(ctx, NULL, k);
		}
		if (rc) return rc;
	}
	return 0;
}

struct use_walk {
	struct pctx *c;
	const struct rnd_scene *sc;
	json_t *lights;
	size_t light;           /* the light whose own `shadow` is walked */
};

static json_t *setting(json_t *shadow, const char *group, const char *key)
{
	if (!json_is_object(shadow)) return NULL;
	return group ? json_object_get(json_object_get(shadow, group), key) : json_object_get(shadow, key);
}

/* A setting of light `w->light`'s own `shadow`: 400 when it contradicts the light, else a
 * warning when the light does not use it (once for the whole object when its shadows are off:
 * api_check_shadow_use). */
static int own_setting(void *ctx, const char *group, const char *key)
{
	struct use_walk *w = ctx;
	const struct rnd_light *l = &w->sc->lights[w->light];
	char why[96];
	const char *r = unused_why(l, group, key, why, sizeof why);
	bool contact_off = r == SHADOWS_OFF && group && !strcmp(group, "contact") && !strcmp(key, "enabled") &&
	                   json_is_true(setting(json_object_get(json_array_get(w->lights, w->light), "shadow"), group, key));
	if (!r || (r == SHADOWS_OFF && !contact_off)) return 0;
	size_t old = api_ptr_index(w->c, w->light);
	api_ptr_push(w->c, "shadow");
	if (group) api_ptr_push(w->c, group);
	int rc = 0;
	if (contact_off)
		rc = api_fail_at(w->c, key, "contact shadows are part of the light's shadows, which are off (enabled "
		                 "false here or in the root shadows): enable them, or leave contact out");
	else
		api_warn(w->c, "%s/%s: not used, the light's %s", w->c->ptr, key, r);
	api_ptr_pop(w->c, old);
	return rc;
}

struct root_walk {
	struct pctx *c;
	const struct rnd_scene *sc;
	json_t *lights;
};

/* A setting of the root `shadows`: a default for every light that does not give its own; a
 * warning when no light takes it and uses it. */
static int root_setting(void *ctx, const char *group, const char *key)
{
	struct root_walk *w = ctx;
	char why[96], first[128] = "";
	size_t n = w->sc->light_count;
	if (!group && !strcmp(key, "enabled")) return 0;
	if (!n) return 1;   /* said once for the whole object */
	for (size_t i = 0; i < n; i++) {
		if (setting(json_object_get(json_array_get(w->lights, i), "shadow"), group, key)) {
			if (!first[0]) snprintf(first, sizeof first, "light %zu gives its own", i);
			continue;
		}
		const char *r = unused_why(&w->sc->lights[i], group, key, why, sizeof why);
		if (!r) return 0;
		if (!first[0]) snprintf(first, sizeof first, "light %zu: %s", i, r);
	}
	api_warn(w->c, "/shadows/%s%s%s: not used by any light (%s)", group ? group : "", group ? "/" : "", key, first);
	return 0;
}

static bool settings_besides_enabled(json_t *j)
{
	const char *k;
	json_t *v;
	json_object_foreach(j, k, v)
		if (strcmp(k, "enabled") && !api_free_member(k)) return true;
	return false;
}

int api_check_shadow_use(struct pctx *c, json_t *root, const struct rnd_scene *sc)
{
	json_t *lights = json_object_get(root, "lights");
	size_t old = api_ptr_push(c, "lights");
	int rc = 0;
	for (size_t i = 0; !rc && i < sc->light_count; i++) {
		const struct rnd_light *l = &sc->lights[i];
		json_t *lj = json_array_get(lights, i), *own = json_object_get(lj, "shadow");
		struct use_walk w = {c, sc, lights, i};
		if (json_object_get(own, "directional") && l->type != RND_LIGHT_DIRECTIONAL) {
			size_t o2 = api_ptr_index(c, i);
			api_ptr_push(c, "shadow");
			rc = api_fail_at(c, "directional", "directional shadow settings (mode, cascades, clipmap) apply to "
			                 "directional lights only; this is a %s light", l->type == RND_LIGHT_SPOT ? "spot" : "point");
			api_ptr_pop(c, o2);
			break;
		}
		if (json_is_object(own) && (rc = each_setting(own, own_setting, &w)) != 0) break;
		if (json_is_object(own) && !l->shadow.enabled && settings_besides_enabled(own))
			api_warn(c, "/lights/%zu/shadow: its settings are not used, the light's shadows are off", i);
		/* A light size draws only through pcss (the blocker search and penumbra); other filters
		 * keep the edge as their kernel makes it. */
		const char *size_key = l->type == RND_LIGHT_DIRECTIONAL ? "angular_diameter" : "radius";
		float size = l->type == RND_LIGHT_DIRECTIONAL ? l->angular_diameter : l->radius;
		enum rnd_filter f = light_filter(l);
		if (l->shadow.enabled && size > 0 && f != RND_FILTER_PCSS)
			api_warn(c, "/lights/%zu/%s: the light's size draws no penumbra with filter \"%s\" (only \"pcss\", "
			         "or \"auto\", uses it)", i, size_key, FILTER_NAMES[f]);
	}
	api_ptr_pop(c, old);
	if (rc) return -1;
	json_t *rs = json_object_get(root, "shadows");
	struct root_walk rw = {c, sc, lights};
	if (json_is_object(rs) && each_setting(rs, root_setting, &rw) && settings_besides_enabled(rs))
		api_warn(c, "/shadows: not used, the scene has no lights");
	return 0;
}
