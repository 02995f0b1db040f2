/*
 * api/lod_colour.c — how far a level's colours are from its full mesh's (see lod_colour.h): a
 * grid over the level's triangles, and for each full-mesh vertex the level triangles within
 * reach of it, their nearest points' interpolated colours against its own.
 *
 * The bound, 2/255 in sRGB encoding beyond one step of the colour's own 8 bits: thumbnails are
 * 8-bit sRGB, so a colour within 2/255 of the full mesh's is one or two steps of the output's
 * rounding, and the lighting (which multiplies the albedo by at most about one in the studio
 * presets) only shrinks an albedo difference in that encoding. Linear 8-bit units would be up
 * to 13x looser near black (linear 1/255 is sRGB 13/255), where a level's averaging of a dark
 * pattern is the most visible. The step of the vertex colours' own precision (linear 8 bits,
 * rounded or truncated by whatever wrote them) is allowed besides: near black one such step is
 * 13/255 of sRGB, and a smooth colour ramp's level, which interpolates the ramp rather than
 * its rounding, measured 3.5/255 over 2/255 there without it (a sphere lit by x, every
 * channel away from black within 0.3/255).
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "lod_colour.h"
#include "workers.h"

#define COLOUR_SLICES 32
#define SRGB_STEPS 1024

/* The level's triangles binned by the cells their boxes cover. */
struct tri_grid {
	float lo[3], cell;
	uint32_t dim[3];
	uint32_t *start, *items;
};

static uint32_t cell_at(const struct tri_grid *g, float x, int k)
{
	float c = (x - g->lo[k]) / g->cell;
	if (!(c > 0.0f)) return 0;
	return c >= (float)g->dim[k] ? g->dim[k] - 1 : (uint32_t)c;
}

static void tri_cells(const struct tri_grid *g, const float *pos, const uint32_t *t, uint32_t a[3], uint32_t b[3])
{
	for (int k = 0; k < 3; k++) {
		float x0 = pos[3 * (size_t)t[0] + (size_t)k], x1 = pos[3 * (size_t)t[1] + (size_t)k],
		      x2 = pos[3 * (size_t)t[2] + (size_t)k];
		a[k] = cell_at(g, fminf(x0, fminf(x1, x2)), k);
		b[k] = cell_at(g, fmaxf(x0, fmaxf(x1, x2)), k);
	}
}

/* Cells of about a level triangle's size (never under reach), at most ~8 a triangle; coarser
 * while the triangles' boxes would cover more than 64 cells each on average (a long slanted
 * triangle's box covers a slab of cells). */
static bool tri_grid_build(struct tri_grid *g, const float *pos, const uint32_t *level, size_t nt, const float lo[3],
                           const float hi[3], float extent, float reach)
{
	memcpy(g->lo, lo, sizeof g->lo);
	g->cell = fmaxf(fmaxf(extent / sqrtf((float)nt), reach), 1e-12f);
	double volume = 1.0, cap = 8.0 * (double)nt + 64.0;
	for (int k = 0; k < 3; k++) volume *= (double)(hi[k] - lo[k]) / g->cell + 1.0;
	if (volume > cap) g->cell *= (float)cbrt(volume / cap);
	size_t cells, entries;
	for (;;) {
		cells = 1;
		for (int k = 0; k < 3; k++) {
			g->dim[k] = (uint32_t)fminf((hi[k] - lo[k]) / g->cell + 1.0f, 1024.0f);
			cells *= g->dim[k];
		}
		entries = 0;
		for (size_t t = 0; t < nt; t++) {
			uint32_t a[3], b[3];
			tri_cells(g, pos, level + 3 * t, a, b);
			entries += (size_t)(b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1);
		}
		if (entries <= 64 * nt + 4096 || cells == 1) break;
		g->cell *= 2.0f;
	}
	g->start = calloc(cells + 1, sizeof *g->start);
	g->items = malloc(entries * sizeof *g->items);
	if (!g->start || !g->items) return false;
	for (int pass = 0; pass < 2; pass++) {
		for (size_t t = 0; t < nt; t++) {
			uint32_t a[3], b[3];
			tri_cells(g, pos, level + 3 * t, a, b);
			for (uint32_t z = a[2]; z <= b[2]; z++)
				for (uint32_t y = a[1]; y <= b[1]; y++)
					for (uint32_t x = a[0]; x <= b[0]; x++) {
						size_t c = ((size_t)z * g->dim[1] + y) * g->dim[0] + x;
						if (pass == 0) g->start[c + 1]++;
						else g->items[g->start[c]++] = (uint32_t)t;
					}
		}
		if (pass == 0)
			for (size_t c = 0; c < cells; c++) g->start[c + 1] += g->start[c];
		else {
			for (size_t c = cells; c > 0; c--) g->start[c] = g->start[c - 1];
			g->start[0] = 0;
		}
	}
	return true;
}

/* The point of triangle abc nearest p: its squared distance, and its barycentric weights in w
 * (Ericson, Real-Time Collision Detection, 5.1.5). */
static float nearest_on_triangle(const float p[3], const float a[3], const float b[3], const float c[3], float w[3])
{
	float ab[3], ac[3], ap[3], bp[3], cp[3];
	for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k];
	float d1 = ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2], d2 = ac[0] * ap[0] + ac[1] * ap[1] + ac[2] * ap[2];
	for (int k = 0; k < 3; k++) bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
	float d3 = ab[0] * bp[0] + ab[1] * bp[1] + ab[2] * bp[2], d4 = ac[0] * bp[0] + ac[1] * bp[1] + ac[2] * bp[2];
	float d5 = ab[0] * cp[0] + ab[1] * cp[1] + ab[2] * cp[2], d6 = ac[0] * cp[0] + ac[1] * cp[1] + ac[2] * cp[2];
	float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
	if (d1 <= 0 && d2 <= 0) w[0] = 1, w[1] = 0, w[2] = 0;
	else if (d3 >= 0 && d4 <= d3) w[0] = 0, w[1] = 1, w[2] = 0;
	else if (d6 >= 0 && d5 <= d6) w[0] = 0, w[1] = 0, w[2] = 1;
	else if (vc <= 0 && d1 >= 0 && d3 <= 0) { float v = d1 / (d1 - d3); w[0] = 1 - v, w[1] = v, w[2] = 0; }
	else if (vb <= 0 && d2 >= 0 && d6 <= 0) { float v = d2 / (d2 - d6); w[0] = 1 - v, w[1] = 0, w[2] = v; }
	else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
		float v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
		w[0] = 0, w[1] = 1 - v, w[2] = v;
	} else {
		float den = va + vb + vc;
		if (!(den > 0.0f)) { w[0] = 1, w[1] = 0, w[2] = 0; } /* degenerate: its first corner */
		else { w[1] = vb / den, w[2] = vc / den, w[0] = 1 - w[1] - w[2]; }
	}
	float d = 0.0f;
	for (int k = 0; k < 3; k++) {
		float q = w[0] * a[k] + w[1] * b[k] + w[2] * c[k] - p[k];
		d += q * q;
	}
	return d;
}

struct colour_job {
	const float *pos;
	const uint8_t *col;
	size_t nv;
	const uint8_t *in_full, *in_level;
	const uint32_t *level;
	const struct tri_grid *g;
	float reach, stop;
	float srgb[SRGB_STEPS + 1];   /* sRGB encoding of linear i / SRGB_STEPS */
	float worst[COLOUR_SLICES];
};

static void srgb_table(float *t)
{
	for (int i = 0; i <= SRGB_STEPS; i++) {
		float x = (float)i / SRGB_STEPS;
		t[i] = x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
	}
}

static float srgb_of(const float *t, float linear)
{
	float x = fminf(fmaxf(linear, 0.0f), 1.0f) * SRGB_STEPS;
	int i = (int)x;
	if (i >= SRGB_STEPS) return t[SRGB_STEPS];
	return t[i] + (x - (float)i) * (t[i + 1] - t[i]);
}

static float to_srgb(const struct colour_job *j, float linear)
{
	return srgb_of(j->srgb, linear);
}

/* The colour error of vertex v: the least over the level triangles within reach (else the
 * nearest within twice that; else 1). */
static float vertex_error(const struct colour_job *j, size_t v)
{
	const float *p = j->pos + 3 * v;
	const uint8_t *own = j->col + 4 * v;
	float mine_lo[3], mine_hi[3];   /* own's channels, one step of their 8 bits either way */
	for (int k = 0; k < 3; k++)
		mine_lo[k] = to_srgb(j, (own[k] - 1.0f) / 255.0f), mine_hi[k] = to_srgb(j, (own[k] + 1.0f) / 255.0f);
	float far = 2.0f * j->reach, best = INFINITY, nearest = far * far, at_nearest = 1.0f;
	uint32_t a[3], b[3];
	for (int k = 0; k < 3; k++) a[k] = cell_at(j->g, p[k] - far, k), b[k] = cell_at(j->g, p[k] + far, k);
	for (uint32_t z = a[2]; z <= b[2]; z++)
		for (uint32_t y = a[1]; y <= b[1]; y++) {
			size_t row = ((size_t)z * j->g->dim[1] + y) * j->g->dim[0];
			for (uint32_t i = j->g->start[row + a[0]], e = j->g->start[row + b[0] + 1]; i < e; i++) {
				const uint32_t *t = j->level + 3 * (size_t)j->g->items[i];
				float w[3];
				float d = nearest_on_triangle(p, j->pos + 3 * (size_t)t[0], j->pos + 3 * (size_t)t[1],
				                              j->pos + 3 * (size_t)t[2], w);
				if (d > far * far) continue;
				const uint8_t *c0 = j->col + 4 * (size_t)t[0], *c1 = j->col + 4 * (size_t)t[1], *c2 = j->col + 4 * (size_t)t[2];
				float diff = fmaxf(fabsf(w[0] * c0[3] + w[1] * c1[3] + w[2] * c2[3] - own[3]) - 1.0f, 0.0f) / 255.0f;
				for (int k = 0; k < 3; k++) {
					float lin = (w[0] * c0[k] + w[1] * c1[k] + w[2] * c2[k]) / 255.0f;
					float x = to_srgb(j, lin);
					diff = fmaxf(diff, fmaxf(mine_lo[k] - x, x - mine_hi[k]));
				}
				if (d <= j->reach * j->reach) best = fminf(best, diff);
				if (d < nearest) nearest = d, at_nearest = diff;
				if (best <= 0.25f / 255.0f) return best;
			}
		}
	return best < INFINITY ? best : at_nearest;
}

static void colour_slice(void *ctx, size_t s, unsigned wk)
{
	(void)wk;
	struct colour_job *j = ctx;
	float worst = 0.0f;
	for (size_t v = s * j->nv / COLOUR_SLICES; v < (s + 1) * j->nv / COLOUR_SLICES && worst <= j->stop; v++)
		if (j->in_full[v] && !j->in_level[v]) worst = fmaxf(worst, vertex_error(j, v));
	j->worst[s] = worst;
}

float api_lod_colour_error(const float *pos, const uint8_t *col, size_t nv, const uint32_t *full, size_t nfull,
                           const uint32_t *level, size_t nlevel, const float lo[3], const float hi[3], float extent,
                           float reach, float stop)
{
	struct tri_grid g = {0};
	struct colour_job *j = calloc(1, sizeof *j);
	uint8_t *in_full = calloc(nv ? nv : 1, 2);
	float worst = INFINITY;
	if (!j || !in_full || nlevel < 3 ||
	    !tri_grid_build(&g, pos, level, nlevel / 3, lo, hi, extent, fmaxf(2.0f * reach, 1e-12f)))
		goto done;
	for (size_t i = 0; i < nfull; i++) in_full[full[i]] = 1;
	for (size_t i = 0; i < nlevel; i++) in_full[nv + level[i]] = 1;
	*j = (struct colour_job){pos, col, nv, in_full, in_full + nv, level, &g, reach, stop, {0}, {0}};
	srgb_table(j->srgb);
	api_workers_run(COLOUR_SLICES, colour_slice, j);
	worst = 0.0f;
	for (int s = 0; s < COLOUR_SLICES; s++) worst = fmaxf(worst, j->worst[s]);
done:
	free(g.start);
	free(g.items);
	free(in_full);
	free(j);
	return worst;
}

/* Vertex v's colour c against its ring's mean m (linear 0..255 per channel), as vertex_error
 * weighs a level's colour: past one step of c's 8 bits (RGB: the sRGB encodings of c -+ 1 less
 * and plus the bound, lo[c] and hi[c]), RGB in sRGB encoding, alpha in its own units. */
static bool rough_vertex(const float *t, const float *lo, const float *hi, const uint8_t *c, const float m[4])
{
	if (fabsf(m[3] - c[3]) - 1.0f > API_LOD_COLOUR_BOUND * 255.0f) return true;
	for (int k = 0; k < 3; k++) {
		float x = srgb_of(t, m[k] / 255.0f);
		if (x < lo[c[k]] || x > hi[c[k]]) return true;
	}
	return false;
}

bool api_lod_colours_rough(const uint8_t *col, size_t nv, const uint32_t *idx, size_t ni)
{
	float *sum = calloc(nv ? nv : 1, 4 * sizeof *sum), *t = malloc((SRGB_STEPS + 1 + 512) * sizeof *t);
	uint32_t *n = calloc(nv ? nv : 1, sizeof *n);
	bool rough = false;
	if (!sum || !t || !n) goto done;
	srgb_table(t);
	float *lo = t + SRGB_STEPS + 1, *hi = lo + 256;
	for (int c = 0; c < 256; c++)
		lo[c] = srgb_of(t, (c - 1.0f) / 255.0f) - API_LOD_COLOUR_BOUND,
		hi[c] = srgb_of(t, (c + 1.0f) / 255.0f) + API_LOD_COLOUR_BOUND;
	for (size_t i = 0; i + 2 < ni; i += 3)
		for (int c = 0; c < 3; c++) {
			uint32_t v = idx[i + (size_t)c], a = idx[i + (size_t)(c + 1) % 3], b = idx[i + (size_t)(c + 2) % 3];
			for (int k = 0; k < 4; k++) sum[4 * (size_t)v + k] += (float)col[4 * (size_t)a + k] + (float)col[4 * (size_t)b + k];
			n[v] += 2;
		}
	size_t used = 0, over = 0;
	for (size_t v = 0; v < nv; v++) {
		if (!n[v]) continue;
		float m[4];
		for (int k = 0; k < 4; k++) m[k] = sum[4 * v + (size_t)k] / (float)n[v];
		used++;
		over += rough_vertex(t, lo, hi, col + 4 * v, m);
	}
	rough = (float)over > API_LOD_COLOUR_ROUGH_SHARE * (float)used;
done:
	free(sum);
	free(t);
	free(n);
	return rough;
}
