/*
 * api/ply_header — the header of a PLY file, and its values read one at a time (ASCII tokens,
 * or binary in either byte order), for the few rewrites umbra does before Assimp reads a PLY
 * (api/ply_strips.h, api/ply_colors.h share it). Pure functions of the bytes; every read is bounded by
 * the input (untrusted: they run inside the import sandbox). Thread-safe.
 *
 * Usage:
 *   struct api_ply_header h;
 *   if (!api_ply_header_parse(d, len, &h)) -> not a PLY this understands (leave it to Assimp)
 *   struct api_ply_reader r = {d, len, h.data, h.format};
 *   double v; if (!api_ply_read(&r, h.elems[0].props[0].type, &v)) -> cut short
 */
#ifndef UMBRA_API_PLY_HEADER_H
#define UMBRA_API_PLY_HEADER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

enum { API_PLY_MAX_PROPS = 32, API_PLY_MAX_ELEMS = 16 };

enum api_ply_type { API_PLY_NONE, API_PLY_I8, API_PLY_U8, API_PLY_I16, API_PLY_U16, API_PLY_I32, API_PLY_U32,
                    API_PLY_F32, API_PLY_F64 };
enum api_ply_format { API_PLY_ASCII, API_PLY_LE, API_PLY_BE };

struct api_ply_prop {
	char name[32];
	bool list;
	enum api_ply_type count_type;   /* lists only */
	enum api_ply_type type;         /* the scalar's, or a list's items' */
};

struct api_ply_elem {
	char name[32];
	uint64_t count;
	int nprops;
	struct api_ply_prop props[API_PLY_MAX_PROPS];
};

struct api_ply_header {
	enum api_ply_format format;
	int nelems;
	struct api_ply_elem elems[API_PLY_MAX_ELEMS];
	size_t data;                    /* offset of the first byte after end_header's line */
};

/* true with *h filled when d starts with a PLY header this reads (at most API_PLY_MAX_ELEMS
 * elements of API_PLY_MAX_PROPS properties, known types). */
bool api_ply_header_parse(const uint8_t *d, size_t len, struct api_ply_header *h);
/* Bytes of one binary value of type t (0 for API_PLY_NONE). */
int api_ply_type_size(enum api_ply_type t);
/* The type's name as a header writes it ("uchar", "float", ...). */
const char *api_ply_type_name(enum api_ply_type t);
/* The index of element `name` in h, or -1; of property `name` in e, or -1. */
int api_ply_elem_index(const struct api_ply_header *h, const char *name);
int api_ply_prop_index(const struct api_ply_elem *e, const char *name);

struct api_ply_reader {
	const uint8_t *d;
	size_t len, at;
	enum api_ply_format format;
};
/* The next value of type t at r->at (an ASCII token, or binary in the file's byte order) into
 * *v, moving past it. false when the data ends first (or an ASCII token is no number). */
bool api_ply_read(struct api_ply_reader *r, enum api_ply_type t, double *v);

#endif
