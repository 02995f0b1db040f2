/* tests — KHR_materials_variants (api/gltf_variants.c): a .glb quad built here with a red
 * default material and the variants "Green" and "Blue" mapped to green and blue materials.
 * A model object's "variant" draws the mapped material; without it the default is drawn and
 * the warning names the variants; an unknown name, a file without variants and a non-glTF
 * model are 400s at /objects/0/variant saying what there is. Before, there was no member:
 * the default materials only. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "models.h"
#include "test.h"
#include "util.h"

static const float POS[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
static const uint16_t IDX[6] = {0, 1, 2, 0, 2, 3};

/* The quad with (variants) or without the extension. */
static uint8_t *variants_glb(bool variants, size_t *len)
{
	uint8_t bin[60] = {0};
	memcpy(bin, POS, 48);
	memcpy(bin + 48, IDX, 12);
	char json[2048];
	int n = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},%s\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0%s}]}],"
		"\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1]}},"
		"{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,1,0,1]}},{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,1,1]}}],"
		"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
		"{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],"
		"\"buffers\":[{\"byteLength\":60}]}",
		variants ? "\"extensionsUsed\":[\"KHR_materials_variants\"],\"extensions\":{\"KHR_materials_variants\":"
		           "{\"variants\":[{\"name\":\"Green\"},{\"name\":\"Blue\"}]}}," : "",
		variants ? ",\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":1,\"variants\":[0]},"
		           "{\"material\":2,\"variants\":[1]}]}}" : "");
	return test_glb_pack(json, (size_t)n, bin, sizeof bin, sizeof bin, len);
}

/* The scene of one model object (data d, format) with "variant": variant (NULL: none). */
static struct api_scene *parse_variant(const uint8_t *d, size_t n, const char *format, const char *variant,
                                       struct api_problem *p)
{
	char *enc = test_b64(d, n);
	size_t cap = strlen(enc) + 256;
	char *doc = malloc(cap);
	char v[96] = "";
	if (variant) snprintf(v, sizeof v, ",\"variant\":\"%s\"", variant);
	snprintf(doc, cap, "{\"camera\":{\"position\":[0,0,30]},\"objects\":[{\"shape\":\"model\",\"format\":\"%s\","
	         "\"data\":\"%s\"%s}]}", format, enc, v);
	free(enc);
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	if (api_scene_parse(doc, strlen(doc), NULL, &s, p) != API_OK) s = NULL;
	free(doc);
	return s;
}

TEST(gltf_variant_draws_the_mapped_material)
{
	size_t n;
	uint8_t *g = variants_glb(true, &n);
	REQUIRE(g);
	static const char *const names[3] = {NULL, "Green", "Blue"};
	for (int k = 0; k < 3; k++) {
		struct api_problem p;
		struct api_scene *s = parse_variant(g, n, "glb", names[k], &p);
		CHECK(s, "%s: %d %s: %s", names[k] ? names[k] : "default", p.status, p.pointer, p.detail);
		if (!s) continue;
		const struct rnd_scene *sc = &s->scene;
		const float *c = sc->materials[sc->objects[0].material].base_color;
		CHECK(c[k] > 0.9f && c[(k + 1) % 3] < 0.1f && c[(k + 2) % 3] < 0.1f, "%s: base colour %.2f %.2f %.2f",
		      names[k] ? names[k] : "default", c[0], c[1], c[2]);
		const char *w = s->warnings;
		if (k == 0) CHECK(strstr(w, "\"variant\" picks one of \"Green\", \"Blue\""), "default: warnings: %s", w);
		else CHECK(!strstr(w, "variants"), "%s: warned: %s", names[k], w);
		api_scene_free(s);
	}
	free(g);
}

TEST(gltf_variant_unknown_or_absent_is_400_at_its_pointer)
{
	size_t n, m;
	uint8_t *with = variants_glb(true, &n), *without = variants_glb(false, &m);
	uint8_t stl[284];
	const float tet[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	size_t ns = test_tetra_stl(stl, tet);
	REQUIRE(with && without);
	struct { const uint8_t *d; size_t n; const char *format, *says; } cases[3] = {
		{with, n, "glb", "variant \"Pink\" is not one of the model's: \"Green\", \"Blue\""},
		{without, m, "glb", "has no material variants"},
		{stl, ns, "stl", "this model is a stl file"}};
	for (int k = 0; k < 3; k++) {
		struct api_problem p;
		struct api_scene *s = parse_variant(cases[k].d, cases[k].n, cases[k].format, "Pink", &p);
		CHECK(!s, "case %d accepted", k);
		if (s) api_scene_free(s);
		CHECK(p.status == 400 && !strcmp(p.pointer, "/objects/0/variant") && strstr(p.detail, cases[k].says),
		      "case %d: %d %s: %s", k, p.status, p.pointer, p.detail);
	}
	free(with);
	free(without);
}
