/*
 * api/model — model import through the Assimp C API, and the process-wide LRU cache of
 * imported models (see model.h).
 *
 * Import: Assimp reads the bytes through an aiFileIO that serves only those bytes, so a file
 * that refers to others (an .obj's mtllib, a .gltf's external buffer or image) can never make
 * the service read from its disk: such references fail or are ignored, as Assimp decides. The
 * node tree is walked with every node's transform (Assimp's aiMatrix4x4 is row-major; ours are
 * column-major), each (node, mesh) pair becoming one instance; meshes keep triangles only.
 * Everything a model holds lives in one arena that dies with the last reference.
 *
 * Cache: a doubly linked LRU list under one mutex, looked up by a 64-bit FNV-1a hash of the
 * bytes and the format and confirmed with memcmp against a copy of the bytes, so a hash
 * collision can never hand one caller another caller's model. The cache holds one reference to
 * each entry it lists; scenes hold their own, so eviction never frees a model in use.
 */
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
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
#include "arena.h"
#include "model.h"
#include "umbra/rnd_math.h"

#define MAX_NODE_DEPTH 256
#define MAX_TEXTURE_PIXELS (64ull << 20)

struct model_priv {
	struct api_model pub;
	atomic_uint refs;
	struct api_arena *arena;
	/* cache key, and the bytes that confirm it (NULL while not cached) */
	uint64_t hash;
	uint8_t *src;
	size_t src_len;
	struct model_priv *prev, *next;
	bool listed;
};

static pthread_mutex_t cache_mu = PTHREAD_MUTEX_INITIALIZER;
static struct model_priv *lru_head, *lru_tail; /* head = most recently used */
static uint64_t cache_total, cache_hits, cache_misses;
/* Assimp's C API keeps the last error in one global std::string: imports take turns. */
static pthread_mutex_t import_mu = PTHREAD_MUTEX_INITIALIZER;

static const char *const FORMAT_NAMES[] = {"glb", "gltf", "obj", "stl", "ply"};

const char *api_model_format_name(enum api_model_format f)
{
	return f >= API_MODEL_GLB && f <= API_MODEL_PLY ? FORMAT_NAMES[f] : "unknown";
}

static enum api_result err_set(char *err, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static enum api_result err_set(char *err, size_t n, const char *fmt, ...)
{
	if (err && n) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(err, n, fmt, ap);
		va_end(ap);
	}
	return API_ERR;
}

/* ---- format sniffing ---- */

static bool starts_with_word(const uint8_t *d, size_t len, const char *w)
{
	size_t n = strlen(w);
	return len > n && !memcmp(d, w, n) && (d[n] == ' ' || d[n] == '\t' || d[n] == '\r' || d[n] == '\n');
}

enum api_model_format api_model_sniff(const uint8_t *d, size_t len)
{
	if (!d || !len) return API_MODEL_SNIFF;
	if (len >= 12 && !memcmp(d, "glTF", 4)) return API_MODEL_GLB;
	if (len >= 4 && !memcmp(d, "ply", 3) && (d[3] == '\n' || d[3] == '\r')) return API_MODEL_PLY;
	/* Binary STL: an 80-byte header, a triangle count, 50 bytes per triangle. Checked before
	 * ASCII STL because many binary headers also start with "solid". */
	if (len >= 84) {
		uint32_t n = (uint32_t)d[80] | (uint32_t)d[81] << 8 | (uint32_t)d[82] << 16 | (uint32_t)d[83] << 24;
		if ((uint64_t)n * 50 + 84 == len) return API_MODEL_STL;
	}
	size_t i = 0;
	if (len >= 3 && d[0] == 0xef && d[1] == 0xbb && d[2] == 0xbf) i = 3; /* UTF-8 BOM */
	while (i < len && (d[i] == ' ' || d[i] == '\t' || d[i] == '\r' || d[i] == '\n')) i++;
	if (i < len && d[i] == '{') return API_MODEL_GLTF;
	if (starts_with_word(d + i, len - i, "solid")) return API_MODEL_STL;
	/* OBJ: text whose statements are OBJ keywords; one vertex or face line settles it. */
	static const char *const kw[] = {"v", "vn", "vt", "f", "o", "g", "s", "mtllib", "usemtl", NULL};
	size_t scan = len < 65536 ? len : 65536;
	for (size_t p = i; p < scan;) {
		size_t e = p;
		while (e < scan && d[e] != '\n') e++;
		if (d[p] != '#' && d[p] != '\r' && d[p] != '\n') {
			bool known = false;
			for (int k = 0; kw[k] && !known; k++) known = starts_with_word(d + p, e - p + (e < scan), kw[k]);
			if (!known) break;
			if (d[p] == 'v' || d[p] == 'f') return API_MODEL_OBJ;
		}
		p = e + 1;
	}
	return API_MODEL_SNIFF;
}

/* ---- glTF checks Assimp 5.2 lacks ---- */

/* Assimp 5.2's glTF2 importer crashes on some malformed documents (an image whose mimeType is
 * neither PNG nor JPEG dereferences NULL). What it does not check, we check first: the JSON
 * chunk is a JSON object, and every image's mimeType (and data: URI type) is PNG or JPEG. */
static bool image_type_ok(const char *t, size_t n)
{
	return (n == 9 && !memcmp(t, "image/png", 9)) || (n == 10 && !memcmp(t, "image/jpeg", 10));
}

static int gltf_precheck(const uint8_t *d, size_t len, enum api_model_format f, char *err, size_t errsize)
{
	const char *json = (const char *)d;
	size_t jlen = len;
	if (f == API_MODEL_GLB) {
		if (len < 20 || memcmp(d + 16, "JSON", 4))
			return err_set(err, errsize, "the glb has no JSON chunk"), -1;
		uint32_t n = (uint32_t)d[12] | (uint32_t)d[13] << 8 | (uint32_t)d[14] << 16 | (uint32_t)d[15] << 24;
		if (n > len - 20) return err_set(err, errsize, "the glb's JSON chunk is longer than the file"), -1;
		json = (const char *)d + 20;
		jlen = n;
	}
	json_error_t je;
	json_t *root = json_loadb(json, jlen, 0, &je);
	if (!json_is_object(root)) {
		json_decref(root);
		return err_set(err, errsize, "the glTF JSON is malformed (line %d: %s)", je.line,
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
	json_decref(root);
	if (rc) return err_set(err, errsize, "glTF image %zu is not a PNG or JPEG image (mimeType)", i), -1;
	return 0;
}

/* ---- an aiFileIO that serves one buffer and nothing else ---- */

#define MEM_NAME "model"

struct mem_io {
	const uint8_t *data;
	size_t len;
	char name[32];
};

struct mem_file {
	struct aiFile f;
	const uint8_t *data;
	size_t len, pos;
};

static size_t mem_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
	struct mem_file *m = (struct mem_file *)f->UserData;
	if (!size || !count) return 0;
	size_t avail = m->len - m->pos, want = count;
	if (want > avail / size) want = avail / size;
	memcpy(buf, m->data + m->pos, want * size);
	m->pos += want * size;
	return want;
}

static size_t mem_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
	(void)f, (void)buf, (void)size, (void)count;
	return 0;
}

static size_t mem_tell(struct aiFile *f)
{
	return ((struct mem_file *)f->UserData)->pos;
}

static size_t mem_size(struct aiFile *f)
{
	return ((struct mem_file *)f->UserData)->len;
}

static void mem_flush(struct aiFile *f)
{
	(void)f;
}

static enum aiReturn mem_seek(struct aiFile *f, size_t off, enum aiOrigin origin)
{
	struct mem_file *m = (struct mem_file *)f->UserData;
	size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? m->pos : m->len;
	if (off > m->len - base) return aiReturn_FAILURE;
	m->pos = base + off;
	return aiReturn_SUCCESS;
}

static struct aiFile *mem_open(struct aiFileIO *io, const char *name, const char *mode)
{
	struct mem_io *mi = (struct mem_io *)io->UserData;
	/* Only the model itself, read-only; Assimp may prefix a directory ("./"). */
	const char *base = strrchr(name, '/');
	base = base ? base + 1 : name;
	if (strcmp(base, mi->name) || (mode && strchr(mode, 'w'))) return NULL;
	struct mem_file *m = calloc(1, sizeof *m);
	if (!m) return NULL;
	m->data = mi->data;
	m->len = mi->len;
	m->f.ReadProc = mem_read;
	m->f.WriteProc = mem_write;
	m->f.TellProc = mem_tell;
	m->f.FileSizeProc = mem_size;
	m->f.SeekProc = mem_seek;
	m->f.FlushProc = mem_flush;
	m->f.UserData = (aiUserData)m;
	return &m->f;
}

static void mem_close(struct aiFileIO *io, struct aiFile *f)
{
	(void)io;
	if (f) free(f->UserData);
}

/* ---- conversion of an aiScene ---- */

struct conv {
	const struct aiScene *sc;
	struct model_priv *m;
	size_t bytes;
	int32_t *mesh_map;            /* Assimp mesh -> our mesh, -1 = skipped (not triangles) */
	struct rnd_texture **tex;     /* decoded embedded textures, by scene->mTextures index */
	struct api_model_instance *inst;
	uint32_t ninst, inst_cap;
	char *err;
	size_t errsize;
};

static void *conv_alloc(struct conv *c, size_t n, size_t size)
{
	void *p = api_arena_calloc(c->m->arena, n ? n : 1, size);
	if (p) c->bytes += n * size;
	return p;
}

/* aiMatrix4x4 is row-major (a1..a4 the first row, a4/b4/c4 the translation). */
static void mat_from_ai(float out[16], const struct aiMatrix4x4 *a)
{
	const float r[16] = {a->a1, a->a2, a->a3, a->a4, a->b1, a->b2, a->b3, a->b4,
	                     a->c1, a->c2, a->c3, a->c4, a->d1, a->d2, a->d3, a->d4};
	for (int row = 0; row < 4; row++)
		for (int col = 0; col < 4; col++) out[col * 4 + row] = r[row * 4 + col];
}

static int convert_mesh(struct conv *c, const struct aiMesh *am, struct api_model_mesh *out)
{
	uint32_t nv = am->mNumVertices, ntri = 0;
	for (unsigned f = 0; f < am->mNumFaces; f++) ntri += am->mFaces[f].mNumIndices == 3;
	float *pos = conv_alloc(c, nv, 3 * sizeof(float));
	float *nrm = am->mNormals ? conv_alloc(c, nv, 3 * sizeof(float)) : NULL;
	float *uv = am->mTextureCoords[0] ? conv_alloc(c, nv, 2 * sizeof(float)) : NULL;
	uint32_t *idx = (uint64_t)ntri * 3 <= UINT32_MAX ? conv_alloc(c, (size_t)ntri * 3, sizeof(uint32_t)) : NULL;
	if (!pos || (am->mNormals && !nrm) || (am->mTextureCoords[0] && !uv) || !idx)
		return err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	for (uint32_t v = 0; v < nv; v++) {
		const struct aiVector3D *p = &am->mVertices[v];
		if (!isfinite(p->x) || !isfinite(p->y) || !isfinite(p->z))
			return err_set(c->err, c->errsize, "mesh \"%.64s\": vertex %u is not a finite position",
			               am->mName.data, v), -1;
		pos[3 * v] = p->x; pos[3 * v + 1] = p->y; pos[3 * v + 2] = p->z;
		if (nrm) {
			const struct aiVector3D *n = &am->mNormals[v];
			bool ok = isfinite(n->x) && isfinite(n->y) && isfinite(n->z);
			/* Degenerate faces leave NaN normals behind; any direction will do for them. */
			nrm[3 * v] = ok ? n->x : 0; nrm[3 * v + 1] = ok ? n->y : 1; nrm[3 * v + 2] = ok ? n->z : 0;
		}
		if (uv) {
			/* Assimp puts v = 0 at the bottom (OpenGL); glTF and our textures at the top. */
			const struct aiVector3D *t = &am->mTextureCoords[0][v];
			uv[2 * v] = isfinite(t->x) ? t->x : 0;
			uv[2 * v + 1] = isfinite(t->y) ? 1.0f - t->y : 0;
		}
	}
	uint32_t k = 0;
	for (unsigned f = 0; f < am->mNumFaces; f++) {
		const struct aiFace *face = &am->mFaces[f];
		if (face->mNumIndices != 3) continue;
		for (int j = 0; j < 3; j++) {
			if (face->mIndices[j] >= nv)
				return err_set(c->err, c->errsize, "mesh \"%.64s\": face %u refers to vertex %u of %u",
				               am->mName.data, f, face->mIndices[j], nv), -1;
			idx[k++] = face->mIndices[j];
		}
	}
	out->positions = pos;
	out->normals = nrm;
	out->uvs = uv;
	out->indices = idx;
	out->vertex_count = nv;
	out->index_count = k;
	out->material = am->mMaterialIndex;
	return 0;
}

static float clampf(float v, float lo, float hi)
{
	return !(v >= lo) ? lo : v > hi ? hi : v;  /* NaN -> lo */
}

/* The embedded texture that `path` names ("*N" or the embedded file's name), or NULL. */
static int find_texture(const struct aiScene *sc, const char *path)
{
	if (path[0] == '*') {
		char *end;
		unsigned long n = strtoul(path + 1, &end, 10);
		if (*end || end == path + 1 || n >= sc->mNumTextures) return -1;
		return (int)n;
	}
	for (unsigned i = 0; i < sc->mNumTextures; i++) {
		const char *fn = sc->mTextures[i]->mFilename.data;
		if (fn[0] && !strcmp(fn, path)) return (int)i;
	}
	return -1;
}

static const struct rnd_texture *texture(struct conv *c, int ti)
{
	if (c->tex[ti]) return c->tex[ti];
	const struct aiTexture *at = c->sc->mTextures[ti];
	struct rnd_texture *t = conv_alloc(c, 1, sizeof *t);
	if (!t) return err_set(c->err, c->errsize, "out of memory importing the model"), NULL;
	if (at->mHeight == 0) {
		/* Compressed: mWidth bytes of a PNG or JPEG file. */
		uint8_t *px;
		uint32_t w, h;
		char e[200];
		if (api_image_decode((const uint8_t *)at->pcData, at->mWidth, MAX_TEXTURE_PIXELS, &px, &w, &h, e,
		                     sizeof e) != API_OK)
			return err_set(c->err, c->errsize, "embedded texture %d: %s", ti, e), NULL;
		uint8_t *copy = conv_alloc(c, (size_t)w * h, 4);
		if (copy) memcpy(copy, px, (size_t)w * h * 4);
		free(px);
		if (!copy) return err_set(c->err, c->errsize, "out of memory importing the model"), NULL;
		t->rgba = copy;
		t->width = w;
		t->height = h;
	} else {
		uint64_t n = (uint64_t)at->mWidth * at->mHeight;
		if (n > MAX_TEXTURE_PIXELS)
			return err_set(c->err, c->errsize, "embedded texture %d is over the texture size limit", ti), NULL;
		uint8_t *px = conv_alloc(c, (size_t)n, 4);
		if (!px) return err_set(c->err, c->errsize, "out of memory importing the model"), NULL;
		for (size_t i = 0; i < n; i++) { /* aiTexel is BGRA */
			px[4 * i] = at->pcData[i].r;
			px[4 * i + 1] = at->pcData[i].g;
			px[4 * i + 2] = at->pcData[i].b;
			px[4 * i + 3] = at->pcData[i].a;
		}
		t->rgba = px;
		t->width = at->mWidth;
		t->height = at->mHeight;
	}
	c->tex[ti] = t;
	return t;
}

static int convert_material(struct conv *c, const struct aiMaterial *am, struct rnd_material *m)
{
	rnd_material_defaults(m);
	struct aiString s;
	/* Formats without materials (stl, ply, obj without mtl) get Assimp's default material:
	 * the contract's default grey stands in for it, as for every other shape. */
	if (aiGetMaterialString(am, AI_MATKEY_NAME, &s) == aiReturn_SUCCESS && !strcmp(s.data, AI_DEFAULT_MATERIAL_NAME))
		return 0;
	struct aiColor4D col;
	if (aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &col) == aiReturn_SUCCESS ||
	    aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &col) == aiReturn_SUCCESS) {
		m->base_color[0] = clampf(col.r, 0, 1e6f);
		m->base_color[1] = clampf(col.g, 0, 1e6f);
		m->base_color[2] = clampf(col.b, 0, 1e6f);
		m->base_color[3] = clampf(col.a, 0, 1);
	}
	ai_real f;
	if (aiGetMaterialFloatArray(am, AI_MATKEY_METALLIC_FACTOR, &f, NULL) == aiReturn_SUCCESS)
		m->metallic = clampf(f, 0, 1);
	if (aiGetMaterialFloatArray(am, AI_MATKEY_ROUGHNESS_FACTOR, &f, NULL) == aiReturn_SUCCESS)
		m->roughness = clampf(f, 0, 1);
	if (aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &col) == aiReturn_SUCCESS) {
		m->emissive[0] = clampf(col.r, 0, 1e6f);
		m->emissive[1] = clampf(col.g, 0, 1e6f);
		m->emissive[2] = clampf(col.b, 0, 1e6f);
	}
	if (aiGetMaterialString(am, "$mat.gltf.alphaMode", 0, 0, &s) == aiReturn_SUCCESS && !strcmp(s.data, "MASK")) {
		m->alpha_mode = RND_ALPHA_MASK;
		if (aiGetMaterialFloatArray(am, "$mat.gltf.alphaCutoff", 0, 0, &f, NULL) == aiReturn_SUCCESS)
			m->alpha_cutoff = clampf(f, 0, 1);
	}
	/* BLEND has no counterpart in the renderer: drawn opaque. */
	static const enum aiTextureType types[] = {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE};
	for (int i = 0; i < 2; i++) {
		if (aiGetMaterialTexture(am, types[i], 0, &s, NULL, NULL, NULL, NULL, NULL, NULL) != aiReturn_SUCCESS)
			continue;
		int ti = find_texture(c->sc, s.data);
		/* A texture in another file is not reachable from a self-contained model: ignored. */
		if (ti < 0) break;
		if (!(m->base_color_texture = texture(c, ti))) return -1;
		break;
	}
	return 0;
}

static int walk(struct conv *c, const struct aiNode *node, const float parent[16], int depth)
{
	if (depth > MAX_NODE_DEPTH)
		return err_set(c->err, c->errsize, "the node tree is deeper than %d levels", MAX_NODE_DEPTH), -1;
	float local[16], global[16];
	mat_from_ai(local, &node->mTransformation);
	rnd_mat4_mul(global, parent, local);
	for (int i = 0; i < 16; i++)
		if (!isfinite(global[i]))
			return err_set(c->err, c->errsize, "node \"%.64s\" has a transform that is not finite",
			               node->mName.data), -1;
	for (unsigned i = 0; i < node->mNumMeshes; i++) {
		unsigned mi = node->mMeshes[i];
		if (mi >= c->sc->mNumMeshes || c->mesh_map[mi] < 0) continue;
		if (c->ninst == c->inst_cap) {
			uint32_t cap = c->inst_cap ? c->inst_cap * 2 : 16;
			struct api_model_instance *n = realloc(c->inst, cap * sizeof *n);
			if (!n || cap < c->inst_cap) return err_set(c->err, c->errsize, "out of memory importing the model"), -1;
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

static int convert(struct conv *c)
{
	const struct aiScene *sc = c->sc;
	struct model_priv *m = c->m;
	c->mesh_map = calloc(sc->mNumMeshes ? sc->mNumMeshes : 1, sizeof *c->mesh_map);
	c->tex = calloc(sc->mNumTextures ? sc->mNumTextures : 1, sizeof *c->tex);
	if (!c->mesh_map || !c->tex) return err_set(c->err, c->errsize, "out of memory importing the model"), -1;

	uint32_t nmat = sc->mNumMaterials ? sc->mNumMaterials : 1;
	struct rnd_material *mats = conv_alloc(c, nmat, sizeof *mats);
	if (!mats) return err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	rnd_material_defaults(&mats[0]);
	for (unsigned i = 0; i < sc->mNumMaterials; i++)
		if (convert_material(c, sc->mMaterials[i], &mats[i]) < 0) return -1;

	struct api_model_mesh *meshes = conv_alloc(c, sc->mNumMeshes, sizeof *meshes);
	if (!meshes) return err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	uint32_t nmesh = 0;
	for (unsigned i = 0; i < sc->mNumMeshes; i++) {
		const struct aiMesh *am = sc->mMeshes[i];
		c->mesh_map[i] = -1;
		if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || !am->mNumVertices) continue;
		if (convert_mesh(c, am, &meshes[nmesh]) < 0) return -1;
		if (!meshes[nmesh].index_count) continue;
		if (meshes[nmesh].material >= nmat) meshes[nmesh].material = 0;
		c->mesh_map[i] = (int32_t)nmesh++;
	}
	if (!nmesh) return err_set(c->err, c->errsize, "the model has no triangles"), -1;

	float id[16];
	rnd_mat4_identity(id);
	if (sc->mRootNode && walk(c, sc->mRootNode, id, 0) < 0) return -1;
	if (!c->ninst) return err_set(c->err, c->errsize, "no node of the model shows a mesh"), -1;
	struct api_model_instance *inst = conv_alloc(c, c->ninst, sizeof *inst);
	if (!inst) return err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	memcpy(inst, c->inst, c->ninst * sizeof *inst);
	uint64_t tris = 0;
	for (uint32_t i = 0; i < c->ninst; i++) tris += meshes[inst[i].mesh].index_count / 3;

	m->pub.meshes = meshes;
	m->pub.mesh_count = nmesh;
	m->pub.instances = inst;
	m->pub.instance_count = c->ninst;
	m->pub.materials = mats;
	m->pub.material_count = nmat;
	m->pub.triangles = tris;
	return 0;
}

static void model_free(struct model_priv *m)
{
	if (!m) return;
	api_arena_destroy(m->arena);
	free(m->src);
	free(m);
}

static struct model_priv *import(const uint8_t *data, size_t len, enum api_model_format format, char *err,
                                 size_t errsize)
{
	struct model_priv *m = calloc(1, sizeof *m);
	if (!m || !(m->arena = api_arena_create())) {
		free(m);
		err_set(err, errsize, "out of memory importing the model");
		return NULL;
	}
	atomic_init(&m->refs, 1);
	m->pub.format = format;
	m->pub.priv_ = m;

	if ((format == API_MODEL_GLB || format == API_MODEL_GLTF) && gltf_precheck(data, len, format, err, errsize) < 0) {
		model_free(m);
		return NULL;
	}
	struct mem_io mi = {.data = data, .len = len};
	snprintf(mi.name, sizeof mi.name, MEM_NAME ".%s", FORMAT_NAMES[format]);
	struct aiFileIO io = {.OpenProc = mem_open, .CloseProc = mem_close, .UserData = (aiUserData)&mi};
	struct aiPropertyStore *props = aiCreatePropertyStore();
	/* Points and lines are dropped by SortByPType: only triangles reach us. */
	aiSetImportPropertyInteger(props, AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
	aiSetImportPropertyInteger(props, AI_CONFIG_IMPORT_NO_SKELETON_MESHES, 1);
	unsigned flags = aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices |
	                 aiProcess_SortByPType | aiProcess_ValidateDataStructure;
	pthread_mutex_lock(&import_mu);
	const struct aiScene *sc = aiImportFileExWithProperties(mi.name, flags, &io, props);
	if (!sc) {
		const char *msg = aiGetErrorString();
		err_set(err, errsize, "%s", msg && msg[0] ? msg : "Assimp could not read it");
	}
	pthread_mutex_unlock(&import_mu);
	aiReleasePropertyStore(props);
	if (!sc) {
		model_free(m);
		return NULL;
	}

	struct conv c = {.sc = sc, .m = m, .err = err, .errsize = errsize};
	int rc = convert(&c);
	free(c.mesh_map);
	free(c.tex);
	free(c.inst);
	pthread_mutex_lock(&import_mu);
	aiReleaseImport(sc);
	pthread_mutex_unlock(&import_mu);
	if (rc < 0) {
		model_free(m);
		return NULL;
	}
	m->pub.bytes_ = c.bytes + sizeof *m;
	return m;
}

/* ---- cache ---- */

static uint64_t fnv1a(const uint8_t *d, size_t n, uint64_t h)
{
	for (size_t i = 0; i < n; i++) {
		h ^= d[i];
		h *= 0x100000001b3ull;
	}
	return h;
}

/* With cache_mu held. */
static void lru_unlink(struct model_priv *m)
{
	if (m->prev) m->prev->next = m->next; else lru_head = m->next;
	if (m->next) m->next->prev = m->prev; else lru_tail = m->prev;
	m->prev = m->next = NULL;
	m->listed = false;
	cache_total -= m->pub.bytes_;
}

static void lru_push_front(struct model_priv *m)
{
	m->prev = NULL;
	m->next = lru_head;
	if (lru_head) lru_head->prev = m; else lru_tail = m;
	lru_head = m;
	m->listed = true;
	cache_total += m->pub.bytes_;
}

static struct model_priv *lru_find(uint64_t h, const uint8_t *data, size_t len, enum api_model_format f)
{
	for (struct model_priv *m = lru_head; m; m = m->next)
		if (m->hash == h && m->src_len == len && m->pub.format == f && !memcmp(m->src, data, len)) return m;
	return NULL;
}

void api_model_release(struct api_model *pub)
{
	if (!pub) return;
	struct model_priv *m = pub->priv_;
	if (atomic_fetch_sub(&m->refs, 1) == 1) model_free(m);
}

enum api_result api_model_get(const uint8_t *data, size_t len, enum api_model_format format, uint64_t cache_bytes,
                              struct api_model **out, char *err, size_t errsize)
{
	*out = NULL;
	if (!data || !len) return err_set(err, errsize, "the model file is empty");
	if (format == API_MODEL_SNIFF) format = api_model_sniff(data, len);
	if (format < API_MODEL_GLB || format > API_MODEL_PLY)
		return err_set(err, errsize, "the file is not a recognisable glb, gltf, obj, stl or ply model "
		               "(give format to say which)");
	uint64_t h = fnv1a(data, len, 0xcbf29ce484222325ull ^ (uint64_t)format);

	pthread_mutex_lock(&cache_mu);
	struct model_priv *hit = lru_find(h, data, len, format);
	if (hit) {
		cache_hits++;
		lru_unlink(hit);
		lru_push_front(hit);
		atomic_fetch_add(&hit->refs, 1);
	} else {
		cache_misses++;
	}
	pthread_mutex_unlock(&cache_mu);
	if (hit) {
		*out = &hit->pub;
		return API_OK;
	}

	struct model_priv *m = import(data, len, format, err, errsize);
	if (!m) return API_ERR;
	uint64_t cost = m->pub.bytes_ + len;
	if (!cache_bytes || cost > cache_bytes || !(m->src = malloc(len))) {
		*out = &m->pub;    /* not cached: the caller's reference is the only one */
		return API_OK;
	}
	memcpy(m->src, data, len);
	m->src_len = len;
	m->hash = h;
	m->pub.bytes_ = cost;

	struct model_priv *evicted = NULL;
	pthread_mutex_lock(&cache_mu);
	/* Another request may have imported the same bytes meanwhile: use the listed one. */
	struct model_priv *dup = lru_find(h, data, len, format);
	if (dup) {
		atomic_fetch_add(&dup->refs, 1);
	} else {
		lru_push_front(m);
		atomic_fetch_add(&m->refs, 1); /* the cache's reference */
		while (cache_total > cache_bytes && lru_tail != m) {
			struct model_priv *t = lru_tail;
			lru_unlink(t);
			t->next = evicted; /* released outside the lock */
			evicted = t;
		}
	}
	pthread_mutex_unlock(&cache_mu);
	while (evicted) {
		struct model_priv *n = evicted->next;
		evicted->next = NULL;
		api_model_release(&evicted->pub);
		evicted = n;
	}
	if (dup) {
		api_model_release(&m->pub);
		m = dup;
	}
	*out = &m->pub;
	return API_OK;
}

void api_model_cache_stats(uint64_t *hits, uint64_t *misses, uint64_t *bytes)
{
	pthread_mutex_lock(&cache_mu);
	if (hits) *hits = cache_hits;
	if (misses) *misses = cache_misses;
	if (bytes) *bytes = cache_total;
	pthread_mutex_unlock(&cache_mu);
}

void api_model_cache_clear(void)
{
	pthread_mutex_lock(&cache_mu);
	struct model_priv *list = NULL;
	while (lru_head) {
		struct model_priv *t = lru_head;
		lru_unlink(t);
		t->next = list;
		list = t;
	}
	pthread_mutex_unlock(&cache_mu);
	while (list) {
		struct model_priv *n = list->next;
		list->next = NULL;
		api_model_release(&list->pub);
		list = n;
	}
}
