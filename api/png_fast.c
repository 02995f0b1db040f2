/*
 * api/png_fast.c — the common PNG with libdeflate (see png_fast.h): the chunks walked, the IDAT
 * stream inflated in one call, the rows unfiltered, the samples widened to RGBA8.
 */
#include <libdeflate.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "png_fast.h"

static uint32_t be32(const uint8_t *p)
{
	return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* What the chunks say: the header's fields and where the image data lies. */
struct png_layout {
	uint32_t w, h;
	unsigned channels;          /* 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA */
	const uint8_t *idat;        /* the first IDAT's data ... */
	size_t idat_len;            /* ... and all of the IDATs' together */
	unsigned idat_chunks;
};

/* The header, if it is one this file reads: 8 bits, no interlace, a colour type without a
 * palette. */
static bool read_ihdr(const uint8_t *c, struct png_layout *l)
{
	static const unsigned channels[7] = {1, 0, 3, 0, 2, 0, 4};
	l->w = be32(c);
	l->h = be32(c + 4);
	uint8_t depth = c[8], type = c[9];
	if (!l->w || !l->h || l->w > 0x7fffffffu || l->h > 0x7fffffffu || depth != 8 || type > 6 || !channels[type] ||
	    c[10] || c[11] || c[12])
		return false;
	l->channels = channels[type];
	return true;
}

/* Walks the chunks up to the end of the image data as libpng reads them: false for anything
 * this file leaves to libpng (a bad CRC on a critical chunk, a tRNS, an unknown critical chunk,
 * IDATs not one after the other, a cut). */
static bool walk(const uint8_t *d, size_t len, struct png_layout *l)
{
	size_t at = 8;
	bool header = false, in_idat = false;
	memset(l, 0, sizeof *l);
	while (at + 12 <= len) {
		uint32_t n = be32(d + at);
		const uint8_t *type = d + at + 4, *data = d + at + 8;
		if (n > 0x7fffffffu || n > len - at - 12) return false;
		bool critical = !(type[0] & 0x20), idat = !memcmp(type, "IDAT", 4);
		if (in_idat && !idat) break;   /* libpng reads no further for the pixels */
		if (critical && libdeflate_crc32(0, type, (size_t)n + 4) != be32(data + n)) return false;
		if (!header) {
			if (memcmp(type, "IHDR", 4) || n != 13 || !read_ihdr(data, l)) return false;
			header = true;
		} else if (idat) {
			if (!l->idat) l->idat = data;
			l->idat_len += n;
			l->idat_chunks++;
			in_idat = true;
		} else if (!memcmp(type, "tRNS", 4) || (critical && (memcmp(type, "PLTE", 4) || l->channels < 3))) {
			/* transparency from a chunk, a critical chunk not read here, a palette for grey */
			return false;
		}
		at += 12 + (size_t)n;
	}
	return header && l->idat_chunks;
}

/* The IDAT data as one stream: in place for one chunk, else gathered into *own (malloc'd). */
static const uint8_t *idat_stream(const struct png_layout *l, uint8_t **own)
{
	*own = NULL;
	if (l->idat_chunks == 1) return l->idat;
	uint8_t *s = malloc(l->idat_len ? l->idat_len : 1);
	if (!s) return NULL;
	const uint8_t *c = l->idat - 8;
	for (size_t got = 0; got < l->idat_len; c += 12 + be32(c)) {
		memcpy(s + got, c + 8, be32(c));
		got += be32(c);
	}
	return *own = s;
}

static uint8_t paeth(uint8_t a, uint8_t b, uint8_t c)
{
	int p = (int)a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
	return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

/* Undoes one row's filter f in place (stride bytes, bpp bytes a pixel; prev: the row above,
 * unfiltered, zeros above the first). false for a filter type that is not one of PNG's five. */
static bool unfilter_row(uint8_t *r, const uint8_t *prev, size_t stride, unsigned bpp, uint8_t f)
{
	size_t i;
	switch (f) {
	case 0:
		return true;
	case 1:
		for (i = bpp; i < stride; i++) r[i] = (uint8_t)(r[i] + r[i - bpp]);
		return true;
	case 2:
		for (i = 0; i < stride; i++) r[i] = (uint8_t)(r[i] + prev[i]);
		return true;
	case 3:
		for (i = 0; i < bpp && i < stride; i++) r[i] = (uint8_t)(r[i] + (prev[i] >> 1));
		for (; i < stride; i++) r[i] = (uint8_t)(r[i] + ((r[i - bpp] + prev[i]) >> 1));
		return true;
	case 4:
		for (i = 0; i < bpp && i < stride; i++) r[i] = (uint8_t)(r[i] + prev[i]);   /* paeth(0, b, 0) = b */
		for (; i < stride; i++) r[i] = (uint8_t)(r[i] + paeth(r[i - bpp], prev[i], prev[i - bpp]));
		return true;
	default:
		return false;
	}
}

/* Every row of raw (1 + stride bytes each: its filter type, then the row) unfiltered in place. */
static bool unfilter(uint8_t *raw, uint32_t h, size_t stride, unsigned bpp)
{
	uint8_t *zeros = calloc(stride ? stride : 1, 1);
	const uint8_t *prev = zeros;
	bool ok = zeros != NULL;
	for (uint32_t y = 0; ok && y < h; y++) {
		uint8_t *r = raw + (size_t)y * (stride + 1);
		ok = unfilter_row(r + 1, prev, stride, bpp, r[0]);
		prev = r + 1;
	}
	free(zeros);
	return ok;
}

/* The unfiltered rows widened to RGBA8 (grey to RGB, alpha 255 where the file has none). */
static void to_rgba(const uint8_t *raw, uint32_t w, uint32_t h, unsigned ch, uint8_t *out)
{
	size_t stride = (size_t)w * ch;
	for (uint32_t y = 0; y < h; y++) {
		const uint8_t *s = raw + (size_t)y * (stride + 1) + 1;
		uint8_t *o = out + (size_t)y * w * 4;
		if (ch == 4) {
			memcpy(o, s, stride);
			continue;
		}
		for (uint32_t x = 0; x < w; x++, o += 4, s += ch) {
			o[0] = s[0];
			o[1] = ch >= 3 ? s[1] : s[0];
			o[2] = ch >= 3 ? s[2] : s[0];
			o[3] = ch == 2 ? s[1] : 255;
		}
	}
}

int api_png_decode_fast(const uint8_t *d, size_t len, uint64_t max_pixels, uint8_t **rgba, uint32_t *w, uint32_t *h)
{
	struct png_layout l;
	*rgba = NULL;
	if (!walk(d, len, &l) || (uint64_t)l.w * l.h > max_pixels) return API_PNG_NOT_MINE;
	size_t stride = (size_t)l.w * l.channels, raw_len = (size_t)l.h * (stride + 1);
	uint8_t *own, *raw = malloc(raw_len), *px = malloc((size_t)l.w * l.h * 4);
	const uint8_t *z = idat_stream(&l, &own);
	struct libdeflate_decompressor *dc = libdeflate_alloc_decompressor();
	int rc = raw && px && z && dc ? 0 : API_PNG_NO_MEMORY;
	size_t in = 0, out = 0;
	/* The whole stream, exactly the rows' bytes, its Adler-32 right: anything else (data
	 * short or left over) is libpng's to judge. */
	if (!rc && (libdeflate_zlib_decompress_ex(dc, z, l.idat_len, raw, raw_len, &in, &out) != LIBDEFLATE_SUCCESS ||
	            in != l.idat_len || out != raw_len || !unfilter(raw, l.h, stride, l.channels)))
		rc = API_PNG_NOT_MINE;
	if (!rc) to_rgba(raw, l.w, l.h, l.channels, px);
	libdeflate_free_decompressor(dc);
	free(own);
	free(raw);
	if (rc) {
		free(px);
		return rc;
	}
	*rgba = px;
	*w = l.w;
	*h = l.h;
	return 0;
}
