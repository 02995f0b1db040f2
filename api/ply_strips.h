/*
 * api/ply_strips.h — rewrites a PLY whose surface is a `tristrips` element as one with a `face`
 * element of triangles (see ply_strips.c). Pure function of the bytes; thread-safe.
 */
#ifndef UMBRA_API_PLY_STRIPS_H
#define UMBRA_API_PLY_STRIPS_H

#include <stddef.h>
#include <stdint.h>

/* A malloc'd PLY (you free it, *out_len bytes) with the strips as triangles, or NULL when the
 * file has no tristrips element (or a face element too, or anything it does not understand:
 * the caller then reads the original). */
uint8_t *api_ply_strips_to_faces(const uint8_t *data, size_t len, size_t *out_len);

#endif
