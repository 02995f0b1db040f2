/* tests/unit — PLY triangle strips (api/ply_strips.c): a `tristrips` element becomes triangles
 * with the strip's alternating winding, -1 restarts, degenerate triangles dropped; the model
 * imports with every triangle (Assimp 5.2 alone read a strip as one flat sliver). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "model.h"
#include "ply_strips.h"
#include "test.h"

/* A binary little-endian PLY: 7 vertices, one strip 0 1 2 3 -1 4 5 6 6 (a quad, a restart, a
 * triangle and a repeated index). */
static uint8_t *strip_ply_binary(size_t *len)
{
	static const char hdr[] = "ply\nformat binary_little_endian 1.0\ncomment strips\nelement vertex 7\n"
	                          "property float x\nproperty float y\nproperty float z\nelement tristrips 1\n"
	                          "property list int int vertex_indices\nend_header\n";
	static const float v[21] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 3, 0, 0, 4, 0, 0, 3, 1, 0};
	static const int32_t s[10] = {9, 0, 1, 2, 3, -1, 4, 5, 6, 6};
	*len = sizeof hdr - 1 + sizeof v + sizeof s;
	uint8_t *d = malloc(*len);
	memcpy(d, hdr, sizeof hdr - 1);
	memcpy(d + sizeof hdr - 1, v, sizeof v);
	memcpy(d + sizeof hdr - 1 + sizeof v, s, sizeof s);
	return d;
}

TEST(ply_strips_become_triangles)
{
	size_t len, n = 0;
	uint8_t *d = strip_ply_binary(&len);
	uint8_t *out = api_ply_strips_to_faces(d, len, &n);
	REQUIRE(out && n > 0);
	static const char face_hdr[] = "element face 3\nproperty list uchar int vertex_indices\n";
	CHECK(memmem(out, n, face_hdr, sizeof face_hdr - 1) != NULL, "header");
	CHECK(!memmem(out, n, "tristrips", 9), "the strips element is gone");
	/* faces after the 84 vertex bytes: (0 1 2), (2 1 3) flipped on the odd step, (4 5 6) */
	const uint8_t *f = memmem(out, n, "end_header\n", 11) + 11 + 84;
	static const int32_t want[9] = {0, 1, 2, 2, 1, 3, 4, 5, 6};
	int ok = 1;
	for (int t = 0; t < 3; t++) {
		int32_t tri[3];
		ok &= f[13 * t] == 3;
		memcpy(tri, f + 13 * t + 1, 12);
		ok &= !memcmp(tri, want + 3 * t, 12);
	}
	CHECK(ok && (size_t)(f + 39 - out) == n, "face records");
	free(out);
	/* A file with faces, or none of the element, is left alone. */
	static const char faces[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
	                            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
	                            "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
	CHECK(!api_ply_strips_to_faces((const uint8_t *)faces, sizeof faces - 1, &n));
	/* Cut short or an index past the vertices: left to the importer (which refuses it). */
	CHECK(!api_ply_strips_to_faces(d, len - 3, &n));
	int32_t bad = 7;
	memcpy(d + len - 4, &bad, 4);
	CHECK(!api_ply_strips_to_faces(d, len, &n));
	free(d);
}

TEST(ply_strips_ascii_import_every_triangle)
{
	static const char ply[] = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
	                          "property float z\nelement tristrips 1\nproperty list int int vertex_indices\n"
	                          "end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n4 0 1 2 3\n";
	struct api_limits l;
	api_limits_defaults(&l);
	struct api_model *m = NULL;
	char err[300];
	int st;
	REQUIRE(api_model_get((const uint8_t *)ply, sizeof ply - 1, API_MODEL_PLY, &l, &m, &st, err, sizeof err) == API_OK &&
	        m, "%s", err);
	CHECK(m->triangles == 2, "%llu triangles (a quad strip has 2)", (unsigned long long)m->triangles);
	/* Both triangles face the same way (+z here): the odd one's winding was flipped back. */
	int up = 0;
	for (uint32_t v = 0; v < m->meshes[0].vertex_count; v++) up += m->meshes[0].normals[3 * v + 2] > 0.99f;
	CHECK(up == (int)m->meshes[0].vertex_count, "%d of %u normals +z", up, m->meshes[0].vertex_count);
	api_model_release(m);
}

/* Big endian too: the faces written in the file's byte order (Assimp 5.2's own strip reader
 * drew one sliver and leaked each triangle's indices). */
TEST(ply_strips_big_endian_import_every_triangle)
{
	static const char hdr[] = "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\n"
	                          "property float y\nproperty float z\nelement tristrips 1\n"
	                          "property list int int vertex_indices\nend_header\n";
	static const float v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
	static const int32_t strip[5] = {4, 0, 1, 2, 3};
	uint8_t d[sizeof hdr - 1 + sizeof v + sizeof strip];
	size_t at = sizeof hdr - 1;
	memcpy(d, hdr, at);
	for (int k = 0; k < 12; k++, at += 4) {
		uint32_t b;
		memcpy(&b, &v[k], 4);
		b = __builtin_bswap32(b);
		memcpy(d + at, &b, 4);
	}
	for (int k = 0; k < 5; k++, at += 4) {
		uint32_t b = __builtin_bswap32((uint32_t)strip[k]);
		memcpy(d + at, &b, 4);
	}
	size_t n = 0;
	uint8_t *out = api_ply_strips_to_faces(d, sizeof d, &n);
	REQUIRE(out, "rewritten");
	/* the second face record (2 1 3, flipped on the odd step), big endian after its count byte */
	const uint8_t *f = memmem(out, n, "end_header\n", 11) + 11 + sizeof v + 13;
	static const uint8_t want[13] = {3, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 3};
	CHECK(!memcmp(f, want, 13) && (size_t)(f + 13 - out) == n, "face records in big endian");
	free(out);
	struct api_limits l;
	api_limits_defaults(&l);
	struct api_model *m = NULL;
	char err[300];
	int st;
	REQUIRE(api_model_get(d, sizeof d, API_MODEL_PLY, &l, &m, &st, err, sizeof err) == API_OK && m, "%s", err);
	CHECK(m->triangles == 2, "%llu triangles (a quad strip has 2)", (unsigned long long)m->triangles);
	int up = 0;
	for (uint32_t i = 0; i < m->meshes[0].vertex_count; i++) up += m->meshes[0].normals[3 * i + 2] > 0.99f;
	CHECK(up == (int)m->meshes[0].vertex_count, "%d of %u normals +z", up, m->meshes[0].vertex_count);
	api_model_release(m);
}

/* A model whose every triangle is degenerate imports "fine" in Assimp and draws nothing: a 400
 * with the reason, never a silently empty image. */
TEST(model_of_degenerate_triangles_is_refused)
{
	static const char obj[] = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n";
	struct api_limits l;
	api_limits_defaults(&l);
	struct api_model *m = NULL;
	char err[300] = "";
	int st = 0;
	enum api_result r = api_model_get((const uint8_t *)obj, sizeof obj - 1, API_MODEL_OBJ, &l, &m, &st, err, sizeof err);
	CHECK(r == API_ERR && st == 400 && strstr(err, "no area"), "%d %d: %s", (int)r, st, err);
	api_model_release(m);
}
