/* tests — what a level (api/model_lod.c) keeps of its mesh besides the surface: a texture seam
 * stays a seam (each side its own uvs), and the level's faces and normals face the way the mesh
 * is wound, whatever a few of the file's normals say. */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"
#include "arena.h"
#include "model.h"
#include "model_lod.h"

#define PI_D 3.14159265358979323846

/* The indices of an s x s grid of quads over (s + 1)^2 vertices in rows, two triangles each,
 * counter-clockwise seen from +Y for a grid laid out along +x (columns) and +z (rows). */
static void grid_indices(uint32_t s, uint32_t *idx)
{
	uint32_t k = 0;
	for (uint32_t i = 0; i < s; i++)
		for (uint32_t j = 0; j < s; j++) {
			uint32_t a = i * (s + 1) + j, b = a + 1, c = a + s + 1, d = c + 1;
			uint32_t t[6] = {a, c, b, b, c, d};
			memcpy(idx + k, t, sizeof t);
			k += 6;
		}
}

/* me's level for 256² images (into me->lods), in the arena returned. */
static struct api_arena *level_at_256(struct api_model_mesh *me)
{
	struct api_model m = {0};
	m.meshes = me;
	m.mesh_count = 1;
	struct api_arena *a = api_arena_create();
	size_t bytes = 0;
	api_model_build_level(&m, 256, a, &bytes);
	return a;
}

/* A texture seam (a sphere's u = 0 and u = 1 meeting, its positions repeated) stays a seam in
 * the level: every level triangle's corners keep their own side's uvs, so none spans the
 * texture's width. Before, the level of the mesh welded by position took one side's uvs for
 * both: the triangles along the seam spanned u 0..0.97, the whole texture squeezed into a
 * strip (a visible line down a textured blob's thumbnail). */
TEST(model_lod_level_keeps_a_texture_seam)
{
	enum { S = 200 };   /* 80,000 triangles */
	uint32_t nv = (S + 1) * (S + 1), ni = 6 * S * S;
	float *pos = malloc(nv * 12ull), *nrm = malloc(nv * 12ull), *uv = malloc(nv * 8ull);
	uint32_t *idx = malloc(ni * 4ull);
	REQUIRE(pos && nrm && uv && idx);
	for (uint32_t i = 0; i <= S; i++)
		for (uint32_t j = 0; j <= S; j++) {
			uint32_t v = i * (S + 1) + j;
			double th = PI_D * i / S, ph = 2 * PI_D * (j % S) / S;   /* column S repeats column 0 */
			float *p = pos + 3 * v;
			p[0] = (float)(sin(th) * cos(ph)), p[1] = (float)cos(th), p[2] = (float)(-sin(th) * sin(ph));
			if (i == 0 || i == S) p[0] = p[2] = 0.0f;
			memcpy(nrm + 3 * v, p, 12);
			uv[2 * v] = (float)j / S, uv[2 * v + 1] = (float)i / S;
		}
	grid_indices(S, idx);
	struct api_model_mesh me = {.positions = pos, .normals = nrm, .uvs = uv, .indices = idx, .vertex_count = nv,
	                            .index_count = ni};
	struct api_arena *a = level_at_256(&me);
	REQUIRE(me.lod_count == 1 && me.lods[0].uvs, "levels: %u", me.lod_count);
	const struct rnd_mesh_lod *lv = &me.lods[0];
	float widest = 0.0f;
	for (uint32_t t = 0; t < lv->index_count; t += 3) {
		float lo = 1.0f, hi = 0.0f;
		bool pole = false;
		for (int c = 0; c < 3; c++) {
			uint32_t v = lv->indices[t + (uint32_t)c];
			float u = lv->uvs[2 * (size_t)v];
			lo = u < lo ? u : lo, hi = u > hi ? u : hi;
			pole |= fabsf(lv->positions[3 * (size_t)v + 1]) > 0.999f;
		}
		/* (not at the poles, where every u meets at one point: any u is that point's) */
		if (!pole) widest = hi - lo > widest ? hi - lo : widest;
	}
	CHECK(widest < 0.25f, "a level triangle spans %.3f of the texture's width (%u triangles)", widest,
	      lv->index_count / 3);
	CHECK(lv->index_count * 10 < ni, "the level keeps %u of %u triangles", lv->index_count / 3, ni / 3);
	api_arena_destroy(a);
	free(pos); free(nrm); free(uv); free(idx);
}

/* A level's faces turn with the winding, not with a few wrong normals in the file: a hilly
 * height field (wound facing up) whose border rows' normals point down, as the farm corpus's
 * terrains' do. Before, each level face followed the sum of its corners' file normals, so the
 * faces over the border turned over, and their corners' normals pointed down (a glb terrain's
 * thumbnail: dark teeth along its border, where the renderer lit those faces from below). */
TEST(model_lod_level_faces_follow_the_winding_not_stray_normals)
{
	enum { S = 200 };   /* 80,000 triangles */
	uint32_t nv = (S + 1) * (S + 1), ni = 6 * S * S;
	float *pos = malloc(nv * 12ull), *nrm = malloc(nv * 12ull);
	uint32_t *idx = malloc(ni * 4ull);
	REQUIRE(pos && nrm && idx);
	for (uint32_t i = 0; i <= S; i++)
		for (uint32_t j = 0; j <= S; j++) {
			uint32_t v = i * (S + 1) + j;
			double x = 2.0 * j / S - 1, z = 2.0 * i / S - 1, h = 0.3 * exp(-3 * (x * x + z * z)) + 0.05 * sin(5 * x);
			double dx = -1.8 * x * exp(-3 * (x * x + z * z)) + 0.25 * cos(5 * x), dz = -1.8 * z * exp(-3 * (x * x + z * z));
			double l = sqrt(dx * dx + 1 + dz * dz);
			pos[3 * v] = (float)x, pos[3 * v + 1] = (float)h, pos[3 * v + 2] = (float)z;
			bool border = i == 0 || j == 0 || i == S || j == S;
			nrm[3 * v] = (float)(-dx / l), nrm[3 * v + 1] = (float)((border ? -1 : 1) / l), nrm[3 * v + 2] = (float)(-dz / l);
		}
	grid_indices(S, idx);
	struct api_model_mesh me = {.positions = pos, .normals = nrm, .indices = idx, .vertex_count = nv, .index_count = ni};
	struct api_arena *a = level_at_256(&me);
	REQUIRE(me.lod_count == 1, "levels: %u", me.lod_count);
	const struct rnd_mesh_lod *lv = &me.lods[0];
	uint32_t down = 0;
	for (uint32_t v = 0; v < lv->vertex_count; v++) down += lv->normals[3 * v + 1] < 0.0f;
	CHECK(down == 0, "%u of the level's %u vertices have normals pointing down", down, lv->vertex_count);
	api_arena_destroy(a);
	free(pos); free(nrm); free(idx);
}
