/*
 * tests/fuzz/fuzz_image.c — libFuzzer target for texture decoding (api_image_decode: PNG via
 * libpng's simplified API, JPEG via libjpeg-turbo with a longjmp error manager). Any bytes must
 * give either an RGBA8 image of the size it reports or an error sentence; never a crash, a
 * leak (a longjmp out of libjpeg must not lose its buffers) or UB.
 *
 * The pixel limit is 4 Mi here, not the 64 Mi of api/model.c: a 40-byte JPEG header can claim
 * 8000x8000 and libjpeg then fills every pixel from nothing (slow, but bounded and correct),
 * which would only slow the search down. The limit check itself is covered either way.
 *
 *   make fuzz && build/fuzz/fuzz_image -runs=1000000 build/fuzz/corpus/fuzz_image tests/fuzz/corpus/fuzz_image
 * Seeds: tests/fuzz/corpus/fuzz_image/, made by tests/fuzz/image_seeds.c (see there).
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>
#include "model.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define MAX_PIXELS (4u << 20)

static volatile uint32_t sink;   /* keeps the pixel reads */

/* Decodes one buffer and checks the contract of api_image_decode. */
static void decode_one(const uint8_t *data, size_t size)
{
	uint8_t *rgba = NULL;
	uint32_t w = 1, h = 1;
	char err[256];
	err[0] = 0;
	if (api_image_decode(data, size, MAX_PIXELS, &rgba, &w, &h, err, sizeof err) != API_OK) {
		/* A failure says why and hands nothing back. */
		if (rgba || w || h || !err[0]) abort();
		return;
	}
	if (!rgba || !w || !h || (uint64_t)w * h > MAX_PIXELS) abort();
	/* Read every pixel: ASan catches a buffer smaller than w * h * 4. */
	uint32_t sum = 0;
	for (size_t i = 0; i < (size_t)w * h * 4; i++) sum += rgba[i];
	sink = sum;
	free(rgba);
}

/* libpng rejects a chunk whose CRC is wrong before looking inside, so almost every mutation of
 * a PNG would stop there (and libpng is not instrumented: the fuzzer cannot see how far it
 * got). A copy with every chunk's CRC recomputed reaches the chunk parsers, zlib and the row
 * filters. The original bytes are decoded too, so the CRC check itself stays covered. */
static uint8_t *png_fix_crcs(const uint8_t *data, size_t size)
{
	if (size < 8 || memcmp(data, "\x89PNG\r\n\x1a\n", 8) != 0) return NULL;
	uint8_t *p = malloc(size);
	if (!p) return NULL;
	memcpy(p, data, size);
	size_t off = 8;
	while (size - off >= 12) {
		uint32_t len = (uint32_t)p[off] << 24 | (uint32_t)p[off + 1] << 16 | (uint32_t)p[off + 2] << 8 | p[off + 3];
		if (len > size - off - 12) break;
		uint32_t crc = (uint32_t)crc32(0, p + off + 4, len + 4);
		uint8_t *c = p + off + 8 + len;
		c[0] = (uint8_t)(crc >> 24); c[1] = (uint8_t)(crc >> 16); c[2] = (uint8_t)(crc >> 8); c[3] = (uint8_t)crc;
		off += 12 + (size_t)len;
	}
	return p;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	decode_one(data, size);
	uint8_t *fixed = png_fix_crcs(data, size);
	if (fixed) {
		if (memcmp(fixed, data, size) != 0) decode_one(fixed, size);
		free(fixed);
	}
	return 0;
}
