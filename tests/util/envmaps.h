/*
 * tests/util/envmaps.h — environment maps the tests make themselves (CI has no network):
 * Radiance .hdr bytes of an RGB float image (tests/util/envmaps.c), and a few generated maps.
 * Plain C, no GPU; results are malloc'd and the caller frees them.
 */
#ifndef UMBRA_TEST_ENVMAPS_H
#define UMBRA_TEST_ENVMAPS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* RGBE as Radiance writes it: the largest component's exponent, mantissas (v / 2^e) * 256. */
void test_rgbe(const float rgb[3], uint8_t out[4]);
/* A .hdr file of w x h rgb floats (rows from the top): new run-length scanlines when rle (w of
 * 8..32767), flat ones otherwise. *n its size. */
uint8_t *test_hdr_bytes(const float *rgb, uint32_t w, uint32_t h, bool rle, size_t *n);
/* A w x h map: `floor` everywhere and a square patch of `value`, `size` degrees a side, centred
 * at (azimuth, elevation) degrees (azimuth from +X towards +Z: u = 0.5 + azimuth / 360). */
float *test_patch_map(uint32_t w, uint32_t h, float azimuth, float elevation, float size, float value, float floor);

#endif
