/* tests/unit/plan_util.c — the plan tests' shared helpers (plan_util.h). */
#include <math.h>
#include <string.h>
#include "plan_util.h"

/* Clip-space transform of a world point in double (the matrix entries are the plan's floats). */
void clip4(const float m[16], const double p[3], double c[4])
{
	for (int r = 0; r < 4; r++) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

/* x/w, y/w, z/w; returns w. */
double ndc3(const float m[16], const double p[3], double n[3])
{
	double c[4];
	clip4(m, p, c);
	for (int i = 0; i < 3; i++) n[i] = c[i] / c[3];
	return c[3];
}

bool inside_clip(const double n[3], double eps)
{
	return fabs(n[0]) <= 1.0 + eps && fabs(n[1]) <= 1.0 + eps && n[2] >= -eps && n[2] <= 1.0 + eps;
}

void set_box(struct rnd_aabb *b, float x0, float y0, float z0, float x1, float y1, float z1)
{
	b->min[0] = x0; b->min[1] = y0; b->min[2] = z0;
	b->max[0] = x1; b->max[1] = y1; b->max[2] = z1;
}

void corner(const struct rnd_aabb *b, int i, double p[3])
{
	p[0] = i & 1 ? b->max[0] : b->min[0];
	p[1] = i & 2 ? b->max[1] : b->min[1];
	p[2] = i & 4 ? b->max[2] : b->min[2];
}


void fixture_init(struct fixture *f, float size, enum rnd_light_type type)
{
	memset(f, 0, sizeof *f);
	rnd_scene_defaults(&f->scene);
	rnd_material_defaults(&f->mat);
	rnd_object_defaults(&f->obj);
	f->obj.shape = RND_SHAPE_PLANE;
	f->obj.size[0] = size; f->obj.size[1] = 0; f->obj.size[2] = size;
	rnd_light_defaults(&f->light, type);
	f->scene.materials = &f->mat; f->scene.material_count = 1;
	f->scene.objects = &f->obj; f->scene.object_count = 1;
	f->scene.lights = &f->light; f->scene.light_count = 1;
	set_box(&f->bounds, -0.5f * size, 0, -0.5f * size, 0.5f * size, 0, 0.5f * size);
}

void set3(float v[3], float x, float y, float z) { v[0] = x; v[1] = y; v[2] = z; }

/* fixture_init with a sun along dir and a single `fit` map. */
void fixture_fit_sun(struct fixture *f, float size, const float dir[3])
{
	fixture_init(f, size, RND_LIGHT_DIRECTIONAL);
	memcpy(f->light.direction, dir, sizeof f->light.direction);
	f->light.shadow.dir_mode = RND_DIR_FIT;
}

/* Camera at pos looking at target, explicit near/far (0 = derived). */
void camera_at(struct rnd_camera *c, float px, float py, float pz, float tx, float ty, float tz,
                      float znear, float zfar)
{
	set3(c->position, px, py, pz);
	set3(c->target, tx, ty, tz);
	set3(c->up, 0, 1, 0);
	c->near = znear; c->far = zfar;
}

double frac_d(double x) { return x - floor(x); }
/* Distance between two fractional parts on the unit circle (0.9999 and 0.0001 are close). */
double frac_dist(double a, double b)
{
	double d = fabs(frac_d(a) - frac_d(b));
	return d > 0.5 ? 1.0 - d : d;
}
