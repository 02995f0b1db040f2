/* tests — api/gltf_decode.c: .glb files built here the way gltfpack writes them, imported
 * through api_scene_parse: KHR_mesh_quantization (POSITION as shorts under a node scale,
 * NORMAL as normalized bytes) and EXT_meshopt_compression (vertex and index streams encoded
 * with meshoptimizer in the BIN chunk, an empty fallback buffer) give the quad the plain file
 * gives; a corrupt meshopt stream is refused, naming the extension. Before, Assimp 5.2 read
 * the quantized positions as garbage ("triangles have no area") and could not read meshopt
 * views at all. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <meshoptimizer.h>
#include "api.h"
#include "models.h"
#include "test.h"
#include "util.h"
#include "umbra/rnd_math.h"


/* One object: a quad from (0,0,0) to (1,1,0) in world space, two triangles, normals +z. */
static void check_quad(const struct api_scene *s)
{
	const struct rnd_scene *sc = &s->scene;
	REQUIRE(sc->object_count == 1, "%u objects", sc->object_count);
	const struct rnd_object *o = &sc->objects[0];
	CHECK(o->index_count == 6, "%u indices", o->index_count);
	struct rnd_aabb b;
	rnd_aabb_empty(&b);
	for (uint32_t v = 0; v < o->vertex_count; v++) {
		float w[3];
		rnd_mat4_mul_point(w, o->model, o->positions + 3 * v);
		rnd_aabb_add_point(&b, w);
		if (o->normals)
			CHECK(fabsf(o->normals[3 * v + 2] - 1) < 0.02f, "vertex %u normal z %.3f", v, o->normals[3 * v + 2]);
	}
	CHECK(fabsf(b.min[0]) < 1e-3f && fabsf(b.min[1]) < 1e-3f && fabsf(b.max[0] - 1) < 1e-3f && fabsf(b.max[1] - 1) < 1e-3f &&
	      fabsf(b.min[2]) < 1e-3f && fabsf(b.max[2]) < 1e-3f, "bounds %.3f..%.3f %.3f..%.3f %.3f..%.3f", b.min[0], b.max[0],
	      b.min[1], b.max[1], b.min[2], b.max[2]);
	CHECK(!s->warnings[0] || (!strstr(s->warnings, "quantization") && !strstr(s->warnings, "meshopt")), "warned: %s",
	      s->warnings);
}

/* Positions as 4 shorts (x y z pad, 0..1000) and normals as 4 normalized bytes. */
static const int16_t QPOS[16] = {0, 0, 0, 0, 1000, 0, 0, 0, 1000, 1000, 0, 0, 0, 1000, 0, 0};
static const int8_t QNRM[16] = {0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0};
static const uint16_t QIDX[6] = {0, 1, 2, 0, 2, 3};

static uint8_t *glb(const char *json_fmt, const uint8_t *bin, size_t binlen, size_t *len, ...)
{
	char json[4096];
	va_list ap;
	va_start(ap, len);
	int jn = vsnprintf(json, sizeof json, json_fmt, ap);
	va_end(ap);
	size_t pad = (binlen + 3) & ~(size_t)3;
	uint8_t *b = calloc(1, pad ? pad : 4);
	memcpy(b, bin, binlen);
	uint8_t *g = test_glb_pack(json, (size_t)jn, b, binlen, pad, len);
	free(b);
	return g;
}

#define QUANT_JSON \
	"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_mesh_quantization\"%s],\"extensionsRequired\":" \
	"[\"KHR_mesh_quantization\"%s],\"scene\":0,\"scenes\":[{\"nodes\":[0]}]," \
	"\"nodes\":[{\"mesh\":0,\"scale\":[0.001,0.001,0.001]}]," \
	"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}]," \
	"\"accessors\":[{\"bufferView\":0,\"componentType\":5122,\"count\":4,\"type\":\"VEC3\",\"min\":[0,0,0]," \
	"\"max\":[1000,1000,0]},{\"bufferView\":1,\"componentType\":5120,\"normalized\":true,\"count\":4,\"type\":\"VEC3\"}," \
	"{\"bufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],"

TEST(gltf_quantized_attributes_read_as_floats)
{
	uint8_t bin[32 + 16 + 12];
	memcpy(bin, QPOS, 32);
	memcpy(bin + 32, QNRM, 16);
	memcpy(bin + 48, QIDX, 12);
	size_t n;
	uint8_t *g = glb(QUANT_JSON "\"buffers\":[{\"byteLength\":60}],\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,"
	                 "\"byteLength\":32,\"byteStride\":8},{\"buffer\":0,\"byteOffset\":32,\"byteLength\":16,\"byteStride\":4},"
	                 "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}]}",
	                 bin, sizeof bin, &n, "", "");
	REQUIRE(g);
	struct api_problem p;
	struct api_scene *s = test_parse_model(g, n, "glb", &p);
	free(g);
	REQUIRE(s, "%d %s: %s", p.status, p.pointer, p.detail);
	check_quad(s);
	api_scene_free(s);
}

/* The streams encoded with meshoptimizer, as gltfpack -cc writes them: buffer 0 (the BIN
 * chunk) holds the compressed bytes, buffer 1 is the fallback without data. corrupt: the
 * vertex stream's bytes changed (its header byte). */
static uint8_t *meshopt_glb(bool corrupt, size_t *len)
{
	uint8_t enc[3][512];
	size_t en[3];
	en[0] = meshopt_encodeVertexBuffer(enc[0], sizeof enc[0], QPOS, 4, 8);
	en[1] = meshopt_encodeVertexBuffer(enc[1], sizeof enc[1], QNRM, 4, 4);
	unsigned idx32[6] = {0, 1, 2, 0, 2, 3};
	en[2] = meshopt_encodeIndexBuffer(enc[2], sizeof enc[2], idx32, 6);
	if (corrupt) enc[0][0] ^= 0xff;
	uint8_t bin[1536];
	size_t off[3], at = 0;
	for (int i = 0; i < 3; i++) {
		off[i] = at;
		memcpy(bin + at, enc[i], en[i]);
		at = (at + en[i] + 3) & ~(size_t)3;
	}
	return glb(QUANT_JSON
	           "\"buffers\":[{\"byteLength\":%zu},{\"byteLength\":60,\"extensions\":{\"EXT_meshopt_compression\":"
	           "{\"fallback\":true}}}],\"bufferViews\":["
	           "{\"buffer\":1,\"byteOffset\":0,\"byteLength\":32,\"byteStride\":8,\"extensions\":{\"EXT_meshopt_compression\":"
	           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":8,\"count\":4,\"mode\":\"ATTRIBUTES\"}}},"
	           "{\"buffer\":1,\"byteOffset\":32,\"byteLength\":16,\"byteStride\":4,\"extensions\":{\"EXT_meshopt_compression\":"
	           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":4,\"count\":4,\"mode\":\"ATTRIBUTES\"}}},"
	           "{\"buffer\":1,\"byteOffset\":48,\"byteLength\":12,\"extensions\":{\"EXT_meshopt_compression\":"
	           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":2,\"count\":6,\"mode\":\"TRIANGLES\"}}}]}",
	           bin, at, len, ",\"EXT_meshopt_compression\"", ",\"EXT_meshopt_compression\"", at, off[0], en[0], off[1],
	           en[1], off[2], en[2]);
}

TEST(gltf_meshopt_compressed_views_decoded)
{
	size_t n;
	uint8_t *g = meshopt_glb(false, &n);
	REQUIRE(g);
	struct api_problem p;
	struct api_scene *s = test_parse_model(g, n, "glb", &p);
	free(g);
	REQUIRE(s, "%d %s: %s", p.status, p.pointer, p.detail);
	check_quad(s);
	api_scene_free(s);
}

TEST(gltf_meshopt_corrupt_stream_is_refused)
{
	size_t n;
	uint8_t *g = meshopt_glb(true, &n);
	REQUIRE(g);
	struct api_problem p;
	struct api_scene *s = test_parse_model(g, n, "glb", &p);
	free(g);
	CHECK(!s, "a corrupt meshopt stream was accepted");
	if (s) api_scene_free(s);
	CHECK(p.status >= 400 && p.status < 500 && strstr(p.detail, "EXT_meshopt_compression"), "%d: %s", p.status, p.detail);
}

TEST(gltf_draco_required_is_refused_with_what_to_do)
{
	uint8_t bin[60] = {0};
	size_t n;
	uint8_t *g = glb(QUANT_JSON "\"buffers\":[{\"byteLength\":60}],\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,"
	                 "\"byteLength\":32,\"byteStride\":8},{\"buffer\":0,\"byteOffset\":32,\"byteLength\":16,\"byteStride\":4},"
	                 "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}]}",
	                 bin, sizeof bin, &n, ",\"KHR_draco_mesh_compression\"", ",\"KHR_draco_mesh_compression\"");
	REQUIRE(g);
	struct api_problem p;
	struct api_scene *s = test_parse_model(g, n, "glb", &p);
	free(g);
	CHECK(!s, "a file requiring Draco was accepted");
	if (s) api_scene_free(s);
	CHECK(p.status >= 400 && p.status < 500 && strstr(p.detail, "Draco") && strstr(p.detail, "gltfpack"), "%d: %s",
	      p.status, p.detail);
}
