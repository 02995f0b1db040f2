/*
 * api/model_refs — the files a model refers to, found and read in the daemon (the sandboxed
 * importer can open nothing): a .gltf's (or .glb's) buffers[].uri and images[].uri, an .obj's
 * `mtllib` files and the map_* / bump / disp / norm textures those name. data: URIs are left
 * to the importer.
 *
 * Where they come from:
 *   - a model by `path`: under the asset root, relative to the referring file's directory, with
 *     the rules of api/asset.h (a ".." above the root, an absolute reference, a link out: 400);
 *   - a model in a multipart request (`part`, or `data` when the request has parts): the parts
 *     named by the reference ("Avocado.bin", "textures/wood.png"); a "../" reference is a 400;
 *   - inline `data` without parts: nothing can be found; a glTF that needs a file is a 400.
 * An .obj's .mtl or texture missing from the request (inline data, or parts without it: the
 * farm sends the model alone) or that cannot be read beside a model by `path` is left out and
 * said in `warning` (Assimp draws an .obj without them): the same answer, 200 with a warning,
 * whichever way the model came. A reference that escapes the root is still a 400.
 * A reference that cannot be found or read is a 400 whose sentence names it; more than
 * API_MODEL_REFS_MAX files or API_ASSET_MAX_FILE bytes with the model is a 422.
 *
 * Usage:
 *   struct api_model_refs r; int status; char err[400];
 *   struct api_ref_source src = {.root = root, .path = "models/Avocado.gltf"};
 *   if (api_model_refs_collect(bytes, len, API_MODEL_GLTF, &src, &r, &status, err, sizeof err) != API_OK)
 *           answer status with err at the model's pointer;
 *   api_model_get_files(bytes, len, r.files, r.count, ...);   // model.h
 *   api_model_refs_release(&r);
 *
 * Ownership: r's files (names and bytes) live until api_model_refs_release() (also safe after
 * a failure); bytes taken from parts point into the parts. Threading: no shared state.
 */
#ifndef UMBRA_API_MODEL_REFS_H
#define UMBRA_API_MODEL_REFS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "api.h"
#include "asset.h"
#include "model.h"

#define API_MODEL_REFS_MAX 256u

struct api_ref_source {
	const char *root;                 /* the asset root ... */
	const char *path;                 /* ... and the model's path under it (NULL: not by path) */
	const struct api_part *parts;     /* the request's parts (multipart), or NULL */
	size_t nparts;
};

struct api_model_refs {
	struct api_model_file *files;
	size_t count;
	uint64_t bytes;                   /* of every file, counted once whatever its names */
	uint64_t asset_hash;              /* files read under the root (api_asset_hash), 0 = none */
	char warning[512];                /* "" or what was left out (an .obj's missing .mtl, "; " between) */
	/* By path: every file read under the root, with its stamp (api/model_paths.h) */
	struct api_asset_origin *origins;
	size_t norigins;
	/* private */
	size_t cap_;
	unsigned char *owned_;            /* per file: 1 when its bytes are ours to free */
};

enum api_result api_model_refs_collect(const uint8_t *data, size_t len, enum api_model_format format,
                                       const struct api_ref_source *src, struct api_model_refs *out, int *status,
                                       char *err, size_t errsize);
void api_model_refs_release(struct api_model_refs *r);

#endif
