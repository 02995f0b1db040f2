/*
 * renderer/render.c — rnd_render(): one scene, start to finish, on one render slot.
 *
 *   validate -> tessellate straight into the slot's mapped vertex/index buffers (upload.c)
 *   -> per view: plan camera and shadow views, grant atlas tiles, write the frame constants
 *   (frame.c), then submit.c records and submits the shadow passes and the main pass (MSAA +
 *   resolve) with its copy into the readback buffer, in several submits when the scene has a
 *   deadline -> copy pixels out (readback.c).
 *
 * Every submit is waited on before the next, so nothing of this render is in flight when
 * rnd_render() returns (unless a fence wait itself failed: the context is then failed) and
 * the slot's resources may be reused or grown by the next render.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "contact.h"
#include "env_pass.h"
#include "env_shadow.h"
#include "proxy.h"
#include "visibility.h"
#include "estimate.h"
#include "frame.h"
#include "lod.h"
#include "material.h"
#include "mesh.h"
#include "plan.h"
#include "moments.h"
#include "readback.h"
#include "record.h"
#include "shadow_cache.h"
#include "submit.h"
#include "upload.h"

static double now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static enum rnd_result validate(const struct rnd_context *ctx, const struct rnd_scene *sc, struct rnd_error *err)
{
	if (sc->width < 1 || sc->height < 1 || sc->width > ctx->desc.max_width || sc->height > ctx->desc.max_height ||
	    sc->width > ctx->props.limits.maxImageDimension2D || sc->height > ctx->props.limits.maxImageDimension2D)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_SIZE, 0, "image %ux%u is outside 1..%u x 1..%u", sc->width, sc->height,
		                ctx->desc.max_width, ctx->desc.max_height);
	if (sc->output.msaa != 1 && sc->output.msaa != 4)
		return rnd_fail(err, RND_ERR_INVALID, "msaa %u: must be 1 or 4", sc->output.msaa);
	if ((unsigned)sc->output.pixels >= RND_COLOR_FORMAT_COUNT)
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

/* What one render holds from its start to its end; the slot is borrowed from the pool. */
struct render {
	struct rnd_context *ctx;
	const struct rnd_scene *sc;
	/* The scene as the shadow passes see it: its lights, then the environment's shadow
	 * directions (env_shadow.h), which only those passes and ibl.glsl's lookups use. */
	struct rnd_scene esc;
	struct rnd_light lights[UMBRA_MAX_LIGHTS];
	struct rnd_env_use env;
	struct rnd_slot *s;
	struct rnd_sheet sheet;
	void *arena;                  /* one block: draws, shadow plan, levels of detail, texture list */
	struct draw *draws;
	struct rnd_shadow_plan *sp;
	uint32_t *lod;
	struct rnd_proxy *proxies;     /* what the camera draws of each sphere (proxy.h) */
	const struct rnd_texture **tex;
	uint32_t ntex;
	struct rnd_pacer pacer;
	struct rnd_timings tm;
	struct rnd_aabb bounds;       /* every object: near/far planes, shadow fits */
	struct rnd_aabb obj_bounds;   /* what `fit: objects` frames */
	struct rnd_aabb casters;      /* what the shadow pass draws: a `fit` sun map's box */
	uint64_t geo;                 /* the casters' key: cached maps' keys start from it */
	struct rnd_cache_grant grants[UMBRA_MAX_LIGHTS];
	uint32_t grant_light[UMBRA_MAX_LIGHTS], req_tiles[UMBRA_MAX_LIGHTS];
	uint32_t ngrant;
	bool granted;
	bool gpu_busy;                /* a submit did not finish: keep its resources alive */
	uint8_t cascades[UMBRA_MAX_LIGHTS];
};

static enum rnd_result check_sheet(const struct rnd_sheet *sh, struct rnd_error *err)
{
	uint64_t sheet_w = sh->width, sheet_h = sh->height;
	if (sheet_w > RND_MAX_SHEET_SIDE || sheet_h > RND_MAX_SHEET_SIDE || sheet_w * sheet_h > RND_MAX_SHEET_PIXELS)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_VIEWS, 0, "a sheet of %u views is %llux%llu pixels: too large", sh->views,
		                (unsigned long long)sheet_w, (unsigned long long)sheet_h);
	return RND_OK;
}

/* Per-request memory: one block for the draw list, the shadow plan, the level of detail of
 * each object and the texture list. */
static enum rnd_result arena_init(struct render *rq, struct rnd_error *err)
{
	const struct rnd_scene *sc = rq->sc;
	size_t draws_bytes = (sc->object_count ? sc->object_count : 1) * sizeof(struct draw);
	size_t lod_bytes = (sc->object_count ? sc->object_count : 1) * sizeof(uint32_t);
	size_t proxy_off = (draws_bytes + sizeof(struct rnd_shadow_plan) + lod_bytes + 15) & ~(size_t)15;
	size_t proxy_bytes = (sc->object_count ? sc->object_count : 1) * sizeof(struct rnd_proxy);
	size_t tex_off = (proxy_off + proxy_bytes + 15) & ~(size_t)15;
	void *arena = malloc(tex_off + rq->ctx->max_textures * sizeof(void *));
	if (!arena) return rnd_fail(err, RND_ERR_OOM, "out of memory for %u objects", sc->object_count);
	rq->arena = arena;
	rq->draws = arena;
	rq->sp = (struct rnd_shadow_plan *)((char *)arena + draws_bytes);
	rq->lod = (uint32_t *)((char *)rq->sp + sizeof *rq->sp);
	rq->proxies = (struct rnd_proxy *)((char *)arena + proxy_off);
	rq->tex = (const struct rnd_texture **)((char *)arena + tex_off);
	rnd_lod_choose(sc, rq->sheet.views, rq->sp, rq->lod);
	rnd_lod_proxies(sc, rq->sheet.views, rq->lod, rq->proxies);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (rq->proxies[i].outline) rq->tm.sphere_proxies++;
	return RND_OK;
}

/* Auto-framing `fit: objects` leaves out planes and shadow catchers (the ground). */
static void frame_bounds(struct render *rq)
{
	const struct rnd_scene *sc = rq->sc;
	rnd_aabb_empty(&rq->obj_bounds);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (rnd_object_frames(&sc->objects[i], sc->material_count ? sc->materials : NULL))
			rnd_aabb_union(&rq->obj_bounds, &rq->draws[i].bounds);
	if (rnd_aabb_is_empty(&rq->obj_bounds)) rq->obj_bounds = rq->bounds;
}

/* A plane with every other object on its lit side shadows nothing: out of the shadow pass,
 * and so is one whose shadow falls only where no camera of the render sees it, on the parts
 * of objects sunk into it (rnd_plane_may_shadow_seen; studio-spots' boxes stand 24 cm deep in
 * its floor: in its maps the floor cost a whole-scene sun map and made the PCSS bounds' lit
 * proofs harder, a few % of the render). Unless a light filters with moments, whose blur
 * needs the ground behind a caster's edge in the map (rnd_moments_need_ground). Then the box
 * of what casts, which sizes a `fit` sun map: a plane drawn only for the moments' sake stays
 * out of it. It is the receiver around the casters, not a caster; inside the box's tile it is
 * drawn, outside it the sun is unblocked anyway. Counted, it made a VSM thumbnail's sun map cover the whole
 * 10 m floor: a 2048^2 map whose moments cost ~100 ms on lavapipe, for shadows within a 256^2
 * corner. */
#define RND_PLANE_CAMERAS 8u   /* renders of more views judge planes on geometry alone */
static void plane_casters(struct render *rq)
{
	const struct rnd_scene *sc = rq->sc;
	struct draw *draws = rq->draws;
	struct rnd_aabb b;
	struct rnd_camera_plan cams[RND_PLANE_CAMERAS];
	struct rnd_error err;
	uint32_t nviews = sc->view_count ? sc->view_count : 1, ncam = 0;
	for (uint32_t v = 0; v < nviews && nviews <= RND_PLANE_CAMERAS; v++) {
		const struct rnd_camera *camera = sc->view_count ? &sc->views[v] : &sc->camera;
		const struct rnd_aabb *fb = camera->fit == RND_FIT_OBJECTS ? &rq->obj_bounds : &rq->bounds;
		if (rnd_camera_plan(camera, sc->width, sc->height, fb, &cams[ncam], &err) != RND_OK) {
			ncam = 0;
			break;
		}
		ncam++;
	}
	bool moments = rnd_moments_need_ground(sc);
	bool fill_only[RND_PLANES_JUDGED_MAX] = {false};
	for (uint32_t i = 0; i < sc->object_count && rnd_planes_judged(sc); i++) {
		if (!draws[i].cast || sc->objects[i].shape != RND_SHAPE_PLANE) continue;
		/* seen: for the scene's lights; seen_env: for the environment's directions too (the
		 * plane then casts into their maps, but the box that sizes a sun's map stays the same) */
		bool other = false, seen = false, seen_env = false;
		for (uint32_t j = 0; j < sc->object_count && !seen; j++) {
			if (j == i) continue;
			rnd_object_bounds(sc, j, &draws[j].bounds, &b);
			if (rnd_aabb_is_empty(&b)) continue;
			other = true;
			seen = rnd_plane_may_shadow_seen(sc, &sc->objects[i], &b, cams, ncam);
			if (!seen_env && rq->esc.light_count > sc->light_count)
				seen_env = rnd_plane_may_shadow_seen(&rq->esc, &sc->objects[i], &b, cams, ncam);
		}
		draws[i].cast = seen || seen_env || (other && moments);
		fill_only[i] = draws[i].cast && !seen;
	}
	rnd_aabb_empty(&rq->casters);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (draws[i].cast && !(i < RND_PLANES_JUDGED_MAX && fill_only[i])) rnd_aabb_union(&rq->casters, &draws[i].bounds);
}

/* What every cached map's key starts from: the casters' world-space geometry, their
 * culling and alpha masks (with texture content), and the scene bounds (far planes). */
static uint64_t caster_key(const struct render *rq)
{
	const struct rnd_scene *sc = rq->sc;
	const struct rnd_slot *s = rq->s;
	uint64_t geo = rnd_hash(0x756d627261ull, &rq->bounds, sizeof rq->bounds);
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct draw *d = &rq->draws[i];
		if (!d->cast || !d->index_count) continue;
		uint32_t flags[3] = {d->single_sided, d->closed, d->masked};
		geo = rnd_hash(geo, flags, sizeof flags);
		geo = rnd_hash(geo, (const struct rnd_vertex *)s->vertices.cpu + d->first_vertex,
		               (size_t)d->vertex_count * sizeof(struct rnd_vertex));
		geo = rnd_hash(geo, (const uint32_t *)s->indices.cpu + d->first_index, (size_t)d->index_count * 4);
		if (d->masked) {
			const struct rnd_material *m = &sc->materials[sc->objects[i].material];
			geo = rnd_hash(geo, &m->alpha_cutoff, sizeof m->alpha_cutoff);
			geo = rnd_hash(geo, &m->alpha_mode, sizeof m->alpha_mode);
			geo = rnd_hash(geo, &m->sampling[RND_TEX_BASE], sizeof m->sampling[RND_TEX_BASE]);
			if (s->has_uv1 && m->sampling[RND_TEX_BASE].uv_set == 1)   /* the alpha test reads uv1 */
				geo = rnd_hash(geo, (const float *)s->uvs1.cpu + 2 * (size_t)d->first_vertex, (size_t)d->vertex_count * 8);
			geo = rnd_hash(geo, m->base_color, sizeof m->base_color);
			if (m->base_color_texture)
				geo = rnd_hash(geo, m->base_color_texture->rgba,
				               (size_t)m->base_color_texture->width * m->base_color_texture->height * 4);
		}
	}
	return geo;
}

/* The scene the shadow passes see (rq->esc): its lights, then the environment's directions
 * that get maps, as many as fit in UMBRA_MAX_LIGHTS. */
static void env_lights(struct render *rq)
{
	const struct rnd_scene *sc = rq->sc;
	float ground[3];
	bool has_ground = rnd_env_ground(sc, rq->draws, ground);
	rnd_env_shadow_dirs(&rq->env, &sc->environment, has_ground ? ground : NULL);
	rq->esc = *sc;
	uint32_t n = sc->light_count < UMBRA_MAX_LIGHTS ? sc->light_count : UMBRA_MAX_LIGHTS;
	if (!rq->env.mapped) return;
	memcpy(rq->lights, sc->lights, n * sizeof *rq->lights);
	rq->env.mapped = rnd_env_lights(&rq->env, &sc->environment, UMBRA_MAX_LIGHTS - n, rq->lights + n);
	rq->esc.lights = rq->lights;
	rq->esc.light_count = n + rq->env.mapped;
	rq->tm.env_directions = rq->env.mapped;
}

/* Everything before the first view: geometry, textures, targets, the readback buffer. */
static enum rnd_result prepare(struct render *rq, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	const struct rnd_scene *sc = rq->sc;
	struct rnd_slot *s = rq->s;
	enum rnd_result r;
	double t0 = now_ms();
	rnd_pacer_init(&rq->pacer, sc);
	if ((r = rnd_pacer_check(&rq->pacer, err)) != RND_OK) return r;
	double wait_until = sc->deadline_ns ? (double)sc->deadline_ns * 1e-9 : 0.0;
	if ((r = rnd_env_acquire(ctx, &sc->environment, wait_until, &rq->env, err)) != RND_OK) return r;
	rq->pacer.ctx = ctx;
	rq->pacer.env = &rq->env;
	if ((r = rnd_upload_scene(ctx, s, sc, &rq->pacer, rq->lod, rq->proxies, rq->draws, &rq->bounds, err)) != RND_OK) return r;
	frame_bounds(rq);
	env_lights(rq);
	if ((r = rnd_material_textures(ctx, s, sc, rq->draws, rq->tex, &rq->ntex, err)) != RND_OK) return r;
	rq->tm.upload_ms = now_ms() - t0;
	rq->pacer.tex = rq->tex;
	rq->pacer.ntex = rq->ntex;
	rq->pacer.prologue = true;

	VkFormat fmt = ctx->color_formats[sc->output.pixels];
	if ((r = rnd_slot_targets(ctx, s, fmt, sc->width, sc->height, sc->output.msaa, err)) != RND_OK) return r;
	if (rq->sheet.passes && (r = rnd_slot_aov(ctx, s, sc->width, sc->height, err)) != RND_OK) return r;
	VkDeviceSize rb = rq->sheet.readback_bytes;
	if ((r = rnd_buffer_reserve(ctx, &s->readback, rb, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "slot readback", err)) != RND_OK)
		return r;
	if (rq->sheet.views > 1) memset(s->readback.map, 0, rb); /* unused cells of the sheet (colour and AOVs) */
	plane_casters(rq);
	rq->geo = caster_key(rq);
	return RND_OK;
}

/* View v's camera and shadow plan. */
static enum rnd_result plan_view(struct render *rq, uint32_t v, struct rnd_camera_plan *cam, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	const struct rnd_scene *sc = rq->sc;
	struct rnd_shadow_plan *sp = rq->sp;
	struct draw *draws = rq->draws;
	enum rnd_result r;
	const struct rnd_camera *camera = sc->view_count ? &sc->views[v] : &sc->camera;
	if ((r = rnd_camera_plan(camera, sc->width, sc->height, camera->fit == RND_FIT_OBJECTS ? &rq->obj_bounds : &rq->bounds,
	                         cam, err)) != RND_OK)
		return r;
	if (camera->fit == RND_FIT_OBJECTS) {
		/* Framed on the objects, but near/far must still hold the whole scene. */
		struct rnd_camera c2 = *camera;
		memcpy(c2.position, cam->pos, sizeof cam->pos);
		for (int k = 0; k < 3; k++) c2.target[k] = cam->pos[k] + cam->fwd[k];
		c2.fit = RND_FIT_NONE;
		if ((r = rnd_camera_plan(&c2, sc->width, sc->height, &rq->bounds, cam, err)) != RND_OK) return r;
	}
	/* A proxy planned for a camera other than this one (a fitted camera, placed here from the
	 * tessellated shapes' bounds, lod.c from the shapes as asked): placed again for this one,
	 * in the same vertices (nothing of this render has been submitted yet); where it cannot be
	 * (this camera inside the sphere, or its near plane cutting it), the sphere's mesh. */
	for (uint32_t i = 0; i < sc->object_count; i++) {
		struct draw *d = &draws[i];
		if (!(d->flags & UMBRA_DRAW_SPHERE)) continue;
		bool moved;
		if (rnd_proxy_refit(&rq->proxies[i], cam, &moved)) {
			if (moved) {
				struct rnd_slot *s = rq->s;
				rnd_proxy_write(&rq->proxies[i], (struct rnd_vertex *)s->vertices.cpu + d->cam_first_vertex,
				                (uint32_t *)s->indices.cpu + d->cam_first_index, d->cam_first_vertex);
				uint32_t nv, ni;
				rnd_proxy_counts(&rq->proxies[i], &nv, &ni);
				rnd_buffer_publish(&s->vertices, (VkDeviceSize)d->cam_first_vertex * sizeof(struct rnd_vertex),
				                   (VkDeviceSize)nv * sizeof(struct rnd_vertex));
				rnd_buffer_publish(&s->indices, (VkDeviceSize)d->cam_first_index * 4, (VkDeviceSize)ni * 4);
			}
			continue;
		}
		d->flags &= ~UMBRA_DRAW_SPHERE;
		d->cam_first_index = d->first_index;
		d->cam_index_count = d->index_count;
		rq->tm.sphere_proxies--;
	}
	for (uint32_t i = 0; i < sc->object_count; i++) rq->tm.camera_triangles += draws[i].cam_index_count / 3;
	/* A sphere's proxy has no back: its slivers along the outline must not be culled. */
	for (uint32_t i = 0; i < sc->object_count; i++)
		draws[i].cull_back = !(draws[i].flags & UMBRA_DRAW_SPHERE) &&
		                     (draws[i].single_sided || (draws[i].closed && record_camera_outside(cam, &draws[i].bounds)));
	const struct rnd_scene *esc = &rq->esc;
	if ((r = rnd_shadow_plan_with(esc, &rq->bounds, &rq->casters, cam, v ? rq->cascades : NULL, sp, err)) != RND_OK)
		return r;
	if (v == 0)
		for (uint32_t i = 0; i < esc->light_count && i < UMBRA_MAX_LIGHTS; i++)
			rq->cascades[i] = sp->lights[i].follows_camera && !sp->lights[i].clipmap;
	bool any_moments = false;
	for (uint32_t i = 0; i < sc->light_count; i++)
		if (sp->lights[i].moments && sp->lights[i].view_count) any_moments = true;
	if (any_moments && !ctx->atlas_moments.img)
		return rnd_fail(err, RND_ERR_INVALID, "shadow filters vsm/evsm need storage images this device lacks");
	for (uint32_t i = 0; i < sc->light_count; i++) {
		struct rnd_light_plan *lp = &sp->lights[i];
		/* exp(2cd) must stay finite in the precision asked for (fp16 storage limits c). */
		float cmax = rnd_moments_max_exponent(lp->fp16 ? VK_FORMAT_R16G16_SFLOAT : ctx->atlas_moments.format);
		if (lp->evsm) lp->evsm_exponent = lp->evsm_exponent > 0 ? fminf(lp->evsm_exponent, cmax) : cmax;
	}
	return RND_OK;
}

/* Tiles: granted once per request. Maps that do not follow the camera (spot and point
 * lights, a sun's one `fit` map) are keyed for reuse by later requests: the casters' geometry,
 * the light's filter and bias and its views (where the map looks, at what resolution) make
 * the key; cascades and clipmap levels are transient. Later views re-render only the maps
 * that follow the camera into the same tiles. */
static enum rnd_result grant_tiles(struct render *rq, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	const struct rnd_scene *sc = &rq->esc;
	const struct rnd_shadow_plan *sp = rq->sp;
	struct rnd_cache_request req[UMBRA_MAX_LIGHTS];
	uint32_t ngrant = 0;
	for (uint32_t i = 0; i < sc->light_count; i++) {
		const struct rnd_light_plan *lp = &sp->lights[i];
		if (!lp->view_count) continue;
		uint64_t key = 0;
		if (!lp->follows_camera) {
			float k[8] = {lp->bias_constant, lp->bias_slope, (float)lp->resolution, (float)lp->filter,
			              lp->moments ? (lp->evsm ? lp->evsm_exponent : -1.0f) : 0.0f,
			              lp->moments ? sc->lights[i].shadow.vsm_blur : 0.0f, (float)sc->lights[i].type, 0};
			key = rnd_hash(rq->geo, k, sizeof k);
			key = rnd_hash(key, &sp->views[lp->first_view], lp->view_count * sizeof(struct umbra_shadow_view));
			if (!key) key = 1;
		}
		rq->grant_light[ngrant] = i;
		rq->req_tiles[ngrant] = lp->view_count;
		/* Moment maps are read as a storage buffer: at most the device's range. */
		uint32_t res = lp->resolution, mmax = rnd_moments_max_res(ctx);
		if (lp->moments && res > mmax) res = mmax;
		req[ngrant++] = (struct rnd_cache_request){key, lp->view_count, res};
	}
	/* Waiting for atlas room counts against the render's deadline like its submits. */
	double wait_until = sc->deadline_ns ? (double)sc->deadline_ns * 1e-9 : 0.0;
	enum rnd_result r = rnd_cache_acquire(ctx, req, ngrant, wait_until, rq->grants, err);
	if (r != RND_OK) return r;
	rq->ngrant = ngrant;
	rq->granted = true;
	return RND_OK;
}

/* Points view v's shadow views at their granted tiles, marks the ones that need no pass (a
 * cache hit, or a map that does not follow the camera after view 0) and sizes the slot's
 * scratch for the largest map drawn. */
static enum rnd_result place_tiles(struct render *rq, uint32_t v, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	struct rnd_shadow_plan *sp = rq->sp;
	const struct rnd_cache_grant *grants = rq->grants;
	enum rnd_result r;
	uint32_t max_moment_res = 0;
	for (uint32_t k = 0; k < rq->ngrant; k++) {
		const struct rnd_light_plan *lp = &sp->lights[rq->grant_light[k]];
		if (lp->view_count != rq->req_tiles[k])
			return rnd_fail(err, RND_ERR_INVALID, "light %u: view %u needs %u shadow tiles, view 0 had %u",
			                rq->grant_light[k], v, lp->view_count, rq->req_tiles[k]);
		/* One cascade or clipmap level follows the camera too (it used to be taken for a fit
		 * map here: a sheet's later views read view 0's map through their own projection). */
		bool skip = grants[k].hit || (v > 0 && !lp->follows_camera);
		for (uint32_t t = 0; t < lp->view_count; t++) {
			float *rect = sp->views[lp->first_view + t].rect;
			rect[0] = (float)grants[k].tile[t].x;
			rect[1] = (float)grants[k].tile[t].y;
			rect[2] = (float)grants[k].res;
			rect[3] = (float)ctx->desc.atlas_size;
			sp->view_skip[lp->first_view + t] = skip;
			if (skip) rq->tm.shadow_maps_reused++;
			else {
				rq->tm.shadow_maps_rendered++;
				rq->tm.shadow_texels += (uint64_t)grants[k].res * grants[k].res;
			}
		}
		if (lp->moments && !skip && grants[k].res > max_moment_res) max_moment_res = grants[k].res;
	}
	if (max_moment_res && (r = rnd_slot_moments_tmp(ctx, rq->s, max_moment_res, err)) != RND_OK) return r;
	uint32_t max_res = 64;
	for (uint32_t k = 0; k < rq->ngrant; k++)
		if (grants[k].res > max_res) max_res = grants[k].res;
	return rnd_slot_shadow_scratch(ctx, rq->s, max_res, err);
}

/* View v: planned, its tiles placed, its constants written, recorded and submitted. */
static enum rnd_result render_view(struct render *rq, uint32_t v, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	const struct rnd_scene *sc = rq->sc;
	struct rnd_slot *s = rq->s;
	const struct rnd_sheet *sh = &rq->sheet;
	const struct rnd_camera *camera = sc->view_count ? &sc->views[v] : &sc->camera;
	struct rnd_camera_plan cam;
	enum rnd_result r;
	if ((r = plan_view(rq, v, &cam, err)) != RND_OK) return r;
	if (!rq->granted && (r = grant_tiles(rq, err)) != RND_OK) return r;
	if ((r = place_tiles(rq, v, err)) != RND_OK) return r;
	bool contact = rnd_contact_any(sc, rq->sp);
	if (contact && (r = rnd_slot_scene_depth(ctx, s, sc->width, sc->height, err)) != RND_OK) return r;
	bool vis = rnd_visibility_wanted(ctx, sc, rq->sp, rq->draws, sc->object_count);
	/* Without the pass its bindings still need images (lavapipe reads every descriptor of a
	 * bound set): whatever the slot has, or 1x1 ones. */
	r = vis ? rnd_slot_visibility(ctx, s, sc->width, sc->height, sc->light_count, err)
	        : s->surfaces.img && s->visibility.img ? RND_OK : rnd_slot_visibility(ctx, s, 1, 1, 1, err);
	if (r != RND_OK) return r;
	if (vis) rq->tm.visibility_views++;
	bool env_pass = rnd_env_pass_wanted(sc, &rq->env, rq->draws, sc->object_count);
	if (env_pass && (r = rnd_slot_env_pass(ctx, s, sc->width, sc->height, err)) != RND_OK) return r;
	if ((r = rnd_frame_write(ctx, s, &rq->esc, &cam, rq->sp, camera->exposure, contact, &rq->env, env_pass, err)) != RND_OK)
		return r;

	uint32_t col = v % sh->cols, row = v / sh->cols;
	VkDeviceSize cell = ((VkDeviceSize)row * sc->height * sh->width + (VkDeviceSize)col * sc->width);
	struct record_view rv = {
		.sc = sc, .cam = &cam, .sp = rq->sp, .draws = rq->draws, .ndraw = sc->object_count, .aov_passes = sh->passes,
		.color_offset = cell * sh->px, .aov_offset = sh->color_bytes + cell * 16, .aov_stride = sh->att_bytes,
		.sheet_width = (uint32_t)sh->width, .pixel_bytes = (uint32_t)sh->px, .contact = contact,
		.vis = vis, .shadow_lights = rq->esc.lights, .env = &rq->env, .env_pass = env_pass,
	};
	return rnd_submit_view(ctx, s, &rv, &rq->pacer, &rq->tm, &rq->gpu_busy, err);
}

/* The end of every render that got a slot, whatever r is. */
static void finish(struct render *rq, enum rnd_result r, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	if (r == RND_ERR_DEVICE_LOST) {
		__atomic_store_n(&ctx->failed, 1, __ATOMIC_RELAXED);
		rnd_cache_wake(ctx);   /* renders waiting for atlas room: they would wait for ever */
		rnd_log(ctx, 0, "device lost: %s", err->msg);
	}
	/* Everything this render submitted has completed (each submit is waited on; a failed
	 * vkQueueSubmit leaves nothing in flight, a deadline stops between submits) — unless a
	 * fence wait failed: then the GPU may still use the tiles and textures, and they stay held
	 * (the context is failed and must be recreated, which waits for the device first). Any
	 * other failure, out of memory included, gives its tiles back to the atlas here. */
	if (!rq->gpu_busy) {
		if (rq->granted) rnd_cache_release(ctx, rq->grants, rq->ngrant, r == RND_OK);
		rnd_slot_drop_textures(ctx, rq->s);
		rnd_slot_trim(ctx, rq->s);
	}
	rq->tm.env_ms = rq->env.ms;
	rnd_env_done(ctx, &rq->env, r == RND_OK, rq->gpu_busy);
	rnd_slot_release(ctx, rq->s);
	free(rq->arena);
}

enum rnd_result rnd_render(struct rnd_context *ctx, const struct rnd_scene *sc, struct rnd_image *out,
                           struct rnd_timings *timings, struct rnd_error *err)
{
	enum rnd_result r;
	struct rnd_error scratch_err;
	if (!err) err = &scratch_err;   /* failure paths below always fill it */
	memset(out, 0, sizeof *out);
	memset(err, 0, sizeof *err);
	if (!ctx) return rnd_fail(err, RND_ERR_NO_DEVICE, "no renderer context (rnd_context_create failed?)");
	if (__atomic_load_n(&ctx->failed, __ATOMIC_RELAXED))
		return rnd_fail(err, RND_ERR_DEVICE_LOST, "the Vulkan device was lost earlier; the context must be recreated");
	if ((r = validate(ctx, sc, err)) != RND_OK) return r;

	struct render rq = {.ctx = ctx, .sc = sc};
	rnd_sheet_init(&rq.sheet, sc);
	if ((r = check_sheet(&rq.sheet, err)) != RND_OK) return r;
	struct rnd_estimate est;
	if ((r = rnd_render_estimate(ctx, sc, &est, err)) != RND_OK) return r;
	if ((r = arena_init(&rq, err)) != RND_OK) return r;

	rq.s = rnd_slot_acquire(ctx);
	if ((r = prepare(&rq, err)) != RND_OK) goto done;
	for (uint32_t v = 0; v < rq.sheet.views; v++)
		if ((r = render_view(&rq, v, err)) != RND_OK) goto done;

	double t_copy = now_ms();
	if ((r = rnd_readback_image(rq.s, sc, &rq.sheet, out, err)) != RND_OK) goto done;
	rq.tm.readback_ms += now_ms() - t_copy;

done:
	finish(&rq, r, err);
	rq.tm.submits = rq.pacer.submits;
	rq.tm.shadow_parts = rq.pacer.shadow_parts;
	if (timings) *timings = rq.tm;
	return r;
}
