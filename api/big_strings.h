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
 * Usage: json_t *root = api_json_load(doc, len, JSON_REJECT_DUPLICATES, &err); as json_loadb.
 * Ownership: the caller owns doc and the returned tree. Threading: reentrant.
 */
#ifndef UMBRA_API_BIG_STRINGS_H
#define UMBRA_API_BIG_STRINGS_H

#include <jansson.h>
#include <stddef.h>

/* Strings shorter than this go through jansson as they are. */
#define API_BIG_STRING ((size_t)64 << 10)

/* json_loadb(doc, len, flags, err) with big strings kept out of the lexer (see above). */
json_t *api_json_load(const char *doc, size_t len, size_t flags, json_error_t *err);

#endif
