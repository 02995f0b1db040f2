/*
 * api/base64 — the base64 decoder (see base64.h for the accepted syntax and why it is lenient).
 *
 * One pass, no lookahead: characters feed a bit accumulator; every 8 bits make a byte. The
 * accumulator keeps at most 13 bits (a leftover below 8 plus 6 new ones) and is masked so it
 * never shifts bits out of its width. Between whole groups (no bits pending) runs of four
 * alphabet characters are decoded three bytes at a time, which gives the same bytes.
 */
#include <pthread.h>
#include "base64.h"

static int b64_value(unsigned char ch)
{
	if (ch >= 'A' && ch <= 'Z') return ch - 'A';
	if (ch >= 'a' && ch <= 'z') return ch - 'a' + 26;
	if (ch >= '0' && ch <= '9') return ch - '0' + 52;
	if (ch == '+' || ch == '-') return 62;   /* standard or URL-safe alphabet */
	if (ch == '/' || ch == '_') return 63;
	return -1;
}

/* b64_value as tables for the fast path, one per position in a group of four, each value
 * already shifted to its place in the group's 24 bits; bit 31 marks anything else (whitespace,
 * '=', invalid: the general path decides). Built once; b64_value stays the one definition. */
#define NOT_B64 0x80000000u
static uint32_t table[4][256];
static pthread_once_t table_once = PTHREAD_ONCE_INIT;

static void table_init(void)
{
	for (int ch = 0; ch < 256; ch++) {
		int v = b64_value((unsigned char)ch);
		for (int k = 0; k < 4; k++) table[k][ch] = v < 0 ? NOT_B64 : (uint32_t)v << (18 - 6 * k);
	}
}

size_t api_base64_decoded_max(size_t n)
{
	return n / 4 * 3 + 3;
}

enum api_result api_base64_decode(const char *s, size_t n, uint8_t *out, size_t out_size, size_t *out_len,
                                  size_t *bad)
{
	uint32_t acc = 0;
	int bits = 0, pad = 0;
	size_t o = 0, dummy;
	if (!bad) bad = &dummy;
	if (out_len) *out_len = 0;
	pthread_once(&table_once, table_init);
	const unsigned char *u = (const unsigned char *)s;
	for (size_t i = 0; i < n; i++) {
		/* Fast path, byte-aligned between groups: four alphabet characters make three bytes
		 * (a 1M-triangle model sent inline is 66 MB of them: 190 -> ~14 ms). Anything else
		 * (whitespace, padding, a bad byte, the last group) takes the general path below. */
		while (bits == 0 && !pad && i + 4 <= n && o + 3 <= out_size) {
			uint32_t w = table[0][u[i]] | table[1][u[i + 1]] | table[2][u[i + 2]] | table[3][u[i + 3]];
			if (w & NOT_B64) break;
			out[o] = (uint8_t)(w >> 16);
			out[o + 1] = (uint8_t)(w >> 8);
			out[o + 2] = (uint8_t)w;
			o += 3;
			i += 4;
		}
		if (i == n) break;
		unsigned char ch = u[i];
		if (ch == ' ' || ch == '\n' || ch == '\r' || ch == '\t') continue;
		if (ch == '=') { pad++; continue; }
		int v = b64_value(ch);
		if (v < 0 || pad) { *bad = i; return API_ERR; }
		acc = ((acc << 6) | (uint32_t)v) & 0x3fffu;
		bits += 6;
		if (bits >= 8) {
			bits -= 8;
			if (o == out_size) { *bad = i; return API_ERR; }
			out[o++] = (uint8_t)(acc >> bits);
		}
	}
	/* 6 leftover bits cannot come from whole bytes; more than two '=' is not base64. */
	if (bits >= 6 || pad > 2) { *bad = n; return API_ERR; }
	if (out_len) *out_len = o;
	return API_OK;
}
