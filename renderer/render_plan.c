/*
 * renderer/render_plan.c — the render plan, built once (see render_plan.h): the scene checked,
 * its memory estimated, each object's level of detail and draw, the cameras, the casters, every
 * light's maps and their tiles, and per view what it draws and what the deadline's estimates
 * are. Each decision is made by the module named after it; here they are called in the order
 * the render used to make them, so that the plan is the render's own (the same bytes: the GPU
 * tests and tests/bench/same_images.py compare them). Pure: no Vulkan.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "atlas.h"
#include "caster_level.h"
#include "contact.h"
#include "cost.h"
#include "env_shadow.h"
#include "error.h"
#include "lod.h"
#include "material_bits.h"
#include "mesh.h"
#include "render_plan.h"
#include "plan_local.h"
#include "shadow_keys.h"
#include "visibility_plan.h"

/* ---- memory: every allocation of a plan on one list, freed by rnd_plan_release ---- */

struct plan_block {
	struct plan_block *next;
	max_align_t data[];
};

/* n bytes (zeroed unless raw) that live as long as the plan; NULL when out of memory. */
static void *plan_alloc_raw(struct rnd_plan *p, size_t n, bool raw)
{
	struct plan_block *b = raw ? malloc(sizeof *b + (n ? n : 1)) : calloc(1, sizeof *b + (n ? n : 1));
	if (!b) return NULL;
	b->next = p->mem;
	p->mem = b;
	return b->data;
}

static void *plan_alloc(struct rnd_plan *p, size_t n)
{
	return plan_alloc_raw(p, n, false);
}

void rnd_plan_release(struct rnd_plan *p)
{
	if (!p) return;
	for (struct plan_block *b = p->mem, *next; b; b = next) {
		next = b->next;
		free(b);
	}
	memset(p, 0, sizeof *p);
}

/* ---- the scene as a whole ---- */

static enum rnd_result validate(const struct rnd_plan_device *dev, const struct rnd_scene *sc, struct rnd_error *err)
{
	if (sc->width < 1 || sc->height < 1 || sc->width > dev->max_width || sc->height > dev->max_height ||
	    sc->width > dev->max_image_dimension || sc->height > dev->max_image_dimension)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_SIZE, 0, "image %ux%u is outside 1..%u x 1..%u", sc->width, sc->height,
		                dev->max_width, dev->max_height);
	if (sc->output.msaa != 1 && sc->output.msaa != 4)
		return rnd_fail(err, RND_ERR_INVALID, "msaa %u: must be 1 or 4", sc->output.msaa);
	if ((unsigned)sc->output.pixels > RND_PIXELS_RGBA32F)
		return rnd_fail(err, RND_ERR_INVALID, "unknown pixel format %d", (int)sc->output.pixels);
	if (sc->material_count > UMBRA_MAX_MATERIALS)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_MATERIALS, 0, "%u materials: at most %d", sc->material_count,
		                   UMBRA_MAX_MATERIALS);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (sc->objects[i].material >= sc->material_count && sc->material_count > 0)
			return rnd_fail(err, RND_ERR_INVALID, "object %u: material %u does not exist", i, sc->objects[i].material);
	if (sc->output.debug == RND_DEBUG_SHADOW && sc->output.debug_light >= sc->light_count && sc->light_count > 0)
		return rnd_fail(err, RND_ERR_INVALID, "debug_light %u names no light", sc->output.debug_light);
	if (sc->output.aovs && sc->output.pixels != RND_PIXELS_RGBA32F)
		return rnd_fail(err, RND_ERR_INVALID, "AOVs need the linear RGBA32F output (EXR)");
	uint32_t planes = rnd_aov_planes(sc);
	if (planes > RND_MAX_AOV_PLANES)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_AOVS, 0, "%u AOV planes: at most %d (shadow AOVs of at most %d lights)",
		                   planes, RND_MAX_AOV_PLANES, RND_MAX_AOV_PLANES - 7);
	if (sc->view_count && !sc->views) return rnd_fail(err, RND_ERR_INVALID, "view_count %u with no views", sc->view_count);
	if (sc->view_count > RND_MAX_VIEWS) return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_VIEWS, 0, "%u views: at most %u", sc->view_count, RND_MAX_VIEWS);
	return RND_OK;
}

/* The sheet, the memory estimate, and the one allocation no device may be asked for. */
static enum rnd_result plan_memory(struct rnd_plan *p, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	const struct rnd_sheet *sh = &p->sheet;
	rnd_sheet_init(&p->sheet, sc);
	if (sh->width > RND_MAX_SHEET_SIDE || sh->height > RND_MAX_SHEET_SIDE || sh->width * sh->height > RND_MAX_SHEET_PIXELS)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_VIEWS, 0, "a sheet of %u views is %llux%llu pixels: too large", sh->views,
		                (unsigned long long)sh->width, (unsigned long long)sh->height);
	rnd_estimate_scene(sc, p->dev.atlas_size, &p->est);
	return rnd_check_allocation(p->dev.max_allocation, sc, &p->est, err);
}

/* ---- objects: level of detail, proxies, and each draw, measured before it is written ---- */

/* Where each object's triangles go in the slot's buffers (every mesh in object order, then the
 * camera's proxies of spheres: where the meshes lie does not depend on the camera; then the
 * environment's maps' caster levels). */
static enum rnd_result plan_layout(struct rnd_plan *p, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	uint64_t nv = 0, ni = 0;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		struct rnd_object o = sc->objects[i];
		struct draw *d = &p->draws[i];
		rnd_lod_apply(&o, p->lod[i]); /* renderer/lod.h: no finer than the output can show */
		rnd_mesh_counts(&o, &d->vertex_count, &d->index_count);
		d->first_vertex = (uint32_t)nv;
		d->first_index = d->cam_first_index = (uint32_t)ni;
		d->cam_index_count = d->index_count;
		nv += d->vertex_count;
		ni += d->index_count;
	}
	for (uint32_t i = 0; i < sc->object_count; i++) {
		uint32_t v, x;
		rnd_proxy_counts(&p->proxies[i], &v, &x);
		if (!x) continue;
		p->draws[i].cam_first_vertex = (uint32_t)nv;
		p->draws[i].cam_first_index = (uint32_t)ni;
		p->draws[i].cam_index_count = x;
		nv += v;
		ni += x;
	}
	/* The environment's maps' caster levels, after them (caster_level.h). */
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		struct draw *d = &p->draws[i];
		if (p->dev.caster_levels_off || !rnd_caster_level_wanted(sc, o, d->index_count)) continue;
		d->env_first_vertex = (uint32_t)nv;
		d->env_vertex_count = o->caster->vertex_count;
		d->env_first_index = (uint32_t)ni;
		d->env_index_count = o->caster->index_count;
		d->env_error = rnd_caster_world_error(o);
		d->env_raise = p->dev.caster_bias_off ? 0.0f : d->env_error;
		nv += o->caster->vertex_count;
		ni += o->caster->index_count;
	}
	if (nv > UINT32_MAX || ni > UINT32_MAX)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_OBJECTS, 0, "scene too large: %llu vertices, %llu indices",
		                (unsigned long long)nv, (unsigned long long)ni);
	p->vertices = nv;
	p->indices = ni;
	return RND_OK;
}

/* Object i's draw: its bounds and area as written (rnd_mesh_measure), its material and how the
 * passes draw it. *kept: the vertices kept so far for the upload. */
static enum rnd_result plan_draw(struct rnd_plan *p, uint32_t i, uint64_t *kept, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	struct rnd_object lo = sc->objects[i];
	rnd_lod_apply(&lo, p->lod[i]);
	const struct rnd_object *o = &lo;
	struct draw *d = &p->draws[i];
	rnd_aabb_empty(&d->bounds);
	/* An analytic shape, while the budget lasts, kept for the upload to copy. */
	if (o->shape != RND_SHAPE_MESH && *kept + d->vertex_count <= RND_PLAN_KEEP_VERTICES) {
		p->kept_vertices[i] = plan_alloc_raw(p, (size_t)d->vertex_count * sizeof(struct rnd_vertex), true);
		p->kept_indices[i] = plan_alloc_raw(p, (size_t)d->index_count * sizeof(uint32_t), true);
		if (!p->kept_vertices[i] || !p->kept_indices[i]) return rnd_fail(err, RND_ERR_OOM, "out of memory for object %u", i);
		*kept += d->vertex_count;
	}
	enum rnd_result r = rnd_mesh_measure(o, p->kept_vertices[i], p->kept_indices[i], &d->bounds, &d->area, err);
	if (r != RND_OK) {
		char m[sizeof err->msg];
		snprintf(m, sizeof m, "%s", err->msg);
		return rnd_fail(err, r, "object %u: %s", i, m);
	}
	bool proxy = p->proxies[i].outline > 0;
	d->material = sc->material_count ? o->material : 0;
	bool catcher = sc->material_count && sc->materials[o->material].shadow_catcher;
	d->flags = (o->receive_shadows ? UMBRA_DRAW_RECEIVE_SHADOWS : 0) | (catcher ? UMBRA_DRAW_SHADOW_CATCHER : 0) |
	           (proxy ? UMBRA_DRAW_SPHERE : 0);
	/* A shadow catcher receives shadows and casts none (contract §7). */
	d->cast = o->cast_shadows && !catcher;
	/* MASK and dithered BLEND both take the alpha-tested depth passes. */
	d->masked = sc->material_count && sc->materials[o->material].alpha_mode != RND_ALPHA_OPAQUE;
	d->texture_set = 0; /* the upload's (material.c rnd_material_textures) */
	/* the slots its material samples (material.c sets the same, and the second uv set's bit) */
	d->tex_bits = sc->material_count ? rnd_material_slot_bits(&sc->materials[o->material]) : 0;
	d->single_sided = !o->double_sided;
	d->closed = o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_BOX || o->shape == RND_SHAPE_CYLINDER ||
	            (o->shape == RND_SHAPE_MESH && o->closed);
	d->cull_back = d->single_sided;
	return RND_OK;
}

/* The environment's shadow directions (its map's light cut into regions: env_analysis.c) over
 * the ground the scene stands on, and the lights the shadow passes draw them as (env_shadow.c):
 * p->esc. */
static void plan_env(struct rnd_plan *p)
{
	const struct rnd_scene *sc = p->sc;
	float ground[3];
	bool has_ground = rnd_env_ground(sc, p->draws, ground);
	rnd_env_plan_dirs(p->dev.env_bins, &sc->environment, has_ground ? ground : NULL, &p->env);
	p->esc = *sc;
	uint32_t n = sc->light_count < UMBRA_MAX_LIGHTS ? sc->light_count : UMBRA_MAX_LIGHTS;
	if (!p->env.mapped) return;
	if (n) memcpy(p->lights, sc->lights, n * sizeof *p->lights);   /* lights NULL when n is 0 */
	p->env.mapped = rnd_env_lights(&p->env, &sc->environment, UMBRA_MAX_LIGHTS - n, p->lights + n);
	p->esc.lights = p->lights;
	p->esc.light_count = n + p->env.mapped;
}

static enum rnd_result plan_objects(struct rnd_plan *p, struct rnd_shadow_plan *scratch, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	size_t n = sc->object_count ? sc->object_count : 1;
	p->draws = plan_alloc(p, n * sizeof *p->draws);
	p->lod = plan_alloc(p, n * sizeof *p->lod);
	p->proxies = plan_alloc(p, n * sizeof *p->proxies);
	p->cast_why = plan_alloc(p, n);
	p->kept_vertices = plan_alloc(p, n * sizeof *p->kept_vertices);
	p->kept_indices = plan_alloc(p, n * sizeof *p->kept_indices);
	if (!p->draws || !p->lod || !p->proxies || !p->cast_why || !p->kept_vertices || !p->kept_indices)
		return rnd_fail(err, RND_ERR_OOM, "out of memory for %u objects", sc->object_count);
	rnd_lod_choose(sc, p->sheet.views, scratch, p->lod);
	rnd_lod_proxies(sc, p->sheet.views, p->lod, p->proxies);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (p->proxies[i].outline) p->sphere_proxies++;
	enum rnd_result r = plan_layout(p, err);
	uint64_t kept = 0;
	rnd_aabb_empty(&p->bounds);
	for (uint32_t i = 0; i < sc->object_count && r == RND_OK; i++) {
		r = plan_draw(p, i, &kept, err);
		rnd_aabb_union(&p->bounds, &p->draws[i].bounds);
	}
	if (r != RND_OK) return r;
	/* Auto-framing `fit: objects` leaves out planes and shadow catchers (the ground). */
	rnd_aabb_empty(&p->obj_bounds);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (rnd_object_frames(&sc->objects[i], sc->material_count ? sc->materials : NULL))
			rnd_aabb_union(&p->obj_bounds, &p->draws[i].bounds);
	if (rnd_aabb_is_empty(&p->obj_bounds)) p->obj_bounds = p->bounds;
	plan_env(p);
	rnd_casters_plan(sc, &p->esc, p->draws, &p->bounds, &p->obj_bounds, &p->casters, p->cast_why);
	p->caster_key = rnd_caster_key(sc, p->draws, p->lod, &p->bounds);
	return RND_OK;
}

/* ---- views ---- */

/* Culling back faces of a closed primitive changes nothing in the picture as long as the
 * viewer is outside it and it lies wholly beyond the near plane; it halves the triangles
 * lavapipe rasterises and shades. */
static bool camera_outside(const struct rnd_camera_plan *cam, const struct rnd_aabb *b)
{
	for (int i = 0; i < 8; i++) {
		float q[3] = {i & 1 ? b->max[0] : b->min[0], i & 2 ? b->max[1] : b->min[1], i & 4 ? b->max[2] : b->min[2]};
		float d[3];
		rnd_v3_sub(d, q, cam->pos);
		if (rnd_v3_dot(d, cam->fwd) <= cam->znear * 1.01f) return false;
	}
	return true;
}

void rnd_plan_view_cull(const struct rnd_plan *p, uint32_t v, struct draw *draws)
{
	const struct rnd_camera_plan *cam = &p->views[v].cam;
	/* A sphere's proxy has no back: its slivers along the outline must not be culled. */
	for (uint32_t i = 0; i < p->sc->object_count; i++)
		draws[i].cull_back = !(draws[i].flags & UMBRA_DRAW_SPHERE) &&
		                     (draws[i].single_sided || (draws[i].closed && camera_outside(cam, &draws[i].bounds)));
}

/* View v's camera: framed on what it asks for, its near and far around the whole scene. */
static enum rnd_result plan_camera(const struct rnd_plan *p, uint32_t v, struct rnd_camera_plan *cam, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	const struct rnd_camera *camera = sc->view_count ? &sc->views[v] : &sc->camera;
	enum rnd_result r;
	if ((r = rnd_camera_plan(camera, sc->width, sc->height, camera->fit == RND_FIT_OBJECTS ? &p->obj_bounds : &p->bounds,
	                         cam, err)) != RND_OK)
		return r;
	if (camera->fit == RND_FIT_OBJECTS) {
		/* Framed on the objects, but near/far must still hold the whole scene. */
		struct rnd_camera c2 = *camera;
		memcpy(c2.position, cam->pos, sizeof cam->pos);
		for (int k = 0; k < 3; k++) c2.target[k] = cam->pos[k] + cam->fwd[k];
		c2.fit = RND_FIT_NONE;
		if ((r = rnd_camera_plan(&c2, sc->width, sc->height, &p->bounds, cam, err)) != RND_OK) return r;
	}
	return RND_OK;
}

/* A proxy planned for a camera other than this one (a fitted camera, placed here from the
 * measured shapes' bounds, lod.c from the shapes as asked): placed again for this one (the
 * upload writes it as placed); where it cannot be (this camera inside the sphere, or its near
 * plane cutting it), the sphere's mesh. Its vertices keep their room in the buffers. */
static void refit_proxies(struct rnd_plan *p, const struct rnd_camera_plan *cam)
{
	for (uint32_t i = 0; i < p->sc->object_count; i++) {
		struct draw *d = &p->draws[i];
		bool moved;
		if (!(d->flags & UMBRA_DRAW_SPHERE) || rnd_proxy_refit(&p->proxies[i], cam, &moved)) continue;
		d->flags &= ~UMBRA_DRAW_SPHERE;
		d->cam_first_index = d->first_index;
		d->cam_index_count = d->index_count;
		p->sphere_proxies--;
	}
}

/* View v's shadow plan (cascades: view 0's choice of `auto` for each light, which later views
 * keep so that they need the same tiles), checked against what the device can draw. */
static enum rnd_result plan_shadows(const struct rnd_plan *p, uint32_t v, const struct rnd_camera_plan *cam,
                                    uint8_t *cascades, struct rnd_shadow_plan *sp, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc, *esc = &p->esc;
	enum rnd_result r;
	if ((r = rnd_shadow_plan_with(esc, &p->bounds, &p->casters, cam, v ? cascades : NULL, p->dev.atlas_size, sp, err)) != RND_OK) return r;
	if (v == 0)
		for (uint32_t i = 0; i < esc->light_count && i < UMBRA_MAX_LIGHTS; i++)
			cascades[i] = sp->lights[i].follows_camera && !sp->lights[i].clipmap;
	/* Later views read view 0's maps that do not follow the camera (plan_view_work skips
	 * drawing them): they read them through view 0's projection, which a `fit` sun's texel
	 * chosen for view 0's camera (plan.c fit_casters) makes their own. */
	for (uint32_t i = 0; v > 0 && i < esc->light_count && i < UMBRA_MAX_LIGHTS; i++) {
		struct rnd_light_plan *lp = &sp->lights[i];
		const struct rnd_light_plan *l0 = &p->views[0].lights[i];
		if (!lp->view_count || lp->follows_camera || lp->view_count != l0->view_count) continue;
		memcpy(&sp->views[lp->first_view], &p->views[0].views[l0->first_view], lp->view_count * sizeof *sp->views);
		lp->resolution = l0->resolution;
		lp->size_rule = l0->size_rule;
		if (lp->resolution > sp->resolution) sp->resolution = lp->resolution;
	}
	bool any_moments = false;
	for (uint32_t i = 0; i < sc->light_count; i++)
		if (sp->lights[i].moments && sp->lights[i].view_count) any_moments = true;
	if (any_moments && !p->dev.moments)
		return rnd_fail(err, RND_ERR_INVALID, "shadow filters vsm/evsm need storage images this device lacks");
	for (uint32_t i = 0; i < sc->light_count; i++) {
		struct rnd_light_plan *lp = &sp->lights[i];
		/* exp(2cd) must stay finite in the precision asked for (fp16 storage limits c). */
		float cmax = lp->fp16 ? p->dev.evsm_max_exponent_fp16 : p->dev.evsm_max_exponent;
		if (lp->evsm) lp->evsm_exponent = lp->evsm_exponent > 0 ? fminf(lp->evsm_exponent, cmax) : cmax;
	}
	return RND_OK;
}

/* Keeps view v's shadow plan in the plan's own memory. */
static enum rnd_result keep_shadows(struct rnd_plan *p, uint32_t v, const struct rnd_shadow_plan *sp, struct rnd_error *err)
{
	struct rnd_view_plan *vp = &p->views[v];
	uint32_t nl = p->esc.light_count, n = sp->view_count;
	vp->shadow_views = n;
	vp->shadow_res = sp->resolution;
	vp->lights = plan_alloc(p, (nl ? nl : 1) * sizeof *vp->lights);
	vp->views = plan_alloc(p, (n ? n : 1) * sizeof *vp->views);
	vp->view_light = plan_alloc(p, (n ? n : 1) * sizeof *vp->view_light);
	vp->view_ortho = plan_alloc(p, (n ? n : 1) * sizeof *vp->view_ortho);
	vp->skip = plan_alloc(p, n ? n : 1);
	vp->map_ms = plan_alloc(p, (n ? n : 1) * sizeof *vp->map_ms);
	vp->map_tris = plan_alloc(p, (n ? n : 1) * sizeof *vp->map_tris);
	if (!vp->lights || !vp->views || !vp->view_light || !vp->view_ortho || !vp->skip || !vp->map_ms || !vp->map_tris)
		return rnd_fail(err, RND_ERR_OOM, "out of memory for the shadow plan of view %u", v);
	memcpy(vp->lights, sp->lights, nl * sizeof *vp->lights);
	memcpy(vp->views, sp->views, n * sizeof *vp->views);
	memcpy(vp->view_light, sp->view_light, n * sizeof *vp->view_light);
	memcpy(vp->view_ortho, sp->view_ortho, n * sizeof *vp->view_ortho);
	return RND_OK;
}

void rnd_plan_view_shadows(const struct rnd_plan *p, uint32_t v, struct rnd_shadow_plan *out)
{
	const struct rnd_view_plan *vp = &p->views[v];
	memset(out, 0, sizeof *out);
	out->resolution = vp->shadow_res;
	out->view_count = vp->shadow_views;
	memcpy(out->lights, vp->lights, p->esc.light_count * sizeof *vp->lights);
	memcpy(out->views, vp->views, vp->shadow_views * sizeof *vp->views);
	memcpy(out->view_light, vp->view_light, vp->shadow_views * sizeof *vp->view_light);
	memcpy(out->view_ortho, vp->view_ortho, vp->shadow_views * sizeof *vp->view_ortho);
	for (uint32_t k = 0; k < vp->shadow_views; k++) out->view_skip[k] = vp->skip[k] != RND_SKIP_NONE;
}

/* ---- maps: tiles granted once per request ---- */

/* Each shadowed light's tiles (view 0's plan: later views re-render only the maps that follow
 * the camera into the same tiles). Maps that do not follow the camera (spot and point lights,
 * a sun's one `fit` map) are keyed for reuse by later requests (shadow_keys.c); cascades and
 * clipmap levels are transient. Sizes: a function of the request alone (rnd_atlas_fit). */
static enum rnd_result plan_maps(struct rnd_plan *p, const struct rnd_shadow_plan *sp, struct rnd_error *err)
{
	const struct rnd_scene *sc = &p->esc;
	uint32_t tiles[UMBRA_MAX_LIGHTS] = {0}, want[UMBRA_MAX_LIGHTS] = {0}, res[UMBRA_MAX_LIGHTS], n = 0;
	uint64_t min_texels = 0;
	for (uint32_t i = 0; i < sc->light_count; i++) {
		const struct rnd_light_plan *lp = &sp->lights[i];
		if (!lp->view_count) continue;
		if (n == UMBRA_MAX_LIGHTS)
			return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_LIGHTS, 0, "%u shadowed lights: at most %d", n + 1, UMBRA_MAX_LIGHTS);
		struct rnd_map_plan *m = &p->maps[n];
		m->light = i;
		m->tiles = tiles[n] = lp->view_count;
		m->want = lp->resolution;
		m->key = lp->follows_camera ? 0 : rnd_map_key(p->caster_key, &sc->lights[i], lp, sp->views);
		/* Moment maps are read as a storage buffer: at most the device's range. */
		want[n] = lp->resolution;
		m->moments_capped = lp->moments && want[n] > p->dev.moments_max_res;
		if (m->moments_capped) want[n] = p->dev.moments_max_res;
		min_texels += (uint64_t)tiles[n] * 64 * 64;
		n++;
	}
	uint32_t atlas = p->dev.atlas_size;
	if (!rnd_atlas_fit(tiles, want, n, atlas, RND_MIN_SHADOW_RESOLUTION, res))
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_LIGHTS, 0,
		                   "the lights need %llu shadow tiles; even at 64x64 texels they do not fit in the "
		                   "%ux%u shadow atlas (raise --atlas-size or use fewer shadowed lights)",
		                   (unsigned long long)(min_texels / 4096), atlas, atlas);
	for (uint32_t k = 0; k < n; k++) {
		p->maps[k].res = res[k];
		p->maps[k].cached = p->maps[k].key && p->dev.cached && p->dev.cached(p->dev.cache_user, p->maps[k].key, tiles[k], res[k]);
	}
	p->nmaps = n;
	return RND_OK;
}

const char *rnd_map_plan_fitted(const struct rnd_plan *p, const struct rnd_map_plan *m)
{
	if (m->res == m->want) return "";
	return m->moments_capped && m->res == p->dev.moments_max_res
	       ? "moment maps are capped at what the device reads as one buffer"
	       : "halved, the largest first, until every map fits in the atlas";
}

const char *rnd_map_plan_state(const struct rnd_map_plan *m, const char **why)
{
	*why = !m->key ? "cascades and clipmap levels follow the camera: drawn by every view, never kept"
	       : m->cached ? "the atlas holds a completed map of this key (drawn by an earlier request)"
	                   : "no map of this key in the atlas: drawn, then kept for later requests";
	return !m->key ? "every view" : m->cached ? "cached" : "drawn";
}

/* View v's maps in their tiles (the side granted, the atlas's size; where comes with the grant),
 * which it draws and what they are estimated to cost; its passes and its bands' estimates. */
static enum rnd_result plan_view_work(struct rnd_plan *p, uint32_t v, struct rnd_shadow_plan *sp, struct draw *draws,
                                      struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	struct rnd_view_plan *vp = &p->views[v];
	rnd_plan_view_shadows(p, v, sp);
	for (uint32_t k = 0; k < p->nmaps; k++) {
		const struct rnd_map_plan *m = &p->maps[k];
		const struct rnd_light_plan *lp = &sp->lights[m->light];
		if (lp->view_count != m->tiles)
			return rnd_fail(err, RND_ERR_INVALID, "light %u: view %u needs %u shadow tiles, view 0 had %u", m->light, v,
			                lp->view_count, m->tiles);
		/* One cascade or clipmap level follows the camera too (it used to be taken for a fit
		 * map here: a sheet's later views read view 0's map through their own projection). */
		uint8_t skip = m->cached ? RND_SKIP_CACHED : v > 0 && !lp->follows_camera ? RND_SKIP_EARLIER_VIEW : RND_SKIP_NONE;
		for (uint32_t t = 0; t < lp->view_count; t++) {
			float *rect = sp->views[lp->first_view + t].rect;
			/* A tile fitted smaller than the light's plan asked (rnd_atlas_fit: the atlas full)
			 * covers the same view with fewer texels: the texel's world size (params[0], planned
			 * at rect[2]) grows with it, or PCSS, the contact march and the normal offset measure
			 * in texels 2-4x too small (issue 31: a point light at resolution 4096, fitted to
			 * 1024, had a 4x over-wide penumbra). */
			if (!sp->view_ortho[lp->first_view + t])
				rnd_plan_local_regrant(&sp->views[lp->first_view + t], lp, (float)m->res);
			sp->views[lp->first_view + t].params[0] *= rect[2] / (float)m->res;
			rect[2] = (float)m->res;
			rect[3] = (float)p->dev.atlas_size;
			vp->skip[lp->first_view + t] = skip;
			sp->view_skip[lp->first_view + t] = skip != RND_SKIP_NONE;
		}
	}
	memcpy(vp->views, sp->views, sp->view_count * sizeof *vp->views);
	memcpy(draws, p->draws, sc->object_count * sizeof *draws);
	rnd_plan_view_cull(p, v, draws);
	for (uint32_t k = 0; k < sp->view_count; k++)
		if (vp->skip[k] != RND_SKIP_EARLIER_VIEW)
			vp->map_ms[k] = rnd_cost_shadow_view_ms(sp, p->esc.lights, draws, sc->object_count, k, &vp->map_tris[k]);
	for (uint32_t i = 0; i < sc->object_count; i++) vp->camera_triangles += draws[i].cam_index_count / 3;
	vp->contact = rnd_contact_any(sc, sp);
	vp->vis = rnd_visibility_wanted(p->dev.visibility_pass, p->dev.visibility_force, sc, sp, draws, sc->object_count,
	                                &vp->vis_why);
	vp->env_pass = rnd_env_pass_wanted(sc, p->env.mapped, draws, sc->object_count, p->dev.env_pass_force);
	vp->deferred = rnd_pixel_shading_wanted(p->dev.pixel_shading, p->dev.visibility_pass, p->dev.pixel_shading_force, sc,
	                                        draws, sc->object_count, vp->vis, sc->environment.source != RND_ENV_AMBIENT,
	                                        &vp->deferred_why);
	double units = rnd_cost_pixel_units(sc, sp, vp->vis || vp->deferred, p->sheet.passes);
	rnd_cost_main(sc, vp->cam.view_proj, draws, sc->object_count, units, &vp->row_ms, &vp->band_ms);
	return RND_OK;
}

/* Every view's camera and shadow plan, the maps' tiles (from view 0), then each view's work. */
static enum rnd_result plan_views(struct rnd_plan *p, struct rnd_shadow_plan *sp, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	enum rnd_result r;
	uint8_t cascades[UMBRA_MAX_LIGHTS] = {0};
	p->nviews = p->sheet.views;
	p->views = plan_alloc(p, p->nviews * sizeof *p->views);
	struct draw *draws = plan_alloc(p, (sc->object_count ? sc->object_count : 1) * sizeof *draws);
	if (!p->views || !draws) return rnd_fail(err, RND_ERR_OOM, "out of memory for %u views", p->nviews);
	for (uint32_t v = 0; v < p->nviews; v++) {
		struct rnd_camera_plan *cam = &p->views[v].cam;
		if ((r = plan_camera(p, v, cam, err)) != RND_OK) return r;
		refit_proxies(p, cam);
		if ((r = plan_shadows(p, v, cam, cascades, sp, err)) != RND_OK) return r;
		if (v == 0 && (r = plan_maps(p, sp, err)) != RND_OK) return r;
		if ((r = keep_shadows(p, v, sp, err)) != RND_OK) return r;
	}
	for (uint32_t v = 0; v < p->nviews; v++)
		if ((r = plan_view_work(p, v, sp, draws, err)) != RND_OK) return r;
	return RND_OK;
}

/* What the render will measure, ready to be filled. */
static enum rnd_result plan_actual(struct rnd_plan *p, struct rnd_error *err)
{
	struct rnd_plan_actual *a = &p->actual;
	a->hit = plan_alloc(p, (p->nmaps ? p->nmaps : 1) * sizeof *a->hit);
	a->shadow_ms = plan_alloc(p, p->nviews * sizeof *a->shadow_ms);
	a->main_ms = plan_alloc(p, p->nviews * sizeof *a->main_ms);
	a->bands = plan_alloc(p, p->nviews * sizeof *a->bands);
	if (!a->hit || !a->shadow_ms || !a->main_ms || !a->bands) return rnd_fail(err, RND_ERR_OOM, "out of memory for the plan");
	return RND_OK;
}

enum rnd_result rnd_plan_build(const struct rnd_scene *sc, const struct rnd_plan_device *dev, struct rnd_plan *p,
                               struct rnd_error *err)
{
	memset(p, 0, sizeof *p);
	p->sc = sc;
	p->dev = *dev;
	enum rnd_result r;
	if ((r = validate(dev, sc, err)) != RND_OK) return r;
	if ((r = plan_memory(p, err)) != RND_OK) return r;
	/* One shadow plan of scratch (~33 KB): the level of detail's, then each view's. */
	struct rnd_shadow_plan *sp = plan_alloc(p, sizeof *sp);
	if (!sp) r = rnd_fail(err, RND_ERR_OOM, "out of memory for the shadow plan");
	if (r == RND_OK) r = plan_objects(p, sp, err);
	if (r == RND_OK) r = plan_views(p, sp, err);
	if (r == RND_OK) r = plan_actual(p, err);
	if (r != RND_OK) rnd_plan_release(p);
	return r;
}
