/* tests/gpu — the shadow-visibility metrics of ../shared/truth/score.py over stored references
 * (test_truth.c: the analytic tracer's; test_truth_cycles.c: Blender Cycles'), and the render +
 * score step both test files share. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "truth_score.h"

static bool is_edge(const float *t, int w, int h, int x, int y)
{
	bool s = t[y * w + x] < 0.5f;
	static const int d[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
	for (int k = 0; k < 4; k++) {
		int nx = x + d[k][0], ny = y + d[k][1];
		if (nx >= 0 && ny >= 0 && nx < w && ny < h && (t[ny * w + nx] < 0.5f) != s) return true;
	}
	return false;
}

static double laplacian(const float *v, int w, int x, int y)
{
	return 4.0 * v[y * w + x] - v[y * w + x - 1] - v[y * w + x + 1] - v[(y - 1) * w + x] - v[(y + 1) * w + x];
}

void truth_score(const float *truth, const float *cand, const float *mask, const float *edge, int w, int h,
                 struct truth_score *s)
{
	memset(s, 0, sizeof *s);
	uint8_t *near_edge = calloc((size_t)w * h, 1);
	if (!near_edge) return;
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++)
			if (is_edge(truth, w, h, x, y))
				for (int dy = -2; dy <= 2; dy++)
					for (int dx = -2; dx <= 2; dx++)
						if (x + dx >= 0 && y + dy >= 0 && x + dx < w && y + dy < h) near_edge[(y + dy) * w + x + dx] = 1;
	/* Within 8 px (Chebyshev) of a geometry edge: where shadows meet their casters. */
	uint8_t *near_geom = calloc((size_t)w * h, 1);
	if (!near_geom) { free(near_edge); return; }
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++)
			if (edge[y * w + x] > 0.5f)
				for (int dy = -8; dy <= 8; dy++)
					for (int dx = -8; dx <= 8; dx++)
						if (x + dx >= 0 && y + dy >= 0 && x + dx < w && y + dy < h) near_geom[(y + dy) * w + x + dx] = 1;
	double se = 0;
	long inter = 0, uni = 0, core = 0, core_bad = 0, pen = 0;
	long contact = 0, contact_missing = 0, core_lit = 0, core_false = 0;
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			int i = y * w + x;
			if (mask[i] < 0.5f || edge[i] > 0.5f) continue;
			s->valid++;
			double e = cand[i] - truth[i];
			se += e * e;
			bool t = truth[i] < 0.5f, c = cand[i] < 0.5f;
			s->shadow += t;
			inter += t && c;
			uni += t || c;
			if (!near_edge[i]) { core++; core_bad += t != c; }
			if (!near_edge[i] && !t) { core_lit++; core_false += c; }
			if (near_geom[i] && t) { contact++; contact_missing += !c; }
			if (x > 0 && y > 0 && x < w - 1 && y < h - 1 && truth[i] > 0.05f && truth[i] < 0.95f) {
				double lc = laplacian(cand, w, x, y), lt = laplacian(truth, w, x, y);
				s->hf_cand += lc * lc;
				s->hf_truth += lt * lt;
				pen++;
			}
		}
	s->rmse = s->valid ? sqrt(se / s->valid) : 0;
	s->iou = uni ? (double)inter / uni : 1;
	s->disagree_core = core ? (double)core_bad / core : 0;
	if (pen) { s->hf_cand /= pen; s->hf_truth /= pen; }
	s->missing_contact = contact ? (double)contact_missing / contact : 0;
	s->false_core = core_lit ? (double)core_false / core_lit : 0;
	free(near_edge);
	free(near_geom);
}

/* Replaces the first `from` in doc by `to` (a new string; NULL when absent or out of memory). */
char *truth_replaced(const char *doc, const char *from, const char *to)
{
	const char *at = strstr(doc, from);
	if (!at) return NULL;
	size_t head = (size_t)(at - doc), nf = strlen(from), nt = strlen(to), tail = strlen(at + nf);
	char *out = malloc(head + nt + tail + 1);
	if (!out) return NULL;
	memcpy(out, doc, head);
	memcpy(out + head, to, nt);
	memcpy(out + head + nt, at + nf, tail + 1);
	return out;
}

/* Renders doc (a debug "shadow" view) and scores its visibility; keeps the image in *img. */
bool truth_render_scored(const char *doc, const float *truth, const float *mask, const float *edge, int w, int h,
                         struct rnd_image *img, struct truth_score *s)
{
	float *cand = malloc(sizeof *cand * w * h);
	bool ok = cand && gpu_render(img, "%s", doc);
	if (ok) {
		for (int y = 0; y < h; y++)
			for (int x = 0; x < w; x++) cand[y * w + x] = gpu_px8(img, x, y)[0] / 255.0f;
		truth_score(truth, cand, mask, edge, w, h, s);
	}
	free(cand);
	return ok;
}
