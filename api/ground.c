/*
 * api/ground — exact world bounds per shape and the self-placing ground plane (see ground.h).
 */
#include <float.h>
#include <math.h>
#include "ground.h"

/* Element (row r, column c) of a column-major 4x4 matrix. */
#define M(m, r, c) ((double)(m)[(c) * 4 + (r)])

void api_object_bounds(const struct rnd_object *o, double lo[3], double hi[3])
{
	const float *m = o->model;
	if (o->shape == RND_SHAPE_MESH) {
		/* The transformed vertices themselves: a rotated mesh's corners of its local box would
		 * reach below its lowest vertex. */
		if (!o->positions) return;
		/* Known local bounds under a matrix without rotation or shear (each world axis a scale
		 * of one local axis): their image is exact, and no pass over the vertices is needed. */
		if (o->mesh_bounds && o->vertex_count && M(m, 0, 1) == 0.0 && M(m, 0, 2) == 0.0 && M(m, 1, 0) == 0.0 &&
		    M(m, 1, 2) == 0.0 && M(m, 2, 0) == 0.0 && M(m, 2, 1) == 0.0) {
			for (int k = 0; k < 3; k++) {
				double a = M(m, k, k) * o->mesh_bounds[k] + M(m, k, 3), b = M(m, k, k) * o->mesh_bounds[3 + k] + M(m, k, 3);
				lo[k] = fmin(lo[k], fmin(a, b));
				hi[k] = fmax(hi[k], fmax(a, b));
			}
			return;
		}
		/* The matrix in locals and branch-free min / max: this runs over every vertex of a
		 * model on every request that frames or grounds it (1M triangles: ~10 -> ~3 ms). */
		double r[3][4], l[3], h[3];
		for (int k = 0; k < 3; k++) {
			for (int c = 0; c < 4; c++) r[k][c] = M(m, k, c);
			l[k] = lo[k];
			h[k] = hi[k];
		}
		const float *p = o->positions;
		for (uint32_t v = 0; v < o->vertex_count; v++, p += 3) {
			double x = p[0], y = p[1], z = p[2];
			for (int k = 0; k < 3; k++) {
				double w = r[k][0] * x + r[k][1] * y + r[k][2] * z + r[k][3];
				l[k] = w < l[k] ? w : l[k];
				h[k] = w > h[k] ? w : h[k];
			}
		}
		for (int k = 0; k < 3; k++) {
			lo[k] = l[k];
			hi[k] = h[k];
		}
		return;
	}
	for (int k = 0; k < 3; k++) {
		/* Half extent along world axis k of the shape centred at its origin under the linear part. */
		double a = M(m, k, 0), b = M(m, k, 1), c = M(m, k, 2), h;
		switch (o->shape) {
		case RND_SHAPE_PLANE:
			h = 0.5 * (o->size[0] * fabs(a) + o->size[2] * fabs(c));
			break;
		case RND_SHAPE_BOX:
			h = 0.5 * (o->size[0] * fabs(a) + o->size[1] * fabs(b) + o->size[2] * fabs(c));
			break;
		case RND_SHAPE_SPHERE: /* an ellipsoid under scale: r times the row's length */
			h = o->radius * sqrt(a * a + b * b + c * c);
			break;
		case RND_SHAPE_CYLINDER: /* axis +Y: the caps' circles plus half the height */
			h = 0.5 * o->height * fabs(b) + o->radius * sqrt(a * a + c * c);
			break;
		default:
			return;
		}
		double t = M(m, k, 3);
		if (t - h < lo[k]) lo[k] = t - h;
		if (t + h > hi[k]) hi[k] = t + h;
	}
}

void api_ground_place(struct rnd_object *objs, uint32_t n, const struct rnd_material *mats, const float *margin)
{
	double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
	bool any_ground = false;
	for (uint32_t i = 0; i < n; i++) {
		const struct rnd_object *o = &objs[i];
		if (margin[i] > 0) any_ground = true;
		if (!rnd_object_frames(o, mats)) continue;
		api_object_bounds(o, lo, hi);
	}
	if (!any_ground) return;
	double centre[3] = {0, 0, 0}, extent = 1;
	if (lo[0] <= hi[0]) {
		extent = 0;
		for (int k = 0; k < 3; k++) {
			centre[k] = 0.5 * (lo[k] + hi[k]);
			extent = fmax(extent, hi[k] - lo[k]);
		}
		/* A flat object (a quad lying down) still gets a ground the size of its footprint. */
		if (!(extent > 0)) extent = 1;
		/* Just below the lowest point, not at it: a model's own bottom face (a quad lying down,
		 * TwoSidedPlane) coplanar with the ground z-fought with it, and the shadow catcher's
		 * background showed through it in stripes. */
		centre[1] = lo[1] - API_GROUND_GAP * extent;
	}
	for (uint32_t i = 0; i < n; i++) {
		if (!(margin[i] > 0)) continue;
		struct rnd_object *g = &objs[i];
		float side = (float)(margin[i] * extent);
		g->size[0] = side; g->size[1] = 0; g->size[2] = side;
		for (int k = 0; k < 16; k++) g->model[k] = (k % 5 == 0) ? 1.0f : 0.0f;
		for (int k = 0; k < 3; k++) g->model[12 + k] = (float)centre[k];
	}
}
