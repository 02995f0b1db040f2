/*
 * api/model_conv.h — the state of one aiScene's conversion into an api_model, shared by the
 * two files that do it: api/model_import.c (meshes, nodes, the import itself) and
 * api/model_material.c (materials and their textures). Private to those two (and
 * api/stl_import.c, for api_join_vertices).
 *
 * Ownership: what api_conv_alloc returns lives in the caller's arena; mesh_map, tex and inst
 * are malloc'd by model_import.c and freed there. Threading: one conversion, one thread.
 */
#ifndef UMBRA_API_MODEL_CONV_H
#define UMBRA_API_MODEL_CONV_H

#include <stdbool.h>
#include <assimp/material.h>
#include <assimp/scene.h>
#include "arena.h"
#include "gltf_material.h"
#include "model.h"

struct api_conv {
	const struct aiScene *sc;
	struct api_arena *arena;
	struct api_model *out;
	size_t bytes;
	bool oom;                     /* an allocation failed: over the memory limit, not a bad file */
	int32_t *mesh_map;            /* Assimp mesh -> our mesh, -1 = skipped (not triangles) */
	struct rnd_texture **tex;     /* decoded textures: scene->mTextures, then the referred files */
	const struct api_model_file *files;
	size_t nfiles;
	struct api_model_instance *inst;
	uint32_t ninst, inst_cap;
	bool gltf;                    /* glb / gltf: every texture slot, glTF material details */
	bool join;                    /* join corners equal to rounding here (STL: Assimp's join is off) */
	struct api_gltf_info gi;      /* those details, and the warnings (filled for glTF only) */
	const struct rnd_material *mats;
	const bool *single_sided;     /* by material */
	uint32_t texture_side;        /* decode textures for this class of images (0 = as stored) ... */
	uint32_t texture_max;         /* ... the largest one's larger side as stored */
	double texture_ms;            /* time spent decoding them */
	char *err;
	size_t errsize;
};

static inline void *api_conv_alloc(struct api_conv *c, size_t n, size_t size)
{
	void *p = api_arena_calloc(c->arena, n ? n : 1, size);
	if (p) c->bytes += n * size;
	else c->oom = true;
	return p;
}

/* Joins the corners of a mesh of positions and normals (and colours: an STL's per-facet
 * colours) that share a position, a colour and a normal to within 2^-14 (coplanar facets'
 * normals, normalised cross products of different edges, differ in their last bits), in place:
 * corners where facets of one plane meet become one vertex, as Assimp's join made them. The
 * corners are found by sorting them by position (api/weld.h), and that weld is handed on:
 * *weld_group (in arena) the weld group of each joined vertex, *weld_groups how many, for the
 * mesh's weld_group_ (the closedness check and the level use it instead of sorting again).
 * Returns the vertices left; without memory they all stay (the same picture) and *weld_group
 * is NULL. (api/model_import.c; api/stl_import.c uses it too.) */
uint32_t api_join_vertices(float *pos, float *nrm, uint8_t *col, uint32_t nv, uint32_t *idx, uint32_t ni,
                           struct api_arena *arena, const uint32_t **weld_group, uint32_t *weld_groups);

/* Material `index` of the scene into *m (defaults for Assimp's default material), with its
 * textures decoded into the arena; *single_sided from glTF's doubleSided. -1 with c->err (and
 * c->oom when an allocation failed) on failure. */
/* Mesh am's points and lines (faces of 1 and 2 indices) as triangles into out (api/model_strokes.c):
 * a prism of radius r along each segment, an octahedron of radius 2.5 r at each point; out
 * without triangles when am has none. 0, or -1 with c's error. */
int api_conv_strokes(struct api_conv *c, const struct aiMesh *am, float r, struct api_model_mesh *out);

int api_conv_material(struct api_conv *c, const struct aiMaterial *am, uint32_t index, struct rnd_material *m,
                      bool *single_sided);

#endif
