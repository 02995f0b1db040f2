/*
 * api/mesh_closed.c — whether a welded mesh closes a volume wound outward (see model_lod.h,
 * api_mesh_closed): every edge is run by exactly two triangles, in opposite directions, found
 * by one sort of the edges as undirected keys with their direction in the lowest bit; the
 * volume's sign from the divergence theorem.
 */
#include <stdlib.h>
#include "model_lod.h"
#include "weld.h"

bool api_mesh_closed(const uint32_t *idx, size_t ni, const float *pos)
{
	/* An edge a -> b as (min << (bits + 1)) | (max << 1) | (a > b): 2 bits + 1 of key. */
	uint32_t top = 0;
	for (size_t i = 0; i < ni; i++) top |= idx[i];
	unsigned bits = 0;
	while (bits < 32 && top >> bits) bits++;
	if (bits > 31) return false;   /* (more vertices than any import holds) */
	size_t cap = ni ? ni : 1;
	uint64_t *e = malloc(cap * sizeof *e), *tmp = malloc(cap * sizeof *tmp);
	bool closed = false;
	if (!e || !tmp) goto out;
	size_t ne = 0;
	double vol = 0.0;
	for (size_t t = 0; t + 2 < ni; t += 3) {
		uint32_t v[3] = {idx[t], idx[t + 1], idx[t + 2]};
		if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;
		for (int k = 0; k < 3; k++) {
			uint64_t a = v[k], b = v[(k + 1) % 3];
			e[ne++] = a < b ? (a << (bits + 1)) | (b << 1) : (b << (bits + 1)) | (a << 1) | 1u;
		}
		const float *a = pos + 3 * (size_t)v[0], *b = pos + 3 * (size_t)v[1], *c = pos + 3 * (size_t)v[2];
		vol += (double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
		       (double)a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
		       (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
	}
	closed = ne > 0 && ne % 2 == 0 && vol > 0.0;
	if (!closed) goto out;
	/* Sorted, the edges come in pairs: one way (bit 0 clear), then the other way (bit 0 set);
	 * an edge run twice the same way, or by a third triangle, breaks a pair. */
	const uint64_t *se = api_radix_sort(e, tmp, NULL, NULL, ne);
	for (size_t i = 0; closed && i < ne; i += 2) closed = !(se[i] & 1u) && se[i + 1] == (se[i] | 1u);
out:
	free(e);
	free(tmp);
	return closed;
}
