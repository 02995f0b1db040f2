/*
 * renderer/render_explain.c — the render plan in words and figures (umbra/rnd_plan.h): what
 * `explain` shows, read from the plan the render executes (render_plan.h), and after the render
 * what it measured. Nothing here decides anything: every reason is in the words of the module
 * that makes the decision (casters.c, plan_words.c, visibility_plan.c, lod.c, env_shadow.c,
 * render_plan.c), and the limits in them are written once, where they are set.
 */
#include <string.h>
#include "caster_level.h"
#include "env_shadow.h"
#include "lod.h"
#include "moments.h"
#include "render_plan.h"
#include "visibility_plan.h"
#include "umbra/rnd_plan.h"

static const char *const shapes[] = {"plane", "box", "sphere", "cylinder", "mesh"};
static const char *const light_types[] = {"directional", "spot", "point"};

static const char *filter_name(const struct rnd_light_plan *lp)
{
	switch (lp->filter) {
	case UMBRA_FILTER_HARD: return "hard";
	case UMBRA_FILTER_PCF: return "pcf";
	case UMBRA_FILTER_PCSS: return "pcss";
	default: return lp->evsm ? "evsm" : "vsm";
	}
}

/* Whether a map draws PCSS's depth bounds: the render's rule (moments.c), from the plan's device. */
static bool pcss_bounds(const struct rnd_plan *p, const struct rnd_light_plan *lp, uint32_t res)
{
	return rnd_bounds_rule(lp, p->dev.pcss_bounds, p->dev.moments_max_res, res);
}

/* The main pass's estimate for view vp: its rows' and its bands' (cost.c). */
static double main_estimate_ms(const struct rnd_plan *p, const struct rnd_view_plan *vp)
{
	return vp->row_ms * p->sc->height + vp->band_ms;
}

void rnd_plan_info(const struct rnd_plan *p, struct rnd_plan_info *out)
{
	memset(out, 0, sizeof *out);
	const struct rnd_scene *sc = p->sc;
	out->width = sc->width;
	out->height = sc->height;
	out->views = p->nviews;
	out->columns = p->sheet.cols;
	out->rows = p->sheet.rows;
	out->objects = sc->object_count;
	out->lights = sc->light_count;
	out->maps = p->nmaps;
	out->passes = rnd_plan_passes(p, NULL, 0);
	for (uint32_t v = 0; v < p->nviews; v++) {
		struct rnd_plan_view_info vi;
		rnd_plan_view(p, v, &vi);
		out->maps_drawn += vi.maps_drawn;
		out->texels_drawn += vi.texels_drawn;
		out->shadow_triangles += vi.shadow_triangles;
		out->camera_triangles += vi.camera_triangles;
		out->estimate_ms += vi.shadow_estimate_ms + vi.main_estimate_ms;
		out->visibility_views += vi.visibility;
		out->pixel_shaded_views += vi.pixel_shading;
		for (uint32_t k = 0; k < p->views[v].shadow_views; k++) out->maps_cached += p->views[v].skip[k] == RND_SKIP_CACHED;
	}
	out->sphere_proxies = p->sphere_proxies;
	out->env_directions = p->env.mapped;
	out->env_weighed = p->env.ndirs - p->env.mapped;
	out->env_ground = p->env.ground;
	out->vertices = p->vertices;
	out->indices = p->indices;
	out->estimate = p->est;
	out->bounds = p->bounds;
	out->casters = p->casters;
	out->plan_ms = p->plan_ms;
	out->analyzed = p->actual.done;
	out->actual = p->actual.tm;
}

void rnd_plan_map(const struct rnd_plan *p, uint32_t k, struct rnd_plan_map_info *out)
{
	memset(out, 0, sizeof *out);
	const struct rnd_scene *sc = &p->esc;
	const struct rnd_map_plan *m = &p->maps[k];
	const struct rnd_light_plan *lp = &p->views[0].lights[m->light];
	bool env = m->light >= p->sc->light_count;
	out->light = m->light;
	out->environment = env ? (int32_t)(m->light - p->sc->light_count) : -1;
	out->light_type = env ? "environment" : light_types[sc->lights[m->light].type % 3];
	if (env) {
		const struct rnd_env_dir *d = &p->env.dirs[out->environment];
		memcpy(out->direction, d->dir, sizeof out->direction);
		out->share = d->share;
	}
	out->kind = rnd_light_plan_kind(&sc->lights[m->light], lp);
	out->tiles = m->tiles;
	out->resolution = m->res;
	out->asked = m->want;
	out->size = env ? rnd_env_lights_size_text() : rnd_size_rule_text(lp->size_rule);
	out->fitted = rnd_map_plan_fitted(p, m);
	out->filter = filter_name(lp);
	out->pcf_radius = lp->pcf_radius;
	out->pcss_bounds = pcss_bounds(p, lp, m->res);
	out->key = m->key;
	out->state = rnd_map_plan_state(m, &out->why);
	for (uint32_t v = 0; v < p->nviews; v++) {
		const struct rnd_view_plan *vp = &p->views[v];
		const struct rnd_light_plan *l = &vp->lights[m->light];
		if (vp->skip[l->first_view] != RND_SKIP_NONE) continue;
		out->drawn_views++;
		for (uint32_t t = 0; t < l->view_count; t++) {
			out->texels += (uint64_t)m->res * m->res;
			out->triangles += vp->map_tris[l->first_view + t];
			out->estimate_ms += vp->map_ms[l->first_view + t];
		}
	}
	out->analyzed = p->actual.done;
	out->hit = p->actual.hit[k];
}

void rnd_plan_view(const struct rnd_plan *p, uint32_t v, struct rnd_plan_view_info *out)
{
	memset(out, 0, sizeof *out);
	const struct rnd_view_plan *vp = &p->views[v];
	const struct rnd_camera_plan *c = &vp->cam;
	memcpy(out->position, c->pos, sizeof c->pos);
	memcpy(out->forward, c->fwd, sizeof c->fwd);
	memcpy(out->up, c->up, sizeof c->up);
	out->znear = c->znear;
	out->zfar = c->zfar;
	out->orthographic = c->ortho;
	out->fov_y = c->ortho ? 0.0f : c->fov_y;
	out->ortho_height = c->ortho ? c->ortho_height : 0.0f;
	out->shadow_views = vp->shadow_views;
	for (uint32_t k = 0; k < vp->shadow_views; k++) {
		if (vp->skip[k] != RND_SKIP_NONE) continue;
		uint32_t res = (uint32_t)vp->views[k].rect[2];
		out->maps_drawn++;
		out->texels_drawn += (uint64_t)res * res;
		out->shadow_triangles += vp->map_tris[k];
		out->shadow_estimate_ms += vp->map_ms[k];
	}
	out->camera_triangles = vp->camera_triangles;
	out->contact = vp->contact;
	out->env_pass = vp->env_pass;
	out->pixel_shading = vp->deferred;
	out->pixel_shading_why = rnd_pixel_why_text(vp->deferred_why);
	out->visibility = vp->vis;
	out->visibility_why = rnd_vis_why_text(vp->vis_why);
	out->row_ms = vp->row_ms;
	out->band_ms = vp->band_ms;
	out->main_estimate_ms = main_estimate_ms(p, vp);
	out->analyzed = p->actual.done;
	out->shadow_ms = p->actual.shadow_ms[v];
	out->main_ms = p->actual.main_ms[v];
	out->bands = p->actual.bands[v];
}

/* An object's level of detail (lod.c chose it). */
static void object_detail(const struct rnd_plan *p, uint32_t i, struct rnd_plan_object_info *out)
{
	const struct rnd_object *o = &p->sc->objects[i];
	uint32_t lod = p->lod[i];
	if (o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_CYLINDER) {
		out->asked = o->segments;
		out->segments = lod;
	} else if (o->shape == RND_SHAPE_MESH && o->lod_count) {
		out->levels = o->lod_count;
		out->level = lod;
	}
	out->detail = rnd_lod_detail(o, lod);
}

void rnd_plan_object(const struct rnd_plan *p, uint32_t i, struct rnd_plan_object_info *out)
{
	memset(out, 0, sizeof *out);
	const struct draw *d = &p->draws[i];
	out->shape = shapes[p->sc->objects[i].shape % 5];
	object_detail(p, i, out);
	out->triangles = d->index_count / 3;
	out->camera_triangles = d->cam_index_count / 3;
	out->caster_triangles = d->env_index_count / 3;
	out->caster_error = d->env_error;
	const struct rnd_view_plan *vp = &p->views[0];
	for (uint32_t k = 0; k < vp->shadow_views && d->env_index_count; k++)
		out->caster_maps += rnd_caster_level_used(&p->esc.lights[vp->view_light[k]], &vp->views[k], vp->view_ortho[k], d);
	out->proxy = (d->flags & UMBRA_DRAW_SPHERE) != 0;
	out->casts = d->cast && d->index_count;
	out->cast_why = rnd_cast_why_text(p->cast_why[i]);
	out->in_casters_box = out->casts && p->cast_why[i] != RND_CAST_FOR_MOMENTS;
}

/* Adds a pass (when there is room) and counts it. */
static void add_pass(struct rnd_plan_pass_info *out, uint32_t max, uint32_t *n, struct rnd_plan_pass_info pass)
{
	if (out && *n < max) out[*n] = pass;
	(*n)++;
}

/* View v's shadow maps, in the order it draws them (its shadow views'). */
static void shadow_passes(const struct rnd_plan *p, uint32_t v, struct rnd_plan_pass_info *out, uint32_t max, uint32_t *n)
{
	const struct rnd_view_plan *vp = &p->views[v];
	for (uint32_t k = 0; k < vp->shadow_views; k++) {
		if (vp->skip[k] != RND_SKIP_NONE) continue;
		uint32_t light = vp->view_light[k], map = 0, res = (uint32_t)vp->views[k].rect[2];
		while (map < p->nmaps && p->maps[map].light != light) map++;
		const struct rnd_light_plan *lp = &vp->lights[light];
		const char *note = pcss_bounds(p, lp, res) ? "and its PCSS depth bounds (a compute pass)"
		                   : lp->moments ? "and its moments, blurred (two fullscreen passes)" : "";
		add_pass(out, max, n, (struct rnd_plan_pass_info){
			.pass = "shadow_map", .view = (int32_t)v, .map = (int32_t)map, .light = (int32_t)light,
			.tile = (int32_t)(k - lp->first_view), .resolution = res, .texels = (uint64_t)res * res,
			.triangles = vp->map_tris[k], .estimate_ms = vp->map_ms[k], .note = note});
	}
}

uint32_t rnd_plan_passes(const struct rnd_plan *p, struct rnd_plan_pass_info *out, uint32_t max)
{
	uint32_t n = 0;
	const struct rnd_scene *sc = p->sc;
	const struct rnd_plan_pass_info none = {.view = -1, .map = -1, .light = -1, .tile = -1, .note = ""};
	struct rnd_plan_pass_info upload = none;
	upload.pass = "upload";
	upload.triangles = p->indices / 3;
	upload.note = "tessellation into the vertex and index buffers, textures staged";
	add_pass(out, max, &n, upload);
	for (uint32_t v = 0; v < p->nviews; v++) {
		const struct rnd_view_plan *vp = &p->views[v];
		struct rnd_plan_pass_info pass = none;
		pass.view = (int32_t)v;
		shadow_passes(p, v, out, max, &n);
		if (vp->contact) {
			pass.pass = "scene_depth";
			pass.triangles = vp->camera_triangles;
			pass.note = "the view's depth, which contact shadows march through";
			add_pass(out, max, &n, pass);
		}
		if (vp->env_pass) {
			pass.pass = "environment";
			pass.triangles = vp->camera_triangles;
			pass.note = "the environment's shadows once per texel of a coarser grid (surfaces, then one lookup per "
			            "direction), read by the main pass";
			add_pass(out, max, &n, pass);
		}
		if (vp->vis || vp->deferred) {
			pass.pass = "visibility";
			pass.triangles = vp->camera_triangles;
			pass.note = vp->deferred ? "the surfaces with their shading inputs, then each pixel centre shaded once, its "
			                           "shadows with it (pixel shading)"
			                         : "each light's shadow once per pixel (a surfaces pass, then a fullscreen pass)";
			add_pass(out, max, &n, pass);
		}
		pass.pass = "main";
		pass.triangles = vp->camera_triangles;
		pass.estimate_ms = main_estimate_ms(p, vp);
		pass.note = vp->deferred         ? "depth only, MSAA 4; each sample takes a pixel centre's colour (the resolve)"
		            : sc->output.msaa > 1 ? "MSAA 4, resolved and copied into the readback buffer"
		                                  : "copied into the readback buffer";
		add_pass(out, max, &n, pass);
		if (p->sheet.passes) {
			pass.pass = "aov";
			pass.estimate_ms = 0;
			pass.note = p->sheet.passes > 1 ? "the AOV planes, in more than one pass" : "the AOV planes";
			add_pass(out, max, &n, pass);
		}
	}
	struct rnd_plan_pass_info readback = none;
	readback.pass = "readback";
	readback.note = "the image out of the readback buffer";
	add_pass(out, max, &n, readback);
	return n;
}
