/*
 * renderer/math — vectors, 4x4 column-major matrices and bounding boxes (see rnd_math.h).
 *
 * Matrices are stored m[col*4 + row]. Projections target Vulkan clip space: depth 0..1 with
 * near -> 0, and clip y negated so that NDC y (+1 = top, contract §1) is -clip.y/clip.w.
 * No state, no allocation.
 */
#include <float.h>
#include <math.h>
#include <string.h>
#include "umbra/rnd_math.h"

uint64_t rnd_fnv1a(uint64_t h, const void *data, size_t len)
{
	const unsigned char *p = data;
	for (size_t i = 0; i < len; i++) {
		h ^= p[i];
		h *= 0x100000001b3ull;
	}
	return h;
}

uint64_t rnd_hash(uint64_t h, const void *data, size_t len)
{
	const uint8_t *p = data;
	const uint64_t m = 0x9e3779b97f4a7c15ull;
	/* Four independent lanes for long inputs: one lane is a chain of dependent multiplies
	 * (~11 ms over a 50 MB model, hashed on every request that sends it inline); four overlap. */
	if (len >= 64) {
		uint64_t l[4] = {h, h ^ 0x243f6a8885a308d3ull, h ^ 0x13198a2e03707344ull, h ^ 0xa4093822299f31d0ull};
		while (len >= 32) {
			for (int k = 0; k < 4; k++) {
				uint64_t w;
				memcpy(&w, p + 8 * k, 8);
				l[k] = (l[k] ^ w) * m;
				l[k] ^= l[k] >> 29;
			}
			p += 32; len -= 32;
		}
		h = l[0];
		for (int k = 1; k < 4; k++) {
			h = (h ^ l[k]) * m;
			h ^= h >> 29;
		}
	}
	while (len >= 8) {
		uint64_t w;
		memcpy(&w, p, 8);
		h = (h ^ w) * m;
		h ^= h >> 29;
		p += 8; len -= 8;
	}
	uint64_t w = 0;
	memcpy(&w, p, len);
	h = (h ^ w ^ ((uint64_t)len << 56)) * m;
	h ^= h >> 32;
	return h;
}

void rnd_mat4_identity(float m[16])
{
	memset(m, 0, 16 * sizeof *m);
	m[0] = m[5] = m[10] = m[15] = 1.0f;
}

void rnd_mat4_mul(float out[16], const float a[16], const float b[16])
{
	for (int c = 0; c < 4; c++)
		for (int r = 0; r < 4; r++) {
			float s = 0.0f;
			for (int k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
			out[c * 4 + r] = s;
		}
}

void rnd_mat4_trs(float out[16], const float t[3], const float q[4], const float s[3])
{
	double x = q[0], y = q[1], z = q[2], w = q[3];
	double n = sqrt(x * x + y * y + z * z + w * w);
	if (!(n > 0.0) || !isfinite(n)) { x = y = z = 0.0; w = 1.0; }
	else { x /= n; y /= n; z /= n; w /= n; }

	/* Columns of the rotation matrix (glTF / standard unit-quaternion formula). */
	float r[9] = {
		(float)(1 - 2 * (y * y + z * z)), (float)(2 * (x * y + z * w)),     (float)(2 * (x * z - y * w)),
		(float)(2 * (x * y - z * w)),     (float)(1 - 2 * (x * x + z * z)), (float)(2 * (y * z + x * w)),
		(float)(2 * (x * z + y * w)),     (float)(2 * (y * z - x * w)),     (float)(1 - 2 * (x * x + y * y)),
	};
	for (int c = 0; c < 3; c++) {
		for (int row = 0; row < 3; row++) out[c * 4 + row] = r[c * 3 + row] * s[c];
		out[c * 4 + 3] = 0.0f;
	}
	out[12] = t[0]; out[13] = t[1]; out[14] = t[2]; out[15] = 1.0f;
}

void rnd_mat4_look_at(float out[16], const float eye[3], const float target[3], const float up[3])
{
	float f[3], s[3], u[3], upn[3];
	rnd_v3_sub(f, target, eye);
	if (!rnd_v3_normalize(f, f)) { f[0] = 0.0f; f[1] = 0.0f; f[2] = -1.0f; }

	/* Contract §7: an up parallel to the view (or zero) becomes -Z, or +Y for a view along Z. */
	bool ok = rnd_v3_normalize(upn, up);
	if (ok) {
		float c[3];
		rnd_v3_cross(c, f, upn);
		ok = rnd_v3_length(c) > 1e-5f;
	}
	if (!ok) {
		bool along_z = fabsf(f[2]) > 0.99999f;
		upn[0] = 0.0f;
		upn[1] = along_z ? 1.0f : 0.0f;
		upn[2] = along_z ? 0.0f : -1.0f;
	}
	rnd_v3_cross(s, f, upn);
	rnd_v3_normalize(s, s);
	rnd_v3_cross(u, s, f);

	out[0] = s[0]; out[4] = s[1]; out[8] = s[2];
	out[1] = u[0]; out[5] = u[1]; out[9] = u[2];
	out[2] = -f[0]; out[6] = -f[1]; out[10] = -f[2];
	out[3] = out[7] = out[11] = 0.0f;
	out[12] = -rnd_v3_dot(s, eye);
	out[13] = -rnd_v3_dot(u, eye);
	out[14] = rnd_v3_dot(f, eye);
	out[15] = 1.0f;
}

void rnd_mat4_perspective(float out[16], float fov_y, float aspect, float znear, float zfar)
{
	float f = 1.0f / tanf(0.5f * fov_y);
	memset(out, 0, 16 * sizeof *out);
	out[0] = f / aspect;
	out[5] = -f;                                  /* Vulkan: y down in clip space */
	out[10] = zfar / (znear - zfar);              /* z = -near -> 0, z = -far -> 1 */
	out[11] = -1.0f;
	out[14] = znear * zfar / (znear - zfar);
}

void rnd_mat4_ortho(float out[16], float l, float r, float b, float t, float znear, float zfar)
{
	memset(out, 0, 16 * sizeof *out);
	out[0] = 2.0f / (r - l);
	out[5] = -2.0f / (t - b);
	out[10] = -1.0f / (zfar - znear);
	out[12] = -(r + l) / (r - l);
	out[13] = (t + b) / (t - b);
	out[14] = -znear / (zfar - znear);
	out[15] = 1.0f;
}

bool rnd_mat4_invert(float out[16], const float m[16])
{
	double inv[16], a[16];
	for (int i = 0; i < 16; i++) a[i] = m[i];

	inv[0] = a[5] * a[10] * a[15] - a[5] * a[11] * a[14] - a[9] * a[6] * a[15] + a[9] * a[7] * a[14] + a[13] * a[6] * a[11] - a[13] * a[7] * a[10];
	inv[4] = -a[4] * a[10] * a[15] + a[4] * a[11] * a[14] + a[8] * a[6] * a[15] - a[8] * a[7] * a[14] - a[12] * a[6] * a[11] + a[12] * a[7] * a[10];
	inv[8] = a[4] * a[9] * a[15] - a[4] * a[11] * a[13] - a[8] * a[5] * a[15] + a[8] * a[7] * a[13] + a[12] * a[5] * a[11] - a[12] * a[7] * a[9];
	inv[12] = -a[4] * a[9] * a[14] + a[4] * a[10] * a[13] + a[8] * a[5] * a[14] - a[8] * a[6] * a[13] - a[12] * a[5] * a[10] + a[12] * a[6] * a[9];
	inv[1] = -a[1] * a[10] * a[15] + a[1] * a[11] * a[14] + a[9] * a[2] * a[15] - a[9] * a[3] * a[14] - a[13] * a[2] * a[11] + a[13] * a[3] * a[10];
	inv[5] = a[0] * a[10] * a[15] - a[0] * a[11] * a[14] - a[8] * a[2] * a[15] + a[8] * a[3] * a[14] + a[12] * a[2] * a[11] - a[12] * a[3] * a[10];
	inv[9] = -a[0] * a[9] * a[15] + a[0] * a[11] * a[13] + a[8] * a[1] * a[15] - a[8] * a[3] * a[13] - a[12] * a[1] * a[11] + a[12] * a[3] * a[9];
	inv[13] = a[0] * a[9] * a[14] - a[0] * a[10] * a[13] - a[8] * a[1] * a[14] + a[8] * a[2] * a[13] + a[12] * a[1] * a[10] - a[12] * a[2] * a[9];
	inv[2] = a[1] * a[6] * a[15] - a[1] * a[7] * a[14] - a[5] * a[2] * a[15] + a[5] * a[3] * a[14] + a[13] * a[2] * a[7] - a[13] * a[3] * a[6];
	inv[6] = -a[0] * a[6] * a[15] + a[0] * a[7] * a[14] + a[4] * a[2] * a[15] - a[4] * a[3] * a[14] - a[12] * a[2] * a[7] + a[12] * a[3] * a[6];
	inv[10] = a[0] * a[5] * a[15] - a[0] * a[7] * a[13] - a[4] * a[1] * a[15] + a[4] * a[3] * a[13] + a[12] * a[1] * a[7] - a[12] * a[3] * a[5];
	inv[14] = -a[0] * a[5] * a[14] + a[0] * a[6] * a[13] + a[4] * a[1] * a[14] - a[4] * a[2] * a[13] - a[12] * a[1] * a[6] + a[12] * a[2] * a[5];
	inv[3] = -a[1] * a[6] * a[11] + a[1] * a[7] * a[10] + a[5] * a[2] * a[11] - a[5] * a[3] * a[10] - a[9] * a[2] * a[7] + a[9] * a[3] * a[6];
	inv[7] = a[0] * a[6] * a[11] - a[0] * a[7] * a[10] - a[4] * a[2] * a[11] + a[4] * a[3] * a[10] + a[8] * a[2] * a[7] - a[8] * a[3] * a[6];
	inv[11] = -a[0] * a[5] * a[11] + a[0] * a[7] * a[9] + a[4] * a[1] * a[11] - a[4] * a[3] * a[9] - a[8] * a[1] * a[7] + a[8] * a[3] * a[5];
	inv[15] = a[0] * a[5] * a[10] - a[0] * a[6] * a[9] - a[4] * a[1] * a[10] + a[4] * a[2] * a[9] + a[8] * a[1] * a[6] - a[8] * a[2] * a[5];

	double det = a[0] * inv[0] + a[1] * inv[4] + a[2] * inv[8] + a[3] * inv[12];
	if (det == 0.0 || !isfinite(det)) return false;
	det = 1.0 / det;
	for (int i = 0; i < 16; i++) out[i] = (float)(inv[i] * det);
	return true;
}

float rnd_mat4_det3(const float m[16])
{
	/* Columns a = m[0..2], b = m[4..6], c = m[8..10]: det = a . (b x c). */
	double a0 = m[0], a1 = m[1], a2 = m[2], b0 = m[4], b1 = m[5], b2 = m[6], c0 = m[8], c1 = m[9], c2 = m[10];
	return (float)(a0 * (b1 * c2 - b2 * c1) + a1 * (b2 * c0 - b0 * c2) + a2 * (b0 * c1 - b1 * c0));
}

bool rnd_mat4_normal_matrix(float out[16], const float m[16])
{
	/* inverse-transpose of the 3x3 = cofactor matrix / det. The cofactor matrix's columns
	 * are b x c, c x a, a x b for the columns a, b, c of m. */
	float a[3] = {m[0], m[1], m[2]}, b[3] = {m[4], m[5], m[6]}, c[3] = {m[8], m[9], m[10]};
	float cb[3], cc[3], ca[3];
	rnd_v3_cross(ca, b, c);
	rnd_v3_cross(cb, c, a);
	rnd_v3_cross(cc, a, b);
	float det = rnd_v3_dot(a, ca);
	if (det == 0.0f || !isfinite(det)) return false;
	float inv = 1.0f / det;
	for (int i = 0; i < 3; i++) {
		out[0 + i] = ca[i] * inv;
		out[4 + i] = cb[i] * inv;
		out[8 + i] = cc[i] * inv;
	}
	out[3] = out[7] = out[11] = 0.0f;
	out[12] = out[13] = out[14] = 0.0f;
	out[15] = 1.0f;
	return true;
}

void rnd_aabb_empty(struct rnd_aabb *b)
{
	for (int i = 0; i < 3; i++) { b->min[i] = FLT_MAX; b->max[i] = -FLT_MAX; }
}

bool rnd_aabb_is_empty(const struct rnd_aabb *b)
{
	return !(b->min[0] <= b->max[0] && b->min[1] <= b->max[1] && b->min[2] <= b->max[2]);
}

void rnd_aabb_union(struct rnd_aabb *b, const struct rnd_aabb *o)
{
	if (rnd_aabb_is_empty(o)) return;
	rnd_aabb_add_point(b, o->min);
	rnd_aabb_add_point(b, o->max);
}

void rnd_aabb_transform(struct rnd_aabb *out, const struct rnd_aabb *b, const float m[16])
{
	struct rnd_aabb r;
	rnd_aabb_empty(&r);
	if (!rnd_aabb_is_empty(b)) {
		for (int i = 0; i < 8; i++) {
			float p[3] = {(i & 1) ? b->max[0] : b->min[0], (i & 2) ? b->max[1] : b->min[1],
			              (i & 4) ? b->max[2] : b->min[2]};
			rnd_mat4_mul_point(p, m, p);
			rnd_aabb_add_point(&r, p);
		}
	}
	*out = r;
}
