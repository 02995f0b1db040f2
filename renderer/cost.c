/*
 * renderer/cost.c — fragments a draw may cover in a view (see cost.h).
 */
#include <math.h>
#include "cost.h"
#include "plan.h"

/* Row r (0..3) of a column-major 4x4 matrix, xyz part and w part. */
static void row(const float m[16], int r, double out[4])
{
	for (int c = 0; c < 4; c++) out[c] = m[c * 4 + r];
}

double rnd_cost_fill(const float view_proj[16], double vp_w, double vp_h, const struct rnd_aabb *b, double area,
                     uint64_t tris, bool closed)
{
	if (!tris || rnd_aabb_is_empty(b) || !rnd_aabb_in_frustum(b, view_proj, true)) return 0.0;
	double r0[4], r1[4], r3[4];
	row(view_proj, 0, r0);
	row(view_proj, 1, r1);
	row(view_proj, 3, r3);
	/* The box's corners projected: the nearest w (view depth; 1 everywhere for an orthographic
	 * view) and the pixels the box covers, clipped to the view. w is affine, so a corner has
	 * the smallest; a box reaching behind the eye may cover the whole view. */
	double wmin = INFINITY, wmax = -INFINITY, x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
	for (int k = 0; k < 8; k++) {
		double p[3] = {k & 1 ? b->max[0] : b->min[0], k & 2 ? b->max[1] : b->min[1], k & 4 ? b->max[2] : b->min[2]};
		double w = r3[0] * p[0] + r3[1] * p[1] + r3[2] * p[2] + r3[3];
		double x = (r0[0] * p[0] + r0[1] * p[1] + r0[2] * p[2] + r0[3]) / w;
		double y = (r1[0] * p[0] + r1[1] * p[1] + r1[2] * p[2] + r1[3]) / w;
		if (w < wmin) wmin = w;
		if (w > wmax) wmax = w;
		if (x < x0) x0 = x;
		if (x > x1) x1 = x;
		if (y < y0) y0 = y;
		if (y > y1) y1 = y;
	}
	double covered = vp_w * vp_h;
	if (wmin > 1e-6)
		covered = (fmin(x1, 1.0) - fmax(x0, -1.0)) * 0.5 * vp_w * (fmin(y1, 1.0) - fmax(y0, -1.0)) * 0.5 * vp_h;
	if (!(covered > 0)) return 0.0;
	/* A closed surface covers its outline at most twice over if convex (front and back): the
	 * estimate's cap for one, where a view close to it makes each triangle look huge (a point
	 * light 5 cm from a cylinder: 192 triangles of 1024^2 texels each, 800 ms, for ~20). */
	double cap = (closed && tris > 2 ? 2.0 : (double)tris) * covered;
	if (!(wmin > 1e-6)) return cap;
	/* A world parallelogram a x b projects to (r0.a)(r1.b) - (r0.b)(r1.a) = (r0 x r1).(a x b)
	 * clip units, divided by w^2: at most |r0 x r1| times its area (exact for an orthographic
	 * view; for a perspective one on its axis, within ~2x off it). The area taken as spread
	 * evenly over the box's depths [wmin, wmax], where 1/w^2 averages 1/(wmin wmax): with
	 * 1/wmin^2 a box reaching from beside a spot light to the floor counted 800 ms of shadow
	 * map (studio-spots; it takes ~20). An estimate, not a bound. Clip [-1, 1] is vp pixels. */
	double cx = r0[1] * r1[2] - r0[2] * r1[1], cy = r0[2] * r1[0] - r0[0] * r1[2], cz = r0[0] * r1[1] - r0[1] * r1[0];
	double scale = sqrt(cx * cx + cy * cy + cz * cz) / (wmin * wmax) * 0.25 * vp_w * vp_h;
	double fill = area * scale;
	return fill < cap ? fill : cap;
}

double rnd_cost_layer_factor(double fill, double w, double h)
{
	double px = w * h;
	if (!(px > 0)) return 1.0;
	double layers = fill / px;
	return layers > RND_COST_LAYERS_CALIBRATED ? layers / RND_COST_LAYERS_CALIBRATED : 1.0;
}
