/*
 * renderer/env.h — the environment's light on the device: an equirectangular map (a user's, or
 * the built-in studio of env_studio.c) prefiltered once for image-based lighting and kept for
 * the renders after it, like shadow maps.
 *
 * Per map (env_build.c records it, in the first submit of the render that needs it first):
 *   - the map itself as RGBA16F with its mip chain (built on the CPU), for the background and as
 *     the prefilter's source;
 *   - a cube map prefiltered for the GGX lobe (shaders/env_prefilter.comp), a mip level per
 *     roughness step: level 0 the mirror, the last roughness 1 (split sum, Karis 2013; the
 *     source read at the mip of each sample's solid angle, "filtered importance sampling");
 *   - on the CPU (env_analysis.h): the irradiance's spherical harmonics, and the median cut of
 *     its light from which every request takes its shadow directions.
 * Per context, once: the split-sum table (shaders/env_brdf.comp, UMBRA_ENV_BRDF_SIZE²).
 * The built-in studio: generated and prefiltered once per process, on its first use.
 *
 * Lifetime: rnd_env_acquire() (before any shadow tile is granted: a render never waits for a
 * map while it holds tiles) to rnd_env_done() (after every submit of the render completed). An
 * entry in use is never evicted; one being built by another render is waited for. At most
 * RND_ENV_ENTRIES maps are kept, the least recently used replaced.
 * Threading: every call takes the cache's mutex; what a use holds is its render's.
 */
#ifndef UMBRA_RENDERER_ENV_H
#define UMBRA_RENDERER_ENV_H

#include "env_analysis.h"
#include "internal.h"

#define RND_ENV_ENTRIES 4u
#define RND_ENV_MAX_LEVELS 8u         /* of the prefiltered cube: 256^2 faces down to 2^2 */
#define RND_ENV_MAX_MAP_WIDTH 2048u   /* wider maps are halved (box) until they fit */
#define RND_ENV_STUDIO_W 512u
#define RND_ENV_STUDIO_H 256u

/* env_studio.c: the built-in studio, w x h linear RGB floats (rows from the zenith). */
void rnd_env_studio(float *rgb, uint32_t w, uint32_t h);

struct rnd_env_entry;
struct rnd_slot;

/* What one render holds of its environment. */
struct rnd_env_use {
	struct rnd_env_entry *entry;  /* NULL: the scene has no map (ambient only) */
	bool build;                   /* this render prefilters the map (recorded into its first submit) */
	bool build_brdf;              /* ... and the context's split-sum table */
	double ms;                    /* CPU time spent here for this render (analysis, staging) */
	/* The shadow directions in the scene's frame (rnd_env_shadow_dirs): the first `mapped` get
	 * shadow maps, the rest (below a ground) are only weighed. */
	uint32_t ndirs, mapped;
	struct rnd_env_dir dirs[RND_MAX_ENV_DIRECTIONS + RND_ENV_GROUND_DIRS];
	bool ground;
	float ground_n[3];
};

/* The cache (no device work: pipelines are made on the first map). */
enum rnd_result rnd_env_init(struct rnd_context *ctx, struct rnd_error *err);
void rnd_env_release_all(struct rnd_context *ctx);
/* The map of env (source MAP or STUDIO; AMBIENT: use->entry NULL, RND_OK) found ready, or
 * claimed for this render to build (its pixels analysed and staged here; bins: the plan's bins
 * of the same map (rnd_env_plan_bins), which the build keeps instead of reading every texel
 * again; NULL: it bins the map). Waits for another render building the same map, or for a free
 * entry, until `deadline` (CLOCK_MONOTONIC seconds, 0 = none: RND_ERR_TIMEOUT). */
enum rnd_result rnd_env_acquire(struct rnd_context *ctx, const struct rnd_environment *env,
                                const struct rnd_env_bins *bins, double deadline, struct rnd_env_use *use,
                                struct rnd_error *err);
/* The shadow directions for this render: the render plan's (rnd_env_plan_dirs, from the bins
 * rnd_env_plan_bins gave it: the same as the entry's). Pure once acquired. */
void rnd_env_shadow_dirs(struct rnd_env_use *use, const struct rnd_env_plan *plan);
/* For a render plan (render_plan.h): the bins of env's map (*out malloc'd; NULL: no map, or no
 * shadow directions asked), the cache's when it holds the map, else binned now. RND_ERR_INVALID
 * for a map without pixels (as rnd_env_acquire). */
enum rnd_result rnd_env_plan_bins(struct rnd_context *ctx, const struct rnd_environment *env, struct rnd_env_bins **out,
                                  struct rnd_error *err);
/* Records the build (map upload, prefilter, table) when use->build: into the render's first
 * command buffer, before anything samples it. */
void rnd_env_record(struct rnd_context *ctx, VkCommandBuffer cmd, const struct rnd_env_use *use);
/* The umbra_env block of a view: inv_view_proj the camera's clip -> world, first_light the
 * index of the first environment direction among the frame's lights, pass_scale the view's
 * pixels per texel of its environment pass (env_pass.h). */
void rnd_env_write(const struct rnd_env_use *use, const struct rnd_environment *env, const float inv_view_proj[16],
                   uint32_t first_light, uint32_t pass_scale, struct umbra_env *out);
/* The images of bindings UMBRA_BINDING_ENV_SPECULAR, _MAP and _BRDF (the slot's white stand-ins
 * without a map). */
void rnd_env_images(const struct rnd_context *ctx, const struct rnd_env_use *use, const struct rnd_slot *s,
                    VkDescriptorImageInfo out[3]);
/* The render's end: ok = its submits completed (a build is then ready for others; else undone).
 * gpu_busy: a submit may still run (the context failed): what it uses is left alone. */
void rnd_env_done(struct rnd_context *ctx, struct rnd_env_use *use, bool ok, bool gpu_busy);
/* Maps kept and builds since create (rnd_context_stats). */
void rnd_env_stats(struct rnd_context *ctx, uint32_t *maps, uint64_t *builds);
/* Drops maps unused for idle_s seconds (not the studio); bytes released. */
uint64_t rnd_env_trim(struct rnd_context *ctx, double idle_s);

/* ---- env_build.c: the device side, under the cache's mutex ---- */

struct rnd_env_gpu {
	VkDescriptorSetLayout set_layout;  /* UMBRA_ENVC_BINDING_*: the compute passes' set */
	VkPipelineLayout layout;
	VkPipeline prefilter, brdf_pipe;
	VkSampler map_sampler;             /* linear, mips, u repeat, v clamp (the equirectangular map) */
	VkSampler cube_sampler;            /* linear, mips, clamp */
	VkSampler lut_sampler;             /* linear, clamp, level 0 */
	struct rnd_image_res brdf;
	VkDescriptorPool brdf_pool;
	VkDescriptorSet brdf_set;
	bool ready;                        /* the above made */
};

/* One map's device objects and what the CPU learned of it. */
struct rnd_env_maps {
	uint32_t map_w, map_h, map_levels;
	uint32_t spec_side, spec_levels;
	struct rnd_image_res map, spec;    /* spec: a cube view of every level */
	VkImageView level_views[RND_ENV_MAX_LEVELS];   /* spec's levels as 2D arrays (the prefilter's output) */
	struct rnd_buffer staging;         /* the map's chain as RGBA16F, until the build completed */
	VkDescriptorPool pool;             /* the prefilter's sets, until the build completed */
	VkDescriptorSet sets[RND_ENV_MAX_LEVELS];
};

enum rnd_result rnd_env_gpu_init(struct rnd_context *ctx, struct rnd_env_gpu *g, struct rnd_error *err);
void rnd_env_gpu_release(struct rnd_context *ctx, struct rnd_env_gpu *g);
/* Makes m's images, staging (the map's mip chain as halves) and prefilter sets for a w x h
 * map rgb; name says whose. */
enum rnd_result rnd_env_maps_create(struct rnd_context *ctx, const struct rnd_env_gpu *g, const float *rgb, uint32_t w,
                                    uint32_t h, const char *name, struct rnd_env_maps *m, struct rnd_error *err);
/* Frees what only the build needs (staging, sets), once it has completed. */
void rnd_env_maps_built(struct rnd_context *ctx, struct rnd_env_maps *m);
void rnd_env_maps_destroy(struct rnd_context *ctx, struct rnd_env_maps *m);
uint64_t rnd_env_maps_bytes(const struct rnd_env_maps *m);
void rnd_env_record_maps(VkCommandBuffer cmd, const struct rnd_env_gpu *g, const struct rnd_env_maps *m);
void rnd_env_record_brdf(VkCommandBuffer cmd, const struct rnd_env_gpu *g);

#endif
