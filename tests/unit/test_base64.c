/* tests/unit/test_base64.c — api/base64: RFC 4648 vectors, both alphabets, the whitespace and
 * padding policy, errors with their offsets, and the output bound. */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include "base64.h"
#include "test.h"

/* Decodes a NUL-terminated string; returns the api_result, *len and *bad. */
static enum api_result dec(const char *s, uint8_t *out, size_t cap, size_t *len, size_t *bad)
{
	*len = 12345;
	*bad = 12345;
	return api_base64_decode(s, strlen(s), out, cap, len, bad);
}

TEST(base64_rfc4648_vectors)
{
	static const struct { const char *enc, *dec; } v[] = {
		{ "", "" }, { "Zg==", "f" }, { "Zm8=", "fo" }, { "Zm9v", "foo" }, { "Zm9vYg==", "foob" },
		{ "Zm9vYmE=", "fooba" }, { "Zm9vYmFy", "foobar" },
		/* padding is optional */
		{ "Zg", "f" }, { "Zm8", "fo" }, { "Zm9vYg", "foob" }, { "Zm9vYmE", "fooba" },
	};
	for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
		uint8_t out[16];
		size_t len, bad;
		enum api_result r = dec(v[i].enc, out, sizeof out, &len, &bad);
		CHECK(r == API_OK, "'%s' rejected at %zu", v[i].enc, bad);
		CHECK(len == strlen(v[i].dec) && !memcmp(out, v[i].dec, len), "'%s' gave %zu bytes", v[i].enc, len);
	}
}

TEST(base64_both_alphabets)
{
	uint8_t out[8];
	size_t len, bad;
	/* 0xfb 0xff 0xbf: "+/+/" in the standard alphabet, "-_-_" URL-safe, and mixed. */
	const char *forms[] = { "+/+/", "-_-_", "+_-/" };
	for (int i = 0; i < 3; i++) {
		REQUIRE(dec(forms[i], out, sizeof out, &len, &bad) == API_OK, "%s", forms[i]);
		CHECK(len == 3 && out[0] == 0xfb && out[1] == 0xff && out[2] == 0xbf, "%s: %zu %02x %02x %02x",
		      forms[i], len, out[0], out[1], out[2]);
	}
}

TEST(base64_whitespace_ignored_anywhere)
{
	uint8_t out[16];
	size_t len, bad;
	REQUIRE(dec("Zm9v\r\nYmFy\n", out, sizeof out, &len, &bad) == API_OK);
	CHECK(len == 6 && !memcmp(out, "foobar", 6));
	REQUIRE(dec(" Z m9v\tYg = = \t", out, sizeof out, &len, &bad) == API_OK);
	CHECK(len == 4 && !memcmp(out, "foob", 4));
	/* Other control characters are not whitespace here (vertical tab, form feed). */
	CHECK(dec("Zm9v\vYmFy", out, sizeof out, &len, &bad) == API_ERR && bad == 4, "bad %zu", bad);
	CHECK(dec("Zm9v\fYmFy", out, sizeof out, &len, &bad) == API_ERR && bad == 4, "bad %zu", bad);
}

TEST(base64_errors_name_the_offset)
{
	uint8_t out[16];
	size_t len, bad;
	CHECK(dec("Zm9v!mFy", out, sizeof out, &len, &bad) == API_ERR && bad == 4, "bad %zu", bad);
	CHECK(dec("Zm\x80v", out, sizeof out, &len, &bad) == API_ERR && bad == 2, "bad %zu", bad);
	CHECK(dec("Zm9v.", out, sizeof out, &len, &bad) == API_ERR && bad == 4, "bad %zu", bad);
	/* Data after padding: the first such character is at fault. */
	CHECK(dec("Zg==Zg==", out, sizeof out, &len, &bad) == API_ERR && bad == 4, "bad %zu", bad);
	CHECK(dec("Zg= =x", out, sizeof out, &len, &bad) == API_ERR && bad == 5, "bad %zu", bad);
	/* An embedded NUL is a bad character, not an end. */
	CHECK(api_base64_decode("Zm\0v", 4, out, sizeof out, &len, &bad) == API_ERR && bad == 2, "bad %zu", bad);
}

TEST(base64_padding_and_truncation)
{
	uint8_t out[16];
	size_t len, bad;
	/* One leftover character (6 bits) cannot end a byte: bad == n. */
	CHECK(dec("Zm9vY", out, sizeof out, &len, &bad) == API_ERR && bad == 5, "bad %zu", bad);
	CHECK(dec("Z", out, sizeof out, &len, &bad) == API_ERR && bad == 1, "bad %zu", bad);
	CHECK(dec("Z===", out, sizeof out, &len, &bad) == API_ERR && bad == 4, "bad %zu", bad);
	/* Three '=' are over-padded; two and one are fine (their count is not checked against
	 * the data: the policy is lenient). */
	CHECK(dec("Zg===", out, sizeof out, &len, &bad) == API_ERR && bad == 5, "bad %zu", bad);
	CHECK(dec("Zg==", out, sizeof out, &len, &bad) == API_OK && len == 1);
	CHECK(dec("Zm9v=", out, sizeof out, &len, &bad) == API_OK && len == 3);
	CHECK(dec("==", out, sizeof out, &len, &bad) == API_OK && len == 0);
	/* Unused low bits of the last group are not checked ("Zh==" also decodes to 'f'). */
	CHECK(dec("Zh==", out, sizeof out, &len, &bad) == API_OK && len == 1 && out[0] == 'f');
}

TEST(base64_output_bound_never_overflows)
{
	CHECK(api_base64_decoded_max(0) == 3);
	CHECK(api_base64_decoded_max(4) == 6);
	CHECK(api_base64_decoded_max(7) == 6);
	size_t m = api_base64_decoded_max(SIZE_MAX);
	CHECK(m == SIZE_MAX / 4 * 3 + 3 && m > SIZE_MAX / 2, "%zu", m);
	/* The bound holds for every unpadded length. */
	char in[65];
	uint8_t out[64];
	for (size_t n = 0; n <= 64; n++) {
		memset(in, 'A', n);
		in[n] = 0;
		size_t len, bad;
		enum api_result r = api_base64_decode(in, n, out, sizeof out, &len, &bad);
		if (n % 4 == 1) {
			CHECK(r == API_ERR && bad == n, "n=%zu", n);
			continue;
		}
		CHECK(r == API_OK && len == n * 3 / 4 && len <= api_base64_decoded_max(n), "n=%zu len=%zu", n, len);
	}
}

TEST(base64_small_buffer_is_refused_not_overrun)
{
	uint8_t out[8];
	memset(out, 0xaa, sizeof out);
	size_t len = 99, bad = 99;
	/* "foobar" needs 6 bytes; give it 4 and check nothing past them is touched. */
	CHECK(api_base64_decode("Zm9vYmFy", 8, out, 4, &len, &bad) == API_ERR && bad == 6, "bad %zu", bad);
	CHECK(out[4] == 0xaa && out[5] == 0xaa, "wrote past out_size");
	CHECK(len == 0, "len %zu on failure", len);
	/* NULL out_len and bad are allowed. */
	CHECK(api_base64_decode("Zm9v", 4, out, sizeof out, NULL, NULL) == API_OK && !memcmp(out, "foo", 3));
}

/* The policy one character at a time, as the decoder was before its four-at-a-time fast path
 * (the test's own copy): the fast path must give the same bytes, lengths, errors and offsets. */
static int ref_value(unsigned char ch)
{
	if (ch >= 'A' && ch <= 'Z') return ch - 'A';
	if (ch >= 'a' && ch <= 'z') return ch - 'a' + 26;
	if (ch >= '0' && ch <= '9') return ch - '0' + 52;
	if (ch == '+' || ch == '-') return 62;
	if (ch == '/' || ch == '_') return 63;
	return -1;
}

static bool ref_decode(const char *s, size_t n, uint8_t *out, size_t cap, size_t *len, size_t *bad)
{
	uint32_t acc = 0;
	int bits = 0, pad = 0;
	size_t o = 0;
	for (size_t i = 0; i < n; i++) {
		unsigned char ch = (unsigned char)s[i];
		if (ch == ' ' || ch == '\n' || ch == '\r' || ch == '\t') continue;
		if (ch == '=') { pad++; continue; }
		int v = ref_value(ch);
		if (v < 0 || pad) { *bad = i; return false; }
		acc = ((acc << 6) | (uint32_t)v) & 0x3fffu;
		bits += 6;
		if (bits >= 8) {
			bits -= 8;
			if (o == cap) { *bad = i; return false; }
			out[o++] = (uint8_t)(acc >> bits);
		}
	}
	if (bits >= 6 || pad > 2) { *bad = n; return false; }
	*len = o;
	return true;
}

TEST(base64_fast_path_matches_one_character_at_a_time)
{
	static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/-_= \n\r\t*\"";
	uint32_t seed = 7;
	long mismatches = 0;
	for (int t = 0; t < 100000; t++) {
		char s[64];
		seed = seed * 1103515245u + 12345u;
		size_t n = (seed >> 16) % 48;
		for (size_t i = 0; i < n; i++) {
			seed = seed * 1103515245u + 12345u;
			uint32_t r = seed >> 8;
			/* mostly the alphabet, sometimes padding, whitespace or a bad byte */
			s[i] = r % 100 < 88 ? alphabet[(r >> 8) % 64] : alphabet[64 + (r >> 8) % (sizeof alphabet - 65)];
		}
		seed = seed * 1103515245u + 12345u;
		size_t cap = (seed >> 16) % 3 == 0 ? (seed >> 20) % 40 : api_base64_decoded_max(n);
		uint8_t a[64], b[64];
		size_t la = 0, lb = 0, ba = 0, bb = 0;
		bool ok_a = api_base64_decode(s, n, a, cap, &la, &ba) == API_OK;
		bool ok_b = ref_decode(s, n, b, cap, &lb, &bb);
		if (ok_a != ok_b || (ok_a && (la != lb || memcmp(a, b, la))) || (!ok_a && ba != bb)) mismatches++;
	}
	CHECK(mismatches == 0, "%ld of 100000 random inputs decoded differently", mismatches);
}
