/*
 * tests/fuzz/fuzz_base64.c — libFuzzer target for api/base64.
 *
 * Two properties per input:
 *   1. The input as base64 text: decoding never reads or writes out of bounds (the output
 *      buffer is malloc'd at the exact size), stays within api_base64_decoded_max(), gives the
 *      same bytes into a buffer of exactly the decoded size and refuses one a byte smaller;
 *      when it succeeds, re-encoding the bytes (reference encoder below) decodes back to them.
 *   2. The input as binary data: encoded by the reference encoder in each accepted form
 *      (standard, URL-safe, unpadded, wrapped at 76 columns with CRLF), it decodes back to
 *      exactly the input.
 * Any violation aborts (libFuzzer reports it as a crash).
 *
 *   make fuzz && build/fuzz/fuzz_base64 -runs=1000000 build/fuzz/corpus/fuzz_base64 tests/fuzz/corpus/fuzz_base64
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "base64.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(c) do { if (!(c)) abort(); } while (0)

/* RFC 4648 encoder, written independently of the decoder: the obvious 3-bytes-to-4 loop.
 * flags: 1 URL-safe alphabet, 2 no padding, 4 CRLF after every 76 characters. */
static char *ref_encode(const uint8_t *d, size_t n, int flags, size_t *out_len)
{
	const char *tab = flags & 1 ? "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_"
	                            : "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	size_t chars = (n + 2) / 3 * 4;
	char *o = malloc(chars + chars / 76 * 2 + 1), *p = o;
	CHECK(o);
	size_t col = 0;
	for (size_t i = 0; i < n; i += 3) {
		uint32_t v = (uint32_t)d[i] << 16;
		if (i + 1 < n) v |= (uint32_t)d[i + 1] << 8;
		if (i + 2 < n) v |= d[i + 2];
		char q[4] = { tab[v >> 18], tab[(v >> 12) & 63], tab[(v >> 6) & 63], tab[v & 63] };
		int keep = i + 2 < n ? 4 : i + 1 < n ? 3 : 2;
		for (int k = 0; k < 4; k++) {
			if (k >= keep && (flags & 2)) break;
			*p++ = k < keep ? q[k] : '=';
			if ((flags & 4) && ++col == 76) { *p++ = '\r'; *p++ = '\n'; col = 0; }
		}
	}
	*out_len = (size_t)(p - o);
	*p = 0;
	return o;
}

/* Decodes s[0..n) into a buffer of exactly `cap` bytes (malloc'd so ASan sees its end). */
static uint8_t *decode_exact(const char *s, size_t n, size_t cap, enum api_result *r, size_t *len)
{
	uint8_t *out = malloc(cap ? cap : 1);
	CHECK(out);
	size_t bad = SIZE_MAX;
	*r = api_base64_decode(s, n, out, cap, len, &bad);
	if (*r != API_OK) CHECK(bad <= n);
	return out;
}

static void check_text(const uint8_t *data, size_t size)
{
	const char *s = (const char *)data;
	size_t max = api_base64_decoded_max(size), len = 0, len2 = 0;
	enum api_result r, r2;
	uint8_t *out = decode_exact(s, size, max, &r, &len);
	if (r != API_OK) {
		free(out);
		return;
	}
	CHECK(len <= max);
	/* The exact size is enough; one byte less is refused, never overrun. */
	uint8_t *exact = decode_exact(s, size, len, &r2, &len2);
	CHECK(r2 == API_OK && len2 == len && !memcmp(exact, out, len));
	free(exact);
	if (len) {
		uint8_t *small = decode_exact(s, size, len - 1, &r2, &len2);
		CHECK(r2 == API_ERR);
		free(small);
	}
	/* Round trip through the reference encoder. */
	size_t elen;
	char *enc = ref_encode(out, len, 0, &elen);
	uint8_t *back = decode_exact(enc, elen, api_base64_decoded_max(elen), &r2, &len2);
	CHECK(r2 == API_OK && len2 == len && !memcmp(back, out, len));
	free(back);
	free(enc);
	free(out);
}

static void check_binary(const uint8_t *data, size_t size)
{
	for (int flags = 0; flags < 8; flags++) {
		size_t elen, len = 0;
		enum api_result r;
		char *enc = ref_encode(data, size, flags, &elen);
		uint8_t *out = decode_exact(enc, elen, api_base64_decoded_max(elen), &r, &len);
		CHECK(r == API_OK && len == size && !memcmp(out, data, size));
		free(out);
		free(enc);
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	check_text(data, size);
	check_binary(data, size);
	return 0;
}
