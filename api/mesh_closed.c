/*
 * api/mesh_closed.c — whether a welded mesh closes a volume wound outward (see model_lod.h,
 * api_mesh_closed): every directed edge once, and its reverse among the edges too, found by
 * sorting the edges as 64-bit keys; the volume's sign from the divergence theorem.
 */
#include <stdlib.h>
#include <string.h>
#include "model_lod.h"

/* Sorts a[n] (tmp: n more) a byte at a time from the lowest, skipping bytes every key shares
 * (the high ones of vertex ids): qsort's call per comparison and a bsearch per edge were a
 * third of a 1M-triangle STL's closedness check. Returns where the sorted keys are (a or tmp). */
static uint64_t *radix_sort_u64(uint64_t *a, uint64_t *tmp, size_t n)
{
	/* Every byte's histogram in one read: a pass moves the keys, not their byte counts. */
	size_t counts[8][256] = {{0}};
	for (size_t i = 0; i < n; i++)
		for (int b = 0; b < 8; b++) counts[b][(a[i] >> (8 * b)) & 0xff]++;
	for (int shift = 0; shift < 64; shift += 8) {
		size_t *count = counts[shift / 8];
		if (n && count[(a[0] >> shift) & 0xff] == n) continue;   /* one value for all */
		size_t sum = 0;
		for (int d = 0; d < 256; d++) {
			size_t c = count[d];
			count[d] = sum;
			sum += c;
		}
		for (size_t i = 0; i < n; i++) tmp[count[(a[i] >> shift) & 0xff]++] = a[i];
		uint64_t *t = a; a = tmp; tmp = t;
	}
	return a;
}

bool api_mesh_closed(const uint32_t *idx, size_t ni, const float *pos)
{
	size_t cap = ni ? ni : 1;
	uint64_t *e = malloc(cap * sizeof *e), *tmp = malloc(cap * sizeof *tmp), *r = NULL;
	bool closed = false;
	if (!e || !tmp) goto out;
	size_t ne = 0;
	double vol = 0.0;
	for (size_t t = 0; t + 2 < ni; t += 3) {
		uint32_t v[3] = {idx[t], idx[t + 1], idx[t + 2]};
		if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;
		for (int k = 0; k < 3; k++) e[ne++] = (uint64_t)v[k] << 32 | v[(k + 1) % 3];
		const float *a = pos + 3 * (size_t)v[0], *b = pos + 3 * (size_t)v[1], *c = pos + 3 * (size_t)v[2];
		vol += (double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
		       (double)a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
		       (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
	}
	closed = ne > 0 && vol > 0.0;
	if (!closed) goto out;
	/* Each directed edge once, and the reversed edges the same set: every edge is run by two
	 * triangles, opposite ways. */
	const uint64_t *se = radix_sort_u64(e, tmp, ne);
	for (size_t i = 1; closed && i < ne; i++) closed = se[i] != se[i - 1];
	if (!closed) goto out;
	uint64_t *other = se == e ? tmp : e;   /* the buffer se does not occupy */
	r = malloc(cap * sizeof *r);
	if (!r) { closed = false; goto out; }
	for (size_t i = 0; i < ne; i++) r[i] = se[i] << 32 | se[i] >> 32;
	closed = memcmp(se, radix_sort_u64(r, other, ne), ne * sizeof *se) == 0;
out:
	free(e);
	free(tmp);
	free(r);
	return closed;
}
