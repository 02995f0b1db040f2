/*
 * api/big_strings — a scene document's large string values parsed without jansson's lexer.
 *
 * jansson reads a string byte by byte through its stream, checks each for UTF-8 and grows a
 * buffer: a 1M-triangle model sent inline is one 66 MB base64 string, ~0.35 s of the request.
 * api_json_load() finds every string *value* of at least API_BIG_STRING bytes that is plain
 * printable ASCII with no escape (what base64 is), parses a copy of the document with each
 * replaced by a short placeholder, then puts the strings back as jansson strings made straight
 * from the bytes: the same tree jansson would have built, for a fraction of the work. Any
 * document it cannot treat that way exactly (one that spells \u0000 itself, which the
 * placeholders use, or whose copy does not parse) is parsed whole by jansson, so errors and
 * their line and column are jansson's own.
 *
 * Members named in `keep` (the scene's base64 members) are not even copied: their value stays
 * a placeholder string ("\0" and its index) that api_big_string() turns into the document's
 * own bytes, for the one reader of each (the base64 decoder): 66 MB less to copy and to hold.
 *
 * Usage: struct api_big_strings big;
 *        json_t *root = api_json_load(doc, len, JSON_REJECT_DUPLICATES, &err, keep, &big);
 *        ... api_big_string(&big, v, &n) where v may be a kept member's value ...
 *        json_decref(root); api_big_strings_free(&big);
 * Ownership: the caller owns doc (which must outlive big's use) and the returned tree.
 * Threading: reentrant.
 */
#ifndef UMBRA_API_BIG_STRINGS_H
#define UMBRA_API_BIG_STRINGS_H

#include <jansson.h>
#include <stddef.h>

/* Strings shorter than this go through jansson as they are. */
#define API_BIG_STRING ((size_t)64 << 10)

struct api_big_strings {
	const char *doc;
	struct api_big_cut { size_t start, end; } *cuts;   /* doc[start..end): a string's bytes */
	size_t n;
};

/* json_loadb(doc, len, flags, err) with big strings kept out of the lexer (see above); keep: a
 * NULL-terminated list of member names whose big values stay placeholders (NULL: none); *big
 * is filled in either case (empty when nothing was cut) and must be freed. */
json_t *api_json_load(const char *doc, size_t len, size_t flags, json_error_t *err, const char *const *keep,
                      struct api_big_strings *big);
/* The text of string value v and its length: a kept member's bytes in the document, or v's own. */
const char *api_big_string(const struct api_big_strings *big, const json_t *v, size_t *len);
void api_big_strings_free(struct api_big_strings *big);

#endif
