/*
 * renderer/render.c — a render plan executed (render_plan.h), start to finish, on one render
 * slot; and the public entry points that make and run plans (rnd_plan_create, rnd_render_plan,
 * rnd_render).
 *
 *   the plan (made before, once) -> tessellate straight into the slot's mapped vertex/index
 *   buffers where the plan's draws say (upload.c) -> grant the plan's atlas tiles -> per view:
 *   its shadow views placed in their tiles, its frame constants written (frame.c), then
 *   submit.c records and submits the shadow passes and the main pass (MSAA + resolve) with its
 *   copy into the readback buffer, in several submits when the scene has a deadline -> copy
 *   pixels out (readback.c).
 *
 * Nothing here decides what to draw: each choice is the plan's. What the render learns as it
 * runs (whether the atlas still held a cached map, how long each step took) goes into the
 * plan's `actual` for EXPLAIN ANALYZE.
 *
 * Every submit is waited on before the next, so nothing of this render is in flight when
 * rnd_render() returns (unless a fence wait itself failed: the context is then failed) and
 * the slot's resources may be reused or grown by the next render.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "deferred.h"
#include "env.h"
#include "env_pass.h"
#include "frame.h"
#include "material.h"
#include "moments.h"
#include "readback.h"
#include "render_plan.h"
#include "shadow_cache.h"
#include "submit.h"
#include "upload.h"

/* ---- plans on a context ---- */

static bool cache_probe(void *user, uint64_t key, uint32_t tiles, uint32_t res)
{
	return rnd_cache_probe(user, key, tiles, res);
}

/* What the plan needs to know of ctx. */
static void plan_device(struct rnd_context *ctx, struct rnd_plan_device *d)
{
	memset(d, 0, sizeof *d);
	d->max_width = ctx->desc.max_width;
	d->max_height = ctx->desc.max_height;
	d->max_image_dimension = ctx->props.limits.maxImageDimension2D;
	d->atlas_size = ctx->desc.atlas_size;
	d->max_allocation = ctx->max_allocation;
	d->max_textures = ctx->max_textures;
	d->moments_max_res = rnd_moments_max_res(ctx);
	d->moments = ctx->atlas_moments.img != VK_NULL_HANDLE;
	d->pcss_bounds = ctx->atlas_bounds.img != VK_NULL_HANDLE;
	d->evsm_max_exponent = rnd_moments_max_exponent(ctx->atlas_moments.format);
	d->evsm_max_exponent_fp16 = rnd_moments_max_exponent(VK_FORMAT_R16G16_SFLOAT);
	d->visibility_pass = ctx->visibility_pass;
	/* UMBRA_VISIBILITY=0 / 1 forces the pass off / on where it can run (tests, comparisons). */
	const char *env = getenv("UMBRA_VISIBILITY");
	d->visibility_force = env && strcmp(env, "0") == 0 ? 0 : env && strcmp(env, "1") == 0 ? 1 : -1;
	const char *ep = getenv("UMBRA_ENV_PASS");   /* 0: the environment's shadows per fragment (tests) */
	d->env_pass_force = ep && strcmp(ep, "0") == 0 ? 0 : -1;
	/* UMBRA_CASTER_LEVEL=0: the environment's maps draw what the camera draws (comparisons) */
	const char *cl = getenv("UMBRA_CASTER_LEVEL");
	d->caster_levels_off = cl && strcmp(cl, "0") == 0;
	const char *cb = getenv("UMBRA_CASTER_BIAS");   /* 0: without their bias (tests: the acne it prevents) */
	d->caster_bias_off = cb && strcmp(cb, "0") == 0;
	d->pixel_shading = ctx->pixel_shading;
	const char *ps = getenv("UMBRA_PIXEL_SHADING");   /* 0: shaded per fragment (tests, comparisons) */
	d->pixel_shading_force = ps && strcmp(ps, "0") == 0 ? 0 : -1;
	d->cached = cache_probe;
	d->cache_user = ctx;
}

enum rnd_result rnd_plan_create(struct rnd_context *ctx, const struct rnd_scene *sc, struct rnd_plan **out,
                                struct rnd_error *err)
{
	struct rnd_error scratch_err;
	if (!err) err = &scratch_err;
	memset(err, 0, sizeof *err);
	*out = NULL;
	if (!ctx) return rnd_fail(err, RND_ERR_NO_DEVICE, "no renderer context (rnd_context_create failed?)");
	if (__atomic_load_n(&ctx->failed, __ATOMIC_RELAXED))
		return rnd_fail(err, RND_ERR_DEVICE_LOST, "the Vulkan device was lost earlier; the context must be recreated");
	struct rnd_plan *p = calloc(1, sizeof *p);
	if (!p) return rnd_fail(err, RND_ERR_OOM, "out of memory for a render plan");
	struct rnd_plan_device dev;
	double t0 = rnd_now_ms();
	plan_device(ctx, &dev);
	struct rnd_env_bins *bins = NULL;
	enum rnd_result r = rnd_env_plan_bins(ctx, &sc->environment, &bins, err);
	dev.env_bins = bins;
	if (r == RND_OK) r = rnd_plan_build(sc, &dev, p, err);
	if (r != RND_OK) {
		free(bins);
		free(p);
		return r;
	}
	p->env_bins = bins;
	p->dev.cached = NULL;   /* the plan outlives no context it was made on */
	p->dev.cache_user = NULL;
	p->context = ctx;
	p->plan_ms = rnd_now_ms() - t0;
	*out = p;
	return RND_OK;
}

void rnd_plan_destroy(struct rnd_plan *p)
{
	if (!p) return;
	free(p->env_bins);
	rnd_plan_release(p);
	free(p);
}

void rnd_plan_estimate(const struct rnd_plan *p, struct rnd_estimate *est)
{
	*est = p->est;
}

/* ---- one render ---- */

/* What one render holds from its start to its end; the slot is borrowed from the pool. */
struct render {
	struct rnd_context *ctx;
	struct rnd_plan *plan;
	const struct rnd_scene *sc;
	struct rnd_env_use env;       /* its environment map (env.h), held to the end */
	struct rnd_slot *s;
	void *arena;                  /* one block: draws, shadow plan, estimates, texture list */
	struct draw *draws;           /* the plan's, with their textures, culled for the view drawn */
	struct rnd_shadow_plan *sp;   /* the view drawn's, placed in its tiles */
	double *map_ms;               /* the plan's estimates of the maps this view draws (0: skipped) */
	uint64_t *map_tris;
	const struct rnd_texture **tex;
	uint32_t ntex;
	struct rnd_pacer pacer;
	struct rnd_timings tm;
	struct rnd_cache_grant grants[UMBRA_MAX_LIGHTS];
	bool granted;
	bool gpu_busy;                /* a submit did not finish: keep its resources alive */
};

/* Per-render memory: one block for the draws, a shadow plan, the maps' estimates and the
 * texture list. */
static enum rnd_result arena_init(struct render *rq, struct rnd_error *err)
{
	const struct rnd_scene *sc = rq->sc;
	size_t n = sc->object_count ? sc->object_count : 1;
	size_t draws_bytes = (n * sizeof(struct draw) + 15) & ~(size_t)15;
	size_t est_bytes = UMBRA_MAX_SHADOW_VIEWS * (sizeof(double) + sizeof(uint64_t));
	size_t tex_off = (draws_bytes + sizeof(struct rnd_shadow_plan) + est_bytes + 15) & ~(size_t)15;
	char *arena = malloc(tex_off + rq->ctx->max_textures * sizeof(void *));
	if (!arena) return rnd_fail(err, RND_ERR_OOM, "out of memory for %u objects", sc->object_count);
	rq->arena = arena;
	rq->draws = (struct draw *)arena;
	rq->sp = (struct rnd_shadow_plan *)(arena + draws_bytes);
	rq->map_ms = (double *)(arena + draws_bytes + sizeof(struct rnd_shadow_plan));
	rq->map_tris = (uint64_t *)(rq->map_ms + UMBRA_MAX_SHADOW_VIEWS);
	rq->tex = (const struct rnd_texture **)(arena + tex_off);
	memcpy(rq->draws, rq->plan->draws, sc->object_count * sizeof *rq->draws);
	return RND_OK;
}

/* Everything before the first view: geometry, textures, targets, the readback buffer. */
static enum rnd_result prepare(struct render *rq, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	const struct rnd_scene *sc = rq->sc;
	const struct rnd_sheet *sh = &rq->plan->sheet;
	struct rnd_slot *s = rq->s;
	enum rnd_result r;
	double t0 = rnd_now_ms();
	rnd_pacer_init(&rq->pacer, sc);
	if ((r = rnd_pacer_check(&rq->pacer, err)) != RND_OK) return r;
	/* The environment's map before any shadow tile is granted (a render never waits for a map
	 * while it holds tiles); its shadow directions are the plan's. */
	double wait_until = sc->deadline_ns ? (double)sc->deadline_ns * 1e-9 : 0.0;
	if ((r = rnd_env_acquire(ctx, &sc->environment, rq->plan->env_bins, wait_until, &rq->env, err)) != RND_OK)
		return r;
	rnd_env_shadow_dirs(&rq->env, &rq->plan->env);
	rq->tm.env_directions = rq->env.mapped;
	rq->pacer.ctx = ctx;
	rq->pacer.env = &rq->env;
	if ((r = rnd_upload_scene(ctx, s, rq->plan, &rq->pacer, err)) != RND_OK) return r;
	if ((r = rnd_material_textures(ctx, s, sc, rq->draws, rq->tex, &rq->ntex, err)) != RND_OK) return r;
	rq->tm.upload_ms = rnd_now_ms() - t0;
	rq->pacer.tex = rq->tex;
	rq->pacer.ntex = rq->ntex;
	rq->pacer.prologue = true;

	double t1 = rnd_now_ms();
	VkFormat fmt = ctx->color_formats[sc->output.pixels];
	if ((r = rnd_slot_targets(ctx, s, fmt, sc->width, sc->height, sc->output.msaa, err)) != RND_OK) return r;
	if (sh->passes && (r = rnd_slot_aov(ctx, s, sc->width, sc->height, err)) != RND_OK) return r;
	VkDeviceSize rb = sh->readback_bytes;
	if ((r = rnd_buffer_reserve(ctx, &s->readback, rb, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "slot readback", err)) != RND_OK)
		return r;
	if (sh->views > 1) memset(s->readback.map, 0, rb); /* unused cells of the sheet (colour and AOVs) */
	rq->tm.targets_ms = rnd_now_ms() - t1;
	return RND_OK;
}

/* The plan's tiles, granted once per request (shadow_cache.c): a map whose key the cache holds
 * completed is a hit, drawn by nobody. */
static enum rnd_result grant_tiles(struct render *rq, struct rnd_error *err)
{
	const struct rnd_plan *p = rq->plan;
	struct rnd_cache_request req[UMBRA_MAX_LIGHTS];
	for (uint32_t k = 0; k < p->nmaps; k++) req[k] = (struct rnd_cache_request){p->maps[k].key, p->maps[k].tiles, p->maps[k].res};
	/* Waiting for atlas room counts against the render's deadline like its submits. */
	double wait_until = rq->sc->deadline_ns ? (double)rq->sc->deadline_ns * 1e-9 : 0.0;
	enum rnd_result r = rnd_cache_acquire(rq->ctx, req, p->nmaps, wait_until, rq->grants, err);
	if (r != RND_OK) return r;
	rq->granted = true;
	for (uint32_t k = 0; k < p->nmaps; k++) p->actual.hit[k] = rq->grants[k].hit;
	return RND_OK;
}

/* Points view v's shadow views at their granted tiles, marks the ones that need no pass (a
 * cache hit, or a map that does not follow the camera after view 0) and sizes the slot's
 * scratch for the largest map drawn. */
static enum rnd_result place_tiles(struct render *rq, uint32_t v, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	const struct rnd_plan *p = rq->plan;
	const struct rnd_view_plan *vp = &p->views[v];
	struct rnd_shadow_plan *sp = rq->sp;
	const struct rnd_cache_grant *grants = rq->grants;
	enum rnd_result r;
	uint32_t max_moment_res = 0, max_res = 64;
	for (uint32_t k = 0; k < p->nmaps; k++) {
		const struct rnd_light_plan *lp = &sp->lights[p->maps[k].light];
		bool skip = grants[k].hit || vp->skip[lp->first_view] == RND_SKIP_EARLIER_VIEW;
		for (uint32_t t = 0; t < lp->view_count; t++) {
			uint32_t sv = lp->first_view + t;
			sp->views[sv].rect[0] = (float)grants[k].tile[t].x;
			sp->views[sv].rect[1] = (float)grants[k].tile[t].y;
			sp->view_skip[sv] = skip;
			rq->map_ms[sv] = skip ? 0.0 : vp->map_ms[sv];
			rq->map_tris[sv] = vp->map_tris[sv];
			if (skip) rq->tm.shadow_maps_reused++;
			else {
				rq->tm.shadow_maps_rendered++;
				rq->tm.shadow_texels += (uint64_t)grants[k].res * grants[k].res;
			}
		}
		if (lp->moments && !skip && grants[k].res > max_moment_res) max_moment_res = grants[k].res;
		if (grants[k].res > max_res) max_res = grants[k].res;
	}
	if (max_moment_res && (r = rnd_slot_moments_tmp(ctx, rq->s, max_moment_res, err)) != RND_OK) return r;
	return rnd_slot_shadow_scratch(ctx, rq->s, max_res, err);
}

/* The key of the view's environment pass (env_pass.h) once its constants are written; 0 where the
 * slot's images are not to be reused (UMBRA_ENV_PASS_REUSE=0: comparisons and tests). */
static uint64_t env_pass_key(const struct render *rq)
{
	const char *e = getenv("UMBRA_ENV_PASS_REUSE");
	if (e && strcmp(e, "0") == 0) return 0;
	const struct rnd_plan *p = rq->plan;
	uint64_t keys[UMBRA_MAX_LIGHTS];
	for (uint32_t k = 0; k < p->nmaps; k++) keys[k] = p->maps[k].key;
	struct record_view rv = {.sc = rq->sc, .draws = rq->draws, .ndraw = rq->sc->object_count};
	return rnd_env_pass_key(rq->s, &rv, keys, p->nmaps, p->vertices * sizeof(struct rnd_vertex),
	                        p->indices * sizeof(uint32_t));
}

/* View v as planned: its tiles placed, its constants written, recorded and submitted. */
static enum rnd_result render_view(struct render *rq, uint32_t v, struct rnd_error *err)
{
	struct rnd_context *ctx = rq->ctx;
	const struct rnd_scene *sc = rq->sc;
	struct rnd_plan *p = rq->plan;
	const struct rnd_view_plan *vp = &p->views[v];
	struct rnd_slot *s = rq->s;
	const struct rnd_sheet *sh = &p->sheet;
	const struct rnd_camera *camera = sc->view_count ? &sc->views[v] : &sc->camera;
	enum rnd_result r;
	rnd_plan_view_shadows(p, v, rq->sp);
	rnd_plan_view_cull(p, v, rq->draws);
	if (!rq->granted && (r = grant_tiles(rq, err)) != RND_OK) return r;
	if ((r = place_tiles(rq, v, err)) != RND_OK) return r;
	if (vp->contact && (r = rnd_slot_scene_depth(ctx, s, sc->width, sc->height, err)) != RND_OK) return r;
	/* Pixel shading (deferred.c) on the visibility pass's surfaces, or on its own ones (an
	 * environment map's view): the visibility pass's passes run for either; its bindings need
	 * images whether it runs or not. */
	bool passes = vp->vis || vp->deferred;
	/* Without the pass its bindings still need images (lavapipe reads every descriptor of a
	 * bound set): whatever the slot has, or 1x1 ones. */
	r = passes ? rnd_slot_visibility(ctx, s, sc->width, sc->height, sc->light_count, err)
	           : s->surfaces.img && s->visibility.img ? RND_OK : rnd_slot_visibility(ctx, s, 1, 1, 1, err);
	if (r != RND_OK) return r;
	if (vp->vis) rq->tm.visibility_views++;
	r = vp->deferred ? rnd_slot_pixel_shading(ctx, s, sc->width, sc->height, ctx->color_formats[sc->output.pixels], err)
	    : s->shading.img && s->shaded.img ? RND_OK : rnd_slot_pixel_shading(ctx, s, 1, 1, VK_FORMAT_R8G8B8A8_UNORM, err);
	if (r != RND_OK) return r;
	if (vp->deferred) rq->tm.pixel_shaded_views++;
	if (vp->env_pass && (r = rnd_slot_env_pass(ctx, s, sc->width, sc->height, err)) != RND_OK) return r;
	if ((r = rnd_frame_write(ctx, s, &p->esc, &vp->cam, rq->sp, camera->exposure, vp->contact, &rq->env, vp->env_pass,
	                         err)) != RND_OK)
		return r;

	uint64_t env_key = vp->env_pass ? env_pass_key(rq) : 0;
	bool env_reused = env_key && env_key == s->env_pass_key;
	if (!env_reused) s->env_pass_key = 0;   /* its images are drawn again (or not this view's) */
	if (env_reused) rq->tm.env_passes_reused++;

	uint32_t col = v % sh->cols, row = v / sh->cols;
	VkDeviceSize cell = ((VkDeviceSize)row * sc->height * sh->width + (VkDeviceSize)col * sc->width);
	struct record_view rv = {
		.sc = sc, .cam = &vp->cam, .sp = rq->sp, .draws = rq->draws, .ndraw = sc->object_count, .aov_passes = sh->passes,
		.color_offset = cell * sh->px, .aov_offset = sh->color_bytes + cell * 16, .aov_stride = sh->att_bytes,
		.sheet_width = (uint32_t)sh->width, .pixel_bytes = (uint32_t)sh->px, .contact = vp->contact, .vis = passes,
		.deferred = vp->deferred, .map_ms = rq->map_ms, .map_tris = rq->map_tris, .row_ms = vp->row_ms,
		.band_ms = vp->band_ms, .drawn_camera = &rq->tm.camera_triangles, .drawn_shadow = &rq->tm.shadow_triangles,
		.shadow_lights = p->esc.lights, .env = &rq->env, .env_pass = vp->env_pass, .env_pass_reused = env_reused,
	};
	double shadow0 = rq->tm.shadow_ms, main0 = rq->tm.main_ms;
	uint32_t bands0 = rq->pacer.measured;
	r = rnd_submit_view(ctx, s, &rv, &rq->pacer, &rq->tm, &rq->gpu_busy, err);
	if (r == RND_OK && env_key) s->env_pass_key = env_key;   /* its submits completed */
	p->actual.shadow_ms[v] = rq->tm.shadow_ms - shadow0;
	p->actual.main_ms[v] = rq->tm.main_ms - main0;
	p->actual.bands[v] = rq->pacer.measured - bands0;
	return r;
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
		if (rq->granted) rnd_cache_release(ctx, rq->grants, rq->plan->nmaps, r == RND_OK);
		rnd_slot_drop_textures(ctx, rq->s);
		rnd_slot_trim(ctx, rq->s);
	}
	rq->tm.env_ms = rq->env.ms;
	rnd_env_done(ctx, &rq->env, r == RND_OK, rq->gpu_busy);
	rnd_slot_release(ctx, rq->s);
	rnd_pipelines_reap(ctx);   /* variants retired while this render ran */
	free(rq->arena);
}

enum rnd_result rnd_render_plan(struct rnd_context *ctx, struct rnd_plan *plan, struct rnd_image *out,
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
	if (plan->context != ctx)
		return rnd_fail(err, RND_ERR_INVALID, "the plan was made for another renderer context");
	if (plan->actual.done)
		return rnd_fail(err, RND_ERR_INVALID, "the plan has been rendered already: make another");
	struct render rq = {.ctx = ctx, .plan = plan, .sc = plan->sc};
	rq.tm.sphere_proxies = plan->sphere_proxies;
	rq.tm.plan_ms = plan->plan_ms;
	if ((r = arena_init(&rq, err)) != RND_OK) return r;

	double compiled = rnd_compile_ms_tls;
	rq.s = rnd_slot_acquire(ctx);
	if ((r = prepare(&rq, err)) != RND_OK) goto done;
	for (uint32_t v = 0; v < plan->nviews; v++)
		if ((r = render_view(&rq, v, err)) != RND_OK) goto done;

	double t_copy = rnd_now_ms();
	if ((r = rnd_readback_image(rq.s, rq.sc, &plan->sheet, out, err)) != RND_OK) goto done;
	rq.tm.readback_ms += rnd_now_ms() - t_copy;

done:
	finish(&rq, r, err);
	rq.tm.submits = rq.pacer.submits;
	rq.tm.shadow_parts = rq.pacer.shadow_parts;
	rq.tm.shadow_submits = rq.pacer.shadow_submits;
	rq.tm.compile_ms = rnd_compile_ms_tls - compiled;
	plan->actual.tm = rq.tm;
	plan->actual.done = r == RND_OK;
	if (timings) *timings = rq.tm;
	return r;
}

enum rnd_result rnd_render(struct rnd_context *ctx, const struct rnd_scene *sc, struct rnd_image *out,
                           struct rnd_timings *timings, struct rnd_error *err)
{
	struct rnd_plan *plan;
	struct rnd_error scratch_err;
	if (!err) err = &scratch_err;
	memset(out, 0, sizeof *out);
	enum rnd_result r = rnd_plan_create(ctx, sc, &plan, err);
	if (r == RND_OK) r = rnd_render_plan(ctx, plan, out, timings, err);
	rnd_plan_destroy(plan);
	return r;
}
