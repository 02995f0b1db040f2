/*
 * tests/util/models.h — model and image files built in memory for the tests (unit and GPU),
 * one copy of each builder: a PNG from RGBA8 texels (libpng), a binary STL tetrahedron, the
 * GLB container around a glTF JSON chunk and a binary chunk, a Draco-compressed glb. Every result is malloc'd (the
 * caller frees it) except where the caller passes the buffer.
 */
#ifndef UMBRA_TEST_MODELS_H
#define UMBRA_TEST_MODELS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdbool.h>
#include <stdint.h>

#include "umbra/rnd.h"

/* Little-endian uint32 at p. */
void test_put32(uint8_t *p, uint32_t v);
/* A render-like RGBA8 image for the encoders (rnd_image_release() frees it): a smooth gradient,
 * a dark disc (a shadow) and, unless opaque, an alpha ramp with a fully transparent 2-pixel
 * border whose colours a lossless encoder must keep too; rows padded (stride > 4 w). */
struct rnd_image test_rgba8_image(uint32_t w, uint32_t h, bool opaque);
/* Peak signal-to-noise ratio of the RGB channels of rgba (w x h, packed) against img, dB
 * (INFINITY when equal); *alpha_diff the largest alpha error. */
double test_psnr_rgb(const struct rnd_image *img, const uint8_t *rgba, int *alpha_diff);
/* A straight-alpha RGBA8 PNG of w x h texels; NULL on failure. */
uint8_t *test_png_rgba(const uint8_t *px, int w, int h, size_t *len);
/* An RGB8 PNG of w x h texels (rgb: 3 bytes each, rows top to bottom) with a gAMA chunk of
 * file_gamma (1/2.2 = 0.45455 is what most tools write); NULL on failure. */
uint8_t *test_png_rgb_gamma(const uint8_t *rgb, int w, int h, double file_gamma, size_t *len);
/* Binary .stl of the tetrahedron with the given 4 vertices into out (84 + 4*50 = 284 bytes);
 * facet normals 0 (the importer recomputes them). Returns the size. */
size_t test_tetra_stl(uint8_t *out, const float p[4][3]);
/* A binary STL of a bumpy, flat-shaded sphere of 2 seg^2 facets (outward winding, degenerate
 * facets at its poles, a step in its radius: what real files look like to the readers);
 * NULL when out of memory. */
uint8_t *test_bumpy_stl(int seg, size_t *len);
/* A .glb: the JSON chunk (padded with spaces) and the binary chunk (bin[0..binlen), padded with
 * zeros to binpad, which the JSON's buffer byteLength must state). NULL when out of memory. */
uint8_t *test_glb_pack(const char *json, size_t json_len, const uint8_t *bin, size_t binlen, size_t binpad,
                       size_t *len);

/* A .glb (NULL when out of memory) with one mesh (positions, optional normals and uvs, uint32
 * indices) in one node translated by `node_t`; with `png`, a material with that base-colour texture and alphaMode
 * MASK (cutoff 0.5) when `mask`, else OPAQUE. */
struct test_glb_mesh {
	const float *pos, *nrm, *uv;
	uint32_t nv;
	const uint32_t *idx;
	uint32_t ni;
	float node_t[3];
	const uint8_t *png;
	size_t png_len;
	bool mask;
};
uint8_t *test_glb_mesh(const struct test_glb_mesh *in, size_t *len);

/* A .glb of one mesh compressed with KHR_draco_mesh_compression as exporters write it
 * (extensionsRequired, no fallback: the accessors have counts and no bufferView), encoded by
 * libdraco (tests/util/draco_encode.h): pos, optional nrm and uv, ntri triangles; indices
 * UNSIGNED_INT (UNSIGNED_SHORT when short_indices). NULL on failure. */
struct test_draco_mesh {
	const float *pos, *nrm, *uv;
	uint32_t nv;
	const uint32_t *idx;
	uint32_t ntri;
	int edgebreaker, position_bits;   /* test_draco_encode's */
	int short_indices;
};
uint8_t *test_draco_glb(const struct test_draco_mesh *m, size_t *len);

#endif
