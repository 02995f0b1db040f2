/*
 * api/model — imported 3D models (contract shape "model"): glb, gltf (self-contained or with
 * its buffer and image files), obj (with its .mtl and textures), stl, ply through the Assimp C
 * API, glTF 2.0 materials (every texture slot, decoded through api/image_decode.c; see
 * api/gltf_material.h), and a bounded LRU cache of imported models keyed by their bytes (and
 * those of the files they refer to).
 *
 * Isolation: model files are untrusted, and Assimp has crashed and looped on small malformed
 * ones. api_model_get() therefore never parses in the calling process: Assimp (and the decoding
 * of embedded textures) runs in a child of the `umbra-import` fork server (api/sandbox.h), under
 * a CPU-time limit, a memory limit (RLIMIT_AS), a wall-clock timeout and a seccomp filter that
 * allows no file access; the child sends back a compact serialized model (api/model_wire.h)
 * that this process validates like any request input. A crash there is a 400, running over the
 * time or memory limit a 422, and this process and every other request carry on. What it costs
 * per model is in `make bench` ("import" lines).
 *
 * Usage (api/scene_parse.c does this for every model object):
 *   struct api_model *m; char err[400]; int status;
 *   if (api_model_get(bytes, len, API_MODEL_SNIFF, &limits, &m, &status, err, sizeof err) != API_OK)
 *           answer `status` (400/422/500) with err at the member that carried the bytes;
 *   ...m->instances[i] -> one rnd_object each, m->materials[...] appended to the scene...
 *   api_model_release(m);          // when the scene that uses it is freed
 *
 * Ownership: api_model_get() hands you one reference; release it with api_model_release()
 * (NULL-safe). A model is immutable once returned: every array (geometry, materials, textures)
 * lives as long as the model, so an rnd_scene may point straight into it while it holds the
 * reference, even after the cache has evicted the entry.
 *
 * Threading: every function is safe to call from several threads. The cache is guarded by one
 * mutex that is never held across an import; imports run in parallel, one child process each.
 */
#ifndef UMBRA_API_MODEL_H
#define UMBRA_API_MODEL_H

#include <stdbool.h>
#include <stddef.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include "api.h"

enum api_model_format {
	API_MODEL_SNIFF = -1,     /* tell from the bytes */
	API_MODEL_GLB = 0, API_MODEL_GLTF, API_MODEL_OBJ, API_MODEL_STL, API_MODEL_PLY,
};

#define API_MODEL_MAX_WARNINGS 1000u
/* Texels a texture keeps per pixel of the request's image-size class (api_texture_class): it
 * is halved while it stays at least this many times as large (a 2048^2 JPEG for a 256^2
 * thumbnail: 512^2). An atlas whose visible part is half of it still has a texel per pixel. */
#define API_TEXTURE_SIDE_PER_PIXEL 2u

/* One geometry array set (an Assimp mesh, triangles only). */
struct api_model_mesh {
	const float *positions;   /* xyz per vertex */
	const float *normals;     /* xyz per vertex, always present (generated when the file has none) */
	const float *uvs;         /* uv per vertex (glTF convention: v = 0 at the image's top row), or NULL */
	const float *uvs1;        /* the second uv set (glTF TEXCOORD_1), the same convention, or NULL
	                             (its levels carry it too) */
	const uint8_t *colors;    /* linear RGBA8 per vertex (glTF COLOR_0), or NULL */
	const float *tangents;    /* xyzw per vertex (w = bitangent sign), or NULL (kept only when the
	                             mesh's material has a normal map) */
	const uint32_t *indices;  /* index_count, a multiple of 3, every index < vertex_count */
	uint32_t vertex_count, index_count;
	uint32_t material;        /* index into api_model.materials */
	bool single_sided;        /* its material says doubleSided: false (back faces culled) */
	/* The simplified level for images of the model's level_side (api/model_lod.h), or none;
	 * other sizes' levels: api_model_mesh_lods(). */
	const struct rnd_mesh_lod *lods;
	uint32_t lod_count;
	/* The environment's shadow maps' coarse level (api/model_caster.h), or NULL: side-independent,
	 * built once at import. */
	const struct rnd_caster_level *caster;
	bool closed;              /* watertight and wound outward (api/model_lod.h, set by the importer) */
	float bounds[6];          /* min xyz, max xyz of positions (api_mesh_bounds) */
	/* private, in the importer only (never on the wire): the weld its join sorted the vertices
	 * by (api/weld.h: group of each vertex, and how many), for the closedness check and the
	 * level to use instead of sorting again; NULL: none made. */
	const uint32_t *weld_group_;
	uint32_t weld_groups_;
};

/* A node's use of a mesh: one rnd_object. */
struct api_model_instance {
	uint32_t mesh;
	float model[16];          /* node -> model root, column-major (all parent nodes applied) */
};

struct api_model {
	const struct api_model_mesh *meshes;       uint32_t mesh_count;
	const struct api_model_instance *instances; uint32_t instance_count;
	const struct rnd_material *materials;      uint32_t material_count; /* textures point into the model */
	uint64_t triangles;       /* over all instances */
	/* What of the file's materials (and scene) is not drawn as the file says, as sentences
	 * joined by "; " (printable ASCII, at most API_MODEL_MAX_WARNINGS bytes), or NULL. */
	const char *warnings;
	enum api_model_format format;
	/* Its textures were decoded for images of the class texture_side (api_texture_class of the
	 * importing request's output_side; 0 = as stored); the largest of them is texture_max
	 * texels on its larger side as stored (0: no texture). */
	uint32_t texture_side, texture_max;
	uint32_t level_side;      /* the meshes' own lods are for images of this side (0: none built) */
	struct api_import_times times;   /* the import's stages (imports = 1), or zero */
	/* private */
	size_t bytes_;            /* what the cache charges for it (cache_mu, api/model.c) */
	void *priv_;
	/* api/model_levels.c: other sizes' levels, a list that only grows; its builders' lock */
	_Atomic(struct api_size_levels *) levels_;
	pthread_mutex_t levels_mu_;
};

/* The levels of one mesh (arena memory). */
struct api_mesh_levels {
	const struct rnd_mesh_lod *lods;
	uint32_t count;
};

/* The levels (*count of them, 0 or 1) of mesh `mesh` of m for images of `side`
 * (api_limits.output_side): the import's for its own side, else those built when the cached
 * model was first drawn at that side (api/model_levels.h); none for side 0. */
const struct rnd_mesh_lod *api_model_mesh_lods(const struct api_model *m, uint32_t mesh, uint32_t side,
                                               uint32_t *count);

/* Imports (or finds in the cache) the model in data[0..len). format API_MODEL_SNIFF tells it
 * from the bytes. The cache is bounded by api_model_cache_set_limit() (api.h). From lim (NULL =
 * api_limits_defaults): import_timeout_ms and import_memory bound the importer. Returns API_OK with *out (one reference), or API_ERR with *status 400 (bad
 * file: refused, crashed the importer), 422 (over the import time or memory limit) or 500 (the
 * importer could not run) and a sentence in err (Assimp's message or what was wrong with the
 * bytes; never mentions the caller's member names). */
enum api_result api_model_get(const uint8_t *data, size_t len, enum api_model_format format,
                              const struct api_limits *lim, struct api_model **out, int *status, char *err,
                              size_t errsize);
void api_model_release(struct api_model *m);

/* Every import gets a serial number no other import shares. api_model_cache_take() gives a
 * reference to the cached model of that serial (a cache hit), or NULL when it is no longer
 * cached (evicted, cleared, or too large to cache): api/model_paths.h finds a model by path
 * this way without the bytes that key the cache. */
uint64_t api_model_serial(const struct api_model *m);
struct api_model *api_model_cache_take(uint64_t serial);

/* A file the model refers to (a .gltf's buffer or image, an .obj's .mtl or texture), named as
 * the referring file writes it; found by api/model_refs.h. */
struct api_model_file {
	const char *name;
	const uint8_t *data;
	size_t len;
};
/* api_model_get() with the files the model refers to: the importer serves them, and only
 * them, when it asks for those names. The cache key covers every file's name and bytes. */
enum api_result api_model_get_files(const uint8_t *data, size_t len, const struct api_model_file *files,
                                    size_t nfiles, enum api_model_format format, const struct api_limits *lim,
                                    struct api_model **out, int *status, char *err, size_t errsize);

/* CLOCK_MONOTONIC in milliseconds: what the import's stages are measured with. */
double api_clock_ms(void);

/* api_model_get_files() that also adds the import's stage times to *times (times->imports + 1),
 * or counts a cache hit (times->hits + 1); times may be NULL. */
enum api_result api_model_get_timed(const uint8_t *data, size_t len, const struct api_model_file *files,
                                    size_t nfiles, enum api_model_format format, const struct api_limits *lim,
                                    struct api_model **out, struct api_import_times *times, int *status, char *err,
                                    size_t errsize);

/* Tells the format from the bytes; API_MODEL_SNIFF when it cannot. */
enum api_model_format api_model_sniff(const uint8_t *data, size_t len);
/* The format to read data as when `stated` was given (a `format` member, a file's extension):
 * the bytes' own where they say it unambiguously (glb and ply magic, a binary STL's size, an
 * ASCII STL's "solid", glTF JSON), else `stated` (an OBJ is never overridden). When the two
 * differ, warning (may be NULL) gets a sentence naming both, else "". SNIFF stays SNIFF. */
enum api_model_format api_model_settle_format(const uint8_t *data, size_t len, enum api_model_format stated,
                                              char *warning, size_t size);
const char *api_model_format_name(enum api_model_format f);

/* ---- image decoding (api/image_decode.c) ---- */

/* Decodes a PNG or JPEG in the calling process (the sandboxed importer calls this; request
 * input goes through api_sandbox_decode_image() in api/sandbox.h) into malloc'd RGBA8 (rows top to bottom, colour as stored, i.e. sRGB).
 * At most max_pixels pixels (0 = 64 Mi). Returns API_OK with *rgba (you free it), or API_ERR
 * with a sentence in err. */
enum api_result api_image_decode(const uint8_t *data, size_t len, uint64_t max_pixels, uint8_t **rgba,
                                 uint32_t *width, uint32_t *height, char *err, size_t errsize);
/* The same, no larger than it must be for a larger side of at least min_side (0 = as stored):
 * halved while it stays that large, a JPEG by libjpeg's scaled decode (the IDCT at 1/2, 1/4,
 * 1/8: it costs what decoding the smaller image costs), a PNG after the
 * decode into the level the renderer's mip chain has there (rnd_texture_reduce: in linear light
 * for an srgb slot, the same bytes), halved k times where 2^k <= larger side / min_side; a JPEG's
 * scaled IDCT filters in the stored colour space. *stored_side (may be NULL): the larger side
 * as stored. */
enum api_result api_image_decode_fit(const uint8_t *data, size_t len, uint64_t max_pixels, uint32_t min_side,
                                     bool srgb, uint8_t **rgba, uint32_t *width, uint32_t *height,
                                     uint32_t *stored_side, char *err, size_t errsize);
/* The size a PNG (IHDR) or JPEG (its first SOFn marker) says it has, read from the header
 * alone (no library: the daemon calls it on request bytes before a decode). false when the
 * bytes say nothing usable. */
bool api_image_header_size(const uint8_t *data, size_t len, uint32_t *width, uint32_t *height);
/* The class of image sizes textures are decoded for: side rounded up to a power of two (0 for
 * 0: as stored). A texture of larger side L is halved while L / 2 >= API_TEXTURE_SIDE_PER_PIXEL
 * times the class, so requests of one class decode every texture alike. */
uint32_t api_texture_class(uint32_t side);

#endif
