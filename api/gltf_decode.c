/*
 * api/gltf_decode — meshopt-compressed views and quantized attributes made readable (see the
 * header; Draco: api/gltf_draco.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <meshoptimizer.h>
#include "errmsg.h"
#include "gltf_decode.h"

#define MESHOPT "EXT_meshopt_compression"
#define QUANT "KHR_mesh_quantization"

/* meshopt's decoders by mode and filter, into dst (count x stride bytes). 0, or -1 with err. */
static int meshopt_decode(uint8_t *dst, size_t count, size_t stride, const char *mode, const char *filter,
                          const uint8_t *src, size_t n, size_t vi, char *err, size_t errsize)
{
	int rc = -2;
	if (!strcmp(mode, "ATTRIBUTES")) {
		if (stride % 4 || stride > 256) goto bad;
		rc = meshopt_decodeVertexBuffer(dst, count, stride, src, n);
		if (rc == 0 && filter && !strcmp(filter, "OCTAHEDRAL")) {
			if (stride != 4 && stride != 8) goto bad;
			meshopt_decodeFilterOct(dst, count, stride);
		} else if (rc == 0 && filter && !strcmp(filter, "QUATERNION")) {
			if (stride != 8) goto bad;
			meshopt_decodeFilterQuat(dst, count, stride);
		} else if (rc == 0 && filter && !strcmp(filter, "EXPONENTIAL")) {
			meshopt_decodeFilterExp(dst, count, stride);
		} else if (rc == 0 && filter && strcmp(filter, "NONE")) {
			goto bad;
		}
	} else if (!strcmp(mode, "TRIANGLES") || !strcmp(mode, "INDICES")) {
		if ((stride != 2 && stride != 4) || (mode[0] == 'T' && count % 3)) goto bad;
		rc = mode[0] == 'T' ? meshopt_decodeIndexBuffer(dst, count, stride, src, n)
		                    : meshopt_decodeIndexSequence(dst, count, stride, src, n);
	}
	if (rc == 0) return 0;
	if (rc != -2) return api_err_set(err, errsize, MESHOPT ": bufferView %zu does not decode (meshoptimizer: %d)", vi, rc), -1;
bad:
	return api_err_set(err, errsize, MESHOPT ": bufferView %zu: mode %.20s, filter %.20s and byteStride %zu do not go "
	                   "together", vi, mode, filter ? filter : "NONE", stride), -1;
}

static int decode_view(struct api_gltf_bufs *b, json_t *view, json_t *ext, size_t vi, char *err, size_t errsize)
{
	json_int_t count = json_integer_value(json_object_get(ext, "count"));
	json_int_t stride = json_integer_value(json_object_get(ext, "byteStride"));
	const char *mode = json_string_value(json_object_get(ext, "mode"));
	const char *filter = json_string_value(json_object_get(ext, "filter"));
	if (count < 1 || stride < 1 || !mode || (uint64_t)count > API_GLTF_MAX_DECODED_VIEW / (uint64_t)stride)
		return api_err_set(err, errsize, MESHOPT ": bufferView %zu: count %lld x byteStride %lld is not a size to decode",
		                   vi, (long long)count, (long long)stride), -1;
	char what[64];
	snprintf(what, sizeof what, MESHOPT " bufferView %zu", vi);
	const uint8_t *src;
	size_t n;
	/* The extension object names the compressed bytes as a bufferView does. */
	if (api_gltf_view_bytes(b, ext, what, &src, &n, err, errsize) != 0) return -1;
	size_t size = (size_t)count * (size_t)stride;
	uint8_t *dst = malloc(size);
	if (!dst) return api_err_set(err, errsize, "out of memory"), -1;
	int rc = meshopt_decode(dst, (size_t)count, (size_t)stride, mode, filter, src, n, vi, err, errsize);
	long at = rc == 0 ? api_gltf_made_bytes(b, dst, size) : -1;
	free(dst);
	if (rc != 0) return -1;
	if (at < 0) return api_err_set(err, errsize, "out of memory"), -1;
	json_object_set_new(view, "buffer", json_integer(b->made_index));
	json_object_set_new(view, "byteOffset", json_integer(at));
	json_object_set_new(view, "byteLength", json_integer((json_int_t)size));
	json_object_del(json_object_get(view, "extensions"), MESHOPT);
	return 0;
}

static long decode_meshopt(struct api_gltf_bufs *b, char *err, size_t errsize)
{
	json_t *views = json_object_get(b->root, "bufferViews"), *v;
	size_t i;
	long made = 0;
	json_array_foreach(views, i, v) {
		json_t *ext = json_object_get(json_object_get(v, "extensions"), MESHOPT);
		if (!json_is_object(ext)) continue;
		if (decode_view(b, v, ext, i, err, errsize) != 0) return -1;
		made++;
	}
	return made;
}

/* Accessor ai (used by a vertex attribute) as floats in a view of the made buffer, if it is
 * stored as integers. 1 changed, 0 not, -1 err. */
static int float_accessor(struct api_gltf_bufs *b, json_t *acc, const char *attr, char *err, size_t errsize)
{
	json_int_t ct = json_integer_value(json_object_get(acc, "componentType"));
	if (!json_is_object(acc) || ct == 5126 || json_object_get(acc, "sparse") || !json_object_get(acc, "bufferView"))
		return 0;
	char what[64];
	snprintf(what, sizeof what, "the %.20s attribute", attr);
	float *v = NULL;
	size_t count = 0;
	int comps = 0;
	if (api_gltf_accessor_floats(b, acc, what, &v, &count, &comps, err, errsize) != 0) return -1;
	long view = api_gltf_made_view(b, v, count * (size_t)comps * sizeof *v);
	if (view >= 0 && (json_object_get(acc, "min") || json_object_get(acc, "max"))) {
		json_t *mn = json_array(), *mx = json_array();
		for (int k = 0; k < comps; k++) {
			float lo = INFINITY, hi = -INFINITY;
			for (size_t i = 0; i < count; i++) {
				lo = fminf(lo, v[i * (size_t)comps + (size_t)k]);
				hi = fmaxf(hi, v[i * (size_t)comps + (size_t)k]);
			}
			json_array_append_new(mn, json_real(lo));
			json_array_append_new(mx, json_real(hi));
		}
		json_object_set_new(acc, "min", mn);
		json_object_set_new(acc, "max", mx);
	}
	free(v);
	if (view < 0) return api_err_set(err, errsize, "out of memory"), -1;
	json_object_set_new(acc, "bufferView", json_integer(view));
	json_object_set_new(acc, "componentType", json_integer(5126));
	json_object_del(acc, "byteOffset");
	json_object_del(acc, "normalized");
	return 1;
}

static int float_attributes(struct api_gltf_bufs *b, json_t *attrs, bool *seen, size_t nacc, char *err,
                            size_t errsize)
{
	json_t *accs = json_object_get(b->root, "accessors"), *ai;
	const char *name;
	int made = 0;
	json_object_foreach(attrs, name, ai) {
		json_int_t i = json_integer_value(ai);
		if (!json_is_integer(ai) || i < 0 || (size_t)i >= nacc || seen[i]) continue;
		seen[i] = true;
		int r = float_accessor(b, json_array_get(accs, (size_t)i), name, err, errsize);
		if (r < 0) return -1;
		made += r;
	}
	return made;
}

static long dequantize(struct api_gltf_bufs *b, char *err, size_t errsize)
{
	size_t nacc = json_array_size(json_object_get(b->root, "accessors"));
	bool *seen = calloc(nacc ? nacc : 1, sizeof *seen);
	if (!seen) return api_err_set(err, errsize, "out of memory"), -1;
	json_t *meshes = json_object_get(b->root, "meshes"), *m, *p, *t;
	size_t i, j, k;
	long made = 0;
	json_array_foreach(meshes, i, m) {
		json_array_foreach(json_object_get(m, "primitives"), j, p) {
			int r = float_attributes(b, json_object_get(p, "attributes"), seen, nacc, err, errsize);
			json_array_foreach(json_object_get(p, "targets"), k, t) {
				if (r < 0) break;
				int rt = float_attributes(b, t, seen, nacc, err, errsize);
				r = rt < 0 ? -1 : r + rt;
			}
			if (r < 0) {
				free(seen);
				return -1;
			}
			made += r;
		}
	}
	free(seen);
	return made;
}

int api_gltf_decode(struct api_gltf_bufs *b, char *err, size_t errsize)
{
	long a = decode_meshopt(b, err, errsize);
	long d = a < 0 ? -1 : api_gltf_decode_draco(b, err, errsize);
	long q = d < 0 ? -1 : dequantize(b, err, errsize);
	if (q < 0) return -1;
	api_gltf_drop_extension_name(b->root, "extensionsUsed", MESHOPT);
	api_gltf_drop_extension_name(b->root, "extensionsRequired", MESHOPT);
	api_gltf_drop_extension_name(b->root, "extensionsUsed", QUANT);
	api_gltf_drop_extension_name(b->root, "extensionsRequired", QUANT);
	return a + d + q > 0;
}

void api_gltf_drop_fallbacks(json_t *root)
{
	json_t *bufs = json_object_get(root, "buffers"), *views = json_object_get(root, "bufferViews"), *v;
	size_t nb = json_array_size(bufs), i;
	if (!nb) return;
	long *map = calloc(nb, sizeof *map);
	bool *used = calloc(nb, sizeof *used);
	if (!map || !used) goto out;
	json_array_foreach(views, i, v) {
		json_int_t bi = json_integer_value(json_object_get(v, "buffer"));
		if (bi >= 0 && (size_t)bi < nb) used[bi] = true;
	}
	/* Buffer 0 of a glb (the BIN chunk, no uri) stays: dropping it would make another buffer
	 * the BIN chunk's. */
	long next = 0;
	for (size_t b = 0; b < nb; b++) {
		bool keep = used[b] || json_object_get(json_array_get(bufs, b), "uri") || b == 0;
		map[b] = keep ? next++ : -1;
	}
	json_array_foreach(views, i, v) {
		json_int_t bi = json_integer_value(json_object_get(v, "buffer"));
		if (bi >= 0 && (size_t)bi < nb && map[bi] >= 0) json_object_set_new(v, "buffer", json_integer(map[bi]));
	}
	for (size_t b = nb; b-- > 0;)
		if (map[b] < 0) json_array_remove(bufs, b);
out:
	free(map);
	free(used);
}

bool api_gltf_drop_skins(json_t *root)
{
	bool changed = false;
	json_t *m, *p, *n;
	size_t i, j;
	json_array_foreach(json_object_get(root, "meshes"), i, m) {
		json_array_foreach(json_object_get(m, "primitives"), j, p) {
			json_t *attrs = json_object_get(p, "attributes");
			const char *key;
			void *tmp;
			json_t *v;
			json_object_foreach_safe(attrs, tmp, key, v) {
				if (strncmp(key, "JOINTS_", 7) && strncmp(key, "WEIGHTS_", 8)) continue;
				json_object_del(attrs, key);
				changed = true;
			}
		}
	}
	json_array_foreach(json_object_get(root, "nodes"), i, n)
		if (json_object_get(n, "skin")) {
			json_object_del(n, "skin");
			changed = true;
		}
	if (json_object_get(root, "skins")) {
		json_object_del(root, "skins");
		changed = true;
	}
	return changed;
}

bool api_gltf_all_indexed(json_t *root)
{
	json_t *m, *p;
	size_t i, j;
	json_array_foreach(json_object_get(root, "meshes"), i, m) {
		json_array_foreach(json_object_get(m, "primitives"), j, p) {
			if (!json_is_integer(json_object_get(p, "indices"))) return false;
		}
	}
	return true;
}
