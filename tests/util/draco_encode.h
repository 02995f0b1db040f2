/*
 * tests/util/draco_encode.h — Draco bitstreams made with libdraco's own encoder, for the
 * tests of KHR_draco_mesh_compression (test-only C++: tests/util/draco_encode.cpp). No tool
 * or file from elsewhere: CI has no network, and Debian's draco_encoder writes only .drc
 * files of OBJ/PLY input, with attribute ids it chooses.
 */
#ifndef UMBRA_TEST_DRACO_ENCODE_H
#define UMBRA_TEST_DRACO_ENCODE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* draco::GeometryAttribute::Type and draco::DataType values. */
enum { TEST_DRACO_POSITION = 0, TEST_DRACO_NORMAL = 1, TEST_DRACO_TEX_COORD = 3, TEST_DRACO_GENERIC = 4 };
enum { TEST_DRACO_UINT16 = 4, TEST_DRACO_INT16 = 3, TEST_DRACO_FLOAT32 = 9 };

struct test_draco_attr {
	int type, data_type, comps;
	const void *values;       /* nv x comps of data_type */
	uint32_t unique_id;       /* out: the id the extension's "attributes" map names */
};

/* The mesh (nv points, ntri triangles of idx) as a Draco bitstream (malloc'd; *len): sequential
 * encoding (points and faces kept in order, floats stored as they are when position_bits
 * is 0) or edgebreaker (reordered, positions quantized to position_bits, as gltf-pipeline and
 * Blender write them). *points and *faces: what a decoder gets back (the accessors' counts).
 * NULL on failure. */
uint8_t *test_draco_encode(struct test_draco_attr *attrs, int nattrs, uint32_t nv, const uint32_t *idx,
                           uint32_t ntri, int edgebreaker, int position_bits, size_t *len, uint32_t *points,
                           uint32_t *faces);

#ifdef __cplusplus
}
#endif

#endif
