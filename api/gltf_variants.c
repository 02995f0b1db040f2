/*
 * api/gltf_variants — a glTF model file with one of its KHR_materials_variants applied (see
 * the header).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "errmsg.h"
#include "gltf_buffers.h"
#include "gltf_variants.h"

#define VARIANTS "KHR_materials_variants"

static json_t *variant_list(json_t *root)
{
	return json_object_get(json_object_get(json_object_get(root, "extensions"), VARIANTS), "variants");
}

void api_gltf_variant_names(json_t *root, char *out, size_t size)
{
	json_t *v;
	size_t i, n = 0;
	if (!size) return;
	out[0] = 0;
	json_array_foreach(variant_list(root), i, v) {
		const char *name = json_string_value(json_object_get(v, "name"));
		char one[80];
		int k = snprintf(one, sizeof one, "%s\"%.60s\"", i ? ", " : "", name ? name : "");
		if (n + (size_t)k + 4 >= size) {
			snprintf(out + n, size - n, "...");
			return;
		}
		memcpy(out + n, one, (size_t)k + 1);
		n += (size_t)k;
	}
	for (char *p = out; *p; p++)   /* names come from the file: printable ASCII in a sentence */
		if (*p < 0x20 || *p > 0x7e) *p = '?';
}

/* The index of variant `name` in root, or -1 with err saying what the file has. */
static long find_variant(json_t *root, const char *name, char *err, size_t errsize)
{
	json_t *list = variant_list(root), *v;
	size_t i;
	json_array_foreach(list, i, v) {
		const char *s = json_string_value(json_object_get(v, "name"));
		if (s && !strcmp(s, name)) return (long)i;
	}
	char names[300];
	api_gltf_variant_names(root, names, sizeof names);
	if (!names[0])
		api_err_set(err, errsize, "the model has no material variants (" VARIANTS "): leave variant out");
	else api_err_set(err, errsize, "variant \"%.60s\" is not one of the model's: %s", name, names);
	return -1;
}

/* Primitive p's material for variant vi, if one of its mappings names it. 0, or -1 with err. */
static int map_primitive(json_t *p, long vi, size_t nmat, size_t mi, size_t pi, char *err, size_t errsize)
{
	json_t *maps = json_object_get(json_object_get(json_object_get(p, "extensions"), VARIANTS), "mappings"), *m, *v;
	size_t i, j;
	json_array_foreach(maps, i, m) {
		json_array_foreach(json_object_get(m, "variants"), j, v) {
			if (json_integer_value(v) != vi || !json_is_integer(v)) continue;
			json_t *mat = json_object_get(m, "material");
			if (!json_is_integer(mat) || json_integer_value(mat) < 0 || (size_t)json_integer_value(mat) >= nmat)
				return api_err_set(err, errsize, VARIANTS ": mesh %zu primitive %zu maps the variant to a material the "
				                   "model does not have", mi, pi), -1;
			json_object_set(p, "material", mat);
			return 0;
		}
	}
	return 0;
}

uint8_t *api_gltf_pick_variant(const uint8_t *d, size_t len, bool glb, const char *name, size_t *out_len, bool *oom,
                               char *err, size_t errsize)
{
	*oom = false;
	const char *json;
	size_t jlen;
	const char *bad = api_gltf_json_of(d, len, glb, &json, &jlen);
	if (bad) return api_err_set(err, errsize, "%s", bad), NULL;
	json_error_t je;
	json_t *root = json_loadb(json, jlen, 0, &je);
	if (!json_is_object(root)) {
		api_err_set(err, errsize, "the glTF JSON is malformed (line %d: %s)", je.line, root ? "not an object" : je.text);
		json_decref(root);
		return NULL;
	}
	uint8_t *out = NULL;
	long vi = find_variant(root, name, err, errsize);
	size_t nmat = json_array_size(json_object_get(root, "materials"));
	json_t *m, *p;
	size_t i, j;
	int rc = vi < 0 ? -1 : 0;
	json_array_foreach(json_object_get(root, "meshes"), i, m) {
		json_array_foreach(json_object_get(m, "primitives"), j, p) {
			if (rc == 0) rc = map_primitive(p, vi, nmat, i, j, err, errsize);
		}
	}
	if (rc == 0) {
		/* A file without variants now: the importer does not warn of the default. */
		api_gltf_drop_extension_name(root, "extensionsUsed", VARIANTS);
		api_gltf_drop_extension_name(root, "extensionsRequired", VARIANTS);
		char *js = json_dumps(root, JSON_COMPACT);
		out = js ? api_gltf_with_json(d, len, glb, js, strlen(js), out_len) : NULL;
		free(js);
		if (!out) *oom = true, api_err_set(err, errsize, "out of memory");
	}
	json_decref(root);
	return out;
}
