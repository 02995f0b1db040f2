/*
 * renderer/proxy.c — a camera's cap of few triangles for an analytic sphere (see proxy.h).
 *
 * The cap is a pole facing the camera and rings of vertices around the axis from the sphere's
 * centre towards the camera, out to the outline (the circle where the camera's rays graze the
 * sphere). Neighbouring vertices inside are at most `step` apart (their chords lie within
 * RND_PROXY_STEP_PIXELS of the sphere), each ring with as few vertices as that allows; the
 * outline ring has as many as lod.h's pixel bound asks of the sphere's outline, raised so its
 * chords straddle the outline as the tessellated sphere's do (rnd_lod_radius). Rings of
 * different counts are zipped by angle.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "lod.h"
#include "proxy.h"

#define PI_D 3.14159265358979323846
/* The widest step inside, radians: far below it a chord's depth error is what limits. */
#define RND_PROXY_MAX_STEP 0.5
/* Fewest vertices of an inner ring. */
#define RND_PROXY_MIN_RING 6u
/* Most rings (step >= pi / 2 / 128: a sphere of ~10^5 pixels' radius). */
#define RND_PROXY_MAX_RINGS 128u

static uint32_t rings_of(const struct rnd_proxy *p, double edge, double theta[RND_PROXY_MAX_RINGS + 1],
                         uint32_t count[RND_PROXY_MAX_RINGS + 1]);

/* Whether sc's scene and o's material allow a proxy at all (see proxy.h). */
static bool proxy_allowed(const struct rnd_scene *sc, const struct rnd_object *o)
{
	if (o->shape != RND_SHAPE_SPHERE) return false;
	if (sc->material_count) {
		const struct rnd_material *m = &sc->materials[o->material];
		if (m->alpha_mode != RND_ALPHA_OPAQUE) return false;
		for (int k = 0; k < RND_TEX_SLOTS; k++)
			if (m->textures[k]) return false;
	}
	for (uint32_t i = 0; i < sc->light_count; i++)
		if (sc->lights[i].shadow.enabled && sc->lights[i].shadow.contact_enabled) return false;
	return true;
}

/* The uniform scale of o's model (no shear); 0 when it scales its axes differently. */
static double uniform_scale(const float m[16])
{
	double c[3][3], l[3];
	for (int i = 0; i < 3; i++) {
		for (int k = 0; k < 3; k++) c[i][k] = m[4 * i + k];
		l[i] = sqrt(c[i][0] * c[i][0] + c[i][1] * c[i][1] + c[i][2] * c[i][2]);
	}
	if (!(l[0] > 0.0)) return 0.0;
	for (int i = 0; i < 3; i++) {
		if (fabs(l[i] / l[0] - 1.0) > 1e-4) return 0.0;
		int j = (i + 1) % 3;
		if (fabs(c[i][0] * c[j][0] + c[i][1] * c[j][1] + c[i][2] * c[j][2]) > 1e-4 * l[0] * l[0]) return 0.0;
	}
	return l[0];
}

/* Places proxy p (its sphere, outline count and lift set) for camera cam: the axis, the
 * outline's angle and raised radius, the eye. False where the camera is inside the sphere or
 * the near plane cuts it (which would cut the cap and show that it has no back). */
static bool place(struct rnd_proxy *p, const struct rnd_camera_plan *cam)
{
	double r = p->radius, a[3], dist = 0.0, ahead = 0.0;
	for (int k = 0; k < 3; k++) {
		a[k] = (double)cam->pos[k] - p->centre[k];
		dist += a[k] * a[k];
		ahead -= a[k] * cam->fwd[k];
	}
	dist = sqrt(dist);
	if (!(ahead - r > 1.01 * cam->znear)) return false;
	if (cam->user_far > 0.0f && !(ahead + r < cam->zfar)) return false;   /* a far plane through it */
	if (cam->ortho) {
		for (int k = 0; k < 3; k++) a[k] = -cam->fwd[k];
		dist = INFINITY;
	} else {
		if (!(dist > 1.001 * r)) return false;
		for (int k = 0; k < 3; k++) a[k] /= dist;
	}
	double edge = cam->ortho ? 0.5 * PI_D : acos(r / dist);
	for (int k = 0; k < 3; k++) {
		p->axis[k] = (float)a[k];
		p->eye[k] = cam->pos[k];
	}
	p->edge = (float)edge;
	p->outline_radius = (float)(2.0 * r * sin(edge) / (1.0 + cos(PI_D / p->outline)));
	p->ortho = cam->ortho;
	return true;
}

bool rnd_proxy_plan(const struct rnd_scene *sc, const struct rnd_object *o, const struct rnd_camera_plan *cam, float w,
                    float h, uint32_t segments, struct rnd_proxy *out)
{
	memset(out, 0, sizeof *out);
	if (!proxy_allowed(sc, o)) return false;
	double scale = uniform_scale(o->model);
	double r = fabs((double)o->radius) * scale;
	if (!(r > 0.0) || !isfinite(r)) return false;
	struct rnd_proxy p = {.radius = (float)r, .outline = 8};
	for (int k = 0; k < 3; k++) p.centre[k] = o->model[12 + k];
	if (!place(&p, cam)) return false;
	float pw = rnd_lod_pixel_world(cam->view_proj, w, h, p.centre, p.radius, cam->ortho ? 0.0f : cam->znear);
	if (!(pw > 0.0f) || !isfinite(pw)) return false;
	uint32_t n = rnd_lod_circle_segments(p.radius * sinf(p.edge), RND_LOD_PIXEL_ERROR * pw);
	if (n < 8) n = 8;
	/* Fewer segments than the outline needs were asked for: the facets are what was asked. */
	if (n == UINT32_MAX || n > segments || n > (1u << 16)) return false;
	p.outline = n;
	place(&p, cam);   /* the outline's radius for that count */
	double depth = (double)RND_PROXY_STEP_PIXELS * pw;
	/* A triangle's plane dips deepest at the centre of its circumcircle, whose angular radius is
	 * about the triangle's longest side over sqrt(2) for the right triangles of a ring pair
	 * and somewhat more where rings of different counts are zipped: sides of `step` keep it
	 * within acos(1 - depth / r) (tests/unit/test_proxy.c measures the deepest). */
	double step = depth >= r ? RND_PROXY_MAX_STEP : acos(1.0 - depth / r);
	if (step > RND_PROXY_MAX_STEP) step = RND_PROXY_MAX_STEP;
	p.step = (float)step;
	p.count_edge = p.edge;
	p.pixel = pw;
	p.lift = (float)(((double)rnd_lod_radius(fabsf(o->radius), segments, o->segments) - fabs((double)o->radius)) * scale);
	*out = p;
	return true;
}

bool rnd_proxy_refit(struct rnd_proxy *p, const struct rnd_camera_plan *cam, bool *moved)
{
	/* Placed again even where it fits: the render's near and far planes come from the
	 * tessellated bounds too. The counts stay (the vertices and indices the render reserved):
	 * the camera moved by a small fraction of the sphere's size, the pixel and the step with it. */
	*moved = !rnd_proxy_fits(p, cam);
	struct rnd_proxy q = *p;
	if (!place(&q, cam)) {
		p->outline = 0;
		return false;
	}
	if (*moved) *p = q;
	return true;
}

bool rnd_proxy_fits(const struct rnd_proxy *p, const struct rnd_camera_plan *cam)
{
	if (!p->outline || cam->ortho != p->ortho) return false;
	/* The grazing circle moves by about the eye's move times R / d (perspective), or R times the
	 * direction's turn (orthographic). */
	double move = 0.0, d = 0.0;
	for (int k = 0; k < 3; k++) {
		double e = cam->ortho ? -cam->fwd[k] - p->axis[k] : cam->pos[k] - p->eye[k];
		move += e * e;
		d += ((double)p->eye[k] - p->centre[k]) * ((double)p->eye[k] - p->centre[k]);
	}
	double shift = sqrt(move) * p->radius / (cam->ortho ? 1.0 : sqrt(d));
	return shift <= p->pixel / 128.0;
}

/* Rings 1..rings (the last the outline at `edge`): theta[j] evenly spaced, at most `step`
 * apart, each with count[j] vertices at most `step` apart (never more than the outline). Near
 * the outline the view ray grazes the sphere, so a chord's dip along the normal is many times
 * that along the ray, which the depth test compares: for thumb-512 up to 6 pixels there, the
 * tessellated sphere's own chords up to 9 (tests/unit/test_proxy.c measures both). Counts come
 * from the planned edge, so that a proxy placed again (another edge) keeps them. Returns rings. */
static uint32_t rings_of(const struct rnd_proxy *p, double edge, double theta[RND_PROXY_MAX_RINGS + 1],
                         uint32_t count[RND_PROXY_MAX_RINGS + 1])
{
	double plan = p->count_edge;
	double k = ceil(plan / p->step);
	uint32_t rings = k < 2.0 ? 2u : k > RND_PROXY_MAX_RINGS ? RND_PROXY_MAX_RINGS : (uint32_t)k;
	for (uint32_t j = 1; j <= rings; j++) {
		theta[j] = edge * j / rings;
		double n = ceil(2.0 * PI_D * sin(plan * j / rings) / p->step);
		uint32_t c = n < RND_PROXY_MIN_RING ? RND_PROXY_MIN_RING : n > p->outline ? p->outline : (uint32_t)n;
		count[j] = j == rings ? p->outline : c;
	}
	return rings;
}

void rnd_proxy_counts(const struct rnd_proxy *p, uint32_t *vertex_count, uint32_t *index_count)
{
	*vertex_count = *index_count = 0;
	if (!p->outline) return;
	double theta[RND_PROXY_MAX_RINGS + 1];
	uint32_t count[RND_PROXY_MAX_RINGS + 1];
	uint32_t rings = rings_of(p, p->edge, theta, count);
	uint32_t nv = 1, tris = count[1];
	for (uint32_t j = 1; j <= rings; j++) {
		nv += count[j];
		if (j < rings) tris += count[j] + count[j + 1];
	}
	*vertex_count = nv;
	*index_count = 3 * tris;
}

static void put_vertex(struct rnd_vertex *v, const struct rnd_proxy *p, const double pos[3])
{
	memset(v, 0, sizeof *v);
	for (int k = 0; k < 3; k++) {
		v->pos[k] = (float)pos[k];
		/* the centre, for the fragment shaders: from the rounded position, so that position
		 * minus normal gives it back to the float of the centre (a small sphere far out) */
		v->nrm[k] = (float)((double)v->pos[k] - p->centre[k]);
	}
	v->uv[0] = p->radius;
	v->uv[1] = p->lift;
	memset(v->color, 255, sizeof v->color);
	v->tangent[0] = 127;
	v->tangent[3] = 127;
}

void rnd_proxy_write(const struct rnd_proxy *p, struct rnd_vertex *v, uint32_t *idx, uint32_t base_vertex)
{
	if (!p->outline) return;
	/* u, w across the axis with u x w = axis: angles run counter-clockwise seen from the camera. */
	double a[3] = {p->axis[0], p->axis[1], p->axis[2]}, t[3] = {1, 0, 0}, u[3], w[3];
	if (fabs(a[0]) > 0.9) t[0] = 0, t[1] = 1;
	u[0] = t[1] * a[2] - t[2] * a[1], u[1] = t[2] * a[0] - t[0] * a[2], u[2] = t[0] * a[1] - t[1] * a[0];
	double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
	for (int k = 0; k < 3; k++) u[k] /= lu;
	w[0] = a[1] * u[2] - a[2] * u[1], w[1] = a[2] * u[0] - a[0] * u[2], w[2] = a[0] * u[1] - a[1] * u[0];
	double pos[3];
	for (int k = 0; k < 3; k++) pos[k] = p->centre[k] + p->radius * a[k];
	put_vertex(&v[0], p, pos);
	double thetas[RND_PROXY_MAX_RINGS + 1];
	uint32_t count[RND_PROXY_MAX_RINGS + 1];
	uint32_t rings = rings_of(p, p->edge, thetas, count);
	uint32_t nv = 1, ni = 0, prev_first = 0, prev_n = 1;
	for (uint32_t j = 1; j <= rings; j++) {
		uint32_t n = count[j], first = nv;
		double theta = thetas[j];
		double along = p->radius * cos(theta), across = j == rings ? p->outline_radius : p->radius * sin(theta);
		for (uint32_t i = 0; i < n; i++) {
			double phi = 2.0 * PI_D * i / n, cu = cos(phi) * across, cw = sin(phi) * across;
			for (int k = 0; k < 3; k++) pos[k] = p->centre[k] + along * a[k] + cu * u[k] + cw * w[k];
			put_vertex(&v[nv++], p, pos);
		}
		/* Zip the previous ring (the pole: one vertex) to this one by angle. */
		uint32_t i = 0, k = 0;
		while (i < prev_n || k < n) {
			uint32_t ai = base_vertex + prev_first + i % prev_n, bk = base_vertex + first + k % n;
			bool outer = k < n && (i >= prev_n || (uint64_t)(k + 1) * prev_n <= (uint64_t)(i + 1) * n);
			if (prev_n == 1) outer = true;
			idx[ni++] = ai;
			idx[ni++] = bk;
			if (outer) {
				idx[ni++] = base_vertex + first + (k + 1) % n;
				k++;
			} else {
				idx[ni++] = base_vertex + prev_first + (i + 1) % prev_n;
				i++;
			}
			if (prev_n == 1 && k == n) break;
		}
		prev_first = first;
		prev_n = n;
	}
}
