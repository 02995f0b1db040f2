/*
 * umbra renderer — public API (build/librenderer.a).
 *
 * Usage:
 *   struct rnd_context_desc cd = {0};           // zero = default everywhere
 *   struct rnd_context *ctx; struct rnd_error err;
 *   if (rnd_context_create(&cd, &ctx, &err) != RND_OK) { fprintf(stderr, "%s\n", err.msg); ... }
 *   struct rnd_scene scene; rnd_scene_defaults(&scene);   // then fill it (api/ does this from JSON)
 *   struct rnd_image img = {0}; struct rnd_timings t;
 *   if (rnd_render(ctx, &scene, &img, &t, &err) == RND_OK) { ...use img.pixels...; }
 *   rnd_image_release(&img);
 *   rnd_context_destroy(ctx);
 *
 * Ownership: the scene and every array it points to belong to the caller and are only read
 * during rnd_render(). If rnd_render() returns RND_OK you own the image and must call
 * rnd_image_release(); on failure the image is left empty. Release/destroy accept NULL/empty.
 *
 * Threading: rnd_render() may be called from several threads at once on one context; it takes
 * one of the context's render slots (desc.slots, each with its own command buffer, fence and
 * targets) and blocks until one is free. Create/destroy are not concurrent with anything.
 *
 * This header needs no Vulkan header: the context is opaque.
 */
#ifndef UMBRA_RND_H
#define UMBRA_RND_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum rnd_result {
	RND_OK = 0,
	RND_ERR_INVALID,     /* the scene asks for something impossible (message says what) */
	RND_ERR_LIMIT,       /* over a resource limit of this context or device */
	RND_ERR_NO_DEVICE,   /* no Vulkan device / driver usable */
	RND_ERR_VULKAN,      /* a Vulkan call failed; vk_result holds the VkResult */
	RND_ERR_DEVICE_LOST, /* the device was lost: the context is FAILED, recreate it */
	RND_ERR_OOM,         /* host or device memory exhausted */
	RND_ERR_TIMEOUT,     /* the render passed its deadline */
	RND_ERR_IO,          /* a file (pipeline cache) could not be read or written */
};

/* Which part of the scene an error is about, so a caller can name the member (api/ turns it
 * into a JSON Pointer). RND_AT_NONE: the scene as a whole or nothing in it (device failures). */
enum rnd_error_at {
	RND_AT_NONE,
	RND_AT_SIZE,         /* width / height (the image, or the sheet of several views) */
	RND_AT_VIEWS,        /* the number of views */
	RND_AT_AOVS,         /* output.aovs (with the size: the AOV planes' memory) */
	RND_AT_LIGHTS,       /* the lights as a whole (index unused): e.g. too many shadow maps */
	RND_AT_LIGHT,        /* lights[index] */
	RND_AT_OBJECTS,      /* the objects as a whole (their total size) */
	RND_AT_OBJECT,       /* objects[index] of the rnd_scene */
	RND_AT_MATERIALS,    /* the materials / textures as a whole */
};

struct rnd_error {
	enum rnd_result code;
	int vk_result;       /* VkResult when code == RND_ERR_VULKAN/DEVICE_LOST, else 0 */
	enum rnd_error_at at; /* what the error is about (RND_AT_NONE when nothing in particular) */
	uint32_t at_index;   /* light or object index for RND_AT_LIGHT / RND_AT_OBJECT */
	char msg[256];       /* what failed first, e.g. "vkCreateImage (shadow map 4096x4096): ..." */
};

/* ---- scene description (api/ fills it from JSON; all angles in radians here) ---- */

enum rnd_shape { RND_SHAPE_PLANE, RND_SHAPE_BOX, RND_SHAPE_SPHERE, RND_SHAPE_CYLINDER, RND_SHAPE_MESH };

#include "umbra/rnd_material.h" /* materials and textures */

/* A coarser version of a mesh object's geometry (api/model_lod.c builds them for imported
 * models with meshoptimizer); renderer/lod.h picks the coarsest whose error the output cannot
 * show. Arrays as in rnd_object (normals and indices always present, uvs, colours and tangents
 * optional). */
struct rnd_mesh_lod {
	const float *positions, *normals, *uvs;
	const uint32_t *indices;
	uint32_t vertex_count, index_count;
	float error;          /* largest deviation from the full mesh, object-space units */
	const float *uvs1;    /* the second uv set, where the mesh has one (a level without it is
	                         not used for an object with uvs1) */
	const uint8_t *colors; /* linear RGBA8 per vertex, where the mesh has them (a level without
	                         them is not used for an object with colors) */
	const float *tangents; /* xyzw per vertex, where the mesh has them (a normal map's; a level
	                         without them is not used for an object with tangents) */
};

/* A coarse stand-in for a dense opaque mesh in the environment's shadow maps only (api/model_caster.h
 * builds it): positions and indices, and error, a bound on the distance between
 * its surface and the mesh's, both ways, object-space units. Those maps are soft (PCSS over
 * 128-256 texels): renderer/caster_level.h draws it into a map whose texel it fits, with the
 * map's depth bias raised by the error; the camera and the lights' maps draw the mesh. */
struct rnd_caster_level {
	const float *positions;
	const uint32_t *indices;
	uint32_t vertex_count, index_count;
	float error;
};

struct rnd_object {
	enum rnd_shape shape;
	float size[3];        /* plane: [sx, 0, sz]; box: [sx, sy, sz] */
	float radius;         /* sphere, cylinder */
	float height;         /* cylinder */
	uint32_t segments;    /* sphere, cylinder (>= 3) */
	/* mesh: positions xyz (vertex_count*3 floats); optional indices (index_count, multiple of 3;
	 * when NULL the vertices are a triangle list); optional normals xyz and uvs uv per vertex. */
	const float *positions;
	uint32_t vertex_count;
	const uint32_t *indices;
	uint32_t index_count;
	const float *normals;
	const float *uvs;
	/* optional second uv set (glTF TEXCOORD_1), uv per vertex, for the material slots whose
	 * sampling says uv_set 1; NULL: those slots read uvs. Its lods need their uvs1 too. */
	const float *uvs1;
	const uint8_t *colors;  /* optional linear RGBA8 per vertex (glTF COLOR_0): multiplies base colour */
	const float *tangents;  /* optional xyzw per vertex (w = bitangent sign), for normal maps */
	const struct rnd_mesh_lod *lods; uint32_t lod_count; /* mesh: coarser levels, finest first, or none */
	const struct rnd_caster_level *caster; /* mesh: the environment's shadow maps' level, or NULL */
	/* mesh: min xyz then max xyz of its positions when the caller knows them (a cached model),
	 * or NULL: then every request that needs the bounds passes over the vertices (a 1M-triangle
	 * model: ~3 ms each time). */
	const float *mesh_bounds;
	bool closed;          /* mesh: watertight, wound outward: back faces never show from outside */
	float model[16];      /* object -> world, column-major (T*R*S resolved by the caller) */
	uint32_t material;    /* index into scene.materials */
	bool cast_shadows, receive_shadows, double_sided;
};

enum rnd_light_type { RND_LIGHT_DIRECTIONAL, RND_LIGHT_SPOT, RND_LIGHT_POINT };

enum rnd_filter { RND_FILTER_AUTO, RND_FILTER_HARD, RND_FILTER_PCF, RND_FILTER_PCSS, RND_FILTER_VSM, RND_FILTER_EVSM };
/* RND_DIR_CASTERS: one map fitted to what casts shadows (not the whole scene), the light's
 * resolution across it: the environment's shadow directions (renderer/env_shadow.c). */
enum rnd_dir_mode { RND_DIR_AUTO, RND_DIR_FIT, RND_DIR_CASCADES, RND_DIR_CLIPMAP, RND_DIR_CASTERS };
enum rnd_vsm_precision { RND_VSM_AUTO, RND_VSM_FP32, RND_VSM_FP16 };

/* Resolved shadow settings of one light (api/ merges root `shadows` and the light's `shadow`).
 * Zero / false in a member marked "0 = renderer" means the renderer chooses. */
struct rnd_shadow {
	bool enabled;                 /* true */
	enum rnd_filter filter;       /* AUTO */
	uint32_t resolution;          /* 64..8192, 0 = renderer */
	uint32_t pcf_radius;          /* 0..5, default 1 */
	bool bias_set;                /* the caller gave `bias` (informational: the values are always used) */
	float bias_constant, bias_slope, bias_normal; /* defaults 1, 1.75, 1.5; normal offset in texels */
	enum rnd_dir_mode dir_mode;   /* AUTO */
	uint32_t cascades;            /* 1..4, 0 = renderer (4) */
	float split_lambda;           /* 0..1, default 0.75 */
	float max_distance;           /* 0 = renderer (camera far / scene bounds) */
	float blend;                  /* fraction of a cascade, default 0.1 */
	float fade;                   /* fraction of max_distance, default 0.1 */
	uint32_t clipmap_levels;      /* 1..8, 0 = renderer */
	float clipmap_extent;         /* 0 = renderer */
	enum rnd_vsm_precision vsm_precision; /* AUTO */
	float vsm_blur;               /* texels, default 2 */
	float vsm_light_bleed;        /* 0..1, default 0.2 */
	float vsm_exponent;           /* 0 = by precision */
	bool contact_enabled;         /* false */
	float contact_distance, contact_thickness; /* 0 = renderer */
	uint32_t contact_steps;       /* 0 = renderer */
};

struct rnd_light {
	enum rnd_light_type type;
	float direction[3];   /* directional/spot: the way the light travels (not normalised) */
	float position[3];    /* spot/point */
	float color[3];       /* linear, default 1 1 1 */
	float intensity;      /* directional: irradiance; spot/point: intensity (candela-like) */
	float angular_diameter; /* directional, radians, 0 = hard */
	float range;          /* spot/point, 0 = unbounded */
	float inner_angle, outer_angle; /* spot half-angles, radians (0, pi/4 default) */
	float radius;         /* spot/point light size, metres, 0 = hard */
	struct rnd_shadow shadow;
};

enum rnd_camera_type { RND_CAMERA_PERSPECTIVE, RND_CAMERA_ORTHOGRAPHIC };
enum rnd_camera_fit { RND_FIT_NONE, RND_FIT_SCENE, RND_FIT_OBJECTS };

struct rnd_camera {
	enum rnd_camera_type type;
	float position[3], target[3], up[3];
	float fov_y;          /* radians, perspective (default 45 deg) */
	float height;         /* orthographic: world units over the image height */
	float near, far;      /* 0 = derived from the scene bounds */
	float exposure;       /* EV */
	enum rnd_camera_fit fit;  /* != NONE: position/target derived from the bounds */
	float fit_direction[3];
	float fit_margin;     /* fraction of the frame, default 0.1 */
};

enum rnd_tonemap { RND_TONEMAP_NEUTRAL, RND_TONEMAP_ACES, RND_TONEMAP_NONE };
/* RND_DEBUG_ENV_SHADOW: the share of the environment's cosine-weighted diffuse light that
 * reaches each pixel (occluded / unoccluded), written as `shadow` writes a light's. */
enum rnd_debug { RND_DEBUG_NONE, RND_DEBUG_SHADOW, RND_DEBUG_CASCADES, RND_DEBUG_NORMALS, RND_DEBUG_DEPTH, RND_DEBUG_ATLAS,
                 RND_DEBUG_ENV_SHADOW };

/* What the renderer writes into rnd_image.pixels. */
enum rnd_pixel_format {
	RND_PIXELS_RGBA8,     /* display-referred: exposure, tone map, sRGB encoding applied */
	RND_PIXELS_RGBA16,    /* the same at 16 bits per channel (host-endian uint16) */
	RND_PIXELS_RGBA32F,   /* linear scene-referred (exposure applied, no tone map) */
};

/* Extra per-pixel outputs (bit mask), float32 planes in rnd_image.aov. */
enum rnd_aov {
	RND_AOV_SHADOW = 1u << 0, /* one plane per light: visibility, 1 = lit */
	RND_AOV_DEPTH  = 1u << 1, /* view-space depth, +inf where no geometry */
	RND_AOV_NORMAL = 1u << 2, /* world normal, 3 planes */
	RND_AOV_ALBEDO = 1u << 3, /* base colour, 3 planes */
};

struct rnd_output {
	enum rnd_pixel_format pixels; /* RGBA8 */
	bool transparent;     /* background (0,0,0,0); RGBA8/16 come back with straight alpha,
	                         RGBA32F premultiplied (as PNG and EXR expect) */
	enum rnd_tonemap tonemap;
	uint32_t msaa;        /* 1 or 4 (default 4) */
	uint32_t aovs;        /* enum rnd_aov mask */
	enum rnd_debug debug;
	uint32_t debug_light;
};

/* Where the environment's light comes from: the hemisphere ambient alone (sky and ground
 * colours), an equirectangular map, or the built-in studio (renderer/env_studio.c, generated). */
enum rnd_env_source { RND_ENV_AMBIENT, RND_ENV_MAP, RND_ENV_STUDIO };

/* An equirectangular map: linear RGB floats, width x height texels, rows from the zenith (top)
 * to the nadir; the scene direction d = (x, y, z) reads it at u = 0.5 + atan2(z, x) / 2pi (from
 * the left edge), v = 0.5 - asin(y) / pi (from the top): the centre column is +X, the column at
 * width/4 is -Z (three.js' equirectUv, ../shared/truth-cycles/envmap.py). */
struct rnd_env_map {
	const float *rgb;     /* width * height * 3 */
	uint32_t width, height;
	/* The caller's hash of the pixels (the prefiltered copy on the device is kept under it:
	 * renderer/env.c), 0 = the renderer hashes them. */
	uint64_t key;
};

struct rnd_environment {
	float background[4];  /* linear RGBA, default 0.5 0.5 0.5 1 */
	float ambient_sky[3], ambient_ground[3];
	float ambient_intensity;
	enum rnd_env_source source;   /* AMBIENT */
	struct rnd_env_map map;       /* source MAP */
	float rotation;               /* radians about +Y (right hand): the map's d appears at R_y d */
	float intensity;              /* multiplies the map's radiance, default 1 */
	bool background_map;          /* the map (tone mapped like the scene) behind the scene */
	/* Shadows of the map's light: directions drawn as shadow maps, each over the map's brightest
	 * region of equal energy (0 = no environment shadows; at most RND_MAX_ENV_DIRECTIONS), and
	 * the side of their maps (0 = renderer: RND_DEFAULT_ENV_SHADOW_RESOLUTION). */
	uint32_t shadow_directions;   /* RND_DEFAULT_ENV_DIRECTIONS */
	uint32_t shadow_resolution;
};
#define RND_MAX_ENV_DIRECTIONS 32u
#define RND_DEFAULT_ENV_DIRECTIONS 12u
#define RND_DEFAULT_ENV_SHADOW_RESOLUTION 512u

struct rnd_scene {
	uint32_t width, height;   /* of one view */
	struct rnd_camera camera;
	/* Several views of one scene (contract `views` / `turntable`): when view_count > 0 these
	 * cameras replace `camera` and the image is a sheet of ceil(sqrt(n)) columns, row-major,
	 * each view width x height; shadow maps that do not depend on the camera render once. */
	const struct rnd_camera *views; uint32_t view_count;
	struct rnd_environment environment;
	const struct rnd_material *materials; uint32_t material_count;
	const struct rnd_object *objects;     uint32_t object_count;
	const struct rnd_light *lights;       uint32_t light_count;
	struct rnd_output output;

	/* How long the render may run (not part of the picture; zero = no limit). The renderer
	 * splits its work into submits that can stop (shadow views in groups, the main pass in
	 * horizontal bands sized from measured time) and checks between submits; past the
	 * deadline, or when `cancel` returns true, it stops at the next submit boundary, releases
	 * everything and returns RND_ERR_TIMEOUT. A submit already running is waited for, so a
	 * render ends at most about one submit (~1 s on lavapipe, less under short deadlines)
	 * past its deadline. Without deadline and cancel everything goes in as few submits as
	 * possible. */
	uint64_t deadline_ns;     /* absolute CLOCK_MONOTONIC time in nanoseconds, 0 = none */
	bool (*cancel)(void *user); /* polled between submits (any thread-safe check), NULL = none */
	void *cancel_user;
	uint32_t band_rows;       /* main-pass rows per submit, 0 = chosen by the renderer (tests) */
	uint32_t shadow_part_triangles; /* every shadow map in parts of this many casters' triangles, a
	                                   submit each; 0 = only a costly map, sized by the renderer (tests) */
	/* false: spheres and cylinders get no more segments, meshes with levels no more triangles,
	 * than the output can show (renderer/lod.h: within 1/32 pixel and 1/8 shadow texel); true:
	 * exactly `segments` and every mesh in full (tests, comparisons). */
	bool exact_segments;
	/* The largest map side (texels) the renderer may choose for a light whose shadow has no
	 * `resolution` of its own, 0 = no cap (8192): a server's limit on shadow resolution
	 * (api/ sets it from umbrad's --max-shadow-resolution) bounds the defaults too. */
	uint32_t max_shadow_resolution;
};

/* Contract defaults: 512x512, perspective camera at (0,0,5) looking at the origin, default
 * environment, no objects, no lights, RGBA8 PNG-style output with neutral tone map, MSAA 4. */
void rnd_scene_defaults(struct rnd_scene *scene);
void rnd_material_defaults(struct rnd_material *m);
void rnd_object_defaults(struct rnd_object *o);     /* identity model, casts/receives, 2-sided */
void rnd_light_defaults(struct rnd_light *l, enum rnd_light_type type);
void rnd_shadow_defaults(struct rnd_shadow *s);
/* The contract's default pcf_radius (kernel 3x3). */
#define RND_DEFAULT_PCF_RADIUS 1u

/* The side of the shadow map (an atlas tile, a power of two from RND_MIN_SHADOW_RESOLUTION to
 * RND_MAX_SHADOW_RESOLUTION) for a light whose resolution is `want`: the power of two at or
 * above it where the request gave it (the parser compares that with a server's limit), at or
 * below `cap` (0 = none) where the renderer chose it itself (want 0: the default,
 * RND_DEFAULT_SHADOW_RESOLUTION). Spot and point lights without a resolution get sizes by
 * importance (plan.c), at most this. */
uint32_t rnd_shadow_map_side(uint32_t want, bool asked, uint32_t cap);
#define RND_MIN_SHADOW_RESOLUTION 64u
#define RND_MAX_SHADOW_RESOLUTION 8192u
#define RND_DEFAULT_SHADOW_RESOLUTION 2048u

/* Triangles the renderer will draw for an object (tessellation of the contract's shapes). */
uint64_t rnd_object_triangle_count(const struct rnd_object *o);

/* Whether the object counts for `fit: "objects"` framing (and for what api/ places a ground
 * under or circles with a turntable): every object but planes and shadow catchers. mats: the
 * scene's materials, NULL when there are none (no object is then a catcher). When no object
 * counts, the whole scene is framed instead. */
bool rnd_object_frames(const struct rnd_object *o, const struct rnd_material *mats);

/* ---- limits ----
 * What rnd_render() accepts at most (RND_ERR_LIMIT / RND_ERR_INVALID past them); api/ checks
 * documents against the same numbers so that the member at fault gets its 422. */
#define RND_MAX_DIMENSION 8192u          /* default desc.max_width / max_height of a view */
#define RND_MAX_VIEWS 1024u              /* scene.view_count */
#define RND_MAX_SHEET_SIDE 65536u        /* pixels per side of the sheet of several views */
#define RND_MAX_SHEET_PIXELS (1ull << 28)
#define RND_MAX_TEXTURE_SIDE 16384u      /* texels per side of one texture */
#define RND_MAX_VSM_BLUR 64u             /* shadow.vsm_blur, texels (the moments blur's widest kernel) */

/* The sheet of several views: ceil(sqrt(n)) columns, as many rows as needed (n = 0 means 1);
 * unused cells count in its size. */
void rnd_sheet_layout(uint32_t view_count, uint32_t *cols, uint32_t *rows);

/* ---- result ---- */

#define RND_MAX_AOV_PLANES 40

struct rnd_image {
	uint32_t width, height;   /* the whole sheet when the scene has several views */
	uint32_t view_count, view_columns, view_width, view_height; /* 1, 1, width, height for one view */
	enum rnd_pixel_format format;
	size_t stride;        /* bytes per row of pixels */
	void *pixels;         /* RGBA, rows top to bottom */
	uint32_t aov_count;   /* float32 planes, width*height each, rows top to bottom */
	char aov_names[RND_MAX_AOV_PLANES][24]; /* "shadow.0", "Z", "N.X", "albedo.R", ... */
	float *aov[RND_MAX_AOV_PLANES];
};
void rnd_image_release(struct rnd_image *img);

/* Milliseconds per stage of one render. */
struct rnd_timings {
	double plan_ms;       /* the render plan (rnd_plan_create): every decision, made once */
	double upload_ms;     /* tessellation + copy to the GPU */
	double shadow_ms;     /* shadow passes (GPU) */
	double main_ms;       /* main pass + resolve (GPU), the visibility pass's included */
	double visibility_ms; /* of main_ms: the visibility pass (renderer/visibility.c: surfaces, shadows per pixel) */
	double readback_ms;   /* copy back to host memory */
	uint32_t shadow_maps_rendered, shadow_maps_reused;
	uint64_t shadow_texels;     /* texels of the shadow maps drawn (each map res x res) */
	uint32_t visibility_views; /* views whose shadows came from the visibility pass (once per pixel) */
	uint32_t pixel_shaded_views; /* of those, views shaded once per pixel centre (renderer/deferred.h) */
	uint32_t sphere_proxies;   /* spheres the camera drew as a proxy shading the true sphere (proxy.h) */
	uint64_t camera_triangles; /* triangles the camera's passes drew, each view counted once */
	uint64_t shadow_triangles; /* casters' triangles the shadow maps drew */
	uint32_t submits;          /* queue submits (more than one when paced by a deadline) */
	uint32_t shadow_parts;     /* submits of shadow maps drawn in parts (too costly for one) */
	uint32_t shadow_submits;   /* submits of shadow maps alone, whole or in parts (0: one submit drew
	                              them with the main pass, as without a deadline) */
	uint32_t env_directions;   /* environment shadow directions drawn (maps rendered or reused) */
	uint32_t env_passes_reused; /* views whose environment pass (renderer/env_pass.h) the slot still held
	                               from a render of the same inputs: not drawn again */
	double env_ms;             /* this render's share of preparing the environment (CPU analysis and
	                              the device's prefiltering, once per map: 0 when it was ready) */
	double targets_ms;         /* the slot's colour/depth targets, AOV images and readback buffer:
	                              made on a slot's first render of a size, else ~0 */
	double compile_ms;         /* pipeline variants this render compiled (first use of a variant) */
};

/* ---- context ---- */

struct rnd_context; /* opaque */

typedef void (*rnd_log_fn)(void *user, int level /* 0 error 1 warn 2 info */, const char *msg);

#define RND_DEFAULT_MAX_TEXTURES 256u
/* The most a context grants (rnd_info.device_max_textures): each render slot preallocates
 * descriptor sets for its textures, ~1 KB each on lavapipe. */
#define RND_MAX_TEXTURES_CEILING 4096u

struct rnd_context_desc {
	const char *device_name;   /* substring of the device name to pick; NULL = $UMBRA_DEVICE, else a GPU, else lavapipe */
	bool validation;           /* enable VK_LAYER_KHRONOS_validation; messages are counted and logged */
	const char *pipeline_cache_path; /* loaded at create, saved by rnd_context_save_cache(); NULL = none */
	uint32_t slots;            /* concurrent renders (render slots); 0 = 1 */
	uint32_t max_width, max_height; /* 0 = 8192 */
	uint32_t atlas_size;       /* texels per side of the shadow atlases (power of two), 0 = 4096 */
	/* Texels of cached shadow maps kept between renders; past it the least recently used go
	 * after each render (tiles are handed out first-fit, so the atlas pages a process touches,
	 * and its memory, stay near this). 0 = RND_DEFAULT_SHADOW_CACHE_TEXELS. */
	uint64_t shadow_cache_texels;
	/* Distinct textures one scene may use; 0 = RND_DEFAULT_MAX_TEXTURES. Capped at
	 * RND_MAX_TEXTURES_CEILING (rnd_info.max_textures says what was granted); each slot holds
	 * two descriptor sets per texture (rnd_texture_sets). Materials sharing textures share a set. */
	uint32_t max_textures;
	/* Tests: give vertex and index buffers their CPU mirror even in host-cached memory, so the
	 * path a GPU's uncached BAR memory takes (renderer/memory.c) runs on lavapipe too. */
	bool mirror_buffers;
	rnd_log_fn log; void *log_user;
};

/* Four 2048^2 maps (64 MiB of D32): a thumbnail farm sends new casters every request and kept
 * every new model's sun map (37 maps, ~160 MB resident after 30 models); a repeated scene keeps
 * its own (thumb-512 one 2048^2 map, studio-spots 17 smaller ones). */
#define RND_DEFAULT_SHADOW_CACHE_TEXELS (4ull * 2048 * 2048)

struct rnd_info {
	char device_name[256];
	char driver_name[256];
	char driver_info[256];
	uint32_t api_version;
	bool is_cpu;               /* lavapipe / software rasteriser */
	uint32_t max_image_dimension;
	uint32_t max_shadow_resolution;
	uint64_t max_allocation;   /* largest single buffer/allocation (an image with its AOVs must fit) */
	uint32_t max_textures;     /* distinct textures per scene: the desc's, capped by the one below */
	uint32_t device_max_textures; /* the renderer's bound on that on this device (see device.c) */
	bool moments_fp32_filterable;
};

enum rnd_result rnd_context_create(const struct rnd_context_desc *desc, struct rnd_context **out,
                                   struct rnd_error *err);
void rnd_context_destroy(struct rnd_context *ctx);
void rnd_context_info(const struct rnd_context *ctx, struct rnd_info *info);
/* Validation-layer messages (warnings and errors) seen since create. Tests require 0. */
uint32_t rnd_context_validation_messages(const struct rnd_context *ctx);

/* What a render of a scene will allocate, from the scene alone (before any allocation): for
 * admission by memory (umbrad --max-memory) and for limits that no retry can cure. Bytes are
 * upper estimates of what the render holds at its peak. A render plan carries it
 * (rnd_plan_estimate). */
struct rnd_estimate {
	uint64_t device_bytes;        /* targets, AOV images, readback buffer, geometry, shadow scratch,
	                                 material textures with their mip chains (image + staging)
	                                 (device memory; on a CPU driver such as lavapipe, host memory) */
	uint64_t host_bytes;          /* the returned image (colour + AOV planes) and its encoding */
	uint64_t largest_allocation;  /* the largest single buffer or image */
	uint64_t readback_bytes;      /* the readback buffer (colour + AOV attachments of the sheet) */
};
/* Counters for metrics; thread-safe. */
struct rnd_stats {
	uint32_t atlas_size;
	double atlas_occupancy;          /* share of atlas texels held by tiles, 0..1 */
	uint32_t atlas_tiles;
	uint32_t cached_maps;            /* shadow maps kept for reuse (spot, point, a sun's fit map) */
	uint64_t shadow_cache_hits;      /* lights whose shadow passes were skipped */
	uint64_t shadow_cache_misses;
	uint32_t pipeline_variants;      /* main-pass pipeline variants compiled and kept */
	uint32_t env_maps;               /* environment maps kept prefiltered (the studio included) */
	uint64_t env_builds;             /* environment maps prefiltered since create (once per map kept) */
};
void rnd_context_stats(struct rnd_context *ctx, struct rnd_stats *st);
/* Idle trim: drops cached shadow maps not used for idle_s seconds (0: all), and once no map
 * is left, gives the shadow atlases' pages back to the system where device memory is host
 * memory (lavapipe), so the atlases are resident only while tiles use them. Does nothing while
 * a render holds tiles. Returns the bytes released (0 when nothing was). Any thread. */
uint64_t rnd_context_trim(struct rnd_context *ctx, double idle_s);
/* What a context keeps between renders beyond rnd_context_trim()'s, for a process held to a
 * memory bound (umbrad --max-rss): the targets and buffers of the render slots no render holds
 * now (the next render there makes them again), and the main-pass pipeline variants but the
 * `keep` most recently used (a variant is compiled again at its next use: lavapipe keeps ~14 MB
 * of JIT code and state per variant, 0.1-0.4 s to make). A variant a running render may have
 * recorded is destroyed only once that render is over. Any thread. trim_pipelines returns the
 * variants taken out. */
void rnd_context_trim_slots(struct rnd_context *ctx);
uint32_t rnd_context_trim_pipelines(struct rnd_context *ctx, uint32_t keep);

/* Writes the pipeline cache to desc.pipeline_cache_path (atomic rename). */
enum rnd_result rnd_context_save_cache(struct rnd_context *ctx, struct rnd_error *err);

/* Test-only fault injection (issue "tests of the bad day"): the nth queue submit of this
 * context from now (1 = the next one) is not submitted and returns kind's VkResult instead —
 * VK_ERROR_DEVICE_LOST (the context turns FAILED, exactly as for a real loss) or
 * VK_ERROR_OUT_OF_DEVICE_MEMORY (the render fails with RND_ERR_OOM, the context stays usable).
 * One shot; RND_FAULT_NONE disarms. umbrad sets it from --test-fault after its warm-up. */
enum rnd_fault { RND_FAULT_NONE, RND_FAULT_DEVICE_LOST, RND_FAULT_OUT_OF_MEMORY };
void rnd_context_inject_fault(struct rnd_context *ctx, enum rnd_fault kind, uint32_t nth_submit);

/* Renders one scene. Blocks until done (or until scene->deadline_ns / cancel stop it:
 * RND_ERR_TIMEOUT). See the threading note at the top. The same as rnd_plan_create(),
 * rnd_render_plan() and rnd_plan_destroy(). */
enum rnd_result rnd_render(struct rnd_context *ctx, const struct rnd_scene *scene,
                           struct rnd_image *out, struct rnd_timings *timings, struct rnd_error *err);

/* ---- render plans ----
 * Every decision of a render — views, shadow maps (kind, size, filter, cached or drawn), each
 * object's level of detail, what each pass leaves out, the passes, the deadline's estimates,
 * the memory estimate — is made once, as a plan, before anything is allocated; the render
 * executes the plan and nothing else. A caller that wants to admit a render by its memory, or
 * show its plan (umbra/rnd_plan.h, `explain`), makes the plan first:
 *   struct rnd_plan *plan;
 *   if (rnd_plan_create(ctx, &scene, &plan, &err) == RND_OK) {
 *       struct rnd_estimate est; rnd_plan_estimate(plan, &est);      // admit by est ...
 *       r = rnd_render_plan(ctx, plan, &img, &t, &err);               // ... then render it
 *       rnd_plan_destroy(plan);
 *   }
 * Ownership: the plan points into the scene, which must outlive it; rnd_plan_destroy frees it
 * (NULL-safe). A plan is rendered at most once, on the context it was made on (its cache's
 * maps, its limits). Threading: plans are independent; a plan is used by one thread at a time. */
struct rnd_plan;
/* Makes the plan of scene on ctx: RND_OK, or the error rnd_render would fail with before
 * drawing anything (invalid, over a limit, RND_ERR_LIMIT at a member when one allocation would
 * be over the device's limit). */
enum rnd_result rnd_plan_create(struct rnd_context *ctx, const struct rnd_scene *scene, struct rnd_plan **out,
                                struct rnd_error *err);
void rnd_plan_destroy(struct rnd_plan *plan);
/* What the plan's render will allocate (see struct rnd_estimate). */
void rnd_plan_estimate(const struct rnd_plan *plan, struct rnd_estimate *est);
/* Executes the plan: as rnd_render. Fills the plan's measured side (rnd_plan.h: EXPLAIN
 * ANALYZE) whatever the result. */
enum rnd_result rnd_render_plan(struct rnd_context *ctx, struct rnd_plan *plan, struct rnd_image *out,
                                struct rnd_timings *timings, struct rnd_error *err);

const char *rnd_result_str(enum rnd_result r);

#ifdef __cplusplus
}
#endif
#endif
