/*
 * api/gltf_draco — KHR_draco_mesh_compression decoded before Assimp reads the document (see
 * api/gltf_decode.h): each compressed primitive's Draco mesh decoded with libdraco
 * (api/draco.h), its indices and the attributes the extension names written into the made
 * buffer in the types their accessors state, and the accessors pointed there; the
 * extension then leaves the primitive. What follows (integer attributes as floats, skins
 * dropped, instancing, material tags) reads those accessors like any other.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "draco.h"
#include "errmsg.h"
#include "gltf_decode.h"

#define DRACO "KHR_draco_mesh_compression"

/* bytes[0..n) as a new view of the made buffer, accessor acc pointed at it as componentType
 * ct. 0, or -1 with err. */
static int point_accessor(struct api_gltf_bufs *b, json_t *acc, json_int_t ct, const void *bytes, size_t n,
                          char *err, size_t errsize)
{
	long view = api_gltf_made_view(b, bytes, n);
	if (view < 0) return b->oom = true, api_err_set(err, errsize, "out of memory"), -1;
	json_object_set_new(acc, "bufferView", json_integer(view));
	json_object_set_new(acc, "componentType", json_integer(ct));
	json_object_del(acc, "byteOffset");
	return 0;
}

/* The faces as the primitive's indices (a new accessor when it has none). */
static int draco_indices(struct api_gltf_bufs *b, json_t *prim, const struct api_draco *d, const char *what,
                         char *err, size_t errsize)
{
	json_t *accs = json_object_get(b->root, "accessors");
	size_t n = (size_t)api_draco_faces(d) * 3;
	json_t *ia = json_object_get(prim, "indices"), *acc;
	if (json_is_integer(ia)) {
		acc = json_array_get(accs, (size_t)json_integer_value(ia));
		if (!json_is_object(acc) || json_integer_value(json_object_get(acc, "count")) != (json_int_t)n)
			return api_err_set(err, errsize, "%s: the indices accessor's count is not the decoded mesh's %zu", what, n), -1;
	} else {
		acc = json_pack("{s:I,s:s}", "count", (json_int_t)n, "type", "SCALAR");
		if (!acc || json_array_append_new(accs, acc) != 0)
			return b->oom = true, api_err_set(err, errsize, "out of memory"), -1;
		json_object_set_new(prim, "indices", json_integer((json_int_t)json_array_size(accs) - 1));
	}
	uint32_t *idx = malloc(n ? n * sizeof *idx : 1);
	if (!idx) return b->oom = true, api_err_set(err, errsize, "out of memory"), -1;
	api_draco_indices(d, idx);
	int rc = point_accessor(b, acc, 5125, idx, n * sizeof *idx, err, errsize);
	free(idx);
	return rc;
}

/* Attribute `name` (the Draco attribute of unique id uid) into its accessor. */
static int draco_attribute(struct api_gltf_bufs *b, json_t *prim, const struct api_draco *d, const char *name,
                           json_t *uid, const char *what, char *err, size_t errsize)
{
	json_t *ai = json_object_get(json_object_get(prim, "attributes"), name);
	json_t *acc = json_array_get(json_object_get(b->root, "accessors"), (size_t)json_integer_value(ai));
	if (!json_is_integer(ai) || !json_is_object(acc))
		return api_err_set(err, errsize, "%s: attribute %.40s has no accessor in the primitive", what, name), -1;
	json_int_t ct = json_integer_value(json_object_get(acc, "componentType"));
	int comps = api_gltf_type_components(json_string_value(json_object_get(acc, "type")));
	size_t np = api_draco_points(d), size = comps <= 4 ? api_gltf_component_size(ct) * (size_t)comps : 0;
	if (!json_is_integer(uid) || json_integer_value(uid) < 0 || json_integer_value(uid) > UINT32_MAX || !size)
		return api_err_set(err, errsize, "%s: attribute %.40s is not a Draco attribute id of a known type", what, name), -1;
	if (json_integer_value(json_object_get(acc, "count")) != (json_int_t)np)
		return api_err_set(err, errsize, "%s: attribute %.40s's accessor count is not the decoded mesh's %zu points", what,
		                   name, np), -1;
	if (np > API_GLTF_MAX_DECODED_VIEW / size)
		return api_err_set(err, errsize, "%s: attribute %.40s decodes to more than %zu bytes", what, name,
		                   API_GLTF_MAX_DECODED_VIEW), -1;
	void *out = malloc(np ? np * size : 1);
	if (!out) return b->oom = true, api_err_set(err, errsize, "out of memory"), -1;
	char e[120];
	int rc = api_draco_attribute(d, (uint32_t)json_integer_value(uid), (int)ct, comps, out, e, sizeof e) == API_DRACO_OK
	         ? point_accessor(b, acc, ct, out, np * size, err, errsize)
	         : (api_err_set(err, errsize, "%s: attribute %.40s (Draco id %lld): %s", what, name,
	                        (long long)json_integer_value(uid), e), -1);
	free(out);
	return rc;
}

static int decode_primitive(struct api_gltf_bufs *b, json_t *prim, json_t *ext, const char *what, char *err,
                            size_t errsize)
{
	json_int_t mode = json_object_get(prim, "mode") ? json_integer_value(json_object_get(prim, "mode")) : 4;
	if (mode != 4 && mode != 5)
		return api_err_set(err, errsize, "%s: mode %lld (Draco compresses triangles only)", what, (long long)mode), -1;
	json_t *bv = json_object_get(ext, "bufferView");
	if (!json_is_integer(bv) || json_integer_value(bv) < 0)
		return api_err_set(err, errsize, "%s: no bufferView", what), -1;
	json_t *view = json_array_get(json_object_get(b->root, "bufferViews"), (size_t)json_integer_value(bv));
	const uint8_t *src;
	size_t n;
	if (api_gltf_view_bytes(b, view, what, &src, &n, err, errsize) != 0) return -1;
	struct api_draco *d;
	char e[160];
	enum api_draco_result r = api_draco_decode(src, n, &d, e, sizeof e);
	if (r != API_DRACO_OK) {
		b->oom = r == API_DRACO_NO_MEMORY;
		return api_err_set(err, errsize, "%s does not decode (libdraco: %s)", what, e), -1;
	}
	int rc = draco_indices(b, prim, d, what, err, errsize);
	json_t *uid;
	const char *name;
	json_object_foreach(json_object_get(ext, "attributes"), name, uid) {
		if (rc) break;
		rc = draco_attribute(b, prim, d, name, uid, what, err, errsize);
	}
	api_draco_free(d);
	if (rc) return -1;
	/* The decoded faces are a triangle list, whatever the strip said. */
	json_object_set_new(prim, "mode", json_integer(4));
	json_t *exts = json_object_get(prim, "extensions");
	json_object_del(exts, DRACO);
	if (!json_object_size(exts)) json_object_del(prim, "extensions");
	return 0;
}

long api_gltf_decode_draco(struct api_gltf_bufs *b, char *err, size_t errsize)
{
	json_t *m, *p;
	size_t i, j;
	long made = 0;
	json_array_foreach(json_object_get(b->root, "meshes"), i, m) {
		json_array_foreach(json_object_get(m, "primitives"), j, p) {
			json_t *ext = json_object_get(json_object_get(p, "extensions"), DRACO);
			if (!json_is_object(ext)) continue;
			char what[96];
			snprintf(what, sizeof what, DRACO " mesh %zu primitive %zu", i, j);
			if (decode_primitive(b, p, ext, what, err, errsize) != 0) return -1;
			made++;
		}
	}
	api_gltf_drop_extension_name(b->root, "extensionsUsed", DRACO);
	api_gltf_drop_extension_name(b->root, "extensionsRequired", DRACO);
	return made;
}
