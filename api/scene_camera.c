/*
 * api/scene_camera.c — one camera (the root `camera`, or an entry of `views` over the root's
 * members), and the sphere around what `fit: "objects"` frames, which the turntable
 * (scene_views.c) circles. See scene_internal.h for the conventions.
 */
#include <float.h>
#include <math.h>
#include <string.h>
#include "ground.h"
#include "scene_internal.h"

static const char *const CAMERA_MEMBERS[] = {"type", "position", "target", "up", "fov_y", "height", "near",
                                             "far", "exposure", "fit", "direction", "margin", NULL};

int api_parse_camera(struct pctx *c, json_t *j, struct rnd_camera *cam)
{
	if (api_require_object(c, j, "camera") < 0 || api_check_members(c, j, CAMERA_MEMBERS, NULL, "a camera") < 0)
		return -1;
	static const char *const types[] = {"perspective", "orthographic", NULL};
	static const char *const fits[] = {"scene", "objects", NULL};
	static const struct range fov = {0, 180, true, true}, ev = {-64, 64, false, false},
	                          margin = {0, 1, false, true};
	/* A view keeps the root camera's type unless it gives its own (scene_views.c). */
	int type = cam->type == RND_CAMERA_ORTHOGRAPHIC, fit = -1, rc;
	if (api_get_enum(c, j, "type", types, &type) < 0 || api_get_enum(c, j, "fit", fits, &fit) < 0) return -1;
	cam->type = type ? RND_CAMERA_ORTHOGRAPHIC : RND_CAMERA_PERSPECTIVE;
	/* Members of the other projection, or a placement that fit replaces, would be dropped: the
	 * document contradicts itself (as direction without fit). */
	const char *other = type ? "fov_y" : "height";
	if (json_object_get(j, other))
		return api_fail_at(c, other, type ? "fov_y is only used by a perspective camera; this camera is "
		                   "orthographic, framed by height" : "height is only used by an orthographic camera "
		                   "(type \"orthographic\"); this camera is perspective, framed by fov_y");
	static const char *const placed[] = {"position", "target", NULL};
	for (int k = 0; fit >= 0 && placed[k]; k++)
		if (json_object_get(j, placed[k]))
			return api_fail_at(c, placed[k], "%s is not used with fit: fit places the camera along direction "
			                   "(give position and target without fit instead)", placed[k]);
	if (api_get_vec(c, j, "position", cam->position, 3, 3, 0) < 0 ||
	    api_get_vec(c, j, "target", cam->target, 3, 3, 0) < 0 ||
	    api_get_vec(c, j, "up", cam->up, 3, 3, V_NONZERO) < 0 ||
	    api_get_angle(c, j, "fov_y", &fov, &cam->fov_y) < 0 ||
	    api_get_float(c, j, "exposure", &ev, &cam->exposure) < 0)
		return -1;
	if ((rc = api_get_float(c, j, "height", &R_POS, &cam->height)) < 0) return -1;
	if (type == 1 && !rc && !(cam->height > 0)) return api_fail_at(c, "height", "an orthographic camera requires height (world units "
	                                     "covered by the image height)");
	double nr = 0, fr = 0;
	int has_near = api_get_num(c, j, "near", &R_POS, &nr), has_far;
	if (has_near < 0 || (has_far = api_get_num(c, j, "far", &R_POS, &fr)) < 0) return -1;
	if (has_near && has_far && !(fr > nr))
		return api_fail_at(c, "far", "far (%g) must be greater than near (%g)", fr, nr);
	if (has_near) cam->near = (float)nr;
	if (has_far) cam->far = (float)fr;
	float dir[3];
	if ((rc = api_get_vec(c, j, "direction", dir, 3, 3, V_NONZERO)) < 0) return -1;
	if (rc && fit < 0) return api_fail_at(c, "direction", "direction is only used with fit");
	if (rc) memcpy(cam->fit_direction, dir, sizeof dir);
	float mg = 0;
	if ((rc = api_get_float(c, j, "margin", &margin, &mg)) < 0) return -1;
	if (rc && fit < 0) return api_fail_at(c, "margin", "margin is only used with fit");
	if (rc) cam->fit_margin = mg;
	/* Auto-framing places a perspective camera (contract §2): an orthographic one asked to fit
	 * would silently come out perspective. */
	if (fit >= 0 && type == 1)
		api_defer(c, true, "type", "fit frames a perspective camera; an orthographic fit is not supported "
		          "(give position, target and height instead)");
	if (fit >= 0) {
		cam->fit = fit ? RND_FIT_OBJECTS : RND_FIT_SCENE;
		if (cam->fit_direction[0] == 0 && cam->fit_direction[1] == 0 && cam->fit_direction[2] == 0) {
			/* No direction and none from the defaults: a three-quarter view from above. */
			cam->fit_direction[0] = -1; cam->fit_direction[1] = -0.75f; cam->fit_direction[2] = -1;
		}
	} else {
		cam->fit = RND_FIT_NONE;
		if (!memcmp(cam->position, cam->target, sizeof cam->position))
			return api_fail_at(c, json_object_get(j, "target") ? "target" : "position",
			               "target must differ from position (the view direction would be zero)");
	}
	return 0;
}


/* Centre and radius of the scene's "objects" bounds: every object rnd_object_frames() counts
 * (all objects when that leaves none; the unit sphere at the origin when empty). */
void api_objects_sphere(const struct rnd_scene *sc, const struct rnd_material *mats, double centre[3],
                           double *radius)
{
	double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
	for (int pass = 0; pass < 2 && lo[0] > hi[0]; pass++)
		for (uint32_t i = 0; i < sc->object_count; i++) {
			const struct rnd_object *o = &sc->objects[i];
			if (!pass && !rnd_object_frames(o, mats)) continue;
			api_object_bounds(o, lo, hi);
		}
	if (lo[0] > hi[0]) {
		centre[0] = centre[1] = centre[2] = 0;
		*radius = 1;
		return;
	}
	double d2 = 0;
	for (int k = 0; k < 3; k++) {
		centre[k] = 0.5 * (lo[k] + hi[k]);
		d2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
	}
	*radius = fmax(0.5 * sqrt(d2), 1e-3);
}
