/*
 * renderer/env.c — the cache of prefiltered environment maps and what a render takes from it
 * (see env.h): acquire (found, waited for, or claimed and staged), the shadow directions of a
 * request, the umbra_env block and the images a view binds, and the render's end.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "env.h"
#include "slot.h"

/* The built-in studio's key (its pixels never change within a build). */
#define STUDIO_KEY 0x5354554449304f31ull

enum { ENTRY_FREE, ENTRY_BUILDING, ENTRY_READY };
enum { BRDF_NONE, BRDF_BUILDING, BRDF_READY };

struct rnd_env_entry {
	uint64_t key;
	int state;
	uint32_t refs;
	double used;                 /* CLOCK_MONOTONIC seconds of its last use */
	struct rnd_env_maps maps;
	float sh[9][3];              /* rnd_env_sh of the map (intensity 1) */
	struct rnd_env_bins bins;    /* for each request's shadow directions */
};

struct rnd_env_cache {
	pthread_mutex_t mu;
	pthread_cond_t cv;
	struct rnd_env_gpu gpu;
	int brdf;
	uint64_t builds;             /* completed */
	struct rnd_env_entry entries[RND_ENV_ENTRIES];
};

enum rnd_result rnd_env_init(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_env_cache *c = calloc(1, sizeof *c);
	if (!c) return rnd_fail(err, RND_ERR_OOM, "out of memory for the environment cache");
	pthread_mutex_init(&c->mu, NULL);
	pthread_condattr_t ca;
	pthread_condattr_init(&ca);
	pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
	pthread_cond_init(&c->cv, &ca);
	pthread_condattr_destroy(&ca);
	ctx->env = c;
	return RND_OK;
}

void rnd_env_release_all(struct rnd_context *ctx)
{
	struct rnd_env_cache *c = ctx->env;
	if (!c) return;
	for (uint32_t i = 0; i < RND_ENV_ENTRIES; i++) rnd_env_maps_destroy(ctx, &c->entries[i].maps);
	rnd_env_gpu_release(ctx, &c->gpu);
	pthread_cond_destroy(&c->cv);
	pthread_mutex_destroy(&c->mu);
	free(c);
	ctx->env = NULL;
}

/* Waits on the cache's condition until deadline (0 = none); RND_ERR_TIMEOUT past it. */
static enum rnd_result wait_cache(struct rnd_env_cache *c, double deadline, struct rnd_error *err)
{
	if (!deadline) {
		pthread_cond_wait(&c->cv, &c->mu);
		return RND_OK;
	}
	struct timespec ts = {(time_t)deadline, (long)((deadline - floor(deadline)) * 1e9)};
	if (pthread_cond_timedwait(&c->cv, &c->mu, &ts) == ETIMEDOUT)
		return rnd_fail(err, RND_ERR_TIMEOUT, "passed its deadline waiting for the environment map");
	return RND_OK;
}

/* A map wider than RND_ENV_MAX_MAP_WIDTH halved (2 x 2 boxes) until it fits: *out malloc'd, or
 * NULL when it fits as it is. false: out of memory. */
static bool fit_width(const float *rgb, uint32_t *w, uint32_t *h, float **out)
{
	*out = NULL;
	const float *src = rgb;
	while (*w > RND_ENV_MAX_MAP_WIDTH && *h > 1) {
		uint32_t nw = *w / 2, nh = *h / 2;
		float *d = malloc((size_t)nw * nh * 3 * sizeof(float));
		if (!d) {
			free(*out);
			*out = NULL;
			return false;
		}
		for (uint32_t y = 0; y < nh; y++)
			for (uint32_t x = 0; x < nw; x++)
				for (int k = 0; k < 3; k++) {
					const float *r0 = src + ((size_t)(2 * y) * *w + 2 * x) * 3 + k, *r1 = r0 + (size_t)*w * 3;
					d[((size_t)y * nw + x) * 3 + k] = 0.25f * (r0[0] + r0[3] + r1[0] + r1[3]);
				}
		free(*out);
		*out = d;
		src = d;
		*w = nw;
		*h = nh;
	}
	return true;
}

/* The CPU's part of a build, without the lock: the pixels (the studio generated), their bins
 * (the plan's when it made them: a map is read for its bins once) and harmonics, the device
 * objects with the staged chain. */
static enum rnd_result stage_entry(struct rnd_context *ctx, struct rnd_env_entry *e, const struct rnd_environment *env,
                                   const struct rnd_env_bins *bins, struct rnd_error *err)
{
	bool studio = env->source == RND_ENV_STUDIO;
	uint32_t w = studio ? RND_ENV_STUDIO_W : env->map.width, h = studio ? RND_ENV_STUDIO_H : env->map.height;
	float *own = NULL, *fitted = NULL;
	const float *rgb = env->map.rgb;
	if (studio) {
		if (!(own = malloc((size_t)w * h * 3 * sizeof(float))))
			return rnd_fail(err, RND_ERR_OOM, "out of memory for the studio environment");
		rnd_env_studio(own, w, h);
		rgb = own;
	}
	if (bins) memcpy(&e->bins, bins, sizeof e->bins);
	else rnd_env_bin(rgb, w, h, &e->bins);
	rnd_env_sh(&e->bins, e->sh);
	enum rnd_result r;
	if (!fit_width(rgb, &w, &h, &fitted)) r = rnd_fail(err, RND_ERR_OOM, "out of memory reducing the environment map");
	else r = rnd_env_maps_create(ctx, &ctx->env->gpu, fitted ? fitted : rgb, w, h, studio ? "studio" : "environment",
	                             &e->maps, err);
	free(fitted);
	free(own);
	return r;
}

/* The entry to build key into: a free one, else the least recently used one nobody holds
 * (its maps destroyed). NULL: every entry is in use. */
static struct rnd_env_entry *claim(struct rnd_context *ctx, struct rnd_env_cache *c)
{
	struct rnd_env_entry *best = NULL;
	for (uint32_t i = 0; i < RND_ENV_ENTRIES; i++) {
		struct rnd_env_entry *e = &c->entries[i];
		if (e->state == ENTRY_FREE) return e;
		if (e->state == ENTRY_READY && !e->refs && (!best || e->used < best->used)) best = e;
	}
	if (best) {
		rnd_env_maps_destroy(ctx, &best->maps);
		best->state = ENTRY_FREE;
	}
	return best;
}

/* The entry of key, ready (a reference taken), or claimed for this render to build. */
static enum rnd_result find_entry(struct rnd_context *ctx, struct rnd_env_cache *c, uint64_t key, double deadline,
                                  struct rnd_env_use *use, struct rnd_error *err)
{
	for (;;) {
		struct rnd_env_entry *found = NULL;
		for (uint32_t i = 0; i < RND_ENV_ENTRIES && !found; i++)
			if (c->entries[i].state != ENTRY_FREE && c->entries[i].key == key) found = &c->entries[i];
		if (found && found->state == ENTRY_READY) {
			found->refs++;
			found->used = (rnd_now_ms() * 1e-3);
			use->entry = found;
			return RND_OK;
		}
		if (!found && (found = claim(ctx, c))) {
			found->key = key;
			found->state = ENTRY_BUILDING;
			found->refs = 1;
			use->entry = found;
			use->build = true;
			return RND_OK;
		}
		enum rnd_result r = wait_cache(c, deadline, err);   /* being built, or every entry in use */
		if (r != RND_OK) return r;
	}
}

/* The split-sum table: ready, or this render makes it (another render making it is waited for). */
static enum rnd_result claim_brdf(struct rnd_env_cache *c, double deadline, struct rnd_env_use *use, struct rnd_error *err)
{
	while (c->brdf == BRDF_BUILDING) {
		enum rnd_result r = wait_cache(c, deadline, err);
		if (r != RND_OK) return r;
	}
	if (c->brdf == BRDF_NONE) {
		c->brdf = BRDF_BUILDING;
		use->build_brdf = true;
	}
	return RND_OK;
}

/* The cache's key of env's map: its own key or its pixels, and its size. */
static uint64_t env_key(const struct rnd_environment *env)
{
	if (env->source != RND_ENV_MAP) return STUDIO_KEY;
	uint32_t dims[2] = {env->map.width, env->map.height};
	uint64_t key = env->map.key ? env->map.key
	                            : rnd_hash(0x656e76ull, env->map.rgb, (size_t)env->map.width * env->map.height * 3 * sizeof(float));
	key = rnd_hash(key, dims, sizeof dims);
	return key == STUDIO_KEY ? key + 1 : key;
}

enum rnd_result rnd_env_acquire(struct rnd_context *ctx, const struct rnd_environment *env,
                                const struct rnd_env_bins *bins, double deadline, struct rnd_env_use *use,
                                struct rnd_error *err)
{
	memset(use, 0, sizeof *use);
	if (env->source == RND_ENV_AMBIENT) return RND_OK;
	if (env->source == RND_ENV_MAP && (!env->map.rgb || env->map.width < 2 || env->map.height < 2))
		return rnd_fail(err, RND_ERR_INVALID, "the environment map has no pixels (%ux%u)", env->map.width, env->map.height);
	double t0 = (rnd_now_ms() * 1e-3);
	struct rnd_env_cache *c = ctx->env;
	uint64_t key = env_key(env);
	pthread_mutex_lock(&c->mu);
	enum rnd_result r = rnd_env_gpu_init(ctx, &c->gpu, err);
	if (r == RND_OK) r = find_entry(ctx, c, key, deadline, use, err);
	if (r == RND_OK) r = claim_brdf(c, deadline, use, err);
	pthread_mutex_unlock(&c->mu);
	if (r == RND_OK && use->build) r = stage_entry(ctx, use->entry, env, bins, err);
	if (r != RND_OK && use->entry) rnd_env_done(ctx, use, false, false);
	if (r != RND_OK) memset(use, 0, sizeof *use);
	use->ms = ((rnd_now_ms() * 1e-3) - t0) * 1e3;
	return r;
}

void rnd_env_shadow_dirs(struct rnd_env_use *use, const struct rnd_env_plan *plan)
{
	use->ndirs = use->mapped = 0;
	use->ground = plan->ground;
	memcpy(use->ground_n, plan->ground_n, sizeof use->ground_n);
	if (!use->entry) return;
	use->ndirs = plan->ndirs;
	use->mapped = plan->mapped;
	memcpy(use->dirs, plan->dirs, plan->ndirs * sizeof plan->dirs[0]);
}

/* The built-in studio's bins, made once per process (its pixels never change within a build):
 * a plan made before the studio's entry is ready (the first render, every --explain of a
 * one-shot CLI) would otherwise generate it (~40-90 ms on lavapipe's machine) twice. */
static struct rnd_env_bins studio_bins;
static pthread_once_t studio_once = PTHREAD_ONCE_INIT;
static bool studio_binned;

static void bin_studio(void)
{
	float *rgb = malloc((size_t)RND_ENV_STUDIO_W * RND_ENV_STUDIO_H * 3 * sizeof(float));
	if (!rgb) return;   /* studio_binned stays false: the plan fails out of memory */
	rnd_env_studio(rgb, RND_ENV_STUDIO_W, RND_ENV_STUDIO_H);
	rnd_env_bin(rgb, RND_ENV_STUDIO_W, RND_ENV_STUDIO_H, &studio_bins);
	free(rgb);
	studio_binned = true;
}

/* A map's bins: the entry's when the cache holds it ready, else binned here (the studio's once
 * per process). */
enum rnd_result rnd_env_plan_bins(struct rnd_context *ctx, const struct rnd_environment *env, struct rnd_env_bins **out,
                                  struct rnd_error *err)
{
	*out = NULL;
	if (env->source == RND_ENV_AMBIENT || !env->shadow_directions) return RND_OK;
	if (env->source == RND_ENV_MAP && (!env->map.rgb || env->map.width < 2 || env->map.height < 2))
		return rnd_fail(err, RND_ERR_INVALID, "the environment map has no pixels (%ux%u)", env->map.width, env->map.height);
	struct rnd_env_bins *b = malloc(sizeof *b);
	if (!b) return rnd_fail(err, RND_ERR_OOM, "out of memory for the environment's bins");
	struct rnd_env_cache *c = ctx->env;
	uint64_t key = env_key(env);
	bool found = false;
	pthread_mutex_lock(&c->mu);
	for (uint32_t i = 0; i < RND_ENV_ENTRIES && !found; i++)
		if (c->entries[i].state == ENTRY_READY && c->entries[i].key == key) {
			memcpy(b, &c->entries[i].bins, sizeof *b);
			found = true;
		}
	pthread_mutex_unlock(&c->mu);
	if (!found && env->source == RND_ENV_STUDIO) {
		pthread_once(&studio_once, bin_studio);
		if (!studio_binned) {
			free(b);
			return rnd_fail(err, RND_ERR_OOM, "out of memory for the studio environment");
		}
		memcpy(b, &studio_bins, sizeof *b);
	} else if (!found) {
		rnd_env_bin(env->map.rgb, env->map.width, env->map.height, b);
	}
	*out = b;
	return RND_OK;
}

void rnd_env_record(struct rnd_context *ctx, VkCommandBuffer cmd, const struct rnd_env_use *use)
{
	if (use->build_brdf) rnd_env_record_brdf(cmd, &ctx->env->gpu);
	if (use->build) rnd_env_record_maps(cmd, &ctx->env->gpu, &use->entry->maps);
}

void rnd_env_write(const struct rnd_env_use *use, const struct rnd_environment *env, const float inv_view_proj[16],
                   uint32_t first_light, uint32_t pass_scale, struct umbra_env *out)
{
	memset(out, 0, sizeof *out);
	memcpy(out->inv_view_proj, inv_view_proj, sizeof out->inv_view_proj);
	if (!use->entry) return;
	const struct rnd_env_entry *e = use->entry;
	for (int i = 0; i < 9; i++)
		for (int k = 0; k < 3; k++) out->sh[i][k] = e->sh[i][k] * env->intensity;
	out->rot[0] = cosf(env->rotation);
	out->rot[1] = sinf(env->rotation);
	out->rot[2] = env->intensity;
	out->rot[3] = (float)(e->maps.spec_levels - 1);
	out->params[0] = (float)e->maps.map_w;
	out->params[1] = (float)e->maps.map_h;
	out->params[2] = (float)first_light;
	out->params[3] = (float)use->mapped;
	memcpy(out->ground, use->ground_n, sizeof use->ground_n);
	out->pass[0] = (float)pass_scale;
	out->ground[3] = (float)use->ndirs;
	for (uint32_t i = 0; i < use->ndirs; i++) {
		memcpy(out->dirs[i], use->dirs[i].dir, 3 * sizeof(float));
		out->dirs[i][3] = use->dirs[i].share;
		out->sizes[i / 4][i % 4] = use->dirs[i].sin_radius;
	}
}

void rnd_env_images(const struct rnd_context *ctx, const struct rnd_env_use *use, const struct rnd_slot *s,
                    VkDescriptorImageInfo out[3])
{
	VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
	if (!use || !use->entry) {
		VkSampler white = ctx->pipes.texture_samplers[0];
		out[0] = (VkDescriptorImageInfo){white, s->white_cube.view, ro};
		out[1] = out[2] = (VkDescriptorImageInfo){white, s->white.view, ro};
		return;
	}
	const struct rnd_env_gpu *g = &ctx->env->gpu;
	out[0] = (VkDescriptorImageInfo){g->cube_sampler, use->entry->maps.spec.view, ro};
	out[1] = (VkDescriptorImageInfo){g->map_sampler, use->entry->maps.map.view, ro};
	out[2] = (VkDescriptorImageInfo){g->lut_sampler, g->brdf.view, ro};
}

void rnd_env_done(struct rnd_context *ctx, struct rnd_env_use *use, bool ok, bool gpu_busy)
{
	struct rnd_env_cache *c = ctx->env;
	struct rnd_env_entry *e = use->entry;
	if (!e) return;
	pthread_mutex_lock(&c->mu);
	if (use->build_brdf) c->brdf = ok ? BRDF_READY : BRDF_NONE;
	if (use->build) {
		/* Undone unless it completed; with a submit perhaps still running (a failed context)
		 * its objects are left to it, and the entry is free for a fresh build. */
		if (ok) {
			rnd_env_maps_built(ctx, &e->maps);
			c->builds++;
		}
		else if (!gpu_busy) rnd_env_maps_destroy(ctx, &e->maps);
		else memset(&e->maps, 0, sizeof e->maps);
		e->state = ok ? ENTRY_READY : ENTRY_FREE;
	}
	e->refs--;
	e->used = (rnd_now_ms() * 1e-3);
	pthread_cond_broadcast(&c->cv);
	pthread_mutex_unlock(&c->mu);
	use->entry = NULL;
	use->build = use->build_brdf = false;
}

void rnd_env_stats(struct rnd_context *ctx, uint32_t *maps, uint64_t *builds)
{
	struct rnd_env_cache *c = ctx->env;
	*maps = 0;
	*builds = 0;
	if (!c) return;
	pthread_mutex_lock(&c->mu);
	for (uint32_t i = 0; i < RND_ENV_ENTRIES; i++) *maps += c->entries[i].state == ENTRY_READY;
	*builds = c->builds;
	pthread_mutex_unlock(&c->mu);
}

uint64_t rnd_env_trim(struct rnd_context *ctx, double idle_s)
{
	struct rnd_env_cache *c = ctx->env;
	uint64_t bytes = 0;
	if (!c) return 0;
	pthread_mutex_lock(&c->mu);
	double now = (rnd_now_ms() * 1e-3);
	for (uint32_t i = 0; i < RND_ENV_ENTRIES; i++) {
		struct rnd_env_entry *e = &c->entries[i];
		if (e->state != ENTRY_READY || e->refs || e->key == STUDIO_KEY || now - e->used < idle_s) continue;
		bytes += rnd_env_maps_bytes(&e->maps);
		rnd_env_maps_destroy(ctx, &e->maps);
		e->state = ENTRY_FREE;
	}
	pthread_mutex_unlock(&c->mu);
	return bytes;
}
