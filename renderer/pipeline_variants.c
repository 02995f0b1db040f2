/*
 * renderer/pipeline_variants.c — the context's table of main-pass pipeline variants: looked
 * up by key, compiled on first use (pipelines.c) outside the lock, kept (at most
 * RND_MAX_VARIANTS), trimmed least-recently-used first and destroyed once no render may still
 * use them.
 *
 * A variant is compiled once: a render that needs a key another render is compiling waits for
 * that compile instead of starting its own. (Sixteen workers' first requests on a GPU all need
 * the same few variants at once; compiling each sixteen times kept every first request waiting
 * on the driver's compiler, 0.5-0.8 s.) The time a thread spends compiling or waiting for a
 * compile is added to rnd_compile_ms_tls: the render's `compile` stage.
 */
#include <stdio.h>
#include <string.h>
#include "internal.h"

_Thread_local double rnd_compile_ms_tls;

/* The variant of key in the table (under mu), marked used; NULL if none. */
static VkPipeline find_locked(struct rnd_pipelines *p, const struct rnd_main_key *key)
{
	for (uint32_t i = 0; i < p->variant_count; i++)
		if (!memcmp(&p->variants[i].key, key, sizeof *key)) {
			p->variants[i].used = ++p->tick;
			return p->variants[i].pipeline;
		}
	return VK_NULL_HANDLE;
}

static bool compiling_locked(const struct rnd_pipelines *p, const struct rnd_main_key *key)
{
	for (uint32_t i = 0; i < p->compiling_count; i++)
		if (!memcmp(p->compiling[i], key, sizeof *key)) return true;
	return false;
}

static void compiling_remove_locked(struct rnd_pipelines *p, const struct rnd_main_key *key)
{
	for (uint32_t i = 0; i < p->compiling_count; i++)
		if (p->compiling[i] == key) {
			p->compiling[i] = p->compiling[--p->compiling_count];
			break;
		}
	pthread_cond_broadcast(&p->compiled);
}

/* The debug name of key's pipeline (and the log's). */
static void variant_name(const struct rnd_main_key *key, char *name, size_t size)
{
	snprintf(name, size, "%s fmt%u msaa%u%s%s sc %u/%u/%u/%u/%u/%u/%u/%u/%u/%u/%u/%u/%u",
	         key->aov ? "aov" : key->resolve ? "resolve" : key->vis_shade ? "pixel shading"
	         : key->vis_pass ? "visibility" : key->vis_read ? "main (visibility)"
	         : key->background ? "background" : key->env_pass ? "environment" : "main",
	         key->format, key->samples, key->cull_back ? " cull" : "", key->prepass ? " eq" : "", key->sc[0], key->sc[1],
	         key->sc[2], key->sc[3], key->sc[4], key->sc[5], key->sc[6], key->sc[7], key->sc[8], key->sc[9], key->sc[10],
	         key->sc[11], key->sc[12]);
}

enum rnd_result rnd_pipelines_main(struct rnd_context *ctx, const struct rnd_main_key *key, VkPipeline *out,
                                   struct rnd_error *err)
{
	struct rnd_pipelines *p = &ctx->pipes;
	double t0 = rnd_now_ms();
	bool waited = false;
	pthread_mutex_lock(&p->mu);
	/* Another render compiling this key (or too many compiles at once): wait for it. */
	while (!(*out = find_locked(p, key)) && (compiling_locked(p, key) || p->compiling_count == RND_COMPILING_MAX)) {
		pthread_cond_wait(&p->compiled, &p->mu);
		waited = true;
	}
	if (*out) {
		pthread_mutex_unlock(&p->mu);
		if (waited) rnd_compile_ms_tls += rnd_now_ms() - t0;
		return RND_OK;
	}
	if (p->variant_count == RND_MAX_VARIANTS) {
		pthread_mutex_unlock(&p->mu);
		return rnd_fail(err, RND_ERR_LIMIT, "more than %d pipeline variants", RND_MAX_VARIANTS);
	}
	struct rnd_main_key mine = *key;
	p->compiling[p->compiling_count++] = &mine;
	pthread_mutex_unlock(&p->mu);

	char name[128];
	variant_name(key, name, sizeof name);
	VkPipeline pipe = VK_NULL_HANDLE;
	double t1 = rnd_now_ms();
	enum rnd_result r = rnd_pipeline_variant_compile(ctx, key, name, &pipe, err);
	if (r == RND_OK) rnd_log(ctx, 2, "pipeline '%s' compiled in %.1f ms", name, rnd_now_ms() - t1);

	pthread_mutex_lock(&p->mu);
	compiling_remove_locked(p, &mine);
	if (r == RND_OK && p->variant_count == RND_MAX_VARIANTS) {   /* filled while this compiled */
		vkDestroyPipeline(ctx->device, pipe, NULL);
		r = rnd_fail(err, RND_ERR_LIMIT, "more than %d pipeline variants", RND_MAX_VARIANTS);
	} else if (r == RND_OK) {
		p->variants[p->variant_count].key = *key;
		p->variants[p->variant_count].pipeline = pipe;
		p->variants[p->variant_count].used = ++p->tick;
		p->variant_count++;
		*out = pipe;
	}
	pthread_mutex_unlock(&p->mu);
	rnd_compile_ms_tls += rnd_now_ms() - t0;
	return r;
}

uint32_t rnd_context_trim_pipelines(struct rnd_context *ctx, uint32_t keep)
{
	struct rnd_pipelines *p = &ctx->pipes;
	uint32_t n = 0;
	pthread_mutex_lock(&p->mu);
	while (p->variant_count > keep && p->retired_count < RND_MAX_VARIANTS) {
		uint32_t lru = 0;
		for (uint32_t i = 1; i < p->variant_count; i++)
			if (p->variants[i].used < p->variants[lru].used) lru = i;
		/* out of the table first: a render that takes a slot from the epoch on cannot find it */
		VkPipeline pipe = p->variants[lru].pipeline;
		p->variants[lru] = p->variants[--p->variant_count];
		p->retired[p->retired_count++] = (struct rnd_retired){pipe, rnd_slot_epoch_advance(ctx)};
		n++;
	}
	pthread_mutex_unlock(&p->mu);
	rnd_pipelines_reap(ctx);
	return n;
}

void rnd_pipelines_reap(struct rnd_context *ctx)
{
	struct rnd_pipelines *p = &ctx->pipes;
	if (!__atomic_load_n(&p->retired_count, __ATOMIC_RELAXED)) return;
	uint64_t oldest = rnd_slot_oldest_busy_epoch(ctx);
	pthread_mutex_lock(&p->mu);
	for (uint32_t i = 0; i < p->retired_count;) {
		if (p->retired[i].epoch > oldest) { i++; continue; }
		vkDestroyPipeline(ctx->device, p->retired[i].pipeline, NULL);
		p->retired[i] = p->retired[--p->retired_count];
	}
	pthread_mutex_unlock(&p->mu);
}

uint32_t rnd_pipelines_count(struct rnd_context *ctx)
{
	pthread_mutex_lock(&ctx->pipes.mu);
	uint32_t n = ctx->pipes.variant_count;
	pthread_mutex_unlock(&ctx->pipes.mu);
	return n;
}
