/*
 * api/weld.c — vertices grouped by quantized position with a radix sort (see weld.h).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "weld.h"
#include "workers.h"

/* LSD passes over the bits below `bits` of keys[0..n), `digit` (at most 11) bits a pass: the
 * histograms in one read, then a stable scatter per digit that is not the same in every key
 * (the high bits of small ids, an axis a flat mesh does not use). Returns where the keys
 * ended, *vals_out where the values did. */
static uint64_t *lsd(uint64_t *keys, uint64_t *tmp, uint32_t *vals, uint32_t *vtmp, size_t n, unsigned bits,
                     unsigned digit, uint32_t **vals_out)
{
	const uint64_t mask = ((uint64_t)1 << digit) - 1;
	unsigned passes = (bits + digit - 1) / digit;
	uint32_t count[8][1u << 11];
	for (unsigned p = 0; p < passes; p++) memset(count[p], 0, (mask + 1) * sizeof count[p][0]);
	for (size_t i = 0; i < n; i++)
		for (unsigned p = 0; p < passes; p++) count[p][(keys[i] >> (p * digit)) & mask]++;
	for (unsigned p = 0; p < passes; p++) {
		unsigned shift = p * digit;
		uint32_t *c = count[p], sum = 0;
		if (!n || c[(keys[0] >> shift) & mask] == n) continue;
		for (size_t d = 0; d <= mask; d++) {
			uint32_t k = c[d];
			c[d] = sum;
			sum += k;
		}
		if (vals)
			for (size_t i = 0; i < n; i++) {
				uint32_t at = c[(keys[i] >> shift) & mask]++;
				tmp[at] = keys[i];
				vtmp[at] = vals[i];
			}
		else
			for (size_t i = 0; i < n; i++) tmp[c[(keys[i] >> shift) & mask]++] = keys[i];
		uint64_t *t = keys; keys = tmp; tmp = t;
		uint32_t *v = vals; vals = vtmp; vtmp = v;
	}
	*vals_out = vals;
	return keys;
}

/* A few keys (and values), in place: insertion, stable. */
static void insertion(uint64_t *k, uint32_t *v, size_t n)
{
	for (size_t i = 1; i < n; i++) {
		uint64_t x = k[i];
		uint32_t y = v ? v[i] : 0;
		size_t j = i;
		for (; j > 0 && k[j - 1] > x; j--) {
			k[j] = k[j - 1];
			if (v) v[j] = v[j - 1];
		}
		k[j] = x;
		if (v) v[j] = y;
	}
}

/* The buckets of api_radix_sort's first pass, each sorted on its own (in tmp, vtmp) by the
 * bits below the top digit: BUCKET_TASKS tasks of consecutive buckets, on the import's
 * threads (api/workers.h). Bucket d: [d ? end[d - 1] : 0, end[d]). */
enum { BUCKET_TASKS = 64 };
struct buckets {
	uint64_t *keys, *tmp;
	uint32_t *vals, *vtmp;
	const size_t *end;
	size_t count;
	unsigned shift;
};

static void sort_buckets(void *ctx, size_t task, unsigned w)
{
	(void)w;
	const struct buckets *q = ctx;
	uint32_t *v;
	for (size_t d = task * q->count / BUCKET_TASKS; d < (task + 1) * q->count / BUCKET_TASKS; d++) {
		size_t b = d ? q->end[d - 1] : 0, m = q->end[d] - b;
		if (m <= 32) {
			insertion(q->tmp + b, q->vals ? q->vtmp + b : NULL, m);
			continue;
		}
		uint64_t *k = lsd(q->tmp + b, q->keys + b, q->vals ? q->vtmp + b : NULL, q->vals ? q->vals + b : NULL, m,
		                  q->shift, 8, &v);
		if (k != q->tmp + b) {
			memcpy(q->tmp + b, k, m * sizeof *k);
			if (q->vals) memcpy(q->vtmp + b, v, m * sizeof *v);
		}
	}
}

/* api_radix_sort's passes over all the keys of a large sort, in SCATTER_TASKS fixed slices on
 * the import's threads: which bits vary (each slice's OR and AND), each slice's histogram of the
 * top digit, then each slice's stable scatter from its own offsets (slice s's keys of digit d
 * go after those of slices 0..s-1): the same bytes as one scatter in order, whatever the thread
 * count. */
enum { SCATTER_TASKS = 16 };
struct scatter {
	uint64_t *keys, *tmp;
	uint32_t *vals, *vtmp;
	size_t n;
	unsigned shift;
	uint64_t mask;
	uint64_t any[SCATTER_TASKS], all[SCATTER_TASKS];
	size_t *at;   /* [SCATTER_TASKS][mask + 1]: counts, then each slice's next place per digit */
};

static void slice_bits(void *ctx, size_t s, unsigned w)
{
	(void)w;
	struct scatter *q = ctx;
	uint64_t any = 0, all = ~0ull;
	for (size_t i = s * q->n / SCATTER_TASKS; i < (s + 1) * q->n / SCATTER_TASKS; i++) any |= q->keys[i], all &= q->keys[i];
	q->any[s] = any;
	q->all[s] = all;
}

static void slice_count(void *ctx, size_t s, unsigned w)
{
	(void)w;
	struct scatter *q = ctx;
	size_t *c = q->at + s * (q->mask + 1);
	for (size_t i = s * q->n / SCATTER_TASKS; i < (s + 1) * q->n / SCATTER_TASKS; i++) c[(q->keys[i] >> q->shift) & q->mask]++;
}

static void slice_scatter(void *ctx, size_t s, unsigned w)
{
	(void)w;
	struct scatter *q = ctx;
	size_t *c = q->at + s * (q->mask + 1);
	for (size_t i = s * q->n / SCATTER_TASKS; i < (s + 1) * q->n / SCATTER_TASKS; i++) {
		size_t j = c[(q->keys[i] >> q->shift) & q->mask]++;
		q->tmp[j] = q->keys[i];
		if (q->vals) q->vtmp[j] = q->vals[i];
	}
}

uint64_t *api_radix_sort(uint64_t *keys, uint64_t *tmp, uint32_t *vals, uint32_t *vtmp, size_t n)
{
	if (n <= 32) {   /* (a histogram of 2048 counters a digit would cost more than the keys) */
		insertion(keys, vals, n);
		return keys;
	}
	struct scatter q = {keys, tmp, vals, vtmp, n, 0, 0, {0}, {0}, NULL};
	bool large = n >= ((size_t)1 << 16);
	uint64_t any = 0, all = ~0ull;
	if (large) {
		api_workers_run(SCATTER_TASKS, slice_bits, &q);
		for (size_t s = 0; s < SCATTER_TASKS; s++) any |= q.any[s], all &= q.all[s];
	} else {
		for (size_t i = 0; i < n; i++) any |= keys[i], all &= keys[i];
	}
	unsigned bits = 0, top = 4;
	while (bits < 64 && (any ^ all) >> bits) bits++;
	while (top < 11 && (size_t)2048 << top < n) top++;   /* buckets of about 2048 keys */
	uint32_t *v;
	size_t *end = large && bits > top ? malloc((((size_t)1 << top) + 1) * sizeof *end) : NULL;
	q.at = end ? calloc(SCATTER_TASKS << top, sizeof *q.at) : NULL;
	if (!q.at) {
		free(end);
		return lsd(keys, tmp, vals, vtmp, n, bits, n < 4096 ? 8 : 11, &v);
	}
	/* Many keys: one stable scatter by the top digit, then each bucket (its keys stay in the
	 * cache) sorted by the bits below it; only the first pass runs through memory. The sorted
	 * keys end in tmp (the values in vtmp). */
	q.shift = bits - top;
	q.mask = ((uint64_t)1 << top) - 1;
	api_workers_run(SCATTER_TASKS, slice_count, &q);
	size_t sum = 0;
	for (size_t d = 0; d <= q.mask; d++) {
		for (size_t s = 0; s < SCATTER_TASKS; s++) {
			size_t k = q.at[s * (q.mask + 1) + d];
			q.at[s * (q.mask + 1) + d] = sum;
			sum += k;
		}
		end[d] = sum;
	}
	api_workers_run(SCATTER_TASKS, slice_scatter, &q);
	free(q.at);
	struct buckets b = {keys, tmp, vals, vtmp, end, q.mask + 1, q.shift};
	api_workers_run(BUCKET_TASKS, sort_buckets, &b);
	free(end);
	return tmp;
}

void api_weld_release(struct api_weld *w)
{
	free(w->group);
	free(w->order);
	free(w->start);
	memset(w, 0, sizeof *w);
}

/* Each position's key: its grid point's three 21-bit coordinates. */
static void position_keys(const float *pos, uint32_t nv, uint64_t *key)
{
	/* (plain comparisons and rounding: fminf and lrintf are calls into libm here, for their
	 * NaN and errno rules, and positions are finite) */
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (size_t v = 0; v < nv; v++)
		for (int k = 0; k < 3; k++) {
			float p = pos[3 * v + (size_t)k];
			if (p < lo[k]) lo[k] = p;
			if (p > hi[k]) hi[k] = p;
		}
	float ext = fmaxf(fmaxf(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
	float unit = ext > 0.0f ? ext / 1048576.0f : 1.0f;
	for (size_t v = 0; v < nv; v++) {
		uint64_t k = 0;
		for (int a = 0; a < 3; a++)   /* 0 .. 2^20 (a little more by rounding): 21 bits */
			k = k << 21 | ((uint64_t)api_round_even((pos[3 * v + (size_t)a] - lo[a]) / unit) & 0x1fffff);
		key[v] = k;
	}
}

bool api_weld_sort(const float *pos, uint32_t nv, struct api_weld *w)
{
	memset(w, 0, sizeof *w);
	size_t n = nv ? nv : 1;
	uint64_t *key = malloc(n * sizeof *key), *tmp = malloc(n * sizeof *tmp);
	uint32_t *vtmp = malloc(n * sizeof *vtmp);
	w->order = malloc(n * sizeof *w->order);
	w->group = malloc(n * sizeof *w->group);
	bool ok = key && tmp && vtmp && w->order && w->group;
	if (ok) {
		position_keys(pos, nv, key);
		for (uint32_t v = 0; v < nv; v++) w->order[v] = v;
		const uint64_t *sorted = api_radix_sort(key, tmp, w->order, vtmp, nv);
		if (sorted != key) memcpy(w->order, vtmp, (size_t)nv * sizeof *vtmp);
		size_t groups = 0;
		for (size_t i = 0; i < nv; i++) groups += !i || sorted[i] != sorted[i - 1];
		w->start = malloc((groups + 1) * sizeof *w->start);
		ok = w->start != NULL;
		for (size_t i = 0, g = 0; ok && i < nv; i++) {
			if (i && sorted[i] != sorted[i - 1]) g++;
			if (!i || sorted[i] != sorted[i - 1]) w->start[g] = (uint32_t)i;
			w->group[w->order[i]] = (uint32_t)g;
		}
		if (ok) w->start[groups] = nv;
		w->groups = groups;
	}
	free(key);
	free(tmp);
	free(vtmp);
	if (!ok) api_weld_release(w);
	return ok;
}

bool api_weld_mesh(const float *pos, uint32_t nv, const uint32_t *indices, uint32_t ni, const uint32_t *group,
                   size_t groups, uint32_t *idx, struct api_welded *out)
{
	memset(out, 0, sizeof *out);
	struct api_weld sorted = {0};
	if (!group) {
		if (!api_weld_sort(pos, nv, &sorted)) return false;
		group = sorted.group;
		groups = sorted.groups;
	}
	uint32_t *id = malloc((groups ? groups : 1) * sizeof *id), *last = NULL;
	bool ok = id != NULL;
	if (ok) {
		memset(id, 0xff, groups * sizeof *id);
		for (uint32_t i = 0; i < ni; i++) {
			uint32_t *g = &id[group[indices[i]]];
			if (*g == ~0u) *g = (uint32_t)out->count++;
			idx[i] = *g;
		}
	}
	free(id);
	api_weld_release(&sorted);
	size_t n = out->count ? out->count : 1;
	out->pos = malloc(n * 12);
	out->rep = malloc(n * sizeof *out->rep);
	last = malloc(n * sizeof *last);
	if (!ok || !out->pos || !out->rep || !last) {
		free(last);
		return false;
	}
	/* The first and the last vertex the indices name in each group. */
	memset(out->rep, 0xff, out->count * sizeof *out->rep);
	memset(last, 0, out->count * sizeof *last);
	for (uint32_t i = 0; i < ni; i++) {
		uint32_t v = indices[i], c = idx[i];
		if (v < out->rep[c]) out->rep[c] = v;
		if (v > last[c]) last[c] = v;
	}
	for (size_t c = 0; c < out->count; c++) memcpy(out->pos + 3 * c, pos + 3 * (size_t)last[c], 12);
	free(last);
	return true;
}

void api_welded_release(struct api_welded *w)
{
	free(w->pos);
	free(w->rep);
	memset(w, 0, sizeof *w);
}
