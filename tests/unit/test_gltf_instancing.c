/* tests — EXT_mesh_gpu_instancing (api/gltf_instancing.c): a .glb built here, one quad drawn
 * at three instances (TRANSLATION floats, ROTATION normalized shorts, SCALE floats) under a
 * node's own translation, imported through api_scene_parse: three objects where each instance
 * says, no "not supported" warning; an accessor outside its buffer is refused, naming it.
 * Before, Assimp 5.2 ignored the extension and drew the quad once. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "models.h"
#include "test.h"
#include "util.h"
#include "umbra/rnd_math.h"

/* The quad (x, y in -1..1 at z 0) and, after it, the instances' TRANSLATION (3 x VEC3),
 * ROTATION (3 x VEC4 normalized short, identity) and SCALE (3 x VEC3). translation_count is
 * the TRANSLATION accessor's count (3, or more to point past its view). */
static uint8_t *instanced_glb(int translation_count, size_t *len)
{
	static const float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
	static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
	static const float tr[9] = {0, 0, 0, 10, 0, 0, 0, 10, 0};
	static const int16_t rot[12] = {0, 0, 0, 32767, 0, 0, 0, 32767, 0, 0, 0, 32767};
	static const float sc[9] = {1, 1, 1, 2, 2, 2, 1, 1, 1};
	uint8_t bin[48 + 24 + 36 + 24 + 36];
	memcpy(bin, pos, 48);
	memcpy(bin + 48, idx, 24);
	memcpy(bin + 72, tr, 36);
	memcpy(bin + 108, rot, 24);
	memcpy(bin + 132, sc, 36);
	char json[2048];
	int jn = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"],\"scene\":0,"
		"\"scenes\":[{\"nodes\":[0]}],"
		"\"nodes\":[{\"mesh\":0,\"translation\":[0,0,5],\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":"
		"{\"TRANSLATION\":2,\"ROTATION\":3,\"SCALE\":4}}}}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
		"\"buffers\":[{\"byteLength\":%zu}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,"
		"\"byteLength\":24},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":108,"
		"\"byteLength\":24},{\"buffer\":0,\"byteOffset\":132,\"byteLength\":36}],"
		"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
		"\"min\":[-1,-1,0],\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"},"
		"{\"bufferView\":2,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},"
		"{\"bufferView\":3,\"componentType\":5122,\"normalized\":true,\"count\":3,\"type\":\"VEC4\"},"
		"{\"bufferView\":4,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}",
		sizeof bin, translation_count);
	return test_glb_pack(json, (size_t)jn, bin, sizeof bin, sizeof bin, len);
}


TEST(gltf_instancing_draws_every_instance)
{
	size_t n;
	uint8_t *g = instanced_glb(3, &n);
	REQUIRE(g);
	struct api_problem p;
	struct api_scene *s = test_parse_model(g, n, "glb", &p);
	free(g);
	REQUIRE(s, "%d %s: %s", p.status, p.pointer, p.detail);
	const struct rnd_scene *sc = &s->scene;
	CHECK(sc->object_count == 3, "%u objects, want 3 instances", sc->object_count);
	/* Each instance's quad centre: node translation (0,0,5) + the instance's translation. */
	static const float want[3][2] = {{0, 0}, {10, 0}, {0, 10}};
	bool found[3] = {false, false, false};
	struct rnd_aabb b;
	rnd_aabb_empty(&b);
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		struct rnd_aabb ob;
		rnd_aabb_empty(&ob);
		for (uint32_t v = 0; v < o->vertex_count; v++) {
			float w[3];
			rnd_mat4_mul_point(w, o->model, o->positions + 3 * v);
			rnd_aabb_add_point(&ob, w);
			rnd_aabb_add_point(&b, w);
		}
		float cx = (ob.min[0] + ob.max[0]) / 2, cy = (ob.min[1] + ob.max[1]) / 2, side = ob.max[0] - ob.min[0];
		for (int k = 0; k < 3; k++)
			if (fabsf(cx - want[k][0]) < 1e-3f && fabsf(cy - want[k][1]) < 1e-3f) {
				found[k] = true;
				/* The second instance is scaled 2: its quad is 4 wide. */
				CHECK(fabsf(side - (k == 1 ? 4.0f : 2.0f)) < 1e-3f, "instance %d is %.3f wide", k, side);
			}
		CHECK(fabsf(ob.min[2] - 5) < 1e-3f && fabsf(ob.max[2] - 5) < 1e-3f, "object %u at z %.3f..%.3f, want 5", i,
		      ob.min[2], ob.max[2]);
	}
	CHECK(found[0] && found[1] && found[2], "instances found: %d %d %d", found[0], found[1], found[2]);
	CHECK(!s->warnings[0] || !strstr(s->warnings, "EXT_mesh_gpu_instancing"), "warned: %s", s->warnings);
	api_scene_free(s);
}

TEST(gltf_instancing_accessor_outside_its_buffer_is_refused)
{
	size_t n;
	uint8_t *g = instanced_glb(4, &n);   /* 4 VEC3 in a 36-byte view */
	REQUIRE(g);
	struct api_problem p;
	struct api_scene *s = test_parse_model(g, n, "glb", &p);
	free(g);
	CHECK(!s, "a TRANSLATION accessor past its view was accepted");
	if (s) api_scene_free(s);
	CHECK(p.status >= 400 && p.status < 500 && strstr(p.detail, "EXT_mesh_gpu_instancing") &&
	      strstr(p.detail, "TRANSLATION"), "%d: %s", p.status, p.detail);
}
