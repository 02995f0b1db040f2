/* tests/unit — what real model files do that the importer must take as they mean it: a model
 * object's `up` (a Z-up file stood upright, the exact rotation of each axis, under the object's
 * transform; a bad value is a 400 at /objects/N/up), PNG gAMA chunks ignored (glTF: texels as
 * stored), PLY face colours carried as vertex colours (ASCII and binary), a point-cloud PLY
 * refused saying so, the format told by the bytes when they say it (a mismatch warned), and
 * the messages of an empty or oversized file by path. Every model is built here. */
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>
#include "api.h"
#include "asset.h"
#include "arena.h"
#include "model.h"
#include "model_import.h"
#include "models.h"
#include "ply_colors.h"
#include "test.h"
#include "util.h"
#include "umbra/rnd_math.h"

/* An .obj box spanning [0,1] x [0,2] x [0,3]: every axis tells its sign apart. */
static const char BOX_OBJ[] =
	"v 0 0 0\nv 1 0 0\nv 1 2 0\nv 0 2 0\nv 0 0 3\nv 1 0 3\nv 1 2 3\nv 0 2 3\n"
	"f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 7 3\nf 4 8 7\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";

/* A scene of one inline model (format given), `extra` inside its object ('' quotes as "). */
static struct api_scene *parse_inline(const void *d, size_t n, const char *format, const char *extra,
                                      struct api_problem *p)
{
	char *enc = test_b64(d, n);
	size_t cap = strlen(enc) + strlen(extra) + 256;
	char *doc = malloc(cap);
	snprintf(doc, cap, "{\"camera\":{\"position\":[0,0,9]},\"objects\":[{\"shape\":\"model\",\"format\":\"%s\","
	         "\"data\":\"%s\"%s}]}", format, enc, extra);
	for (char *q = doc; *q; q++) if (*q == '\'') *q = '"';
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	if (api_scene_parse(doc, strlen(doc), NULL, &s, p) != API_OK) s = NULL;
	free(doc);
	free(enc);
	return s;
}

static struct rnd_aabb world_bounds(const struct rnd_scene *sc)
{
	struct rnd_aabb b;
	rnd_aabb_empty(&b);
	for (uint32_t i = 0; i < sc->object_count; i++)
		for (uint32_t v = 0; v < sc->objects[i].vertex_count; v++) {
			float w[3];
			rnd_mat4_mul_point(w, sc->objects[i].model, sc->objects[i].positions + 3 * v);
			rnd_aabb_add_point(&b, w);
		}
	return b;
}

static bool bounds_are(const struct rnd_aabb *b, const float want[6])
{
	for (int k = 0; k < 3; k++)
		if (fabsf(b->min[k] - want[k]) > 1e-4f || fabsf(b->max[k] - want[3 + k]) > 1e-4f) return false;
	return true;
}

/* ---- up ---- */

TEST(model_up_rotates_each_axis_to_plus_y)
{
	static const struct { const char *up; float b[6]; } cases[] = {
		{"+y", {0, 0, 0, 1, 2, 3}},
		{"+z", {0, 0, -2, 1, 3, 0}},    /* (x, y, z) -> (x, z, -y) */
		{"-z", {0, -3, 0, 1, 0, 2}},    /* (x, -z, y) */
		{"-y", {0, -2, -3, 1, 0, 0}},   /* (x, -y, -z) */
		{"+x", {-2, 0, 0, 0, 1, 3}},    /* (-y, x, z) */
		{"-x", {0, -1, 0, 2, 0, 3}},    /* (y, -x, z) */
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		char extra[64];
		snprintf(extra, sizeof extra, ",'up':'%s'", cases[i].up);
		struct api_problem p;
		struct api_scene *s = parse_inline(BOX_OBJ, strlen(BOX_OBJ), "obj", extra, &p);
		REQUIRE(s, "%s: %d %s %s", cases[i].up, p.status, p.pointer, p.detail);
		struct rnd_aabb b = world_bounds(&s->scene);
		CHECK(bounds_are(&b, cases[i].b), "%s: [%g %g %g] .. [%g %g %g]", cases[i].up, b.min[0], b.min[1], b.min[2],
		      b.max[0], b.max[1], b.max[2]);
		api_scene_free(s);
	}
}

TEST(model_up_comes_before_the_transform)
{
	/* up first (y spans the file's z: 0..3), then the object's scale and translation */
	struct api_problem p;
	struct api_scene *s = parse_inline(BOX_OBJ, strlen(BOX_OBJ), "obj",
	                                   ",'up':'+z','transform':{'translation':[5,0,0],'scale':[1,2,1]}", &p);
	REQUIRE(s, "%d %s", p.status, p.detail);
	struct rnd_aabb b = world_bounds(&s->scene);
	static const float want[6] = {5, 0, -2, 6, 6, 0};
	CHECK(bounds_are(&b, want), "[%g %g %g] .. [%g %g %g]", b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]);
	api_scene_free(s);
}

TEST(model_up_bad_value_is_400_at_its_pointer)
{
	static const char *const bad[] = {",'up':'z'", ",'up':'up'", ",'up':[0,0,1]", ",'up':true"};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		struct api_problem p;
		struct api_scene *s = parse_inline(BOX_OBJ, strlen(BOX_OBJ), "obj", bad[i], &p);
		CHECK(!s && p.status == 400 && !strcmp(p.pointer, "/objects/0/up") && strstr(p.detail, "+z"),
		      "%s: %d %s %s", bad[i], p.status, p.pointer, p.detail);
		api_scene_free(s);
	}
	/* `up` belongs to models only */
	const char *doc = "{\"camera\":{\"position\":[0,0,9]},\"objects\":[{\"shape\":\"box\",\"up\":\"+z\"}]}";
	struct api_scene *s = NULL;
	struct api_problem p;
	CHECK(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_ERR && p.status == 400 &&
	      !strcmp(p.pointer, "/objects/0/up"), "%d %s %s", p.status, p.pointer, p.detail);
}

/* ---- PNG gAMA ---- */

TEST(png_gamma_chunk_is_ignored)
{
	/* 1/2.2 is what most tools write; 1.0 and 0.2 made the old decoder convert (0,136,0) */
	static const double gammas[] = {1 / 2.2, 1.0, 0.2};
	const uint8_t rgb[6] = {0, 136, 0, 200, 61, 7};
	for (size_t i = 0; i < 3; i++) {
		size_t n;
		uint8_t *png = test_png_rgb_gamma(rgb, 2, 1, gammas[i], &n);
		REQUIRE(png);
		REQUIRE(memmem(png, n, "gAMA", 4), "the file has a gAMA chunk");
		uint8_t *px = NULL;
		uint32_t w, h;
		char err[128];
		CHECK(api_image_decode(png, n, 0, &px, &w, &h, err, sizeof err) == API_OK && w == 2 && h == 1, "%s", err);
		CHECK(px && px[0] == 0 && px[1] == 136 && px[2] == 0 && px[3] == 255 && px[4] == 200 && px[5] == 61 &&
		      px[6] == 7 && px[7] == 255, "gamma %g: (%u,%u,%u,%u) (%u,%u,%u)", gammas[i], px ? px[0] : 0,
		      px ? px[1] : 0, px ? px[2] : 0, px ? px[3] : 0, px ? px[4] : 0, px ? px[5] : 0, px ? px[6] : 0);
		free(px);
		free(png);
	}
}

/* ---- PLY face colours, point clouds ---- */

/* Two triangles sharing an edge, the first red, the second green (face properties). */
static const char PLY_FACES_ASCII[] =
	"ply\nformat ascii 1.0\ncomment two faces, two colours\nelement vertex 4\nproperty float x\nproperty float y\n"
	"property float z\nelement face 2\nproperty list uchar int vertex_indices\nproperty uchar red\n"
	"property uchar green\nproperty uchar blue\nend_header\n"
	"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 255 0 0\n3 0 2 3 0 255 0\n";

static uint8_t *ply_faces_binary(size_t *len)
{
	static const char hdr[] = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
	                          "property float y\nproperty float z\nelement face 2\nproperty uchar red\n"
	                          "property uchar green\nproperty uchar blue\nproperty list uchar int vertex_indices\n"
	                          "end_header\n";
	static const float v[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
	size_t h = sizeof hdr - 1;
	*len = h + sizeof v + 2 * (3 + 1 + 12);
	uint8_t *d = malloc(*len);
	memcpy(d, hdr, h);
	memcpy(d + h, v, sizeof v);
	uint8_t *f = d + h + sizeof v;
	static const uint8_t col[2][3] = {{255, 0, 0}, {0, 255, 0}};
	static const int32_t idx[2][3] = {{0, 1, 2}, {0, 2, 3}};
	for (int i = 0; i < 2; i++, f += 16) {
		memcpy(f, col[i], 3);
		f[3] = 3;
		memcpy(f + 4, idx[i], 12);
	}
	return d;
}

/* Every triangle of the scene has one colour on all three corners; *red and *green count them. */
static bool faces_one_colour(const struct rnd_scene *sc, int *red, int *green)
{
	*red = *green = 0;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		if (!o->colors) return false;
		for (uint32_t t = 0; t < o->index_count; t += 3) {
			const uint8_t *c[3];
			for (int k = 0; k < 3; k++) c[k] = o->colors + 4 * o->indices[t + k];
			if (memcmp(c[0], c[1], 3) || memcmp(c[0], c[2], 3)) return false;
			*red += c[0][0] == 255 && c[0][1] == 0 && c[0][2] == 0;
			*green += c[0][0] == 0 && c[0][1] == 255 && c[0][2] == 0;
		}
	}
	return true;
}

TEST(ply_face_colours_become_vertex_colours)
{
	size_t blen;
	uint8_t *bin = ply_faces_binary(&blen);
	const struct { const char *name; const uint8_t *d; size_t n; } files[] = {
		{"ascii", (const uint8_t *)PLY_FACES_ASCII, sizeof PLY_FACES_ASCII - 1}, {"binary", bin, blen},
	};
	for (int i = 0; i < 2; i++) {
		size_t n = 0;
		uint8_t *out = api_ply_face_colors_to_vertices(files[i].d, files[i].n, &n);
		CHECK(out && memmem(out, n, "element vertex 6\n", 17) && memmem(out, n, "property uchar red", 18),
		      "%s: one vertex per corner", files[i].name);
		free(out);
		struct api_problem p;
		struct api_scene *s = parse_inline(files[i].d, files[i].n, "ply", "", &p);
		REQUIRE(s, "%s: %d %s", files[i].name, p.status, p.detail);
		int red, green;
		CHECK(faces_one_colour(&s->scene, &red, &green) && red == 1 && green == 1, "%s: %d red, %d green faces",
		      files[i].name, red, green);
		api_scene_free(s);
	}
	free(bin);
	/* Vertex colours of their own, or no face colour: left to Assimp as they are. */
	size_t n;
	static const char plain[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
	                            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
	                            "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
	CHECK(!api_ply_face_colors_to_vertices((const uint8_t *)plain, sizeof plain - 1, &n));
	/* cut short, an index past the vertices */
	CHECK(!api_ply_face_colors_to_vertices((const uint8_t *)PLY_FACES_ASCII, sizeof PLY_FACES_ASCII - 8, &n));
	char bad[sizeof PLY_FACES_ASCII];
	memcpy(bad, PLY_FACES_ASCII, sizeof bad);
	char *q = strstr(bad, "3 0 2 3 ");
	q[6] = '9';
	CHECK(!api_ply_face_colors_to_vertices((const uint8_t *)bad, sizeof bad - 1, &n));
}

TEST(ply_point_cloud_says_what_it_is)
{
	static const char cloud[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
	                            "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
	CHECK(api_ply_point_cloud((const uint8_t *)cloud, sizeof cloud - 1) == 3);
	CHECK(api_ply_point_cloud((const uint8_t *)PLY_FACES_ASCII, sizeof PLY_FACES_ASCII - 1) == 0);
	struct api_problem p;
	struct api_scene *s = parse_inline(cloud, sizeof cloud - 1, "ply", ",'name':'scan'", &p);
	CHECK(!s && p.status == 400 && strstr(p.detail, "\"scan\"") && strstr(p.detail, "no faces") &&
	      strstr(p.detail, "point clouds are not drawn"), "%d %s", p.status, p.detail);
	api_scene_free(s);
}

/* ---- the format from the bytes ---- */

TEST(model_format_from_the_bytes_wins_and_is_warned)
{
	uint8_t stl[284];
	const float tet[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	size_t n = test_tetra_stl(stl, tet);
	char w[300];
	CHECK(api_model_settle_format(stl, n, API_MODEL_OBJ, w, sizeof w) == API_MODEL_STL &&
	      strstr(w, "stl file by its bytes, not obj"), "%s", w);
	CHECK(api_model_settle_format(stl, n, API_MODEL_STL, w, sizeof w) == API_MODEL_STL && !w[0]);
	CHECK(api_model_settle_format((const uint8_t *)BOX_OBJ, strlen(BOX_OBJ), API_MODEL_STL, w, sizeof w) ==
	      API_MODEL_STL && !w[0], "an OBJ (a heuristic) never overrides");
	CHECK(api_model_settle_format((const uint8_t *)PLY_FACES_ASCII, 10, API_MODEL_GLB, w, sizeof w) == API_MODEL_PLY);
	/* a binary STL sent as "glb" renders, with the warning naming both */
	struct api_problem p;
	struct api_scene *s = parse_inline(stl, n, "glb", "", &p);
	REQUIRE(s, "%d %s", p.status, p.detail);
	CHECK(s->triangles == 4 && strstr(s->warnings, "/objects/0/data: the file is a stl file by its bytes, not glb"),
	      "%s", s->warnings);
	api_scene_free(s);
}

/* ---- messages of files by path ---- */

TEST(model_path_empty_or_too_large_says_which)
{
	char root[] = "/tmp/umbra-quirks-XXXXXX";
	REQUIRE(mkdtemp(root));
	test_put_file(root, "empty.stl", "");
	char big[400];
	snprintf(big, sizeof big, "%s/big.stl", root);
	int fd = open(big, O_CREAT | O_WRONLY, 0600);
	REQUIRE(fd >= 0);
	CHECK(ftruncate(fd, (off_t)API_ASSET_MAX_FILE + 1) == 0);   /* sparse: costs no disk */
	close(fd);
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = root;
	static const struct { const char *path, *want; } cases[] = {
		{"empty.stl", "is an empty file (0 bytes)"}, {"big.stl", "larger than the limit of 1073741824 bytes"},
	};
	for (int i = 0; i < 2; i++) {
		char doc[256];
		snprintf(doc, sizeof doc, "{\"camera\":{\"position\":[0,0,9]},\"objects\":[{\"shape\":\"model\",\"path\":\"%s\"}]}",
		         cases[i].path);
		struct api_scene *s = NULL;
		struct api_problem p;
		CHECK(api_scene_parse(doc, strlen(doc), &lim, &s, &p) == API_ERR && p.status == 400 &&
		      !strcmp(p.pointer, "/objects/0/path") && strstr(p.detail, cases[i].want), "%s: %d %s", cases[i].path,
		      p.status, p.detail);
	}
	unlink(big);
	snprintf(big, sizeof big, "%s/empty.stl", root);
	unlink(big);
	rmdir(root);
}

/* Points and lines are drawn as thin geometry (api/model_strokes.c), no longer dropped: an
 * .obj of one triangle, one line (`l`) and one point (`p`) imports as the triangle, a prism
 * of 6 triangles along the line and an octahedron of 8 at the point, of radius 1/500 and
 * 2.5/500 of the box's diagonal (here 5: 0.01 and 0.025). Before: the triangle alone. */
TEST(model_points_and_lines_drawn_as_thin_geometry)
{
	static const char obj[] = "v 0 0 0\nv 4 0 0\nv 0 3 0\nv 4 3 0\nf 1 2 3\nl 2 4\np 4\n";
	struct api_problem p;
	struct api_scene *s = parse_inline(obj, strlen(obj), "obj", "", &p);
	REQUIRE(s, "parse failed: %d %s", p.status, p.detail);
	uint32_t tris = 0;
	for (uint32_t i = 0; i < s->scene.object_count; i++) tris += s->scene.objects[i].index_count / 3;
	struct rnd_aabb b = world_bounds(&s->scene);
	printf("    %u objects, %u triangles; x %.3f..%.3f, y %.3f..%.3f\n", s->scene.object_count, tris, b.min[0], b.max[0],
	       b.min[1], b.max[1]);
	CHECK(tris == 1 + 6 + 8, "triangles %u, want 15 (the triangle, a prism, an octahedron)", tris);
	/* the octahedron at (4, 3, 0) reaches 0.025 past it; the prism along x = 4 reaches 0.01 */
	CHECK(fabsf(b.max[0] - 4.025f) < 1e-3f && fabsf(b.max[1] - 3.025f) < 1e-3f, "box max %.4f %.4f", b.max[0], b.max[1]);
	api_scene_free(s);
}

/* A glb of one quad as two triangles with six vertices, the shared corners written twice with
 * the same attributes; indexed (0..5) or not. Its vertex count once imported. */
static uint32_t quad_six_vertices(bool indexed)
{
	static const float pos[18] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0};
	static const float nrm[18] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
	static const uint32_t idx[6] = {0, 1, 2, 3, 4, 5};
	uint8_t bin[168];
	memcpy(bin, pos, 72);
	memcpy(bin + 72, nrm, 72);
	memcpy(bin + 144, idx, 24);
	char json[1024];
	int jn = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1}%s}]}],"
		"\"buffers\":[{\"byteLength\":168}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":72},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":72},"
		"{\"buffer\":0,\"byteOffset\":144,\"byteLength\":24}],"
		"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\",\"min\":[-1,-1,0],"
		"\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"},"
		"{\"bufferView\":2,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"}]}",
		indexed ? ",\"indices\":2" : "");
	size_t len;
	uint8_t *glb = test_glb_pack(json, (size_t)jn, bin, sizeof bin, sizeof bin, &len);
	struct api_arena *a = api_arena_create();
	struct api_model m;
	size_t bytes;
	char err[256] = "";
	uint32_t nv = 0;
	if (glb && a && api_model_import_local(glb, len, API_MODEL_GLB, a, &m, &bytes, err, sizeof err) == API_WIRE_OK &&
	    m.mesh_count == 1 && m.meshes[0].index_count == 6)
		nv = m.meshes[0].vertex_count;
	else
		printf("    import: %s\n", err);
	api_arena_destroy(a);
	free(glb);
	return nv;
}

/* Assimp's join of identical vertices runs only for a glTF with a primitive without indices
 * (each corner its own vertex): an indexed one's vertices are the exporter's, kept as they
 * are (the join's spatial sort was most of a glb's import). */
TEST(gltf_vertices_joined_only_where_a_primitive_has_no_indices)
{
	uint32_t plain = quad_six_vertices(false), indexed = quad_six_vertices(true);
	CHECK(plain == 4, "no indices: the six corners joined into 4 vertices, got %u", plain);
	CHECK(indexed == 6, "indexed: its 6 vertices kept as written, got %u", indexed);
}
