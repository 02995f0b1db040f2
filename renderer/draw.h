/*
 * renderer/draw.h — one object's draw: where its triangles lie in the slot's buffers, what it
 * covers, and how the passes draw it. The render plan (render_plan.c) makes every draw from the
 * scene before anything is written; upload.c then writes each object's triangles where its
 * draw says, and record.c draws them. No Vulkan.
 */
#ifndef UMBRA_RENDERER_DRAW_H
#define UMBRA_RENDERER_DRAW_H

#include <stdbool.h>
#include <stdint.h>
#include "umbra/rnd_math.h"

struct draw {
	uint32_t first_index, index_count;
	uint32_t cam_first_index, cam_index_count;   /* what the camera passes draw: the same, or a
	                                                sphere's proxy (UMBRA_DRAW_SPHERE, proxy.h) */
	uint32_t cam_first_vertex;                   /* the proxy's first vertex */
	uint32_t first_vertex, vertex_count;
	/* What the environment's shadow maps may draw instead (caster_level.h): a mesh's caster
	 * level, at env_first_vertex; env_index_count 0: none. env_error: its error, world units;
	 * env_raise: how far it is drawn away from the light (env_error, 0 with UMBRA_CASTER_BIAS=0). */
	uint32_t env_first_index, env_index_count, env_first_vertex, env_vertex_count;
	float env_error, env_raise;
	struct rnd_aabb bounds;
	double area;         /* world-space area of its triangles (renderer/cost.h) */
	uint32_t material;
	uint32_t flags;      /* UMBRA_DRAW_* */
	bool cast, cull_back;
	bool closed;         /* sphere / box / cylinder: back faces never show from outside */
	bool single_sided;   /* double_sided: false */
	bool masked;         /* alpha_mode MASK or BLEND (dithered): alpha-tested depth passes */
	uint32_t texture_set; /* slot->texture_sets index: 0 = white, 1 + i = textured material i */
	uint32_t tex_bits;    /* (1 << UMBRA_TEX_*) its material samples (| UMBRA_TEXBIT_UV1) */
};

#endif
