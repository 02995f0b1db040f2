/* tests/unit/plan_util.h — what the plan's unit tests (test_plan_*.c, test_camera.c) share: points
 * through the plan's matrices in double, boxes, a one-plane scene with one light, cameras. */
#ifndef UMBRA_TESTS_PLAN_UTIL_H
#define UMBRA_TESTS_PLAN_UTIL_H

#include <stdbool.h>
#include "umbra/rnd.h"
#include "umbra/rnd_math.h"

#define PI_D 3.14159265358979323846

/* Clip-space transform of a world point in double (the matrix entries are the plan's floats). */
void clip4(const float m[16], const double p[3], double c[4]);
/* x/w, y/w, z/w; returns w. */
double ndc3(const float m[16], const double p[3], double n[3]);
bool inside_clip(const double n[3], double eps);
void set_box(struct rnd_aabb *b, float x0, float y0, float z0, float x1, float y1, float z1);
void corner(const struct rnd_aabb *b, int i, double p[3]);
/* A scene with one plane of side `size` at y = 0 and one light; bounds computed here. */
struct fixture {
	struct rnd_scene scene;
	struct rnd_material mat;
	struct rnd_object obj;
	struct rnd_light light;
	struct rnd_aabb bounds;
};

/* f as that scene: a plane of side size, one light of type (its defaults). */
void fixture_init(struct fixture *f, float size, enum rnd_light_type type);
void set3(float v[3], float x, float y, float z);
/* fixture_init with a sun along dir and a single `fit` map. */
void fixture_fit_sun(struct fixture *f, float size, const float dir[3]);
/* Camera at pos looking at target, explicit near/far (0 = derived). */
void camera_at(struct rnd_camera *c, float px, float py, float pz, float tx, float ty, float tz, float znear,
               float zfar);
double frac_d(double x);
/* Distance between two fractional parts on the unit circle (0.9999 and 0.0001 are close). */
double frac_dist(double a, double b);

#endif
