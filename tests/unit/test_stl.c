/* tests/unit — STL import (api/model_import.c): facets arrive with flat normals made from their
 * winding, so a corner is one vertex only where facets of one plane meet. Assimp's join is off
 * for STL (it searched a 1M-triangle file for ~1 s and found next to nothing); umbra joins the
 * corners itself, normals compared to within 2^-14: two coplanar facets of a tilted plane get
 * normals that differ in their last bits. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "arena.h"
#include "model.h"
#include "model_import.h"
#include "models.h"
#include "stl_import.h"
#include "test.h"
#include "workers.h"

/* A binary STL of `n` facets (corners tri[t][0..2], normals left zero) into out. */
static size_t stl_of(uint8_t *out, const float (*tri)[3][3], uint32_t n)
{
	memset(out, 0, 84 + 50 * (size_t)n);
	memcpy(out + 80, &n, 4);
	for (uint32_t t = 0; t < n; t++) memcpy(out + 84 + 50 * (size_t)t + 12, tri[t], sizeof tri[t]);
	return 84 + 50 * (size_t)n;
}

static struct api_model *import_stl(const uint8_t *d, size_t len)
{
	struct api_limits l;
	api_limits_defaults(&l);
	struct api_model *m = NULL;
	char err[300];
	int st;
	if (api_model_get(d, len, API_MODEL_STL, &l, &m, &st, err, sizeof err) != API_OK) {
		printf("    import failed: %s\n", err);
		return NULL;
	}
	return m;
}

/* Every facet keeps its own three corners, at their positions. */
static void corners_kept(const struct api_model_mesh *me, const float (*tri)[3][3], uint32_t n)
{
	REQUIRE(me->index_count == 3 * n, "%u indices for %u facets", me->index_count, n);
	for (uint32_t t = 0; t < n; t++)
		for (int k = 0; k < 3; k++) {
			uint32_t v = me->indices[3 * t + (uint32_t)k];
			REQUIRE(v < me->vertex_count);
			const float *q = me->positions + 3 * (size_t)v;
			CHECK(!memcmp(q, tri[t][k], 12), "facet %u corner %d moved to (%g, %g, %g)", t, k, q[0], q[1], q[2]);
		}
}

TEST(stl_joins_the_corners_of_coplanar_facets)
{
	/* a square of two facets on the floor and a third folded up along its edge */
	const float tri[3][3][3] = {
		{{0, 0, 0}, {0, 0, 1}, {1, 0, 0}},
		{{1, 0, 0}, {0, 0, 1}, {1, 0, 1}},
		{{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}},
	};
	uint8_t stl[84 + 3 * 50];
	struct api_model *m = import_stl(stl, stl_of(stl, tri, 3));
	REQUIRE(m && m->mesh_count == 1);
	const struct api_model_mesh *me = &m->meshes[0];
	CHECK(me->vertex_count == 7, "%u vertices: the square's 4, the folded facet's own 3", me->vertex_count);
	corners_kept(me, tri, 3);
	api_model_release(m);
}

TEST(stl_joins_coplanar_facets_of_a_tilted_plane)
{
	/* The quad p0 p1 p2 p3 lies in one plane, but its facets' normalised cross products differ in
	 * the last bit of y (0.26726124 against 0.26726127): compared bit for bit they stayed 6
	 * vertices. */
	const float p[4][3] = {{0, 0, 0}, {0.1f, 2 * 0.1f, 0}, {0.1f, 5 * 0.1f, 0.1f}, {0, 3 * 0.1f, 0.1f}};
	float tri[2][3][3];
	const int f[2][3] = {{0, 3, 1}, {1, 3, 2}};
	for (int t = 0; t < 2; t++)
		for (int k = 0; k < 3; k++) memcpy(tri[t][k], p[f[t][k]], 12);
	uint8_t stl[84 + 2 * 50];
	struct api_model *m = import_stl(stl, stl_of(stl, (const float (*)[3][3])tri, 2));
	REQUIRE(m && m->mesh_count == 1);
	const struct api_model_mesh *me = &m->meshes[0];
	CHECK(me->vertex_count == 4, "%u vertices for a quad of two facets", me->vertex_count);
	corners_kept(me, (const float (*)[3][3])tri, 2);
	api_model_release(m);
}

/* The reader without Assimp (api/stl_import.c) makes the model the Assimp path made: the same
 * vertices (positions bit for bit, normals to float rounding), the same indices, one mesh and
 * instance, the default material. */
TEST(stl_binary_reader_matches_the_assimp_path)
{
	size_t len;
	uint8_t *d = test_bumpy_stl(48, &len);
	REQUIRE(d != NULL);
	struct api_arena *a = api_arena_create(), *b = api_arena_create();
	struct api_model fast, slow;
	size_t fb, sb;
	char err[300];
	REQUIRE(api_model_import_files(d, len, NULL, 0, API_MODEL_STL, 0, a, &fast, &fb, err, sizeof err) == API_WIRE_OK, "%s", err);
	REQUIRE(api_model_import_assimp(d, len, NULL, 0, API_MODEL_STL, 0, b, &slow, &sb, err, sizeof err) == API_WIRE_OK, "%s", err);
	REQUIRE(fast.mesh_count == 1 && slow.mesh_count == 1 && fast.instance_count == 1 && slow.instance_count == 1);
	const struct api_model_mesh *f = &fast.meshes[0], *s = &slow.meshes[0];
	CHECK(fast.triangles == slow.triangles && f->vertex_count == s->vertex_count && f->index_count == s->index_count,
	      "%u/%u vertices, %u/%u indices", f->vertex_count, s->vertex_count, f->index_count, s->index_count);
	CHECK(!f->uvs && !f->colors && !f->tangents && !s->uvs && !s->colors && !s->tangents);
	if (f->vertex_count == s->vertex_count && f->index_count == s->index_count) {
		CHECK(!memcmp(f->positions, s->positions, (size_t)f->vertex_count * 12), "positions");
		CHECK(!memcmp(f->indices, s->indices, (size_t)f->index_count * 4), "indices");
		float worst = 0;
		for (size_t k = 0; k < 3 * (size_t)f->vertex_count; k++) worst = fmaxf(worst, fabsf(f->normals[k] - s->normals[k]));
		CHECK(worst < 1e-6f, "normals differ by %g", worst);
	}
	CHECK(!memcmp(fast.instances[0].model, slow.instances[0].model, 64), "identity instance");
	CHECK(!memcmp(&fast.materials[0], &slow.materials[0], sizeof fast.materials[0]), "default material");
	api_arena_destroy(a);
	api_arena_destroy(b);
	free(d);
}

/* Colours stay Assimp's: a facet with bit 15 of its attribute set (VisCAM / SolidView colour)
 * comes back with vertex colours, through the Assimp path. */
TEST(stl_binary_reader_leaves_colours_to_assimp)
{
	size_t len;
	uint8_t *d = test_bumpy_stl(8, &len);
	REQUIRE(d != NULL);
	uint16_t red = 0x8000 | 31;   /* valid bit, 5 bits of red */
	memcpy(d + 84 + 48, &red, 2);
	struct api_arena *a = api_arena_create();
	struct api_model m;
	size_t bytes;
	char err[300];
	REQUIRE(api_model_import_files(d, len, NULL, 0, API_MODEL_STL, 0, a, &m, &bytes, err, sizeof err) == API_WIRE_OK, "%s", err);
	CHECK(m.mesh_count == 1 && m.meshes[0].colors != NULL, "the coloured facet's colours are kept");
	api_arena_destroy(a);
	free(d);
}

/* The reader's facets are read in slices on the import's threads (api/workers.h): 1 and 3
 * threads give the same bytes, and a corner that is not finite in a late slice, or no facet
 * with an area, still sends the file to Assimp. */
TEST(stl_binary_reader_gives_the_same_bytes_on_threads)
{
	size_t len;
	uint8_t *d = test_bumpy_stl(48, &len);
	REQUIRE(d != NULL);
	struct api_arena *a[2] = {api_arena_create(), api_arena_create()};
	REQUIRE(a[0] && a[1]);
	struct api_model m[2];
	size_t bytes;
	char err[300];
	for (int run = 0; run < 2; run++) {
		api_workers_start(run ? 3 : 1);
		REQUIRE(api_stl_import_binary(d, len, a[run], &m[run], &bytes, err, sizeof err) == API_WIRE_OK, "%s", err);
		api_workers_stop();
	}
	const struct api_model_mesh *f = &m[0].meshes[0], *s = &m[1].meshes[0];
	REQUIRE(f->vertex_count == s->vertex_count && f->index_count == s->index_count && f->index_count > 3000,
	        "%u/%u vertices, %u/%u indices", f->vertex_count, s->vertex_count, f->index_count, s->index_count);
	CHECK(!memcmp(f->positions, s->positions, (size_t)f->vertex_count * 12) &&
	      !memcmp(f->normals, s->normals, (size_t)f->vertex_count * 12) &&
	      !memcmp(f->indices, s->indices, (size_t)f->index_count * 4), "the same vertices and indices");
	uint32_t n;
	memcpy(&n, d + 80, 4);
	uint8_t *bad = malloc(len);
	REQUIRE(bad != NULL);
	memcpy(bad, d, len);
	float inf = INFINITY, zero[9] = {0};
	memcpy(bad + 84 + 50 * (size_t)(n - 2) + 12 + 20, &inf, 4);
	api_workers_start(3);
	CHECK(api_stl_import_binary(bad, len, a[0], &m[0], &bytes, err, sizeof err) == API_STL_NOT_MINE, "infinite corner");
	for (uint32_t t = 0; t < n; t++) memcpy(bad + 84 + 50 * (size_t)t + 12, zero, 36);
	CHECK(api_stl_import_binary(bad, len, a[0], &m[0], &bytes, err, sizeof err) == API_STL_NOT_MINE, "no area");
	api_workers_stop();
	free(bad);
	api_arena_destroy(a[0]);
	api_arena_destroy(a[1]);
	free(d);
}
