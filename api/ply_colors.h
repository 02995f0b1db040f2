/*
 * api/ply_colors — PLY files whose colours are on the faces (per-face red/green/blue
 * properties, as in cycloidal.ply and many CAD exports) rewritten with them on the vertices
 * before Assimp reads them: Assimp 5.2 reads a PLY's vertex colours but drops face colours, and
 * the model rendered white. Also tells a point cloud (vertices, no faces) from a surface, so
 * that its refusal says what it is. Pure functions of the bytes (untrusted: they run in the
 * import sandbox), bounded by the input. Thread-safe.
 */
#ifndef UMBRA_API_PLY_COLORS_H
#define UMBRA_API_PLY_COLORS_H

#include <stddef.h>
#include <stdint.h>

/* A malloc'd PLY (you free it, *out_len bytes) in the same format (ascii or binary, either
 * byte order) with one vertex per face corner (the corner's vertex, all its properties, plus
 * the face's red, green, blue and alpha as uchar) and faces of those vertices; Assimp joins the
 * corners again where position and colour agree. NULL when the file is not a PLY of exactly a
 * vertex and a face element, its faces carry no colour, its vertices carry their own, or
 * anything it does not understand (the caller then reads the original). */
uint8_t *api_ply_face_colors_to_vertices(const uint8_t *data, size_t len, size_t *out_len);

/* The vertex count of a PLY with vertices and no surface (no face or tristrips element, or
 * none in them): a point cloud. 0 for anything else. */
uint64_t api_ply_point_cloud(const uint8_t *data, size_t len);

#endif
