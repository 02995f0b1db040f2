/*
 * renderer/shadow_cache.c — persistent shadow atlases and the shadow-map cache (see
 * shadow_cache.h).
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <time.h>
#include <string.h>
#include <unistd.h>
#include "moments.h"
#include "shadow_cache.h"
#include "env.h"
#include "slot.h"

#define MAX_ENTRIES 1024
#define MIN_TILE RND_MIN_SHADOW_RESOLUTION   /* the smallest map is the smallest tile */
/* Depth bounds blocks never straddle two tiles (tiles are aligned to their size). */
_Static_assert(MIN_TILE % UMBRA_BOUNDS_BLOCK == 0, "depth bounds blocks must divide the smallest tile");

struct rnd_cache_entry {
	uint64_t key;
	struct rnd_tile tile[8];
	uint32_t ntiles, res;
	uint32_t refs;
	uint64_t last_use;
	double used_at;           /* CLOCK_MONOTONIC seconds of the last grant (idle eviction) */
	bool live, valid;
};

struct rnd_shadow_cache {
	pthread_mutex_t mu;
	pthread_cond_t released;  /* broadcast whenever a render gives tiles back */
	struct rnd_atlas atlas;
	struct rnd_cache_entry entries[MAX_ENTRIES];
	uint64_t clock;
	bool touched;             /* a tile was drawn since the atlases' pages were last released */
};

/* One-time set-up of both atlases on slot 0's command buffer: both in GENERAL layout for good.
 * Not cleared: every map is copied whole into its tile before anything samples it, and the
 * filters never read outside a tile. Where device memory is host memory (lavapipe), pages
 * no tile ever used are never touched, so the atlases take resident memory only as tiles use
 * it (an 8192² depth atlas cleared at start-up was 256 MB of the daemon's warm RSS). */
static enum rnd_result init_layouts(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_slot *s = ctx->slots[0];
	VkResult vr;
	VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
	if ((vr = vkBeginCommandBuffer(s->cmd, &bi)) != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkBeginCommandBuffer (atlas init)");
	VkImageMemoryBarrier2 g[3];
	uint32_t n = 0;
	const struct rnd_image_res *im[3] = {&ctx->atlas_depth, &ctx->atlas_moments, &ctx->atlas_bounds};
	for (int i = 0; i < 3; i++) {
		if (!im[i]->img) continue;
		g[n++] = (VkImageMemoryBarrier2){
			.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_NONE,
			.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
			.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
			.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, .newLayout = VK_IMAGE_LAYOUT_GENERAL,
			.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
			.image = im[i]->img,
			.subresourceRange = {i == 0 ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1},
		};
	}
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = n, .pImageMemoryBarriers = g};
	vkCmdPipelineBarrier2(s->cmd, &di);
	if ((vr = vkEndCommandBuffer(s->cmd)) != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkEndCommandBuffer (atlas init)");
	VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &s->cmd};
	if ((vr = vkQueueSubmit(ctx->queue, 1, &si, s->fence)) != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkQueueSubmit (atlas init)");
	if ((vr = vkWaitForFences(ctx->device, 1, &s->fence, VK_TRUE, UINT64_MAX)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkWaitForFences (atlas init)");
	vkResetFences(ctx->device, 1, &s->fence);
	return RND_OK;
}

enum rnd_result rnd_cache_init(struct rnd_context *ctx, struct rnd_error *err)
{
	enum rnd_result r;
	uint32_t size = ctx->desc.atlas_size;
	struct rnd_shadow_cache *c = calloc(1, sizeof *c);
	if (!c) return rnd_fail(err, RND_ERR_OOM, "out of memory for the shadow cache");
	if (!rnd_atlas_init(&c->atlas, size, MIN_TILE)) {
		free(c);
		return rnd_fail(err, RND_ERR_INVALID, "atlas size %u: must be a power of two between 64 and 16384", size);
	}
	pthread_mutex_init(&c->mu, NULL);
	pthread_condattr_t ca;
	pthread_condattr_init(&ca);
	pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
	pthread_cond_init(&c->released, &ca);
	pthread_condattr_destroy(&ca);
	ctx->cache = c;
	/* Maps are drawn at the origin of a slot's scratch depth image and copied into their tile;
	 * the atlas itself is never a render target. */
	if ((r = rnd_image_create(ctx, RND_SHADOW_FORMAT, size, size, 1, 1,
	                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
	                          VK_IMAGE_ASPECT_DEPTH_BIT, "shadow depth atlas", &ctx->atlas_depth, err)) != RND_OK)
		goto fail;
	if (ctx->moments.available &&
	    (r = rnd_image_create(ctx, rnd_moments_format(ctx, false), size, size, 1, 1,
	                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
	                          "shadow moment atlas", &ctx->atlas_moments, err)) != RND_OK)
		goto fail;
	/* PCSS depth bounds (RGBA32F: a storage format every device has), not cleared either: a
	 * tile's blocks are written with its map (record.c). */
	if ((r = rnd_image_create(ctx, VK_FORMAT_R32G32B32A32_SFLOAT, size / UMBRA_BOUNDS_BLOCK * UMBRA_BOUNDS_TEXELS,
	                          size / UMBRA_BOUNDS_BLOCK,
	                          1, 1, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
	                          "shadow depth bounds", &ctx->atlas_bounds, err)) != RND_OK)
		goto fail;
	if ((r = init_layouts(ctx, err)) != RND_OK) goto fail;
	return RND_OK;
fail:
	rnd_cache_release_all(ctx);
	return r;
}

void rnd_cache_release_all(struct rnd_context *ctx)
{
	struct rnd_shadow_cache *c = ctx->cache;
	rnd_image_destroy(ctx, &ctx->atlas_bounds);
	rnd_image_destroy(ctx, &ctx->atlas_moments);
	rnd_image_destroy(ctx, &ctx->atlas_depth);
	if (!c) return;
	rnd_atlas_release(&c->atlas);
	pthread_cond_destroy(&c->released);
	pthread_mutex_destroy(&c->mu);
	free(c);
	ctx->cache = NULL;
}

static void entry_free(struct rnd_shadow_cache *c, struct rnd_cache_entry *e)
{
	for (uint32_t i = 0; i < e->ntiles; i++) rnd_atlas_free(&c->atlas, &e->tile[i]);
	memset(e, 0, sizeof *e);
}

/* Evicts the least recently used entry nobody is using. False when there is none. */
static bool evict_one_counted(struct rnd_shadow_cache *c, uint64_t *texels);

static bool evict_one(struct rnd_shadow_cache *c)
{
	uint64_t texels;
	return evict_one_counted(c, &texels);
}

/* The least recently used unreferenced map freed; *texels: what it held. */
static bool evict_one_counted(struct rnd_shadow_cache *c, uint64_t *texels)
{
	struct rnd_cache_entry *lru = NULL;
	for (uint32_t i = 0; i < MAX_ENTRIES; i++) {
		struct rnd_cache_entry *e = &c->entries[i];
		if (e->live && e->valid && !e->refs && (!lru || e->last_use < lru->last_use)) lru = e;
	}
	if (!lru) return false;
	*texels = (uint64_t)lru->ntiles * lru->res * lru->res;
	entry_free(c, lru);
	return true;
}

/* Allocates `tiles` tiles of res into e (all or none). */
static bool alloc_tiles(struct rnd_shadow_cache *c, struct rnd_cache_entry *e, uint32_t tiles, uint32_t res)
{
	for (uint32_t i = 0; i < tiles; i++) {
		if (!rnd_atlas_alloc(&c->atlas, res, &e->tile[i])) {
			for (uint32_t k = 0; k < i; k++) rnd_atlas_free(&c->atlas, &e->tile[k]);
			return false;
		}
	}
	e->ntiles = tiles;
	e->res = res;
	return true;
}

static uint32_t free_slot(struct rnd_shadow_cache *c)
{
	for (uint32_t i = 0; i < MAX_ENTRIES; i++)
		if (!c->entries[i].live) return i;
	if (evict_one(c))
		for (uint32_t i = 0; i < MAX_ENTRIES; i++)
			if (!c->entries[i].live) return i;
	return MAX_ENTRIES;
}

/* Gives back what one attempt took (hits referenced, new entries allocated). */
static void undo_attempt(struct rnd_shadow_cache *c, struct rnd_cache_grant *out, const bool *granted, uint32_t n)
{
	for (uint32_t k = 0; k < n; k++) {
		if (!granted[k]) continue;
		struct rnd_cache_entry *e = &c->entries[out[k].entry];
		if (out[k].hit) e->refs--;
		else entry_free(c, e);
	}
}

/* One try at granting every request at its planned resolution: completed maps with the same
 * key and resolution are reused when use_hits, the rest allocated largest first, evicting
 * maps nobody uses. All or nothing: false (with nothing held) when the atlas has no room now. */
static bool attempt(struct rnd_shadow_cache *c, const struct rnd_cache_request *req, uint32_t n, const uint32_t *res,
                    bool use_hits, struct rnd_cache_grant *out)
{
	bool granted[UMBRA_MAX_LIGHTS] = {false};
	uint32_t order[UMBRA_MAX_LIGHTS], nmiss = 0;
	for (uint32_t k = 0; k < n; k++) {
		struct rnd_cache_grant *g = &out[k];
		memset(g, 0, sizeof *g);
		for (uint32_t i = 0; use_hits && req[k].key && i < MAX_ENTRIES; i++) {
			struct rnd_cache_entry *e = &c->entries[i];
			if (e->live && e->valid && e->key == req[k].key && e->ntiles == req[k].tiles && e->res == res[k]) {
				e->refs++;
				e->last_use = c->clock;
				e->used_at = (rnd_now_ms() * 1e-3);
				g->entry = i; g->res = e->res; g->hit = true;
				memcpy(g->tile, e->tile, sizeof e->tile);
				granted[k] = true;
				break;
			}
		}
		if (!granted[k]) order[nmiss++] = k;
	}
	/* Largest first: in a buddy quadtree, power-of-two squares placed in decreasing size
	 * always fit when their area does. */
	for (uint32_t a = 0; a < nmiss; a++)
		for (uint32_t b = a + 1; b < nmiss; b++)
			if (res[order[b]] > res[order[a]]) { uint32_t t = order[a]; order[a] = order[b]; order[b] = t; }
	for (uint32_t m = 0; m < nmiss; m++) {
		uint32_t k = order[m];
		uint32_t slot = free_slot(c);
		struct rnd_cache_entry *e = slot < MAX_ENTRIES ? &c->entries[slot] : NULL;
		bool ok = false;
		while (e && !(ok = alloc_tiles(c, e, req[k].tiles, res[k])) && evict_one(c)) {}
		if (!ok) {
			undo_attempt(c, out, granted, n);
			return false;
		}
		e->live = true; e->valid = false; e->key = req[k].key; e->refs = 1; e->last_use = c->clock;
		e->used_at = (rnd_now_ms() * 1e-3);
		c->touched = true;
		out[k].entry = slot; out[k].res = e->res; out[k].hit = false;
		memcpy(out[k].tile, e->tile, sizeof e->tile);
		granted[k] = true;
	}
	return true;
}

static bool others_hold_tiles(const struct rnd_shadow_cache *c)
{
	for (uint32_t i = 0; i < MAX_ENTRIES; i++)
		if (c->entries[i].live && c->entries[i].refs) return true;
	return false;
}

enum rnd_result rnd_cache_acquire(struct rnd_context *ctx, const struct rnd_cache_request *req, uint32_t n,
                                  double deadline, struct rnd_cache_grant *out, struct rnd_error *err)
{
	struct rnd_shadow_cache *c = ctx->cache;
	uint32_t res[UMBRA_MAX_LIGHTS];
	if (n > UMBRA_MAX_LIGHTS)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_LIGHTS, 0, "%u shadowed lights: at most %d", n, UMBRA_MAX_LIGHTS);
	uint64_t need = 0;
	for (uint32_t k = 0; k < n; k++) {
		if (req[k].tiles == 0 || req[k].tiles > 8)
			return rnd_fail(err, RND_ERR_INVALID, "%u shadow tiles for one light", req[k].tiles);
		res[k] = req[k].res;
		if (res[k] < MIN_TILE || res[k] > c->atlas.size || (res[k] & (res[k] - 1)))
			return rnd_fail(err, RND_ERR_INVALID, "a shadow tile of %u texels in a %u atlas", res[k], c->atlas.size);
		need += (uint64_t)req[k].tiles * res[k] * res[k];
	}
	/* The plan sized the maps to fit (rnd_atlas_fit): this holds unless it was made for another atlas. */
	if (need > (uint64_t)c->atlas.size * c->atlas.size)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_LIGHTS, 0, "the shadow maps need %llu texels, more than the %ux%u atlas",
		                   (unsigned long long)need, c->atlas.size, c->atlas.size);
	pthread_mutex_lock(&c->mu);
	c->clock++;
	enum rnd_result r = RND_OK;
	/* Reusing completed maps first; when they leave no room, drawing everything again (the
	 * request's own maps are then evictable). When other renders hold the room, wait for them:
	 * each render holds its tiles only while it runs, and a waiting render holds none, so the
	 * wait ends. */
	while (!attempt(c, req, n, res, true, out) && !attempt(c, req, n, res, false, out)) {
		/* A lost device never gives its tiles back (the GPU may still use them): waiting for
		 * them would last until the context is recreated, which waits for this render. */
		if (__atomic_load_n(&ctx->failed, __ATOMIC_RELAXED)) {
			r = rnd_fail(err, RND_ERR_DEVICE_LOST, "the device was lost while waiting for room in the shadow atlas");
			break;
		}
		if (!others_hold_tiles(c)) {
			r = rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_LIGHTS, 0, "the shadow maps do not fit in the %ux%u atlas",
			                c->atlas.size, c->atlas.size);
			break;
		}
		if (deadline > 0) {
			struct timespec ts;
			double whole;
			double frac = modf(deadline, &whole);
			ts.tv_sec = (time_t)whole;
			ts.tv_nsec = (long)(frac * 1e9);
			if (pthread_cond_timedwait(&c->released, &c->mu, &ts) == ETIMEDOUT) {
				r = rnd_fail(err, RND_ERR_TIMEOUT, "the render passed its deadline waiting for room in the shadow atlas");
				break;
			}
		} else {
			pthread_cond_wait(&c->released, &c->mu);
		}
	}
	if (r == RND_OK)
		for (uint32_t k = 0; k < n; k++) {
			if (!req[k].key) continue;
			if (out[k].hit) __atomic_add_fetch(&ctx->stats_hits, 1, __ATOMIC_RELAXED);
			else __atomic_add_fetch(&ctx->stats_misses, 1, __ATOMIC_RELAXED);
		}
	pthread_mutex_unlock(&c->mu);
	return r;
}

bool rnd_cache_probe(struct rnd_context *ctx, uint64_t key, uint32_t tiles, uint32_t res)
{
	struct rnd_shadow_cache *c = ctx->cache;
	bool hit = false;
	if (!c || !key) return false;
	pthread_mutex_lock(&c->mu);
	for (uint32_t i = 0; i < MAX_ENTRIES && !hit; i++) {
		const struct rnd_cache_entry *e = &c->entries[i];
		hit = e->live && e->valid && e->key == key && e->ntiles == tiles && e->res == res;
	}
	pthread_mutex_unlock(&c->mu);
	return hit;
}

/* Texels of the completed maps the cache keeps. */
static uint64_t kept_texels(const struct rnd_shadow_cache *c)
{
	uint64_t t = 0;
	for (uint32_t i = 0; i < MAX_ENTRIES; i++)
		if (c->entries[i].live && c->entries[i].valid) t += (uint64_t)c->entries[i].ntiles * c->entries[i].res * c->entries[i].res;
	return t;
}

void rnd_cache_release(struct rnd_context *ctx, const struct rnd_cache_grant *g, uint32_t n, bool ok)
{
	struct rnd_shadow_cache *c = ctx->cache;
	pthread_mutex_lock(&c->mu);
	for (uint32_t i = 0; i < n; i++) {
		struct rnd_cache_entry *e = &c->entries[g[i].entry];
		if (!e->live) continue;
		if (e->refs) e->refs--;
		if (g[i].hit) continue;
		/* Transient maps, and maps of a failed render, go back to the atlas now. A second
		 * render that made the same map meanwhile keeps only one of them. */
		bool dup = false;
		for (uint32_t k = 0; k < MAX_ENTRIES && e->key && !dup; k++)
			dup = &c->entries[k] != e && c->entries[k].live && c->entries[k].valid && c->entries[k].key == e->key;
		if (!e->key || !ok || dup) { if (!e->refs) entry_free(c, e); }
		else e->valid = true;
	}
	uint64_t cap = ctx->desc.shadow_cache_texels ? ctx->desc.shadow_cache_texels : RND_DEFAULT_SHADOW_CACHE_TEXELS;
	/* one scan for the total, then each eviction subtracts what it freed */
	uint64_t kept = kept_texels(c), freed;
	while (kept > cap && evict_one_counted(c, &freed)) kept -= freed;
	pthread_cond_broadcast(&c->released);
	pthread_mutex_unlock(&c->mu);
}

void rnd_context_stats(struct rnd_context *ctx, struct rnd_stats *st)
{
	memset(st, 0, sizeof *st);
	struct rnd_shadow_cache *c = ctx->cache;
	pthread_mutex_lock(&c->mu);
	st->atlas_size = c->atlas.size;
	st->atlas_occupancy = rnd_atlas_occupancy(&c->atlas);
	st->atlas_tiles = c->atlas.used_tiles;
	for (uint32_t i = 0; i < MAX_ENTRIES; i++) st->cached_maps += c->entries[i].live && c->entries[i].valid;
	pthread_mutex_unlock(&c->mu);
	st->shadow_cache_hits = __atomic_load_n(&ctx->stats_hits, __ATOMIC_RELAXED);
	st->shadow_cache_misses = __atomic_load_n(&ctx->stats_misses, __ATOMIC_RELAXED);
	st->pipeline_variants = rnd_pipelines_count(ctx);
	rnd_env_stats(ctx, &st->env_maps, &st->env_builds);
}

void rnd_cache_wake(struct rnd_context *ctx)
{
	struct rnd_shadow_cache *c = ctx->cache;
	if (!c) return;
	pthread_mutex_lock(&c->mu);
	pthread_cond_broadcast(&c->released);
	pthread_mutex_unlock(&c->mu);
}

/* Gives the pages of one atlas image back to the system (madvise MADV_DONTNEED over the
 * whole pages inside its memory; they read as zero when next touched). Only where every
 * memory type the image may use is host-visible: there device memory is host memory (a CPU
 * device such as lavapipe) and holds resident pages; elsewhere it is not this process's RSS. */
static uint64_t release_pages(struct rnd_context *ctx, const struct rnd_image_res *im)
{
	if (!im->img || ctx->props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) return 0;
	VkMemoryRequirements req;
	vkGetImageMemoryRequirements(ctx->device, im->img, &req);
	for (uint32_t i = 0; i < ctx->mem_props.memoryTypeCount; i++)
		if ((req.memoryTypeBits & (1u << i)) &&
		    !(ctx->mem_props.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT))
			return 0;
	void *map = NULL;
	if (vkMapMemory(ctx->device, im->mem, 0, VK_WHOLE_SIZE, 0, &map) != VK_SUCCESS || !map) return 0;
	uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE);
	uintptr_t lo = ((uintptr_t)map + page - 1) & ~(page - 1), hi = ((uintptr_t)map + req.size) & ~(page - 1);
	uint64_t released = 0;
	if (hi > lo && madvise((void *)lo, hi - lo, MADV_DONTNEED) == 0) released = hi - lo;
	vkUnmapMemory(ctx->device, im->mem);
	return released;
}

uint64_t rnd_context_trim(struct rnd_context *ctx, double idle_s)
{
	struct rnd_shadow_cache *c = ctx->cache;
	if (!c || __atomic_load_n(&ctx->failed, __ATOMIC_RELAXED)) return 0;
	uint64_t released = 0;
	pthread_mutex_lock(&c->mu);
	/* A render that holds tiles may be drawing into the atlas: then nothing is released. One
	 * that holds none never reads a texel (maps are sampled only inside granted tiles). */
	if (!others_hold_tiles(c)) {
		double now = (rnd_now_ms() * 1e-3);
		for (uint32_t i = 0; i < MAX_ENTRIES; i++) {
			struct rnd_cache_entry *e = &c->entries[i];
			if (e->live && now - e->used_at >= idle_s) entry_free(c, e);
		}
		bool empty = true;
		for (uint32_t i = 0; i < MAX_ENTRIES && empty; i++) empty = !c->entries[i].live;
		/* All or nothing, like the grants: with every map gone the whole atlas is free, so its
		 * pages go back without knowing how the driver lays texels out in memory. */
		if (empty && c->touched) {
			released = release_pages(ctx, &ctx->atlas_depth) + release_pages(ctx, &ctx->atlas_moments) +
			           release_pages(ctx, &ctx->atlas_bounds);
			c->touched = false;
		}
	}
	pthread_mutex_unlock(&c->mu);
	return released + rnd_env_trim(ctx, idle_s);
}
