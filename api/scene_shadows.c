/*
 * api/scene_shadows.c — shadow settings: the root `shadows` (object or boolean) over the
 * renderer's defaults, and each light's `shadow` over the root's (scene_lights.c). Contact
 * shadows are validated but a 422 (the renderer does not march them). See scene_internal.h.
 */
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
	if ((rc = api_get_u32(c, j, "resolution", 64, 8192, &s->resolution)) < 0) return -1;
	if (rc && c->lim->max_shadow_resolution && s->resolution > c->lim->max_shadow_resolution)
		api_defer(c, false, "resolution", "shadow resolution %u is over this server's limit of %u", s->resolution,
		      c->lim->max_shadow_resolution);
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
		static const struct range blur = {0, 64, false, false}, expo = {0, 42, true, false};
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
	} else if (shj) {
		size_t old = api_ptr_push(c, "shadows");
		int rc = api_parse_shadow(c, shj, s, "shadows");
		api_ptr_pop(c, old);
		if (rc < 0) return -1;
	}
	return 0;
}
