/*
 * api/model_import — the Assimp import itself (see model_import.h): untrusted bytes in, an
 * api_model in an arena out. Runs inside the sandboxed importer process (api/sandbox_child.c);
 * the daemon never calls it (the bench does, to measure what isolation costs).
 *
 * Import: Assimp reads the bytes through an aiFileIO (api/model_io.c) that serves only those
 * bytes and the files the daemon found for the model's references (an .obj's mtllib and
 * textures, a .gltf's buffers and images; api/model_refs.h), so the importer never reads from a
 * disk (the sandbox's system-call filter would refuse an open anyway); a name it was not given
 * fails. The node tree is walked with
 * every node's transform (Assimp's aiMatrix4x4 is row-major; ours are column-major), each
 * (node, mesh) pair becoming one instance; meshes keep triangles, and points and lines become
 * thin geometry (api/model_strokes.c).
 *
 * Materials: glTF's core material model (every texture slot, samplers, texture transforms,
 * emissive strength, doubleSided: what Assimp 5.2 does not hand over reliably is read from the
 * document's JSON, api/gltf_material.c; the conversion in api/model_material.c), vertex
 * colours, and tangents for normal maps. What a
 * file asks for and is not drawn becomes the model's warnings.
 */
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <jansson.h>
#include "errmsg.h"
#include "gltf_buffers.h"
#include "gltf_decode.h"
#include "gltf_instancing.h"
#include "gltf_material.h"
#include "model_conv.h"
#include "model_import.h"
#include "model_io.h"
#include "model_lod.h"
#include "obj_import.h"
#include "ply_colors.h"
#include "ply_import.h"
#include "ply_strips.h"
#include "stl_import.h"
#include "umbra/rnd_math.h"

#define MAX_NODE_DEPTH 256

/* Assimp's C API keeps the last error in one global std::string. In the sandbox each process
 * imports once; in-process callers (the bench) take turns. */
static pthread_mutex_t import_mu = PTHREAD_MUTEX_INITIALIZER;

static const char *const FORMAT_NAMES[] = {"glb", "gltf", "obj", "stl", "ply"};


/* ---- glTF checks Assimp 5.2 lacks ---- */

/* Assimp 5.2's glTF2 importer crashes on some malformed documents (an image whose mimeType is
 * neither PNG nor JPEG dereferences NULL). What it does not check, we check first: the JSON
 * chunk is a JSON object, and every image's mimeType (and data: URI type) is PNG or JPEG. */
static bool image_type_ok(const char *t, size_t n)
{
	return (n == 9 && !memcmp(t, "image/png", 9)) || (n == 10 && !memcmp(t, "image/jpeg", 10));
}

/* On success *root_out is the parsed document (the caller's reference). */
static int gltf_precheck(const uint8_t *d, size_t len, enum api_model_format f, json_t **root_out, char *err,
                         size_t errsize)
{
	*root_out = NULL;
	const char *json;
	size_t jlen;
	const char *bad = api_gltf_json_of(d, len, f == API_MODEL_GLB, &json, &jlen);
	if (bad) return api_err_set(err, errsize, "%s", bad), -1;
	json_error_t je;
	json_t *root = json_loadb(json, jlen, 0, &je);
	if (!json_is_object(root)) {
		json_decref(root);
		return api_err_set(err, errsize, "the glTF JSON is malformed (line %d: %s)", je.line,
		               root ? "not an object" : je.text), -1;
	}
	json_t *images = json_object_get(root, "images"), *im;
	size_t i;
	int rc = 0;
	if (images && !json_is_array(images)) rc = -1;
	json_array_foreach(images, i, im) {
		json_t *mt = json_object_get(im, "mimeType"), *uri = json_object_get(im, "uri");
		if (!json_is_object(im) || (mt && (!json_is_string(mt) ||
		                                   !image_type_ok(json_string_value(mt), json_string_length(mt)))))
			rc = -1;
		if (json_is_string(uri) && !strncmp(json_string_value(uri), "data:", 5)) {
			const char *u = json_string_value(uri) + 5, *semi = strpbrk(u, ";,");
			if (!semi || !image_type_ok(u, (size_t)(semi - u))) rc = -1;
		}
		if (rc) break;
	}
	if (rc) {
		json_decref(root);
		return api_err_set(err, errsize, "glTF image %zu is not a PNG or JPEG image (mimeType)", i), -1;
	}
	*root_out = root;
	return 0;
}

/* The model's own name in the aiFileIO (api/model_io.c): "model.<format>". */
#define MEM_NAME "model"

/* ---- conversion of an aiScene (materials and textures: api/model_material.c) ---- */

/* aiMatrix4x4 is row-major (a1..a4 the first row, a4/b4/c4 the translation). */
static void mat_from_ai(float out[16], const struct aiMatrix4x4 *a)
{
	const float r[16] = {a->a1, a->a2, a->a3, a->a4, a->b1, a->b2, a->b3, a->b4,
	                     a->c1, a->c2, a->c3, a->c4, a->d1, a->d2, a->d3, a->d4};
	for (int row = 0; row < 4; row++)
		for (int col = 0; col < 4; col++) out[col * 4 + row] = r[row * 4 + col];
}

bool api_model_meshes_have_area(const struct api_model_mesh *m, uint32_t n)
{
	for (uint32_t i = 0; i < n; i++)
		for (uint32_t t = 0; t + 2 < m[i].index_count; t += 3) {
			const float *a = &m[i].positions[3 * m[i].indices[t]], *b = &m[i].positions[3 * m[i].indices[t + 1]],
			            *c = &m[i].positions[3 * m[i].indices[t + 2]];
			float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
			float x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
			if (x * x + y * y + z * z > 0.0f) return true;
		}
	return false;
}

/* Vertex colours (COLOR_0) and, for a mesh whose material has a normal map, tangents (from
 * the file or made by aiProcess_CalcTangentSpace). aiColor4D and aiVector3D are plain floats. */
_Static_assert(sizeof(struct aiVector3D) == 12 && sizeof(struct aiColor4D) == 16, "Assimp built with doubles");
static int convert_extras(struct api_conv *c, const struct aiMesh *am, struct api_model_mesh *out)
{
	uint32_t nv = am->mNumVertices;
	unsigned mi = am->mMaterialIndex < c->sc->mNumMaterials ? am->mMaterialIndex : 0;
	bool tan = am->mTangents && am->mBitangents && am->mNormals && c->mats[mi].normal_texture;
	uint8_t *col = am->mColors[0] ? api_conv_alloc(c, nv, 4) : NULL;
	float *t = tan ? api_conv_alloc(c, nv, 4 * sizeof(float)) : NULL;
	if ((am->mColors[0] && !col) || (tan && !t))
		return api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	if (col) api_vertex_colors((const float *)am->mColors[0], nv, col);
	if (t) api_vertex_tangents((const float *)am->mTangents, (const float *)am->mBitangents, (const float *)am->mNormals, nv, t);
	out->colors = col;
	out->tangents = t;
	return 0;
}

/* Fills convert_mesh's arrays; sets out->index_count (and its colours and tangents). */
/* Assimp's uv set `set` of am into uv (glTF's v, finite), when it has one. */
static void convert_uvs(const struct aiMesh *am, int set, float *uv)
{
	if (!uv) return;
	for (uint32_t v = 0; v < am->mNumVertices; v++) {
		/* Assimp puts v = 0 at the bottom (OpenGL); glTF and our textures at the top. */
		const struct aiVector3D *t = &am->mTextureCoords[set][v];
		uv[2 * v] = isfinite(t->x) ? t->x : 0;
		uv[2 * v + 1] = isfinite(t->y) ? 1.0f - t->y : 0;
	}
}

static int convert_data(struct api_conv *c, const struct aiMesh *am, struct api_model_mesh *out, float *pos, float *nrm,
                        float *uv, float *uv1, uint32_t *idx)
{
	uint32_t nv = am->mNumVertices;
	if (!pos || (am->mNormals && !nrm) || (am->mTextureCoords[0] && !uv) || (am->mTextureCoords[1] && !uv1) || !idx)
		return api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	if (convert_extras(c, am, out) < 0) return -1;
	for (uint32_t v = 0; v < nv; v++) {
		const struct aiVector3D *p = &am->mVertices[v];
		if (!isfinite(p->x) || !isfinite(p->y) || !isfinite(p->z))
			return api_err_set(c->err, c->errsize, "mesh \"%.64s\": vertex %u is not a finite position",
			               am->mName.data, v), -1;
		pos[3 * v] = p->x; pos[3 * v + 1] = p->y; pos[3 * v + 2] = p->z;
		if (nrm) {
			const struct aiVector3D *n = &am->mNormals[v];
			bool ok = isfinite(n->x) && isfinite(n->y) && isfinite(n->z);
			/* Degenerate faces leave NaN normals behind; any direction will do for them. */
			nrm[3 * v] = ok ? n->x : 0; nrm[3 * v + 1] = ok ? n->y : 1; nrm[3 * v + 2] = ok ? n->z : 0;
		}
	}
	convert_uvs(am, 0, uv);
	convert_uvs(am, 1, uv1);
	uint32_t k = 0;
	for (unsigned f = 0; f < am->mNumFaces; f++) {
		const struct aiFace *face = &am->mFaces[f];
		if (face->mNumIndices != 3) continue;
		for (int j = 0; j < 3; j++) {
			if (face->mIndices[j] >= nv)
				return api_err_set(c->err, c->errsize, "mesh \"%.64s\": face %u refers to vertex %u of %u",
				               am->mName.data, f, face->mIndices[j], nv), -1;
			idx[k++] = face->mIndices[j];
		}
	}
	out->index_count = k;
	return 0;
}

/* A material slot on TEXCOORD_1 of a mesh without that set: the renderer draws it with
 * TEXCOORD_0 (rnd.h uvs1), and the model says so. */
static void warn_missing_uv1(struct api_conv *c, const struct aiMesh *am, const struct api_model_mesh *me,
                             const struct rnd_material *m)
{
	if (me->uvs1) return;
	for (uint32_t k = 0; k < RND_TEX_SLOTS; k++)
		if (m->textures[k] && m->sampling[k].uv_set == 1)
			api_gltf_warn(&c->gi, "mesh \"%.40s\": its material's %s reads TEXCOORD_1, which the mesh lacks: drawn "
			              "with TEXCOORD_0", am->mName.data, api_gltf_slot_name(k));
}

static int convert_mesh(struct api_conv *c, const struct aiMesh *am, struct api_model_mesh *out)
{
	uint32_t nv = am->mNumVertices, ntri = 0;
	for (unsigned f = 0; f < am->mNumFaces; f++) ntri += am->mFaces[f].mNumIndices == 3;
	float *pos = api_conv_alloc(c, nv, 3 * sizeof(float));
	float *nrm = am->mNormals ? api_conv_alloc(c, nv, 3 * sizeof(float)) : NULL;
	float *uv = am->mTextureCoords[0] ? api_conv_alloc(c, nv, 2 * sizeof(float)) : NULL;
	float *uv1 = am->mTextureCoords[1] ? api_conv_alloc(c, nv, 2 * sizeof(float)) : NULL;
	uint32_t *idx = (uint64_t)ntri * 3 <= UINT32_MAX ? api_conv_alloc(c, (size_t)ntri * 3, sizeof(uint32_t)) : NULL;
	if (convert_data(c, am, out, pos, nrm, uv, uv1, idx) < 0) return -1;
	out->positions = pos;
	out->normals = nrm;
	out->uvs = uv;
	out->uvs1 = uv1;
	out->single_sided = c->single_sided[am->mMaterialIndex < c->sc->mNumMaterials ? am->mMaterialIndex : 0];
	out->indices = idx;
	out->vertex_count = nv;
	out->material = am->mMaterialIndex;
	/* the colours are ours (the arena) until the model is shared */
	if (c->join && nrm && !uv && !uv1 && !out->tangents && nv)
		out->vertex_count = api_join_vertices(pos, nrm, (uint8_t *)out->colors, nv, idx, out->index_count, c->arena,
		                                      &out->weld_group_, &out->weld_groups_);
	return 0;
}

static int walk(struct api_conv *c, const struct aiNode *node, const float parent[16], int depth)
{
	if (depth > MAX_NODE_DEPTH)
		return api_err_set(c->err, c->errsize, "the node tree is deeper than %d levels", MAX_NODE_DEPTH), -1;
	float local[16], global[16];
	mat_from_ai(local, &node->mTransformation);
	rnd_mat4_mul(global, parent, local);
	for (int i = 0; i < 16; i++)
		if (!isfinite(global[i]))
			return api_err_set(c->err, c->errsize, "node \"%.64s\" has a transform that is not finite",
			               node->mName.data), -1;
	for (unsigned i = 0; i < node->mNumMeshes; i++) {
		unsigned mi = node->mMeshes[i];
		if (mi >= c->sc->mNumMeshes || c->mesh_map[mi] < 0) continue;
		if (c->ninst == c->inst_cap) {
			uint32_t cap = c->inst_cap ? c->inst_cap * 2 : 16;
			struct api_model_instance *n = realloc(c->inst, cap * sizeof *n);
			if (!n || cap < c->inst_cap)
				return c->oom = true, api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;
			c->inst = n;
			c->inst_cap = cap;
		}
		c->inst[c->ninst].mesh = (uint32_t)c->mesh_map[mi];
		memcpy(c->inst[c->ninst].model, global, sizeof global);
		c->ninst++;
	}
	for (unsigned i = 0; i < node->mNumChildren; i++)
		if (walk(c, node->mChildren[i], global, depth + 1) < 0) return -1;
	return 0;
}

/* The radius points and lines are drawn with (api/model_strokes.c): 1/500 of the diagonal of
 * the box of every mesh's vertices (node transforms left out: a size, not a place). */
static float stroke_radius(const struct aiScene *sc)
{
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (unsigned i = 0; i < sc->mNumMeshes; i++)
		for (unsigned v = 0; v < sc->mMeshes[i]->mNumVertices; v++) {
			const struct aiVector3D *p = &sc->mMeshes[i]->mVertices[v];
			const float q[3] = {p->x, p->y, p->z};
			for (int k = 0; k < 3; k++)
				if (isfinite(q[k])) lo[k] = fminf(lo[k], q[k]), hi[k] = fmaxf(hi[k], q[k]);
		}
	float d = 0;
	for (int k = 0; k < 3; k++) d += hi[k] > lo[k] ? (hi[k] - lo[k]) * (hi[k] - lo[k]) : 0;
	return d > 0 && isfinite(d) ? sqrtf(d) / 500 : 1e-3f;
}

static int convert(struct api_conv *c)
{
	const struct aiScene *sc = c->sc;
	struct api_model *m = c->out;
	c->mesh_map = calloc(sc->mNumMeshes ? sc->mNumMeshes : 1, sizeof *c->mesh_map);
	c->tex = calloc(sc->mNumTextures + c->nfiles + 1, sizeof *c->tex);
	if (!c->mesh_map || !c->tex)
		return c->oom = true, api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;

	uint32_t nmat = sc->mNumMaterials ? sc->mNumMaterials : 1;
	struct rnd_material *mats = api_conv_alloc(c, nmat, sizeof *mats);
	bool *single = api_conv_alloc(c, nmat, sizeof *single);
	if (!mats || !single) return api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	rnd_material_defaults(&mats[0]);
	for (unsigned i = 0; i < sc->mNumMaterials; i++)
		if (api_conv_material(c, sc->mMaterials[i], i, &mats[i], &single[i]) < 0) return -1;
	c->mats = mats;
	c->single_sided = single;

	struct api_model_mesh *meshes = api_conv_alloc(c, sc->mNumMeshes, sizeof *meshes);
	if (!meshes) return api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	uint32_t nmesh = 0;
	float stroke = stroke_radius(sc);
	for (unsigned i = 0; i < sc->mNumMeshes; i++) {
		const struct aiMesh *am = sc->mMeshes[i];
		c->mesh_map[i] = -1;
		if (!am->mNumVertices) continue;
		if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) {   /* points and lines (SortByPType split them off) */
			if (api_conv_strokes(c, am, stroke, &meshes[nmesh]) < 0) return -1;
		} else if (convert_mesh(c, am, &meshes[nmesh]) < 0) {
			return -1;
		}
		if (!meshes[nmesh].index_count) continue;
		if (meshes[nmesh].material >= nmat) meshes[nmesh].material = 0;
		warn_missing_uv1(c, am, &meshes[nmesh], &mats[meshes[nmesh].material]);
		c->mesh_map[i] = (int32_t)nmesh++;
	}
	if (!nmesh) return api_err_set(c->err, c->errsize, "the model has no triangles"), -1;
	if (!api_model_meshes_have_area(meshes, nmesh))
		return api_err_set(c->err, c->errsize, "the model's triangles have no area (every one's corners lie on a line "
		               "or a point): nothing would be drawn"), -1;

	float id[16];
	rnd_mat4_identity(id);
	if (sc->mRootNode && walk(c, sc->mRootNode, id, 0) < 0) return -1;
	if (!c->ninst) return api_err_set(c->err, c->errsize, "no node of the model shows a mesh"), -1;
	struct api_model_instance *inst = api_conv_alloc(c, c->ninst, sizeof *inst);
	if (!inst) return api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	memcpy(inst, c->inst, c->ninst * sizeof *inst);
	uint64_t tris = 0;
	for (uint32_t i = 0; i < c->ninst; i++) tris += meshes[inst[i].mesh].index_count / 3;

	m->meshes = meshes;
	m->mesh_count = nmesh;
	m->instances = inst;
	m->instance_count = c->ninst;
	m->materials = mats;
	m->material_count = nmat;
	m->triangles = tris;
	if (c->gi.warnings[0]) {
		size_t n = strlen(c->gi.warnings) + 1;
		char *w = api_conv_alloc(c, n, 1);
		if (!w) return api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;
		memcpy(w, c->gi.warnings, n);
		m->warnings = w;
	}
	return 0;
}


/* A PLY before Assimp reads it: a point cloud is refused saying what it is; triangle strips
 * (Assimp 5.2 reads a strip as one polygon: a flat sliver) and face colours (which it drops)
 * are rewritten into *out (malloc'd, or NULL: read the original; *face_colors for the second).
 * 0, or -1 with err set. */
static int ply_prepare(const uint8_t *data, size_t len, uint8_t **out, size_t *out_len, bool *face_colors, char *err,
                       size_t errsize)
{
	uint64_t points = api_ply_point_cloud(data, len);
	if (points)
		return api_err_set(err, errsize, "the ply has %llu vertices and no faces: it is a point cloud, and point clouds "
		                   "are not drawn (only surfaces are)", (unsigned long long)points), -1;
	*out = api_ply_strips_to_faces(data, len, out_len);
	if (!*out) *face_colors = (*out = api_ply_face_colors_to_vertices(data, len, out_len)) != NULL;
	return 0;
}

enum api_wire_status api_model_import_local(const uint8_t *data, size_t len, enum api_model_format format,
                                            struct api_arena *arena, struct api_model *out, size_t *bytes,
                                            char *err, size_t errsize)
{
	enum api_wire_status st = api_model_import_files(data, len, NULL, 0, format, 0, arena, out, bytes, err, errsize);
	if (st == API_WIRE_OK) api_model_finish_import(out, 0, arena, bytes);
	return st;
}

enum api_wire_status api_model_import_files(const uint8_t *data, size_t len, const struct api_model_file *files,
                                            size_t nfiles, enum api_model_format format, uint32_t output_side,
                                            struct api_arena *arena, struct api_model *out, size_t *bytes, char *err,
                                            size_t errsize)
{
	double t0 = api_clock_ms();
	memset(out, 0, sizeof *out);
	*bytes = 0;
	/* Our own readers first (their NOT_MINE values are all -1): what they leave goes to Assimp */
	int st = API_STL_NOT_MINE;
	if (format == API_MODEL_STL && data) st = api_stl_import_binary(data, len, arena, out, bytes, err, errsize);
	if (format == API_MODEL_OBJ && data)
		st = api_obj_import(data, len, files, nfiles, output_side, arena, out, bytes, err, errsize);
	if (format == API_MODEL_PLY && data) st = api_ply_import(data, len, arena, out, bytes, err, errsize);
	if (st == API_STL_NOT_MINE)
		st = api_model_import_assimp(data, len, files, nfiles, format, output_side, arena, out, bytes, err, errsize);
	out->times.ms[API_IMPORT_PARSE] = (float)(api_clock_ms() - t0) - out->times.ms[API_IMPORT_TEXTURES];
	out->times.imports = 1;
	return (enum api_wire_status)st;
}

/* Why Assimp read nothing (its error string; under import_mu), into err: the status. */
static enum api_wire_status import_error(enum api_model_format format, char *err, size_t errsize)
{
	const char *msg = aiGetErrorString();
	if (msg && strstr(msg, "contains no faces"))   /* ValidateDataStructure's "Mesh  contains no faces" */
		api_err_set(err, errsize, "the %s file has a mesh with no faces (points or lines only): only surfaces are "
		            "drawn, point clouds are not", FORMAT_NAMES[format]);
	else api_err_set(err, errsize, "%s", msg && msg[0] ? msg : "Assimp could not read it");
	/* Assimp turns std::bad_alloc into its error string. */
	return msg && strstr(msg, "bad_alloc") ? API_WIRE_OVER_MEMORY : API_WIRE_BAD_INPUT;
}

/* Assimp's post-processing for a file of this format (indexed: a glTF whose primitives all
 * have indices, api_gltf_all_indexed). */
static unsigned import_flags(enum api_model_format format, bool face_colors, bool indexed)
{
	unsigned flags = aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices |
	                 aiProcess_SortByPType | aiProcess_ValidateDataStructure;
	/* STL facet normals are often wrong (opposite the winding, or zero): flat normals from the
	 * winding instead, as STL viewers shade them. Assimp's join of identical vertices compares
	 * them by searching space (its documentation: senseless with GenNormals) and cost a
	 * 1M-triangle STL ~1 s; convert_mesh joins the corners of coplanar facets by hashing
	 * (join_vertices, 0.25 s), and model_lod.c welds by position where it needs to. */
	if (format == API_MODEL_STL)
		flags = (flags & ~(unsigned)(aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices)) |
		        aiProcess_DropNormals | aiProcess_GenNormals;
	/* Assimp 5.2's join of identical vertices ignores their colours: the corners of a red and a
	 * green face became one vertex. */
	if (face_colors) flags &= ~(unsigned)aiProcess_JoinIdenticalVertices;
	/* Normal maps need tangents: the file's, or made from the uvs where it has none. */
	if (format == API_MODEL_GLB || format == API_MODEL_GLTF) flags |= aiProcess_CalcTangentSpace;
	/* An indexed glTF's vertices are already one per distinct set of attributes: Assimp's join
	 * (a spatial sort of every vertex) found nothing to join in the farm corpus's glbs and was
	 * most of their import (the 100k knot's parse 39-57 -> 15-16 ms, the 1M torus's 540-634 ->
	 * 195-230). A primitive without indices (every corner its own vertex) keeps it. */
	if (indexed) flags &= ~(unsigned)aiProcess_JoinIdenticalVertices;
	return flags;
}

/* A glTF document made readable for Assimp 5.2 (api/gltf_decode.h, api/gltf_instancing.h) and
 * its materials tagged (api/gltf_material.h): *tagged the bytes to import (NULL: the file as
 * it is), b the buffers with what was made, *io_files the files Assimp is served (the
 * made buffer's among them). 0, or -1 with err. */
static int prepare_gltf(json_t *root, const uint8_t *data, size_t len, bool glb, const struct api_model_file *files,
                        size_t nfiles, struct api_conv *c, struct api_gltf_bufs *b, uint8_t **tagged,
                        size_t *tagged_len, const struct api_model_file **io_files, size_t *io_nfiles, char *err,
                        size_t errsize)
{
	api_gltf_bufs_init(b, root, data, len, glb, files, nfiles);
	int dec = api_gltf_decode(b, err, errsize);
	int inst = dec < 0 ? -1 : api_gltf_expand_instancing(b, API_GLTF_MAX_INSTANCES, err, errsize);
	if (inst < 0) return -1;
	if (api_gltf_bufs_finish(b) != 0) return api_err_set(err, errsize, "out of memory"), -1;
	api_gltf_drop_fallbacks(root);
	api_gltf_info_read(root, &c->gi);   /* it warns of the skins before they go */
	api_gltf_ext_images(&c->gi, b);
	bool skins = api_gltf_drop_skins(root);
	bool changed = dec > 0 || inst > 0 || skins;
	/* Materials renamed to their glTF index, to find them again (see gltf_material.h); the
	 * document handed to Assimp also when it was changed here. */
	*tagged = api_gltf_tag_materials(root, data, len, glb, changed, tagged_len);
	if ((!*tagged && changed) || api_gltf_bufs_files(b, io_files, io_nfiles) != 0)
		return api_err_set(err, errsize, "out of memory"), -1;
	return 0;
}

/* Assimp's scene of data[0..len), a file of format beside io_files (what it opens: the model's
 * own file and those it names), or NULL with *st and err saying why. The caller releases the
 * scene (aiReleaseImport, under import_mu). */
static const struct aiScene *assimp_read(const uint8_t *data, size_t len, const struct api_model_file *io_files,
                                         size_t io_nfiles, enum api_model_format format, bool face_colors, bool indexed,
                                         enum api_wire_status *st, char *err, size_t errsize)
{
	struct api_mem_io mi = {.data = data, .len = len, .files = io_files, .nfiles = io_nfiles};
	snprintf(mi.name, sizeof mi.name, MEM_NAME ".%s", FORMAT_NAMES[format]);
	struct aiFileIO io;
	api_mem_io_init(&mi, &io);
	struct aiPropertyStore *props = aiCreatePropertyStore();
	/* SortByPType puts points and lines in meshes of their own: drawn as thin geometry (convert). */
	aiSetImportPropertyInteger(props, AI_CONFIG_IMPORT_NO_SKELETON_MESHES, 1);
	pthread_mutex_lock(&import_mu);   /* Assimp's error string is global: read under the lock */
	const struct aiScene *sc = aiImportFileExWithProperties(mi.name, import_flags(format, face_colors, indexed), &io, props);
	if (!sc) *st = import_error(format, err, errsize);
	pthread_mutex_unlock(&import_mu);
	aiReleasePropertyStore(props);
	return sc;
}

enum api_wire_status api_model_import_assimp(const uint8_t *data, size_t len, const struct api_model_file *files,
                                             size_t nfiles, enum api_model_format format, uint32_t output_side,
                                             struct api_arena *arena, struct api_model *out, size_t *bytes, char *err,
                                             size_t errsize)
{
	memset(out, 0, sizeof *out);
	*bytes = 0;
	if (!data || !len || format < API_MODEL_GLB || format > API_MODEL_PLY)
		return api_err_set(err, errsize, "the model file is empty or of no known format"), API_WIRE_BAD_INPUT;
	out->format = format;
	bool gltf = format == API_MODEL_GLB || format == API_MODEL_GLTF;
	json_t *root = NULL;
	if (gltf && gltf_precheck(data, len, format, &root, err, errsize) < 0) return API_WIRE_BAD_INPUT;
	struct api_conv c = {.arena = arena, .out = out, .err = err, .errsize = errsize, .gltf = gltf,
	                     .join = format == API_MODEL_STL, .texture_side = api_texture_class(output_side)};
	uint8_t *tagged = NULL;
	bool indexed = false;
	struct api_gltf_bufs bufs;
	memset(&bufs, 0, sizeof bufs);
	const struct api_model_file *io_files = files;
	size_t io_nfiles = nfiles;
	if (gltf) {
		size_t tagged_len = 0;
		int rc = prepare_gltf(root, data, len, format == API_MODEL_GLB, files, nfiles, &c, &bufs, &tagged, &tagged_len,
		                      &io_files, &io_nfiles, err, errsize);
		indexed = rc == 0 && api_gltf_all_indexed(root);
		json_decref(root);
		if (rc != 0) {
			bool oom = bufs.oom;   /* a decode over the memory limit, not a bad file */
			free(tagged);
			api_gltf_bufs_release(&bufs);
			api_gltf_info_free(&c.gi);
			return oom ? API_WIRE_OVER_MEMORY : API_WIRE_BAD_INPUT;
		}
		if (tagged) {
			data = tagged;
			len = tagged_len;
		}
	}
	size_t strips_len = 0;
	uint8_t *strips = NULL;
	bool face_colors = false;
	if (format == API_MODEL_PLY && ply_prepare(data, len, &strips, &strips_len, &face_colors, err, errsize) < 0)
		return API_WIRE_BAD_INPUT;
	if (strips) {
		data = strips;
		len = strips_len;
	}
	/* Assimp 5.2's join of identical vertices ignores their colours (import_flags leaves it
	 * out): convert_mesh joins them by position, normal and colour. */
	if (face_colors) c.join = true;
	enum api_wire_status st = API_WIRE_OK;
	const struct aiScene *sc = assimp_read(data, len, io_files, io_nfiles, format, face_colors, indexed, &st, err,
	                                       errsize);
	free(strips);   /* Assimp copied what it needed */
	free(tagged);
	api_gltf_bufs_release(&bufs);
	if (!sc) {
		api_gltf_info_free(&c.gi);
		return st;
	}
	c.sc = sc;
	c.files = files;
	c.nfiles = nfiles;
	int rc = convert(&c);
	out->texture_side = c.texture_side;
	out->texture_max = c.texture_max;
	out->times.ms[API_IMPORT_TEXTURES] = (float)c.texture_ms;
	api_gltf_info_free(&c.gi);
	free(c.mesh_map);
	free(c.tex);
	free(c.inst);
	pthread_mutex_lock(&import_mu);
	aiReleaseImport(sc);
	pthread_mutex_unlock(&import_mu);
	if (rc < 0) return c.oom ? API_WIRE_OVER_MEMORY : API_WIRE_BAD_INPUT;
	*bytes = c.bytes;
	return API_WIRE_OK;
}
