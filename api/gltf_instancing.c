/*
 * api/gltf_instancing — EXT_mesh_gpu_instancing as child nodes (see the header).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "errmsg.h"
#include "gltf_instancing.h"

#define EXT "EXT_mesh_gpu_instancing"

/* Attribute `attr` of the extension as count x comps floats (malloc'd, yours). float_only:
 * TRANSLATION (the extension allows normalized integers for ROTATION and SCALE). */
static int read_attr(struct api_gltf_bufs *b, json_t *ai, const char *attr, int comps, bool float_only, float **out,
                     size_t *count, char *err, size_t errsize)
{
	*out = NULL;
	json_t *acc = json_is_integer(ai) ? json_array_get(json_object_get(b->root, "accessors"),
	                                                   (size_t)json_integer_value(ai)) : NULL;
	json_int_t ct = json_integer_value(json_object_get(acc, "componentType"));
	bool norm = json_is_true(json_object_get(acc, "normalized"));
	const char *type = json_string_value(json_object_get(acc, "type"));
	if (!acc || !type || strcmp(type, comps == 3 ? "VEC3" : "VEC4") ||
	    (ct != 5126 && (float_only || !norm || (ct != 5120 && ct != 5122))))
		return api_err_set(err, errsize, EXT ": the %s accessor is not a %s of floats%s", attr,
		                   comps == 3 ? "VEC3" : "VEC4", float_only ? "" : " or normalized bytes or shorts"), -1;
	char what[64];
	snprintf(what, sizeof what, EXT ": %s", attr);
	int nc = 0;
	return api_gltf_accessor_floats(b, acc, what, out, count, &nc, err, errsize);
}

static json_t *floats(const float *v, int n)
{
	json_t *a = json_array();
	for (int k = 0; a && k < n; k++) json_array_append_new(a, json_real(v[k]));
	return a;
}

/* The node's instances as its children (at most room); returns how many, or -1. */
static long expand_node(struct api_gltf_bufs *b, json_t *nodes, json_t *node, json_t *ext, size_t room, char *err,
                        size_t errsize)
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
		if (read_attr(b, ai, NAMES[a], COMPS[a], a == 0, &v[a], &n, err, errsize) != 0) goto out;
		if (count && n != count) {
			api_err_set(err, errsize, EXT ": the %s accessor has %zu values, another %zu", NAMES[a], n, count);
			goto out;
		}
		count = n;
	}
	if (count > room) {
		api_err_set(err, errsize, EXT ": more than %d instances in one model", API_GLTF_MAX_INSTANCES);
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
			api_err_set(err, errsize, "out of memory");
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

int api_gltf_expand_instancing(struct api_gltf_bufs *b, size_t max, char *err, size_t errsize)
{
	json_t *nodes = json_object_get(b->root, "nodes");
	size_t n0 = json_array_size(nodes), made = 0;
	for (size_t i = 0; i < n0; i++) {
		json_t *node = json_array_get(nodes, i);
		json_t *ext = json_object_get(json_object_get(node, "extensions"), EXT);
		if (!json_is_object(ext)) continue;
		long k = expand_node(b, nodes, node, ext, max - made, err, errsize);
		if (k < 0) return -1;
		made += (size_t)k;
	}
	if (made) {
		api_gltf_drop_extension_name(b->root, "extensionsUsed", EXT);
		api_gltf_drop_extension_name(b->root, "extensionsRequired", EXT);
	}
	return (int)made;
}
