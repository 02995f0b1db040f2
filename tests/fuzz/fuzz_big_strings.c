/*
 * tests/fuzz/fuzz_big_strings.c — libFuzzer target for api/big_strings: whatever the document,
 * api_json_load() must agree with json_loadb(): the same tree, or the same error (text, line,
 * column); and a kept member must read back (api_big_string) as jansson's value of it.
 *
 * Big strings need 64 KiB, more than a fuzz input holds, so the input is a template: every '@'
 * becomes API_BIG_STRING + 1 bytes; the next input byte picks them: base64 characters (what
 * gets cut) with, for most values, that byte itself at one place in the run (a quote that ends
 * the string early, a backslash, a control or non-ASCII byte that must keep it whole).
 *
 *   make fuzz && build/fuzz/fuzz_big_strings -runs=100000 build/fuzz/corpus/fuzz_big_strings tests/fuzz/corpus/fuzz_big_strings
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include "big_strings.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(c) do { if (!(c)) abort(); } while (0)

/* a (api_json_load's tree) equals b (jansson's), strings read through api_big_string: kept
 * members stay placeholders at any depth. */
static void same(const struct api_big_strings *big, json_t *a, json_t *b)
{
	if (json_is_string(b)) {
		size_t len;
		const char *s = api_big_string(big, a, &len);
		CHECK(json_is_string(a) && len == json_string_length(b) && !memcmp(s, json_string_value(b), len));
	} else if (json_is_object(b)) {
		const char *key;
		json_t *vb;
		CHECK(json_is_object(a) && json_object_size(a) == json_object_size(b));
		json_object_foreach(b, key, vb) {
			json_t *va = json_object_get(a, key);
			CHECK(va);
			same(big, va, vb);
		}
	} else if (json_is_array(b)) {
		CHECK(json_is_array(a) && json_array_size(a) == json_array_size(b));
		for (size_t i = 0; i < json_array_size(b); i++) same(big, json_array_get(a, i), json_array_get(b, i));
	} else {
		CHECK(json_equal(a, b));
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	size_t ats = 0;
	for (size_t i = 0; i < size; i++) ats += data[i] == '@';
	if (ats > 4) return 0;
	size_t run = API_BIG_STRING + 1, cap = size + ats * run + 1;
	char *doc = malloc(cap);
	CHECK(doc);
	size_t n = 0;
	for (size_t i = 0; i < size; i++) {
		if (data[i] != '@') { doc[n++] = (char)data[i]; continue; }
		static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
		unsigned pick = i + 1 < size ? data[i + 1] : 'A';
		size_t at = (size_t)pick * 257 % run;   /* where the picked byte goes */
		for (size_t k = 0; k < run; k++) doc[n++] = b64[(pick + k) % 64];
		if (pick % 4) doc[n - run + at] = (char)pick;
	}
	static const char *const keep[] = {"data", "b", NULL};
	struct api_big_strings big;
	json_error_t ea, eb;
	json_t *a = api_json_load(doc, n, JSON_REJECT_DUPLICATES, &ea, keep, &big);
	json_t *b = json_loadb(doc, n, JSON_REJECT_DUPLICATES, &eb);
	CHECK(!a == !b);
	if (!a) {
		CHECK(!strcmp(ea.text, eb.text) && ea.line == eb.line && ea.column == eb.column && big.n == 0);
	} else {
		same(&big, a, b);
	}
	json_decref(a);
	json_decref(b);
	api_big_strings_free(&big);
	free(doc);
	return 0;
}
