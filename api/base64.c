/*
 * api/base64 — the base64 decoder (see base64.h for the accepted syntax and why it is lenient).
 *
 * One pass, no lookahead: characters feed a bit accumulator; every 8 bits make a byte. The
 * accumulator keeps at most 13 bits (a leftover below 8 plus 6 new ones) and is masked so it
 * never shifts bits out of its width.
 */
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
	for (size_t i = 0; i < n; i++) {
		unsigned char ch = (unsigned char)s[i];
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
