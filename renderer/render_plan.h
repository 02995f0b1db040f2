/*
 * renderer/render_plan.h — the render plan: every decision one render makes, made once, before
 * anything is allocated or written, by one pure function (rnd_plan_build, render_plan.c) from
 * the scene and what the plan needs to know of the context (struct rnd_plan_device: its limits,
 * its switches, which shadow maps its cache holds). Like a frame graph (Filament's fg/), the
 * plan is a value: the renderer executes it and nothing else (render.c), admission reads its
 * memory estimate (server/worker.c), and `explain` prints it (render_explain.c, with the
 * measured time of each step after the render: like PostgreSQL's EXPLAIN ANALYZE).
 *
 * What is decided where (each in the module named after it; render_plan.c only calls them, in
 * order, and keeps their answers):
 *   the views' sheet and the memory estimate ...... estimate.c
 *   each object's level of detail, sphere proxies .. lod.c, proxy.c
 *   each draw: where it lies, its bounds and area .. mesh.c (rnd_mesh_measure), draw.h
 *   the cameras ..................................... camera.c
 *   the environment's shadow directions, its pass ... env_analysis.c, env_shadow.c (as lights)
 *   what casts shadows, into which map .............. casters.c
 *   each light's maps: kind, size, filter, views .... plan.c
 *   the maps' tile sizes in the atlas ............... atlas.c (rnd_atlas_fit)
 *   cached maps' keys, and which the cache holds .... shadow_keys.c, shadow_cache.c (the probe)
 *   contact shadows' depth pass ..................... contact.c
 *   the visibility pass, pixel shading .............. visibility_plan.c
 *   the deadline's bands (cost estimates) ........... cost.c
 *
 * Ownership: rnd_plan_build fills a caller's struct rnd_plan and allocates what it points to;
 * rnd_plan_release frees it. The plan points into the scene, which must outlive it.
 * Threading: building reads only its inputs (and calls dev->cached, which must be thread-safe);
 * a built plan is read-only but for its `actual` member, which its one render fills.
 */
#ifndef UMBRA_RENDERER_RENDER_PLAN_H
#define UMBRA_RENDERER_RENDER_PLAN_H

#include "casters.h"
#include "draw.h"
#include "env_analysis.h"
#include "estimate.h"
#include "plan.h"
#include "mesh.h"
#include "proxy.h"

/* Vertices of analytic shapes (10 MB) the plan keeps as it measures them, so that the upload
 * copies instead of tessellating them a second time. */
#define RND_PLAN_KEEP_VERTICES (1u << 18)

/* What the plan needs to know of the context (render.c fills it from the rnd_context). */
struct rnd_plan_device {
	uint32_t max_width, max_height;        /* the context's largest view */
	uint32_t max_image_dimension;          /* the device's largest image side */
	uint32_t atlas_size;                   /* texels a side of the shadow atlases */
	uint64_t max_allocation;               /* the device's largest allocation (0: no limit) */
	uint32_t max_textures;                 /* distinct textures one scene may use */
	uint32_t moments_max_res;              /* largest moment map (moments.c rnd_moments_max_res) */
	bool moments;                          /* VSM / EVSM can be drawn (the moment atlas exists) */
	bool pcss_bounds;                      /* PCSS depth bounds can be drawn (their atlas exists) */
	float evsm_max_exponent;               /* largest EVSM exponent in the moment atlas's format */
	float evsm_max_exponent_fp16;          /* and in fp16 (vsm.precision "fp16") */
	bool visibility_pass;                  /* the device can run the visibility pass */
	int visibility_force;                  /* UMBRA_VISIBILITY: -1 unset, 0 off, 1 on */
	int env_pass_force;                    /* UMBRA_ENV_PASS: -1 unset, 0 off */
	bool caster_levels_off;                /* UMBRA_CASTER_LEVEL=0: no caster levels (caster_level.h) */
	bool caster_bias_off;                  /* UMBRA_CASTER_BIAS=0: drawn without their bias (tests: the acne) */
	bool pixel_shading;                    /* the device can shade per pixel (deferred.c) */
	int pixel_shading_force;               /* UMBRA_PIXEL_SHADING: -1 unset, 0 off */
	/* The environment map's bins (env.c rnd_env_plan_bins; NULL: no map, or no shadow directions
	 * asked), read while the plan is built (rnd_plan_create keeps them: struct rnd_plan.env_bins). */
	const struct rnd_env_bins *env_bins;
	/* Whether the cache holds a completed map of key (shadow_cache.c rnd_cache_probe); NULL:
	 * it holds none. */
	bool (*cached)(void *user, uint64_t key, uint32_t tiles, uint32_t res);
	void *cache_user;
};

/* Why a shadow view draws nothing in a view (struct rnd_view_plan.skip). */
enum rnd_map_skip {
	RND_SKIP_NONE,          /* drawn */
	RND_SKIP_CACHED,        /* the cache holds its map (the probe; the grant may find otherwise) */
	RND_SKIP_EARLIER_VIEW,  /* a map that does not follow the camera: view 0 drew it */
};

/* One light's maps: the tiles it takes in the atlas (granted once per render). */
struct rnd_map_plan {
	uint32_t light;
	uint32_t tiles;                        /* 1, 6 cube faces, or the cascades / clipmap levels */
	uint32_t want;                         /* the side the light's plan asks for (rnd_light_plan.resolution) */
	uint32_t res;                          /* the side granted: want, moment maps capped, fitted in the atlas */
	uint64_t key;                          /* 0: follows the camera (drawn by every view, never kept) */
	bool cached;                           /* the cache held it when the plan was made */
	bool moments_capped;                   /* want was over the device's moment map cap */
};

/* One view of the render (a sheet's cell). Its shadow plan is kept compact: shadow_views views
 * of the scene's lights (rnd_plan_view_shadows makes the struct the recorders read). */
struct rnd_view_plan {
	struct rnd_camera_plan cam;            /* as drawn: framed, near / far around the whole scene */
	uint32_t shadow_views, shadow_res;     /* rnd_shadow_plan.view_count, .resolution */
	struct rnd_light_plan *lights;         /* [light_count] */
	struct umbra_shadow_view *views;       /* [shadow_views]: rect[2] the tile side, rect[3] the atlas's;
	                                          rect[0], rect[1] (where) come with the grant */
	uint32_t *view_light;                  /* [shadow_views] */
	bool *view_ortho;                      /* [shadow_views] */
	uint8_t *skip;                         /* [shadow_views] enum rnd_map_skip */
	double *map_ms;                        /* [shadow_views] estimated milliseconds (cost.c) */
	uint64_t *map_tris;                    /* [shadow_views] casters' triangles it draws */
	bool contact;                          /* the view's depth for contact shadows */
	bool vis;                              /* shadows from the visibility pass */
	uint8_t vis_why;                       /* enum rnd_vis_why */
	bool env_pass;                         /* the environment's shadows from its pass (env_pass.h) */
	bool deferred;                         /* shaded once per pixel centre (pixel shading, deferred.h):
	                                          the visibility pass's passes run then even without vis */
	uint8_t deferred_why;                  /* enum rnd_pixel_why */
	uint64_t camera_triangles;
	double row_ms, band_ms;                /* the main pass: per row, per band (cost.c) */
};

/* What the render measured (EXPLAIN ANALYZE), filled by the render that executes the plan. */
struct rnd_plan_actual {
	bool done;                             /* the render ran to its end (RND_OK) */
	bool *hit;                             /* [nmaps] the grant found the map cached */
	double upload_ms, readback_ms;
	double *shadow_ms, *main_ms;           /* [nviews] GPU milliseconds */
	uint32_t *bands;                       /* [nviews] main-pass submits */
	struct rnd_timings tm;
};

struct rnd_plan {
	const struct rnd_scene *sc;
	struct rnd_plan_device dev;
	struct rnd_sheet sheet;
	struct rnd_estimate est;
	/* objects */
	struct draw *draws;                    /* [object_count] as uploaded: cull_back for no camera yet */
	uint32_t *lod;                         /* [object_count] segments or level (rnd_lod_apply) */
	struct rnd_proxy *proxies;             /* [object_count] final, for the one camera (outline 0: none) */
	uint8_t *cast_why;                     /* [object_count] enum rnd_cast_why */
	/* [object_count] an analytic shape's triangles as rnd_mesh_write writes them at base 0,
	 * where the plan kept them (at most RND_PLAN_KEEP_VERTICES in all): the upload copies them
	 * (NULL: it writes the object). */
	struct rnd_vertex **kept_vertices;
	uint32_t **kept_indices;
	uint64_t vertices, indices;            /* the slot's buffers: counts */
	uint32_t sphere_proxies;
	struct rnd_aabb bounds, obj_bounds, casters;
	uint64_t caster_key;
	/* The environment's shadow directions (env_analysis.h), and the scene as the shadow passes
	 * see it: sc's lights, then a directional light per mapped direction (env_shadow.c), as
	 * many as fit in UMBRA_MAX_LIGHTS. Every light index below counts in esc. */
	struct rnd_env_plan env;
	struct rnd_scene esc;
	struct rnd_light lights[UMBRA_MAX_LIGHTS];
	/* views and maps */
	uint32_t nviews;
	struct rnd_view_plan *views;           /* [nviews] */
	uint32_t nmaps;
	struct rnd_map_plan maps[UMBRA_MAX_LIGHTS];
	struct rnd_plan_actual actual;
	struct rnd_context *context;           /* the context it was made on (render.c) */
	/* rnd_plan_create's: the environment map's bins it was built from (dev.env_bins; NULL:
	 * none), freed by rnd_plan_destroy. The render's build of the map keeps them (env.c
	 * rnd_env_acquire): a map's texels are read for its bins once. */
	struct rnd_env_bins *env_bins;
	double plan_ms;                        /* how long rnd_plan_create took */
	void *mem;                             /* what the plan allocated (render_plan.c) */
};

/* Builds the whole plan of scene sc on a context described by dev. RND_OK, or the error the
 * render would have failed with (the same codes, members and messages: invalid or over a
 * limit); on failure the plan holds nothing (rnd_plan_release is still safe). */
enum rnd_result rnd_plan_build(const struct rnd_scene *sc, const struct rnd_plan_device *dev, struct rnd_plan *p,
                               struct rnd_error *err);
void rnd_plan_release(struct rnd_plan *p);

/* plan_maps' decisions about map m, in words: why its side is under the one asked for ("" when
 * it is not); whether it is drawn ("drawn", "cached", "every view"), and why (*why). */
const char *rnd_map_plan_fitted(const struct rnd_plan *p, const struct rnd_map_plan *m);
const char *rnd_map_plan_state(const struct rnd_map_plan *m, const char **why);

/* View v's shadow plan as the recorders read it (out: views' skip from the plan's prediction;
 * the executor replaces it with the grant's answer). */
void rnd_plan_view_shadows(const struct rnd_plan *p, uint32_t v, struct rnd_shadow_plan *out);
/* Sets draws[i].cull_back (draws: a copy of the plan's) as view v's camera allows. */
void rnd_plan_view_cull(const struct rnd_plan *p, uint32_t v, struct draw *draws);

#endif
