/*
 * renderer/cost.c — the deadline's cost model and the fragments a draw may cover in a view
 * (see cost.h).
 */
#include <math.h>
#include "caster_level.h"
#include "casters.h"
#include "contact.h"
#include "cost.h"

/* Cost model for the first band and for grouping shadow views, in lavapipe milliseconds (a
 * GPU is faster: the model then only makes the first band smaller than needed, and measured
 * times take over from the second band on). On the high side: an underestimate lets one submit
 * run past a deadline. But not far: every band redraws every triangle (and repeats the
 * visibility pass's), and the measured rows are never trusted below a quarter of the estimate
 * (rnd_pacer_band_rows). Calibrated on 26 bench scenes (ninth landing): the main pass's
 * estimate is 0.6x (five stacked layers of small two-sided triangles) to 4.5x (16 soft lights)
 * of its time, mostly 1-2.5x. It had been 20-200x since the filters got cheaper, and under
 * umbrad's default 30 s deadline (slices of 1 s) a render of 0.02-0.3 s was cut into bands: the
 * ogre OBJ under three soft lights took 262 ms instead of 140, 16 soft lights 166 instead of
 * 141. */
#define EST_MS_PER_PIXEL_UNIT 1.5e-5 /* one pixel, one unit of shading (rnd_cost_pixel_units) */
#define EST_MS_PER_BAND 3.0          /* a band's clears, resolve and copy */
#define EST_MS_PER_TRIANGLE 3e-4     /* main pass: vertex work, repeated in every band */
#define EST_MS_PER_TEXEL 5e-6        /* shadow map clear, raster, copy into the atlas */
#define EST_MS_PER_CASTER 1e-4       /* depth-only triangle */
#define EST_MS_PER_DEPTH_FRAG 2e-6   /* depth-only fragment beyond the map's first layer (cost.h) */

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

/* Shadow view v: its triangles (*tris) and their fill beyond one layer over the map, in
 * milliseconds. The first layer is in the per-texel term (clear, raster, copy). */
double rnd_cost_shadow_view_ms(const struct rnd_shadow_plan *sp, const struct rnd_light *lights,
                               const struct draw *draws, uint32_t ndraw, uint32_t v, uint64_t *tris)
{
	const struct umbra_shadow_view *sv = &sp->views[v];
	double res = sv->rect[2], fill = 0;
	int cull;
	*tris = 0;
	for (uint32_t i = 0; i < ndraw; i++) {
		float raise;
		if (!rnd_shadow_view_draws(sp, lights, draws, v, i, &cull)) continue;
		/* the triangles it draws: the environment's maps may draw a caster level (caster_level.h) */
		struct draw d = rnd_caster_view_draw(sp, lights, v, &draws[i], &cull, &raise);
		*tris += d.index_count / 3;
		fill += rnd_cost_fill(sv->view_proj, res, res, &d.bounds, d.area, d.index_count / 3, d.closed);
	}
	double beyond = fill > res * res ? fill - res * res : 0;
	return res * res * EST_MS_PER_TEXEL + (double)*tris * EST_MS_PER_CASTER + beyond * EST_MS_PER_DEPTH_FRAG;
}

/* Shading work per pixel, in units of a hard-shadowed light's. */
double rnd_cost_pixel_units(const struct rnd_scene *sc, const struct rnd_shadow_plan *sp, bool vis, uint32_t aov_passes)
{
	double u = 1;
	for (uint32_t i = 0; i < sc->light_count; i++) {
		const struct rnd_light_plan *lp = &sp->lights[i];
		if (!lp->view_count) { u += 0.5; continue; }
		switch (lp->filter) {
		case UMBRA_FILTER_PCF: u += 1 + 0.5 * lp->pcf_radius; break;
		case UMBRA_FILTER_PCSS: u += 4; break;
		case UMBRA_FILTER_MOMENTS: u += 1.5; break;
		default: u += 1; break;
		}
		if (lp->view_count > 1 && sc->lights[i].type == RND_LIGHT_DIRECTIONAL) u += 2;   /* cascades, levels */
		if (rnd_contact_on(sc, sp, i)) u += 4;                                           /* the march */
	}
	if (vis) u += 4;   /* the visibility pass's own passes */
	if (sc->output.msaa > 1) u *= 1.5;
	if (sc->output.pixels == RND_PIXELS_RGBA32F) u *= 1.5;   /* float targets, resolve and copy */
	return u * (1 + 3 * aov_passes);
}

void rnd_cost_main(const struct rnd_scene *sc, const float view_proj[16], const struct draw *draws, uint32_t ndraw,
                   double units, double *row_ms, double *fixed_ms)
{
	uint64_t tris = 0;
	for (uint32_t i = 0; i < ndraw; i++) tris += draws[i].cam_index_count / 3;
	/* Geometry stacked many layers deep costs per layer (cost.h): a band of rows sized as if
	 * each pixel were covered once had run a 10 s submit past a 3 s deadline. */
	double fill = 0;
	for (uint32_t i = 0; i < ndraw; i++)
		fill += rnd_cost_fill(view_proj, sc->width, sc->height, &draws[i].bounds, draws[i].area,
		                      draws[i].cam_index_count / 3, draws[i].closed);
	*row_ms = sc->width * units * EST_MS_PER_PIXEL_UNIT * rnd_cost_layer_factor(fill, sc->width, sc->height);
	/* lavapipe shades each triangle's 4x4 blocks: a triangle costs more where a pixel does */
	*fixed_ms = EST_MS_PER_BAND + (double)tris * EST_MS_PER_TRIANGLE * (1 + units / 4);
}
