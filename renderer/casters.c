/*
 * renderer/casters.c — what casts shadows (see casters.h): the plane rules (a plane with
 * nothing behind it from any light, or whose shadow no camera sees, draws into no shadow map),
 * the box of the casters, and which casters each shadow map draws.
 */
#include <math.h>
#include <string.h>
#include "casters.h"
#include "lod.h"

/* The corners of the part of box b behind the plane (n through p0) from side `side` (the sign
 * along n of the light's side): b's corners behind it and where b's edges cross it. Returns
 * how many (at most 8 + 12). */
static int part_behind(const struct rnd_aabb *b, const float n[3], const float p0[3], float side, float x[20][3])
{
	float c[8][3], sd[8];
	for (int k = 0; k < 8; k++) {
		float d[3];
		for (int a = 0; a < 3; a++) c[k][a] = k >> a & 1 ? b->max[a] : b->min[a];
		rnd_v3_sub(d, c[k], p0);
		sd[k] = side * rnd_v3_dot(n, d);
	}
	int nx = 0;
	for (int k = 0; k < 8; k++) {
		if (sd[k] < 0.0f) memcpy(x[nx++], c[k], sizeof x[0]);
		for (int a = 0; a < 3; a++) {
			int j = k | 1 << a;
			if (j == k || (sd[k] < 0.0f) == (sd[j] < 0.0f)) continue;
			float t = sd[k] / (sd[k] - sd[j]);
			for (int m = 0; m < 3; m++) x[nx][m] = c[k][m] + t * (c[j][m] - c[k][m]);
			nx++;
		}
	}
	return nx;
}

/* Whether the points x[nx] behind `plane` (part_behind) are all hidden from a camera by the
 * plane's own quad (opaque): every line of sight to them crosses the plane inside the quad.
 * The part of a box behind the plane is convex and so is its central (or, orthographic,
 * parallel) projection onto the plane, so its corners decide. False unless the camera's whole
 * near rectangle is strictly on the plane's side `side`: a camera whose near plane cuts the
 * ground sees under it. inv: the inverse of the plane's model matrix. */
static bool quad_hides(const struct rnd_object *plane, const float inv[16], const float n[3], const float p0[3],
                       float side, float x[][3], int nx, const struct rnd_camera_plan *cam)
{
	float right[3];
	if (cam->ortho && side * rnd_v3_dot(n, cam->fwd) >= 0.0f) return false;   /* looking away from it */
	rnd_v3_cross(right, cam->fwd, cam->up);
	if (!rnd_v3_normalize(right, right)) return false;
	float hh = cam->ortho ? 0.5f * (cam->ortho_height > 0 ? cam->ortho_height : 1.0f) : cam->znear * tanf(0.5f * cam->fov_y);
	float hw = hh * cam->aspect;
	for (int k = 0; k < 4; k++) {
		float q[3];
		for (int a = 0; a < 3; a++)
			q[a] = cam->pos[a] + cam->fwd[a] * cam->znear + right[a] * (k & 1 ? hw : -hw) + cam->up[a] * (k & 2 ? hh : -hh) -
			       p0[a];
		if (side * rnd_v3_dot(n, q) <= 0.0f) return false;
	}
	/* the quad's edge shrunk by 1e-4 of its size */
	float hx = 0.5f * plane->size[0] * (1.0f - 1e-4f), hz = 0.5f * plane->size[2] * (1.0f - 1e-4f);
	for (int k = 0; k < nx; k++) {
		/* along the line of sight to x, onto the plane */
		float dir[3], q[3], lq[3], dx[3];
		if (cam->ortho) memcpy(dir, cam->fwd, sizeof dir);
		else rnd_v3_sub(dir, x[k], cam->pos);
		float dn = rnd_v3_dot(n, dir);
		if (fabsf(dn) < 1e-12f) return false;
		rnd_v3_sub(dx, p0, x[k]);
		float t = rnd_v3_dot(n, dx) / dn;
		for (int m = 0; m < 3; m++) q[m] = x[k][m] + t * dir[m];
		rnd_mat4_mul_point(lq, inv, q);
		if (fabsf(lq[0]) > hx || fabsf(lq[2]) > hz) return false;
	}
	return true;
}

/* rnd_plane_may_shadow (ncam 0) and rnd_plane_may_shadow_seen in one: for each shadowed light,
 * whether part of b lies behind the plane from it, and then whether a camera may see that part.
 * A one-sided plane hides nothing (culled from behind, and a mirroring transform turns its
 * front). */
static bool plane_shadows(const struct rnd_scene *sc, const struct rnd_object *plane, const struct rnd_aabb *b,
                          const struct rnd_camera_plan *cams, uint32_t ncam)
{
	float inv[16];
	if (ncam && (!plane->double_sided || !rnd_mat4_invert(inv, plane->model))) ncam = 0;
	float nm[16], n[3], up[3] = {0.0f, 1.0f, 0.0f}, p0[3] = {plane->model[12], plane->model[13], plane->model[14]};
	if (!rnd_mat4_normal_matrix(nm, plane->model)) return true;
	rnd_mat4_mul_dir(n, nm, up);
	if (!rnd_v3_normalize(n, n)) return true;
	/* Signed distances of the box from the plane: the corner farthest on each side. */
	float lo = 0.0f, hi = 0.0f;
	for (int k = 0; k < 3; k++) {
		float a = n[k] * (b->min[k] - p0[k]), c = n[k] * (b->max[k] - p0[k]);
		lo += a < c ? a : c;
		hi += a < c ? c : a;
	}
	const float eps = 1e-4f;
	for (uint32_t i = 0; i < sc->light_count; i++) {
		const struct rnd_light *L = &sc->lights[i];
		if (!L->shadow.enabled) continue;
		float side; /* > 0: the light is on the normal's side */
		if (L->type == RND_LIGHT_DIRECTIONAL) side = -rnd_v3_dot(n, L->direction);
		else {
			float d[3];
			rnd_v3_sub(d, L->position, p0);
			side = rnd_v3_dot(n, d);
		}
		if (fabsf(side) <= eps) return true;        /* grazing: keep it simple, it casts */
		if (side > 0.0f ? lo >= -eps : hi <= eps) continue;  /* nothing of the box behind it */
		if (!ncam) return true;
		float x[20][3], sgn = side > 0.0f ? 1.0f : -1.0f;
		int nx = part_behind(b, n, p0, sgn, x);
		for (uint32_t v = 0; v < ncam; v++)
			if (!quad_hides(plane, inv, n, p0, sgn, x, nx, &cams[v])) return true;
	}
	return false;
}

bool rnd_planes_judged(const struct rnd_scene *sc)
{
	return sc->object_count <= RND_PLANES_JUDGED_MAX;
}

bool rnd_plane_may_shadow(const struct rnd_scene *sc, const struct rnd_object *plane, const struct rnd_aabb *b)
{
	return plane_shadows(sc, plane, b, NULL, 0);
}

bool rnd_plane_may_shadow_seen(const struct rnd_scene *sc, const struct rnd_object *plane, const struct rnd_aabb *b,
                               const struct rnd_camera_plan *cams, uint32_t ncam)
{
	bool opaque = !sc->material_count || sc->materials[plane->material].alpha_mode == RND_ALPHA_OPAQUE;
	return plane_shadows(sc, plane, b, cams, opaque ? ncam : 0);
}

bool rnd_moments_need_ground(const struct rnd_scene *sc)
{
	for (uint32_t k = 0; k < sc->light_count; k++)
		if (sc->lights[k].shadow.enabled &&
		    (sc->lights[k].shadow.filter == RND_FILTER_VSM || sc->lights[k].shadow.filter == RND_FILTER_EVSM))
			return true;
	return false;
}

/* Whether plane i may shadow any other object of sc where a camera of cams[ncam] may see it
 * (ncam 0: anywhere; rnd_plane_may_shadow_seen), each taken at its bounds as asked;
 * *other: there is another object at all. */
/* Whether plane i shadows another object where a camera sees it, for the scene's lights; and
 * (*seen_env, when esc has more lights than sc) for the environment's directions too. */
static bool shadows_others(const struct rnd_scene *sc, const struct rnd_scene *esc, const struct draw *draws, uint32_t i,
                           const struct rnd_camera_plan *cams, uint32_t ncam, bool *other, bool *seen_env)
{
	struct rnd_aabb b;
	bool seen = false;
	*other = *seen_env = false;
	for (uint32_t j = 0; j < sc->object_count && !seen; j++) {
		if (j == i) continue;
		rnd_object_bounds(sc, j, &draws[j].bounds, &b);
		if (rnd_aabb_is_empty(&b)) continue;
		*other = true;
		seen = rnd_plane_may_shadow_seen(sc, &sc->objects[i], &b, cams, ncam);
		if (!*seen_env && esc->light_count > sc->light_count)
			*seen_env = rnd_plane_may_shadow_seen(esc, &sc->objects[i], &b, cams, ncam);
	}
	return seen;
}

/* Why each object casts or not, for the plan's reader (the decisions are made above): a plane
 * that does not cast is told apart as alone, lit side or unseen by the same tests. */
static void cast_reasons(const struct rnd_scene *sc, const struct rnd_scene *esc, const struct draw *draws,
                         const bool *fill_only, uint8_t *why)
{
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		bool catcher = sc->material_count && sc->materials[o->material].shadow_catcher;
		bool plane = o->shape == RND_SHAPE_PLANE;
		if (!o->cast_shadows) why[i] = RND_CAST_NOT_ASKED;
		else if (catcher) why[i] = RND_CAST_CATCHER;
		else if (!plane) why[i] = RND_CAST_YES;
		else if (!rnd_planes_judged(sc)) why[i] = RND_CAST_UNJUDGED;
		else if (draws[i].cast && !(i < RND_PLANES_JUDGED_MAX && fill_only[i])) why[i] = RND_CAST_YES;
		else if (draws[i].cast) why[i] = rnd_moments_need_ground(sc) ? RND_CAST_FOR_MOMENTS : RND_CAST_FOR_ENV;
		else {
			bool other, env, behind = shadows_others(sc, esc, draws, i, NULL, 0, &other, &env);
			why[i] = !other ? RND_CAST_ALONE : behind ? RND_CAST_UNSEEN : RND_CAST_LIT_SIDE;
		}
	}
}

/* A plane with every other object on its lit side shadows nothing: out of the shadow pass,
 * and so is one whose shadow falls only where no camera of the render sees it, on the parts
 * of objects sunk into it (rnd_plane_may_shadow_seen; studio-spots' boxes stand 24 cm deep in
 * its floor: in its maps the floor cost a whole-scene sun map and made the PCSS bounds' lit
 * proofs harder, a few % of the render). Unless a light filters with moments, whose blur
 * needs the ground behind a caster's edge in the map (rnd_moments_need_ground). Then the box
 * of what casts, which sizes a `fit` sun map: a plane drawn only for the moments' sake stays
 * out of it. It is the receiver around the casters, not a caster; inside the box's tile it is
 * drawn, outside it the sun is unblocked anyway. Counted, it made a VSM thumbnail's sun map cover the whole
 * 10 m floor: a 2048^2 map whose moments cost ~100 ms on lavapipe, for shadows within a 256^2
 * corner. */
#define RND_PLANE_CAMERAS 8u   /* renders of more views judge planes on geometry alone */
void rnd_casters_plan(const struct rnd_scene *sc, const struct rnd_scene *esc, struct draw *draws,
                      const struct rnd_aabb *bounds, const struct rnd_aabb *obj_bounds, struct rnd_aabb *casters,
                      uint8_t *why)
{
	struct rnd_camera_plan cams[RND_PLANE_CAMERAS];
	struct rnd_error err;
	uint32_t nviews = sc->view_count ? sc->view_count : 1, ncam = 0;
	for (uint32_t v = 0; v < nviews && nviews <= RND_PLANE_CAMERAS; v++) {
		const struct rnd_camera *camera = sc->view_count ? &sc->views[v] : &sc->camera;
		const struct rnd_aabb *fb = camera->fit == RND_FIT_OBJECTS ? obj_bounds : bounds;
		if (rnd_camera_plan(camera, sc->width, sc->height, fb, &cams[ncam], &err) != RND_OK) {
			ncam = 0;
			break;
		}
		ncam++;
	}
	bool moments = rnd_moments_need_ground(sc);
	bool fill_only[RND_PLANES_JUDGED_MAX] = {false};
	for (uint32_t i = 0; i < sc->object_count && rnd_planes_judged(sc); i++) {
		if (!draws[i].cast || sc->objects[i].shape != RND_SHAPE_PLANE) continue;
		/* seen: for the scene's lights; seen_env: for the environment's directions too (the
		 * plane then casts into their maps, but the box that sizes a sun's map stays the same) */
		bool other, seen_env, seen = shadows_others(sc, esc, draws, i, cams, ncam, &other, &seen_env);
		draws[i].cast = seen || seen_env || (other && moments);
		fill_only[i] = draws[i].cast && !seen;
	}
	rnd_aabb_empty(casters);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (draws[i].cast && !(i < RND_PLANES_JUDGED_MAX && fill_only[i])) rnd_aabb_union(casters, &draws[i].bounds);
	if (why) cast_reasons(sc, esc, draws, fill_only, why);
}

static bool point_outside(const float p[3], const struct rnd_aabb *b, float pad)
{
	for (int k = 0; k < 3; k++)
		if (p[k] < b->min[k] - pad || p[k] > b->max[k] + pad) return true;
	return false;
}

bool rnd_shadow_view_draws(const struct rnd_shadow_plan *sp, const struct rnd_light *lights, const struct draw *draws,
                           uint32_t v, uint32_t i, int *cull)
{
	const struct draw *d = &draws[i];
	if (!d->cast || !d->index_count) return false;
	if (!rnd_aabb_in_frustum(&d->bounds, sp->views[v].view_proj, sp->view_ortho[v])) return false;
	const struct rnd_light *L = &lights[sp->view_light[v]];
	*cull = d->single_sided ||
	        (d->closed && (L->type == RND_LIGHT_DIRECTIONAL || point_outside(L->position, &d->bounds, 0.05f)));
	return true;
}

/* Each reason above in words (the plan shows them). */
const char *rnd_cast_why_text(unsigned why)
{
	static const char *const text[RND_CAST_WHY_COUNT] = {
		[RND_CAST_YES] = "casts",
		[RND_CAST_NOT_ASKED] = "cast_shadows is false",
		[RND_CAST_CATCHER] = "a shadow catcher receives shadows and casts none",
		[RND_CAST_ALONE] = "a plane with no other object to shadow",
		[RND_CAST_LIT_SIDE] = "a plane with every other object on its lit side",
		[RND_CAST_UNSEEN] = "a plane whose shadow falls only where no camera sees it (on parts of objects sunk into it)",
		[RND_CAST_FOR_MOMENTS] = "a plane drawn into the maps for the VSM/EVSM blur, left out of the casters' box",
		[RND_CAST_UNJUDGED] = "a plane in a scene of more than " RND_NUMBER_WORDS(RND_PLANES_JUDGED_MAX)
		                       " objects: planes are not judged, it casts",
		[RND_CAST_FOR_ENV] = ("a plane that shadows others only from the environment's directions: in their maps, "
		                      "left out of the casters' box"),
	};
	return why < RND_CAST_WHY_COUNT ? text[why] : "";
}
