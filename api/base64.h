/*
 * api/base64 — the one base64 decoder of umbra (RFC 4648 §4 and §5), for every base64 member of
 * a scene document (mesh arrays, textures, inline models).
 *
 * Usage:
 *   size_t cap = api_base64_decoded_max(n);          // never overflows
 *   uint8_t *buf = malloc(cap); size_t len, bad;
 *   if (api_base64_decode(s, n, buf, cap, &len, &bad) != API_OK)
 *       bad < n ? "bad character at offset bad" : "truncated or over-padded";
 *
 * Policy (lenient on purpose, what clients already send): the standard ('+' '/') and URL-safe
 * ('-' '_') alphabets, even mixed; '=' padding optional, at most two, and nothing but padding
 * or whitespace after the first '='; ASCII whitespace (space, tab, CR, LF) ignored anywhere, so
 * MIME-wrapped lines decode; unused low bits of the last group are not checked. Rejected: any
 * other byte, a lone leftover character (6 bits cannot end a byte), three or more '='.
 *
 * Ownership: the caller owns both buffers; nothing is allocated. Threading: pure functions.
 */
#ifndef UMBRA_API_BASE64_H
#define UMBRA_API_BASE64_H

#include <stddef.h>
#include <stdint.h>
#include "api.h"

/* An upper bound of the bytes that n characters decode to (n / 4 * 3 + 3: no overflow for any
 * n, and enough for unpadded input). */
size_t api_base64_decoded_max(size_t n);

/* Decodes s[0..n) into out[0..out_size). Returns API_OK with *out_len bytes written, or
 * API_ERR with *bad = the offset of the offending character, or *bad = n when the input ends
 * badly (a lone leftover character, more than two '='). Never writes past out_size: a buffer
 * smaller than api_base64_decoded_max(n) that the data does not fit is API_ERR with *bad = the
 * offset of the character that did not fit. out_len and bad may be NULL. */
enum api_result api_base64_decode(const char *s, size_t n, uint8_t *out, size_t out_size, size_t *out_len,
                                  size_t *bad);

#endif
