/* tests — renderer/math.c against hand-computed values (rnd_math.h conventions). */
#include <math.h>
#include <string.h>
#include "test.h"
#include "umbra/rnd_math.h"

#define EPS 1e-5f
#define PI_F 3.14159265358979323846f

static bool near_f(float a, float b, float eps)
{
	return fabsf(a - b) <= eps * (1.0f + fabsf(b));
}

static bool near_v3(const float a[3], float x, float y, float z, float eps)
{
	return near_f(a[0], x, eps) && near_f(a[1], y, eps) && near_f(a[2], z, eps);
}

static bool near_m4(const float a[16], const float b[16], float eps)
{
	for (int i = 0; i < 16; i++)
		if (!near_f(a[i], b[i], eps)) return false;
	return true;
}

/* Clip-space transform of a view-space point: returns x/w, y/w, z/w and w. */
static void project(const float m[16], const float p[3], float ndc[3], float *w)
{
	float c[4];
	for (int r = 0; r < 4; r++) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
	*w = c[3];
	for (int i = 0; i < 3; i++) ndc[i] = c[i] / c[3];
}

TEST(math_v3_basics)
{
	float a[3] = {1, 0, 0}, b[3] = {0, 1, 0}, c[3];
	rnd_v3_cross(c, a, b);
	CHECK(near_v3(c, 0, 0, 1, EPS), "x cross y = %g %g %g", c[0], c[1], c[2]);
	rnd_v3_cross(a, a, b); /* aliasing allowed */
	CHECK(near_v3(a, 0, 0, 1, EPS), "aliased cross");
	float d[3] = {3, 4, 12};
	CHECK(near_f(rnd_v3_length(d), 13.0f, EPS), "length %g", rnd_v3_length(d));
	CHECK(near_f(rnd_v3_dot(d, d), 169.0f, EPS), "dot");
	float n[3];
	CHECK(rnd_v3_normalize(n, d), "normalize ok");
	CHECK(near_v3(n, 3.0f / 13, 4.0f / 13, 12.0f / 13, EPS), "normalized");
	float z[3] = {0, 0, 0}, o[3] = {7, 7, 7};
	CHECK(!rnd_v3_normalize(o, z), "zero vector cannot be normalized");
	CHECK(near_v3(o, 0, 0, 0, 0), "out = a on failure");
	float inf[3] = {INFINITY, 0, 0};
	CHECK(!rnd_v3_normalize(o, inf), "infinite vector cannot be normalized");
	float s[3];
	rnd_v3_add(s, d, b); CHECK(near_v3(s, 3, 5, 12, EPS), "add");
	rnd_v3_sub(s, d, b); CHECK(near_v3(s, 3, 3, 12, EPS), "sub");
	rnd_v3_scale(s, d, 2); CHECK(near_v3(s, 6, 8, 24, EPS), "scale");
}

TEST(math_mat4_mul_order)
{
	/* T(1,2,3) * S(2,2,2) applied to (1,1,1) = 2*(1,1,1) + (1,2,3). */
	float t[16], s[16], m[16], p[3] = {1, 1, 1};
	rnd_mat4_identity(t); t[12] = 1; t[13] = 2; t[14] = 3;
	rnd_mat4_identity(s); s[0] = s[5] = s[10] = 2;
	rnd_mat4_mul(m, t, s);
	rnd_mat4_mul_point(p, m, p);
	CHECK(near_v3(p, 3, 4, 5, EPS), "T*S p = %g %g %g", p[0], p[1], p[2]);
	rnd_mat4_mul(m, s, t);
	float q[3] = {1, 1, 1};
	rnd_mat4_mul_point(q, m, q);
	CHECK(near_v3(q, 4, 6, 8, EPS), "S*T p = %g %g %g", q[0], q[1], q[2]);
}

TEST(math_look_at_maps_eye_and_target)
{
	float eye[3] = {4, 3, 4}, target[3] = {0, 0.8f, 0}, up[3] = {0, 1, 0}, v[16], p[3];
	rnd_mat4_look_at(v, eye, target, up);
	rnd_mat4_mul_point(p, v, eye);
	CHECK(near_v3(p, 0, 0, 0, 1e-5f), "eye -> %g %g %g", p[0], p[1], p[2]);
	float d[3];
	rnd_v3_sub(d, target, eye);
	float dist = rnd_v3_length(d);
	rnd_mat4_mul_point(p, v, target);
	CHECK(near_v3(p, 0, 0, -dist, 1e-5f), "target -> %g %g %g (dist %g)", p[0], p[1], p[2], dist);
	CHECK(near_f(rnd_mat4_det3(v), 1.0f, 1e-5f), "view is a rotation: det %g", rnd_mat4_det3(v));
	/* World up stays up in view space (y of a point above the target is positive). */
	float above[3] = {0, 1.8f, 0};
	rnd_mat4_mul_point(p, v, above);
	CHECK(p[1] > 0, "up maps to +y: %g", p[1]);
}

TEST(math_look_at_right_handed)
{
	/* Camera at +Z looking at the origin: +X world is to the right, +Y up (glTF default view). */
	float eye[3] = {0, 0, 5}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0}, v[16], p[3];
	rnd_mat4_look_at(v, eye, target, up);
	float expect[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -5, 1};
	CHECK(near_m4(v, expect, EPS), "view from +Z is a translation by -5");
	float x[3] = {1, 0, 0};
	rnd_mat4_mul_point(p, v, x);
	CHECK(near_v3(p, 1, 0, -5, EPS), "+X -> %g %g %g", p[0], p[1], p[2]);
}

TEST(math_look_at_up_parallel_uses_minus_z)
{
	/* Looking straight down with up +Y: up becomes -Z, so world -Z is image-up. */
	float eye[3] = {0, 5, 0}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0}, v[16], p[3];
	rnd_mat4_look_at(v, eye, target, up);
	for (int i = 0; i < 16; i++) REQUIRE(isfinite(v[i]), "finite view matrix");
	float mz[3] = {0, 0, -1}, px[3] = {1, 0, 0};
	rnd_mat4_mul_point(p, v, mz);
	CHECK(near_v3(p, 0, 1, -5, EPS), "-Z -> %g %g %g", p[0], p[1], p[2]);
	rnd_mat4_mul_point(p, v, px);
	CHECK(near_v3(p, 1, 0, -5, EPS), "+X -> %g %g %g", p[0], p[1], p[2]);
	/* Looking straight up, up = -Y (also parallel). */
	float eye2[3] = {0, -5, 0}, up2[3] = {0, -1, 0};
	rnd_mat4_look_at(v, eye2, target, up2);
	rnd_mat4_mul_point(p, v, mz);
	CHECK(near_v3(p, 0, 1, -5, EPS), "looking up: -Z -> %g %g %g", p[0], p[1], p[2]);
	/* A zero up is treated like a parallel one. */
	float zero[3] = {0, 0, 0};
	rnd_mat4_look_at(v, eye, target, zero);
	rnd_mat4_mul_point(p, v, mz);
	CHECK(near_v3(p, 0, 1, -5, EPS), "zero up: -Z -> %g %g %g", p[0], p[1], p[2]);
}

TEST(math_look_at_up_parallel_along_z_uses_plus_y)
{
	float eye[3] = {0, 0, 5}, target[3] = {0, 0, 0}, up[3] = {0, 0, 1}, v[16], p[3];
	rnd_mat4_look_at(v, eye, target, up);
	float y[3] = {0, 1, 0}, x[3] = {1, 0, 0};
	rnd_mat4_mul_point(p, v, y);
	CHECK(near_v3(p, 0, 1, -5, EPS), "+Y -> %g %g %g", p[0], p[1], p[2]);
	rnd_mat4_mul_point(p, v, x);
	CHECK(near_v3(p, 1, 0, -5, EPS), "+X -> %g %g %g", p[0], p[1], p[2]);
	/* From -Z looking +Z: +Y up, and +X is on the left. */
	float eye2[3] = {0, 0, -5};
	rnd_mat4_look_at(v, eye2, target, up);
	rnd_mat4_mul_point(p, v, y);
	CHECK(near_v3(p, 0, 1, -5, EPS), "from -Z: +Y -> %g %g %g", p[0], p[1], p[2]);
	rnd_mat4_mul_point(p, v, x);
	CHECK(near_v3(p, -1, 0, -5, EPS), "from -Z: +X -> %g %g %g", p[0], p[1], p[2]);
}

TEST(math_perspective_vulkan_clip)
{
	float fov = 60.0f * PI_F / 180.0f, aspect = 2.0f, n = 0.5f, f = 100.0f, m[16], ndc[3], w;
	rnd_mat4_perspective(m, fov, aspect, n, f);
	float pn[3] = {0, 0, -n}, pf[3] = {0, 0, -f};
	project(m, pn, ndc, &w);
	CHECK(near_f(ndc[2], 0.0f, 1e-5f), "near depth %g", ndc[2]);
	CHECK(near_f(w, n, 1e-6f), "w = distance %g", w);
	project(m, pf, ndc, &w);
	CHECK(near_f(ndc[2], 1.0f, 1e-5f), "far depth %g", ndc[2]);
	/* Top of the frustum at distance 10: y = 10 tan(fov/2) -> clip y/w = -1 (Vulkan y down). */
	float th = tanf(0.5f * fov);
	float top[3] = {0, 10 * th, -10}, right[3] = {10 * th * aspect, 0, -10};
	project(m, top, ndc, &w);
	CHECK(near_f(ndc[1], -1.0f, 1e-5f), "top y/w %g", ndc[1]);
	CHECK(ndc[2] > 0 && ndc[2] < 1, "depth inside 0..1: %g", ndc[2]);
	project(m, right, ndc, &w);
	CHECK(near_f(ndc[0], 1.0f, 1e-5f), "right x/w %g", ndc[0]);
	/* Depth increases with distance. */
	float a[3] = {0, 0, -2}, b[3] = {0, 0, -3}, da[3], db[3];
	project(m, a, da, &w); project(m, b, db, &w);
	CHECK(da[2] < db[2], "monotonic depth %g < %g", da[2], db[2]);
}

TEST(math_ortho_vulkan_clip)
{
	float m[16], ndc[3], w;
	rnd_mat4_ortho(m, -2, 4, -1, 3, 1, 11);
	float lbn[3] = {-2, -1, -1}, rtf[3] = {4, 3, -11}, mid[3] = {1, 1, -6};
	project(m, lbn, ndc, &w);
	CHECK(near_f(w, 1, 0) && near_v3(ndc, -1, 1, 0, 1e-6f), "left-bottom-near -> %g %g %g", ndc[0], ndc[1], ndc[2]);
	project(m, rtf, ndc, &w);
	CHECK(near_v3(ndc, 1, -1, 1, 1e-6f), "right-top-far -> %g %g %g", ndc[0], ndc[1], ndc[2]);
	project(m, mid, ndc, &w);
	CHECK(near_v3(ndc, 0, 0, 0.5f, 1e-6f), "centre -> %g %g %g", ndc[0], ndc[1], ndc[2]);
}

TEST(math_trs_hand_computed)
{
	float h = sqrtf(0.5f);
	float t[3] = {1, 2, 3}, qz[4] = {0, 0, h, h}, s[3] = {2, 3, 4}, m[16];
	rnd_mat4_trs(m, t, qz, s);
	/* Rz(90): x -> y, y -> -x. Columns: R e0 * 2, R e1 * 3, R e2 * 4, t. */
	float expect[16] = {0, 2, 0, 0, -3, 0, 0, 0, 0, 0, 4, 0, 1, 2, 3, 1};
	CHECK(near_m4(m, expect, 1e-6f), "TRS with Rz(90)");

	float zero[3] = {0, 0, 0}, one[3] = {1, 1, 1}, qy[4] = {0, h, 0, h}, qx[4] = {h, 0, 0, h}, p[3];
	rnd_mat4_trs(m, zero, qy, one);
	float ex[3] = {1, 0, 0};
	rnd_mat4_mul_point(p, m, ex);
	CHECK(near_v3(p, 0, 0, -1, 1e-6f), "Ry(90) +X -> %g %g %g", p[0], p[1], p[2]);
	rnd_mat4_trs(m, zero, qx, one);
	float ey[3] = {0, 1, 0};
	rnd_mat4_mul_point(p, m, ey);
	CHECK(near_v3(p, 0, 0, 1, 1e-6f), "Rx(90) +Y -> %g %g %g", p[0], p[1], p[2]);
}

TEST(math_trs_normalises_quaternion)
{
	float t[3] = {0, 0, 0}, s[3] = {1, 1, 1}, m1[16], m2[16], m3[16], id[16];
	float qn[4] = {0, 0.6f, 0, 0.8f}, qbig[4] = {0, 3, 0, 4}, qzero[4] = {0, 0, 0, 0};
	rnd_mat4_trs(m1, t, qn, s);
	rnd_mat4_trs(m2, t, qbig, s);
	CHECK(near_m4(m1, m2, 1e-6f), "scaled quaternion gives the same rotation");
	CHECK(near_f(rnd_mat4_det3(m2), 1.0f, 1e-6f), "rotation has det 1: %g", rnd_mat4_det3(m2));
	rnd_mat4_trs(m3, t, qzero, s);
	rnd_mat4_identity(id);
	CHECK(near_m4(m3, id, 0), "zero quaternion is the identity rotation");
}

TEST(math_invert_roundtrip)
{
	float h = sqrtf(0.5f);
	float t[3] = {1, -2, 3}, q[4] = {0.1f, h, 0.3f, h}, s[3] = {2, -0.5f, 3}, m[16], inv[16], p[16], id[16];
	rnd_mat4_trs(m, t, q, s);
	REQUIRE(rnd_mat4_invert(inv, m), "invertible");
	rnd_mat4_mul(p, inv, m);
	rnd_mat4_identity(id);
	CHECK(near_m4(p, id, 1e-5f), "inv(m) * m = I");
	rnd_mat4_mul(p, m, inv);
	CHECK(near_m4(p, id, 1e-5f), "m * inv(m) = I");

	float pr[16], pinv[16];
	rnd_mat4_perspective(pr, 1.0f, 1.5f, 0.1f, 50.0f);
	REQUIRE(rnd_mat4_invert(pinv, pr), "projection invertible");
	rnd_mat4_mul(p, pinv, pr);
	CHECK(near_m4(p, id, 1e-4f), "inv(P) * P = I");

	float sing[16], out[16];
	rnd_mat4_identity(sing); sing[5] = 0;
	for (int i = 0; i < 16; i++) out[i] = 42;
	CHECK(!rnd_mat4_invert(out, sing), "singular");
	for (int i = 0; i < 16; i++) CHECK(out[i] == 42, "out untouched at %d", i);
}

TEST(math_det3_sign)
{
	float t[3] = {5, 5, 5}, q[4] = {0.2f, 0.4f, 0.1f, 0.9f}, m[16];
	float s1[3] = {1, 2, 3}, s2[3] = {-1, 2, 3}, s3[3] = {-1, -1, -1};
	rnd_mat4_trs(m, t, q, s1);
	CHECK(near_f(rnd_mat4_det3(m), 6.0f, 1e-5f), "det = product of scales: %g", rnd_mat4_det3(m));
	rnd_mat4_trs(m, t, q, s2);
	CHECK(near_f(rnd_mat4_det3(m), -6.0f, 1e-5f), "mirror: %g", rnd_mat4_det3(m));
	rnd_mat4_trs(m, t, q, s3);
	CHECK(rnd_mat4_det3(m) < 0, "odd number of negative scales mirrors");
}

TEST(math_mul_point_and_dir)
{
	float m[16], p[3] = {1, 2, 3}, o[3];
	rnd_mat4_identity(m); m[12] = 10; m[13] = 20; m[14] = 30;
	rnd_mat4_mul_point(o, m, p);
	CHECK(near_v3(o, 11, 22, 33, EPS), "point translated");
	rnd_mat4_mul_dir(o, m, p);
	CHECK(near_v3(o, 1, 2, 3, EPS), "direction not translated");
	/* w divide: a matrix with w = 2 for every point halves it. */
	rnd_mat4_identity(m); m[15] = 2;
	rnd_mat4_mul_point(o, m, p);
	CHECK(near_v3(o, 0.5f, 1, 1.5f, EPS), "divided by w: %g %g %g", o[0], o[1], o[2]);
}

TEST(math_normal_matrix_keeps_perpendicular)
{
	float t[3] = {1, 1, 1}, q[4] = {0.3f, 0.1f, 0.2f, 0.9f}, s[3] = {4, 0.5f, -2}, m[16], nm[16];
	rnd_mat4_trs(m, t, q, s);
	REQUIRE(rnd_mat4_normal_matrix(nm, m), "normal matrix");
	/* A surface with normal n contains the tangents a, b; after transform, n' . (M a) = 0. */
	float n[3] = {1, 2, 2}, a[3] = {2, -1, 0}, b[3] = {0, 1, -1};
	float n2[3], a2[3], b2[3];
	rnd_mat4_mul_dir(n2, nm, n);
	rnd_mat4_mul_dir(a2, m, a);
	rnd_mat4_mul_dir(b2, m, b);
	CHECK(fabsf(rnd_v3_dot(n2, a2)) < 1e-4f, "n'.a' = %g", rnd_v3_dot(n2, a2));
	CHECK(fabsf(rnd_v3_dot(n2, b2)) < 1e-4f, "n'.b' = %g", rnd_v3_dot(n2, b2));
	/* Non-uniform scale by hand: S(2,1,1), normal (1,1,0) -> (0.5,1,0). */
	float sc[3] = {2, 1, 1}, z[3] = {0, 0, 0}, qi[4] = {0, 0, 0, 1}, n3[3] = {1, 1, 0};
	rnd_mat4_trs(m, z, qi, sc);
	REQUIRE(rnd_mat4_normal_matrix(nm, m), "normal matrix");
	rnd_mat4_mul_dir(n3, nm, n3);
	CHECK(near_v3(n3, 0.5f, 1, 0, EPS), "S(2,1,1) normal -> %g %g %g", n3[0], n3[1], n3[2]);
	CHECK(nm[12] == 0 && nm[13] == 0 && nm[14] == 0 && nm[15] == 1, "no translation");
	m[0] = 0;
	CHECK(!rnd_mat4_normal_matrix(nm, m), "singular");
}

TEST(math_aabb_ops)
{
	struct rnd_aabb b, o;
	rnd_aabb_empty(&b);
	CHECK(rnd_aabb_is_empty(&b), "empty");
	float p1[3] = {1, -2, 3}, p2[3] = {-1, 5, 0};
	rnd_aabb_add_point(&b, p1);
	CHECK(!rnd_aabb_is_empty(&b), "one point is not empty");
	rnd_aabb_add_point(&b, p2);
	CHECK(near_v3(b.min, -1, -2, 0, 0) && near_v3(b.max, 1, 5, 3, 0), "bounds of two points");
	rnd_aabb_empty(&o);
	rnd_aabb_union(&b, &o);
	CHECK(near_v3(b.min, -1, -2, 0, 0) && near_v3(b.max, 1, 5, 3, 0), "union with empty is a no-op");
	float p3[3] = {10, 10, 10};
	rnd_aabb_add_point(&o, p3);
	rnd_aabb_union(&b, &o);
	CHECK(near_v3(b.max, 10, 10, 10, 0) && near_v3(b.min, -1, -2, 0, 0), "union grows");
}

TEST(math_aabb_transform)
{
	struct rnd_aabb b = {{0, 0, 0}, {1, 2, 3}}, out;
	float h = sqrtf(0.5f), t[3] = {10, 0, 0}, q[4] = {0, h, 0, h}, s[3] = {1, 1, 1}, m[16];
	rnd_mat4_trs(m, t, q, s);
	rnd_aabb_transform(&out, &b, m);
	/* Ry(90): x' = z, z' = -x; then +10 in x. */
	CHECK(near_v3(out.min, 10, 0, -1, 1e-5f), "min %g %g %g", out.min[0], out.min[1], out.min[2]);
	CHECK(near_v3(out.max, 13, 2, 0, 1e-5f), "max %g %g %g", out.max[0], out.max[1], out.max[2]);
	/* 45 degrees about Z grows the box: unit cube -> x extent sqrt(2). */
	struct rnd_aabb c = {{-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}};
	float s8 = sinf(PI_F / 8), c8 = cosf(PI_F / 8), q45[4] = {0, 0, s8, c8}, z[3] = {0, 0, 0};
	rnd_mat4_trs(m, z, q45, s);
	rnd_aabb_transform(&out, &c, m);
	CHECK(near_f(out.max[0], sqrtf(2) / 2, 1e-5f) && near_f(out.min[1], -sqrtf(2) / 2, 1e-5f), "45 deg growth");
	struct rnd_aabb e;
	rnd_aabb_empty(&e);
	rnd_aabb_transform(&out, &e, m);
	CHECK(rnd_aabb_is_empty(&out), "empty stays empty");
}
