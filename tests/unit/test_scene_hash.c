/* tests — api/scene_hash.c: the canonical hash behind the ETag is of the parsed scene with its
 * defaults filled (a default written out or left out hashes alike), keeps what the parsed
 * scene does not hold (data, model sources, a model's format hint), and no address reaches it. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api.h"
#include "models.h"
#include "test.h"
#include "util.h"

/* The scene hash of a document written with ' for " (test_vdoc); 0 when it does not parse. */
static uint64_t hash_of(const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	char *doc = test_vdoc(fmt, ap);
	va_end(ap);
	struct api_scene *s = NULL;
	struct api_problem p;
	uint64_t h = 0;
	if (doc && api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_OK) h = s->scene_hash;
	else fprintf(stderr, "# parse failed: %s at %s\n", doc ? p.detail : "out of memory", doc ? p.pointer : "");
	api_scene_free(s);
	free(doc);
	return h;
}

#define SCENE(objects, rest) \
	"{'width': 32, 'height': 32, 'camera': {'position': [0, 1, 6], 'target': [0, 0, 0]}, 'objects': [" objects \
	"], 'lights': [{'type': 'directional', 'direction': [-1, -2, -1]}]" rest "}"

/* Each pair: a member (or object) given its default value, and the same scene without it. */
static const char *const SAME[][2] = {
	{SCENE("{'shape': 'sphere', 'segments': 64}", ""), SCENE("{'shape': 'sphere'}", "")},
	{SCENE("{'shape': 'sphere', 'radius': 1.0, 'cast_shadows': true}", ""), SCENE("{'shape': 'sphere'}", "")},
	{SCENE("{'shape': 'box', 'size': [1, 1, 1], 'transform': {'translation': [0, 0, 0], 'scale': [1, 1, 1]}}", ""),
	 SCENE("{'shape': 'box'}", "")},
	{SCENE("{'shape': 'box', 'material': {'roughness': 0.5, 'base_color': [0.8, 0.8, 0.8, 1]}}", ""),
	 SCENE("{'shape': 'box', 'material': {}}", "")},
	{SCENE("{'shape': 'box'}", ", 'shadows': {'enabled': true, 'filter': 'auto', 'directional': {'mode': 'auto'}}"),
	 SCENE("{'shape': 'box'}", "")},
	{SCENE("{'shape': 'box'}", ", 'shadows': true"), SCENE("{'shape': 'box'}", "")},
	{SCENE("{'shape': 'box'}", ", 'output': {'format': 'png', 'msaa': 4, 'tonemap': 'neutral', 'transparent': false}"),
	 SCENE("{'shape': 'box'}", ", 'output': {'format': 'png'}")},
	{SCENE("{'shape': 'box'}", ", 'environment': {'background': [0.5, 0.5, 0.5, 1], 'ambient': {}}"),
	 SCENE("{'shape': 'box'}", "")},
	/* Degrees to the same float radians; a number past float precision. */
	{"{'width': 32, 'height': 32, 'camera': {'position': [0, 1, 6], 'target': [0, 0, 0], 'fov_y': 45.000000000001,"
	 " 'up': [0, 1, 0], 'exposure': 0}, 'objects': [{'shape': 'sphere', 'radius': 1.00000000000001}]}",
	 "{'width': 32, 'height': 32, 'camera': {'position': [0, 1, 6], 'target': [0, 0, 0]}, 'objects': [{'shape': "
	 "'sphere'}]}"},
	/* A light's own shadow settings equal to the root's it would take. */
	{SCENE("{'shape': 'box'}", ", 'shadows': {'filter': 'pcss'}"),
	 "{'width': 32, 'height': 32, 'camera': {'position': [0, 1, 6], 'target': [0, 0, 0]}, 'objects': [{'shape': 'box'}],"
	 " 'lights': [{'type': 'directional', 'direction': [-1, -2, -1], 'shadow': {'filter': 'pcss'}}]}"},
};

TEST(scene_hash_fills_defaults)
{
	for (size_t i = 0; i < sizeof SAME / sizeof SAME[0]; i++) {
		uint64_t a = hash_of(SAME[i][0]), b = hash_of(SAME[i][1]);
		CHECK(a != 0 && a == b, "pair %zu: a default written out or left out must hash alike (%016llx vs %016llx)",
		      i, (unsigned long long)a, (unsigned long long)b);
	}
}

/* Each pair differs in what is drawn or answered: the hashes must differ. */
static const char *const DIFFERENT[][2] = {
	{SCENE("{'shape': 'sphere', 'segments': 32}", ""), SCENE("{'shape': 'sphere'}", "")},
	{SCENE("{'shape': 'sphere', 'radius': 1.001}", ""), SCENE("{'shape': 'sphere'}", "")},
	{SCENE("{'shape': 'box'}", ", 'shadows': {'filter': 'pcf'}"), SCENE("{'shape': 'box'}", "")},
	{SCENE("{'shape': 'box'}", ", 'shadows': false"), SCENE("{'shape': 'box'}", "")},
	{SCENE("{'shape': 'box'}", ", 'output': {'quality': 80, 'format': 'webp'}"),
	 SCENE("{'shape': 'box'}", ", 'output': {'format': 'webp'}")},
	{SCENE("{'shape': 'box'}", ", 'output': {'aovs': ['depth']}"), SCENE("{'shape': 'box'}", "")},
	/* The format given or chosen by Accept later: output.format is part of the answer. */
	{SCENE("{'shape': 'box'}", ", 'output': {'format': 'png'}"), SCENE("{'shape': 'box'}", "")},
	/* Data: a mesh's vertices, in arrays or base64. */
	{SCENE("{'shape': 'mesh', 'positions': [0, 0, 0, 1, 0, 0, 0, 1, 0]}", ""),
	 SCENE("{'shape': 'mesh', 'positions': [0, 0, 0, 1, 0, 0, 0, 2, 0]}", "")},
	/* A member the scene names but does not draw differently is kept (conservative). */
	{SCENE("{'shape': 'box', 'extras': {'a': 1}}", ""), SCENE("{'shape': 'box'}", "")},
};

TEST(scene_hash_tells_scenes_apart)
{
	for (size_t i = 0; i < sizeof DIFFERENT / sizeof DIFFERENT[0]; i++) {
		uint64_t a = hash_of(DIFFERENT[i][0]), b = hash_of(DIFFERENT[i][1]);
		CHECK(a != 0 && b != 0 && a != b, "pair %zu: different scenes must hash apart", i);
	}
}

/* An STL tetrahedron as a model, inline (base64) with an optional format hint. */
static uint64_t tetra_hash(float scale, const char *format_member)
{
	const float p[4][3] = {{0, 0, 0}, {scale, 0, 0}, {0, scale, 0}, {0, 0, scale}};
	uint8_t stl[284];
	size_t n = test_tetra_stl(stl, p);
	char *b64 = test_b64(stl, n);
	uint64_t h = b64 ? hash_of(SCENE("{'shape': 'model', 'data': '%s'%s}", ""), b64, format_member) : 0;
	free(b64);
	return h;
}

TEST(scene_hash_keeps_model_sources)
{
	uint64_t plain = tetra_hash(1, "");
	CHECK(plain != 0);
	CHECK(tetra_hash(1, "") == plain, "the same model bytes hash alike");
	CHECK(tetra_hash(2, "") != plain, "other model bytes hash apart");
	/* The format is a hint to the importer, not a value of the parsed scene: kept as written. */
	CHECK(tetra_hash(1, ", 'format': 'stl'") != plain, "a model's format hint stays in the hash");
}

/* A scene with every kind of pointer the parsed scene holds: mesh arrays, a texture, an
 * imported model (its levels, bounds), several views. */
static char *pointer_scene(void)
{
	uint8_t px[4 * 4] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
	size_t n = 0, pn = 0;
	uint8_t *stl = test_bumpy_stl(110, &n), *png = test_png_rgba(px, 2, 2, &pn);
	char *m = stl ? test_b64(stl, n) : NULL, *t = png ? test_b64(png, pn) : NULL;
	free(stl);
	free(png);
	const char *fmt = "{'width': 32, 'height': 32, 'views': [{'position': [0, 1, 6], 'target': [0, 0, 0]}, "
	                  "{'position': [6, 1, 0], 'target': [0, 0, 0]}], 'objects': [{'shape': 'model', 'data': '%s'}, "
	                  "{'shape': 'mesh', 'positions': [0, 0, 0, 1, 0, 0, 0, 1, 0], 'normals': [0, 0, 1, 0, 0, 1, 0, 0, 1], "
	                  "'uvs': [0, 0, 1, 0, 0, 1], 'indices': [0, 1, 2], 'material': {'base_color_texture': '%s'}}], "
	                  "'lights': [{'type': 'spot', 'position': [0, 3, 0], 'direction': [0, -1, 0]}]}";
	char *doc = NULL;
	if (m && t) {
		size_t len = strlen(fmt) + strlen(m) + strlen(t);
		doc = malloc(len);
		if (doc) {
			snprintf(doc, len, fmt, m, t);
			for (char *c = doc; *c; c++)
				if (*c == '\'') *c = '"';
		}
	}
	free(m);
	free(t);
	return doc;
}

TEST(scene_hash_ignores_addresses)
{
	char *doc = pointer_scene();
	REQUIRE(doc != NULL);
	struct api_scene *a = NULL, *b = NULL;
	struct api_problem p;
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &a, &p) == API_OK, "%s at %s", p.detail, p.pointer);
	/* A second parse with the model imported again: every array at another address. */
	api_model_cache_clear();
	REQUIRE(api_scene_parse(doc, strlen(doc), NULL, &b, &p) == API_OK, "%s at %s", p.detail, p.pointer);
	CHECK(a->scene.objects[0].positions != b->scene.objects[0].positions, "the model was imported again");
	const struct rnd_object *o = &a->scene.objects[0];
	CHECK(o->lod_count > 0 && o->lods && o->mesh_bounds, "the model has levels and bounds: %u %p %p %u", o->lod_count, (void *)o->lods, (void *)o->mesh_bounds, o->vertex_count);
	CHECK(a->scene_hash == b->scene_hash, "no address may reach the hash: %016llx vs %016llx",
	      (unsigned long long)a->scene_hash, (unsigned long long)b->scene_hash);
	api_scene_free(a);
	api_scene_free(b);
	free(doc);
}
