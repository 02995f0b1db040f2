/*
 * api/stl_import.c — binary STL without Assimp (see stl_import.h).
 *
 * A binary STL is an 80-byte header, a triangle count and 50 bytes a facet: a normal (ignored:
 * facet normals are often wrong), three corners and two attribute bytes. Assimp read it, then
 * made flat normals from the winding (aiProcess_GenNormals), and api/model_import.c joined the
 * corners of coplanar facets; for a 1M-triangle file that was ~1.5 s, most of it Assimp's
 * generic machinery (a scene graph, post-processing steps that do nothing here). This reads
 * the facets straight into the arrays the model keeps and makes the same normals the same way
 * (Assimp's cross product and 1/length scaling, in float), then joins with the same function,
 * so the model is the one the Assimp path made (tests/unit/test_stl.c compares them).
 *
 * Colours are Assimp's: a header with "COLOR=" (Materialise) or a facet with bit 15 of its
 * attribute set (VisCAM, SolidView) goes to Assimp, and so does anything odd (a count that does
 * not match the size, a position that is not finite, no facet with an area), for its messages.
 */
#include <math.h>
#include <stdatomic.h>
#include <string.h>
#include "errmsg.h"
#include "model_conv.h"
#include "stl_import.h"
#include "umbra/rnd_math.h"
#include "workers.h"

static bool has_colour(const uint8_t *d, uint32_t n)
{
	for (size_t i = 0; i + 6 <= 80; i++)
		if (!memcmp(d + i, "COLOR=", 6)) return true;
	for (uint32_t f = 0; f < n; f++)
		if (d[84 + 50 * (size_t)f + 49] & 0x80) return true;
	return false;
}

/* Assimp's face normal: (b - a) x (c - a), scaled by 1/length when the length is not 0. */
static void face_normal(const float a[3], const float b[3], const float c[3], float n[3])
{
	float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
	n[0] = u[1] * v[2] - u[2] * v[1];
	n[1] = u[2] * v[0] - u[0] * v[2];
	n[2] = u[0] * v[1] - u[1] * v[0];
	float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
	if (len > 0.0f) {
		float inv = 1.0f / len;
		n[0] *= inv; n[1] *= inv; n[2] *= inv;
	}
}

/* The facets in FACET_TASKS slices on the import's threads (api/workers.h): each slice writes
 * only its own facets' corners, normals and indices, so the bytes do not depend on the thread
 * count; a slice only ever sets the two flags. */
#define FACET_TASKS 64

struct facets {
	const uint8_t *d;
	uint32_t n;
	float *pos, *nrm;
	uint32_t *idx;
	atomic_int infinite, area;
};

static void read_facets(void *ctx, size_t task, unsigned wk)
{
	(void)wk;
	struct facets *q = ctx;
	bool area = false;
	for (uint32_t f = (uint32_t)(task * q->n / FACET_TASKS); f < (uint32_t)((task + 1) * q->n / FACET_TASKS); f++) {
		const uint8_t *r = q->d + 84 + 50 * (size_t)f + 12;
		float *p = q->pos + 9 * (size_t)f, *nm = q->nrm + 9 * (size_t)f;
		memcpy(p, r, 36);
		for (int k = 0; k < 9; k++)
			if (!isfinite(p[k])) {
				atomic_store(&q->infinite, 1);
				return;
			}
		face_normal(p, p + 3, p + 6, nm);
		area |= nm[0] != 0.0f || nm[1] != 0.0f || nm[2] != 0.0f;
		memcpy(nm + 3, nm, 12);
		memcpy(nm + 6, nm, 12);
		for (uint32_t k = 0; k < 3; k++) q->idx[3 * f + k] = 3 * f + k;
	}
	if (area) atomic_store(&q->area, 1);
}

int api_stl_import_binary(const uint8_t *d, size_t len, struct api_arena *arena, struct api_model *out,
                          size_t *bytes, char *err, size_t errsize)
{
	if (len < 84) return API_STL_NOT_MINE;
	uint32_t n;
	memcpy(&n, d + 80, 4);
	if (!n || (uint64_t)n * 50 + 84 != len || (uint64_t)n * 3 > UINT32_MAX || has_colour(d, n)) return API_STL_NOT_MINE;
	uint32_t nv = 3 * n;
	float *pos = api_arena_calloc(arena, nv, 12), *nrm = api_arena_calloc(arena, nv, 12);
	uint32_t *idx = api_arena_calloc(arena, nv, 4);
	struct api_model_mesh *me = api_arena_calloc(arena, 1, sizeof *me);
	struct api_model_instance *inst = api_arena_calloc(arena, 1, sizeof *inst);
	struct rnd_material *mat = api_arena_calloc(arena, 1, sizeof *mat);
	if (!pos || !nrm || !idx || !me || !inst || !mat) {
		api_err_set(err, errsize, "out of memory importing the model");
		return API_WIRE_OVER_MEMORY;
	}
	struct facets q = {d, n, pos, nrm, idx, 0, 0};
	api_workers_run(FACET_TASKS, read_facets, &q);
	if (atomic_load(&q.infinite) || !atomic_load(&q.area)) return API_STL_NOT_MINE;
	rnd_material_defaults(mat);
	*me = (struct api_model_mesh){.positions = pos, .normals = nrm, .indices = idx, .index_count = nv, .material = 0};
	me->vertex_count = api_join_vertices(pos, nrm, NULL, nv, idx, nv, arena, &me->weld_group_, &me->weld_groups_);
	inst->mesh = 0;
	rnd_mat4_identity(inst->model);
	*out = (struct api_model){.meshes = me, .mesh_count = 1, .instances = inst, .instance_count = 1, .materials = mat,
	                          .material_count = 1, .triangles = n, .format = API_MODEL_STL};
	*bytes = (size_t)nv * 28 + sizeof *me + sizeof *inst + sizeof *mat;
	return API_WIRE_OK;
}
