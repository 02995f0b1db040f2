/*
 * umbra renderer — what a render plan says (struct rnd_plan, umbra/rnd.h): the decisions of one
 * render, for `explain` to show (api/plan_json.c prints them as JSON), and after
 * rnd_render_plan() what its steps measured (EXPLAIN ANALYZE).
 *
 * Usage:
 *   struct rnd_plan_info info; rnd_plan_info(plan, &info);
 *   for (uint32_t k = 0; k < info.maps; k++) { struct rnd_plan_map_info m; rnd_plan_map(plan, k, &m); ... }
 *   (the same for views, objects and passes)
 * Ownership: nothing is allocated; every string is static text, every figure a copy.
 * Threading: as the plan (one thread at a time).
 */
#ifndef UMBRA_RND_PLAN_H
#define UMBRA_RND_PLAN_H

#include "umbra/rnd.h"
#include "umbra/rnd_math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The render as a whole. Counts run over every view of the sheet. */
struct rnd_plan_info {
	uint32_t width, height;             /* one view */
	uint32_t views, columns, rows;      /* the sheet */
	uint32_t objects, lights, maps, passes;
	uint32_t maps_drawn;                /* shadow views the plan draws (a cube map: 6) */
	uint32_t maps_cached;               /* shadow views the cache held when the plan was made */
	uint64_t texels_drawn;              /* the texels of the maps drawn */
	uint64_t shadow_triangles;          /* casters' triangles the maps drawn draw */
	uint64_t camera_triangles;          /* what the cameras draw, each view counted */
	uint32_t sphere_proxies;            /* spheres the camera draws as a proxy (renderer/proxy.h) */
	uint32_t visibility_views;          /* views whose shadows come from the visibility pass */
	uint32_t pixel_shaded_views;        /* views shaded once per pixel centre (deferred.h) */
	uint64_t vertices, indices;         /* the geometry the render writes */
	/* The environment map's shadows (env_analysis.h): the directions drawn as shadow maps (each a
	 * directional light after the scene's: struct rnd_plan_map_info.environment), and those a
	 * ground hides, only weighed; whether the scene stands on such a ground. */
	uint32_t env_directions, env_weighed;
	bool env_ground;
	struct rnd_estimate estimate;       /* memory (admission reads it) */
	struct rnd_aabb bounds, casters;    /* the scene's, and what casts shadows */
	double estimate_ms;                 /* the deadline's estimates summed (lavapipe milliseconds) */
	double plan_ms;                     /* how long the plan took to make */
	bool analyzed;                      /* rendered to its end: `actual` holds what it measured */
	struct rnd_timings actual;
};
void rnd_plan_info(const struct rnd_plan *plan, struct rnd_plan_info *out);

/* One light's shadow maps: its tiles in the atlas. */
struct rnd_plan_map_info {
	uint32_t light;                     /* among the scene's lights, then the environment's directions */
	int32_t environment;                /* -1: a light of the scene; k: the environment's direction k */
	float direction[3];                 /* environment: towards the sky, the scene's frame */
	float share;                        /* environment: its region's part of the map's light */
	const char *light_type;             /* "directional", "spot", "point", "environment" */
	const char *kind;                   /* "fit", "cascades", "clipmap", "spot", "cube" */
	uint32_t tiles;                     /* 1, 6 cube faces, or the cascades / levels */
	uint32_t resolution;                /* texels a side of each tile */
	uint32_t asked;                     /* the side the light's plan asked for, before the atlas */
	const char *size;                   /* what chose `asked` (below) */
	const char *fitted;                 /* why resolution < asked ("" when equal) */
	const char *filter;                 /* "hard", "pcf", "pcss", "vsm", "evsm" */
	uint32_t pcf_radius;
	bool pcss_bounds;                   /* the PCSS depth bounds drawn with the map */
	const char *state;                  /* "drawn", "cached", "every view" */
	const char *why;                    /* why it is drawn or not */
	uint64_t key;                       /* the cache key (0: follows the camera, never kept) */
	uint32_t drawn_views;               /* views that draw it */
	uint64_t texels;                    /* texels drawn over every view */
	uint64_t triangles;                 /* casters' triangles drawn over every view */
	double estimate_ms;                 /* over every view */
	bool analyzed, hit;                 /* measured: the grant found it cached */
};
void rnd_plan_map(const struct rnd_plan *plan, uint32_t k, struct rnd_plan_map_info *out);

/* One view (a cell of the sheet). */
struct rnd_plan_view_info {
	float position[3], forward[3], up[3];
	float znear, zfar;
	bool orthographic;
	float fov_y, ortho_height;          /* radians; world units */
	uint32_t shadow_views, maps_drawn;
	uint64_t texels_drawn, shadow_triangles, camera_triangles;
	bool contact;                       /* a depth pass for contact shadows */
	bool env_pass;                      /* the environment's shadows from their pass (env_pass.h) */
	bool pixel_shading;                 /* shaded once per pixel centre (deferred.h) */
	const char *pixel_shading_why;
	bool visibility;                    /* shadows from the visibility pass */
	const char *visibility_why;
	double shadow_estimate_ms, row_ms, band_ms, main_estimate_ms;
	bool analyzed;
	double shadow_ms, main_ms;          /* measured (GPU) */
	uint32_t bands;                     /* main-pass submits */
};
void rnd_plan_view(const struct rnd_plan *plan, uint32_t v, struct rnd_plan_view_info *out);

/* One object of the rnd_scene (a model brings several). */
struct rnd_plan_object_info {
	const char *shape;                  /* "plane", "box", "sphere", "cylinder", "mesh" */
	const char *detail;                 /* its level of detail, in words */
	uint32_t segments, asked;           /* sphere / cylinder: drawn with, asked for */
	uint32_t level, levels;             /* a mesh with levels: drawn (0 = full), how many it has */
	uint64_t triangles;                 /* written (what the shadow maps draw) */
	uint64_t camera_triangles;          /* what the cameras draw of it (a proxy's, or the same) */
	bool proxy;
	bool casts;
	const char *cast_why;
	bool in_casters_box;                /* sizes a `fit` sun map */
	/* Its caster level for the environment's shadow maps (api/model_caster.h), if it has one
	 * laid out: triangles, error (world units), and how many of the first view's maps draw it
	 * (those whose texel its error fits; the rest draw `triangles`). caster_triangles 0: none. */
	uint64_t caster_triangles;
	float caster_error;
	uint32_t caster_maps;
};
void rnd_plan_object(const struct rnd_plan *plan, uint32_t i, struct rnd_plan_object_info *out);

/* The passes in the order the render runs them. */
struct rnd_plan_pass_info {
	const char *pass;                   /* "upload", "shadow_map", "scene_depth", "environment",
	                                       "visibility", "main", "aov", "readback" */
	int32_t view;                       /* -1: the render's, not one view's */
	int32_t map, light, tile;           /* shadow_map: which (else -1) */
	uint32_t resolution;
	uint64_t texels, triangles;
	double estimate_ms;                 /* 0 where the cost model has none */
	const char *note;                   /* "" or what else the pass does (PCSS bounds, moments, ...) */
};
/* Fills out[0 .. min(n, max)) and returns n, the number of passes. */
uint32_t rnd_plan_passes(const struct rnd_plan *plan, struct rnd_plan_pass_info *out, uint32_t max);

#ifdef __cplusplus
}
#endif
#endif
