/*
 * tests/unit/model_util — models the model tests (tests/unit/test_model*.c) build: TEX, a 2x2
 * RGBA texture (red, half-transparent green, transparent blue, white) and its PNG, and a glb
 * quad (2 triangles) in a node translated by (0,2,0), material: baseColorFactor, metallic,
 * roughness, alphaMode MASK with cutoff 0.4, and a PNG as its base-colour texture.
 */
#ifndef UMBRA_TESTS_MODEL_UTIL_H
#define UMBRA_TESTS_MODEL_UTIL_H

#include <stddef.h>
#include <stdint.h>
#include "api.h"
#include "model.h"

extern const uint8_t TEX[16];
/* TEX as a PNG (malloc'd; *len its size). */
uint8_t *png_2x2(size_t *len);
/* The quad with `png` (taken: freed here) as its texture; tex_extra is added to the
 * baseColorTexture object, root_extra to the document. The glb, malloc'd (*len its size). */
uint8_t *quad_glb_png(uint8_t *png, size_t pnglen, const char *tex_extra, const char *root_extra, size_t *len);
/* The same with png_2x2 as the texture; quad_glb: with no extras. */
uint8_t *quad_glb_ex(const char *tex_extra, const char *root_extra, size_t *len);
uint8_t *quad_glb(size_t *len);
/* api_model_get of d as format for images of `side` (0: the default limits' import timeout,
 * else timeout_ms): the model (a reference), or NULL with the reason printed. */
struct api_model *model_get_for(const uint8_t *d, size_t len, enum api_model_format format, uint32_t side,
                                uint32_t timeout_ms);

#endif
