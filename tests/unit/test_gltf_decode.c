/* tests — api/gltf_decode.c: .glb files built here the way gltfpack writes them, imported
 * through api_scene_parse: KHR_mesh_quantization (POSITION as shorts under a node scale,
 * NORMAL as normalized bytes) and EXT_meshopt_compression (vertex and index streams encoded
 * with meshoptimizer in the BIN chunk, an empty fallback buffer) give the quad the plain file
 * gives; a corrupt meshopt stream is refused, naming the extension. Before, Assimp 5.2 read
 * the quantized positions as garbage ("triangles have no area") and could not read meshopt
 * views at all. KHR_draco_mesh_compression (api/gltf_draco.c), streams made by libdraco's
 * encoder here (tests/util/draco_encode.h): a 67,600-vertex grid with UNSIGNED_INT indices
 * (Assimp 5.2's own Draco path: "Invalid accessor without data"), a skinned quad with
 * quantized positions (Assimp's: "Invalid draco attribute ... JOINTS_0"), a corrupt stream
 * and a wrong count refused naming the extension. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <meshoptimizer.h>
#include "api.h"
#include "draco_encode.h"
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

/* A grid of GRID x GRID (67,600) vertices over [0, 1]^2 (z 0, normals +z), edgebreaker with positions
 * quantized to 14 bits, as gltf-pipeline and Blender write it: more than 65,536 vertices, so
 * UNSIGNED_INT indices. */
#define GRID 260
TEST(gltf_draco_grid_with_uint32_indices_decoded)
{
	uint32_t nv = GRID * GRID, ntri = 2 * (GRID - 1) * (GRID - 1);
	float *pos = malloc(nv * 12), *nrm = malloc(nv * 12), *uv = malloc(nv * 8);
	uint32_t *idx = malloc(ntri * 12);
	REQUIRE(pos && nrm && uv && idx);
	for (uint32_t y = 0; y < GRID; y++)
		for (uint32_t x = 0; x < GRID; x++) {
			uint32_t v = y * GRID + x;
			pos[3 * v] = (float)x / (GRID - 1), pos[3 * v + 1] = (float)y / (GRID - 1), pos[3 * v + 2] = 0;
			nrm[3 * v] = nrm[3 * v + 1] = 0, nrm[3 * v + 2] = 1;
			uv[2 * v] = pos[3 * v], uv[2 * v + 1] = pos[3 * v + 1];
		}
	uint32_t t = 0;
	for (uint32_t y = 0; y + 1 < GRID; y++)
		for (uint32_t x = 0; x + 1 < GRID; x++) {
			uint32_t a = y * GRID + x, b = a + 1, c = a + GRID, d = c + 1;
			uint32_t q[6] = {a, b, d, a, d, c};
			memcpy(idx + 3 * t, q, sizeof q);
			t += 2;
		}
	struct test_draco_mesh dm = {.pos = pos, .nrm = nrm, .uv = uv, .nv = nv, .idx = idx, .ntri = ntri,
	                             .edgebreaker = 1, .position_bits = 14};
	size_t n;
	uint8_t *g = test_draco_glb(&dm, &n);
	free(pos), free(nrm), free(uv), free(idx);
	REQUIRE(g, "encoding failed");
	struct api_problem p;
	struct api_scene *s = test_parse_model(g, n, "glb", &p);
	free(g);
	REQUIRE(s, "%d %s: %s", p.status, p.pointer, p.detail);
	REQUIRE(s->scene.object_count == 1, "%u objects", s->scene.object_count);
	const struct rnd_object *o = &s->scene.objects[0];
	CHECK(o->index_count == 3 * ntri, "%u indices, want %u", o->index_count, 3 * ntri);
	CHECK(o->vertex_count >= nv, "%u vertices", o->vertex_count);
	float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
	double area = 0;
	for (uint32_t v = 0; v < o->vertex_count; v++)
		for (int k = 0; k < 3; k++) lo[k] = fminf(lo[k], o->positions[3 * v + k]), hi[k] = fmaxf(hi[k], o->positions[3 * v + k]);
	for (uint32_t i = 0; i + 2 < o->index_count; i += 3) {
		const float *a = o->positions + 3 * o->indices[i], *b = o->positions + 3 * o->indices[i + 1],
		            *c = o->positions + 3 * o->indices[i + 2];
		area += 0.5 * fabs((double)(b[0] - a[0]) * (c[1] - a[1]) - (double)(b[1] - a[1]) * (c[0] - a[0]));
	}
	CHECK(fabsf(lo[0]) < 1e-3f && fabsf(lo[1]) < 1e-3f && fabsf(hi[0] - 1) < 1e-3f && fabsf(hi[1] - 1) < 1e-3f &&
	      fabsf(lo[2]) < 1e-3f && fabsf(hi[2]) < 1e-3f, "bounds %.4f..%.4f %.4f..%.4f %.4f..%.4f", lo[0], hi[0], lo[1],
	      hi[1], lo[2], hi[2]);
	/* every index right: the triangles tile the square once (wrong indices overlap or leave holes) */
	CHECK(fabs(area - 1) < 1e-3, "the triangles cover %.5f of the unit square", area);
	api_scene_free(s);
}

/* The quantized quad (QPOS under the node's 0.001 scale, normals +z) with a skin: POSITION as
 * a Draco int16 attribute (KHR_mesh_quantization), JOINTS_0 (uint16) and WEIGHTS_0 compressed
 * too, sequential encoding, UNSIGNED_SHORT indices as the Khronos samples have them. corrupt:
 * the stream's magic overwritten; bad_count: the POSITION accessor's count one too many. */
static uint8_t *draco_skinned_glb(bool corrupt, bool bad_count, size_t *len)
{
	int16_t qp[12];
	float nrm[12], w[16] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
	uint16_t j[16] = {0};
	uint32_t idx[6];
	for (int v = 0; v < 4; v++) {
		memcpy(qp + 3 * v, QPOS + 4 * v, 6);
		nrm[3 * v] = nrm[3 * v + 1] = 0, nrm[3 * v + 2] = 1;
	}
	for (int i = 0; i < 6; i++) idx[i] = QIDX[i];
	struct test_draco_attr at[4] = {{TEST_DRACO_POSITION, TEST_DRACO_INT16, 3, qp, 0},
	                                {TEST_DRACO_NORMAL, TEST_DRACO_FLOAT32, 3, nrm, 0},
	                                {TEST_DRACO_GENERIC, TEST_DRACO_UINT16, 4, j, 0},
	                                {TEST_DRACO_GENERIC, TEST_DRACO_FLOAT32, 4, w, 0}};
	size_t n;
	uint32_t np, nf;
	uint8_t *drc = test_draco_encode(at, 4, 4, idx, 2, 0, 0, &n, &np, &nf);
	if (!drc) return NULL;
	if (corrupt) memset(drc, 'x', 5);
	uint8_t *g = glb(
		"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\",\"KHR_mesh_quantization\"],"
		"\"extensionsRequired\":[\"KHR_draco_mesh_compression\",\"KHR_mesh_quantization\"],\"scene\":0,"
		"\"scenes\":[{\"nodes\":[0,1]}],\"nodes\":[{\"mesh\":0,\"skin\":0,\"scale\":[0.001,0.001,0.001]},{\"name\":\"bone\"}],"
		"\"skins\":[{\"joints\":[1]}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":1,\"NORMAL\":2,"
		"\"JOINTS_0\":3,\"WEIGHTS_0\":4},\"indices\":0,\"extensions\":{\"KHR_draco_mesh_compression\":{\"bufferView\":0,"
		"\"attributes\":{\"POSITION\":%u,\"NORMAL\":%u,\"JOINTS_0\":%u,\"WEIGHTS_0\":%u}}}}]}],\"accessors\":["
		"{\"componentType\":5123,\"count\":%u,\"type\":\"SCALAR\"},{\"componentType\":5122,\"count\":%u,\"type\":\"VEC3\","
		"\"min\":[0,0,0],\"max\":[1000,1000,0]},{\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"},"
		"{\"componentType\":5123,\"count\":%u,\"type\":\"VEC4\"},{\"componentType\":5126,\"count\":%u,\"type\":\"VEC4\"}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu}],\"buffers\":[{\"byteLength\":%zu}]}",
		drc, n, len, at[0].unique_id, at[1].unique_id, at[2].unique_id, at[3].unique_id, 3 * nf, np + bad_count, np, np,
		np, n, (n + 3) & ~(size_t)3);
	free(drc);
	return g;
}

TEST(gltf_draco_skinned_quantized_decoded)
{
	size_t n;
	uint8_t *g = draco_skinned_glb(false, false, &n);
	REQUIRE(g, "encoding failed");
	struct api_problem p;
	struct api_scene *s = test_parse_model(g, n, "glb", &p);
	free(g);
	REQUIRE(s, "%d %s: %s", p.status, p.pointer, p.detail);
	check_quad(s);
	CHECK(!strstr(s->warnings, "Draco"), "warned: %s", s->warnings);
	api_scene_free(s);
}

TEST(gltf_draco_corrupt_or_miscounted_is_refused)
{
	for (int bad = 0; bad < 2; bad++) {
		size_t n;
		uint8_t *g = draco_skinned_glb(bad == 0, bad == 1, &n);
		REQUIRE(g, "encoding failed");
		struct api_problem p;
		struct api_scene *s = test_parse_model(g, n, "glb", &p);
		free(g);
		CHECK(!s, "case %d accepted", bad);
		if (s) api_scene_free(s);
		CHECK(p.status == 400 && strstr(p.detail, "KHR_draco_mesh_compression mesh 0 primitive 0") &&
		      strstr(p.detail, bad ? "count" : "does not decode"), "case %d: %d: %s", bad, p.status, p.detail);
	}
}
