/*
 * api/model_paths — models by `path` remembered by their files' stamps, so that a request
 * naming a model the daemon has already imported finds it without reading the files again.
 *
 * The model cache (api/model.h) is keyed by the bytes: a 50 MB model by path was read, hashed
 * and compared on every request (~100 ms of a 1M-triangle thumbnail's ~150 ms). This remembers,
 * per (asset root, path, format asked for), the stamps (api/asset.h) of the
 * model file and of every file it referred to when it was imported, the serial of the cached
 * model and the hash the files' bytes added to the scene's asset hash (the ETag). A later
 * request stats the same files; when every stamp is equal it takes the cached model by its
 * serial and adds the same hash. Any change to any of the files (write, replace, touch, chmod),
 * a file gone, or the model evicted from the cache: a miss, and the caller reads as before.
 * Files changed less than API_ASSET_SETTLE_NS (1 s; 3 s on a file system with whole-second
 * times) before they were read are not trusted by their stamps (a second change within the
 * file system's clock tick keeps the times): such a model
 * is imported and used, but remembered only by a later request. Models whose import left something out (an .obj's missing .mtl: a warning) are not
 * remembered, as the missing file may appear.
 *
 * Usage (api/scene_parse.c):
 *   struct api_model_path_key k = {root, path, format_or_minus_1};
 *   struct api_model *m = api_model_paths_find(&k, lim, &hash);   // NULL: read and import, then
 *   api_model_paths_remember(&k, &stamp, refs.origins, refs.norigins, m, hash);
 *
 * Bounds: API_MODEL_PATHS_MAX entries, least recently used replaced; models of more than
 * API_MODEL_PATHS_MAX_FILES files are not remembered. Holds no model reference (the cache owns
 * the models). Threading: one mutex; the stat calls of a lookup run under it (microseconds).
 */
#ifndef UMBRA_API_MODEL_PATHS_H
#define UMBRA_API_MODEL_PATHS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "asset.h"
#include "model.h"

#define API_MODEL_PATHS_MAX 256u
#define API_MODEL_PATHS_MAX_FILES 64u

struct api_model_path_key {
	const char *root;
	const char *path;
	int format;            /* the request's `format` (enum api_model_format), -1 when not given */
};

/* A reference to the model remembered for k whose files are unchanged, and the hash its files
 * add to the scene's asset hash; NULL when there is none. A hit is a cache hit: lim's import
 * limits bound the build of its levels (api/model_levels.h). */
struct api_model *api_model_paths_find(const struct api_model_path_key *k, const struct api_limits *lim,
                                       uint64_t *files_hash);
/* Remembers m (imported from the model file stamped `stamp` and the files of `refs`). Failing
 * to remember (out of memory, too many files) only costs the next request a read. */
void api_model_paths_remember(const struct api_model_path_key *k, const struct api_asset_stamp *stamp,
                              const struct api_asset_origin *refs, size_t nrefs, const struct api_model *m,
                              uint64_t files_hash);
/* Lookups answered without reading (for tests and metrics), and forgetting everything. */
uint64_t api_model_paths_hits(void);
void api_model_paths_clear(void);

#endif
