/*
 * api/model_up — "up": "auto" (see model_up.h).
 */
#include <math.h>
#include "model_up.h"

/* What the two walks over the model's triangles gather. */
struct up_walk {
	bool measure;                 /* the first walk: the box; the second: the areas */
	double lo[3], hi[3];
	double total, flat[3];        /* twice the areas: all, and flat on the lowest plane facing down */
};

/* One triangle (corners a, b, c in the model's space) into w. */
static void visit(struct up_walk *w, const double a[3], const double b[3], const double c[3])
{
	if (!w->measure) {
		for (int r = 0; r < 3; r++) {
			w->lo[r] = fmin(w->lo[r], fmin(a[r], fmin(b[r], c[r])));
			w->hi[r] = fmax(w->hi[r], fmax(a[r], fmax(b[r], c[r])));
		}
		return;
	}
	double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
	double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
	double area2 = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
	if (!(area2 > 0)) return;
	w->total += area2;
	for (int ax = 1; ax < 3; ax++) {
		double eps = 0.01 * (w->hi[ax] - w->lo[ax]), lo = w->lo[ax];
		if (-n[ax] / area2 >= 0.9 && a[ax] - lo <= eps && b[ax] - lo <= eps && c[ax] - lo <= eps) w->flat[ax] += area2;
	}
}

/* Every triangle of every instance of m, transformed by its instance, into w. */
static void walk(const struct api_model *m, struct up_walk *w)
{
	for (uint32_t i = 0; i < m->instance_count; i++) {
		const struct api_model_mesh *me = &m->meshes[m->instances[i].mesh];
		const float *mm = m->instances[i].model;
		for (uint32_t t = 0; t < me->index_count / 3; t++) {
			double p[3][3];
			for (int k = 0; k < 3; k++) {
				const float *v = me->positions + 3 * (size_t)me->indices[3 * (size_t)t + (uint32_t)k];
				for (int r = 0; r < 3; r++) p[k][r] = mm[r] * v[0] + mm[4 + r] * v[1] + mm[8 + r] * v[2] + mm[12 + r];
			}
			visit(w, p[0], p[1], p[2]);
		}
	}
}

char api_model_auto_up(const struct api_model *m, double *contact_y, double *contact_z)
{
	struct up_walk w = {.lo = {INFINITY, INFINITY, INFINITY}, .hi = {-INFINITY, -INFINITY, -INFINITY}};
	walk(m, &w);
	w.measure = true;
	walk(m, &w);
	double sy = w.total > 0 ? w.flat[1] / w.total : 0, sz = w.total > 0 ? w.flat[2] / w.total : 0;
	if (contact_y) *contact_y = sy;
	if (contact_z) *contact_z = sz;
	if (m->format == API_MODEL_GLB || m->format == API_MODEL_GLTF) return 'y';
	return sz > 0.02 && sz > 2 * sy ? 'z' : 'y';
}
