/*
 * umbra renderer — small vector/matrix math shared by the renderer and api/, and the byte-stream
 * hash of the project (rnd_fnv1a: ETags, the model cache).
 *
 * Conventions: float arrays; matrices are 4x4 column-major (m[col*4 + row]) as in glTF and
 * GLSL; right-handed world, +Y up. Projections produce Vulkan clip space: depth 0..1 and the
 * Y axis flipped, so that image row 0 is the top of the picture and NDC y (contract sense,
 * +1 = top) equals -clip.y/clip.w. No allocation, no state: every function is thread-safe.
 * Output pointers may alias inputs unless a function says otherwise.
 */
#ifndef UMBRA_RND_MATH_H
#define UMBRA_RND_MATH_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

struct rnd_aabb { float min[3], max[3]; };

/* The byte-stream hash (64-bit FNV-1a) of the project: start from RND_FNV_SEED (or a previous
 * result); streaming, so hashing a then b equals hashing a‖b, and a body that arrives in chunks
 * hashes the same however it is cut. Used for ETags (server/negotiate.c), the model cache key
 * and asset files. Not for security. Whole buffers (shadow-cache keys, the model cache key)
 * use rnd_hash() instead: word at a time, several times faster on large inputs but not
 * streaming. */
#define RND_FNV_SEED 0xcbf29ce484222325ull
uint64_t rnd_fnv1a(uint64_t h, const void *data, size_t len);
/* 64-bit hash of a whole buffer, word at a time (content keys: shadow-cache entries, the model
 * cache; not streaming, not security). */
uint64_t rnd_hash(uint64_t h, const void *data, size_t len);

/* Defined here, inline: api/'s mesh work (model_lod.c's level error, ~40 % of a 124k-triangle
 * OBJ's import) called them across translation units, one call per dot product. */
static inline float rnd_v3_dot(const float a[3], const float b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void rnd_v3_cross(float out[3], const float a[3], const float b[3])
{
	float x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
	out[0] = x;
	out[1] = y;
	out[2] = z;
}

static inline void rnd_v3_sub(float out[3], const float a[3], const float b[3])
{
	for (int i = 0; i < 3; i++) out[i] = a[i] - b[i];
}

static inline void rnd_v3_add(float out[3], const float a[3], const float b[3])
{
	for (int i = 0; i < 3; i++) out[i] = a[i] + b[i];
}

static inline void rnd_v3_scale(float out[3], const float a[3], float s)
{
	for (int i = 0; i < 3; i++) out[i] = a[i] * s;
}

static inline float rnd_v3_length(const float a[3])
{
	return sqrtf(rnd_v3_dot(a, a));
}

/* Returns false (and leaves out = a) when |a| is 0 or not finite. */
static inline bool rnd_v3_normalize(float out[3], const float a[3])
{
	float len = rnd_v3_length(a);
	if (!(len > 0.0f) || !isfinite(len)) {
		if (out != a) memcpy(out, a, 3 * sizeof *out);
		return false;
	}
	rnd_v3_scale(out, a, 1.0f / len);
	return true;
}

void rnd_mat4_identity(float m[16]);
/* out = a * b; out may not alias a or b. */
void rnd_mat4_mul(float out[16], const float a[16], const float b[16]);
/* T * R * S with q = [x,y,z,w] (normalised here; a zero quaternion gives identity rotation). */
void rnd_mat4_trs(float out[16], const float t[3], const float q[4], const float s[3]);
/* View matrix (world -> view, camera looks down -Z). An `up` parallel to the view direction
 * is replaced by -Z, or by +Y when the view itself is along Z (contract §7). */
void rnd_mat4_look_at(float out[16], const float eye[3], const float target[3], const float up[3]);
/* Perspective, vertical fov in radians, Vulkan clip (y flipped, z in 0..1: near -> 0). */
void rnd_mat4_perspective(float out[16], float fov_y, float aspect, float znear, float zfar);
/* Orthographic box in view space (x in l..r, y in b..t, visible z in -n..-f), Vulkan clip. */
void rnd_mat4_ortho(float out[16], float l, float r, float b, float t, float znear, float zfar);
/* Returns false when m is singular (out untouched). */
bool rnd_mat4_invert(float out[16], const float m[16]);
/* Determinant of the upper-left 3x3 block (negative = mirroring transform). */
float rnd_mat4_det3(const float m[16]);
/* w = 1, divides by w. Inline, as the rest below: the renderer's tessellation and the render
 * plan's measure of each mesh run them once or twice per vertex. */
/* The largest length of the matrix's first three columns: the most it stretches an object-space
 * distance (a level's error, a radius) in world space. */
static inline float rnd_mat4_max_axis_scale(const float m[16])
{
	float s = 0.0f;
	for (int c = 0; c < 3; c++) {
		const float *col = m + 4 * c;
		float l = sqrtf(col[0] * col[0] + col[1] * col[1] + col[2] * col[2]);
		if (l > s) s = l;
	}
	return s;
}

static inline void rnd_mat4_mul_point(float out[3], const float m[16], const float p[3])
{
	float r[4];
	for (int row = 0; row < 4; row++)
		r[row] = m[row] * p[0] + m[4 + row] * p[1] + m[8 + row] * p[2] + m[12 + row];
	float iw = (r[3] != 0.0f) ? 1.0f / r[3] : 1.0f;
	out[0] = r[0] * iw; out[1] = r[1] * iw; out[2] = r[2] * iw;
}

/* w = 0 */
static inline void rnd_mat4_mul_dir(float out[3], const float m[16], const float d[3])
{
	float r[3];
	for (int row = 0; row < 3; row++)
		r[row] = m[row] * d[0] + m[4 + row] * d[1] + m[8 + row] * d[2];
	memcpy(out, r, sizeof r);
}
/* Inverse-transpose of the upper 3x3, as a 4x4 (for normals). False when singular. */
bool rnd_mat4_normal_matrix(float out[16], const float m[16]);

void rnd_aabb_empty(struct rnd_aabb *b);
bool rnd_aabb_is_empty(const struct rnd_aabb *b);
static inline void rnd_aabb_add_point(struct rnd_aabb *b, const float p[3])
{
	for (int i = 0; i < 3; i++) {
		if (p[i] < b->min[i]) b->min[i] = p[i];
		if (p[i] > b->max[i]) b->max[i] = p[i];
	}
}
void rnd_aabb_union(struct rnd_aabb *b, const struct rnd_aabb *o);
/* Bounds of the 8 transformed corners of b. */
void rnd_aabb_transform(struct rnd_aabb *out, const struct rnd_aabb *b, const float m[16]);

#ifdef __cplusplus
}
#endif
#endif
