/*
 * renderer/camera.c — camera planning (plan.h rnd_camera_plan): the view, the reversed-Z
 * projection, near and far derived from the scene bounds where the request gives none, and
 * `fit` framing. Pure math; unit-tested in tests/unit/test_camera.c.
 */
#include <math.h>
#include <string.h>
#include "error.h"
#include "plan.h"

static void reverse_z(float m[16])
{
	/* z' = w - z: depth 0..1 becomes 1..0, far-away depths keep float precision. */
	for (int c = 0; c < 4; c++) m[c * 4 + 2] = m[c * 4 + 3] - m[c * 4 + 2];
}

/* Auto-framing (`fit`): aim at the bounds' centre along the fit direction, then back off until
 * every corner of the box projects inside the frame less the margin (margin = fraction of the
 * frame on each side), so the widest corner touches the margin. bounds NULL: the unit box. */
static enum rnd_result fit_eye(const struct rnd_camera *cam, struct rnd_camera_plan *out,
                               const struct rnd_aabb *bounds, float pos[3], float target[3], struct rnd_error *err)
{
	float dir[3];
	if (!rnd_v3_normalize(dir, cam->fit_direction))
		return rnd_fail(err, RND_ERR_INVALID, "camera fit direction must not be zero");
	float c[3] = {0, 0, 0};
	struct rnd_aabb b = {{-1, -1, -1}, {1, 1, 1}};
	if (bounds) b = *bounds;
	for (int i = 0; i < 3; i++) c[i] = 0.5f * (b.min[i] + b.max[i]);
	float eye0[3], basis[16];
	for (int i = 0; i < 3; i++) eye0[i] = c[i] - dir[i];
	rnd_mat4_look_at(basis, eye0, c, cam->up);
	float shrink = fmaxf(1.0f - 2.0f * cam->fit_margin, 0.05f);
	float ty = tanf(0.5f * out->fov_y) * shrink, tx = tanf(0.5f * out->fov_y) * out->aspect * shrink;
	float dist = 1e-3f;
	for (int i = 0; i < 8; i++) {
		float p[3] = {i & 1 ? b.max[0] : b.min[0], i & 2 ? b.max[1] : b.min[1], i & 4 ? b.max[2] : b.min[2]};
		float q[3], rel[3];
		rnd_v3_sub(rel, p, c);
		rnd_mat4_mul_dir(q, basis, rel);     /* view axes: x right, y up, -z forward */
		float z = -q[2];                     /* along the view direction */
		dist = fmaxf(dist, fabsf(q[0]) / tx - z);
		dist = fmaxf(dist, fabsf(q[1]) / ty - z);
	}
	for (int i = 0; i < 3; i++) { target[i] = c[i]; pos[i] = c[i] - dir[i] * dist; }
	out->ortho = false;
	return RND_OK;
}

enum rnd_result rnd_camera_plan(const struct rnd_camera *cam, uint32_t width, uint32_t height,
                                const struct rnd_aabb *bounds, struct rnd_camera_plan *out, struct rnd_error *err)
{
	memset(out, 0, sizeof *out);
	out->aspect = (float)width / (float)height;
	out->ortho = cam->type == RND_CAMERA_ORTHOGRAPHIC;
	out->fov_y = cam->fov_y > 0 ? cam->fov_y : 45.0f * (float)M_PI / 180.0f;
	out->ortho_height = cam->height;
	float pos[3], target[3];
	memcpy(pos, cam->position, sizeof pos);
	memcpy(target, cam->target, sizeof target);
	bool empty = !bounds || rnd_aabb_is_empty(bounds);

	if (cam->fit != RND_FIT_NONE) {
		enum rnd_result r = fit_eye(cam, out, empty ? NULL : bounds, pos, target, err);
		if (r != RND_OK) return r;
	}
	memcpy(out->pos, pos, sizeof pos);
	float fwd[3];
	rnd_v3_sub(fwd, target, pos);
	if (!rnd_v3_normalize(out->fwd, fwd))
		return rnd_fail(err, RND_ERR_INVALID, "camera position and target are the same point");
	rnd_mat4_look_at(out->view, pos, target, cam->up);

	float znear = cam->near, zfar = cam->far;
	if (znear <= 0 || zfar <= 0) {
		float dmin = 1e30f, dmax = -1e30f;
		if (!empty) {
			for (int i = 0; i < 8; i++) {
				float p[3] = {i & 1 ? bounds->max[0] : bounds->min[0], i & 2 ? bounds->max[1] : bounds->min[1],
				              i & 4 ? bounds->max[2] : bounds->min[2]};
				float d[3];
				rnd_v3_sub(d, p, pos);
				float z = rnd_v3_dot(d, out->fwd);
				dmin = fminf(dmin, z); dmax = fmaxf(dmax, z);
			}
		}
		if (empty || dmax <= 0) { dmin = 0.1f; dmax = 100.0f; }
		if (zfar <= 0) zfar = dmax * 1.01f + 1e-3f;
		if (znear <= 0) {
			if (out->ortho) znear = cam->near > 0 ? cam->near : 0.0f;
			else znear = fmaxf(dmin * 0.99f, zfar * 1e-4f);
		}
	}
	if (zfar <= znear) zfar = znear + 1.0f;
	out->znear = znear; out->zfar = zfar;
	out->user_near = cam->near > 0 ? cam->near : 0.0f;
	out->user_far = cam->far > 0 ? cam->far : 0.0f;
	if (out->ortho) {
		float h = cam->height > 0 ? cam->height : 1.0f, w = h * out->aspect;
		rnd_mat4_ortho(out->proj, -w / 2, w / 2, -h / 2, h / 2, znear, zfar);
	} else {
		rnd_mat4_perspective(out->proj, out->fov_y, out->aspect, znear, zfar);
	}
	reverse_z(out->proj);
	rnd_mat4_mul(out->view_proj, out->proj, out->view);
	float up[3] = {out->view[1], out->view[5], out->view[9]};
	memcpy(out->up, up, sizeof up);
	return RND_OK;
}
