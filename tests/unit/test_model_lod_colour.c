/* tests — the levels of vertex-coloured meshes (api/model_lod.c split by colour, api/lod_colour.c
 * measured for colour) and the renderer's use of their colours (renderer/lod.c): a sphere in
 * bands of colour gets a level whose band edges stay one row of the full mesh wide, a sphere of
 * random colours (no level could show them) gets none, and a level drawn for a coloured object
 * brings its own colours. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"
#include "api.h"
#include "arena.h"
#include "model.h"
#include "model_levels.h"
#include "lod.h"
#include "lod_colour.h"
#include "model_lod.h"
#include "model_util.h"

#define PI_D 3.14159265358979323846

/* An indexed unit UV sphere of `rows` rows of 2 * rows quads (the poles' rows are fans of
 * vertices at one position), normals its positions, colour(row, column) per vertex (malloc'd). */
static struct api_model_mesh coloured_sphere(uint32_t rows, void (*colour)(uint32_t, uint32_t, uint32_t, uint8_t[4]))
{
	uint32_t cols = 2 * rows, nv = (rows + 1) * cols, ni = rows * cols * 6;
	float *pos = malloc(nv * 12), *nrm = malloc(nv * 12);
	uint8_t *col = malloc(nv * 4);
	uint32_t *idx = malloc(ni * 4), k = 0;
	for (uint32_t i = 0; i <= rows; i++)
		for (uint32_t j = 0; j < cols; j++) {
			double th = PI_D * i / rows, ph = 2 * PI_D * j / cols;
			float *p = pos + 3 * (i * cols + j);
			p[0] = (float)(sin(th) * cos(ph)), p[1] = (float)cos(th), p[2] = (float)(sin(th) * sin(ph));
			if (i == 0 || i == rows) p[0] = p[2] = 0;
			memcpy(nrm + 3 * (i * cols + j), p, 12);
			colour(i, j, rows, col + 4 * (i * cols + j));
		}
	for (uint32_t i = 0; i < rows; i++)
		for (uint32_t j = 0; j < cols; j++) {
			uint32_t a = i * cols + j, b = i * cols + (j + 1) % cols, c = a + cols, d = b + cols;
			uint32_t t[6] = {a, c, b, b, c, d};
			memcpy(idx + k, t, sizeof t);
			k += 6;
		}
	return (struct api_model_mesh){.positions = pos, .normals = nrm, .colors = col, .indices = idx, .vertex_count = nv,
	                               .index_count = ni};
}

static void free_sphere(struct api_model_mesh *me)
{
	free((void *)me->positions);
	free((void *)me->normals);
	free((void *)me->colors);
	free((void *)me->indices);
}

static const uint8_t band_colours[5][4] = {
	{230, 40, 30, 255}, {30, 60, 220, 255}, {250, 250, 250, 255}, {20, 20, 20, 255}, {90, 200, 60, 255}};

/* Five bands by row, like the farm corpus's vertex-coloured blob (by height). */
static void bands(uint32_t i, uint32_t j, uint32_t rows, uint8_t out[4])
{
	(void)j;
	memcpy(out, band_colours[i * 5 / (rows + 1)], 4);
}

static void noise(uint32_t i, uint32_t j, uint32_t rows, uint8_t out[4])
{
	uint32_t h = (i * 2 * rows + j) * 2654435761u;
	h ^= h >> 15;
	h *= 2246822519u;
	h ^= h >> 13;
	out[0] = (uint8_t)h, out[1] = (uint8_t)(h >> 8), out[2] = (uint8_t)(h >> 16), out[3] = 255;
}

/* The row of the sphere at height y. */
static uint32_t row_of(float y, uint32_t rows)
{
	return (uint32_t)lround(acos(fmax(-1.0, fmin(1.0, (double)y))) / PI_D * rows);
}

static struct api_arena *level_for(struct api_model_mesh *me, uint32_t side)
{
	struct api_model m = {0};
	m.meshes = me;
	m.mesh_count = 1;
	struct api_arena *a = api_arena_create();
	size_t bytes = 0;
	api_model_build_level(&m, side, a, &bytes);
	return a;
}

TEST(model_lod_coloured_bands_get_a_level_that_keeps_their_edges)
{
	uint32_t rows = 160;   /* 102,400 triangles */
	struct api_model_mesh me = coloured_sphere(rows, bands);
	CHECK(api_mesh_wants_levels(&me), "a vertex-coloured mesh wants a level");
	struct api_arena *a = level_for(&me, 256);
	REQUIRE(me.lod_count == 1, "levels: %u", me.lod_count);
	const struct rnd_mesh_lod *lv = &me.lods[0];
	REQUIRE(lv->colors != NULL, "the level carries colours");
	CHECK(lv->index_count * 4 <= me.index_count, "%u of %u triangles", lv->index_count / 3, me.index_count / 3);
	/* Every vertex keeps its own colour, and every triangle that blends two bands spans one row
	 * of the full mesh, as the full mesh's own blending rows do: the edges neither moved nor
	 * widened (a level simplified by position alone blends across a dozen rows). */
	uint32_t wrong = 0, wide = 0, blending = 0;
	for (uint32_t v = 0; v < lv->vertex_count; v++) {
		uint8_t want[4];
		bands(row_of(lv->positions[3 * v + 1], rows), 0, rows, want);
		wrong += memcmp(lv->colors + 4 * v, want, 4) != 0;
	}
	for (uint32_t t = 0; t < lv->index_count; t += 3) {
		const uint32_t *c = lv->indices + t;
		if (!memcmp(lv->colors + 4 * c[0], lv->colors + 4 * c[1], 4) && !memcmp(lv->colors + 4 * c[0], lv->colors + 4 * c[2], 4))
			continue;
		blending++;
		uint32_t lo = rows, hi = 0;
		for (int k = 0; k < 3; k++) {
			uint32_t r = row_of(lv->positions[3 * c[k] + 1], rows);
			lo = r < lo ? r : lo;
			hi = r > hi ? r : hi;
		}
		wide += hi - lo > 1;
	}
	CHECK(wrong == 0, "%u of %u vertices with another colour", wrong, lv->vertex_count);
	CHECK(blending > 0 && wide == 0, "%u of %u blending triangles span more than one row", wide, blending);
	api_arena_destroy(a);
	free_sphere(&me);
}

TEST(model_lod_colours_no_level_can_show_get_none)
{
	uint32_t rows = 160;
	struct api_model_mesh me = coloured_sphere(rows, noise);
	struct api_arena *a = level_for(&me, 256);
	CHECK(me.lod_count == 0, "random colours got a level of %u triangles", me.lod_count ? me.lods[0].index_count / 3 : 0);
	api_arena_destroy(a);
	/* the same sphere without its colours does: the colours refused it */
	const uint8_t *col = me.colors;
	me.colors = NULL;
	me.lods = NULL;
	me.lod_count = 0;
	a = level_for(&me, 256);
	CHECK(me.lod_count == 1, "uncoloured: %u levels", me.lod_count);
	api_arena_destroy(a);
	me.colors = col;
	free_sphere(&me);
}

/* A smooth ramp of colour by height (a level interpolates it), and the bands with noise of
 * +-12/255 on every vertex (a scan's colours: no level keeps them). */
static void ramp(uint32_t i, uint32_t j, uint32_t rows, uint8_t out[4])
{
	(void)j;
	out[0] = (uint8_t)(255 * i / rows), out[1] = (uint8_t)(128 + 100 * i / rows), out[2] = 40, out[3] = 255;
}

static void noisy_bands(uint32_t i, uint32_t j, uint32_t rows, uint8_t out[4])
{
	uint8_t n[4];
	bands(i, j, rows, out);
	noise(i, j, rows, n);
	for (int k = 0; k < 3; k++) out[k] = (uint8_t)fmin(255.0, fmax(0.0, out[k] + (n[k] % 25) - 12.0));
}

/* The cheap guess that spares a level's cost: rough for random colours and noisy bands, not
 * for bands or a ramp, which get their levels; the noisy bands none (before the guess, the
 * same outcome after a refused build). */
TEST(model_lod_colours_rough_only_where_no_level_can_show_them)
{
	void (*kinds[4])(uint32_t, uint32_t, uint32_t, uint8_t[4]) = {bands, ramp, noise, noisy_bands};
	const char *names[4] = {"bands", "ramp", "noise", "noisy bands"};
	for (int k = 0; k < 4; k++) {
		struct api_model_mesh me = coloured_sphere(120, kinds[k]);
		bool rough = api_lod_colours_rough(me.colors, me.vertex_count, me.indices, me.index_count);
		CHECK(rough == (k >= 2), "%s: rough %d", names[k], rough);
		if (k != 2) {   /* (noise: model_lod_colours_no_level_can_show_get_none) */
			struct api_arena *a = level_for(&me, 256);
			CHECK(me.lod_count == (k < 2), "%s: %u levels", names[k], me.lod_count);
			api_arena_destroy(a);
		}
		free_sphere(&me);
	}
}

TEST(model_lod_colour_error_of_a_level_that_blurs_a_stripe)
{
	/* A square of two triangles over a full mesh whose middle vertex is red among white: the
	 * square's interpolation shows white where the full mesh shows red. */
	float pos[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5f, 0.5f, 0};
	uint8_t col[] = {255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 0, 0, 255};
	uint32_t full[] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4}, level[] = {0, 1, 2, 0, 2, 3};
	float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
	float e = api_lod_colour_error(pos, col, 5, full, 12, level, 6, lo, hi, 1.0f, 0.01f, 1.0f);
	CHECK(e > 0.9f, "the red vertex shown white: error %g", e);
	/* A step of the colours' own 8 bits is within the bound (a ramp's level interpolates the
	 * ramp, not its rounding), and so are 2/255 of sRGB past it: mid-grey 131 among 128 */
	uint8_t grey[20], dark[20];
	memset(grey, 128, sizeof grey);
	memset(grey + 16, 131, 3);
	e = api_lod_colour_error(pos, grey, 5, full, 12, level, 6, lo, hi, 1.0f, 0.01f, 1.0f);
	CHECK(e <= API_LOD_COLOUR_BOUND, "grey 131 shown 128: error %g", e);
	/* but not near black, where sRGB spreads those steps: 3 among 0 is 22/255 off */
	memset(dark, 0, sizeof dark);
	memset(dark + 16, 3, 3);
	e = api_lod_colour_error(pos, dark, 5, full, 12, level, 6, lo, hi, 1.0f, 0.01f, 1.0f);
	CHECK(e > 8.0f / 255.0f, "dark 3 shown 0: error %g", e);
	/* alpha has no encoding: 251 among 128 is over */
	memset(grey + 16, 128, 3);
	grey[19] = 251;
	e = api_lod_colour_error(pos, grey, 5, full, 12, level, 6, lo, hi, 1.0f, 0.01f, 1.0f);
	CHECK(e > API_LOD_COLOUR_BOUND, "alpha 251 shown 128: error %g", e);
}

/* The same for tangents: a normal-mapped object draws a level only with them. */
TEST(lod_apply_draws_a_level_with_its_tangents)
{
	float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, n[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
	float full_tan[12] = {0}, level_tan[12] = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, -1};
	uint32_t i[3] = {0, 1, 2};
	struct rnd_mesh_lod with = {p, n, NULL, i, 3, 3, 0.1f, NULL, NULL, level_tan};
	struct rnd_mesh_lod without = {p, n, NULL, i, 3, 3, 0.1f, NULL, NULL, NULL};
	struct rnd_object o = {.shape = RND_SHAPE_MESH, .tangents = full_tan, .lods = &with, .lod_count = 1};
	rnd_lod_apply(&o, 1);
	CHECK(o.tangents == level_tan && o.index_count == 3, "the level's tangents are drawn");
	struct rnd_object q = {.shape = RND_SHAPE_MESH, .tangents = full_tan, .lods = &without, .lod_count = 1, .index_count = 99};
	rnd_lod_apply(&q, 1);
	CHECK(q.tangents == full_tan && q.index_count == 99, "a level without tangents is not drawn for a normal-mapped mesh");
	struct rnd_object u = {.shape = RND_SHAPE_MESH, .lods = &with, .lod_count = 1};
	rnd_lod_apply(&u, 1);
	CHECK(u.tangents == NULL && u.index_count == 3, "an object without tangents gets none");
}

TEST(lod_apply_draws_a_level_with_its_colours)
{
	float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, n[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
	uint32_t i[3] = {0, 1, 2};
	uint8_t full_col[12] = {0}, level_col[12] = {1, 2, 3, 4};
	struct rnd_mesh_lod with = {p, n, NULL, i, 3, 3, 0.1f, NULL, level_col}, without = {p, n, NULL, i, 3, 3, 0.1f, NULL, NULL};
	struct rnd_object o = {.shape = RND_SHAPE_MESH, .colors = full_col, .lods = &with, .lod_count = 1};
	rnd_lod_apply(&o, 1);
	CHECK(o.colors == level_col, "the level's colours are drawn");
	struct rnd_object q = {.shape = RND_SHAPE_MESH, .colors = full_col, .lods = &without, .lod_count = 1, .index_count = 99};
	rnd_lod_apply(&q, 1);
	CHECK(q.colors == full_col && q.index_count == 99, "a level without colours is not drawn for a coloured mesh");
	struct rnd_object u = {.shape = RND_SHAPE_MESH, .lods = &with, .lod_count = 1};
	rnd_lod_apply(&u, 1);
	CHECK(u.colors == NULL && u.index_count == 3, "an uncoloured object stays uncoloured");
}

/* me as a binary PLY (positions, uchar RGB, triangles); malloc'd, *len its size. */
static uint8_t *ply_of(const struct api_model_mesh *me, size_t *len)
{
	char head[400];
	int h = snprintf(head, sizeof head,
	                 "ply\nformat binary_little_endian 1.0\nelement vertex %u\nproperty float x\nproperty float y\n"
	                 "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face %u\n"
	                 "property list uchar int vertex_indices\nend_header\n",
	                 me->vertex_count, me->index_count / 3);
	*len = (size_t)h + (size_t)me->vertex_count * 15 + (size_t)me->index_count / 3 * 13;
	uint8_t *d = malloc(*len), *p = d;
	if (!d) return NULL;
	memcpy(p, head, (size_t)h);
	p += h;
	for (uint32_t v = 0; v < me->vertex_count; v++, p += 15) {
		memcpy(p, me->positions + 3 * v, 12);
		memcpy(p + 12, me->colors + 4 * v, 3);
	}
	for (uint32_t t = 0; t < me->index_count; t += 3, p += 13) {
		p[0] = 3;
		memcpy(p + 1, me->indices + t, 12);
	}
	return d;
}

static struct api_model *get_ply(const uint8_t *d, size_t len, uint32_t side)
{
	return model_get_for(d, len, API_MODEL_PLY, side, 0);
}

/* Through the sandbox: a banded PLY imported for 256^2 images has its coloured level, and
 * drawn from the cache at 128^2 gets that size's level built by the levels job, with colours,
 * the same level (colours too) as a fresh import for 128^2 builds. */
TEST(model_lod_coloured_level_for_another_size_equals_a_fresh_imports)
{
	struct api_model_mesh me = coloured_sphere(120, bands);   /* 57,600 triangles */
	size_t len;
	uint8_t *d = ply_of(&me, &len);
	REQUIRE(d != NULL);
	api_model_cache_clear();
	struct api_model *a = get_ply(d, len, 256), *b = get_ply(d, len, 128);
	REQUIRE(a && b == a);
	uint32_t n256, n128, nf;
	const struct rnd_mesh_lod *l256 = api_model_mesh_lods(a, 0, 256, &n256), *l128 = api_model_mesh_lods(a, 0, 128, &n128);
	REQUIRE(n256 == 1 && n128 == 1, "%u and %u levels", n256, n128);
	CHECK(a->meshes[0].colors && l256->colors && l128->colors, "the levels carry colours");
	CHECK(l128->index_count < l256->index_count, "128^2: %u indices; 256^2: %u", l128->index_count, l256->index_count);
	/* the levels job's level, kept past the model's release */
	uint32_t nv = l128->vertex_count, ni = l128->index_count;
	float *pos = malloc((size_t)nv * 12);
	uint32_t *idx = malloc((size_t)ni * 4);
	uint8_t *col = malloc((size_t)nv * 4);
	REQUIRE(pos && idx && col);
	memcpy(pos, l128->positions, (size_t)nv * 12);
	memcpy(idx, l128->indices, (size_t)ni * 4);
	memcpy(col, l128->colors ? l128->colors : col, (size_t)nv * 4);
	api_model_release(a);
	api_model_release(b);
	api_model_cache_clear();
	struct api_model *fresh = get_ply(d, len, 128);
	REQUIRE(fresh != NULL);
	const struct rnd_mesh_lod *lf = api_model_mesh_lods(fresh, 0, 128, &nf);
	REQUIRE(nf == 1);
	CHECK(lf->vertex_count == nv && lf->index_count == ni && !memcmp(lf->positions, pos, (size_t)nv * 12) &&
	      !memcmp(lf->indices, idx, (size_t)ni * 4) && lf->colors && !memcmp(lf->colors, col, (size_t)nv * 4),
	      "the fresh import's level is the levels job's");
	api_model_release(fresh);
	api_model_cache_clear();
	free(pos);
	free(idx);
	free(col);
	free(d);
	free_sphere(&me);
}
