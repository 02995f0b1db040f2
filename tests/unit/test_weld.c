/* tests/unit — api/weld.h: the sorted weld gives the meshes the hashed joins and welds gave
 * before it, number for number. The references below are the old paths, written again with
 * meshoptimizer's own remap (which api/remap.c, the hash they used, matched key for key): the
 * STL join of api/model_import.c (corners equal in position, normal to 2^-14 and colour) and
 * the level's weld of api/model_lod.c (positions equal on a grid of 2^-20 of the extent,
 * numbered in the order the indices meet them, each at its last vertex's position, represented
 * by its first). */
#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>
#include "arena.h"
#include "model_conv.h"
#include "test.h"
#include "weld.h"
#include "workers.h"

struct old_key {
	float pos[3];
	int16_t nrm[3];
	uint8_t col[4];
	int16_t pad;
};

/* The join as api_join_vertices made it with a hash (meshoptimizer's numbering). */
static uint32_t old_join(float *pos, float *nrm, uint8_t *col, uint32_t nv, uint32_t *idx, uint32_t ni)
{
	uint32_t *remap = malloc(nv * sizeof *remap);
	struct old_key *key = calloc(nv, sizeof *key);
	for (uint32_t v = 0; v < nv; v++) {
		for (int k = 0; k < 3; k++) {
			key[v].pos[k] = pos[3 * v + k] + 0.0f;
			key[v].nrm[k] = (int16_t)lrintf(nrm[3 * v + k] * 16384.0f);
		}
		if (col) memcpy(key[v].col, col + 4 * v, 4);
	}
	size_t unique = meshopt_generateVertexRemap(remap, NULL, nv, key, nv, sizeof *key);
	for (uint32_t v = 0; v < nv; v++)
		if (remap[v] != v) {
			memcpy(pos + 3 * remap[v], pos + 3 * v, 12);
			memcpy(nrm + 3 * remap[v], nrm + 3 * v, 12);
			if (col) memcpy(col + 4 * remap[v], col + 4 * v, 4);
		}
	meshopt_remapIndexBuffer(idx, idx, ni, remap);
	free(remap);
	free(key);
	return (uint32_t)unique;
}

/* The level's weld as api/model_lod.c made it (index_order_remap over quantized keys). */
static size_t old_weld(const float *pos, uint32_t nv, const uint32_t *ind, uint32_t ni, uint32_t *idx, float *wpos,
                       uint32_t *rep)
{
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (uint32_t v = 0; v < nv; v++)
		for (int k = 0; k < 3; k++) lo[k] = fminf(lo[k], pos[3 * v + k]), hi[k] = fmaxf(hi[k], pos[3 * v + k]);
	float ext = fmaxf(fmaxf(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]), unit = ext > 0 ? ext / 1048576.0f : 1.0f;
	int32_t *q = calloc(nv, 12);
	uint32_t *group = malloc(nv * 4), *first = malloc(nv * 4), *remap = malloc(nv * 4);
	for (uint32_t v = 0; v < nv; v++)
		for (int k = 0; k < 3; k++) q[3 * v + k] = (int32_t)lrintf((pos[3 * v + k] - lo[k]) / unit);
	meshopt_generateVertexRemap(group, NULL, nv, q, nv, 12);
	memset(first, 0xff, nv * 4);
	memset(remap, 0xff, nv * 4);
	size_t count = 0;
	for (uint32_t i = 0; i < ni; i++) {
		uint32_t v = ind[i];
		if (remap[v] != ~0u) continue;
		if (first[group[v]] == ~0u) first[group[v]] = (uint32_t)count++;
		remap[v] = first[group[v]];
	}
	meshopt_remapVertexBuffer(wpos, pos, nv, 12, remap);
	meshopt_remapIndexBuffer(idx, ind, ni, remap);
	for (uint32_t v = nv; v-- > 0;)
		if (remap[v] != ~0u) rep[remap[v]] = v;
	free(q);
	free(group);
	free(first);
	free(remap);
	return count;
}

/* A test mesh of nv corners (3 a facet): an STL's flat-shaded facets of a bumpy sphere, a cone
 * whose apex and flat base centre meet 48 facets each (more than the few compared in place),
 * a flat grid whose coplanar facets join, positions 2^-22 of the extent apart (one on the weld's
 * grid, two exactly), -0 beside 0, and colours of two kinds. */
static uint32_t test_mesh(float *pos, float *nrm, uint8_t *col)
{
	uint32_t k = 0;
	float tri[3][3];
	for (int f = 0; f < 600; f++) {   /* bumpy sphere facets */
		int i = f / 20, j = f % 20, c[3][2] = {{i, j}, {i + 1, j}, {i, j + 1}};
		for (int a = 0; a < 3; a++) {
			float th = 3.14159f * (float)c[a][0] / 30, ph = 6.28318f * (float)c[a][1] / 20;
			float r = 1.0f + 0.05f * sinf(5 * th) * cosf(3 * ph);
			tri[a][0] = r * sinf(th) * cosf(ph), tri[a][1] = r * cosf(th), tri[a][2] = r * sinf(th) * sinf(ph);
		}
		for (int a = 0; a < 3; a++, k++) memcpy(pos + 3 * k, tri[a], 12);
	}
	for (int f = 0; f < 96; f++) {    /* a cone: apex and base centre */
		float a0 = 6.28318f * (float)(f % 48) / 48, a1 = 6.28318f * (float)(f % 48 + 1) / 48;
		float y = f < 48 ? 2.0f : 0.0f;
		float t[3][3] = {{0, y, 0}, {cosf(a0), -0.0f, sinf(a0)}, {cosf(a1), 0.0f, sinf(a1)}};
		for (int a = 0; a < 3; a++, k++) memcpy(pos + 3 * k, t[a], 12);
	}
	for (int f = 0; f < 64; f++) {    /* a flat grid, two facets a cell */
		int i = (f / 2) % 4, j = (f / 2) / 4;
		float x = (float)i * 0.25f - 3, z = (float)j * 0.25f, d = f % 2 ? 0.25f : 0;
		float t[3][3] = {{x, -1, z}, {x + 0.25f, -1, z + d}, {x + 0.25f - d, -1, z + 0.25f}};
		for (int a = 0; a < 3; a++, k++) memcpy(pos + 3 * k, t[a], 12);
	}
	for (int f = 0; f < 3; f++) {     /* near-equal positions */
		float e = 4.0f / 4194304.0f * (float)f;
		float t[3][3] = {{3 + e, 1, 1}, {3, 1.5f, 1}, {3, 1, 1.5f}};
		for (int a = 0; a < 3; a++, k++) memcpy(pos + 3 * k, t[a], 12);
	}
	for (uint32_t t = 0; t < k; t += 3) {
		float e1[3], e2[3], n[3];
		for (int a = 0; a < 3; a++) e1[a] = pos[3 * (t + 1) + a] - pos[3 * t + a], e2[a] = pos[3 * (t + 2) + a] - pos[3 * t + a];
		n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
		float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
		for (uint32_t c = t; c < t + 3; c++) {
			for (int a = 0; a < 3; a++) nrm[3 * c + a] = l > 0 ? n[a] / l : 0;
			uint8_t kind = (uint8_t)(t / 3 % 5 == 0 ? 255 : 0);
			if (col) col[4 * c] = kind, col[4 * c + 1] = 0, col[4 * c + 2] = 0, col[4 * c + 3] = 255;
		}
	}
	return k;
}

TEST(weld_join_matches_the_hashed_join)
{
	enum { MAX = 3000 };
	for (int colours = 0; colours < 2; colours++) {
		float *p[2], *n[2];
		uint8_t *c[2] = {NULL, NULL};
		uint32_t *ix[2], nv = 0, got[2];
		for (int s = 0; s < 2; s++) {
			p[s] = malloc(MAX * 12), n[s] = malloc(MAX * 12), ix[s] = malloc(MAX * 4);
			if (colours) c[s] = malloc(MAX * 4);
			nv = test_mesh(p[s], n[s], c[s]);
			for (uint32_t i = 0; i < nv; i++) ix[s][i] = i;
		}
		REQUIRE(nv <= MAX);
		struct api_arena *a = api_arena_create();
		const uint32_t *group;
		uint32_t groups;
		got[0] = old_join(p[0], n[0], c[0], nv, ix[0], nv);
		got[1] = api_join_vertices(p[1], n[1], c[1], nv, ix[1], nv, a, &group, &groups);
		CHECK(got[0] == got[1] && got[1] < nv - 100, "colours %d: %u vertices joined, %u by the hash (of %u)", colours,
		      got[1], got[0], nv);
		CHECK(!memcmp(p[0], p[1], got[0] * 12) && !memcmp(n[0], n[1], got[0] * 12), "the same positions and normals");
		CHECK(!colours || !memcmp(c[0], c[1], got[0] * 4), "the same colours");
		CHECK(!memcmp(ix[0], ix[1], nv * 4), "the same indices");
		/* The weld handed on, and the one sorted afresh, weld as the old one did. */
		REQUIRE(group && groups > 0);
		uint32_t *oi = malloc(nv * 4), *ni = malloc(nv * 4), *orep = malloc(nv * 4);
		float *opos = malloc(nv * 12);
		size_t oc = old_weld(p[0], got[0], ix[0], nv, oi, opos, orep);
		for (int fresh = 0; fresh < 2; fresh++) {
			struct api_welded w;
			REQUIRE(api_weld_mesh(p[1], got[1], ix[1], nv, fresh ? NULL : group, groups, ni, &w));
			CHECK(w.count == oc && oc < got[0], "fresh %d: %zu welded, %zu before", fresh, w.count, oc);
			CHECK(!memcmp(ni, oi, nv * 4), "fresh %d: the same welded indices", fresh);
			CHECK(!memcmp(w.pos, opos, oc * 12) && !memcmp(w.rep, orep, oc * 4), "fresh %d: the same positions and "
			      "representatives", fresh);
			api_welded_release(&w);
		}
		free(oi);
		free(ni);
		free(orep);
		free(opos);
		api_arena_destroy(a);
		for (int s = 0; s < 2; s++) free(p[s]), free(n[s]), free(c[s]), free(ix[s]);
	}
}

/* Vertices no index names are left out of the weld, as before; the first named one
 * represents a group, the last named one places it. */
TEST(weld_leaves_out_unnamed_vertices)
{
	float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1e-9f, 0, 0, 5, 5, 5, 1, 1e-9f, 0};
	uint32_t ind[] = {3, 1, 2, 0, 5, 2}, idx[6], oi[6], orep[6];
	float opos[18];
	struct api_welded w;
	REQUIRE(api_weld_mesh(pos, 6, ind, 6, NULL, 0, idx, &w));
	size_t oc = old_weld(pos, 6, ind, 6, oi, opos, orep);
	CHECK(w.count == 3 && oc == 3, "%zu welded (%zu before)", w.count, oc);
	CHECK(!memcmp(idx, oi, sizeof idx) && !memcmp(w.pos, opos, 3 * 12) && !memcmp(w.rep, orep, 3 * 4),
	      "as before: rep %u %u %u", w.rep[0], w.rep[1], w.rep[2]);
	CHECK(w.rep[0] == 0 && w.pos[0] == 1e-9f, "vertex 0 represents, vertex 3 places: %u %g", w.rep[0], (double)w.pos[0]);
	api_welded_release(&w);
}

/* Inputs of every path (a few: insertion; small: 8-bit digits; medium: 11-bit; large: scattered
 * by their top bits first), with values and without: sorted, ties in their first order. */
TEST(weld_radix_sort_is_stable)
{
	static const uint32_t sizes[5] = {20, 1000, 5000, 200000, 200000};
	for (int z = 0; z < 5; z++) {
		uint32_t n = sizes[z], x = 7;
		api_workers_start(z == 4 ? 3 : 1);   /* the large sort's slices and buckets on threads too */
		uint64_t *k = malloc(n * 8ull), *t = malloc(n * 8ull), *k2 = malloc(n * 8ull), *t2 = malloc(n * 8ull);
		uint32_t *v = malloc(n * 4ull), *vt = malloc(n * 4ull);
		for (uint32_t i = 0; i < n; i++) {
			x = x * 1103515245u + 12345u;
			k[i] = k2[i] = (uint64_t)(x >> 20) << 40 | (uint64_t)(x >> 28) << (z % 2 * 9);   /* few values: many ties */
			v[i] = i;
		}
		const uint64_t *s = api_radix_sort(k, t, v, vt, n), *s2 = api_radix_sort(k2, t2, NULL, NULL, n);
		const uint32_t *sv = s == k ? v : vt;
		int bad = 0;
		for (uint32_t i = 1; i < n; i++) bad += s[i] < s[i - 1] || (s[i] == s[i - 1] && sv[i] < sv[i - 1]);
		for (uint32_t i = 0; i < n; i++) bad += s2[i] != s[i];
		CHECK(bad == 0, "%u keys: %d out of order", n, bad);
		api_workers_stop();
		free(k);
		free(t);
		free(k2);
		free(t2);
		free(v);
		free(vt);
	}
}
