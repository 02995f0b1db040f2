/*
 * renderer/proxy — what the camera passes draw for an analytic sphere: a cap of few triangles
 * facing the camera whose outline is as fine as the level of detail asks, and whose fragments
 * shade the true sphere (shaders/facet.glsl sphere_point: the point where the fragment's view
 * ray meets it, its exact normal).
 *
 * Why: lavapipe shades a whole 4x4 block of pixels once per triangle that touches it. A sphere
 * tessellated finely enough for its outline (1/32 pixel, lod.h) and for its shadow maps (1/8
 * texel) has thousands of triangles of a few pixels each, most of them inside the outline
 * where nothing shows their size: thumb-512's sphere cost the main pass ~10 ms over the
 * ground alone, a 500-triangle one 2.7. Inside the outline only the depth test needs the mesh
 * (against other objects that meet the sphere), so the cap's vertices lie on the sphere at
 * most RND_PROXY_STEP_PIXELS apart in depth error; the shadow passes keep the tessellated
 * sphere.
 *
 * A sphere gets a proxy (rnd_proxy_plan) when one camera renders it (single view), from
 * outside it and clear of the near plane (a fitted camera: when the render's own placement
 * agrees with the plan's, rnd_proxy_fits); when its model scales it
 * uniformly; when its material has no texture and is opaque (the proxy carries no uv), and no
 * light marches contact shadows (they march the camera's depth, which the proxy holds only to
 * within its bound). Otherwise, and with UMBRA_SPHERE_PROXY=0, the sphere's mesh is drawn.
 * A proxy's vertices carry the sphere: normal = position - centre, uv = (radius, lift), and its
 * draws are flagged UMBRA_DRAW_SPHERE. lift: the shadow maps hold the tessellated sphere, whose
 * vertices lie outside the true one by up to half a chord error (rnd_lod_radius); a shadow
 * lookup on the true sphere would find itself behind its own caster there (specks on the lit
 * side), so the lookups look from the sphere raised by that much, outside every facet.
 *
 * Pure C, no Vulkan, no allocation, thread-safe.
 */
#ifndef UMBRA_RENDERER_PROXY_H
#define UMBRA_RENDERER_PROXY_H

#include <stdbool.h>
#include <stdint.h>
#include "mesh.h"
#include "plan.h"

/* Depth error of the cap's chords inside the outline, in pixels of the sphere's nearest point:
 * where another surface meets the sphere, their line of intersection moves by about this much. */
#define RND_PROXY_STEP_PIXELS 1.0f

struct rnd_proxy {
	uint32_t outline;        /* segments of the outline ring; 0: no proxy, draw the mesh */
	float step;              /* largest angle between neighbouring vertices inside (radians) */
	float centre[3], radius; /* the sphere, world */
	float axis[3];           /* unit, from the centre towards the camera */
	float edge;              /* angle of the outline from the axis: acos(radius / distance) */
	float count_edge;        /* the edge the rings' vertex counts were planned with (they stay) */
	float outline_radius;    /* radius of the outline ring, raised so its chords straddle it */
	float lift;              /* how far the shadow passes' tessellated sphere reaches outside it */
	float eye[3];            /* the camera it was planned for: position (perspective) */
	float pixel;             /* world size of a pixel at the sphere's nearest point */
	bool ortho;
};

/* Whether sphere o of sc gets a proxy for camera cam (w x h pixels; segments: what the level of
 * detail tessellates it with) and its shape; false (out->outline 0) where the mesh is drawn. */
bool rnd_proxy_plan(const struct rnd_scene *sc, const struct rnd_object *o, const struct rnd_camera_plan *cam, float w,
                    float h, uint32_t segments, struct rnd_proxy *out);

/* Whether cam, the camera a render actually draws with, is the one p was planned for: up to a
 * move of the outline by 1/128 pixel. A fitted camera is placed from the tessellated shapes'
 * bounds, which the plan (lod.c) estimated from the shapes as asked. */
bool rnd_proxy_fits(const struct rnd_proxy *p, const struct rnd_camera_plan *cam);

/* Makes p that of camera cam where it was planned for another (rnd_proxy_fits; *moved then
 * true: its vertices must be written again): the same counts of vertices and indices, placed
 * for cam. False (p->outline 0: draw the mesh) where cam is inside the sphere or its near or
 * far plane cuts it. */
bool rnd_proxy_refit(struct rnd_proxy *p, const struct rnd_camera_plan *cam, bool *moved);

/* Vertices and indices of proxy p (0 when none). */
void rnd_proxy_counts(const struct rnd_proxy *p, uint32_t *vertex_count, uint32_t *index_count);

/* Writes them, indices offset by base_vertex; counter-clockwise seen from the camera. */
void rnd_proxy_write(const struct rnd_proxy *p, struct rnd_vertex *v, uint32_t *idx, uint32_t base_vertex);

#endif
