/*
 * api/gltf_instancing — EXT_mesh_gpu_instancing as child nodes (see the header).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base64.h"
#include "errmsg.h"
#include "gltf_instancing.h"
#include "model_io.h"

#define EXT "EXT_mesh_gpu_instancing"

struct bytes {
	const uint8_t *p;
	size_t n;
	uint8_t *owned;   /* a decoded data: URI */
	bool loaded;
};

struct inst_ctx {
	json_t *root;
	const uint8_t *data;
	size_t len;
	bool glb;
	const struct api_model_file *files;
	size_t nfiles;
	struct bytes *buffers;
	size_t nbuffers;
	char *err;
	size_t errsize;
};

static uint32_t le32(const uint8_t *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* A glb's BIN chunk: the chunk after the JSON one, if its type is BIN. */
static void glb_bin(const uint8_t *d, size_t len, struct bytes *out)
{
	if (len < 20) return;
	size_t off = 20 + (size_t)le32(d + 12);
	if (off > len || len - off < 8 || memcmp(d + off + 4, "BIN\0", 4)) return;
	size_t n = le32(d + off);
	out->p = d + off + 8;
	out->n = n < len - off - 8 ? n : len - off - 8;
}

/* Buffer bi's bytes (loaded once): the BIN chunk, a data: URI, or a file the daemon sent. */
static int buffer_of(struct inst_ctx *c, size_t bi, struct bytes **out)
{
	if (bi >= c->nbuffers) return api_err_set(c->err, c->errsize, EXT ": buffer %zu does not exist", bi), -1;
	struct bytes *b = &c->buffers[bi];
	*out = b;
	if (b->loaded) return 0;
	b->loaded = true;
	json_t *uri = json_object_get(json_array_get(json_object_get(c->root, "buffers"), bi), "uri");
	const char *u = json_string_value(uri);
	if (!u) {
		if (c->glb && bi == 0) glb_bin(c->data, c->len, b);
		return 0;
	}
	if (!strncmp(u, "data:", 5)) {
		const char *s = strstr(u, ";base64,");
		if (!s) return api_err_set(c->err, c->errsize, EXT ": buffer %zu: a data: URI that is not base64", bi), -1;
		s += 8;
		size_t n = strlen(s), cap = api_base64_decoded_max(n), got = 0, bad = 0;
		if (!(b->owned = malloc(cap ? cap : 1))) return api_err_set(c->err, c->errsize, "out of memory"), -1;
		if (api_base64_decode(s, n, b->owned, cap, &got, &bad) != API_OK)
			return api_err_set(c->err, c->errsize, EXT ": buffer %zu: bad base64 at %zu", bi, bad), -1;
		b->p = b->owned;
		b->n = got;
		return 0;
	}
	long fi = api_model_file_index(c->files, c->nfiles, u);
	if (fi >= 0) {
		b->p = c->files[fi].data;
		b->n = c->files[fi].len;
	}
	return 0;
}

static size_t comp_size(json_int_t ct)
{
	return ct == 5126 ? 4 : ct == 5120 || ct == 5121 ? 1 : ct == 5122 || ct == 5123 ? 2 : 0;
}

static float comp_value(const uint8_t *p, json_int_t ct)
{
	switch (ct) {
	case 5126: { float f; memcpy(&f, p, 4); return f; }
	case 5120: return fmaxf((int8_t)p[0] / 127.0f, -1.0f);
	case 5121: return p[0] / 255.0f;
	case 5122: { int16_t v; memcpy(&v, p, 2); return fmaxf(v / 32767.0f, -1.0f); }
	default:   { uint16_t v; memcpy(&v, p, 2); return v / 65535.0f; }
	}
}

/* Accessor `ai` as `count` x `comps` floats into out (malloc'd, yours), *count its count.
 * float_only: TRANSLATION (the extension allows normalized integers for ROTATION and SCALE). */
static int read_accessor(struct inst_ctx *c, json_t *ai, const char *attr, int comps, bool float_only, float **out,
                         size_t *count)
{
	*out = NULL;
	json_t *acc = json_array_get(json_object_get(c->root, "accessors"), (size_t)json_integer_value(ai));
	const char *type = json_string_value(json_object_get(acc, "type"));
	json_int_t ct = json_integer_value(json_object_get(acc, "componentType"));
	json_int_t n = json_integer_value(json_object_get(acc, "count"));
	size_t cs = comp_size(ct);
	bool norm = json_is_true(json_object_get(acc, "normalized"));
	if (!json_is_integer(ai) || !acc || !type || strcmp(type, comps == 3 ? "VEC3" : "VEC4") || !cs ||
	    (ct != 5126 && (float_only || !norm)) || n < 1)
		return api_err_set(c->err, c->errsize, EXT ": the %s accessor is not a %s of floats%s", attr,
		                   comps == 3 ? "VEC3" : "VEC4", float_only ? "" : " or normalized integers"), -1;
	*count = (size_t)n;
	json_t *bvi = json_object_get(acc, "bufferView");
	json_t *bv = json_array_get(json_object_get(c->root, "bufferViews"), (size_t)json_integer_value(bvi));
	size_t elem = cs * (size_t)comps;
	size_t stride = (size_t)json_integer_value(json_object_get(bv, "byteStride"));
	stride = stride ? stride : elem;
	size_t voff = (size_t)json_integer_value(json_object_get(bv, "byteOffset"));
	size_t vlen = (size_t)json_integer_value(json_object_get(bv, "byteLength"));
	size_t aoff = (size_t)json_integer_value(json_object_get(acc, "byteOffset"));
	struct bytes *b = NULL;
	if (!bv || buffer_of(c, (size_t)json_integer_value(json_object_get(bv, "buffer")), &b) != 0) {
		if (!bv) api_err_set(c->err, c->errsize, EXT ": the %s accessor has no bufferView", attr);
		return -1;
	}
	/* Every element inside the view, the view inside the buffer (no overflow: n < 2^31). */
	if (!b->p || voff > b->n || vlen > b->n - voff || stride < elem || aoff > vlen || elem > vlen - aoff ||
	    (size_t)(n - 1) > (vlen - aoff - elem) / stride)
		return api_err_set(c->err, c->errsize, EXT ": the %s accessor's %lld values are not inside its buffer", attr,
		                   (long long)n), -1;
	float *v = malloc((size_t)n * (size_t)comps * sizeof *v);
	if (!v) return api_err_set(c->err, c->errsize, "out of memory"), -1;
	const uint8_t *base = b->p + voff + aoff;
	for (size_t i = 0; i < (size_t)n; i++)
		for (int k = 0; k < comps; k++) {
			float f = comp_value(base + i * stride + (size_t)k * cs, ct);
			v[i * (size_t)comps + (size_t)k] = isfinite(f) ? f : 0.0f;
		}
	*out = v;
	return 0;
}

static json_t *floats(const float *v, int n)
{
	json_t *a = json_array();
	for (int k = 0; a && k < n; k++) json_array_append_new(a, json_real(v[k]));
	return a;
}

/* The node's instances as its children (at most room); returns how many, or -1. */
static long expand_node(struct inst_ctx *c, json_t *nodes, json_t *node, json_t *ext, size_t room)
{
	json_t *mesh = json_object_get(node, "mesh"), *attrs = json_object_get(ext, "attributes");
	static const char *const NAMES[3] = {"TRANSLATION", "ROTATION", "SCALE"};
	static const int COMPS[3] = {3, 4, 3};
	float *v[3] = {NULL, NULL, NULL};
	size_t count = 0;
	long made = -1;
	if (!json_is_integer(mesh)) return 0;   /* the extension needs a mesh: nothing to draw */
	for (int a = 0; a < 3; a++) {
		json_t *ai = json_object_get(attrs, NAMES[a]);
		size_t n = 0;
		if (!ai) continue;
		if (read_accessor(c, ai, NAMES[a], COMPS[a], a == 0, &v[a], &n) != 0) goto out;
		if (count && n != count) {
			api_err_set(c->err, c->errsize, EXT ": the %s accessor has %zu values, another %zu", NAMES[a], n, count);
			goto out;
		}
		count = n;
	}
	if (count > room) {
		api_err_set(c->err, c->errsize, EXT ": more than %d instances in one model", API_GLTF_MAX_INSTANCES);
		goto out;
	}
	json_t *children = json_object_get(node, "children");
	if (!json_is_array(children)) {
		children = json_array();
		json_object_set_new(node, "children", children);
	}
	for (size_t i = 0; i < count; i++) {
		json_t *child = json_object();
		json_object_set(child, "mesh", mesh);
		for (int a = 0; a < 3; a++)
			if (v[a]) json_object_set_new(child, NAMES[a][0] == 'T' ? "translation" : NAMES[a][0] == 'R' ? "rotation" : "scale",
			                              floats(v[a] + i * (size_t)COMPS[a], COMPS[a]));
		json_array_append_new(children, json_integer((json_int_t)json_array_size(nodes)));
		if (json_array_append_new(nodes, child) != 0) {
			api_err_set(c->err, c->errsize, "out of memory");
			goto out;
		}
	}
	json_object_del(node, "mesh");
	json_object_del(json_object_get(node, "extensions"), EXT);
	made = (long)count;
out:
	for (int a = 0; a < 3; a++) free(v[a]);
	return made;
}

static void drop_from(json_t *root, const char *key)
{
	json_t *list = json_object_get(root, key), *e;
	size_t i;
	json_array_foreach(list, i, e)
		if (json_is_string(e) && !strcmp(json_string_value(e), EXT)) {
			json_array_remove(list, i);
			return;
		}
}

int api_gltf_expand_instancing(json_t *root, const uint8_t *data, size_t len, bool glb,
                               const struct api_model_file *files, size_t nfiles, size_t max, char *err,
                               size_t errsize)
{
	json_t *nodes = json_object_get(root, "nodes");
	size_t n0 = json_array_size(nodes), made = 0;
	struct inst_ctx c = {.root = root, .data = data, .len = len, .glb = glb, .files = files, .nfiles = nfiles,
	                     .nbuffers = json_array_size(json_object_get(root, "buffers")), .err = err, .errsize = errsize};
	int rc = 0;
	for (size_t i = 0; i < n0 && rc == 0; i++) {
		json_t *node = json_array_get(nodes, i);
		json_t *ext = json_object_get(json_object_get(node, "extensions"), EXT);
		if (!json_is_object(ext)) continue;
		if (!c.buffers && c.nbuffers && !(c.buffers = calloc(c.nbuffers, sizeof *c.buffers))) {
			api_err_set(err, errsize, "out of memory");
			rc = -1;
			break;
		}
		long k = expand_node(&c, nodes, node, ext, max - made);
		if (k < 0) rc = -1;
		else made += (size_t)k;
	}
	for (size_t b = 0; c.buffers && b < c.nbuffers; b++) free(c.buffers[b].owned);
	free(c.buffers);
	if (rc) return -1;
	if (made) {
		drop_from(root, "extensionsUsed");
		drop_from(root, "extensionsRequired");
	}
	return (int)made;
}
