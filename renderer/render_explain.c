/*
 * renderer/render_explain.c — the render plan in words and figures (umbra/rnd_plan.h): what
 * `explain` shows, read from the plan the render executes (render_plan.h), and after the render
 * what it measured. Nothing here decides anything: every reason is the name of a decision made
 * in its own module (casters.c, plan.c, visibility_plan.c, lod.c, shadow_cache.c).
 */
#include <string.h>
#include "caster_level.h"
#include "lod.h"
#include "render_plan.h"
#include "visibility_plan.h"
#include "umbra/rnd_plan.h"

static const char *const cast_why[RND_CAST_WHY_COUNT] = {
	[RND_CAST_YES] = "casts",
	[RND_CAST_NOT_ASKED] = "cast_shadows is false",
	[RND_CAST_CATCHER] = "a shadow catcher receives shadows and casts none",
	[RND_CAST_ALONE] = "a plane with no other object to shadow",
	[RND_CAST_LIT_SIDE] = "a plane with every other object on its lit side",
	[RND_CAST_UNSEEN] = "a plane whose shadow falls only where no camera sees it (on parts of objects sunk into it)",
	[RND_CAST_FOR_MOMENTS] = "a plane drawn into the maps for the VSM/EVSM blur, left out of the casters' box",
	[RND_CAST_UNJUDGED] = "a plane in a scene of more than 256 objects: planes are not judged, it casts",
	[RND_CAST_FOR_ENV] = ("a plane that shadows others only from the environment's directions: in their maps, "
	                      "left out of the casters' box"),
};

static const char *const size_why[RND_SIZE_RULE_COUNT] = {
	[RND_SIZE_ASKED] = "the light's shadow.resolution",
	[RND_SIZE_DEFAULT] = "a sun's default",
	[RND_SIZE_IMPORTANCE] = "the share of the view the light's reach covers",
	[RND_SIZE_HARD_EDGE] = "a hard light: its filter kernel within a pixel of the output",
	[RND_SIZE_CASTERS] = "the casters' box: texels finer than the default map's where the camera sees them close",
	[RND_SIZE_CAPPED] = "the server's largest shadow resolution",
};

static const char *const vis_why[RND_VIS_WHY_COUNT] = {
	[RND_VIS_DENSE] = "enough small triangles under wide filters for the pass to pay",
	[RND_VIS_FORCED_ON] = "UMBRA_VISIBILITY=1",
	[RND_VIS_NO_DEVICE] = "the device cannot run it",
	[RND_VIS_DEBUG] = "a debug view shows the filters' own work",
	[RND_VIS_NO_SHADOWS] = "no light has shadow maps",
	[RND_VIS_MASKED] = "an alpha-tested material",
	[RND_VIS_TOO_LARGE] = "its images would be too large",
	[RND_VIS_FORCED_OFF] = "UMBRA_VISIBILITY=0",
	[RND_VIS_NARROW] = "no light filters widely enough (PCSS, PCF radius 4 or more)",
	[RND_VIS_SPARSE] = "too few triangles for its passes to pay",
};

static const char *const pixel_why[RND_PIXEL_WHY_COUNT] = {
	[RND_PIXEL_VISIBILITY] = "plain draws: the visibility pass's surfaces shaded once per pixel centre",
	[RND_PIXEL_ENVIRONMENT] = "an environment map over dense plain draws: its own surfaces pass, shaded once per pixel",
	[RND_PIXEL_NO_DEVICE] = "the device cannot",
	[RND_PIXEL_OUTPUT] = "not MSAA 4, or a debug view",
	[RND_PIXEL_BACKGROUND] = "the environment map is the background",
	[RND_PIXEL_NOT_PLAIN] = "a textured, alpha-tested or extension material, or a sphere's proxy",
	[RND_PIXEL_NO_PASS] = "no visibility pass and no environment map",
	[RND_PIXEL_TOO_LARGE] = "its images would be too large",
	[RND_PIXEL_SPARSE] = "too few triangles for its passes to pay",
	[RND_PIXEL_FORCED_OFF] = "UMBRA_PIXEL_SHADING=0",
};

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

/* What PCSS's depth bounds need (moments.c rnd_bounds_wanted, from the plan's device). */
static bool pcss_bounds(const struct rnd_plan *p, const struct rnd_light_plan *lp, uint32_t res)
{
	return lp->filter == UMBRA_FILTER_PCSS && p->dev.pcss_bounds && res <= p->dev.moments_max_res;
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

static const char *map_kind(const struct rnd_scene *sc, const struct rnd_light_plan *lp, uint32_t light)
{
	if (sc->lights[light].shadow.dir_mode == RND_DIR_CASTERS) return "casters";
	if (sc->lights[light].type == RND_LIGHT_SPOT) return "spot";
	if (sc->lights[light].type == RND_LIGHT_POINT) return "cube";
	return lp->clipmap ? "clipmap" : lp->follows_camera ? "cascades" : "fit";
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
	out->kind = map_kind(sc, lp, m->light);
	out->tiles = m->tiles;
	out->resolution = m->res;
	out->asked = m->want;
	out->size = env ? "the environment's shadow_resolution, coarser for a wider region (env_shadow.c)"
	                : size_why[lp->size_rule % RND_SIZE_RULE_COUNT];
	out->fitted = m->res == m->want ? "" : m->moments_capped && m->res == p->dev.moments_max_res
	                                       ? "moment maps are capped at what the device reads as one buffer"
	                                       : "halved, the largest first, until every map fits in the atlas";
	out->filter = filter_name(lp);
	out->pcf_radius = lp->pcf_radius;
	out->pcss_bounds = pcss_bounds(p, lp, m->res);
	out->key = m->key;
	out->state = !m->key ? "every view" : m->cached ? "cached" : "drawn";
	out->why = !m->key ? "cascades and clipmap levels follow the camera: drawn by every view, never kept"
	           : m->cached ? "the atlas holds a completed map of this key (drawn by an earlier request)"
	                       : "no map of this key in the atlas: drawn, then kept for later requests";
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
	out->pixel_shading_why = pixel_why[vp->deferred_why % RND_PIXEL_WHY_COUNT];
	out->visibility = vp->vis;
	out->visibility_why = vis_why[vp->vis_why % RND_VIS_WHY_COUNT];
	out->row_ms = vp->row_ms;
	out->band_ms = vp->band_ms;
	out->main_estimate_ms = vp->row_ms * p->sc->height + vp->band_ms;
	out->analyzed = p->actual.done;
	out->shadow_ms = p->actual.shadow_ms[v];
	out->main_ms = p->actual.main_ms[v];
	out->bands = p->actual.bands[v];
}

/* A level of detail in words. */
static void object_detail(const struct rnd_plan *p, uint32_t i, struct rnd_plan_object_info *out)
{
	const struct rnd_object *o = &p->sc->objects[i];
	uint32_t lod = p->lod[i];
	if (o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_CYLINDER) {
		out->asked = o->segments;
		out->segments = lod;
		out->detail = lod < o->segments ? "fewer segments: the output shows no more (1/32 pixel, 1/8 shadow texel)"
		                                : "the segments asked for";
	} else if (o->shape == RND_SHAPE_MESH && o->lod_count) {
		out->levels = o->lod_count;
		out->level = lod;
		out->detail = lod ? "a simplified level: its error within half a pixel of every camera"
		                  : "the full mesh: no level's error fits the output";
	} else {
		out->detail = "as given";
	}
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
	out->cast_why = cast_why[p->cast_why[i] % RND_CAST_WHY_COUNT];
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
		pass.estimate_ms = vp->row_ms * sc->height + vp->band_ms;
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
