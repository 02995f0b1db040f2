/*
 * api/gltf_buffers — a glTF document's binary data (see the header).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base64.h"
#include "errmsg.h"
#include "gltf_buffers.h"
#include "model_io.h"

static uint32_t le32(const uint8_t *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

void api_gltf_bufs_init(struct api_gltf_bufs *b, json_t *root, const uint8_t *data, size_t len, bool glb,
                        const struct api_model_file *files, size_t nfiles)
{
	memset(b, 0, sizeof *b);
	b->root = root;
	b->data = data;
	b->len = len;
	b->glb = glb;
	b->files = files;
	b->nfiles = nfiles;
	b->made_index = -1;
	b->nbuffers = json_array_size(json_object_get(root, "buffers"));
}

void api_gltf_bufs_release(struct api_gltf_bufs *b)
{
	for (size_t i = 0; b->buffers && i < b->nbuffers; i++) free(b->buffers[i].owned);
	free(b->buffers);
	free(b->made);
	free(b->all_files);
	memset(b, 0, sizeof *b);
}

const char *api_gltf_json_of(const uint8_t *d, size_t len, bool glb, const char **json, size_t *jlen)
{
	*json = (const char *)d;
	*jlen = len;
	if (!glb) return NULL;
	if (len < 20 || memcmp(d + 16, "JSON", 4)) return "the glb has no JSON chunk";
	uint32_t n = le32(d + 12);
	if (n > len - 20) return "the glb's JSON chunk is longer than the file";
	*json = (const char *)d + 20;
	*jlen = n;
	return NULL;
}

uint8_t *api_gltf_with_json(const uint8_t *d, size_t len, bool glb, const char *js, size_t jn, size_t *out_len)
{
	uint8_t *out = NULL;
	if (!glb) {
		if ((out = malloc(jn ? jn : 1))) memcpy(out, js, jn);
		*out_len = jn;
		return out;
	}
	/* header, the new JSON chunk, then the original chunks after the JSON one */
	size_t jpad = (jn + 3) & ~(size_t)3;
	size_t rest_at = len >= 20 ? 20 + (size_t)le32(d + 12) : len, rest = rest_at <= len ? len - rest_at : 0;
	size_t total = 20 + jpad + rest;
	if (total > UINT32_MAX || !(out = malloc(total))) return NULL;
	memcpy(out, d, 12);
	uint32_t t32 = (uint32_t)total, j32 = (uint32_t)jpad;
	for (int k = 0; k < 4; k++) {
		out[8 + k] = (uint8_t)(t32 >> (8 * k));
		out[12 + k] = (uint8_t)(j32 >> (8 * k));
	}
	memcpy(out + 16, "JSON", 4);
	memcpy(out + 20, js, jn);
	memset(out + 20 + jn, ' ', jpad - jn);
	memcpy(out + 20 + jpad, d + rest_at, rest);
	*out_len = total;
	return out;
}

/* A glb's BIN chunk: the chunk after the JSON one, if its type is BIN. */
static void glb_bin(const uint8_t *d, size_t len, struct api_gltf_bytes *out)
{
	if (len < 20) return;
	size_t off = 20 + (size_t)le32(d + 12);
	if (off > len || len - off < 8 || memcmp(d + off + 4, "BIN\0", 4)) return;
	size_t n = le32(d + off);
	out->p = d + off + 8;
	out->n = n < len - off - 8 ? n : len - off - 8;
}

static int load_data_uri(struct api_gltf_bytes *bb, size_t bi, const char *u, char *err, size_t errsize)
{
	const char *s = strstr(u, ";base64,");
	if (!s) return api_err_set(err, errsize, "glTF buffer %zu: a data: URI that is not base64", bi), -1;
	s += 8;
	size_t n = strlen(s), cap = api_base64_decoded_max(n), got = 0, bad = 0;
	if (!(bb->owned = malloc(cap ? cap : 1))) return api_err_set(err, errsize, "out of memory"), -1;
	if (api_base64_decode(s, n, bb->owned, cap, &got, &bad) != API_OK)
		return api_err_set(err, errsize, "glTF buffer %zu: bad base64 at %zu", bi, bad), -1;
	bb->p = bb->owned;
	bb->n = got;
	return 0;
}

int api_gltf_buffer(struct api_gltf_bufs *b, size_t bi, const struct api_gltf_bytes **out, char *err,
                    size_t errsize)
{
	if (b->made_index >= 0 && bi == (size_t)b->made_index) {
		b->made_view_ = (struct api_gltf_bytes){.p = b->made, .n = b->made_len, .loaded = true};
		*out = &b->made_view_;
		return 0;
	}
	if (bi >= b->nbuffers) return api_err_set(err, errsize, "glTF buffer %zu does not exist", bi), -1;
	if (!b->buffers && !(b->buffers = calloc(b->nbuffers, sizeof *b->buffers)))
		return api_err_set(err, errsize, "out of memory"), -1;
	struct api_gltf_bytes *bb = &b->buffers[bi];
	*out = bb;
	if (bb->loaded) return 0;
	bb->loaded = true;
	const char *u = json_string_value(json_object_get(json_array_get(json_object_get(b->root, "buffers"), bi), "uri"));
	if (!u) {
		if (b->glb && bi == 0) glb_bin(b->data, b->len, bb);
		return 0;
	}
	if (!strncmp(u, "data:", 5)) return load_data_uri(bb, bi, u, err, errsize);
	long fi = api_model_file_index(b->files, b->nfiles, u);
	if (fi >= 0) {
		bb->p = b->files[fi].data;
		bb->n = b->files[fi].len;
	}
	return 0;
}

int api_gltf_view_bytes(struct api_gltf_bufs *b, json_t *view, const char *what, const uint8_t **p, size_t *n,
                        char *err, size_t errsize)
{
	*p = NULL;
	*n = 0;
	if (!json_is_object(view)) return api_err_set(err, errsize, "%s: no such bufferView", what), -1;
	json_t *bi = json_object_get(view, "buffer");
	const struct api_gltf_bytes *bb;
	if (!json_is_integer(bi) || json_integer_value(bi) < 0 ||
	    api_gltf_buffer(b, (size_t)json_integer_value(bi), &bb, err, errsize) != 0)
		return json_is_integer(bi) ? -1 : (api_err_set(err, errsize, "%s: a bufferView with no buffer", what), -1);
	json_int_t off = json_integer_value(json_object_get(view, "byteOffset"));
	json_int_t len = json_integer_value(json_object_get(view, "byteLength"));
	if (!bb->p || off < 0 || len < 0 || (uint64_t)off > bb->n || (uint64_t)len > bb->n - (size_t)off)
		return api_err_set(err, errsize, "%s: its bufferView is not inside its buffer (or the buffer's file was not sent)",
		                   what), -1;
	*p = bb->p + off;
	*n = (size_t)len;
	return 0;
}

int api_gltf_type_components(const char *t)
{
	static const char *const NAMES[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
	static const int COMPS[] = {1, 2, 3, 4, 4, 9, 16};
	for (int i = 0; t && i < 7; i++)
		if (!strcmp(t, NAMES[i])) return COMPS[i];
	return 0;
}

size_t api_gltf_component_size(json_int_t ct)
{
	return ct == 5126 || ct == 5125 ? 4 : ct == 5120 || ct == 5121 ? 1 : ct == 5122 || ct == 5123 ? 2 : 0;
}

static float comp_value(const uint8_t *p, json_int_t ct, bool norm)
{
	switch (ct) {
	case 5126: { float f; memcpy(&f, p, 4); return isfinite(f) ? f : 0.0f; }
	case 5125: { uint32_t v; memcpy(&v, p, 4); return (float)v; }
	case 5120: return norm ? fmaxf((int8_t)p[0] / 127.0f, -1.0f) : (float)(int8_t)p[0];
	case 5121: return norm ? p[0] / 255.0f : (float)p[0];
	case 5122: { int16_t v; memcpy(&v, p, 2); return norm ? fmaxf(v / 32767.0f, -1.0f) : (float)v; }
	default:   { uint16_t v; memcpy(&v, p, 2); return norm ? v / 65535.0f : (float)v; }
	}
}

int api_gltf_accessor_floats(struct api_gltf_bufs *b, json_t *acc, const char *what, float **out, size_t *count,
                             int *comps, char *err, size_t errsize)
{
	*out = NULL;
	json_int_t ct = json_integer_value(json_object_get(acc, "componentType"));
	json_int_t n = json_integer_value(json_object_get(acc, "count"));
	int nc = api_gltf_type_components(json_string_value(json_object_get(acc, "type")));
	size_t cs = api_gltf_component_size(ct);
	if (!nc || !cs || n < 1 || n > (1 << 28))
		return api_err_set(err, errsize, "%s: an accessor of an unknown type or count", what), -1;
	json_t *views = json_object_get(b->root, "bufferViews"), *vi = json_object_get(acc, "bufferView");
	json_t *view = json_is_integer(vi) ? json_array_get(views, (size_t)json_integer_value(vi)) : NULL;
	if (!view) return api_err_set(err, errsize, "%s: the accessor has no bufferView", what), -1;
	const uint8_t *p;
	size_t vlen;
	if (api_gltf_view_bytes(b, view, what, &p, &vlen, err, errsize) != 0) return -1;
	size_t elem = cs * (size_t)nc, stride = (size_t)json_integer_value(json_object_get(view, "byteStride"));
	size_t aoff = (size_t)json_integer_value(json_object_get(acc, "byteOffset"));
	stride = stride ? stride : elem;
	/* Every element inside the view: aoff + (n - 1) stride + elem <= vlen. */
	if (stride < elem || aoff > vlen || elem > vlen - aoff || (size_t)(n - 1) > (vlen - aoff - elem) / stride)
		return api_err_set(err, errsize, "%s: the accessor's %lld values are not inside its bufferView", what,
		                   (long long)n), -1;
	float *v = malloc((size_t)n * (size_t)nc * sizeof *v);
	if (!v) return api_err_set(err, errsize, "out of memory"), -1;
	bool norm = json_is_true(json_object_get(acc, "normalized"));
	for (size_t i = 0; i < (size_t)n; i++)
		for (int k = 0; k < nc; k++)
			v[i * (size_t)nc + (size_t)k] = comp_value(p + aoff + i * stride + (size_t)k * cs, ct, norm);
	*out = v;
	*count = (size_t)n;
	*comps = nc;
	return 0;
}

long api_gltf_made_bytes(struct api_gltf_bufs *b, const void *bytes, size_t n)
{
	size_t at = (b->made_len + 3) & ~(size_t)3;
	if (n > ((size_t)1 << 31) || at + n > ((size_t)1 << 31)) return -1;
	if (at + n > b->made_cap) {
		size_t cap = b->made_cap ? b->made_cap : 4096;
		while (cap < at + n) cap *= 2;
		uint8_t *m = realloc(b->made, cap);
		if (!m) return b->oom = true, -1;
		memset(m + b->made_cap, 0, cap - b->made_cap);
		b->made = m;
		b->made_cap = cap;
	}
	memcpy(b->made + at, bytes, n);
	b->made_len = at + n;
	if (b->made_index < 0) b->made_index = (long)b->nbuffers;   /* added by api_gltf_bufs_finish */
	return (long)at;
}

long api_gltf_made_view(struct api_gltf_bufs *b, const void *bytes, size_t n)
{
	long at = api_gltf_made_bytes(b, bytes, n);
	if (at < 0) return -1;
	json_t *views = json_object_get(b->root, "bufferViews");
	if (!json_is_array(views)) {
		views = json_array();
		json_object_set_new(b->root, "bufferViews", views);
	}
	json_t *v = json_pack("{s:I,s:I,s:I}", "buffer", (json_int_t)b->made_index, "byteOffset", (json_int_t)at,
	                      "byteLength", (json_int_t)n);
	if (!v || json_array_append_new(views, v) != 0) return -1;
	return (long)json_array_size(views) - 1;
}

int api_gltf_bufs_finish(struct api_gltf_bufs *b)
{
	if (b->made_index < 0) return 0;
	json_t *bufs = json_object_get(b->root, "buffers");
	json_t *e = json_pack("{s:s,s:I}", "uri", API_GLTF_MADE_FILE, "byteLength", (json_int_t)b->made_len);
	/* Buffers are removed only after this (api_gltf_drop_fallbacks): the index still holds. */
	if (!e || json_array_size(bufs) != (size_t)b->made_index) {
		json_decref(e);
		return -1;
	}
	return json_array_append_new(bufs, e) == 0 ? 0 : -1;
}

void api_gltf_drop_extension_name(json_t *root, const char *key, const char *name)
{
	json_t *list = json_object_get(root, key), *e;
	size_t i;
	json_array_foreach(list, i, e)
		if (json_is_string(e) && !strcmp(json_string_value(e), name)) {
			json_array_remove(list, i);
			return;
		}
}

int api_gltf_bufs_files(struct api_gltf_bufs *b, const struct api_model_file **files, size_t *nfiles)
{
	*files = b->files;
	*nfiles = b->nfiles;
	if (b->made_index < 0) return 0;
	if (!(b->all_files = calloc(b->nfiles + 1, sizeof *b->all_files))) return -1;
	/* First: a file of the model's own of that name does not shadow it. */
	b->all_files[0] = (struct api_model_file){API_GLTF_MADE_FILE, b->made, b->made_len};
	if (b->nfiles) memcpy(b->all_files + 1, b->files, b->nfiles * sizeof *b->files);
	*files = b->all_files;
	*nfiles = b->nfiles + 1;
	return 0;
}
