/*
 * renderer/mesh — tessellation of the contract's shapes into world-space triangles.
 *
 * Usage: rnd_mesh_counts() tells how many vertices and indices an object needs; the caller
 * reserves that much (usually straight in a mapped GPU buffer) and rnd_mesh_write() fills it.
 * Vertices are in world space (object.model applied; normals by the inverse transpose,
 * renormalised); a negative-determinant model swaps the winding so front faces stay front.
 * Front faces are counter-clockwise seen from outside, as in glTF.
 *
 * Tessellation (contract §2): plane = 2 triangles in XZ, normal +Y; box = 6 faces x 2
 * triangles with flat normals; sphere = UV sphere of `segments` longitudes x segments/2
 * latitudes (smooth normals, poles as triangle fans); cylinder = `segments` side quads with
 * smooth normals + two capped fans with flat normals; mesh = as given (flat normals computed
 * when none given; with no indices, the vertices are a triangle list). Meshes carry their
 * vertex colours and tangents (model matrix applied, w flipped by a mirroring one); other
 * shapes get white and +x.
 * Pure C, no Vulkan, thread-safe.
 */
#ifndef UMBRA_RENDERER_MESH_H
#define UMBRA_RENDERER_MESH_H

#include <stdint.h>
#include "umbra/rnd.h"
#include "umbra/rnd_math.h"

/* 40 bytes: lavapipe pays per vertex fetched, so colour and tangent are 8-bit (the colour
 * linear RGBA unorm, the tangent xyzw snorm: a direction to ~0.5 degrees, w the sign). */
struct rnd_vertex {
	float pos[3];
	float nrm[3];
	float uv[2];
	uint8_t color[4];
	int8_t tangent[4];
};

/* Vertex and index counts rnd_mesh_write() will produce for o. */
void rnd_mesh_counts(const struct rnd_object *o, uint32_t *vertex_count, uint32_t *index_count);

/* Writes the object's vertices and indices (indices offset by base_vertex) and grows
 * *bounds by the world-space vertices. Returns RND_ERR_INVALID (message in err) for a mesh
 * whose indices reference missing vertices or whose model matrix is singular. */
enum rnd_result rnd_mesh_write(const struct rnd_object *o, struct rnd_vertex *vertices, uint32_t *indices,
                               uint32_t base_vertex, struct rnd_aabb *bounds, struct rnd_error *err);

/* rnd_mesh_write() of an object rnd_mesh_measure() accepted: a mesh's arrays are not checked
 * again, and no bounds are grown (the measure has them: tests/unit/test_render_plan.c checks
 * that they are the write's). */
enum rnd_result rnd_mesh_write_measured(const struct rnd_object *o, struct rnd_vertex *vertices, uint32_t *indices,
                                        uint32_t base_vertex, struct rnd_error *err);

/* The second uv set of the count vertices rnd_mesh_write() wrote for o at vertices (the same
 * order), into out (2 floats each): o->uvs1 where it has them, else each vertex's own uv, so
 * a slot that asks for set 1 on an object without it reads set 0. */
void rnd_mesh_write_uv1(const struct rnd_object *o, const struct rnd_vertex *vertices, uint32_t count, float *out);

/* The world-space area of the index_count / 3 triangles at indices (as rnd_mesh_write leaves
 * them: offset by base_vertex) over vertices (the buffer's start, vertex 0 = base 0): exact up
 * to RND_MESH_AREA_SAMPLES triangles, past it estimated from that many, evenly strided. */
#define RND_MESH_AREA_SAMPLES 16384u
double rnd_mesh_area(const struct rnd_vertex *vertices, const uint32_t *indices, uint32_t index_count);

/* What rnd_mesh_write() would write for o (the render plan's measure of each draw, made before
 * anything is written): the world bounds it would grow *bounds by (the same floats: the same
 * transform of the same positions), the world area rnd_mesh_area() would find there, and the
 * same errors. A mesh is measured from its arrays, without writing; an analytic shape (small:
 * its level of detail bounds them) is written, with base vertex 0, into keep_vertices and
 * keep_indices (rnd_mesh_counts() of each) where the caller gives them, so that the upload
 * copies it instead of writing it again, else its shape alone into scratch memory. */
enum rnd_result rnd_mesh_measure(const struct rnd_object *o, struct rnd_vertex *keep_vertices, uint32_t *keep_indices,
                                 struct rnd_aabb *bounds, double *area, struct rnd_error *err);

/* Object-space bounds before any tessellation (cheap; for culling and camera derivation). */
void rnd_mesh_local_bounds(const struct rnd_object *o, struct rnd_aabb *out);

#endif
