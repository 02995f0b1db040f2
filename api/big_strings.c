/*
 * api/big_strings — see big_strings.h. The scan is a small JSON string finder, not a parser:
 * outside strings it only looks for '"'; a string ends at the first '"' not escaped. It never
 * has to be right about a malformed document: whatever it cuts, jansson parses the rest, and a
 * copy that does not parse sends the original to jansson whole.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "big_strings.h"


/* Whether any byte of the 8 in x is zero (the classic bit trick, exact). */
static uint64_t zero_byte(uint64_t x)
{
	return (x - 0x0101010101010101ull) & ~x & 0x8080808080808080ull;
}

/* Bytes jansson takes as they are: printable ASCII (no control character, no UTF-8 to check,
 * no escape). Eight at a time: 66 MB in ~10 ms where a byte loop took ~50. */
static int plain(const char *s, size_t n)
{
	size_t i = 0;
	uint64_t bad = 0;
	for (; i + 8 <= n; i += 8) {
		uint64_t x;
		memcpy(&x, s + i, 8);
		/* >= 0x80; < 0x20 (x - 0x20 borrows into the high bit of a byte that had it clear);
		 * == 0x7f; == '\\' */
		bad |= x & 0x8080808080808080ull;
		bad |= (x - 0x2020202020202020ull) & ~x & 0x8080808080808080ull;
		bad |= zero_byte(x ^ 0x7f7f7f7f7f7f7f7full) | zero_byte(x ^ 0x5c5c5c5c5c5c5c5cull);
		if (bad) return 0;
	}
	for (; i < n; i++) {
		unsigned char c = (unsigned char)s[i];
		if (c < 0x20 || c >= 0x7f || c == '\\') return 0;
	}
	return 1;
}

/* The end (index of the closing quote) of the string whose first byte is doc[i], or len when
 * it is not closed. */
static size_t string_end(const char *doc, size_t len, size_t i)
{
	while (i < len) {
		const char *q = memchr(doc + i, '"', len - i);
		if (!q) return len;
		size_t k = (size_t)(q - doc);
		/* escaped when preceded by an odd number of backslashes */
		size_t b = k;
		while (b > i && doc[b - 1] == '\\') b--;
		if ((k - b) % 2 == 0) return k;
		i = k + 1;
	}
	return len;
}

/* The big plain string values of doc, in order; their count, or -1 (out of memory). */
static long find_cuts(const char *doc, size_t len, struct api_big_cut **out)
{
	struct api_big_cut *v = NULL;
	size_t n = 0, cap = 0;
	size_t i = 0;
	while (i < len) {
		const char *q = memchr(doc + i, '"', len - i);
		if (!q) break;
		size_t start = (size_t)(q - doc) + 1, end = string_end(doc, len, start);
		if (end >= len) break;
		size_t next = end + 1;
		while (next < len && (doc[next] == ' ' || doc[next] == '\t' || doc[next] == '\n' || doc[next] == '\r')) next++;
		bool key = next < len && doc[next] == ':';
		if (!key && end - start >= API_BIG_STRING && plain(doc + start, end - start)) {
			if (n == cap) {
				cap = cap ? 2 * cap : 8;
				struct api_big_cut *nv = realloc(v, cap * sizeof *nv);
				if (!nv) { free(v); return -1; }
				v = nv;
			}
			v[n++] = (struct api_big_cut){start, end};
		}
		i = end + 1;
	}
	*out = v;
	return (long)n;
}

/* The index of the placeholder v stands for, or -1 when v is not one. */
static long placeholder(const json_t *v, size_t ncut)
{
	if (!json_is_string(v) || json_string_length(v) < 2 || json_string_value(v)[0] != 0) return -1;
	unsigned long k = strtoul(json_string_value(v) + 1, NULL, 10);
	return k < ncut ? (long)k : -1;
}

static bool kept(const char *key, const char *const *keep)
{
	for (size_t i = 0; keep && keep[i]; i++)
		if (!strcmp(key, keep[i])) return true;
	return false;
}

/* A cut string as jansson's string value: its bytes need no check (plain() passed them). NULL
 * on failure, which json_*_set_new() refuses. */
static json_t *cut_string(const char *doc, const struct api_big_cut *c)
{
	return json_stringn_nocheck(doc + c->start, c->end - c->start);
}

/* Puts the cut strings back in place of their placeholders, except as members named in keep. */
static int restore(json_t *j, const char *doc, const struct api_big_cut *cuts, size_t ncut, const char *const *keep)
{
	if (json_is_object(j)) {
		const char *key;
		json_t *val;
		void *tmp;
		json_object_foreach_safe(j, tmp, key, val) {
			long k = placeholder(val, ncut);
			if (k < 0) {
				if (restore(val, doc, cuts, ncut, keep) < 0) return -1;
			} else if (!kept(key, keep) && json_object_set_new(j, key, cut_string(doc, &cuts[k])) < 0) {
				return -1;
			}
		}
	} else if (json_is_array(j)) {
		for (size_t a = 0; a < json_array_size(j); a++) {
			json_t *val = json_array_get(j, a);
			long k = placeholder(val, ncut);
			if (k < 0) {
				if (restore(val, doc, cuts, ncut, keep) < 0) return -1;
			} else if (json_array_set_new(j, a, cut_string(doc, &cuts[k])) < 0) {
				return -1;
			}
		}
	}
	return 0;
}

const char *api_big_string(const struct api_big_strings *big, const json_t *v, size_t *len)
{
	long k = big ? placeholder(v, big->n) : -1;
	if (k < 0) {
		*len = json_string_length(v);
		return json_string_value(v);
	}
	*len = big->cuts[k].end - big->cuts[k].start;
	return big->doc + big->cuts[k].start;
}

void api_big_strings_free(struct api_big_strings *big)
{
	free(big->cuts);
	memset(big, 0, sizeof *big);
}

json_t *api_json_load(const char *doc, size_t len, size_t flags, json_error_t *err, const char *const *keep,
                      struct api_big_strings *big)
{
	memset(big, 0, sizeof *big);
	struct api_big_cut *cuts = NULL;
	long ncut = len >= API_BIG_STRING ? find_cuts(doc, len, &cuts) : 0;
	/* The placeholders spell \u0000: a document that does cannot be cut (the cut strings
	 * themselves have no backslash, so only the rest needs looking at). */
	for (long k = 0; k <= ncut && ncut > 0; k++) {
		size_t from = k ? cuts[k - 1].end : 0, to = k < ncut ? cuts[k].start : len;
		if (memmem(doc + from, to - from, "\\u0000", 6)) ncut = 0;
	}
	if (ncut <= 0) {
		free(cuts);
		return json_loadb(doc, len, flags, err);
	}
	/* The copy: the document with each big string's bytes replaced by \u0000 and its index. */
	size_t cap = len, o = 0, from = 0;
	char *copy = malloc(cap);
	json_t *root = NULL;
	if (!copy) goto whole;
	for (long k = 0; k < ncut; k++) {
		char ph[32];
		int phn = snprintf(ph, sizeof ph, "\\u0000%ld", k);
		size_t seg = cuts[k].start - from;
		memcpy(copy + o, doc + from, seg);   /* the placeholder is shorter than the string */
		o += seg;
		memcpy(copy + o, ph, (size_t)phn);
		o += (size_t)phn;
		from = cuts[k].end;
	}
	memcpy(copy + o, doc + from, len - from);
	o += len - from;
	root = json_loadb(copy, o, flags | JSON_ALLOW_NUL, NULL);
	free(copy);
	if (root && restore(root, doc, cuts, (size_t)ncut, keep) == 0) {
		*big = (struct api_big_strings){doc, cuts, (size_t)ncut};
		return root;
	}
	json_decref(root);
whole:
	free(cuts);
	return json_loadb(doc, len, flags, err);
}
