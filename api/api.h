/*
 * umbra api — scene documents (JSON, contract v1) to renderer scenes, problems (RFC 9457),
 * and image encoders (PNG via libpng, EXR via OpenEXR's C core, WebP via libwebp).
 *
 * Usage:
 *   struct api_limits lim; api_limits_defaults(&lim);
 *   struct api_scene *s; struct api_problem p;
 *   if (api_scene_parse(body, len, &lim, &s, &p) != API_OK) { send p.status + api_problem_json(&p) }
 *   rnd_render(ctx, &s->scene, &img, ...);
 *   api_encode(s, &img, &bytes, &n, &p);  free(bytes);
 *   api_scene_free(s);
 *
 * Ownership: a parsed api_scene owns every array its rnd_scene points to (one arena) and
 * must be freed with api_scene_free() (NULL-safe). Encoders return malloc'd bytes the caller
 * frees. Threading: every function is safe to call from several threads. The one process-wide
 * state is the cache of imported models (api/model.h), behind its own mutex.
 * jansson is used only inside api/; this header does not expose it.
 */
#ifndef UMBRA_API_H
#define UMBRA_API_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "umbra/rnd.h"

enum api_result { API_OK = 0, API_ERR };

/* RFC 9457 problem details. status is the HTTP status (400, 413, 422, 500...). */
struct api_problem {
	int status;
	char type[96];      /* URI, e.g. "https://umbra.dev/problems/invalid-scene" */
	char title[96];     /* short, per type, e.g. "Invalid scene" */
	char detail[512];   /* human sentence saying what is wrong with which member */
	char pointer[256];  /* RFC 6901 JSON Pointer of the offending member ("" = whole document) */
};

/* Fills p (status, type from status, title) with a printf-style detail. Returns API_ERR. */
enum api_result api_problem_set(struct api_problem *p, int status, const char *pointer, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* Writes the problem as an application/problem+json document (NUL-terminated, malloc'd). */
char *api_problem_json(const struct api_problem *p);
/* One line for CLI stderr: "400 Invalid scene: /lights/0/direction: must not be zero". */
void api_problem_format(const struct api_problem *p, char *buf, size_t size);

/* Who may start a sandboxed model import now (the daemon's import slots, server/imports.c):
 * try_enter(user) before each import of a model the cache lacks (levels of a cached model and
 * texture decodes are not gated: each is bounded by the import limits and happens once per
 * model and size). false: the parse stops with a 503 problem at the model's member, having
 * started nothing; the caller, who knows why, parses the request again later. */
struct api_import_gate {
	bool (*try_enter)(void *user);
	void *user;
};

/* The caller's admission of memory a parse is about to take (the daemon's --max-memory,
 * server/admit.h): reserve(user, bytes, p) before a texture is decoded (its header's pixels:
 * the decode's reply and the copy the scene keeps). false: the parse stops with the problem
 * the callback wrote (422 over the budget alone, 504 past the deadline while waiting). */
struct api_memory_gate {
	bool (*reserve)(void *user, uint64_t bytes, struct api_problem *p);
	void *user;
};

/* Resource limits; going over one is a 422. 0 = unlimited. */
struct api_limits {
	uint64_t max_pixels;             /* width*height (and per sheet when several views), default 16777216 */
	uint64_t max_triangles;          /* after tessellation, default 20000000 */
	uint32_t max_lights;             /* default 64 */
	uint32_t max_shadow_resolution;  /* default 8192 */
	/* Directory that model `path`s are relative to (NULL = none: a `path` is a 400). A path never
	 * leaves it: no absolute paths, no ".." components, no symlinks that resolve outside. */
	const char *asset_root;          /* default NULL */
	/* Bounds of one sandboxed model import or texture decode (api/sandbox.h): wall clock (the CPU
	 * time limit is the same, rounded up to seconds) and address space of the importer process.
	 * Over either is a 422 at the member that carried the bytes. */
	uint32_t import_timeout_ms;      /* default 10000; 0 = the default */
	uint64_t import_memory;          /* bytes, default 2147483648 (2 GiB); 0 = no memory limit */
	/* Not a limit: the two above are the caller's --import-timeout-ms and --import-memory
	 * (umbrad), and their 422s say so; false: the caller has no option for them (umbra-render),
	 * and the 422s say that. */
	bool import_flags;               /* default false */
	/* Distinct textures in one scene (the renderer's rnd_info.max_textures: its desc's value
	 * capped by the device); over it is a 422 at the object that brought one too many. */
	uint32_t max_textures;           /* default RND_DEFAULT_MAX_TEXTURES (256); 0 = the default */
	/* Not a server limit: what one request can show, set by the scene parser on its own copy
	 * (the largest side of its images, pixels). A model imported for it does no work beyond
	 * that: one level of detail for that size (api/model_lod.h). 0 = unknown (none). */
	uint32_t output_side;
	/* Not a limit either: the caller's gate for imports (NULL = none: every import starts). */
	const struct api_import_gate *import_gate;
	const struct api_memory_gate *memory_gate;   /* NULL = none */
};
void api_limits_defaults(struct api_limits *l);

enum api_format { API_FORMAT_PNG, API_FORMAT_EXR, API_FORMAT_WEBP, API_FORMAT_AVIF, API_FORMAT_COUNT };
/* WebP's own bound on each side of an image (its 14-bit dimensions). */
#define API_WEBP_MAX_SIDE 16383u
/* AVIF's: what libavif's decoders take by default (16384 x 16384 pixels), browsers included. */
#define API_AVIF_MAX_SIDE 16384u

/* Where the time of a request's model imports went, ms (Server-Timing's model-* stages; the
 * importer measures its own in the sandbox, api/model.c the daemon's). */
enum api_import_stage {
	API_IMPORT_READ,       /* the model's bytes: base64, the file by path, the multipart part */
	API_IMPORT_PARSE,      /* the importer's parse and conversion (Assimp, or api/stl_import.c) */
	API_IMPORT_TEXTURES,   /* its texture decoding */
	API_IMPORT_CLOSED,     /* its closedness check (welding included) */
	API_IMPORT_LEVEL,      /* its one level of detail for the request (api/model_lod.h) */
	API_IMPORT_TRANSFER,   /* the sandbox round trip less the importer's work: fork, socket copies */
	API_IMPORT_VALIDATE,   /* the daemon's check and copy of the reply (api/model_wire.h) */
	API_IMPORT_CACHE,      /* what the cache keeps of a model it lists: its textures' mip chains and
	                          a copy of its bytes (what confirms a hit) */
	API_IMPORT_STAGES
};
struct api_import_times {
	float ms[API_IMPORT_STAGES];
	uint32_t imports;      /* models imported for the request */
	uint32_t hits;         /* models found in the cache */
};
extern const char *const API_IMPORT_STAGE_NAMES[API_IMPORT_STAGES];   /* "model-read", ... */

struct api_scene {
	struct rnd_scene scene;     /* ready for rnd_render() */
	enum api_format format;
	int format_explicit;        /* output.format was given (else the Accept header may choose) */
	uint32_t bit_depth;         /* 8 or 16 (png) */
	int png_level;              /* zlib level for PNG, -1 = chosen by image size */
	float quality;              /* output.quality: lossy WebP 0..100; -1 = not given (lossless WebP) */
	uint64_t triangles;         /* total after tessellation */
	uint64_t asset_hash;        /* hash of files read under the asset root (`path` models), 0 = none:
	                               the answer depends on them, so caches and ETags must too */
	uint64_t scene_hash;        /* canonical hash of the document after its preset, and of the
	                               parts (api/scene_hash.h): key order, whitespace, escapes and
	                               number spellings do not change it */
	/* What the image leaves out of what the scene asked for ("" = nothing), as sentences joined
	 * by "; " that start with the member's JSON Pointer: an .obj sent inline whose .mtl is not in
	 * the request, material data of a model that is not drawn as its file says. The server sends
	 * it as the Umbra-Warnings header, the CLI on stderr. */
	char warnings[1024];
	struct api_import_times import;   /* the request's model imports, summed (zero without models) */
	/* private: the arena that owns the arrays, and the imported models the scene points into */
	void *arena_;
	void *models_;
	void *env_map_;                 /* the environment map the scene points into (api/env_map.h) */
	const uint32_t *object_source_; /* document object index of each scene.objects[i] (NULL: i) */
	const char *views_key_;         /* "views" / "turntable" / NULL */
	unsigned png_only_;             /* output members given that only a PNG answer uses (scene_views.c) */
};

/* Parses and validates a scene document. On failure fills p (400: malformed / wrong type /
 * out of range / unknown member, with the member's JSON Pointer; 422: over a limit).
 *
 * Several views: root `views` (cameras; each starts from the root `camera` when there is one)
 * or `turntable` ({frames 1..1024, elevation -90..90 degrees (20), distance > 0}) fill
 * scene.views / view_count, and `camera` may then be absent. Turntable frame k looks at the
 * centre of the objects' bounds (every object but planes and shadow catchers; all objects when
 * only those exist) from azimuth 360°·k/N (frame 0 on +Z, frame N/4 on +X) at the elevation:
 * view direction -(cos el·sin az, sin el, cos el·cos az), up +Y, fov_y of a perspective root
 * camera (else 45°), the root camera's exposure, near/far derived; from `distance`, or else
 * where the bounding sphere fills the frame with a 0.1 margin (a sphere, so that every frame is
 * at the same distance). A camera's `fit` ("scene" or "objects") is left to the renderer, which
 * frames the bounds tightly (rnd_object_frames() says what counts for "objects"). The sheet
 * (rnd_sheet_layout(), unused cells included) counts against max_pixels: 422 at /views or
 * /turntable. Material `base_color_texture` is decoded here (PNG/JPEG, 400 at the member when it
 * cannot be); more than limits.max_textures distinct textures (422 at the object that brought
 * one too many), or one over RND_MAX_TEXTURE_SIDE texels a side, is a 422. */
enum api_result api_scene_parse(const char *json, size_t len, const struct api_limits *limits,
                                struct api_scene **out, struct api_problem *p);
void api_scene_free(struct api_scene *s);

/* A named binary part of the request (multipart/form-data), referenced by a model's `part`.
 * The bytes are only read during the parse (imported models are copied or cached). */
struct api_part {
	const char *name;
	const uint8_t *data;
	size_t len;
};
/* api_scene_parse() with the request's binary parts; a `part` that names none of them is a 400.
 * api_scene_parse() is this with no parts. */
enum api_result api_scene_parse_parts(const char *json, size_t len, const struct api_limits *limits,
                                      const struct api_part *parts, size_t nparts,
                                      struct api_scene **out, struct api_problem *p);

/* Imported models are cached process-wide (LRU, keyed by the file's bytes), so its bound is
 * process-wide too: set it once at start-up (umbrad --model-cache); bytes 0 = do not cache;
 * default 268435456 (256 MiB). Lowering it evicts at once (models still used by a scene live
 * until that scene is freed). Thread-safe. */
void api_model_cache_set_limit(uint64_t bytes);
/* Counters since start; any pointer may be NULL. Thread-safe. */
void api_model_cache_stats(uint64_t *hits, uint64_t *misses, uint64_t *bytes);
/* Drops every cached model (models still used by a scene live until that scene is freed).
 * For tests and shutdown: after it and after every scene is freed, nothing is left allocated. */
void api_model_cache_clear(void);
/* Switches the output to the given format as if output.format had said so (Accept header,
 * CLI -o extension): adjusts scene.output.pixels. Fails (400) for PNG with AOVs. */
enum api_result api_scene_set_format(struct api_scene *s, enum api_format f, struct api_problem *p);

/* After the format is settled (output.format, then the Accept header or the CLI's output name
 * through api_scene_set_format): 400 at /output/aovs when AOVs were asked for and the answer is
 * still the default PNG. Call it before rendering; api_encode() refuses such a scene too. */
enum api_result api_scene_check_output(const struct api_scene *s, struct api_problem *p);

/* The problem for a render of s that failed with e: status (422 for RND_ERR_LIMIT, ...) and the
 * JSON Pointer of the member e->at names (/width, /output/aovs, /lights/3, the document object
 * a model's mesh came from, ...), detail = e->msg. Returns API_ERR. */
enum api_result api_problem_from_render(struct api_problem *p, const struct api_scene *s, const struct rnd_error *e,
                                        int status);

/* Encodes a rendered image as the scene asks (PNG 8/16-bit, EXR with AOVs, WebP or AVIF). Several
 * views: the PNG, WebP and AVIF are the sheet as rendered; the EXR is multi-part (api_exr_encode). */
enum api_result api_encode(const struct api_scene *s, const struct rnd_image *img, uint8_t **out, size_t *len,
                           struct api_problem *p);
/* PNG of an RGBA8 or RGBA16 image; level -1 = chosen by size. */
enum api_result api_png_encode(const struct rnd_image *img, int level, uint8_t **out, size_t *len,
                               struct api_problem *p);
/* EXR (ZIP) of an RGBA32F image: R,G,B,A half plus the image's AOV planes as float. An image of
 * several views (img->view_count > 1, a sheet) becomes a multi-part EXR: one part per view, named
 * "view0", "view1", ..., each view_width x view_height with the same channels, cut from the
 * view's cell of the sheet and of every AOV plane. One view: a single part with no name. */
enum api_result api_exr_encode(const struct rnd_image *img, uint8_t **out, size_t *len, struct api_problem *p);

/* WebP of an RGBA8 image (api/encode_webp.c): lossless when quality < 0 (every sample, alpha
 * included, decodes exactly), else lossy at quality 0..100 with a lossless alpha plane. Fully
 * opaque images carry no alpha. A side over API_WEBP_MAX_SIDE is a 422; the bytes are malloc'd. */
enum api_result api_webp_encode(const struct rnd_image *img, float quality, uint8_t **out, size_t *len,
                                struct api_problem *p);

/* AVIF of an RGBA8 image (api/encode_avif.c, libavif + libaom), as api_webp_encode: lossless when
 * quality < 0, else lossy at quality 0..100 with a lossless alpha plane; no alpha when fully
 * opaque. A side over API_AVIF_MAX_SIDE is a 422; the bytes are malloc'd. */
enum api_result api_avif_encode(const struct rnd_image *img, float quality, uint8_t **out, size_t *len,
                                struct api_problem *p);
/* The formats whose answer may be lossy (output.quality): WebP and AVIF. */
bool api_format_lossy(enum api_format f);
/* The largest side of an image in format f (WebP, AVIF), 0 = no bound of the format's own. */
uint32_t api_format_max_side(enum api_format f);

/* "image/png", "image/x-exr", "image/webp", "image/avif". */
const char *api_format_mime(enum api_format f);
/* "png", "exr", "webp", "avif": output.format's name, and the extension of the format's files. */
const char *api_format_name(enum api_format f);
/* "a PNG", "an EXR", "a WebP", "an AVIF": for messages. */
const char *api_format_label(enum api_format f);
/* The format an output file name's extension names (.png, .exr, .webp, .avif, in any case): true with
 * *f set; false (*f untouched) for any other name. */
bool api_format_from_name(const char *name, enum api_format *f);

/* What umbrad says of itself in GET /v1/info (the strings are only read). */
struct api_info {
	const char *version, *device, *driver, *driver_info;
	uint32_t vulkan_api;              /* VK_MAKE_API_VERSION packing */
	bool cpu;                         /* a CPU (software) device */
	struct api_limits limits;         /* the 422 limits in force */
	uint64_t max_body, max_memory, device_max_allocation;
	uint32_t max_dimension, device_max_shadow_resolution, deadline_ms, queue, workers;
	uint32_t max_textures, device_max_textures;   /* in force (--max-textures, capped) / the device's */
	uint64_t max_rss, rss;            /* the resident-memory bound (0 = none) and the process's now */
};
/* The /v1/info document (compact JSON and a newline), malloc'd (the caller frees it); *len its
 * length. NULL when out of memory. api/info.c. */
char *api_info_json(const struct api_info *in, size_t *len);

/* What a caller measured around a render, for `explain` (milliseconds; < 0: not measured). */
struct api_plan_times {
	double parse_ms, encode_ms, total_ms;
};
/* The render plan of s (rnd_plan_create, umbra/rnd_plan.h) as the JSON document `explain`
 * answers (api/explain.schema.json): the image, the memory estimate, the views, every shadow
 * map, every object, the passes in order; after rnd_render_plan(), "analyzed" and what each step
 * measured (EXPLAIN ANALYZE; t: the caller's stages, or NULL). Compact JSON, malloc'd (the caller
 * frees it), *len its length (len may be NULL); NULL when out of memory. api/plan_json.c. */
char *api_plan_json(const struct api_scene *s, const struct rnd_plan *plan, const struct api_plan_times *t, size_t *len);

/* One line of a JSON-lines render manifest (umbra-render --manifest), api/manifest.c:
 * {"scene": "path.json" | {document}, "output": "name.png"}; output optional, a bare file name.
 * On API_OK exactly one of scene_path / scene_json is set (malloc'd, as is output); release with
 * api_manifest_entry_release() (NULL-safe, also after a failure). */
struct api_manifest_entry {
	char *scene_path;
	char *scene_json;
	char *output;
};
enum api_result api_manifest_line(const char *line, size_t len, struct api_manifest_entry *e, struct api_problem *p);
void api_manifest_entry_release(struct api_manifest_entry *e);

/* A copy of the scene document doc with "output": {"format": "png" | "exr"} set (compact
 * JSON, malloc'd, *out_len its length), for a manifest line's output name that picks the
 * format: umbrad lets an explicit output.format win over Accept. NULL when doc is not a JSON
 * object (send it as it is: the daemon's 400 says why) or out of memory. api/manifest.c. */
char *api_scene_doc_set_format(const char *doc, size_t len, enum api_format f, size_t *out_len);

/* One line of a farm report (umbra-render's report.jsonl, read back by --resume), api/manifest.c:
 * file, output (or NULL), status and hash (or NULL) of the line, malloc'd; release with
 * api_report_entry_release() (NULL-safe). API_ERR: not such a line (p says why). */
struct api_report_entry {
	char *file;
	char *output;
	char *status;
	char *hash;
};
enum api_result api_report_line(const char *line, size_t len, struct api_report_entry *e, struct api_problem *p);
void api_report_entry_release(struct api_report_entry *e);

/* An application/problem+json document (a daemon's answer with HTTP status `status`) back into
 * p, as api_problem_json() wrote it. A body that is no such document still fills p: its status,
 * and as detail the start of the body. api/problem.c. */
void api_problem_parse(const char *body, size_t len, int status, struct api_problem *p);

/* A hint for a big buffer not yet written (4 MiB or more; smaller ones are left alone): the
 * kernel may back it with 2 MiB pages, one fault each instead of 512 (api/arena.c). */
void api_mem_huge(void *p, size_t len);

#endif
