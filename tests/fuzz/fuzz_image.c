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
#include "model.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define MAX_PIXELS (4u << 20)

static volatile uint32_t sink;   /* keeps the pixel reads */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	uint8_t *rgba = NULL;
	uint32_t w = 1, h = 1;
	char err[256];
	err[0] = 0;
	if (api_image_decode(data, size, MAX_PIXELS, &rgba, &w, &h, err, sizeof err) != API_OK) {
		/* A failure says why and hands nothing back. */
		if (rgba || w || h || !err[0]) abort();
		return 0;
	}
	if (!rgba || !w || !h || (uint64_t)w * h > MAX_PIXELS) abort();
	/* Read every pixel: ASan catches a buffer smaller than w * h * 4. */
	uint32_t sum = 0;
	for (size_t i = 0; i < (size_t)w * h * 4; i++) sum += rgba[i];
	sink = sum;
	free(rgba);
	return 0;
}
