/*
 * api/asset — files under the asset root (`--asset-root`): a model's `path` and the files that
 * model refers to (a .gltf's buffers and images, an .obj's .mtl and textures).
 *
 * Rules, the same for a `path` and for every reference inside a file:
 *   - a `path` is relative: not empty, no leading "/", no "\\", no ":" (no drive or scheme),
 *     no ".." segment at all (api_asset_check_path);
 *   - a reference found inside a file is joined onto that file's directory (api_asset_resolve):
 *     "." and ".." segments are resolved by name, and one that climbs above the root is refused;
 *     "\\" is read as "/" (Windows exporters write it into .mtl files);
 *   - the file is opened with openat2(RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS) relative to the
 *     root's descriptor: the kernel refuses any resolution, symbolic links included, that leaves
 *     the root, with no window between checking a path and opening it. Kernels without openat2
 *     (before 5.6, or a filter that refuses it) get the older realpath() comparison;
 *   - only regular files are read: a FIFO or a device is opened non-blocking and refused at once;
 *   - a file is at most API_ASSET_MAX_FILE bytes and not empty.
 *
 * Usage:
 *   char err[300]; int status; uint8_t *b; size_t n;
 *   if (api_asset_check_path(path, err, sizeof err) != API_OK) -> 400 with err
 *   if (api_asset_read(root, path, &b, &n, &status, err, sizeof err) != API_OK) -> status with err
 *   ... free(b);
 *
 * Ownership: api_asset_read() hands you a malloc'd buffer. Threading: no shared state; every
 * function is safe from several threads. Messages name the path but never a member: the caller
 * adds the JSON Pointer.
 */
#ifndef UMBRA_API_ASSET_H
#define UMBRA_API_ASSET_H

#include <stddef.h>
#include <stdint.h>
#include "api.h"

#define API_ASSET_MAX_FILE (1ull << 30)

/* API_OK when `path` may be used as a model's `path` (see the rules above); else a sentence. */
enum api_result api_asset_check_path(const char *path, char *err, size_t errsize);

/* Joins `ref` (a relative reference found inside the file at `base`, itself a path under the
 * root) onto base's directory into out: "textures/../a.png" inside "models/x.gltf" is
 * "models/a.png". Fails (a sentence) for an absolute reference, one with a scheme or drive
 * ("http:", "C:"), an empty one, or one whose ".." climbs above the root. */
enum api_result api_asset_resolve(const char *base, const char *ref, char *out, size_t outsize, char *err,
                                  size_t errsize);

/* Reads root/path (path already checked or resolved) into a malloc'd buffer. API_ERR with
 * *status 400 (missing, leaves the root, not a regular file, empty or over API_ASSET_MAX_FILE,
 * unreadable) or 500 (the root itself cannot be opened), and a sentence in err. */
enum api_result api_asset_read(const char *root, const char *path, uint8_t **out, size_t *len, int *status,
                               char *err, size_t errsize);

/* Folds a file's name and bytes into *h (FNV-1a; *h == 0 starts it): the scene's asset hash, so
 * an answer that depends on files changes its ETag when they do. */
void api_asset_hash(uint64_t *h, const char *name, const uint8_t *data, size_t len);

#endif
