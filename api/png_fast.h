/*
 * api/png_fast — the common PNG, decoded with libdeflate instead of libpng (api/image_decode.c
 * tries it first, in the sandboxed importer like every decode).
 *
 * A model's 2048^2 PNG texture spent ~70 % of its decode in zlib's inflate; libdeflate inflates
 * the same stream in two thirds of the time (it needs the whole stream and the exact output
 * size, which a PNG's header gives). This reads only the PNG most textures are: 8 bits a
 * sample, grey, grey + alpha, RGB or RGBA, not interlaced, no tRNS, its IDAT chunks one after
 * the other. It checks what libpng checks on the way to the pixels (every critical chunk's CRC,
 * the zlib stream's Adler-32, the filter types, the amount of data) and on anything else, or
 * anything odd, answers API_PNG_NOT_MINE: libpng then decodes the file, with its rules and its
 * messages. What it decodes is libpng's answer byte for byte (tests/unit/test_png_fast.c).
 *
 * Threading: no shared state.
 */
#ifndef UMBRA_API_PNG_FAST_H
#define UMBRA_API_PNG_FAST_H

#include <stddef.h>
#include <stdint.h>

/* Not decoded here: the caller decodes it with libpng. */
#define API_PNG_NOT_MINE (-1)
/* Decoded here, no memory for it. */
#define API_PNG_NO_MEMORY (-2)

/* d[0..len) (a PNG: the caller checked its signature) into malloc'd RGBA8 (*rgba, the caller's
 * to free) of *w x *h, at most max_pixels: 0, API_PNG_NOT_MINE or API_PNG_NO_MEMORY. */
int api_png_decode_fast(const uint8_t *d, size_t len, uint64_t max_pixels, uint8_t **rgba, uint32_t *w, uint32_t *h);

#endif
