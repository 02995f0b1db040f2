/*
 * api/remap.c — open addressing over a power-of-two table at most half full; a slot holds the
 * key's index and its hash's top 32 bits (see remap.h).
 */
#include <stdlib.h>
#include <string.h>
#include "remap.h"

static uint64_t hash_key(const uint8_t *k, size_t size)
{
	uint64_t h = 0x9e3779b97f4a7c15ull ^ size;
	for (size_t i = 0; i < size; i += 4) {
		uint32_t w;
		memcpy(&w, k + i, 4);
		h = (h ^ w) * 0xff51afd7ed558ccdull;
		h ^= h >> 32;
	}
	h ^= h >> 29;
	h *= 0xc4ceb9fe1a85ec53ull;
	return h ^ (h >> 32);
}

size_t api_remap_keys(const void *keys, size_t n, size_t key_size, uint32_t *remap)
{
	const uint8_t *k = keys;
	size_t cap = 16;
	while (cap < 2 * n) cap *= 2;
	uint64_t *slot = malloc(cap * sizeof *slot);   /* (hash >> 32) << 32 | index + 1, 0 = empty */
	if (!slot) return SIZE_MAX;
	memset(slot, 0, cap * sizeof *slot);
	size_t unique = 0, mask = cap - 1;
	for (size_t i = 0; i < n; i++) {
		const uint8_t *key = k + i * key_size;
		uint64_t h = hash_key(key, key_size), tag = h & 0xffffffff00000000ull;
		size_t s = (size_t)h & mask;
		for (;;) {
			uint64_t e = slot[s];
			if (!e) {
				slot[s] = tag | (uint64_t)(i + 1);
				remap[i] = (uint32_t)unique++;
				break;
			}
			size_t j = (size_t)(e & 0xffffffffu) - 1;
			if ((e & 0xffffffff00000000ull) == tag && !memcmp(k + j * key_size, key, key_size)) {
				remap[i] = remap[j];
				break;
			}
			s = (s + 1) & mask;
		}
	}
	free(slot);
	return unique;
}
