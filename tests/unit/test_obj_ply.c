/* tests/unit — umbra's own OBJ and PLY readers (api/obj_import.c, api/ply_import.c) make the
 * model the Assimp path makes: each file here is built by the test (a bumpy grid of triangles
 * and quads), imported both ways and compared (tests/util/model_compare.h: vertices in order,
 * indices, normals to 1e-5, uvs, colours, materials with their textures, instances); the test
 * also says which files the own reader must take itself, and which it must leave to Assimp. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "arena.h"
#include "model.h"
#include "model_compare.h"
#include "model_import.h"
#include "model_lod.h"
#include "model_wire.h"
#include "models.h"
#include "obj_import.h"
#include "ply_import.h"
#include "test.h"

#define N 6   /* the grid: N x N cells, (N + 1)^2 vertices */

static float height(int i, int j)
{
	return 0.1f * sinf(3.0f * (float)i / N) * cosf(2.0f * (float)j / N);
}

/* Whether the own reader takes d itself (not NOT_MINE). */
static bool own_takes(enum api_model_format f, const uint8_t *d, size_t len, const struct api_model_file *files,
                      size_t nfiles)
{
	struct api_arena *a = api_arena_create();
	struct api_model m;
	size_t bytes;
	char err[300];
	int st = f == API_MODEL_OBJ ? api_obj_import(d, len, files, nfiles, 256, a, &m, &bytes, err, sizeof err)
	                            : api_ply_import(d, len, a, &m, &bytes, err, sizeof err);
	api_arena_destroy(a);
	return st != API_OBJ_NOT_MINE;
}

/* d imported through the importer's entry (own readers first) and through Assimp alone: the
 * same status, message and model; the own reader took it when `own` says so. */
static void same_both_ways(const char *what, enum api_model_format f, const uint8_t *d, size_t len,
                           const struct api_model_file *files, size_t nfiles, bool own)
{
	CHECK(own_takes(f, d, len, files, nfiles) == own, "%s: the own reader %s it", what, own ? "left" : "took");
	struct api_arena *a[2] = {api_arena_create(), api_arena_create()};
	struct api_model m[2];
	char err[2][400] = {"", ""}, why[300];
	int st[2];
	for (int w = 0; w < 2; w++) {
		size_t bytes = 0;
		st[w] = w == 0 ? api_model_import_files(d, len, files, nfiles, f, 256, a[w], &m[w], &bytes, err[w], 400)
		               : api_model_import_assimp(d, len, files, nfiles, f, 256, a[w], &m[w], &bytes, err[w], 400);
		if (st[w] == API_WIRE_OK) api_model_finish_import(&m[w], 0, a[w], &bytes);
	}
	CHECK(st[0] == st[1] && !strcmp(err[0], err[1]), "%s: %d \"%s\" against Assimp's %d \"%s\"", what, st[0], err[0],
	      st[1], err[1]);
	if (st[0] == API_WIRE_OK && st[1] == API_WIRE_OK)
		CHECK(test_models_equal(&m[0], &m[1], 1e-5f, why, sizeof why), "%s: %s", what, why);
	api_arena_destroy(a[0]);
	api_arena_destroy(a[1]);
}

/* ---- OBJ ---- */

enum { OBJ_NORMALS = 1, OBJ_UVS = 2, OBJ_NEGATIVE = 4, OBJ_QUADS = 8, OBJ_GROUPS = 16, OBJ_MATERIALS = 32 };

/* The grid as an OBJ (malloc'd text): faces by flags; with OBJ_GROUPS an object and groups
 * (one named twice), with OBJ_MATERIALS an mtllib and usemtl changes inside a group. */
static char *grid_obj(int flags, size_t *len)
{
	char *s = NULL;
	FILE *f = open_memstream(&s, len);
	fprintf(f, "# made by tests/unit/test_obj_ply.c\n");
	if (flags & OBJ_MATERIALS) fprintf(f, "mtllib grid.mtl\n");
	for (int j = 0; j <= N; j++)
		for (int i = 0; i <= N; i++) {
			fprintf(f, "v %g %.7f %g\n", (double)i / N, (double)height(i, j), (double)j / N);
			if (flags & OBJ_UVS) fprintf(f, "vt %g %g\n", (double)i / N, (double)j / N);
			if (flags & OBJ_NORMALS) fprintf(f, "vn %g 1 %g\n", 0.1 * i, -0.05 * j);
		}
	int nv = (N + 1) * (N + 1);
	for (int j = 0; j < N; j++) {
		if ((flags & OBJ_GROUPS) && j % 2 == 0) fprintf(f, j == 0 ? "o sheet\n" : "g %s\n", j == 4 ? "rows" : "row s");
		if ((flags & OBJ_MATERIALS) && j % 3 == 1) fprintf(f, "usemtl %s\n", j == 1 ? "red" : "wood");
		for (int i = 0; i < N; i++) {
			int c[4] = {j * (N + 1) + i + 1, (j + 1) * (N + 1) + i + 1, (j + 1) * (N + 1) + i + 2, j * (N + 1) + i + 2};
			int tris[2][3] = {{0, 1, 2}, {0, 2, 3}}, quad[4] = {0, 1, 2, 3};
			for (int t = 0; t < ((flags & OBJ_QUADS) && (i + j) % 2 ? 1 : 2); t++) {
				const int *k = (flags & OBJ_QUADS) && (i + j) % 2 ? quad : tris[t];
				fprintf(f, "f");
				for (int q = 0; q < ((flags & OBJ_QUADS) && (i + j) % 2 ? 4 : 3); q++) {
					int v = flags & OBJ_NEGATIVE ? c[k[q]] - nv - 1 : c[k[q]];
					if (flags & OBJ_NORMALS && flags & OBJ_UVS) fprintf(f, " %d/%d/%d", v, v, v);
					else if (flags & OBJ_NORMALS) fprintf(f, " %d//%d", v, v);
					else if (flags & OBJ_UVS) fprintf(f, " %d/%d", v, v);
					else fprintf(f, " %d", v);
				}
				fprintf(f, "\n");
			}
		}
	}
	fclose(f);
	return s;
}

TEST(obj_own_reader_matches_assimp)
{
	static const int cases[] = {0, OBJ_NORMALS, OBJ_UVS, OBJ_NORMALS | OBJ_UVS, OBJ_NEGATIVE | OBJ_UVS,
	                            OBJ_QUADS, OBJ_QUADS | OBJ_NORMALS | OBJ_UVS, OBJ_GROUPS, OBJ_GROUPS | OBJ_QUADS | OBJ_UVS};
	for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
		size_t len;
		char *s = grid_obj(cases[c], &len), what[32];
		snprintf(what, sizeof what, "obj flags %d", cases[c]);
		same_both_ways(what, API_MODEL_OBJ, (const uint8_t *)s, len, NULL, 0, true);
		free(s);
	}
}

TEST(obj_own_reader_takes_materials_and_textures_as_assimp_does)
{
	/* two materials, one textured with a PNG, a third (unused) one; usemtl inside a group */
	uint8_t px[4 * 4 * 4];
	for (int i = 0; i < 64; i++) px[i] = (uint8_t)(i * 37);
	size_t png_len, len;
	uint8_t *png = test_png_rgba(px, 4, 4, &png_len);
	static const char mtl[] = "newmtl red\nKd 0.8 0.1 0.1\nNs 20\n\nnewmtl unused\nKd 0 1 0\n\n"
	                          "newmtl wood\nKd 1 1 1\nmap_Kd tex/wood.png\nd 0.5\n";
	struct api_model_file files[2] = {{"grid.mtl", (const uint8_t *)mtl, sizeof mtl - 1}, {"tex/wood.png", png, png_len}};
	REQUIRE(png);
	for (int flags = OBJ_MATERIALS; flags <= (OBJ_MATERIALS | OBJ_GROUPS | OBJ_UVS); flags += OBJ_GROUPS | OBJ_UVS) {
		char *s = grid_obj(flags, &len), what[40];
		snprintf(what, sizeof what, "obj with materials, flags %d", flags);
		same_both_ways(what, API_MODEL_OBJ, (const uint8_t *)s, len, files, 2, true);
		/* without the .mtl (a farm sends the model alone): Assimp's named empty materials */
		same_both_ways(what, API_MODEL_OBJ, (const uint8_t *)s, len, NULL, 0, true);
		free(s);
	}
	free(png);
}

TEST(obj_own_reader_refuses_a_broken_texture_as_assimp_does)
{
	/* Assimp refuses the skeleton's material (its texture is no image): the file's answer, with
	 * Assimp's status and message, from that one Assimp run (own_takes: not left to a second
	 * run over the whole file) */
	static const char mtl[] = "newmtl red\nKd 0.8 0.1 0.1\n\nnewmtl wood\nKd 1 1 1\nmap_Kd tex/wood.png\n";
	static const char not_png[] = "this is not a PNG file at all";
	struct api_model_file files[2] = {{"grid.mtl", (const uint8_t *)mtl, sizeof mtl - 1},
	                                  {"tex/wood.png", (const uint8_t *)not_png, sizeof not_png - 1}};
	size_t len;
	char *s = grid_obj(OBJ_MATERIALS | OBJ_UVS, &len);
	same_both_ways("obj with a texture that is no image", API_MODEL_OBJ, (const uint8_t *)s, len, files, 2, true);
	struct api_arena *a = api_arena_create();
	struct api_model m;
	size_t bytes;
	char err[300] = "";
	int st = api_obj_import((const uint8_t *)s, len, files, 2, 256, a, &m, &bytes, err, sizeof err);
	CHECK(st == API_WIRE_BAD_INPUT && strstr(err, "tex/wood.png"), "%d \"%s\"", st, err);
	api_arena_destroy(a);
	free(s);
}

TEST(obj_own_reader_leaves_the_rest_to_assimp)
{
	static const char *const files[] = {
		/* a pentagon (Assimp's triangulation of polygons is its own) */
		"v 0 0 0\nv 1 0 0\nv 1.5 1 0\nv 0.5 1.5 0\nv -0.5 1 0\nf 1 2 3 4 5\n",
		/* lines and points */
		"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2\np 3\n",
		/* vertex colours */
		"v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n",
		/* an index past the vertices */
		"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
		/* a number Assimp reads its own way */
		"v 0 0 0\nv 1,5 0 0\nv 0 1 0\nf 1 2 3\n",
		/* an earlier object named again */
		"o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nv 0 0 1\nf 1 2 4\no a\nf 2 3 4\n",
		/* only degenerate triangles */
		"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
		/* no faces: a point cloud */
		"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 3 3\n",
	};
	for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
		char what[64];
		snprintf(what, sizeof what, "obj case %zu", i);
		same_both_ways(what, API_MODEL_OBJ, (const uint8_t *)files[i], strlen(files[i]), NULL, 0, false);
	}
}

/* ---- PLY ---- */

enum ply_kind { PLY_PLAIN, PLY_VCOL8, PLY_VCOL16, PLY_NUV, PLY_FCOL, PLY_STRIPS, PLY_KINDS };

static void put(FILE *f, int fmt, char type, double x)
{
	if (fmt == 0) {
		fprintf(f, type == 'f' || type == 'd' ? " %.9g" : " %.0f", x);
		return;
	}
	uint8_t b[8];
	int n = type == 'd' ? 8 : type == 'f' || type == 'i' ? 4 : type == 's' ? 2 : 1;
	if (type == 'd') memcpy(b, &x, 8);
	else if (type == 'f') { float v = (float)x; memcpy(b, &v, 4); }
	else if (type == 'i') { int32_t v = (int32_t)x; memcpy(b, &v, 4); }
	else if (type == 's') { uint16_t v = (uint16_t)x; memcpy(b, &v, 2); }
	else b[0] = (uint8_t)x;
	for (int k = 0; k < n; k++) fputc(b[fmt == 2 ? n - 1 - k : k], f);
}

/* The faces of grid_ply's grid: cells by turns a quad, two triangles, a hole. */
static int grid_faces(void)
{
	int n = 0;
	for (int j = 0; j < N; j++)
		for (int i = 0; i < N; i++) n += (i + j) % 4 == 3 ? 0 : (i + j) % 2 ? 1 : 2;
	return n;
}

/* The grid as a PLY of a kind, in fmt 0 ascii, 1 binary little endian, 2 big endian. */
static char *grid_ply(enum ply_kind kind, int fmt, size_t *len)
{
	static const char *const fmts[] = {"ascii", "binary_little_endian", "binary_big_endian"};
	char *s = NULL;
	FILE *f = open_memstream(&s, len);
	int nv = (N + 1) * (N + 1);
	fprintf(f, "ply\nformat %s 1.0\ncomment made by tests/unit/test_obj_ply.c\nelement vertex %d\n", fmts[fmt], nv);
	fprintf(f, "property %s x\nproperty %s y\nproperty %s z\n", kind == PLY_NUV ? "double" : "float",
	        kind == PLY_NUV ? "double" : "float", kind == PLY_NUV ? "double" : "float");
	if (kind == PLY_VCOL8) fprintf(f, "property uchar red\nproperty uchar green\nproperty uchar blue\n");
	if (kind == PLY_VCOL16) fprintf(f, "property ushort r\nproperty ushort g\nproperty ushort b\nproperty ushort alpha\n");
	if (kind == PLY_NUV) fprintf(f, "property float nx\nproperty float ny\nproperty float nz\nproperty float confidence\n"
	                                "property float s\nproperty float t\n");
	if (kind == PLY_STRIPS) fprintf(f, "element tristrips 1\nproperty list int int vertex_indices\n");
	else fprintf(f, "element face %d\nproperty list uchar int vertex_indices\n", grid_faces());
	if (kind == PLY_FCOL) fprintf(f, "property uchar red\nproperty uchar green\nproperty uchar blue\n");
	fprintf(f, "end_header\n");
	for (int j = 0; j <= N; j++)
		for (int i = 0; i <= N; i++) {
			char t = kind == PLY_NUV ? 'd' : 'f';
			put(f, fmt, t, (double)i / N), put(f, fmt, t, height(i, j)), put(f, fmt, t, (double)j / N);
			for (int c = 0; kind == PLY_VCOL8 && c < 3; c++) put(f, fmt, 'c', (i * 40 + j * 17 + c * 90) % 256);
			for (int c = 0; kind == PLY_VCOL16 && c < 4; c++) put(f, fmt, 's', (i * 9000 + j * 3000 + c * 20000) % 65536);
			if (kind == PLY_NUV) {
				put(f, fmt, 'f', 0.1 * i), put(f, fmt, 'f', 1), put(f, fmt, 'f', -0.05 * j), put(f, fmt, 'f', 0.5);
				put(f, fmt, 'f', (double)i / N), put(f, fmt, 'f', (double)j / N);
			}
			if (fmt == 0) fprintf(f, "\n");
		}
	if (kind == PLY_STRIPS) {   /* a strip a row, -1 between */
		put(f, fmt, 'i', N * (2 * (N + 1) + 1));
		for (int j = 0; j < N; j++) {
			for (int i = 0; i <= N; i++) put(f, fmt, 'i', j * (N + 1) + i), put(f, fmt, 'i', (j + 1) * (N + 1) + i);
			put(f, fmt, 'i', -1);
		}
		if (fmt == 0) fprintf(f, "\n");
	}
	for (int j = 0; kind != PLY_STRIPS && j < N; j++)   /* a quad and two triangles, by turns */
		for (int i = 0; i < N; i++) {
			int c[4] = {j * (N + 1) + i, (j + 1) * (N + 1) + i, (j + 1) * (N + 1) + i + 1, j * (N + 1) + i + 1};
			int quad = (i + j) % 2, n = quad ? 1 : 2;
			if ((i + j) % 4 == 3) continue;   /* a hole */
			for (int t = 0; t < n; t++) {
				put(f, fmt, 'c', quad ? 4 : 3);
				for (int k = 0; k < (quad ? 4 : 3); k++) put(f, fmt, 'i', c[quad ? k : k == 0 ? 0 : k + t]);
				for (int k = 0; kind == PLY_FCOL && k < 3; k++) put(f, fmt, 'c', (i * 50 + t * 100 + k * 70) % 256);
				if (fmt == 0) fprintf(f, "\n");
			}
		}
	fclose(f);
	return s;
}

TEST(ply_own_reader_matches_assimp)
{
	for (int kind = 0; kind < PLY_KINDS; kind++)
		for (int fmt = 0; fmt < 3; fmt++) {
			size_t len;
			char *s = grid_ply((enum ply_kind)kind, fmt, &len), what[64];
			snprintf(what, sizeof what, "ply kind %d format %d", kind, fmt);
			same_both_ways(what, API_MODEL_PLY, (const uint8_t *)s, len, NULL, 0, true);
			free(s);
		}
}

TEST(ply_own_reader_leaves_the_rest_to_assimp)
{
	size_t len;
	char *s = grid_ply(PLY_PLAIN, 0, &len);
	/* cut short: Assimp reads what there is */
	same_both_ways("ply cut short", API_MODEL_PLY, (const uint8_t *)s, len - 40, NULL, 0, false);
	free(s);
	static const char *const files[] = {
		/* a pentagon */
		"ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
		"element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1.5 1 0\n0.5 1.5 0\n"
		"-0.5 1 0\n5 0 1 2 3 4\n",
		/* an index past the vertices */
		"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
		"element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
		/* a point cloud */
		"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
		"end_header\n0 0 0\n1 0 0\n0 1 0\n",
		/* a second face property that is not a colour */
		"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
		"element face 1\nproperty list uchar int vertex_indices\nproperty int flags\nend_header\n0 0 0\n1 0 0\n"
		"0 1 0\n3 0 1 2 7\n",
	};
	for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
		char what[64];
		snprintf(what, sizeof what, "ply case %zu", i);
		same_both_ways(what, API_MODEL_PLY, (const uint8_t *)files[i], strlen(files[i]), NULL, 0, false);
	}
}
