/*
 * api/obj_import.c — OBJ without Assimp (see obj_import.h).
 *
 * Assimp 5.2 reads an OBJ line by line (ObjFileParser), keeps each face corner as a vertex of
 * its own (ObjFileImporter), then triangulates, makes smooth normals and joins identical
 * vertices (api/assimp_post.h does those the same way). For a 100k-triangle file that took
 * ~120 ms of CPU; most of it the parser's per-line buffers and post-processing's spatial sorts.
 * This reads the same lines into the same meshes: a mesh per `o` and per change of `g` (Assimp
 * maps groups to objects), numbers read as Assimp's fast_atof reads them, face indices
 * 1-based or relative, positional (a face's third texture index is its third corner's, even
 * when the first corners have none), texture indices taken for normals in a face like
 * "1/2" once normals and no texture coordinates have been read (Assimp's rule), corners without
 * an index getting zeros, and a mesh's normals or uvs dropped when an index is out of range.
 * Without materials the material is Assimp's default one.
 *
 * With materials (an mtllib or usemtl line) which faces make which mesh, and with which
 * material, follows rules of Assimp's that depend on the .mtl's contents (a library read
 * makes its last material current and may re-point the current mesh; a usemtl of an unknown
 * name makes a material; a mesh splits only when it has faces). Rather than copy them, Assimp
 * reads a skeleton of the file: its o, g, usemtl and mtllib lines as they are and one small
 * triangle per run of faces between them (three vertices of their own, x = the run's number).
 * Its meshes (the runs each holds, read back from the triangles' x, in order), their
 * materials, the materials themselves with their textures, the nodes and the warnings are
 * the model's; the meshes' faces are made here. The skeleton is a few hundred bytes for a
 * typical file, so Assimp's cost is its materials' and textures'.
 *
 * Left to Assimp, for its behaviour and its messages: faces of other than 3 or 4 corners
 * (its triangulation of polygons is its own), points and lines, vertices with colours or a
 * w, curves, line continuations, an `o` naming an earlier object, numbers not written plainly
 * (no digit first, a comma, nan, inf, no exponent digits), values past 1e18, out-of-range
 * vertex indices, more than 4M runs of faces, a file of no triangle with an area, and anything
 * else odd. A skeleton Assimp refuses is the file's refusal, with Assimp's message: it holds the
 * file's o, g, usemtl and mtllib lines as they are, and every other line was read here (what
 * Assimp refuses in it is a material's, such as a texture it cannot decode); Assimp is not run a
 * second time on the whole file only to refuse it again.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "assimp_post.h"
#include "errmsg.h"
#include "model_import.h"
#include "model_wire.h"
#include "obj_import.h"
#include "umbra/rnd_math.h"

#define NOT_MINE API_OBJ_NOT_MINE
#define NO_MEMORY (-3)   /* (not NOT_MINE, nor API_ASSIMP_POST_GIVE_UP) */

/* A growing array of floats, n a count of `width`-float items. */
struct floats {
	float *p;
	size_t n, cap;
};

static bool floats_push(struct floats *a, const float *v, int width)
{
	if (a->n == a->cap) {
		size_t cap = a->cap ? 2 * a->cap : 1024;
		float *p = realloc(a->p, cap * (size_t)width * sizeof *p);
		if (!p) return false;
		a->p = p;
		a->cap = cap;
	}
	memcpy(a->p + a->n++ * (size_t)width, v, (size_t)width * sizeof *v);
	return true;
}

/* One face: up to 4 corners' vertex, texture and normal indices (0-based, as Assimp stores
 * them: unsigned, so a relative index before the start wraps), positionally. */
struct face {
	uint32_t v[4], t[4], n[4];
	uint8_t nv, nt, nn;
};

struct faces {
	struct face *p;
	size_t n, cap;
};

/* Faces [first, end). Without materials a mesh's faces are one span (a new object starts a new
 * mesh, and nothing goes back to an earlier one); with them, the spans Assimp put together. */
struct span {
	size_t first, end;
};

/* The file's structure for Assimp when it has materials (see build_skeleton): its o, g,
 * usemtl and mtllib lines as they are, and one face in place of each run of faces. */
struct skeleton {
	char *p;
	size_t n, cap;
	struct span *run;
	size_t nrun, runcap;
	bool in_run;
	bool materials;             /* an mtllib or usemtl line */
};

struct parse {
	struct floats v, vt, vn;
	struct faces f;
	struct span *m;             /* a mesh an object */
	size_t nm, mcap;
	bool current;               /* an object (and its mesh) exists */
	const char *group;          /* the active group's name (in the file; "" at first) */
	size_t group_len;
	const char **obj_name;      /* each object's name (an `o` searches them), by mesh */
	size_t *obj_len;
	struct skeleton sk;
};

static void parse_free(struct parse *p)
{
	free(p->v.p);
	free(p->vt.p);
	free(p->vn.p);
	free(p->f.p);
	free(p->m);
	free(p->obj_name);
	free(p->obj_len);
	free(p->sk.p);
	free(p->sk.run);
}

static bool blank(char c)
{
	return c == ' ' || c == '\t';
}

/* Numbers of a v / vt / vn line from s[0..n) (after the keyword): exactly `want` of them (or
 * want - 1 when may_short: a vt of two), each finite and within 1e18, blanks between and after.
 * How many, or -1. */
static int numbers(const char *s, size_t n, float *out, int want, bool may_short)
{
	size_t i = 0;
	int k = 0;
	for (;;) {
		size_t b = i;
		while (i < n && blank(s[i])) i++;
		if (i == n) break;
		if (i == b || k == want) return -1;
		size_t used = api_assimp_atof(s + i, n - i, &out[k]);
		if (!used || (i + used < n && !blank(s[i + used])) || !(fabsf(out[k]) <= 1e18f)) return -1;
		i += used;
		k++;
	}
	return k == want || (may_short && k == want - 1) ? k : -1;
}

/* A face index: -?[1-9][0-9]* within int. Its value, 0 when it is not one. */
static long face_index(const char *s, size_t n, size_t *used)
{
	size_t i = s[0] == '-';
	if (i >= n || s[i] < '1' || s[i] > '9') return 0;
	long v = 0;
	for (; i < n && s[i] >= '0' && s[i] <= '9'; i++)
		if ((v = v * 10 + (s[i] - '0')) > 0x7fffffff) return 0;
	*used = i;
	return s[0] == '-' ? -v : v;
}

/* A face line's corners (after "f"), as ObjFileParser::getFace reads them. false: not mine. */
static bool face_line(struct parse *p, const char *s, size_t n, struct face *f)
{
	memset(f, 0, sizeof *f);
	/* Assimp reads "1/2" as vertex/normal when normals and no texture coordinates have been
	 * read so far */
	bool vt = p->vt.n != 0, vn = p->vn.n != 0;
	size_t i = 0;
	int pos = 0;
	while (i < n) {
		if (blank(s[i])) { pos = 0; i++; continue; }
		if (s[i] == '/') {
			if (++pos > 2) return false;
			i++;
			continue;
		}
		size_t used = 0;
		long v = face_index(s + i, n - i, &used);
		if (!v || (i + used < n && !blank(s[i + used]) && s[i + used] != '/')) return false;
		i += used;
		if (pos == 1 && !vt && vn) pos = 2;   /* (a '/' after it makes it 3: refused) */
		int at = pos;
		/* relative: from the count so far (Assimp's int arithmetic, stored unsigned) */
		size_t count = at == 0 ? p->v.n : at == 1 ? p->vt.n : p->vn.n;
		uint32_t idx = v > 0 ? (uint32_t)(v - 1) : (uint32_t)((long)count + v);
		uint8_t *k = at == 0 ? &f->nv : at == 1 ? &f->nt : &f->nn;
		uint32_t *slot = at == 0 ? f->v : at == 1 ? f->t : f->n;
		if (*k == 4) return false;
		slot[(*k)++] = idx;
	}
	return (f->nv == 3 || f->nv == 4) && f->nt <= f->nv && f->nn <= f->nv;
}

/* Assimp's createObject: a new object named s[0..n) (in the file, or static) and its mesh. */
static bool new_object(struct parse *p, const char *s, size_t n)
{
	if (p->nm == p->mcap) {
		size_t cap = p->mcap ? 2 * p->mcap : 8;
		struct span *m = realloc(p->m, cap * sizeof *m);
		const char **nm = realloc(p->obj_name, cap * sizeof *nm);
		if (nm) p->obj_name = nm;
		size_t *nl = realloc(p->obj_len, cap * sizeof *nl);
		if (nl) p->obj_len = nl;
		if (m) p->m = m;
		if (!m || !nm || !nl) return false;
		p->mcap = cap;
	}
	p->obj_name[p->nm] = s;
	p->obj_len[p->nm] = n;
	p->m[p->nm++] = (struct span){p->f.n, p->f.n};
	p->current = true;
	return true;
}

static bool add_face(struct parse *p, const struct face *f)
{
	if (!p->current && !new_object(p, "defaultobject", 13)) return false;
	if (p->f.n == p->f.cap) {
		size_t cap = p->f.cap ? 2 * p->f.cap : 1024;
		struct face *g = realloc(p->f.p, cap * sizeof *g);
		if (!g) return false;
		p->f.p = g;
		p->f.cap = cap;
	}
	p->f.p[p->f.n++] = *f;
	p->m[p->nm - 1].end = p->f.n;
	return true;
}

/* `o NAME` (its first word; none: nothing happens) and `g NAME` (the rest of the line from its
 * first non-blank, trailing blanks kept; the active group at first is "", so that a `g` of no
 * name then does nothing): Assimp's getObjectName and getGroupName. s[0..n) follows the
 * keyword. 1 handled, 0 not mine, -1 out of memory. */
static int object_line(struct parse *p, char kind, const char *s, size_t n)
{
	while (n && blank(*s)) s++, n--;
	if (kind == 'g') {
		if (p->group_len == n && !memcmp(p->group, s, n)) return 1;
		p->group = s;
		p->group_len = n;
		return new_object(p, s, n) ? 1 : -1;
	}
	size_t w = 0;
	while (w < n && !blank(s[w])) w++;
	if (!w) return 1;
	for (size_t i = 0; i < p->nm; i++)
		if (p->obj_len[i] == w && !memcmp(p->obj_name[i], s, w)) return 0;   /* an earlier object again */
	return new_object(p, s, w) ? 1 : -1;
}

static bool word_is(const char *s, size_t n, const char *w)
{
	size_t k = strlen(w);
	return n >= k && !memcmp(s, w, k) && (n == k || blank(s[k]));
}

/* A usemtl or mtllib line (Assimp reads it in the skeleton; one of no name does nothing). 1. */
static int material_line(struct parse *p)
{
	p->sk.materials = true;
	return 1;
}

/* One line (no line end): 1 read, 0 not mine, -1 out of memory. */
static int line(struct parse *p, const char *s, size_t n)
{
	float x[3] = {0, 0, 0};
	if (!n) return 1;
	if (n == 1 && (s[0] == 'g' || s[0] == 'o')) return object_line(p, s[0], s + 1, 0);
	if (n == 1) return !strchr("fpl", s[0]);
	switch (s[0]) {
	case 'v':
		if (n > 1 && blank(s[1])) return numbers(s + 1, n - 1, x, 3, false) == 3 ? (floats_push(&p->v, x, 3) ? 1 : -1) : 0;
		if (n > 2 && s[1] == 't' && blank(s[2])) return numbers(s + 2, n - 2, x, 3, true) > 0 ? (floats_push(&p->vt, x, 3) ? 1 : -1) : 0;
		if (n > 2 && s[1] == 'n' && blank(s[2])) return numbers(s + 2, n - 2, x, 3, false) == 3 ? (floats_push(&p->vn, x, 3) ? 1 : -1) : 0;
		return s[1] == 't' || s[1] == 'n' ? 0 : 1;   /* vp and other v words: ignored (so is "v") */
	case 'f': {
		struct face f;
		if (n < 2 || !blank(s[1]) || !face_line(p, s + 1, n - 1, &f)) return 0;
		return add_face(p, &f) ? 1 : -1;
	}
	case 'o':
	case 'g':
		return n > 1 && blank(s[1]) ? object_line(p, s[0], s + 1, n - 1) : 0;
	case 'p': case 'l':
		return 0;   /* points and lines */
	case 'u':
		return word_is(s, n, "usemtl") ? material_line(p) : 1;
	case 'm':
		return word_is(s, n, "mtllib") ? material_line(p) : 1;
	case 'c':
		return !word_is(s, n, "cstype");
	default:
		return 1;   /* comments, s, blanks, and the lines Assimp skips (one starting with a blank) */
	}
}

static int skeleton_add(struct skeleton *k, const char *s, size_t n)
{
	if (k->cap - k->n < n + 1) {
		size_t cap = k->cap ? 2 * k->cap : 4096;
		while (cap - k->n < n + 1) cap *= 2;
		char *q = realloc(k->p, cap);
		if (!q) return -1;
		k->p = q;
		k->cap = cap;
	}
	memcpy(k->p + k->n, s, n);
	k->n += n;
	k->p[k->n++] = '\n';
	return 0;
}

/* The skeleton's part of a line (faces[nf] the next face): an o, g, usemtl or mtllib line as
 * it is; a face, when it starts a run, as a face of run
 * r's three vertices (3r + 1 ..). 0, or -1 without memory. */
static int skeleton_line(struct skeleton *k, const char *s, size_t n, size_t nf)
{
	if (((s[0] == 'o' || s[0] == 'g') && (n == 1 || blank(s[1]))) || word_is(s, n, "usemtl") || word_is(s, n, "mtllib")) {
		if (k->in_run) k->run[k->nrun - 1].end = nf;
		k->in_run = false;
		return skeleton_add(k, s, n);
	}
	if (s[0] != 'f' || k->in_run) return 0;
	if (k->nrun == k->runcap) {
		size_t cap = k->runcap ? 2 * k->runcap : 64;
		struct span *r = realloc(k->run, cap * sizeof *r);
		if (!r) return -1;
		k->run = r;
		k->runcap = cap;
	}
	k->run[k->nrun++] = (struct span){nf, nf};
	k->in_run = true;
	char f[64];
	size_t v = 3 * (k->nrun - 1);
	return skeleton_add(k, f, (size_t)snprintf(f, sizeof f, "f %zu %zu %zu", v + 1, v + 2, v + 3));
}

/* The file's lines (ends: \n, \r) into p: 1, 0 not mine, -1 out of memory. */
static int parse_lines(const uint8_t *d, size_t len, struct parse *p)
{
	/* Assimp's stream buffer reads 16 MiB at a time and drops a last line without an end
	 * past the first block */
	if (len > 4096u * 4096u && d[len - 1] != '\n' && d[len - 1] != '\r') return 0;
	const char *s = (const char *)d;
	for (size_t i = 0; i < len;) {
		size_t e = i;
		while (e < len && d[e] != '\n' && d[e] != '\r') {
			if (!d[e] || d[e] == '\f') return 0;   /* also line ends to Assimp */
			e++;
		}
		if (e > i && d[e - 1] == '\\') return 0;     /* a continued line */
		if (e > i && skeleton_line(&p->sk, s + i, e - i, p->f.n) != 0) return -1;
		int rc = line(p, s + i, e - i);
		if (rc <= 0) return rc;
		i = e + 1;
	}
	if (p->sk.in_run) p->sk.run[p->sk.nrun - 1].end = p->f.n;
	return 1;
}

/* A mesh's faces: spans sp[0 .. nsp). */
struct faces_of {
	const struct span *sp;
	size_t nsp;
};

/* The mesh's corners as Assimp's createVertexArray lays them out into a (malloc'd arrays; the
 * mesh has normals and uvs where some face names one): 0, NOT_MINE, or NO_MEMORY. */
static int mesh_corners(const struct parse *p, struct faces_of m, struct api_assimp_mesh *a, float **bufs,
                        uint32_t **corners, uint8_t **sizes)
{
	size_t nc = 0, nf = 0;
	bool nrm = false, uv = false;
	for (size_t s = 0; s < m.nsp; s++)
		for (size_t f = m.sp[s].first; f < m.sp[s].end; f++, nf++) {
			nc += p->f.p[f].nv;
			nrm |= p->f.p[f].nn != 0;
			uv |= p->f.p[f].nt != 0;
		}
	if (nc > UINT32_MAX / 4) return NOT_MINE;
	nrm &= p->vn.n != 0;
	uv &= p->vt.n != 0;
	bufs[0] = malloc(nc * 12);
	bufs[1] = nrm ? calloc(nc, 12) : NULL;
	bufs[2] = uv ? calloc(nc, 12) : NULL;
	*corners = malloc(nc * sizeof **corners);
	*sizes = malloc(nf ? nf : 1);
	if (!bufs[0] || (nrm && !bufs[1]) || (uv && !bufs[2]) || !*corners || !*sizes) return NO_MEMORY;
	uint32_t k = 0, i = 0;
	for (size_t s = 0; s < m.nsp; s++)
		for (size_t f = m.sp[s].first; f < m.sp[s].end; f++) {
			const struct face *fc = &p->f.p[f];
			(*sizes)[i++] = fc->nv;
			a->quads |= fc->nv == 4;
			for (uint32_t c = 0; c < fc->nv; c++, k++) {
				if (fc->v[c] >= p->v.n) return NOT_MINE;
				memcpy(bufs[0] + 3 * (size_t)k, p->v.p + 3 * (size_t)fc->v[c], 12);
				(*corners)[k] = k;
				if (nrm && c < fc->nn) {
					if (fc->n[c] >= p->vn.n) nrm = false;   /* Assimp drops the mesh's normals */
					else memcpy(bufs[1] + 3 * (size_t)k, p->vn.p + 3 * (size_t)fc->n[c], 12);
				}
				if (uv && c < fc->nt) {
					if (fc->t[c] >= p->vt.n) uv = false;
					else memcpy(bufs[2] + 3 * (size_t)k, p->vt.p + 3 * (size_t)fc->t[c], 12);
				}
			}
		}
	*a = (struct api_assimp_mesh){.pos = bufs[0], .nrm = nrm ? bufs[1] : NULL, .uv = uv ? bufs[2] : NULL, .nv = k,
	                              .corners = *corners, .sizes = *sizes, .nfaces = i, .quads = a->quads};
	return 0;
}

static int one_mesh(const struct parse *p, struct faces_of m, struct api_arena *arena, struct api_model_mesh *out,
                    size_t *bytes)
{
	float *bufs[3] = {NULL, NULL, NULL};
	uint32_t *corners = NULL;
	uint8_t *sizes = NULL;
	struct api_assimp_mesh a = {0};
	int rc = mesh_corners(p, m, &a, bufs, &corners, &sizes);
	if (rc == 0) rc = api_assimp_post(&a, arena, out, bytes);
	else if (rc == NO_MEMORY) rc = API_WIRE_OVER_MEMORY;
	if (rc == API_ASSIMP_POST_GIVE_UP) rc = NOT_MINE;
	free(bufs[0]);
	free(bufs[1]);
	free(bufs[2]);
	free(corners);
	free(sizes);
	return rc;
}

/* The meshes mesh[0 .. nm) (mesh i's faces: spans sp[start[i] .. start[i + 1])) made into
 * out[0 .. nm), with their triangles' count in *tris: API_WIRE_OK, NOT_MINE, or
 * API_WIRE_OVER_MEMORY. */
static int make_meshes(const struct parse *p, const struct span *sp, const size_t *start, uint32_t nm,
                       struct api_arena *arena, struct api_model_mesh *out, size_t *bytes)
{
	for (uint32_t i = 0; i < nm; i++) {
		int rc = one_mesh(p, (struct faces_of){sp + start[i], start[i + 1] - start[i]}, arena, &out[i], bytes);
		if (rc != API_WIRE_OK) return rc;
	}
	return api_model_meshes_have_area(out, nm) ? API_WIRE_OK : NOT_MINE;
}

/* The parsed file's meshes (those with faces) as the model, an instance each. */
static int build(const struct parse *p, struct api_arena *arena, struct api_model *out, size_t *bytes)
{
	uint32_t nm = 0;
	for (size_t i = 0; i < p->nm; i++) nm += p->m[i].end > p->m[i].first;
	if (!nm) return NOT_MINE;
	struct api_model_mesh *meshes = api_arena_calloc(arena, nm, sizeof *meshes);
	struct api_model_instance *inst = api_arena_calloc(arena, nm, sizeof *inst);
	struct rnd_material *mat = api_arena_calloc(arena, 1, sizeof *mat);
	struct span *sp = malloc(nm * sizeof *sp);
	size_t *start = malloc((nm + 1) * sizeof *start);
	int rc = meshes && inst && mat && sp && start ? API_WIRE_OK : API_WIRE_OVER_MEMORY;
	for (size_t i = 0, k = 0; rc == API_WIRE_OK && i < p->nm; i++)
		if (p->m[i].end > p->m[i].first) {
			sp[k] = p->m[i];
			start[k] = k;
			k++;
		}
	if (start) start[nm] = nm;
	if (rc == API_WIRE_OK) rc = make_meshes(p, sp, start, nm, arena, meshes, bytes);
	free(sp);
	free(start);
	if (rc != API_WIRE_OK) return rc;
	uint64_t tris = 0;
	for (uint32_t k = 0; k < nm; k++) {
		inst[k].mesh = k;
		rnd_mat4_identity(inst[k].model);
		tris += meshes[k].index_count / 3;
	}
	rnd_material_defaults(mat);   /* Assimp's default material, as api_conv_material reads it */
	*out = (struct api_model){.meshes = meshes, .mesh_count = nm, .instances = inst, .instance_count = nm,
	                          .materials = mat, .material_count = 1, .triangles = tris, .format = API_MODEL_OBJ};
	*bytes += nm * (sizeof *meshes + sizeof *inst) + sizeof *mat;
	return API_WIRE_OK;
}

/* What the skeleton's import needs: the files the model names, and the images' size. */
struct obj_files {
	const struct api_model_file *files;
	size_t nfiles;
	uint32_t output_side;
};

/* The skeleton as an OBJ: run r's three vertices (x = r), then the skeleton's lines. Malloc'd,
 * *n bytes; NULL without memory. */
static char *skeleton_text(const struct skeleton *k, size_t *n)
{
	size_t cap = k->nrun * 3 * 32 + k->n + 1;
	char *t = malloc(cap);
	*n = 0;
	for (size_t r = 0; t && r < k->nrun; r++)
		*n += (size_t)snprintf(t + *n, cap - *n, "v %zu 0 0\nv %zu 1 0\nv %zu 0 1\n", r, r, r);
	if (t) memcpy(t + *n, k->p, k->n), *n += k->n;
	return t;
}

/* The runs of each of the skeleton's meshes, in its triangles' order, as spans of faces:
 * mesh i's sp[start[i] .. start[i + 1]). API_WIRE_OK, or NOT_MINE when a run is in no mesh or
 * in two (nothing known does that). */
static int skeleton_runs(const struct skeleton *k, const struct api_model *sk, struct span *sp, size_t *start,
                         uint8_t *seen)
{
	size_t ns = 0;
	for (uint32_t i = 0; i < sk->mesh_count; i++) {
		const struct api_model_mesh *m = &sk->meshes[i];
		start[i] = ns;
		for (uint32_t t = 0; t < m->index_count; t += 3) {
			float x = m->positions[3 * (size_t)m->indices[t]];
			if (!(x >= 0 && x < (float)k->nrun) || x != (float)(size_t)x || seen[(size_t)x]) return NOT_MINE;
			seen[(size_t)x] = 1;
			sp[ns++] = k->run[(size_t)x];
		}
	}
	start[sk->mesh_count] = ns;
	return ns == k->nrun ? API_WIRE_OK : NOT_MINE;
}

/* With materials: Assimp imports the skeleton, so that the meshes (which runs of faces each
 * holds, in which order), their materials, the materials themselves, their textures and
 * warnings are Assimp's; each mesh's faces are then made here. */
static int build_with_materials(const struct parse *p, const struct obj_files *of, struct api_arena *arena,
                                struct api_model *out, size_t *bytes, char *err, size_t errsize)
{
	const struct skeleton *k = &p->sk;
	if (!k->nrun || k->nrun > (1u << 22)) return NOT_MINE;   /* (x exact in a float) */
	size_t n, skb = 0;
	char *text = skeleton_text(k, &n);
	if (!text) return API_WIRE_OVER_MEMORY;
	struct api_model sk;
	int rc = api_model_import_assimp((const uint8_t *)text, n, of->files, of->nfiles, API_MODEL_OBJ, of->output_side,
	                                 arena, &sk, &skb, err, errsize);
	free(text);
	if (rc != API_WIRE_OK) return rc;   /* the file's refusal: Assimp said why (see the top) */
	size_t *start = malloc((sk.mesh_count + 1) * sizeof *start);
	struct span *sp = malloc(k->nrun * sizeof *sp);
	uint8_t *seen = calloc(k->nrun, 1);
	struct api_model_mesh *meshes = api_arena_calloc(arena, sk.mesh_count, sizeof *meshes);
	rc = start && sp && seen && meshes ? skeleton_runs(k, &sk, sp, start, seen) : API_WIRE_OVER_MEMORY;
	if (rc == API_WIRE_OK) rc = make_meshes(p, sp, start, sk.mesh_count, arena, meshes, bytes);
	free(start);
	free(sp);
	free(seen);
	if (rc != API_WIRE_OK) return rc;
	*out = sk;
	out->meshes = meshes;
	out->triangles = 0;
	for (uint32_t i = 0; i < sk.mesh_count; i++) {
		meshes[i].material = sk.meshes[i].material;
		meshes[i].single_sided = sk.meshes[i].single_sided;
	}
	for (uint32_t i = 0; i < sk.instance_count; i++) out->triangles += meshes[sk.instances[i].mesh].index_count / 3;
	*bytes += skb + sk.mesh_count * sizeof *meshes;
	return API_WIRE_OK;
}

int api_obj_import(const uint8_t *d, size_t len, const struct api_model_file *files, size_t nfiles,
                   uint32_t output_side, struct api_arena *arena, struct api_model *out, size_t *bytes, char *err,
                   size_t errsize)
{
	*bytes = 0;
	if (len < 16) return NOT_MINE;   /* Assimp: "OBJ-file is too small" */
	struct parse p;
	memset(&p, 0, sizeof p);
	p.group = "";
	int rc = parse_lines(d, len, &p);
	for (size_t f = 0; rc > 0 && f < p.f.n; f++)   /* (before Assimp reads materials and textures) */
		for (int c = 0; c < p.f.p[f].nv; c++)
			if (p.f.p[f].v[c] >= p.v.n) rc = 0;
	struct obj_files of = {files, nfiles, output_side};
	rc = rc < 0 ? API_WIRE_OVER_MEMORY
	     : rc == 0 ? NOT_MINE
	     : p.sk.materials ? build_with_materials(&p, &of, arena, out, bytes, err, errsize)
	     : build(&p, arena, out, bytes);
	parse_free(&p);
	if (rc == API_WIRE_OVER_MEMORY) api_err_set(err, errsize, "out of memory importing the model");
	return rc;
}
