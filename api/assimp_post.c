/*
 * api/assimp_post.c — Assimp 5.2's triangulation, smooth normals and join of a plain mesh
 * (see assimp_post.h). The arithmetic is Assimp's, operation for operation, in float (its
 * ai_real): aiVector3D's cross product, Normalize and NormalizeSafe (a multiplication by the
 * inverse length), acosf for a quad's concave corner. Positions are grouped by sorting
 * (api/weld.h: the grid's groups, then exact equality inside each), where Assimp searches a
 * spatial sort and a hash table; the groups are what the closedness check and the level use
 * afterwards too (weld_group_).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "assimp_post.h"
#include "gltf_material.h"
#include "model_wire.h"
#include "weld.h"

/* ---- aiProcess_Triangulate ---- */

static void normalize(float v[3])   /* aiVector3D::Normalize */
{
	float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
	if (l == 0.0f) return;
	float inv = 1.0f / l;
	v[0] *= inv; v[1] *= inv; v[2] *= inv;
}

/* The corner a quad is fanned from: its concave one (the angles to the diagonal summing past
 * pi), else the first. */
static unsigned quad_start(const float *pos, const uint32_t q[4])
{
	for (unsigned i = 0; i < 4; i++) {
		const float *v0 = pos + 3 * (size_t)q[(i + 3) % 4], *v1 = pos + 3 * (size_t)q[(i + 2) % 4];
		const float *v2 = pos + 3 * (size_t)q[(i + 1) % 4], *v = pos + 3 * (size_t)q[i];
		float l[3], d[3], r[3];
		for (int k = 0; k < 3; k++) l[k] = v0[k] - v[k], d[k] = v1[k] - v[k], r[k] = v2[k] - v[k];
		normalize(l);
		normalize(d);
		normalize(r);
		float angle = acosf(l[0] * d[0] + l[1] * d[1] + l[2] * d[2]) + acosf(r[0] * d[0] + r[1] * d[1] + r[2] * d[2]);
		if (angle > 3.1415926538f) return i;   /* AI_MATH_PI_F */
	}
	return 0;
}

/* Assimp's NGONEncoder: a triangle whose first corner is the previous face's first is
 * turned, so that the two do not read as one polygon. */
static void rotate_right(uint32_t *t)   /* swap(0, 2), swap(1, 2) */
{
	uint32_t a = t[0], b = t[1], c = t[2];
	t[0] = c; t[1] = a; t[2] = b;
}

static void rotate_left(uint32_t *t)    /* swap(1, 2), swap(0, 2) */
{
	uint32_t a = t[0], b = t[1], c = t[2];
	t[0] = b; t[1] = c; t[2] = a;
}

/* The faces as triangles into tri (3 a triangle); their count. */
static size_t triangulate(const struct api_assimp_mesh *in, uint32_t *tri)
{
	const uint32_t *c = in->corners;
	uint32_t last = ~0u;
	size_t nt = 0;
	for (uint32_t f = 0; f < in->nfaces; c += in->sizes[f++]) {
		uint32_t *t = tri + 3 * nt;
		if (in->sizes[f] == 3) {
			memcpy(t, c, 12);
			nt++;
			if (!in->quads) continue;   /* a mesh of triangles is left as it is */
			if (t[0] == last) rotate_right(t);
			last = t[0];
			continue;
		}
		unsigned s = quad_start(in->pos, c);
		uint32_t *u = t + 3;
		t[0] = c[s]; t[1] = c[(s + 1) % 4]; t[2] = c[(s + 2) % 4];
		u[0] = c[s]; u[1] = c[(s + 2) % 4]; u[2] = c[(s + 3) % 4];
		if (t[0] == last) {
			rotate_right(t);
			rotate_left(u);
		}
		last = t[0];
		nt += 2;
	}
	return nt;
}

/* ---- positions: the grid's groups, exact equality inside them ---- */

struct positions {
	uint32_t *id;         /* id[v]: v's position, in the grid's order */
	uint32_t *start;      /* position p's vertices: member[start[p] .. start[p + 1]) */
	uint32_t *member;
	uint32_t count;
	struct api_weld weld;
};

static void positions_release(struct positions *p)
{
	free(p->id);
	free(p->start);
	free(p->member);
	api_weld_release(&p->weld);
}

static bool same_position(const float *a, const float *b)
{
	return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];   /* -0 is 0, as Assimp's hash has it */
}

/* A position's bits, -0 as 0, and a vertex: sorted to group many vertices of one grid point
 * (a pole's fan, written with sin(0) != 0). */
struct exact_key {
	uint32_t bits[3], v;
};

static int exact_cmp(const void *a, const void *b)
{
	const struct exact_key *x = a, *y = b;
	for (int k = 0; k < 3; k++)
		if (x->bits[k] != y->bits[k]) return x->bits[k] < y->bits[k] ? -1 : 1;
	return (x->v > y->v) - (x->v < y->v);
}

/* The members m[0..nm) of one grid point (in vertex order) split by exact position, numbered
 * from p->count on, their lists appended at *at. 0, or -1 without memory. */
static int split_point(const float *pos, const uint32_t *m, uint32_t nm, struct positions *p, uint32_t *at)
{
	enum { FEW = 16 };
	if (nm <= FEW) {   /* compared with each other */
		uint32_t lead[FEW], nl = 0;
		for (uint32_t i = 0; i < nm; i++) {
			uint32_t j = 0;
			while (j < nl && !same_position(pos + 3 * (size_t)m[i], pos + 3 * (size_t)lead[j])) j++;
			if (j == nl) lead[nl++] = m[i];
			p->id[m[i]] = p->count + j;
		}
		for (uint32_t j = 0; j < nl; j++) {
			p->start[p->count + j] = *at;
			for (uint32_t i = 0; i < nm; i++)
				if (p->id[m[i]] == p->count + j) p->member[(*at)++] = m[i];
		}
		p->count += nl;
		return 0;
	}
	struct exact_key *k = malloc(nm * sizeof *k);
	if (!k) return -1;
	for (uint32_t i = 0; i < nm; i++) {
		for (int a = 0; a < 3; a++) {
			float x = pos[3 * (size_t)m[i] + (size_t)a] + 0.0f;
			memcpy(&k[i].bits[a], &x, 4);
		}
		k[i].v = m[i];
	}
	qsort(k, nm, sizeof *k, exact_cmp);
	for (uint32_t i = 0; i < nm; i++) {
		if (!i || memcmp(k[i].bits, k[i - 1].bits, sizeof k[i].bits)) p->start[p->count++] = *at;
		p->id[k[i].v] = p->count - 1;
		p->member[(*at)++] = k[i].v;
	}
	free(k);
	return 0;
}

/* Groups pos by exact position (Assimp's equality: -0 is 0): 0, or -1 without memory. */
static int positions_group(const float *pos, uint32_t nv, struct positions *p)
{
	memset(p, 0, sizeof *p);
	size_t n = nv ? nv : 1;
	p->id = malloc(n * sizeof *p->id);
	p->start = malloc((n + 1) * sizeof *p->start);
	p->member = malloc(n * sizeof *p->member);
	if (!p->id || !p->start || !p->member || !api_weld_sort(pos, nv, &p->weld)) return -1;
	uint32_t at = 0;
	for (size_t g = 0; g < p->weld.groups; g++)
		if (split_point(pos, p->weld.order + p->weld.start[g], p->weld.start[g + 1] - p->weld.start[g], p, &at) != 0)
			return -1;
	p->start[p->count] = at;
	return 0;
}

/* ---- aiProcess_GenSmoothNormals ---- */

/* ComputePositionEpsilon: 1e-4 of the diagonal of the box of all vertices, as ArrayBounds
 * makes it (component by component, std::min and std::max from 1e10 and -1e10). */
static float position_epsilon(const float *pos, uint32_t nv)
{
	float lo[3] = {1e10f, 1e10f, 1e10f}, hi[3] = {-1e10f, -1e10f, -1e10f};
	for (size_t v = 0; v < nv; v++)
		for (int k = 0; k < 3; k++) {
			float x = pos[3 * v + (size_t)k];
			lo[k] = lo[k] < x ? lo[k] : x;    /* std::min(x, lo) */
			hi[k] = x < hi[k] ? hi[k] : x;    /* std::max(x, hi) */
		}
	float d[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
	return sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) * (float)1e-4;
}

/* Pairs of distinct positions closer than eps (Assimp's search radius), appended to *pairs
 * (both ways). The positions are sorted by their cell of a grid of 2 eps (three 21-bit
 * coordinates, one key), so that two such positions are in one cell or in neighbouring ones;
 * each cell is compared with itself and with its 13 neighbours of larger key, found by one
 * cursor each running along the sorted cells. 0, -1 without memory, or give up: a box too
 * large for the grid, or past a budget of comparisons (positions packed closely). */
struct pair_list {
	uint32_t *v, n, cap;
};

static int pair_add(struct pair_list *l, uint32_t a, uint32_t b)
{
	if (l->n + 2 > l->cap) {
		uint32_t cap = l->cap ? 2 * l->cap : 64;
		uint32_t *g = realloc(l->v, 2 * (size_t)cap * sizeof *g);
		if (!g) return -1;
		l->v = g;
		l->cap = cap;
	}
	l->v[2 * l->n] = a; l->v[2 * l->n + 1] = b; l->n++;
	l->v[2 * l->n] = b; l->v[2 * l->n + 1] = a; l->n++;
	return 0;
}

/* The sorted cells' keys sk and positions sv: the close pairs among positions sv[a0 .. a1)
 * and sv[b0 .. b1) (the same run: each pair once). */
static int compare_cells(const float *pos, const struct positions *p, const uint32_t *sv, size_t a0, size_t a1, size_t b0,
                         size_t b1, float eps2, size_t *spent, struct pair_list *l)
{
	for (size_t i = a0; i < a1; i++) {
		const float *qa = pos + 3 * (size_t)p->member[p->start[sv[i]]];
		for (size_t j = a0 == b0 ? i + 1 : b0; j < b1; j++) {
			const float *qb = pos + 3 * (size_t)p->member[p->start[sv[j]]];
			float e[3] = {qb[0] - qa[0], qb[1] - qa[1], qb[2] - qa[2]};
			++*spent;
			if (e[0] * e[0] + e[1] * e[1] + e[2] * e[2] < eps2 && pair_add(l, sv[i], sv[j]) != 0) return -1;
		}
	}
	return 0;
}

static int close_pairs(const float *pos, const struct positions *p, float eps, struct pair_list *l)
{
	uint32_t n = p->count;
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, cell = 2.0f * eps;
	for (uint32_t i = 0; i < n; i++)
		for (int k = 0; k < 3; k++) {
			float x = pos[3 * (size_t)p->member[p->start[i]] + (size_t)k];
			lo[k] = x < lo[k] ? x : lo[k];
			hi[k] = x > hi[k] ? x : hi[k];
		}
	for (int k = 0; k < 3; k++)
		if (n && !((hi[k] - lo[k]) / cell < 2000000.0f)) return API_ASSIMP_POST_GIVE_UP;
	size_t m = n ? n : 1;
	uint64_t *key = malloc(m * sizeof *key), *tmp = malloc(m * sizeof *tmp);
	uint32_t *val = malloc(m * sizeof *val), *vtmp = malloc(m * sizeof *vtmp);
	int rc = key && tmp && val && vtmp ? 0 : -1;
	for (uint32_t i = 0; rc == 0 && i < n; i++) {
		const float *q = pos + 3 * (size_t)p->member[p->start[i]];
		uint64_t k = 0;
		for (int a = 0; a < 3; a++) k = k << 21 | ((uint64_t)((q[a] - lo[a]) / cell) + 1);   /* 1 .. 2e6 */
		key[i] = k;
		val[i] = i;
	}
	const uint64_t *sk = rc == 0 ? api_radix_sort(key, tmp, val, vtmp, n) : NULL;
	const uint32_t *sv = sk == key ? val : vtmp;
	/* the 13 neighbours of larger key: +x (any y, z), then +y (any z), then +z */
	int64_t off[13];
	int no = 0;
	for (int dx = -1; dx <= 1; dx++)
		for (int dy = -1; dy <= 1; dy++)
			for (int dz = -1; dz <= 1; dz++) {
				int64_t o = (int64_t)dx * ((int64_t)1 << 42) + (int64_t)dy * ((int64_t)1 << 21) + dz;
				if (o > 0) off[no++] = o;
			}
	size_t cursor[13] = {0}, spent = 0, budget = 64 * (size_t)n + 65536;
	float eps2 = eps * eps;
	for (size_t a0 = 0, a1; rc == 0 && a0 < n; a0 = a1) {
		for (a1 = a0 + 1; a1 < n && sk[a1] == sk[a0]; a1++) {}
		rc = compare_cells(pos, p, sv, a0, a1, a0, a1, eps2, &spent, l);
		for (int o = 0; rc == 0 && o < no; o++) {
			uint64_t want = sk[a0] + (uint64_t)off[o];
			while (cursor[o] < n && sk[cursor[o]] < want) cursor[o]++;
			size_t b1 = cursor[o];
			while (b1 < n && sk[b1] == want) b1++;
			rc = compare_cells(pos, p, sv, a0, a1, cursor[o], b1, eps2, &spent, l);
		}
		if (rc == 0 && spent > budget) rc = API_ASSIMP_POST_GIVE_UP;
	}
	free(key);
	free(tmp);
	free(val);
	free(vtmp);
	return rc;
}

/* The positions near each (close_pairs) as lists: near[nstart[q] .. nstart[q + 1]). */
static int near_lists(const float *pos, const struct positions *p, float eps, uint32_t **nstart, uint32_t **near)
{
	struct pair_list l = {0};
	*near = NULL;
	*nstart = calloc((size_t)p->count + 1, sizeof **nstart);
	int rc = *nstart ? close_pairs(pos, p, eps, &l) : -1;
	if (rc == 0 && l.n) {
		*near = malloc(l.n * sizeof **near);
		if (!*near) rc = -1;
		uint32_t *s = *nstart;
		for (uint32_t k = 0; rc == 0 && k < l.n; k++) s[l.v[2 * k] + 1]++;
		for (uint32_t k = 0; rc == 0 && k < p->count; k++) s[k + 1] += s[k];
		for (uint32_t k = 0; rc == 0 && k < l.n; k++) (*near)[s[l.v[2 * k]]++] = l.v[2 * k + 1];
		for (uint32_t k = p->count; rc == 0 && k > 0; k--) s[k] = s[k - 1];
		if (rc == 0) s[0] = 0;
	}
	free(l.v);
	return rc;
}

/* Whether the slots of the vertices near position q (and at it) are all zero. */
static bool all_zero(const float *slot, const struct positions *p, const uint32_t *nstart, const uint32_t *near, uint32_t q)
{
	for (uint32_t k = nstart[q]; k <= nstart[q + 1]; k++) {
		uint32_t w = k < nstart[q + 1] ? near[k] : q;
		for (uint32_t i = p->start[w]; i < p->start[w + 1]; i++)
			for (int c = 0; c < 3; c++)
				if (slot[3 * (size_t)p->member[i] + (size_t)c] != 0.0f) return false;
	}
	return true;
}

/* Normals as GenSmoothNormals makes them (at most 175 degrees between faces: no limit),
 * one per position, into pn (3 a position). 0, -1 without memory, or give up. */
static int smooth_normals(const float *pos, uint32_t nv, const uint32_t *tri, size_t nt, const struct positions *p,
                          float *pn)
{
	float *slot = calloc((size_t)(nv ? nv : 1) * 3, sizeof *slot);
	uint8_t *had = calloc(p->count ? p->count : 1, 1);
	uint32_t *nstart = NULL, *near = NULL;
	float eps = position_epsilon(pos, nv);
	int rc = slot && had ? 0 : -1;
	/* a radius whose square is 0 finds nothing, not even the vertex itself: Assimp's normals
	 * are then all zero, a case not worth copying */
	if (rc == 0 && !(eps * eps > 0.0f)) rc = API_ASSIMP_POST_GIVE_UP;
	if (rc == 0) rc = near_lists(pos, p, eps, &nstart, &near);
	for (size_t t = 0; rc == 0 && t < nt; t++) {
		const uint32_t *f = tri + 3 * t;
		const float *v1 = pos + 3 * (size_t)f[0], *v2 = pos + 3 * (size_t)f[1], *v3 = pos + 3 * (size_t)f[2];
		float a[3] = {v2[0] - v1[0], v2[1] - v1[1], v2[2] - v1[2]}, b[3] = {v3[0] - v1[0], v3[1] - v1[1], v3[2] - v1[2]};
		float n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
		float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);   /* NormalizeSafe */
		if (len > 0.0f) {
			float inv = 1.0f / len;
			n[0] *= inv; n[1] *= inv; n[2] *= inv;
		}
		for (int k = 0; k < 3; k++) memcpy(slot + 3 * (size_t)f[k], n, 12);   /* the last face's wins */
	}
	/* Vertex by vertex: one not yet written takes the sum over every vertex within eps and
	 * writes it to all of them. In positions: the first vertex of each decides. */
	for (uint32_t v = 0; rc == 0 && v < nv; v++) {
		uint32_t q = p->id[v];
		if (had[q]) continue;
		float sum[3] = {0, 0, 0};
		uint32_t terms = 0;
		for (uint32_t k = nstart[q]; k <= nstart[q + 1]; k++) {
			uint32_t w = k < nstart[q + 1] ? near[k] : q;
			for (uint32_t i = p->start[w]; i < p->start[w + 1]; i++, terms++)
				for (int c = 0; c < 3; c++) sum[c] += slot[3 * (size_t)p->member[i] + (size_t)c];
		}
		float len = sqrtf(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
		/* Faces that (nearly) cancel (a sheet's two sides, a fold): the sum is mostly rounding,
		 * and Assimp's order of summing (its spatial sort's) gives another direction */
		if (terms > 2 && len < 0.0625f * (float)terms && (len > 0.0f || !all_zero(slot, p, nstart, near, q))) {
			rc = API_ASSIMP_POST_GIVE_UP;
			break;
		}
		if (len > 0.0f) {
			float inv = 1.0f / len;
			sum[0] *= inv; sum[1] *= inv; sum[2] *= inv;
		}
		for (uint32_t k = nstart[q]; k <= nstart[q + 1]; k++) {
			uint32_t w = k < nstart[q + 1] ? near[k] : q;
			memcpy(pn + 3 * (size_t)w, sum, 12);
			had[w] = 1;
		}
	}
	free(slot);
	free(had);
	free(nstart);
	free(near);
	return rc;
}

/* ---- aiProcess_JoinIdenticalVertices ---- */

/* Whether a and b differ by more than Assimp's 1e-5 (its squared length against 1e-5f^2). */
static bool differ(const float *a, const float *b)
{
	const float eps = 1e-5f, eps2 = eps * eps;
	float d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
	return d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > eps2;
}

/* The used vertices joined: remap[v] their new number (~0u unused), src[k] the first vertex of
 * each new one (numbered in vertex order); the count. nrm: a normal a vertex. */
static uint32_t join(const struct api_assimp_mesh *in, const float *nrm, const uint32_t *tri, size_t nt,
                     const struct positions *p, uint32_t *remap, uint32_t *src, uint32_t *newest, uint32_t *older)
{
	memset(remap, 0xff, (size_t)in->nv * sizeof *remap);
	for (size_t i = 0; i < 3 * nt; i++) remap[tri[i]] = 0;   /* used */
	memset(newest, 0xff, (size_t)p->count * sizeof *newest);
	uint32_t count = 0;
	for (uint32_t v = 0; v < in->nv; v++) {
		if (remap[v] == ~0u) continue;
		uint32_t q = p->id[v], k = newest[q];
		/* Assimp's hash table finds the newest of the vertices at this position first */
		for (; k != ~0u; k = older[k]) {
			uint32_t w = src[k];
			if (differ(nrm + 3 * (size_t)v, nrm + 3 * (size_t)w)) continue;
			if (in->uv && differ(in->uv + 3 * (size_t)v, in->uv + 3 * (size_t)w)) continue;
			break;
		}
		if (k == ~0u) {
			k = count++;
			src[k] = v;
			older[k] = newest[q];
			newest[q] = k;
		}
		remap[v] = k;
	}
	return count;
}

/* ---- the mesh umbra keeps ---- */

static int emit(const struct api_assimp_mesh *in, const float *nrm, const uint32_t *tri, size_t nt, const uint32_t *remap,
                const uint32_t *src, uint32_t count, const struct positions *p, bool all_used, struct api_arena *arena,
                struct api_model_mesh *out, size_t *bytes)
{
	float *pos = api_arena_calloc(arena, count ? count : 1, 12), *on = api_arena_calloc(arena, count ? count : 1, 12);
	float *uv = in->uv ? api_arena_calloc(arena, count ? count : 1, 8) : NULL;
	uint8_t *col = in->col ? api_arena_calloc(arena, count ? count : 1, 4) : NULL;
	float *rgba = in->col ? malloc((size_t)(count ? count : 1) * 16) : NULL;
	uint32_t *idx = api_arena_calloc(arena, nt ? 3 * nt : 1, 4);
	uint32_t *groups = all_used ? api_arena_calloc(arena, count ? count : 1, 4) : NULL;
	bool ok = pos && on && idx && (!in->uv || uv) && (!in->col || (col && rgba)) && (!all_used || groups);
	for (uint32_t k = 0; ok && k < count; k++) {
		uint32_t v = src[k];
		memcpy(pos + 3 * (size_t)k, in->pos + 3 * (size_t)v, 12);
		memcpy(on + 3 * (size_t)k, nrm + 3 * (size_t)v, 12);
		if (uv) {   /* as convert_uvs: v = 0 at the top, not finite read as 0 */
			const float *t = in->uv + 3 * (size_t)v;
			uv[2 * k] = isfinite(t[0]) ? t[0] : 0;
			uv[2 * k + 1] = isfinite(t[1]) ? 1.0f - t[1] : 0;
		}
		if (rgba) memcpy(rgba + 4 * (size_t)k, in->col + 4 * (size_t)v, 16);
		if (groups) groups[k] = p->weld.group[v];
	}
	if (ok && col) api_vertex_colors(rgba, count, col);
	free(rgba);
	if (!ok) return API_WIRE_OVER_MEMORY;
	for (size_t i = 0; i < 3 * nt; i++) idx[i] = remap[tri[i]];
	/* a normal that is not finite (a sum that overflowed) is read as convert_data reads it */
	for (uint32_t k = 0; k < count; k++) {
		float *n = on + 3 * (size_t)k;
		if (!isfinite(n[0]) || !isfinite(n[1]) || !isfinite(n[2])) n[0] = 0, n[1] = 1, n[2] = 0;
	}
	*out = (struct api_model_mesh){.positions = pos, .normals = on, .uvs = uv, .colors = col, .indices = idx,
	                               .vertex_count = count, .index_count = (uint32_t)(3 * nt), .weld_group_ = groups,
	                               .weld_groups_ = groups ? (uint32_t)p->weld.groups : 0};
	*bytes += (size_t)count * (24 + (uv ? 8 : 0) + (col ? 4 : 0)) + 3 * nt * 4;
	return API_WIRE_OK;
}

int api_assimp_post(const struct api_assimp_mesh *in, struct api_arena *arena, struct api_model_mesh *out,
                    size_t *bytes)
{
	size_t nt = 0;
	for (uint32_t f = 0; f < in->nfaces; f++) nt += in->sizes[f] - 2u;
	if (3 * nt > UINT32_MAX || !in->nv) return API_ASSIMP_POST_GIVE_UP;
	size_t nv = in->nv;
	uint32_t *tri = malloc(3 * nt * sizeof *tri), *remap = malloc(nv * sizeof *remap), *src = malloc(nv * sizeof *src);
	uint32_t *newest = NULL, *older = malloc(nv * sizeof *older);
	float *made = NULL, *pn = NULL;
	struct positions p;
	int rc = tri && remap && src && older ? positions_group(in->pos, in->nv, &p) : (memset(&p, 0, sizeof p), -1);
	if (rc == 0) {
		newest = malloc((size_t)(p.count ? p.count : 1) * sizeof *newest);
		if (!newest) rc = -1;
	}
	if (rc == 0) nt = triangulate(in, tri);
	const float *nrm = in->nrm;
	if (rc == 0 && !nrm) {
		pn = malloc((size_t)(p.count ? p.count : 1) * 12);
		made = malloc(nv * 12);
		rc = pn && made ? smooth_normals(in->pos, in->nv, tri, nt, &p, pn) : -1;
		for (size_t v = 0; rc == 0 && v < nv; v++) memcpy(made + 3 * v, pn + 3 * (size_t)p.id[v], 12);
		nrm = made;
	}
	if (rc == 0) {
		uint32_t count = in->no_join ? in->nv : join(in, nrm, tri, nt, &p, remap, src, newest, older);
		for (uint32_t v = 0; in->no_join && v < in->nv; v++) remap[v] = src[v] = v;
		bool all_used = true;
		for (size_t v = 0; v < nv && all_used; v++) all_used = remap[v] != ~0u;
		rc = emit(in, nrm, tri, nt, remap, src, count, &p, all_used, arena, out, bytes);
	} else if (rc == -1) {
		rc = API_WIRE_OVER_MEMORY;
	}
	positions_release(&p);
	free(tri);
	free(remap);
	free(src);
	free(newest);
	free(older);
	free(made);
	free(pn);
	return rc;
}

/* ---- fast_atoreal_move ---- */

static const double FRACTION_SCALE[16] = {0.0, 0.1, 0.01, 0.001, 0.0001, 0.00001, 0.000001, 0.0000001, 0.00000001,
                                          0.000000001, 0.0000000001, 0.00000000001, 0.000000000001,
                                          0.0000000000001, 0.00000000000001, 0.000000000000001};

/* The parts of a number as fast_atoreal_move reads them; the characters read, 0 when it is
 * not one this takes. */
static size_t number_parts(const char *s, size_t n, bool *neg, uint64_t *whole, double *frac, bool *has_exp,
                           bool *exp_neg, uint64_t *exp)
{
	size_t i = 0;
	*neg = n && s[0] == '-';
	if (n && (s[0] == '-' || s[0] == '+')) i++;
	if (i == n || s[i] < '0' || s[i] > '9') return 0;
	*whole = 0;
	unsigned digits = 0;
	for (; i < n && s[i] >= '0' && s[i] <= '9'; i++, digits++) *whole = *whole * 10 + (uint64_t)(s[i] - '0');
	if (digits > 18) return 0;   /* strtoul10_64 overflows somewhere past 19 */
	*frac = 0.0;
	if (i < n && s[i] == '.') {
		i++;
		uint64_t f = 0;
		unsigned k = 0;
		for (; i < n && s[i] >= '0' && s[i] <= '9'; i++)
			if (k < 15) f = f * 10 + (uint64_t)(s[i] - '0'), k++;   /* the rest are skipped */
		*frac = (double)f * FRACTION_SCALE[k];
	}
	*has_exp = i < n && (s[i] == 'e' || s[i] == 'E');
	*exp_neg = false;
	*exp = 0;
	if (*has_exp) {
		i++;
		*exp_neg = i < n && s[i] == '-';
		if (i < n && (s[i] == '-' || s[i] == '+')) i++;
		unsigned e = 0;
		for (; i < n && s[i] >= '0' && s[i] <= '9'; i++, e++) *exp = *exp * 10 + (uint64_t)(s[i] - '0');
		if (!e || e > 4) return 0;   /* no digit: Assimp throws */
	}
	return i;
}

/* The number at s as fast_atoreal_move<float> (fo) or <double> (dout) reads it: the same
 * steps in that type. The characters read, 0 when it is not one this takes. */
static size_t atoreal(const char *s, size_t n, float *fo, double *dout)
{
	bool neg, has_exp, exp_neg;
	uint64_t whole, exp;
	double frac;
	size_t i = number_parts(s, n, &neg, &whole, &frac, &has_exp, &exp_neg, &exp);
	if (!i) return 0;
	if (fo) {
		float f = (float)whole + (float)frac;
		if (has_exp) f *= powf(10.0f, exp_neg ? -(float)exp : (float)exp);
		*fo = neg ? -f : f;
	} else {
		double d = (double)whole + frac;
		if (has_exp) d *= pow(10.0, exp_neg ? -(double)exp : (double)exp);
		*dout = neg ? -d : d;
	}
	return i;
}

size_t api_assimp_atof(const char *s, size_t n, float *out)
{
	return atoreal(s, n, out, NULL);
}

size_t api_assimp_atod(const char *s, size_t n, double *out)
{
	return atoreal(s, n, NULL, out);
}
