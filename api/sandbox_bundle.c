/*
 * api/sandbox_bundle.c — a model's input to the sandboxed importer with the files it refers
 * to, and its decoding in the child (see sandbox.h, api_sbx_bundle_encode). Pure: no I/O.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "sandbox.h"

/* The first earlier file with the same bytes (api/model_refs.c shares them between spellings
 * of one name), or i. */
static size_t alias_of(const struct api_model_file *files, size_t i)
{
	for (size_t k = 0; k < i; k++)
		if (files[k].data == files[i].data && files[k].len == files[i].len && files[i].len) return k;
	return i;
}

uint8_t *api_sbx_bundle_encode(const uint8_t *model, size_t len, const struct api_model_file *files, size_t n,
                               size_t *out_len)
{
	size_t total = len;
	for (size_t i = 0; i < n; i++) {
		size_t add = 12 + strlen(files[i].name) + 1 + (alias_of(files, i) < i ? 0 : files[i].len);
		if (total + add < total || strlen(files[i].name) >= UINT32_MAX) return NULL;
		total += add;
	}
	uint8_t *b = malloc(total ? total : 1), *p = b;
	if (!b) return NULL;
	memcpy(p, model, len);
	p += len;
	for (size_t i = 0; i < n; i++) {
		uint32_t nl = (uint32_t)strlen(files[i].name) + 1;
		size_t k = alias_of(files, i);
		uint64_t dl = k < i ? API_SBX_ALIAS | k : files[i].len;
		memcpy(p, &nl, 4);
		memcpy(p + 4, &dl, 8);
		memcpy(p + 12, files[i].name, nl);
		p += 12 + nl;
		if (k < i) continue;
		memcpy(p, files[i].data, files[i].len);
		p += files[i].len;
	}
	*out_len = total;
	return b;
}

int api_sbx_bundle_decode(const uint8_t *in, size_t len, size_t model_len, uint32_t count,
                          struct api_model_file *files)
{
	if (model_len > len) return -1;
	size_t off = model_len;
	for (uint32_t i = 0; i < count; i++) {
		uint32_t nl;
		uint64_t dl;
		if (len - off < 12) return -1;
		memcpy(&nl, in + off, 4);
		memcpy(&dl, in + off + 4, 8);
		off += 12;
		if (!nl || nl > len - off || in[off + nl - 1] != 0) return -1;
		if (dl & API_SBX_ALIAS) {   /* the bytes of an earlier file */
			uint64_t k = dl & ~API_SBX_ALIAS;
			if (k >= i) return -1;
			files[i] = (struct api_model_file){(const char *)in + off, files[k].data, files[k].len};
			off += nl;
			continue;
		}
		if (dl > len - off - nl) return -1;
		files[i] = (struct api_model_file){(const char *)in + off, in + off + nl, (size_t)dl};
		off += nl + (size_t)dl;
	}
	return off == len ? 0 : -1;
}
