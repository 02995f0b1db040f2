/*
 * renderer/plan_local.c — shadow views of spot and point lights (see plan_local.h). Pure math.
 *
 * A spot light's map was its whole cone (widened by the filter's reach) and a point light's six
 * cube faces, sized by the light's share of the view (light_importance_res) or a hard edge's
 * need (hard_light_res). Where the casters are known, as for a `fit` sun map (plan.c
 * fit_casters), a spot's map is cut down to the part of its cone the casters cover (a receiver
 * outside the view has nothing between it and the light: the shader reads it as lit), and both
 * kinds are sized for where the camera sees the casters: texels never coarser than the whole
 * cone's, finer until the filter's narrowest kernel spans a camera pixel there, the tile at
 * most doubled (a spot up to 2048, a cube face up to 1024); and for PCSS never finer than its
 * 24-texel blocker search can reach the widest penumbra the casters cast (spot_need), which
 * also holds for an asked resolution: texels finer than that are ones the search cannot use
 * (issue 31: the Spot model under a 0.2 m spot scored rmse 0.0104 against Cycles at the
 * default 1024 and 0.0110 at 4096, the search reaching a quarter as far).
 */
#include <math.h>
#include "error.h"
#include "plan_local.h"

static void persp_view(struct umbra_shadow_view *v, const float eye[3], const float dir[3], const float up[3],
                       float fov, float znear, float zfar, float res)
{
	float view[16], proj[16], target[3];
	rnd_v3_add(target, eye, dir);
	rnd_mat4_look_at(view, eye, target, up);
	rnd_mat4_perspective(proj, fov, 1.0f, znear, zfar);
	rnd_mat4_mul(v->view_proj, proj, view);
	v->params[0] = 2.0f * tanf(fov * 0.5f) / res;
	v->params[1] = 1.0f;
	v->params[2] = znear;
	v->params[3] = zfar;
	v->rect[2] = res;   /* x, y and the atlas size are filled in when the tile is granted */
}

/* Farthest distance from p to the box (for spot/point far planes). */
float rnd_plan_max_dist(const float p[3], const struct rnd_aabb *b)
{
	float d2 = 0;
	for (int k = 0; k < 3; k++) {
		float a = fmaxf(fabsf(p[k] - b->min[k]), fabsf(p[k] - b->max[k]));
		d2 += a * a;
	}
	return sqrtf(d2);
}

/* Tile size of a spot or point light with no resolution of its own: by importance, here the
 * share of the view its lit region covers (range, else the scene's extent from the light).
 * A light filling the view gets 1024 (spot) or 512 per cube face (six of them), a small one
 * down to 256 (an explicit `resolution` asks for more),
 * so many small lights share the atlas and a large one gets resolution. */
static uint32_t light_importance_res(const struct rnd_light *L, const struct rnd_aabb *b, const struct rnd_camera_plan *cam)
{
	float reach = rnd_plan_max_dist(L->position, b);
	if (L->range > 0 && L->range < reach) reach = L->range;
	if (L->type == RND_LIGHT_SPOT) reach *= fminf(sinf(fminf(L->outer_angle, 1.5f)) + 0.25f, 1.0f);
	float d[3];
	rnd_v3_sub(d, L->position, cam->pos);
	float dist = rnd_v3_length(d);
	float frac;
	if (cam->ortho) frac = reach / fmaxf(0.5f * cam->ortho_height, 1e-6f);
	else frac = dist <= reach ? 1.0f : tanf(asinf(reach / dist)) / tanf(0.5f * cam->fov_y);
	frac = fminf(fmaxf(frac, 0.0f), 1.0f);
	float top = L->type == RND_LIGHT_SPOT ? 1024.0f : 512.0f;
	float want = fmaxf(top * frac, 256.0f);
	return (uint32_t)want;
}

/* Tile size a hard spot or point light (no radius, PCF or hard filter) needs so that its
 * filter kernel, (2r+1) texels, spans at most one pixel where the camera may see what the
 * light reaches (the corners and centre of the scene bounds, pulled in to the light's reach):
 * such a light's edge is a step, and a kernel wider than a pixel is blur the light does not
 * have. The 512-texel cube faces importance gives a full-view point light 3 m above a 12 m
 * floor made a 3-texel ramp up to ~2 pixels wide on a 128² image; against the traced answer
 * rmse 0.025, at 1024 0.017. Kept cheap: at most one doubling of the importance choice `base`
 * (a light keeps its share of the atlas, its shadow pass grows at most 4x), and at most 2048
 * for a spot, 1024 for a cube face (six of them). 0 = no need. */
static uint32_t hard_light_res(const struct rnd_light *L, const struct rnd_light_plan *lp, const struct rnd_aabb *b,
                               const struct rnd_camera_plan *cam, uint32_t height, uint32_t base)
{
	if (L->radius > 0 || (lp->filter != UMBRA_FILTER_PCF && lp->filter != UMBRA_FILTER_HARD) || height == 0)
		return 0;
	float reach = rnd_plan_max_dist(L->position, b);
	if (L->range > 0 && L->range < reach) reach = L->range;
	float tan_half = L->type == RND_LIGHT_SPOT ? tanf(fminf(L->outer_angle, 85.0f * (float)M_PI / 180.0f)) : 1.0f;
	float kernel = (float)(lp->filter == UMBRA_FILTER_PCF ? 2 * lp->pcf_radius + 1 : 1);
	float pix = cam->ortho ? cam->ortho_height / (float)height : 2.0f * tanf(0.5f * cam->fov_y) / (float)height;
	float want = 0;
	for (int i = 0; i < 9; i++) {
		float p[3], d[3];
		for (int k = 0; k < 3; k++)
			p[k] = i == 8 ? 0.5f * (b->min[k] + b->max[k]) : (i >> k & 1 ? b->max[k] : b->min[k]);
		rnd_v3_sub(d, p, L->position);
		float to_light = rnd_v3_length(d);
		if (to_light > reach) {
			for (int k = 0; k < 3; k++) p[k] = L->position[k] + d[k] * (reach / to_light);
			to_light = reach;
		}
		rnd_v3_sub(d, p, cam->pos);
		float footprint = cam->ortho ? pix : pix * fmaxf(rnd_v3_length(d), cam->znear);
		/* texel at p: 2 tan_half |p - L| / res <= footprint / kernel */
		want = fmaxf(want, kernel * 2.0f * tan_half * to_light / footprint);
	}
	float cap = fminf(2.0f * (float)base, L->type == RND_LIGHT_SPOT ? 2048.0f : 1024.0f);
	return (uint32_t)fminf(want, cap);
}

uint32_t rnd_plan_local_want(const struct rnd_light *L, const struct rnd_light_plan *lp, const struct rnd_aabb *bounds,
                             const struct rnd_camera_plan *cam, uint32_t height, uint8_t *rule)
{
	uint32_t want = light_importance_res(L, bounds, cam);
	*rule = RND_SIZE_IMPORTANCE;
	uint32_t hard = hard_light_res(L, lp, bounds, cam, height, rnd_shadow_map_side(want, true, 0));
	if (hard > want) {
		want = hard;
		*rule = RND_SIZE_HARD_EDGE;
	}
	return want;
}

/* Texels a view is widened by on each side so that filter taps near its edge stay inside: no
 * seams between cube faces, no clipped cones. */
static float local_margin(const struct rnd_light_plan *lp)
{
	return (float)(lp->pcf_radius + 2) + (lp->filter == UMBRA_FILTER_PCSS ? lp->search_texels : 0.0f);
}

/* Depth of p from a light at eye: along the spot's axis d, or (d NULL) a cube face's, the
 * largest axis of p - eye. */
static float light_depth(const float eye[3], const float *d, const float p[3])
{
	float e[3];
	rnd_v3_sub(e, p, eye);
	if (d) return rnd_v3_dot(e, d);
	return fmaxf(fmaxf(fabsf(e[0]), fabsf(e[1])), fabsf(e[2]));
}

/* What a local light's texels (tan units: world size per unit of depth) must resolve around
 * the casters: `camera` the coarsest that keeps the filter's narrowest kernel within a camera
 * pixel at the casters' box (corners and centre; 0: no camera), `search` the finest whose
 * PCSS search (search_texels) still reaches the widest penumbra a caster casts, a blocker at
 * the casters' nearest depth onto a receiver where their shadows land farthest (rays from the
 * light through the box's corners to the scene's bounds): radius (1/zb - 1/zr) / search
 * (0: not PCSS, or the light among its casters). */
struct local_texels {
	float camera, search;
};

static struct local_texels local_need(const struct rnd_light *L, const float *d, const struct rnd_local_need *need,
                                      const struct rnd_light_plan *lp)
{
	struct local_texels t = {0, 0};
	const struct rnd_aabb *c = need->casters, *b = need->bounds;
	const struct rnd_camera_plan *cam = need->cam;
	float kernel = rnd_plan_kernel_texels(lp), zb = 1e30f, zr = 0;
	float pix = !cam || !need->height ? 0.0f
	          : cam->ortho ? cam->ortho_height / (float)need->height : 2.0f * tanf(0.5f * cam->fov_y) / (float)need->height;
	for (int i = 0; i < 9; i++) {
		float p[3], e[3];
		for (int k = 0; k < 3; k++) p[k] = i == 8 ? 0.5f * (c->min[k] + c->max[k]) : (i >> k & 1 ? c->max[k] : c->min[k]);
		float depth = light_depth(L->position, d, p);
		if (pix > 0 && depth > 1e-4f) {
			rnd_v3_sub(e, p, cam->pos);
			float px = cam->ortho ? pix : pix * fmaxf(rnd_v3_length(e), cam->znear);
			float want = px / (kernel * depth);
			t.camera = t.camera > 0 ? fminf(t.camera, want) : want;
		}
		if (i == 8) break;
		zb = fminf(zb, depth);
		float dir[3], far = 1e30f;
		rnd_v3_sub(dir, p, L->position);
		if (!rnd_v3_normalize(dir, dir)) continue;
		for (int k = 0; k < 3; k++)
			if (fabsf(dir[k]) > 1e-6f) far = fminf(far, ((dir[k] > 0 ? b->max[k] : b->min[k]) - p[k]) / dir[k]);
		float q[3];
		for (int k = 0; k < 3; k++) q[k] = p[k] + dir[k] * fmaxf(far, 0.0f);
		zr = fmaxf(zr, light_depth(L->position, d, q));
	}
	if (L->range > 0) zr = fminf(zr, L->range);
	if (lp->filter == UMBRA_FILTER_PCSS && L->radius > 0 && zb > 1e-3f && zr > zb)
		t.search = L->radius * (1.0f / zb - 1.0f / zr) / lp->search_texels;
	return t;
}

/* The casters' box in the tan plane of a light's view (NDC of a 90-degree frustum, y down),
 * clipped to [-lim, lim]^2 (the view's widened extent: a caster outside it shades no receiver
 * this view serves). 1: r = {u0, u1, v0, v1}; 0: nothing inside; -1: a corner not in front
 * of the light (the box's image is unbounded: the whole view). */
static int casters_rect(const float view[16], const struct rnd_aabb *c, float lim, float r[4])
{
	r[0] = r[2] = 1e30f; r[1] = r[3] = -1e30f;
	for (int i = 0; i < 8; i++) {
		float p[3], q[3];
		for (int k = 0; k < 3; k++) p[k] = i >> k & 1 ? c->max[k] : c->min[k];
		rnd_mat4_mul_point(q, view, p);
		if (-q[2] < 1e-3f) return -1;
		r[0] = fminf(r[0], q[0] / -q[2]); r[1] = fmaxf(r[1], q[0] / -q[2]);
		r[2] = fminf(r[2], q[1] / q[2]); r[3] = fmaxf(r[3], q[1] / q[2]);
	}
	r[0] = fmaxf(r[0], -lim); r[1] = fminf(r[1], lim); r[2] = fmaxf(r[2], -lim); r[3] = fminf(r[3], lim);
	return r[0] < r[1] && r[2] < r[3];
}

/* A rectangle of a view's tan plane: centre cx, cy, half extent h (a square tile). */
struct tan_rect {
	float cx, cy, h;
};

/* The texel (tan units) a tile of res texels gives rect r with the filter's margin m: the
 * span filling it, never finer than `floor_t`. */
static float fill_texel(const float r[4], float res, float m, float floor_t)
{
	float span = fmaxf(r[1] - r[0], r[3] - r[2]);
	return fmaxf(span / fmaxf(res - 2.0f * m - 2.0f, 1.0f), floor_t);
}

/* A spot's cone cut down to its casters (casters_rect within the widened cone): a square tile
 * of texels t, from today's (the whole widened cone over lp->resolution) down to the camera's
 * need (the tile at most doubled), then filling the tile, never finer than PCSS's search
 * reaches unless the default size's texels are (the tile, an asked one too, shrunk to what it
 * needs: texels the search cannot reach cost accuracy, Spot and the duck at 4096). Writes the view's rectangle
 * and lp->resolution / size_rule; false: the whole cone (a light among its casters, or no
 * gain), at lp->resolution (64 when none of the casters is in the cone). */
static bool fit_spot(const struct rnd_light *L, const float d[3], const float view[16], float tc,
                     const struct rnd_local_need *need, struct rnd_light_plan *lp, struct tan_rect *out)
{
	bool asked = lp->size_rule == RND_SIZE_ASKED;
	float m = local_margin(lp), res0 = (float)lp->resolution, r[4];
	float t0 = 2.0f * tc * (1.0f + 2.0f * m / res0) / res0;
	int in = casters_rect(view, need->casters, tc + m * t0, r);
	if (in < 0) return false;
	if (in == 0) {
		lp->resolution = RND_MIN_SHADOW_RESOLUTION;   /* nothing in the cone casts */
		lp->size_rule = RND_SIZE_CASTERS;
		return false;
	}
	float span = fmaxf(r[1] - r[0], r[3] - r[2]);
	struct local_texels need_t = local_need(L, d, need, lp);
	float top = asked ? res0 : fmaxf(res0, fminf(2.0f * res0, 2048.0f));
	if (need->cap) top = fminf(top, fmaxf((float)need->cap, res0));
	float res = RND_MIN_SHADOW_RESOLUTION;
	while (res < span / t0 + 2.0f * m + 2.0f && res < res0) res *= 2.0f;
	if (asked) res = res0;
	if (need_t.camera > 0)
		while (!asked && res < span / need_t.camera + 2.0f * m + 2.0f && 2.0f * res <= top) res *= 2.0f;
	/* the search's floor: no finer than it reaches, unless the default size's texels are */
	float def = (float)need->default_res, reach = fminf(need_t.search, 2.0f * tc * (1.0f + 2.0f * m / def) / def);
	float t = fill_texel(r, res, m, 0.0f);
	bool search = reach > t;
	if (search)
		while (res > RND_MIN_SHADOW_RESOLUTION && res / 2.0f >= span / reach + 2.0f * m + 2.0f) res /= 2.0f;
	t = fill_texel(r, res, m, reach);
	if (!search && t >= t0) return false;
	*out = (struct tan_rect){0.5f * (r[0] + r[1]), 0.5f * (r[2] + r[3]), 0.5f * res * t};
	lp->resolution = (uint32_t)res;
	lp->size_rule = search ? RND_SIZE_SEARCH : RND_SIZE_CASTERS;
	return true;
}

/* A perspective view through rectangle q of the tan plane of `view` (off-axis: the light's
 * axis and depth stay, so a texel is 2 q.h / res per unit of depth). */
static void persp_rect_view(struct umbra_shadow_view *v, const float view[16], struct tan_rect q,
                            float znear, float zfar, float res)
{
	float proj[16];
	rnd_mat4_perspective(proj, 0.5f * (float)M_PI, 1.0f, znear, zfar);
	for (int col = 0; col < 4; col++) {
		proj[col * 4 + 0] = (proj[col * 4 + 0] - q.cx * proj[col * 4 + 3]) / q.h;
		proj[col * 4 + 1] = (proj[col * 4 + 1] - q.cy * proj[col * 4 + 3]) / q.h;
	}
	rnd_mat4_mul(v->view_proj, proj, view);
	v->params[0] = 2.0f * q.h / res;
	v->params[1] = 1.0f;
	v->params[2] = znear;
	v->params[3] = zfar;
	v->rect[2] = res;
}

/* Texels (tan units) of a whole cube face of res texels widened by m on each side. */
static float face_texel(float res, float m)
{
	return 2.0f * (1.0f + 2.0f * m / res) / res;
}

/* A point light's faces sized for its casters as fit_spot sizes a spot's tile: finer for the
 * camera up to twice today's side (at most 1024, never for an asked resolution), no finer
 * than PCSS's search reaches unless the default size's are (an asked size is shrunk to that). Each face is then cut to the casters in it
 * (point_face): a receiver's face is its direction's major axis, and so is that of every
 * caster between it and the light. Returns the search's floor on the texel. */
static float size_point(const struct rnd_light *L, const struct rnd_local_need *need, struct rnd_light_plan *lp)
{
	bool asked = lp->size_rule == RND_SIZE_ASKED;
	float m = local_margin(lp), res0 = (float)lp->resolution, res = res0;
	struct local_texels t = local_need(L, NULL, need, lp);
	float top = asked ? res0 : fmaxf(res0, fminf(2.0f * res0, 1024.0f));
	if (need->cap) top = fminf(top, fmaxf((float)need->cap, res0));
	while (t.camera > 0 && face_texel(res, m) > t.camera && 2.0f * res <= top) res *= 2.0f;
	if (res > res0) lp->size_rule = RND_SIZE_CASTERS;
	float def = (float)need->default_res, floor_t = fminf(t.search, face_texel(def, m));
	while (face_texel(res, m) < floor_t && res > def) {
		res /= 2.0f;
		lp->size_rule = RND_SIZE_SEARCH;
	}
	lp->resolution = (uint32_t)res;
	return floor_t;
}

/* Face f of a point light's cube (view): the whole widened face, or the casters' part of it
 * filling the tile, never finer than floor_t. */
static void point_face(struct umbra_shadow_view *v, const float view[16], const struct rnd_local_need *need,
                       const struct rnd_light_plan *lp, float floor_t, float znear, float zfar)
{
	float m = local_margin(lp), res = (float)lp->resolution, whole = face_texel(res, m), r[4];
	struct tan_rect q = {0, 0, 0.5f * res * whole};
	if (need->casters && !rnd_aabb_is_empty(need->casters) && casters_rect(view, need->casters, 1.0f + m * whole, r) > 0) {
		float t = fill_texel(r, res, m, floor_t);
		if (t < whole) q = (struct tan_rect){0.5f * (r[0] + r[1]), 0.5f * (r[2] + r[3]), 0.5f * res * t};
	}
	persp_rect_view(v, view, q, znear, zfar, res);
}

/* A spot light's cone (or the part of it its casters cover), or a point light's six cube
 * faces (each cut to the casters in it). */
enum rnd_result rnd_plan_local(const struct rnd_light *L, uint32_t i, const struct rnd_local_need *need,
                               struct rnd_light_plan *lp, struct rnd_shadow_plan *out, struct rnd_error *err)
{
	/* PCF or hard on a light with a radius: its blur over today's texels stands in for the
	 * penumbra it does not compute (finer texels cost rmse: truth-scenes soft_spot pcf
	 * 0.0266 -> 0.0299); moment maps keep their blur: both keep the whole view. */
	bool fits = need->casters && need->cam && !rnd_aabb_is_empty(need->bounds) && !lp->moments &&
	            (lp->filter == UMBRA_FILTER_PCSS || L->radius <= 0);
	if (fits && rnd_aabb_is_empty(need->casters)) {
		lp->resolution = RND_MIN_SHADOW_RESOLUTION;   /* nothing casts */
		lp->size_rule = RND_SIZE_CASTERS;
		fits = false;
	}
	float reach = L->range > 0 ? L->range : rnd_plan_max_dist(L->position, need->bounds);
	float zfar = fmaxf(reach, 0.1f) * 1.01f;
	float znear = fmaxf(zfar * 1e-3f, 0.01f);
	if (L->type == RND_LIGHT_SPOT) {
		float d[3];
		if (!rnd_v3_normalize(d, L->direction))
			return rnd_fail(err, RND_ERR_INVALID, "light %u: direction is zero", i);
		float up[3] = {0, 1, 0};
		if (fabsf(d[1]) > 0.99f) { up[1] = 0; up[2] = 1; }
		float half = fminf(L->outer_angle, 85.0f * (float)M_PI / 180.0f);
		float view[16], target[3];
		struct tan_rect q;
		rnd_v3_add(target, L->position, d);
		rnd_mat4_look_at(view, L->position, target, up);
		if (fits && fit_spot(L, d, view, tanf(half), need, lp, &q)) {
			persp_rect_view(rnd_plan_next_view(out, i, false), view, q, znear, zfar, (float)lp->resolution);
			return RND_OK;
		}
		float fres = (float)lp->resolution;
		float fov = 2.0f * atanf(tanf(half) * (1.0f + 2.0f * local_margin(lp) / fres));
		persp_view(rnd_plan_next_view(out, i, false), L->position, d, up, fov, znear, zfar, fres);
		return RND_OK;
	}
	static const float dirs[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
	static const float ups[6][3] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
	float floor_t = fits ? size_point(L, need, lp) : 0.0f;
	float fres = (float)lp->resolution;
	float fov = 2.0f * atanf(1.0f + 2.0f * local_margin(lp) / fres);
	for (int f6 = 0; f6 < 6; f6++) {
		if (!fits) {
			persp_view(rnd_plan_next_view(out, i, false), L->position, dirs[f6], ups[f6], fov, znear, zfar, fres);
			continue;
		}
		float view[16], target[3];
		rnd_v3_add(target, L->position, dirs[f6]);
		rnd_mat4_look_at(view, L->position, target, ups[f6]);
		point_face(rnd_plan_next_view(out, i, false), view, need, lp, floor_t, znear, zfar);
	}
	return RND_OK;
}

void rnd_plan_local_regrant(struct umbra_shadow_view *v, const struct rnd_light_plan *lp, float granted)
{
	float planned = v->rect[2], m = local_margin(lp);
	if (granted >= planned || granted <= 2.0f * m + 2.0f) return;
	float k = (planned - 2.0f * m - 2.0f) / planned * granted / (granted - 2.0f * m - 2.0f);   /* >= 1 */
	for (int col = 0; col < 4; col++) {
		v->view_proj[col * 4 + 0] /= k;
		v->view_proj[col * 4 + 1] /= k;
	}
	v->params[0] *= k;
}
