/*
 * api/scene_hash — the canonical hash of a merged scene document and its parts (scene_hash.h).
 */
#include <stdlib.h>
#include <string.h>

#include "scene_hash.h"
#include "umbra/rnd_math.h"

/* One framed item: a tag byte and a 64-bit length, then the bytes (a word at a time,
 * rnd_hash: byte-at-a-time FNV-1a was ~70 ms over a 50 MB model part, paid by each parse of
 * the request, the worker's and the import thread's). */
static uint64_t item(uint64_t h, char tag, const void *data, size_t len)
{
	uint64_t n = len;
	h = rnd_fnv1a(h, &tag, 1);
	h = rnd_fnv1a(h, &n, sizeof n);
	return len ? rnd_hash(h, data, len) : h;
}

/* A container's tag and count. */
static uint64_t frame(uint64_t h, char tag, size_t count)
{
	uint64_t n = count;
	h = rnd_fnv1a(h, &tag, 1);
	return rnd_fnv1a(h, &n, sizeof n);
}

static int key_cmp(const void *a, const void *b)
{
	return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static uint64_t value(uint64_t h, const json_t *v, const struct api_big_strings *big, unsigned depth);

/* An object's members in key order. The keys are sorted on the stack for small objects (a
 * scene's are), on the heap for large ones; out of memory: jansson's order (still
 * deterministic for one document, only not canonical). */
static uint64_t object(uint64_t h, const json_t *v, const struct api_big_strings *big, unsigned depth)
{
	size_t n = json_object_size(v);
	const char *stack[32];
	const char **keys = n <= 32 ? stack : malloc(n * sizeof *keys);
	h = frame(h, '{', n);
	const char *k;
	json_t *m;
	if (!keys) {
		json_object_foreach((json_t *)v, k, m) {
			h = item(h, 'k', k, strlen(k));
			h = value(h, m, big, depth + 1);
		}
		return h;
	}
	size_t i = 0;
	json_object_foreach((json_t *)v, k, m)
		keys[i++] = k;
	qsort(keys, n, sizeof *keys, key_cmp);
	for (i = 0; i < n; i++) {
		h = item(h, 'k', keys[i], strlen(keys[i]));
		h = value(h, json_object_get(v, keys[i]), big, depth + 1);
	}
	if (keys != stack)
		free(keys);
	return h;
}

static uint64_t value(uint64_t h, const json_t *v, const struct api_big_strings *big, unsigned depth)
{
	if (depth > 256) /* deeper than any document the parser accepts: hashed as a marker */
		return item(h, '^', NULL, 0);
	switch (json_typeof(v)) {
	case JSON_OBJECT:
		return object(h, v, big, depth);
	case JSON_ARRAY: {
		size_t n = json_array_size(v);
		h = frame(h, '[', n);
		for (size_t i = 0; i < n; i++)
			h = value(h, json_array_get(v, i), big, depth + 1);
		return h;
	}
	case JSON_STRING: {
		size_t len = 0;
		const char *s = api_big_string(big, v, &len);
		return item(h, 's', s, len);
	}
	case JSON_INTEGER:
	case JSON_REAL: {
		double d = json_number_value(v);
		if (d == 0)
			d = 0; /* -0 as 0 */
		return item(h, 'n', &d, sizeof d);
	}
	case JSON_TRUE:
		return item(h, 't', NULL, 0);
	case JSON_FALSE:
		return item(h, 'f', NULL, 0);
	default:
		return item(h, '0', NULL, 0);
	}
}

static int part_cmp(const void *a, const void *b)
{
	const struct api_part *x = *(const struct api_part *const *)a, *y = *(const struct api_part *const *)b;
	return strcmp(x->name ? x->name : "", y->name ? y->name : "");
}

uint64_t api_scene_hash(const json_t *root, const struct api_big_strings *big, const struct api_part *parts,
                        size_t nparts)
{
	uint64_t h = value(RND_FNV_SEED, root, big, 0);
	if (!nparts)
		return h;
	const struct api_part **order = malloc(nparts * sizeof *order);
	for (size_t i = 0; i < nparts; i++) {
		if (order)
			order[i] = &parts[i];
	}
	if (order)
		qsort(order, nparts, sizeof *order, part_cmp);
	h = frame(h, 'P', nparts);
	for (size_t i = 0; i < nparts; i++) {
		const struct api_part *p = order ? order[i] : &parts[i];
		h = item(h, 'k', p->name ? p->name : "", p->name ? strlen(p->name) : 0);
		h = item(h, 'b', p->data, p->len);
	}
	free(order);
	return h;
}
