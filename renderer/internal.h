/*
 * renderer/internal.h — what the renderer's modules share; never included outside renderer/.
 *
 * Ownership: struct rnd_context owns the device, the pipelines (pipelines.c) and the render
 * slots (slot.c). A slot owns everything one render needs (command buffer, fence, query pool,
 * descriptor set, buffers and images that grow to fit and are kept for the next render).
 * Threading: the context is read-only after create except slot hand-out (slot_mu/slot_cv) and
 * queue submission (queue_mu). A slot is used by one thread at a time.
 */
#ifndef UMBRA_RENDERER_INTERNAL_H
#define UMBRA_RENDERER_INTERNAL_H

#include <pthread.h>
#include <stdio.h>
#include <stdarg.h>
#include <vulkan/vulkan.h>
#include "umbra/rnd.h"
#include "umbra/rnd_math.h"
#include "umbra_shared.h"
#include "error.h"

#define RND_COLOR_FORMAT_COUNT 3   /* enum rnd_pixel_format */
#define RND_DEPTH_FORMAT VK_FORMAT_D32_SFLOAT
#define RND_SHADOW_FORMAT VK_FORMAT_D32_SFLOAT
/* The visibility pass (visibility.c): its surfaces (position, normal: shaders/surface.frag) and
 * its output (a layer per light, 16 bits: 8 would band smooth penumbrae in the darks; vis.frag's
 * storage image says r16 too). */
#define RND_SURFACES_FORMAT VK_FORMAT_R32G32B32A32_SFLOAT
#define RND_SURFACE_NORMALS_FORMAT VK_FORMAT_R16G16B16A16_SNORM
#define RND_VISIBILITY_FORMAT VK_FORMAT_R16_UNORM
/* Pixel shading (deferred.c): what shading a pixel centre's surface needs (umbra_shared.h
 * UMBRA_SHADING_*); the colour shaded there has the output's colour format. */
#define RND_SURFACE_SHADING_FORMAT VK_FORMAT_R32G32B32A32_UINT
#define RND_MAX_VARIANTS 1024
/* variants compiled at once on one context (more wait their turn: a few per core is plenty) */
#define RND_COMPILING_MAX 32

/* Map a VkResult to a result + message "what: VK_ERROR_..." */
enum rnd_result rnd_fail_vk(struct rnd_error *err, VkResult vr, const char *what);
const char *rnd_vk_str(VkResult r);

struct rnd_buffer {
	VkBuffer buf;
	VkDeviceMemory mem;
	VkDeviceSize size;
	void *map;               /* persistently mapped (all our buffers are host-visible) */
	/* Where the CPU writes and reads the contents: `map` itself where the memory is host-cached
	 * (lavapipe, readback and staging buffers), else (vertex and index buffers in a GPU's
	 * device-local, uncached BAR memory, which a CPU reads at a few MB/s) a heap mirror that
	 * rnd_buffer_publish copies into `map` in one sequential write. */
	void *cpu;
};

struct rnd_image_res {
	VkImage img;
	VkDeviceMemory mem;
	VkImageView view;        /* whole image */
	VkFormat format;
	uint32_t width, height, layers, samples;
};

/* Samplers of material textures: mip mode (3, enum rnd_mip) x wrap s (3) x wrap t (3) x mag
 * nearest (2) x min nearest (2); index 0 is repeat / linear / trilinear (glTF's default, and
 * the white texture's). */
#define RND_TEXTURE_SAMPLERS 108
static inline uint32_t rnd_texture_sampler_index(const struct rnd_texture_sampling *t)
{
	return (uint32_t)(t->mip % 3u) * 36u + (uint32_t)(t->wrap_s % 3u) * 12u + (uint32_t)(t->wrap_t % 3u) * 4u +
	       (t->mag_nearest ? 2u : 0u) + (t->min_nearest ? 1u : 0u);
}

struct rnd_pipelines {
	VkDescriptorSetLayout set_layout;     /* set 0: frame, materials, lights, views, shadow maps */
	VkDescriptorSetLayout texture_layout; /* set 1: the draw's material textures (UMBRA_TEX_SLOTS bindings) */
	VkPipelineLayout layout;
	VkSampler shadow_sampler;            /* nearest, clamp to border white (depth 1 = lit) */
	VkSampler atlas_sampler;             /* nearest, clamp to edge: the depth atlas's gathers */
	/* material textures, one per sampling state: see rnd_texture_sampler_index() */
	VkSampler texture_samplers[RND_TEXTURE_SAMPLERS];
	/* [cull: 0 none, 1 back] */
	VkPipeline shadow[2];
	/* [msaa: 0 = 1x, 1 = 4x][cull] depth-only pre-pass of the camera view */
	VkPipeline prepass[2][2];
	/* alpha-tested (alpha_mode MASK) variants of the two depth-only passes */
	VkPipeline shadow_masked[2];
	VkPipeline prepass_masked[2][2];
	/* [cull] the surfaces pass of the visibility pass (renderer/visibility.c): single-sample,
	 * world position and normal per pixel */
	VkPipeline surfaces[2];
	/* [cull] the same with pixel shading's inputs too (deferred.c) */
	VkPipeline surfaces_shade[2];
	/* Main-pass variants, created on first use (rnd_pipelines_main) and kept. */
	VkShaderModule mesh_vs, mesh_fs, mesh_vis_fs, aov_fs, fullscreen_vs, vis_fs, vis_shade_fs, resolve_fs, background_fs,
	               env_vis_fs;
	pthread_mutex_t mu;
	pthread_cond_t compiled;             /* broadcast when a variant in `compiling` is done */
	struct rnd_main_key *compiling[RND_COMPILING_MAX]; /* keys being compiled now (outside mu) */
	uint32_t compiling_count;
	uint32_t variant_count;
	struct rnd_main_variant {
		struct rnd_main_key {
			uint32_t format;             /* enum rnd_pixel_format */
			uint32_t samples;            /* 1 or 4 */
			uint32_t cull_back;
			uint32_t aov;                /* 1 = the AOV pass (aov.frag, 4 x RGBA32F, 1 sample) */
			uint32_t prepass;            /* 1 = after a depth pre-pass: depth EQUAL, no writes */
			uint32_t atlas_view;         /* 1 = debug view `atlas` (fullscreen.vert + atlas.frag) */
			uint32_t vis_pass;           /* 1 = the visibility pass (fullscreen.vert + vis.frag) */
			uint32_t vis_read;           /* 1 = main pass reading the visibility pass (mesh_vis.frag) */
			uint32_t vis_shade;          /* with vis_pass: pixel shading's pass (vis_shade.frag, deferred.c) */
			uint32_t resolve;            /* 1 = pixel shading's resolve (fullscreen.vert + resolve.frag) */
			uint32_t background;         /* 1 = the environment map behind the scene (fullscreen.vert +
			                                env_background.frag, where the depth is still the far plane) */
			uint32_t env_pass;           /* 1 = the environment pass (fullscreen.vert + env_vis.frag, R16) */
			uint32_t sc[UMBRA_SC_COUNT]; /* mesh.frag specialization constants */
		} key;
		VkPipeline pipeline;
		uint64_t used;               /* `tick` at its last look-up */
	} variants[RND_MAX_VARIANTS];
	uint64_t tick;
	/* Variants taken out of the table (rnd_context_trim_pipelines), destroyed once no render
	 * that began before (slot epoch below `epoch`) still runs: it may have recorded them. */
	struct rnd_retired {
		VkPipeline pipeline;
		uint64_t epoch;
	} retired[RND_MAX_VARIANTS];
	uint32_t retired_count;
};

struct rnd_moments {
	VkDescriptorSetLayout set_layout;    /* minmax.comp: the scratch map, the depth bounds */
	VkPipelineLayout layout;
	VkPipeline bounds;                   /* minmax.comp: PCSS depth bounds */
	VkDescriptorSetLayout blur_set_layout; /* moments.frag: the depth atlas, the blur temporary */
	VkPipelineLayout blur_layout;
	VkPipeline blur_x[2][2];             /* moments.frag pass 0 into the temporary [EVSM][perspective] */
	VkPipeline blur_y;                   /* moments.frag pass 1 into the moment atlas */
	VkSampler sampler;                   /* linear, clamp to edge */
	VkSampler nearest;                   /* moments.frag's texel fetches */
	bool fp32;                           /* R32G32_SFLOAT filterable + renderable */
	bool available;                      /* VSM / EVSM can be offered at all */
};

struct rnd_slot;
struct rnd_shadow_cache;
struct rnd_env_cache;

struct rnd_context {
	struct rnd_context_desc desc;
	char cache_path[4096];
	VkInstance instance;
	VkDebugUtilsMessengerEXT messenger;
	VkPhysicalDevice phys;
	VkPhysicalDeviceProperties props;
	VkPhysicalDeviceMemoryProperties mem_props;
	VkDeviceSize max_allocation;         /* maxMemoryAllocationSize (Vulkan 1.1), min maxBufferSize (1.3) */
	uint32_t max_textures, device_max_textures; /* distinct textures per scene (device.c) */
	char driver_name[256], driver_info[256];
	VkDevice device;
	VkQueue queue;
	uint32_t queue_family;
	VkPipelineCache pipeline_cache;
	struct rnd_pipelines pipes;
	struct rnd_moments moments;
	struct rnd_shadow_cache *cache;      /* shadow_cache.c */
	struct rnd_env_cache *env;           /* env.c: environment maps prefiltered on the device */
	struct rnd_image_res atlas_depth;    /* D32, GENERAL layout, every shadow view is a tile */
	struct rnd_image_res atlas_moments;  /* VSM / EVSM moments, same tiles */
	struct rnd_image_res atlas_bounds;   /* PCSS depth bounds: a texel per UMBRA_BOUNDS_BLOCK² block */
	uint64_t stats_hits, stats_misses;
	bool has_debug_utils;
	PFN_vkSetDebugUtilsObjectNameEXT set_object_name;   /* NULL without VK_EXT_debug_utils */
	bool timestamps;                     /* queue supports timestamps */
	bool visibility_pass;                /* the device can run the visibility pass (visibility.c) */
	bool pixel_shading;                  /* ... and shade per pixel (deferred.c) */
	float timestamp_period;              /* ns per tick */
	VkFormat color_formats[RND_COLOR_FORMAT_COUNT];

	pthread_mutex_t queue_mu;
	pthread_mutex_t slot_mu;
	pthread_cond_t slot_cv;
	struct rnd_slot **slots;
	uint32_t slot_count;
	bool *slot_busy;
	uint64_t slot_epoch;                 /* under slot_mu: advanced by each retired pipeline */

	volatile int validation_count;       /* atomically incremented by the messenger */
	volatile int failed;                 /* device lost: every render fails */
	int fault_kind;                      /* enum rnd_fault armed by rnd_context_inject_fault (atomic) */
	uint32_t fault_countdown;            /* submits until it fires (atomic) */
};

void rnd_log(const struct rnd_context *ctx, int level, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* CLOCK_MONOTONIC in milliseconds: every stage time of the renderer. */
double rnd_now_ms(void);
/* pipelines.c: milliseconds this thread has spent compiling pipeline variants (rnd_timings.compile_ms). */
extern _Thread_local double rnd_compile_ms_tls;
/* Debug name for any Vulkan object (no-op without VK_EXT_debug_utils). */
void rnd_name(const struct rnd_context *ctx, VkObjectType type, uint64_t handle, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
#define RND_NAME(ctx, type, h, ...) rnd_name((ctx), (type), (uint64_t)(uintptr_t)(h), __VA_ARGS__)

/* memory.c */
enum rnd_result rnd_buffer_create(struct rnd_context *ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                                  const char *name, struct rnd_buffer *out, struct rnd_error *err);
void rnd_buffer_destroy(struct rnd_context *ctx, struct rnd_buffer *b);
/* Copies bytes [off, off + n) of a mirrored buffer's `cpu` into its mapping; nothing where
 * `cpu` is the mapping. Call after the CPU's last write and before the GPU reads. */
void rnd_buffer_publish(struct rnd_buffer *b, VkDeviceSize off, VkDeviceSize n);
/* Grows b to at least size (power-of-two steps); contents are not kept. */
enum rnd_result rnd_buffer_reserve(struct rnd_context *ctx, struct rnd_buffer *b, VkDeviceSize size,
                                   VkBufferUsageFlags usage, const char *name, struct rnd_error *err);
enum rnd_result rnd_image_create(struct rnd_context *ctx, VkFormat format, uint32_t w, uint32_t h, uint32_t layers,
                                 uint32_t samples, VkImageUsageFlags usage, VkImageAspectFlags aspect,
                                 const char *name, struct rnd_image_res *out, struct rnd_error *err);
/* As rnd_image_create() with `levels` mip levels (the view sees them all). */
enum rnd_result rnd_image_create_levels(struct rnd_context *ctx, VkFormat format, uint32_t w, uint32_t h,
                                        uint32_t layers, uint32_t samples, uint32_t levels, VkImageUsageFlags usage,
                                        VkImageAspectFlags aspect, const char *name, struct rnd_image_res *out,
                                        struct rnd_error *err);
/* A cube map (6 layers, cube-compatible) of `levels` mip levels; its view is a cube of them all. */
enum rnd_result rnd_image_create_cube(struct rnd_context *ctx, VkFormat format, uint32_t side, uint32_t levels,
                                      VkImageUsageFlags usage, const char *name, struct rnd_image_res *out,
                                      struct rnd_error *err);
void rnd_image_destroy(struct rnd_context *ctx, struct rnd_image_res *im);

/* pipelines.c */
enum rnd_result rnd_pipelines_init(struct rnd_context *ctx, struct rnd_error *err);
void rnd_pipelines_release(struct rnd_context *ctx);
/* A named shader module of SPIR-V code (size bytes); the caller destroys it. */
enum rnd_result rnd_shader_module(struct rnd_context *ctx, const uint32_t *code, size_t size, const char *name,
                                  VkShaderModule *out, struct rnd_error *err);
/* A pipeline for a fullscreen pass (shaders/fullscreen.vert and fs): no vertex input, no depth,
 * one colour attachment of format `color`, dynamic viewport and scissor; `layout` the caller's.
 * Needs rnd_pipelines_init(); the caller destroys it. */
enum rnd_result rnd_pipeline_fullscreen(struct rnd_context *ctx, VkShaderModule fs, VkFormat color, VkPipelineLayout layout,
                                        const VkSpecializationInfo *spec, const char *name, VkPipeline *out,
                                        struct rnd_error *err);
/* The descriptor type of each binding of the main set (UMBRA_BINDING_* of umbra_shared.h): one
 * table for the set layout and for the descriptor writes (render.c). */
extern const VkDescriptorType rnd_binding_type[UMBRA_BINDING_COUNT];
/* Compiles main-pass variant key (pipelines.c; the caller keeps it: pipeline_variants.c). */
enum rnd_result rnd_pipeline_variant_compile(struct rnd_context *ctx, const struct rnd_main_key *key, const char *name,
                                             VkPipeline *out, struct rnd_error *err);

/* pipeline_variants.c */
/* The main-pass pipeline for key, compiled on first use (thread-safe; a render that needs a
 * variant another is compiling waits for it instead of compiling it again). */
enum rnd_result rnd_pipelines_main(struct rnd_context *ctx, const struct rnd_main_key *key, VkPipeline *out,
                                   struct rnd_error *err);
/* Destroys the retired pipeline variants no running render may use. */
void rnd_pipelines_reap(struct rnd_context *ctx);
uint32_t rnd_pipelines_count(struct rnd_context *ctx);

/* slot.c */
/* The slot epoch after advancing it (a pipeline retired now: renders given a slot from now on
 * never see it), and the oldest epoch among busy slots (UINT64_MAX: none busy). */
uint64_t rnd_slot_epoch_advance(struct rnd_context *ctx);
uint64_t rnd_slot_oldest_busy_epoch(struct rnd_context *ctx);
struct rnd_slot *rnd_slot_acquire(struct rnd_context *ctx);
void rnd_slot_release(struct rnd_context *ctx, struct rnd_slot *s);
enum rnd_result rnd_slots_init(struct rnd_context *ctx, struct rnd_error *err);
void rnd_slots_release(struct rnd_context *ctx);

#endif
