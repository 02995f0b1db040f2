/*
 * api/model_paths — see model_paths.h. A small table of entries, each one malloc'd block: the
 * key, then the files' stamps and paths. Replacement: least recently used (a tick per use).
 */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "model_levels.h"
#include "model_paths.h"

struct entry {
	char *key;                       /* "root\npath\nformat" */
	size_t nfiles;                   /* the model file, then the files it referred to */
	char **paths;
	struct api_asset_stamp *stamps;
	uint64_t serial, files_hash, used;
};

static pthread_mutex_t mu = PTHREAD_MUTEX_INITIALIZER;
static struct entry *table[API_MODEL_PATHS_MAX];
static uint64_t tick, hits;

static char *key_of(const struct api_model_path_key *k)
{
	size_t n = strlen(k->root) + strlen(k->path) + 32;
	char *s = malloc(n);
	if (s) snprintf(s, n, "%s\n%s\n%d", k->root, k->path, k->format);
	return s;
}

static void entry_free(struct entry *e)
{
	if (!e) return;
	for (size_t i = 0; i < e->nfiles; i++) free(e->paths[i]);
	free(e->paths);
	free(e->stamps);
	free(e->key);
	free(e);
}

/* With mu held. */
static struct entry **slot_of(const char *key)
{
	for (size_t i = 0; i < API_MODEL_PATHS_MAX; i++)
		if (table[i] && !strcmp(table[i]->key, key)) return &table[i];
	return NULL;
}

/* With mu held: every file still has the stamp it had when the model was imported. */
static bool unchanged(const char *root, const struct entry *e)
{
	for (size_t i = 0; i < e->nfiles; i++) {
		struct api_asset_stamp now;
		int status;
		char err[300];
		if (api_asset_stat(root, e->paths[i], &now, &status, err, sizeof err) != API_OK ||
		    !api_asset_stamp_equal(&now, &e->stamps[i]))
			return false;
	}
	return true;
}

struct api_model *api_model_paths_find(const struct api_model_path_key *k, const struct api_limits *lim,
                                       uint64_t *files_hash)
{
	char *key = key_of(k);
	if (!key) return NULL;
	struct api_model *m = NULL;
	pthread_mutex_lock(&mu);
	struct entry **slot = slot_of(key);
	if (slot && unchanged(k->root, *slot) && (m = api_model_cache_take((*slot)->serial))) {
		(*slot)->used = ++tick;
		*files_hash = (*slot)->files_hash;
		hits++;
	} else if (slot) { /* stale: a file changed or the model left the cache */
		entry_free(*slot);
		*slot = NULL;
	}
	pthread_mutex_unlock(&mu);
	free(key);
	/* A hit like the cache's: this size's level, built outside the lock (it may take a while). */
	if (m) api_levels_on_hit(m, lim);
	return m;
}

static struct entry *entry_new(const struct api_model_path_key *k, const struct api_asset_stamp *stamp,
                               const struct api_asset_origin *refs, size_t nrefs)
{
	struct entry *e = calloc(1, sizeof *e);
	if (!e) return NULL;
	e->key = key_of(k);
	e->paths = calloc(nrefs + 1, sizeof *e->paths);
	e->stamps = calloc(nrefs + 1, sizeof *e->stamps);
	if (!e->key || !e->paths || !e->stamps) goto fail;
	for (size_t i = 0; i <= nrefs; i++) {
		if (!(e->paths[i] = strdup(i ? refs[i - 1].path : k->path))) goto fail;
		e->stamps[i] = i ? refs[i - 1].stamp : *stamp;
		e->nfiles = i + 1;
	}
	return e;
fail:
	entry_free(e);
	return NULL;
}

void api_model_paths_remember(const struct api_model_path_key *k, const struct api_asset_stamp *stamp,
                              const struct api_asset_origin *refs, size_t nrefs, const struct api_model *m,
                              uint64_t files_hash)
{
	if (nrefs + 1 > API_MODEL_PATHS_MAX_FILES || !api_asset_stamp_settled(stamp)) return;
	for (size_t i = 0; i < nrefs; i++)
		if (!api_asset_stamp_settled(&refs[i].stamp)) return;
	struct entry *e = entry_new(k, stamp, refs, nrefs);
	if (!e) return;
	e->serial = api_model_serial(m);
	e->files_hash = files_hash;
	struct entry *old = NULL;
	pthread_mutex_lock(&mu);
	e->used = ++tick;
	struct entry **slot = slot_of(e->key);
	for (size_t i = 0; !slot && i < API_MODEL_PATHS_MAX; i++)
		if (!table[i]) slot = &table[i];
	if (!slot) { /* full: the least recently used */
		slot = &table[0];
		for (size_t i = 1; i < API_MODEL_PATHS_MAX; i++)
			if (table[i]->used < (*slot)->used) slot = &table[i];
	}
	old = *slot;
	*slot = e;
	pthread_mutex_unlock(&mu);
	entry_free(old);
}

uint64_t api_model_paths_hits(void)
{
	pthread_mutex_lock(&mu);
	uint64_t h = hits;
	pthread_mutex_unlock(&mu);
	return h;
}

void api_model_paths_clear(void)
{
	pthread_mutex_lock(&mu);
	for (size_t i = 0; i < API_MODEL_PATHS_MAX; i++) {
		entry_free(table[i]);
		table[i] = NULL;
	}
	pthread_mutex_unlock(&mu);
}
