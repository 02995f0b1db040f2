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

#include <stdbool.h>
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

/* What tells one version of a file from another without reading it: device, inode, size and
 * the modification and status-change times in nanoseconds, as make and rsync trust them. A
 * write, a rename over the file, a chmod or a touch changes one of them (the status-change
 * time cannot be set back from user space). */
struct api_asset_stamp {
	uint64_t dev, ino, size;
	int64_t mtime_ns, ctime_ns;
	int64_t seen_ns;       /* the clock just before the stamp was taken (not compared) */
};
/* File times come from a coarse clock: the kernel's tick (up to 10 ms) on ext4 or tmpfs, whole
 * seconds on ext3, HFS+, FAT, sshfs and exports of those (2 s on FAT), and a network file
 * system's times come from the server's clock. A file changed again within its clock's tick
 * keeps its times, so a stamp taken less than this long after the file's last change is
 * "racy" (git's word) and must not stand for the file's bytes: 1 s (covers a server's clock
 * up to ~1 s behind), 3 s when both times are whole seconds (a coarse file system). */
#define API_ASSET_SETTLE_NS 1000000000ll
#define API_ASSET_SETTLE_COARSE_NS 3000000000ll
/* A file read under the root: its path there and its stamp when it was read. */
struct api_asset_origin {
	char *path;
	struct api_asset_stamp stamp;
};

/* api_asset_read() that also gives the stamp of what it read (taken from the descriptor it
 * read, so it names that file, not whatever is at the path a moment later). */
enum api_result api_asset_read_stamped(const char *root, const char *path, uint8_t **out, size_t *len,
                                       struct api_asset_stamp *stamp, int *status, char *err, size_t errsize);
/* The stamp of root/path now, with the rules of api_asset_read() (API_ERR: as it would fail). */
enum api_result api_asset_stat(const char *root, const char *path, struct api_asset_stamp *out, int *status,
                               char *err, size_t errsize);
bool api_asset_stamp_equal(const struct api_asset_stamp *a, const struct api_asset_stamp *b);
/* The file had not changed for API_ASSET_SETTLE_NS when the stamp was taken: any later change
 * will change the stamp. */
bool api_asset_stamp_settled(const struct api_asset_stamp *s);

/* Folds a file's name and bytes into *h (*h == 0 starts it; the bytes a word at a time:
 * rnd_hash, as a 50 MB model is hashed on each read): the scene's asset hash, so
 * an answer that depends on files changes its ETag when they do. */
void api_asset_hash(uint64_t *h, const char *name, const uint8_t *data, size_t len);

#endif
