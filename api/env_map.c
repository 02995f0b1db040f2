/*
 * api/env_map — decoded environment maps, kept by the hash of their file's bytes (see
 * env_map.h). At most API_ENV_CACHE_BYTES of maps nobody holds stay, the least recently used
 * dropped first; a map held by a scene lives until its last reference goes.
 */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "env_map.h"

#define ENV_CACHE_MAX 8

static pthread_mutex_t cache_mu = PTHREAD_MUTEX_INITIALIZER;
static struct api_env_map *cache[ENV_CACHE_MAX];
static uint64_t cache_clock;

static uint64_t map_bytes(const struct api_env_map *m) { return (uint64_t)m->width * m->height * 12; }

static void map_free(struct api_env_map *m)
{
	if (!m) return;
	free(m->rgb);
	free(m);
}

/* 64-bit FNV-1a over 8-byte words, then the tail (the key only tells files apart). */
static uint64_t bytes_hash(const uint8_t *b, size_t len)
{
	uint64_t h = 0xcbf29ce484222325ull ^ len;
	size_t i = 0;
	for (; i + 8 <= len; i += 8) {
		uint64_t w;
		memcpy(&w, b + i, 8);
		h = (h ^ w) * 0x100000001b3ull;
		h ^= h >> 29;
	}
	for (; i < len; i++) h = (h ^ b[i]) * 0x100000001b3ull;
	return h ? h : 1;
}

/* Keeps the cache within its bytes (and slots) by dropping unheld maps, oldest first. Under the lock. */
static void cache_trim(uint64_t limit)
{
	for (;;) {
		uint64_t held = 0;
		int oldest = -1, used = 0;
		for (int i = 0; i < ENV_CACHE_MAX; i++) {
			if (!cache[i]) continue;
			used++;
			held += map_bytes(cache[i]);
			if (!cache[i]->refs && (oldest < 0 || cache[i]->used < cache[oldest]->used)) oldest = i;
		}
		if (oldest < 0 || (held <= limit && used < ENV_CACHE_MAX)) return;
		map_free(cache[oldest]);
		cache[oldest] = NULL;
	}
}

static struct api_env_map *cache_find(uint64_t key)
{
	for (int i = 0; i < ENV_CACHE_MAX; i++)
		if (cache[i] && cache[i]->key == key) {
			cache[i]->refs++;
			cache[i]->used = ++cache_clock;
			return cache[i];
		}
	return NULL;
}

/* m into the cache with one reference (the caller's); a map of the same key decoded meanwhile
 * by another thread is taken instead (m freed). */
static struct api_env_map *cache_add(struct api_env_map *m)
{
	pthread_mutex_lock(&cache_mu);
	struct api_env_map *other = cache_find(m->key);
	if (other) {
		pthread_mutex_unlock(&cache_mu);
		map_free(m);
		return other;
	}
	m->refs = 1;
	m->used = ++cache_clock;
	cache_trim(API_ENV_CACHE_BYTES > map_bytes(m) ? API_ENV_CACHE_BYTES - map_bytes(m) : 0);
	for (int i = 0; i < ENV_CACHE_MAX; i++)
		if (!cache[i]) {
			cache[i] = m;
			break;
		}
	/* every slot held by a scene: m lives on its reference alone (freed at its release) */
	pthread_mutex_unlock(&cache_mu);
	return m;
}

enum api_result api_env_map_get(const uint8_t *b, size_t len, struct api_env_map **out, int *status, char *err,
                                size_t errsize)
{
	*out = NULL;
	*status = 400;
	uint64_t key = bytes_hash(b, len);
	pthread_mutex_lock(&cache_mu);
	struct api_env_map *m = cache_find(key);
	pthread_mutex_unlock(&cache_mu);
	if (m) {
		*out = m;
		return API_OK;
	}
	struct api_env_reducer r = {0};
	enum api_result rc;
	if (api_env_is_hdr(b, len)) rc = api_env_decode_hdr(b, len, &r, err, errsize);
	else if (api_env_is_exr(b, len)) rc = api_env_decode_exr(b, len, &r, err, errsize);
	else {
		snprintf(err, errsize, "not an environment map: a Radiance .hdr (\"#?RADIANCE\") or an OpenEXR file");
		return API_ERR;
	}
	if (rc != API_OK) {
		free(r.out);
		return API_ERR;
	}
	if (!(m = calloc(1, sizeof *m))) {
		free(r.out);
		*status = 500;
		snprintf(err, errsize, "out of memory for the environment map");
		return API_ERR;
	}
	*m = (struct api_env_map){r.out, r.ow, r.oh, r.w, r.h, key, 0, 0};
	*out = cache_add(m);
	return API_OK;
}

void api_env_map_release(struct api_env_map *m)
{
	if (!m) return;
	pthread_mutex_lock(&cache_mu);
	bool cached = false;
	for (int i = 0; i < ENV_CACHE_MAX; i++) cached |= cache[i] == m;
	bool last = --m->refs == 0;
	if (last && cached) cache_trim(API_ENV_CACHE_BYTES);
	pthread_mutex_unlock(&cache_mu);
	if (last && !cached) map_free(m);
}

void api_env_map_cache_clear(void)
{
	pthread_mutex_lock(&cache_mu);
	cache_trim(0);
	pthread_mutex_unlock(&cache_mu);
}
