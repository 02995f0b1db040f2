/*
 * api/scene_hash — the canonical hash of a parsed scene, the document it does not hold, and
 * the parts (scene_hash.h).
 */
#include <stdint.h>
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

/* ---- the document less what the parsed scene holds ---- */

/* Drops the object members of v that are (or become) empty objects; true when v is an empty
 * object afterwards. Arrays keep their elements (their count is in the parsed scene anyway). */
static bool prune(json_t *v, unsigned depth)
{
	if (depth > 256)
		return false;
	if (json_is_array(v)) {
		for (size_t i = 0; i < json_array_size(v); i++)
			prune(json_array_get(v, i), depth + 1);
		return false;
	}
	if (!json_is_object(v))
		return false;
	const char *k;
	json_t *m;
	void *tmp;
	json_object_foreach_safe(v, tmp, k, m) {
		if (prune(m, depth + 1))
			json_object_del(v, k);
	}
	return json_object_size(v) == 0;
}

/* ---- the parsed scene ---- */

/* A pointer member as whether it is set (what it points to is hashed by its source). */
#define AS_SET(p) ((p) = (p) ? (__typeof__(p))(uintptr_t)1 : NULL)

static uint64_t object_bytes(uint64_t h, const struct rnd_object *src)
{
	struct rnd_object o;
	memcpy(&o, src, sizeof o);
	AS_SET(o.positions);
	AS_SET(o.indices);
	AS_SET(o.normals);
	AS_SET(o.uvs);
	AS_SET(o.uvs1);
	AS_SET(o.colors);
	AS_SET(o.tangents);
	AS_SET(o.lods);
	AS_SET(o.caster);
	AS_SET(o.mesh_bounds);
	return rnd_hash(h, &o, sizeof o);
}

static uint64_t material_bytes(uint64_t h, const struct rnd_material *src)
{
	struct rnd_material m;
	memcpy(&m, src, sizeof m);
	for (int i = 0; i < RND_TEX_SLOTS; i++)
		AS_SET(m.textures[i]);
	return rnd_hash(h, &m, sizeof m);
}

static uint64_t parsed(uint64_t h, const struct api_scene *s)
{
	struct rnd_scene sc;
	memcpy(&sc, &s->scene, sizeof sc);
	AS_SET(sc.views);
	AS_SET(sc.materials);
	AS_SET(sc.objects);
	AS_SET(sc.lights);
	AS_SET(sc.environment.map.rgb);   /* its pixels: map.key (their hash) */
	sc.deadline_ns = 0;   /* how long, not what: set per request */
	sc.cancel = NULL;
	sc.cancel_user = NULL;
	h = item(h, 'S', &sc, sizeof sc);
	h = frame(h, 'V', sc.view_count);
	if (sc.view_count)   /* no pointers, no padding; NULL when none (memcpy's NULL is UB even for 0 bytes) */
		h = rnd_hash(h, s->scene.views, sc.view_count * sizeof *s->scene.views);
	h = frame(h, 'M', sc.material_count);
	for (uint32_t i = 0; i < sc.material_count; i++)
		h = material_bytes(h, &s->scene.materials[i]);
	h = frame(h, 'O', sc.object_count);
	for (uint32_t i = 0; i < sc.object_count; i++)
		h = object_bytes(h, &s->scene.objects[i]);
	h = frame(h, 'L', sc.light_count);
	if (sc.light_count)   /* no pointers */
		h = rnd_hash(h, s->scene.lights, sc.light_count * sizeof *s->scene.lights);
	/* The answer's own members (api.h), and what the image leaves out. */
	int32_t own[4] = {(int32_t)s->format, s->format_explicit, (int32_t)s->bit_depth, s->png_level};
	h = item(h, 'A', own, sizeof own);
	h = item(h, 'q', &s->quality, sizeof s->quality);
	/* The PNG-only members given decide warnings when the answer is an EXR, WebP or AVIF (scene_views.c);
	 * the answer is a PNG whatever the Accept when output.format says so. */
	unsigned png_only = s->format_explicit && s->format == API_FORMAT_PNG ? 0 : s->png_only_;
	h = item(h, 'p', &png_only, sizeof png_only);
	return item(h, 'w', s->warnings, strlen(s->warnings));
}

uint64_t api_scene_hash(json_t *root, const struct api_big_strings *big, const struct api_part *parts,
                        size_t nparts, const struct api_member_read *reads, size_t nreads,
                        const struct api_scene *s)
{
	uint64_t h = parsed(RND_FNV_SEED, s);
	if (reads) {
		for (size_t i = 0; i < nreads; i++)
			json_object_del(reads[i].obj, reads[i].key);
		prune(root, 0);
	}
	h = value(h, root, big, 0);
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
