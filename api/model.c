/*
 * api/model — the process-wide LRU cache of imported models, format sniffing, and the entry
 * point api_model_get() (see model.h). The import itself happens in a sandboxed helper process
 * (api/sandbox.h runs api/model_import.c there); this file only ever sees the validated reply.
 *
 * Cache: a doubly linked LRU list under one mutex, looked up by a 64-bit FNV-1a hash of the
 * bytes and the format and confirmed with memcmp against a copy of the bytes, so a hash
 * collision can never hand one caller another caller's model. The cache holds one reference to
 * each entry it lists; scenes hold their own, so eviction never frees a model in use. The
 * mutex is never held across an import: two requests that miss on the same bytes both import
 * them and the second keeps the first one's entry.
 */
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include "errmsg.h"
#include "arena.h"
#include "model.h"
#include "model_levels.h"
#include "model_lod.h"
#include "umbra/rnd_math.h"
#include "sandbox.h"
#include "sandbox_stats.h"

struct model_priv {
	struct api_model pub;
	atomic_uint refs;
	struct api_arena *arena;
	/* cache key, and the bytes that confirm it (NULL while not cached) */
	uint64_t hash;
	uint8_t *src;
	size_t src_len;
	size_t model_len;             /* of src: the model file; the rest are the files it refers to */
	uint64_t serial;              /* unique per import: api_model_cache_take() */
	struct model_priv *prev, *next;
	bool listed;
};

static pthread_mutex_t cache_mu = PTHREAD_MUTEX_INITIALIZER;
static struct model_priv *lru_head, *lru_tail; /* head = most recently used */
static uint64_t cache_total, cache_hits, cache_misses;
static uint64_t cache_limit = 256u << 20;   /* api_model_cache_set_limit() */
static atomic_uint_fast64_t next_serial = 1;

static const char *const FORMAT_NAMES[] = {"glb", "gltf", "obj", "stl", "ply"};

const char *const API_IMPORT_STAGE_NAMES[API_IMPORT_STAGES] = {
	"model-read", "model-parse", "model-textures", "model-closed", "model-lod", "model-transfer", "model-validate",
	"model-cache",
};

double api_clock_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

const char *api_model_format_name(enum api_model_format f)
{
	return f >= API_MODEL_GLB && f <= API_MODEL_PLY ? FORMAT_NAMES[f] : "unknown";
}


/* ---- format sniffing ---- */

static bool starts_with_word(const uint8_t *d, size_t len, const char *w)
{
	size_t n = strlen(w);
	return len > n && !memcmp(d, w, n) && (d[n] == ' ' || d[n] == '\t' || d[n] == '\r' || d[n] == '\n');
}

enum api_model_format api_model_sniff(const uint8_t *d, size_t len)
{
	if (!d || !len) return API_MODEL_SNIFF;
	if (len >= 12 && !memcmp(d, "glTF", 4)) return API_MODEL_GLB;
	if (len >= 4 && !memcmp(d, "ply", 3) && (d[3] == '\n' || d[3] == '\r')) return API_MODEL_PLY;
	/* Binary STL: an 80-byte header, a triangle count, 50 bytes per triangle. Checked before
	 * ASCII STL because many binary headers also start with "solid". */
	if (len >= 84) {
		uint32_t n = (uint32_t)d[80] | (uint32_t)d[81] << 8 | (uint32_t)d[82] << 16 | (uint32_t)d[83] << 24;
		if ((uint64_t)n * 50 + 84 == len) return API_MODEL_STL;
	}
	size_t i = 0;
	if (len >= 3 && d[0] == 0xef && d[1] == 0xbb && d[2] == 0xbf) i = 3; /* UTF-8 BOM */
	while (i < len && (d[i] == ' ' || d[i] == '\t' || d[i] == '\r' || d[i] == '\n')) i++;
	if (i < len && d[i] == '{') return API_MODEL_GLTF;
	if (starts_with_word(d + i, len - i, "solid")) return API_MODEL_STL;
	/* OBJ: text whose statements are OBJ keywords; one vertex or face line settles it. */
	static const char *const kw[] = {"v", "vn", "vt", "f", "o", "g", "s", "mtllib", "usemtl", NULL};
	size_t scan = len < 65536 ? len : 65536;
	for (size_t p = i; p < scan;) {
		size_t e = p;
		while (e < scan && d[e] != '\n') e++;
		if (d[p] != '#' && d[p] != '\r' && d[p] != '\n') {
			bool known = false;
			for (int k = 0; kw[k] && !known; k++) known = starts_with_word(d + p, e - p + (e < scan), kw[k]);
			if (!known) break;
			if (d[p] == 'v' || d[p] == 'f') return API_MODEL_OBJ;
		}
		p = e + 1;
	}
	return API_MODEL_SNIFF;
}

enum api_model_format api_model_settle_format(const uint8_t *data, size_t len, enum api_model_format stated,
                                              char *warning, size_t size)
{
	if (warning && size) warning[0] = 0;
	enum api_model_format seen = api_model_sniff(data, len);
	/* OBJ is told by its statements (a heuristic): it never overrides what was stated. */
	if (stated == API_MODEL_SNIFF || seen == API_MODEL_SNIFF || seen == API_MODEL_OBJ) return stated;
	if (seen != stated && warning && size)
		snprintf(warning, size, "the file is a %s file by its bytes, not %s as its format or file name says: read as "
		         "%s", FORMAT_NAMES[seen], api_model_format_name(stated), FORMAT_NAMES[seen]);
	return seen;
}

static void model_free(struct model_priv *m)
{
	if (!m) return;
	api_levels_free(&m->pub);
	pthread_mutex_destroy(&m->pub.levels_mu_);
	api_arena_destroy(m->arena);   /* the source's copy with it (src_copy) */
	free(m);
}

/* The cache's copy of a model's bytes (what confirms a hit, byte for byte), on a mapping of its
 * own that m's arena owns, advised to use transparent huge pages: the heap's fresh 4 KiB pages
 * fault one at a time, and a 50 MB copy took 140-210 ms that way on a virtualised machine
 * against 6-14 ms. NULL without memory. */
static uint8_t *src_copy(struct api_arena *arena, const uint8_t *data, size_t len)
{
	void *p = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
	if (p == MAP_FAILED) return NULL;
	api_mem_huge(p, len);   /* a hint: refused or ignored, the copy is only slower */
	if (api_arena_own_mapping(arena, p, len) != 0) {
		munmap(p, len);
		return NULL;
	}
	memcpy(p, data, len);
	mprotect(p, len, PROT_READ);
	return p;
}

/* Every texture's mip levels 1.. (rnd_texture.chain), for the colour space of the first slot
 * that reads it: a cached model's renders then copy them instead of building them
 * (DamagedHelmet's five 2048^2 textures: ~220 ms of CPU per render). Built only for a model the
 * cache keeps (get(): they count in its cost), 1/3 of the decoded texels. With build false:
 * only the bytes they would take. Best effort: out of memory leaves a texture without them. */
static uint64_t texture_chains(struct api_model *m, struct api_arena *arena, bool build)
{
	uint64_t total = 0;
	for (uint32_t i = 0; i < m->material_count; i++)
		for (uint32_t k = 0; k < RND_TEX_SLOTS; k++) {
			struct rnd_texture *t = (struct rnd_texture *)m->materials[i].textures[k];
			if (!t || t->chain || !t->rgba) continue;
			bool seen = false;   /* shared by an earlier slot (counted once) */
			for (uint32_t j = 0; j <= i && !seen; j++)
				for (uint32_t l = 0; l < (j < i ? RND_TEX_SLOTS : k); l++)
					if (m->materials[j].textures[l] == t) seen = true;
			if (seen) continue;
			size_t base = (size_t)t->width * t->height * 4, n = (size_t)rnd_texture_chain_bytes(t->width, t->height);
			total += n - base;
			if (!build) continue;
			uint8_t *full = malloc(n), *rest = api_arena_alloc(arena, n - base);
			if (full && rest) {
				t->chain_srgb = rnd_texture_slot_srgb((enum rnd_texture_slot)k);
				rnd_texture_build_chain(t->rgba, t->width, t->height, t->chain_srgb, full);
				memcpy(rest, full + base, n - base);
				t->chain = rest;
			}
			free(full);
		}
	return total;
}

/* Imports through the sandbox (api/sandbox.h): the bytes never meet Assimp in this process. */
static struct model_priv *import(const uint8_t *data, size_t len, size_t model_len, size_t nfiles,
                                 enum api_model_format format, const struct api_limits *lim, int *status, char *err,
                                 size_t errsize)
{
	const struct api_import_gate *g = lim ? lim->import_gate : NULL;
	if (g && !g->try_enter(g->user)) {
		*status = 503;
		api_err_set(err, errsize, "no import slot is free now (--import-slots); retry later");
		return NULL;
	}
	struct model_priv *m = calloc(1, sizeof *m);
	if (!m || !(m->arena = api_arena_create())) {
		free(m);
		*status = 500;
		api_err_set(err, errsize, "out of memory importing the model");
		return NULL;
	}
	atomic_init(&m->refs, 1);
	pthread_mutex_init(&m->pub.levels_mu_, NULL);
	m->pub.priv_ = m;
	m->serial = atomic_fetch_add(&next_serial, 1);
	size_t bytes = 0;
	if (api_sandbox_import_bundle(data, len, model_len, nfiles, format, lim, m->arena, &m->pub, &bytes, status, err,
	                              errsize) != API_OK) {
		model_free(m);
		return NULL;
	}
	/* The importer marked the meshes closed and built the level of this request's image size;
	 * a cached model drawn at another size gets that size's then (api/model_levels.h). */
	m->pub.format = format;
	m->pub.level_side = lim ? lim->output_side : 0;
	m->pub.priv_ = m;
	m->pub.bytes_ = bytes + sizeof *m;
	return m;
}

/* ---- cache ---- */

/* With cache_mu held. */
static void lru_unlink(struct model_priv *m)
{
	if (m->prev) m->prev->next = m->next; else lru_head = m->next;
	if (m->next) m->next->prev = m->prev; else lru_tail = m->prev;
	m->prev = m->next = NULL;
	m->listed = false;
	cache_total -= m->pub.bytes_;
}

static void lru_push_front(struct model_priv *m)
{
	m->prev = NULL;
	m->next = lru_head;
	if (lru_head) lru_head->prev = m; else lru_tail = m;
	lru_head = m;
	m->listed = true;
	cache_total += m->pub.bytes_;
}

/* Whether textures decoded for class c (api_texture_class; 0 = as stored) leave every
 * texture of at most max texels as stored. */
static bool none_reduced(uint32_t max, uint32_t c)
{
	return !c || (uint64_t)max < 2ull * API_TEXTURE_SIDE_PER_PIXEL * c;
}

/* Whether m's textures are the ones a fresh import for images of `side` decodes: the same
 * class, or neither class reduces any of them (the same request, the same bytes). */
static bool textures_cover(const struct model_priv *m, uint32_t side)
{
	uint32_t c = api_texture_class(side), mc = m->pub.texture_side, max = m->pub.texture_max;
	return !max || c == mc || (none_reduced(max, c) && none_reduced(max, mc));
}

uint32_t api_texture_class(uint32_t side)
{
	uint32_t c = 1;
	while (side && c < side && c < (1u << 30)) c <<= 1;
	return side ? c : 0;
}

/* Whether m was imported from these bytes (hash h, the model's first model_len of them). */
static bool same_source(const struct model_priv *m, uint64_t h, const uint8_t *data, size_t len, size_t model_len,
                        enum api_model_format f)
{
	return m->hash == h && m->src_len == len && m->model_len == model_len && m->pub.format == f &&
	       !memcmp(m->src, data, len);
}

static struct model_priv *lru_find(uint64_t h, const uint8_t *data, size_t len, size_t model_len,
                                   enum api_model_format f, uint32_t side)
{
	for (struct model_priv *m = lru_head; m; m = m->next)
		if (textures_cover(m, side) && same_source(m, h, data, len, model_len, f)) return m;
	return NULL;
}

/* With cache_mu held: unlists the entries for the same bytes as m whose requests m serves (a
 * model imported again for larger images replaces one whose textures were decoded smaller
 * when m's are the same: neither reduces them); returns them as a list for release_list(). */
static struct model_priv *unlist_covered(const struct model_priv *m)
{
	struct model_priv *out = NULL;
	for (struct model_priv *o = lru_head, *n; o; o = n) {
		n = o->next;
		if (o == m || !textures_cover(m, o->pub.texture_side) ||
		    !same_source(o, m->hash, m->src, m->src_len, m->model_len, m->pub.format))
			continue;
		lru_unlink(o);
		o->next = out;
		out = o;
	}
	return out;
}

void api_model_release(struct api_model *pub)
{
	if (!pub) return;
	struct model_priv *m = pub->priv_;
	if (atomic_fetch_sub(&m->refs, 1) == 1) model_free(m);
}

/* With cache_mu held: unlists least recently used models (never `keep`) until the cache is
 * within its limit; returns them as a list for release_list() outside the lock. */
static struct model_priv *evict_over_limit(const struct model_priv *keep)
{
	struct model_priv *evicted = NULL;
	while (lru_tail && lru_tail != keep && cache_total > cache_limit) {
		struct model_priv *t = lru_tail;
		lru_unlink(t);
		t->next = evicted;
		evicted = t;
	}
	return evicted;
}

/* Drops the cache's reference to each model of the list (without cache_mu). */
static void release_list(struct model_priv *list)
{
	while (list) {
		struct model_priv *n = list->next;
		list->next = NULL;
		api_model_release(&list->pub);
		list = n;
	}
}

/* The listed model of data[0..len) (hash h) for images of side, a reference taken and moved to
 * the list's front; NULL on a miss. Counts the hit or miss. */
static struct model_priv *cache_take(uint64_t h, const uint8_t *data, size_t len, size_t model_len,
                                     enum api_model_format format, uint32_t side)
{
	pthread_mutex_lock(&cache_mu);
	struct model_priv *hit = lru_find(h, data, len, model_len, format, side);
	if (hit) {
		cache_hits++;
		lru_unlink(hit);
		lru_push_front(hit);
		atomic_fetch_add(&hit->refs, 1);
	} else {
		cache_misses++;
	}
	pthread_mutex_unlock(&cache_mu);
	return hit;
}

/* Lists m, just imported from data[0..len) (the cache's reference taken; the models it covers,
 * and those it pushes over the cache's limit, released), and returns NULL; or, when another
 * request listed the same bytes meanwhile, returns that one with a reference taken (m is then
 * not listed: the caller's to release). */
static struct model_priv *cache_list(struct model_priv *m, const uint8_t *data, size_t len, size_t model_len,
                                     enum api_model_format format, uint32_t side)
{
	struct model_priv *evicted = NULL;
	pthread_mutex_lock(&cache_mu);
	struct model_priv *dup = lru_find(m->hash, data, len, model_len, format, side);
	if (dup) {
		atomic_fetch_add(&dup->refs, 1);
	} else {
		struct model_priv *older = unlist_covered(m);
		lru_push_front(m);
		atomic_fetch_add(&m->refs, 1); /* the cache's reference */
		evicted = evict_over_limit(m);
		if (older) {   /* both lists end in NULL: join them for one release */
			struct model_priv *t = older;
			while (t->next) t = t->next;
			t->next = evicted;
			evicted = older;
		}
	}
	pthread_mutex_unlock(&cache_mu);
	release_list(evicted);
	return dup;
}

/* The cache's entry for `data` (the model's model_len bytes, then nfiles files as the sandbox's
 * bundle lays them out: the key covers the files too), importing it on a miss. */
static enum api_result get(const uint8_t *data, size_t len, size_t model_len, size_t nfiles,
                           enum api_model_format format, const struct api_limits *lim, struct api_model **out,
                           bool *was_hit, int *status, char *err, size_t errsize)
{
	/* Word at a time: a cached 50 MB model is hashed on every request that names it (byte at a
	 * time that alone took ~50 ms); the whole buffer is at hand, so no need to stream. */
	uint64_t h = rnd_hash(RND_FNV_SEED ^ (uint64_t)format, data, len);

	uint32_t side = lim ? lim->output_side : 0;
	struct model_priv *hit = cache_take(h, data, len, model_len, format, side);
	if (hit) {
		api_levels_on_hit(&hit->pub, lim);
		*was_hit = true;
		*out = &hit->pub;
		*status = 0;
		return API_OK;
	}

	struct model_priv *m = import(data, len, model_len, nfiles, format, lim, status, err, errsize);
	if (!m) return API_ERR;
	*status = 0;
	uint64_t chains = texture_chains(&m->pub, m->arena, false);
	double t0 = api_clock_ms();
	uint64_t cost = m->pub.bytes_ + len + chains;
	pthread_mutex_lock(&cache_mu);
	uint64_t cache_bytes = cache_limit;
	pthread_mutex_unlock(&cache_mu);
	if (!cache_bytes || cost > cache_bytes || !(m->src = src_copy(m->arena, data, len))) {
		api_sbx_stats_import_times(&m->pub.times);
		*out = &m->pub;    /* not cached: the caller's reference is the only one */
		return API_OK;
	}
	texture_chains(&m->pub, m->arena, true);
	m->pub.times.ms[API_IMPORT_CACHE] = (float)(api_clock_ms() - t0);
	api_sbx_stats_import_times(&m->pub.times);
	m->src_len = len;
	m->model_len = model_len;
	m->hash = h;
	m->pub.bytes_ = cost;

	/* Another request may have imported the same bytes meanwhile: use the listed one. */
	struct model_priv *dup = cache_list(m, data, len, model_len, format, side);
	if (dup) {
		/* Imported for another image size of the same texture class, maybe: this request's
		 * level as on any hit, or it would render at full detail here and with its level
		 * the next time (the same request, other bytes). */
		api_model_release(&m->pub);
		m = dup;
		api_levels_on_hit(&m->pub, lim);
	}
	*out = &m->pub;
	return API_OK;
}

enum api_result api_model_get_timed(const uint8_t *data, size_t len, const struct api_model_file *files,
                                    size_t nfiles, enum api_model_format format, const struct api_limits *lim,
                                    struct api_model **out, struct api_import_times *times, int *status, char *err,
                                    size_t errsize)
{
	*out = NULL;
	*status = 400;
	struct api_limits def;
	if (!lim) {
		api_limits_defaults(&def);
		lim = &def;
	}
	if (!data || !len) return api_err_set(err, errsize, "the model file is empty");
	if (format == API_MODEL_SNIFF) format = api_model_sniff(data, len);
	if (format < API_MODEL_GLB || format > API_MODEL_PLY)
		return api_err_set(err, errsize, "the file is not a recognisable glb, gltf, obj, stl or ply model "
		               "(give format to say which)");
	bool hit = false;
	enum api_result rc;
	if (!nfiles) {
		rc = get(data, len, len, 0, format, lim, out, &hit, status, err, errsize);
	} else {
		size_t blen;
		uint8_t *bundle = api_sbx_bundle_encode(data, len, files, nfiles, &blen);
		if (!bundle) {
			*status = 422;
			return api_err_set(err, errsize, "the model and its files are too large to import (out of memory)");
		}
		rc = get(bundle, blen, len, nfiles, format, lim, out, &hit, status, err, errsize);
		free(bundle);
	}
	if (rc == API_OK && times) {
		if (hit) times->hits++;
		else {
			for (int k = 0; k < API_IMPORT_STAGES; k++) times->ms[k] += (*out)->times.ms[k];
			times->imports++;
		}
	}
	return rc;
}

enum api_result api_model_get_files(const uint8_t *data, size_t len, const struct api_model_file *files,
                                    size_t nfiles, enum api_model_format format, const struct api_limits *lim,
                                    struct api_model **out, int *status, char *err, size_t errsize)
{
	return api_model_get_timed(data, len, files, nfiles, format, lim, out, NULL, status, err, errsize);
}



enum api_result api_model_get(const uint8_t *data, size_t len, enum api_model_format format,
                              const struct api_limits *lim, struct api_model **out, int *status, char *err,
                              size_t errsize)
{
	return api_model_get_files(data, len, NULL, 0, format, lim, out, status, err, errsize);
}

uint64_t api_model_serial(const struct api_model *pub)
{
	return ((const struct model_priv *)pub->priv_)->serial;
}

struct api_model *api_model_cache_take(uint64_t serial)
{
	struct model_priv *hit = NULL;
	pthread_mutex_lock(&cache_mu);
	for (struct model_priv *m = lru_head; m && !hit; m = m->next)
		if (m->serial == serial) hit = m;
	if (hit) {
		cache_hits++;
		lru_unlink(hit);
		lru_push_front(hit);
		atomic_fetch_add(&hit->refs, 1);
	}
	pthread_mutex_unlock(&cache_mu);
	return hit ? &hit->pub : NULL;
}

void api_model_charge_(struct api_model *pub, size_t bytes)
{
	struct model_priv *m = pub->priv_;
	pthread_mutex_lock(&cache_mu);
	bool listed = m->listed;
	if (listed) lru_unlink(m);
	pub->bytes_ += bytes;
	struct model_priv *evicted = NULL;
	if (listed) {
		lru_push_front(m);
		evicted = evict_over_limit(m);
	}
	pthread_mutex_unlock(&cache_mu);
	release_list(evicted);
}

void api_model_cache_set_limit(uint64_t bytes)
{
	pthread_mutex_lock(&cache_mu);
	cache_limit = bytes;
	struct model_priv *evicted = evict_over_limit(NULL);
	pthread_mutex_unlock(&cache_mu);
	release_list(evicted);
}

void api_model_cache_stats(uint64_t *hits, uint64_t *misses, uint64_t *bytes)
{
	pthread_mutex_lock(&cache_mu);
	if (hits) *hits = cache_hits;
	if (misses) *misses = cache_misses;
	if (bytes) *bytes = cache_total;
	pthread_mutex_unlock(&cache_mu);
}

void api_model_cache_clear(void)
{
	pthread_mutex_lock(&cache_mu);
	struct model_priv *list = NULL;
	while (lru_head) {
		struct model_priv *t = lru_head;
		lru_unlink(t);
		t->next = list;
		list = t;
	}
	pthread_mutex_unlock(&cache_mu);
	release_list(list);
}
