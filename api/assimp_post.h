/*
 * api/assimp_post — what Assimp 5.2's post-processing does to a plain mesh, done here for the
 * readers that take OBJ and PLY files without Assimp (api/obj_import.h, api/ply_import.h):
 * the steps api/model_import.c asks of Assimp for those formats, in its order —
 * aiProcess_Triangulate (of quads: the concave corner's fan, and the "ngon encoding" that
 * turns some triangles), aiProcess_GenSmoothNormals (a face normal written into each of its
 * corners' slots, the last face's winning where faces share a vertex; then the slots of all
 * vertices within 1e-4 of the diagonal of the vertices' box summed and normalised, every
 * vertex taking the normal of the last vertex, in vertex order, whose search met it) and
 * aiProcess_JoinIdenticalVertices (vertices at one position joined where their normals and
 * first uv sets differ by at most 1e-5, colours not compared, unused vertices dropped,
 * numbered in order) — so that the model is the one the Assimp path made: the same vertices
 * in the same order, the same triangles.
 *
 * Two differences (tests/unit/test_obj_ply.c and build/tests/import_compare compare the two
 * paths): a made normal is a sum of face normals in another order than Assimp's (it sums in
 * the order of its spatial sort, std::sort's), so it can differ in its last bits — where the
 * normals summed nearly cancel (a sheet's two sides, a fold: the sum is then mostly rounding,
 * and the order decides its direction) this gives up and the file goes to Assimp; and
 * Assimp's join compares, by chance of its hash table's buckets, vertices less than 1e-5 apart
 * that are not at one position, which this never joins.
 *
 * Threading: no shared state. Memory: scratch malloc'd, the result in the caller's arena.
 */
#ifndef UMBRA_API_ASSIMP_POST_H
#define UMBRA_API_ASSIMP_POST_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "arena.h"
#include "model.h"

/* A mesh as an Assimp importer hands it to post-processing. */
struct api_assimp_mesh {
	const float *pos;          /* xyz a vertex, finite */
	const float *nrm;          /* xyz a vertex (the file's), or NULL: made (GenSmoothNormals) */
	const float *uv;           /* Assimp's uvw a vertex (w 0 where the file has two), or NULL */
	const float *col;          /* RGBA a vertex (Assimp's floats), or NULL */
	uint32_t nv;
	const uint32_t *corners;   /* the faces' vertices, face after face, each < nv */
	const uint8_t *sizes;      /* each face's corner count: 3 or 4 */
	uint32_t nfaces;
	bool quads;                /* some face has 4 corners (Assimp triangulates the mesh then) */
	bool no_join;              /* JoinIdenticalVertices left out: every vertex kept, in order */
};

/* Not done here: the caller imports the file through Assimp instead (a search for close
 * vertices that would take too long, positions packed too closely to group cheaply). */
#define API_ASSIMP_POST_GIVE_UP (-2)

/* in post-processed into *out (arena memory: positions, normals, uvs as umbra keeps them, v
 * flipped, colours as RGBA8, indices; material 0; out->weld_group_ when every vertex was
 * used), *bytes what it holds added: API_WIRE_OK, API_WIRE_OVER_MEMORY or
 * API_ASSIMP_POST_GIVE_UP. */
int api_assimp_post(const struct api_assimp_mesh *in, struct api_arena *arena, struct api_model_mesh *out,
                    size_t *bytes);

/* Assimp's fast_atoreal_move<float> (and <double>, *dbl) on s[0..n): the same float for the
 * same digits (it is not strtof: the digits after the point are read as an integer, at most
 * 15, scaled by a table of doubles, added in float; the exponent by powf). Takes an optional
 * sign, digits, optionally a point and digits, optionally e or E, a sign and digits; returns
 * the characters read, 0 for anything else (no digit first, nan, inf, a comma, an empty
 * exponent, more than 18 digits before the point or 4 in the exponent). */
size_t api_assimp_atof(const char *s, size_t n, float *out);
size_t api_assimp_atod(const char *s, size_t n, double *out);

#endif
