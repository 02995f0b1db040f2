/*
 * renderer/shadow_cache.c — persistent shadow atlases and the shadow-map cache (see
 * shadow_cache.h).
 */
#include <stdlib.h>
#include <string.h>
#include "moments.h"
#include "shadow_cache.h"
#include "slot.h"

#define MAX_ENTRIES 1024

struct rnd_cache_entry {
	uint64_t key;
	struct rnd_tile tile[8];
	uint32_t ntiles, res;
	uint32_t refs;
	uint64_t last_use;
	bool live, valid;
};

struct rnd_shadow_cache {
	pthread_mutex_t mu;
	struct rnd_atlas atlas;
	struct rnd_cache_entry entries[MAX_ENTRIES];
	uint64_t clock;
};

uint64_t rnd_hash(uint64_t h, const void *data, size_t len)
{
	const uint8_t *p = data;
	const uint64_t m = 0x9e3779b97f4a7c15ull;
	while (len >= 8) {
		uint64_t w;
		memcpy(&w, p, 8);
		h = (h ^ w) * m;
		h ^= h >> 29;
		p += 8; len -= 8;
	}
	uint64_t w = 0;
	memcpy(&w, p, len);
	h = (h ^ w ^ ((uint64_t)len << 56)) * m;
	h ^= h >> 32;
	return h;
}

/* One-time set-up of both atlases on slot 0's command buffer: the depth atlas cleared to 1
 * (empty texels read "nothing here"), then both in GENERAL layout for good. */
static enum rnd_result init_layouts(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_slot *s = ctx->slots[0];
	VkResult vr;
	VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
	if ((vr = vkBeginCommandBuffer(s->cmd, &bi)) != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkBeginCommandBuffer (atlas init)");
	VkImageSubresourceRange range = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
	VkImageMemoryBarrier2 b = {
		.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_NONE,
		.dstStageMask = VK_PIPELINE_STAGE_2_CLEAR_BIT, .dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
		.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, .newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
		.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
		.image = ctx->atlas_depth.img, .subresourceRange = range,
	};
	VkDependencyInfo di = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1, .pImageMemoryBarriers = &b};
	vkCmdPipelineBarrier2(s->cmd, &di);
	VkClearDepthStencilValue one = {1.0f, 0};
	vkCmdClearDepthStencilImage(s->cmd, ctx->atlas_depth.img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &one, 1, &range);
	VkImageMemoryBarrier2 g[2];
	uint32_t n = 0;
	g[n++] = (VkImageMemoryBarrier2){
		.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_CLEAR_BIT,
		.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT, .dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
		.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
		.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, .newLayout = VK_IMAGE_LAYOUT_GENERAL,
		.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
		.image = ctx->atlas_depth.img, .subresourceRange = range,
	};
	if (ctx->atlas_moments.img)
		g[n++] = (VkImageMemoryBarrier2){
			.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_NONE,
			.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
			.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
			.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, .newLayout = VK_IMAGE_LAYOUT_GENERAL,
			.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
			.image = ctx->atlas_moments.img, .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1},
		};
	di.imageMemoryBarrierCount = n;
	di.pImageMemoryBarriers = g;
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
	if (!rnd_atlas_init(&c->atlas, size, 64)) {
		free(c);
		return rnd_fail(err, RND_ERR_INVALID, "atlas size %u: must be a power of two between 64 and 16384", size);
	}
	pthread_mutex_init(&c->mu, NULL);
	ctx->cache = c;
	/* Maps are drawn at the origin of a slot's scratch depth image and copied into their tile;
	 * the atlas itself is never a render target. */
	if ((r = rnd_image_create(ctx, RND_SHADOW_FORMAT, size, size, 1, 1,
	                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
	                          VK_IMAGE_ASPECT_DEPTH_BIT, "shadow depth atlas", &ctx->atlas_depth, err)) != RND_OK)
		goto fail;
	if (ctx->moments.available &&
	    (r = rnd_image_create(ctx, rnd_moments_format(ctx, false), size, size, 1, 1,
	                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
	                          "shadow moment atlas", &ctx->atlas_moments, err)) != RND_OK)
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
	rnd_image_destroy(ctx, &ctx->atlas_moments);
	rnd_image_destroy(ctx, &ctx->atlas_depth);
	if (!c) return;
	rnd_atlas_release(&c->atlas);
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
static bool evict_one(struct rnd_shadow_cache *c)
{
	struct rnd_cache_entry *lru = NULL;
	for (uint32_t i = 0; i < MAX_ENTRIES; i++) {
		struct rnd_cache_entry *e = &c->entries[i];
		if (e->live && e->valid && !e->refs && (!lru || e->last_use < lru->last_use)) lru = e;
	}
	if (!lru) return false;
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

enum rnd_result rnd_cache_acquire(struct rnd_context *ctx, const struct rnd_cache_request *req, uint32_t n,
                                  struct rnd_cache_grant *out, struct rnd_error *err)
{
	struct rnd_shadow_cache *c = ctx->cache;
	enum rnd_result r = RND_OK;
	uint32_t res[UMBRA_MAX_LIGHTS], order[UMBRA_MAX_LIGHTS], nmiss = 0;
	bool granted[UMBRA_MAX_LIGHTS] = {false};
	if (n > UMBRA_MAX_LIGHTS) return rnd_fail(err, RND_ERR_LIMIT, "%u shadowed lights: at most %d", n, UMBRA_MAX_LIGHTS);
	pthread_mutex_lock(&c->mu);
	c->clock++;
	/* 1. Completed maps with the same key are reused as they are. */
	for (uint32_t k = 0; k < n; k++) {
		const struct rnd_cache_request *q = &req[k];
		struct rnd_cache_grant *g = &out[k];
		memset(g, 0, sizeof *g);
		if (q->tiles == 0 || q->tiles > 8) { r = rnd_fail(err, RND_ERR_LIMIT, "%u tiles for one light", q->tiles); goto fail; }
		for (uint32_t i = 0; q->key && i < MAX_ENTRIES; i++) {
			struct rnd_cache_entry *e = &c->entries[i];
			/* Only at the resolution asked for: a map made smaller under atlas pressure is not
			 * what this request would draw, and reusing it would make its bytes depend on
			 * what the cache held. */
			uint32_t want = q->res < 64 ? 64 : q->res > c->atlas.size ? c->atlas.size : q->res;
			if (e->live && e->valid && e->key == q->key && e->ntiles == q->tiles && e->res == want) {
				e->refs++;
				e->last_use = c->clock;
				g->entry = i; g->res = e->res; g->hit = true;
				memcpy(g->tile, e->tile, sizeof e->tile);
				granted[k] = true;
				__atomic_add_fetch(&ctx->stats_hits, 1, __ATOMIC_RELAXED);
				break;
			}
		}
		if (granted[k]) continue;
		res[k] = q->res < 64 ? 64 : q->res > c->atlas.size ? c->atlas.size : q->res;
		order[nmiss++] = k;
	}
	/* 2. Budget: what is not held by maps in use (by this or other renders) can be had,
	 * evicting unused maps. Over budget, the largest maps give up resolution first. */
	uint64_t held = 0;
	for (uint32_t i = 0; i < MAX_ENTRIES; i++)
		if (c->entries[i].live && c->entries[i].refs)
			held += (uint64_t)c->entries[i].ntiles * c->entries[i].res * c->entries[i].res;
	uint64_t budget = (uint64_t)c->atlas.size * c->atlas.size - held;
	for (;;) {
		uint64_t need = 0;
		uint32_t big = n;
		for (uint32_t m = 0; m < nmiss; m++) {
			uint32_t k = order[m];
			need += (uint64_t)req[k].tiles * res[k] * res[k];
			if (res[k] > 64 && (big == n || res[k] > res[big])) big = k;
		}
		if (need <= budget || big == n) break;
		res[big] /= 2;
	}
	/* 3. Allocate the largest first (fewest holes), evicting unused maps as needed; where
	 * fragmentation still leaves no room, that light goes down one more step. */
	for (uint32_t a = 0; a < nmiss; a++)
		for (uint32_t b2 = a + 1; b2 < nmiss; b2++)
			if (res[order[b2]] > res[order[a]]) { uint32_t t = order[a]; order[a] = order[b2]; order[b2] = t; }
	for (uint32_t m = 0; m < nmiss; m++) {
		uint32_t k = order[m];
		const struct rnd_cache_request *q = &req[k];
		struct rnd_cache_grant *g = &out[k];
		uint32_t slot = free_slot(c);
		if (slot == MAX_ENTRIES) { r = rnd_fail(err, RND_ERR_LIMIT, "shadow cache: all %d entries in use", MAX_ENTRIES); goto fail; }
		struct rnd_cache_entry *e = &c->entries[slot];
		bool ok = false;
		while (!ok) {
			ok = alloc_tiles(c, e, q->tiles, res[k]);
			if (ok || evict_one(c)) continue;
			if (res[k] <= 64) break;
			res[k] /= 2;
		}
		if (!ok) {
			r = rnd_fail(err, RND_ERR_LIMIT, "shadow atlas (%ux%u) is full: %u tiles of 64 do not fit next to the "
			             "maps in use (raise the atlas size)", c->atlas.size, c->atlas.size, q->tiles);
			goto fail;
		}
		e->live = true; e->valid = false; e->key = q->key; e->refs = 1; e->last_use = c->clock;
		g->entry = slot; g->res = e->res; g->hit = false;
		memcpy(g->tile, e->tile, sizeof e->tile);
		granted[k] = true;
		if (q->key) __atomic_add_fetch(&ctx->stats_misses, 1, __ATOMIC_RELAXED);
	}
	pthread_mutex_unlock(&c->mu);
	return RND_OK;
fail:
	pthread_mutex_unlock(&c->mu);
	for (uint32_t k = 0; k < n; k++)
		if (granted[k]) rnd_cache_release(ctx, &out[k], 1, false);
	return r;
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
}
