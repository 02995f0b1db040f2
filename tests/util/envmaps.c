/* tests/util/envmaps.c — see envmaps.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "envmaps.h"

void test_rgbe(const float rgb[3], uint8_t out[4])
{
	float m = fmaxf(rgb[0], fmaxf(rgb[1], rgb[2]));
	if (m < 1e-32f) {
		memset(out, 0, 4);
		return;
	}
	int e;
	float f = frexpf(m, &e) * 256.0f / m;
	for (int c = 0; c < 3; c++) out[c] = (uint8_t)(rgb[c] * f);
	out[3] = (uint8_t)(e + 128);
}

/* One channel of a scanline as runs: repeats of 4 or more as runs, the rest as literals. */
static size_t rle_channel(const uint8_t *v, uint32_t w, uint8_t *o)
{
	size_t n = 0;
	for (uint32_t x = 0; x < w;) {
		uint32_t run = 1;
		while (x + run < w && run < 127 && v[x + run] == v[x]) run++;
		if (run >= 4) {
			o[n++] = (uint8_t)(128 + run);
			o[n++] = v[x];
			x += run;
			continue;
		}
		uint32_t lit = 0;
		while (x + lit < w && lit < 128) {
			uint32_t r = 1;
			while (x + lit + r < w && r < 4 && v[x + lit + r] == v[x + lit]) r++;
			if (r >= 4) break;
			lit++;
		}
		o[n++] = (uint8_t)lit;
		memcpy(o + n, v + x, lit);
		n += lit;
		x += lit;
	}
	return n;
}

uint8_t *test_hdr_bytes(const float *rgb, uint32_t w, uint32_t h, bool rle, size_t *n)
{
	char head[128];
	int hl = snprintf(head, sizeof head, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %u +X %u\n", h, w);
	uint8_t *b = malloc((size_t)hl + (size_t)h * (4 + 5 * (size_t)w + 16)), *p = b;
	uint8_t *row = malloc((size_t)w * 4), *ch = malloc(w);
	memcpy(p, head, (size_t)hl);
	p += hl;
	for (uint32_t y = 0; y < h; y++) {
		for (uint32_t x = 0; x < w; x++) test_rgbe(rgb + ((size_t)y * w + x) * 3, row + 4 * x);
		if (!rle) {
			memcpy(p, row, (size_t)w * 4);
			p += (size_t)w * 4;
			continue;
		}
		*p++ = 2; *p++ = 2; *p++ = (uint8_t)(w >> 8); *p++ = (uint8_t)(w & 255);
		for (int c = 0; c < 4; c++) {
			for (uint32_t x = 0; x < w; x++) ch[x] = row[4 * x + c];
			p += rle_channel(ch, w, p);
		}
	}
	free(row);
	free(ch);
	*n = (size_t)(p - b);
	return b;
}

float *test_patch_map(uint32_t w, uint32_t h, float azimuth, float elevation, float size, float value, float floor)
{
	float *m = malloc((size_t)w * h * 3 * sizeof(float));
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			float az = (((float)x + 0.5f) / (float)w - 0.5f) * 360.0f, el = (0.5f - ((float)y + 0.5f) / (float)h) * 180.0f;
			float daz = fmodf(az - azimuth + 540.0f, 360.0f) - 180.0f;
			float v = fabsf(el - elevation) <= size / 2 && fabsf(daz) <= size / 2 ? value : floor;
			for (int c = 0; c < 3; c++) m[((size_t)y * w + x) * 3 + c] = v;
		}
	return m;
}
