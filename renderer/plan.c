/*
 * renderer/plan.c — shadow-view planning (see plan.h; the camera's is in camera.c). Pure math.
 *
 * Directional lights: `fit` is one orthographic map around what casts shadows, as deep as the
 * scene, with texels no coarser than the default map's around the whole scene and finer where
 * the camera sees the casters close (fit_casters); `cascades` are camera-
 * centred bounding spheres of the practical split scheme's slices (rotating the camera in place
 * moves no cascade), snapped to whole texels in a light basis that does not depend on the
 * camera (translating it moves shadows by whole texels: no shimmer); their depth range covers
 * the scene bounds and depth clamp pancakes casters in front of the near plane.
 */
#include <math.h>
#include <string.h>
#include "error.h"
#include "plan.h"
#include "plan_local.h"

uint32_t rnd_shadow_map_side(uint32_t want, bool asked, uint32_t cap)
{
	if (!want) want = RND_DEFAULT_SHADOW_RESOLUTION;
	if (asked || !cap || cap > RND_MAX_SHADOW_RESOLUTION) cap = RND_MAX_SHADOW_RESOLUTION;
	uint32_t side = RND_MIN_SHADOW_RESOLUTION;
	while (side < want && side * 2 <= cap) side *= 2;
	return side;
}

void rnd_cascade_splits(float znear, float zfar, uint32_t n, float lambda, float out[4])
{
	for (uint32_t i = 0; i < 4; i++) out[i] = zfar;
	for (uint32_t i = 1; i <= n && i <= 4; i++) {
		float t = (float)i / (float)n;
		float lg = znear * powf(zfar / znear, t);
		float un = znear + (zfar - znear) * t;
		out[i - 1] = lambda * lg + (1.0f - lambda) * un;
	}
	if (n >= 1 && n <= 4) out[n - 1] = zfar; /* exact, no rounding drift */
}

bool rnd_aabb_in_frustum(const struct rnd_aabb *b, const float m[16], bool no_near)
{
	/* Planes from the rows of m (Gribb-Hartmann), Vulkan clip: -w<=x<=w, -w<=y<=w, 0<=z<=w. */
	float row[4][4];
	for (int r = 0; r < 4; r++)
		for (int c = 0; c < 4; c++) row[r][c] = m[c * 4 + r];
	float planes[6][4];
	for (int c = 0; c < 4; c++) {
		planes[0][c] = row[3][c] + row[0][c];
		planes[1][c] = row[3][c] - row[0][c];
		planes[2][c] = row[3][c] + row[1][c];
		planes[3][c] = row[3][c] - row[1][c];
		planes[4][c] = row[3][c] - row[2][c];  /* far: z <= w */
		planes[5][c] = row[2][c];              /* near: z >= 0 */
	}
	int np = no_near ? 5 : 6;
	for (int i = 0; i < np; i++) {
		/* The corner furthest along the plane normal. */
		float p[3];
		for (int k = 0; k < 3; k++) p[k] = planes[i][k] >= 0 ? b->max[k] : b->min[k];
		if (planes[i][0] * p[0] + planes[i][1] * p[1] + planes[i][2] * p[2] + planes[i][3] < 0) return false;
	}
	return true;
}

/* A light basis (rotation only) looking along d. */
static void light_basis(float view[16], const float d[3])
{
	float zero[3] = {0, 0, 0};
	float up[3] = {0, 1, 0};
	if (fabsf(d[1]) > 0.99f) { up[1] = 0; up[2] = 1; }
	rnd_mat4_look_at(view, zero, d, up);
}

/* Light-space depth range (distances along the light axis) covering the scene bounds. */
static void depth_range(const float view[16], const struct rnd_aabb *bounds, float *zmin, float *zmax)
{
	*zmin = 1e30f; *zmax = -1e30f;
	for (int i = 0; i < 8; i++) {
		float p[3] = {i & 1 ? bounds->max[0] : bounds->min[0], i & 2 ? bounds->max[1] : bounds->min[1],
		              i & 4 ? bounds->max[2] : bounds->min[2]};
		float q[3];
		rnd_mat4_mul_point(q, view, p);
		*zmin = fminf(*zmin, -q[2]); *zmax = fmaxf(*zmax, -q[2]);
	}
	float pad = fmaxf((*zmax - *zmin) * 0.01f, 1e-3f);
	*zmin -= pad; *zmax += pad;
}

/* An orthographic view of half-width hx and half-height hy; params[0], the texel's world size
 * the shaders use (normal offset, PCSS, contact distance), is the larger side of a texel. */
static void ortho_view_rect(struct umbra_shadow_view *v, const float view[16], float cx, float cy, float hx, float hy,
                            float zmin, float zmax, float res)
{
	float proj[16];
	rnd_mat4_ortho(proj, cx - hx, cx + hx, cy - hy, cy + hy, zmin, zmax);
	rnd_mat4_mul(v->view_proj, proj, view);
	v->params[0] = 2.0f * fmaxf(hx, hy) / res;
	v->params[1] = 0.0f;
	v->params[2] = zmin;
	v->params[3] = zmax;
	v->rect[2] = res;   /* x, y and the atlas size are filled in when the tile is granted */
}

static void ortho_view(struct umbra_shadow_view *v, const float view[16], float cx, float cy, float half,
                       float zmin, float zmax, float res, const float dir[3])
{
	float proj[16];
	rnd_mat4_ortho(proj, cx - half, cx + half, cy - half, cy + half, zmin, zmax);
	rnd_mat4_mul(v->view_proj, proj, view);
	v->params[0] = 2.0f * half / res;
	v->params[1] = 0.0f;
	v->params[2] = zmin;
	v->params[3] = zmax;
	(void)dir;
	v->rect[2] = res;   /* x, y and the atlas size are filled in when the tile is granted */
}

static bool use_cascades(const struct rnd_shadow *s, const struct rnd_aabb *b, const struct rnd_camera_plan *cam)
{
	if (s->dir_mode == RND_DIR_CASCADES) return true;
	if (s->dir_mode == RND_DIR_FIT || s->dir_mode == RND_DIR_CLIPMAP || s->dir_mode == RND_DIR_CASTERS) return false;
	/* auto: one fitted map when the whole scene is seen at about one scale (its size is
	 * within a few camera distances); else cascades. */
	float c[3], d[3], e[3];
	for (int k = 0; k < 3; k++) c[k] = 0.5f * (b->min[k] + b->max[k]);
	rnd_v3_sub(d, b->max, b->min);
	rnd_v3_sub(e, c, cam->pos);
	float dist = fmaxf(rnd_v3_length(e), cam->znear);
	return rnd_v3_length(d) > 8.0f * dist;
}

enum rnd_result rnd_shadow_plan(const struct rnd_scene *scene, const struct rnd_aabb *bounds,
                                const struct rnd_camera_plan *cam, struct rnd_shadow_plan *out, struct rnd_error *err)
{
	return rnd_shadow_plan_with(scene, bounds, NULL, cam, NULL, 0, out, err);
}

/* The next shadow view, of light i (ortho: depth clamp instead of near-plane culling). */
struct umbra_shadow_view *rnd_plan_next_view(struct rnd_shadow_plan *out, uint32_t i, bool ortho)
{
	out->view_light[out->view_count] = i;
	out->view_ortho[out->view_count] = ortho;
	return &out->views[out->view_count++];
}

/* The light's filter (AUTO: PCSS for an area light, else PCF), PCF radius, search and bias. */
static enum rnd_result plan_filter(const struct rnd_light *L, uint32_t i, struct rnd_light_plan *lp,
                                   struct rnd_error *err)
{
	const struct rnd_shadow *s = &L->shadow;
	float size = L->type == RND_LIGHT_DIRECTIONAL ? L->angular_diameter : L->radius;
	enum rnd_filter f = s->filter;
	if (f == RND_FILTER_AUTO) f = size > 0 ? RND_FILTER_PCSS : RND_FILTER_PCF;
	switch (f) {
	case RND_FILTER_HARD: lp->filter = UMBRA_FILTER_HARD; break;
	case RND_FILTER_PCF: lp->filter = UMBRA_FILTER_PCF; break;
	case RND_FILTER_PCSS: lp->filter = UMBRA_FILTER_PCSS; break;
	case RND_FILTER_VSM:
	case RND_FILTER_EVSM:
		lp->filter = UMBRA_FILTER_MOMENTS;
		lp->moments = true;
		lp->evsm = f == RND_FILTER_EVSM;
		lp->evsm_exponent = s->vsm_exponent;
		lp->fp16 = s->vsm_precision == RND_VSM_FP16;
		break;
	default:
		return rnd_fail(err, RND_ERR_INVALID, "light %u: unknown shadow filter %d", i, (int)f);
	}
	lp->pcf_radius = s->pcf_radius > 5 ? 5 : s->pcf_radius;
	lp->search_texels = 24.0f;
	/* Defaults come from rnd_shadow_defaults(); see there. */
	lp->bias_constant = s->bias_constant; lp->bias_slope = s->bias_slope; lp->bias_normal = s->bias_normal;
	return RND_OK;
}

/* Clipmap: concentric camera-centred levels, each twice as wide as the one before; every level
 * snapped to its own texel grid. */
static void plan_clipmap(const struct rnd_shadow *s, uint32_t i, const float view[16], const float d[3], float zmin,
                         float zmax, const struct rnd_aabb *bounds, const struct rnd_camera_plan *cam, uint32_t ncasc,
                         struct rnd_light_plan *lp, struct rnd_shadow_plan *out)
{
	float fres = (float)lp->resolution;
	float maxd = s->max_distance > 0 ? s->max_distance : fminf(cam->zfar, rnd_plan_max_dist(cam->pos, bounds));
	float extent = s->clipmap_extent > 0 ? s->clipmap_extent : 2.0f * maxd / (float)(1u << (ncasc - 1));
	float eye_ls[3];
	rnd_mat4_mul_point(eye_ls, view, cam->pos);
	for (uint32_t c = 0; c < ncasc; c++) {
		float half = 0.5f * extent * (float)(1u << c);
		float texel = 2.0f * half / fres;
		float cx = floorf(eye_ls[0] / texel + 0.5f) * texel;
		float cy = floorf(eye_ls[1] / texel + 0.5f) * texel;
		ortho_view(rnd_plan_next_view(out, i, true), view, cx, cy, half, zmin, zmax, fres, d);
	}
	lp->clipmap = true;
	lp->max_distance = s->max_distance > 0 ? s->max_distance : 0.5f * extent * (float)(1u << (ncasc - 1));
}

/* Cascades: camera-centred spheres of the split slices, snapped to whole texels. */
static void plan_cascades(const struct rnd_shadow *s, uint32_t i, const float view[16], const float d[3], float zmin,
                          float zmax, const struct rnd_aabb *bounds, const struct rnd_camera_plan *cam,
                          uint32_t ncasc, struct rnd_light_plan *lp, struct rnd_shadow_plan *out)
{
	float fres = (float)lp->resolution;
	/* Splits must not depend on where the camera is (a derived near/far does), or the
	 * cascades' texel size would change as it moves: use the light's max_distance, else the
	 * caller's far, capped by the scene's size. */
	float diag[3];
	rnd_v3_sub(diag, bounds->max, bounds->min);
	float maxd = rnd_v3_length(diag);
	if (cam->user_far > 0 && cam->user_far < maxd) maxd = cam->user_far;
	if (s->max_distance > 0) maxd = s->max_distance;
	float split_near = cam->user_near > 0 ? cam->user_near : fmaxf(0.05f, maxd / 2000.0f);
	split_near = fmaxf(split_near, 0.05f);
	if (maxd <= split_near) maxd = split_near * 2.0f;
	rnd_cascade_splits(split_near, maxd, ncasc, s->split_lambda, lp->splits);
	lp->max_distance = maxd;
	/* Distance from the eye to a far corner of the slice at depth z. */
	float k = cam->ortho ? 0.0f : tanf(cam->fov_y * 0.5f);
	float corner = sqrtf(1.0f + k * k * (1.0f + cam->aspect * cam->aspect));
	float eye_ls[3];
	rnd_mat4_mul_point(eye_ls, view, cam->pos);
	for (uint32_t c = 0; c < ncasc; c++) {
		float r = lp->splits[c] * corner;
		if (cam->ortho) {
			float h = cam->ortho_height * 0.5f, w = h * cam->aspect;
			r = sqrtf(lp->splits[c] * lp->splits[c] + h * h + w * w);
		}
		/* Round the radius up to a coarse step so small changes of near/far do not change
		 * the texel size; then snap the centre to whole texels. */
		r = ceilf(r * 16.0f) / 16.0f;
		/* Room for the half texel that snapping moves the centre by and for the filter
		 * footprint, so taps near a cascade's edge stay inside it. */
		float margin = 0.5f + (float)lp->pcf_radius + 2.0f +
		               (lp->filter == UMBRA_FILTER_PCSS ? lp->search_texels : 0.0f);
		r *= fres / (fres - 2.0f * margin);
		float texel = 2.0f * r / fres;
		float cx = floorf(eye_ls[0] / texel + 0.5f) * texel;
		float cy = floorf(eye_ls[1] / texel + 0.5f) * texel;
		ortho_view(rnd_plan_next_view(out, i, true), view, cx, cy, r, zmin, zmax, fres, d);
	}
}

/* The `fit` map's light-space box around box b (centre cx, cy; half sizes hx, hy). Under a
 * low sun the ground's extent across the light's up axis is sin(elevation) of its length, and
 * a square map wastes all but that share of its rows (7 degrees: texels 8x longer on the
 * ground than across, a PCF ramp of several pixels along every long shadow). So where a
 * square map would leave more than half its rows or columns empty, the map is the box itself
 * (texels at most 32:1 for a flat scene under a horizon sun). Not below that: finer texels
 * make round shapes finer in the map (lod.c: 1/8 texel), which cost thumb-512 (sun 60 degrees
 * up, box 1.3:1) ~15 % CPU for no visible change. PCSS sizes its disk from one texel size and
 * keeps square texels. */
static void fit_box(const float view[16], const struct rnd_aabb *b, uint32_t filter, float *cx, float *cy, float *hx,
                    float *hy)
{
	struct rnd_aabb lb;
	rnd_aabb_transform(&lb, b, view);
	*cx = 0.5f * (lb.min[0] + lb.max[0]); *cy = 0.5f * (lb.min[1] + lb.max[1]);
	*hx = 0.5f * (lb.max[0] - lb.min[0]); *hy = 0.5f * (lb.max[1] - lb.min[1]);
	float hmax = fmaxf(*hx, *hy);
	if (filter == UMBRA_FILTER_PCSS || fminf(*hx, *hy) > 0.5f * hmax) *hx = *hy = hmax;
	*hx = fmaxf(*hx, hmax / 32.0f); *hy = fmaxf(*hy, hmax / 32.0f);
}

/* World size of one camera pixel at the point of box b nearest the camera (an orthographic
 * camera: the same everywhere); 0 = no camera, no image height or an empty box. */
static float camera_pixel_at(const struct rnd_camera_plan *cam, uint32_t height, const struct rnd_aabb *b)
{
	if (!cam || !height || rnd_aabb_is_empty(b)) return 0.0f;
	if (cam->ortho) return cam->ortho_height / (float)height;
	float d2 = 0;
	for (int k = 0; k < 3; k++) {
		float e = fmaxf(fmaxf(b->min[k] - cam->pos[k], cam->pos[k] - b->max[k]), 0.0f);
		d2 += e * e;
	}
	return 2.0f * tanf(0.5f * cam->fov_y) * fmaxf(sqrtf(d2), cam->znear) / (float)height;
}

/* What a `fit` sun map's texel must resolve: a camera pixel's world size at the casters'
 * nearest point (0: no camera), and the half-width of the light's widest penumbra on the
 * scene's receivers (world units). */
struct fit_need {
	float pixel, penumbra;
};

/* The longest way light passes from a corner of the casters' box along d before it leaves the
 * scene's box: where their shadows can fall at the farthest. */
static float shadow_reach(const float d[3], const struct rnd_aabb *casters, const struct rnd_aabb *bounds)
{
	float far = 0;
	for (int i = 0; i < 8 && !rnd_aabb_is_empty(casters); i++) {
		float t = 1e30f;
		for (int k = 0; k < 3; k++) {
			float p = i >> k & 1 ? casters->max[k] : casters->min[k];
			if (fabsf(d[k]) > 1e-6f) t = fminf(t, ((d[k] > 0 ? bounds->max[k] : bounds->min[k]) - p) / d[k]);
		}
		far = fmaxf(far, fmaxf(t, 0.0f));
	}
	return far;
}

/* Width in texels of the smallest footprint the light's filter blurs an edge over: PCF's
 * (2r+1) kernel, PCSS's narrowest disk (radius 1) and its bilinear taps; a moment map's blur
 * is the softness asked for, in texels (test_moments): one texel. */
float rnd_plan_kernel_texels(const struct rnd_light_plan *lp)
{
	if (lp->filter == UMBRA_FILTER_PCSS) return 3.0f;
	return lp->filter == UMBRA_FILTER_PCF ? 2.0f * (float)lp->pcf_radius + 1.0f : 1.0f;
}

/* A `fit` map (centre cx, cy; half sizes hx, hy; margin grow; fres texels) cut down to the
 * casters' box, as deep as before: a receiver outside it has nothing between it and the sun.
 * (thumb-256 drew a 2048^2 map and used a 400^2 corner.) The texel: the whole scene's map's,
 * finer where the camera sees the casters close (`pixel`, a camera pixel's world size at the
 * casters' nearest point): the filter's narrowest kernel within a pixel, as hard_light_res
 * asks of a hard spot, and at most one doubling of the tile the scene's texels need (the
 * shadow pass grows at most 4x); then the tile filled (the texel shrunk until the box and the
 * filter's reach span it: the same texels, finer), except that PCSS's texels stay wide enough
 * for its 24-texel search to reach the light's widest penumbra on the scene's receivers
 * (`penumbra`), in the tile they need, coarser than the scene's if need be. A light asking for
 * a resolution gets that tile, filled, unless PCSS's texels are coarser than the scene's: then
 * the tile they need. Below the default too (issue 31: a 4 cm pole on a 10 m ground under a
 * soft sun, asked 256, had 4 cm texels over the whole ground and its shadow came out a grey
 * line: missing_contact 0.156 with contact shadows; on the casters 0.031). Issue 31: a masked checker 0.7 m over a
 * 14 m ground had the ground's 9 mm texels in a half-empty 256 tile, about three to a pixel:
 * PCSS's narrowest disk blurred its cells' edges over a pixel (IoU 0.948 against Cycles).
 * The grid: whole texels from the light basis' origin. A moment blur clamps at the tile's edge
 * and a lit ground read dark within a blur of it: that band reads as lit (moment_edge), the
 * casters keep a blur away from it. */
static void fit_casters(const struct rnd_shadow *s, const float view[16], const struct rnd_aabb *casters,
                        const struct fit_need *need, struct rnd_light_plan *lp, float *fres, float *cx, float *cy,
                        float *hx, float *hy, float *grow)
{
	float blur = ceilf(fmaxf(s->vsm_blur, 0.0f));
	float reach = (lp->filter == UMBRA_FILTER_PCSS ? lp->search_texels
	               : lp->moments ? 2.0f * blur + 1.0f : (float)lp->pcf_radius) + 2.0f;
	/* the whole scene's map's texels */
	float tx = 2.0f * *hx * *grow / *fres, ty = 2.0f * *hy * *grow / *fres;
	uint32_t res = 64;
	float fill = 1.0f;   /* texels per scene texel: > 1 finer than the scene's, < 1 coarser */
	bool cut = rnd_aabb_is_empty(casters);   /* nothing casts: the smallest tile */
	if (!cut) {
		struct rnd_aabb lc;
		rnd_aabb_transform(&lc, casters, view);
		float span = fmaxf((lc.max[0] - lc.min[0]) / tx, (lc.max[1] - lc.min[1]) / ty);  /* in those texels */
		while ((float)res < span + 2.0f * reach + 2.0f && (float)res < *fres) res *= 2;
		if (s->resolution) res = (uint32_t)*fres;
		float want = need->pixel / rnd_plan_kernel_texels(lp), finer = want > 0 ? fminf(want / fmaxf(tx, ty), 1.0f) : 1.0f;
		if (span / finer + 2.0f * reach + 2.0f > (float)res && 2.0f * (float)res <= *fres) res *= 2;
		float fit = ((float)res - 2.0f * reach - 2.0f) / fmaxf(span, 1e-6f);   /* texels per scene texel */
		/* PCSS searches and filters within search_texels: texels no finer than its widest
		 * penumbra there needs (coarser than the scene's if need be: a 14 degree sun's
		 * penumbra 1.2 m under a plate is 50 of the scene's texels wide, and a search and
		 * filter cut at 24 drew it half as wide as the traced one); the tile no larger than
		 * they need */
		float least = 1.0f;   /* the coarsest texels allowed, per scene texel */
		fill = fit;
		if (lp->filter == UMBRA_FILTER_PCSS && need->penumbra > 0) {
			float search = fmaxf(tx, ty) * lp->search_texels / need->penumbra;
			fill = fminf(fit, search);
			least = fminf(search, 1.0f);
		}
		/* an asked tile too where the search's texels are coarser than the scene's: the
		 * rest of it would cover nothing that casts, in the same texels */
		while ((!s->resolution || fill < 1.0f) && res > 64 && (float)res / 2.0f >= span * fill + 2.0f * reach + 2.0f)
			res /= 2;
		if (fit >= least) {
			cut = true;
			tx /= fill; ty /= fill;
			*hx = 0.5f * (float)res * tx; *hy = 0.5f * (float)res * ty;
			*cx = tx * roundf(0.5f * (lc.min[0] + lc.max[0]) / tx);
			*cy = ty * roundf(0.5f * (lc.min[1] + lc.max[1]) / ty);
			*grow = 1.0f;
			if (lp->moments) lp->moment_edge = blur + 1.0f;
		}
	}
	if (!cut) res = (uint32_t)*fres;
	lp->resolution = res;
	if (cut) lp->size_rule = fill < 1.0f ? RND_SIZE_SEARCH : RND_SIZE_CASTERS;
	*fres = (float)lp->resolution;
}

/* A directional light's views: clipmap levels, one fitted map, or cascades. */
static enum rnd_result plan_directional(const struct rnd_light *L, uint32_t i, const struct rnd_aabb *bounds,
                                        const struct rnd_aabb *casters, float cam_pixel, const struct rnd_camera_plan *cam,
                                        bool clipmap, bool cascades, uint32_t ncasc, struct rnd_light_plan *lp,
                                        struct rnd_shadow_plan *out, struct rnd_error *err)
{
	const struct rnd_shadow *s = &L->shadow;
	float fres = (float)lp->resolution;
	float d[3], view[16];
	if (!rnd_v3_normalize(d, L->direction))
		return rnd_fail(err, RND_ERR_INVALID, "light %u: direction is zero", i);
	light_basis(view, d);
	float zmin, zmax;
	depth_range(view, bounds, &zmin, &zmax);
	if (clipmap) {
		plan_clipmap(s, i, view, d, zmin, zmax, bounds, cam, ncasc, lp, out);
	} else if (!cascades) {
		/* fit: the box (fit_box) of the scene's light-space bounds, the texels it has at
		 * the light's resolution; then the casters' (fit_casters). */
		float cx, cy, hx, hy;
		/* RND_DIR_CASTERS (the environment's directions): the casters' box at the light's own
		 * resolution; as deep as the scene, which holds every receiver. */
		bool own = s->dir_mode == RND_DIR_CASTERS && casters && !rnd_aabb_is_empty(casters);
		fit_box(view, own ? casters : bounds, lp->filter, &cx, &cy, &hx, &hy);
		float grow = 1.0f + 4.0f / fres;   /* a filter footprint of margin at the edges */
		if (own) grow = 1.0f + 2.0f * ((lp->filter == UMBRA_FILTER_PCSS ? lp->search_texels : (float)lp->pcf_radius) + 3.0f) / fres;
		else if (casters) {
			struct fit_need need = {cam_pixel, tanf(0.5f * L->angular_diameter) * shadow_reach(d, casters, bounds)};
			fit_casters(s, view, casters, &need, lp, &fres, &cx, &cy, &hx, &hy, &grow);
		}
		ortho_view_rect(rnd_plan_next_view(out, i, true), view, cx, cy, hx * grow, hy * grow, zmin, zmax, fres);
		lp->max_distance = s->max_distance;
	} else {
		plan_cascades(s, i, view, d, zmin, zmax, bounds, cam, ncasc, lp, out);
	}
	lp->fade_start = lp->max_distance * (1.0f - fminf(fmaxf(s->fade, 0.0f), 1.0f));
	return RND_OK;
}

enum rnd_result rnd_shadow_plan_with(const struct rnd_scene *scene, const struct rnd_aabb *bounds,
                                     const struct rnd_aabb *casters, const struct rnd_camera_plan *cam,
                                     const uint8_t *forced, uint32_t atlas,
                                     struct rnd_shadow_plan *out, struct rnd_error *err)
{
	memset(out, 0, sizeof *out);
	if (scene->light_count > UMBRA_MAX_LIGHTS)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_LIGHTS, 0, "%u lights: the renderer takes at most %d",
		                   scene->light_count, UMBRA_MAX_LIGHTS);
	bool empty = rnd_aabb_is_empty(bounds);
	out->resolution = 0;
	float cam_pixel = casters ? camera_pixel_at(cam, scene->height, casters) : 0.0f;
	uint32_t local_lights = 0;
	for (uint32_t i = 0; i < scene->light_count; i++)
		local_lights += scene->lights[i].shadow.enabled && scene->lights[i].type != RND_LIGHT_DIRECTIONAL;
	const struct rnd_aabb *fit = local_lights <= RND_LOCAL_FIT_LIGHTS_MAX ? casters : NULL;
	struct rnd_local_need local = {bounds, fit, cam, scene->height, scene->max_shadow_resolution, 0};

	for (uint32_t i = 0; i < scene->light_count && !empty; i++) {
		const struct rnd_light *L = &scene->lights[i];
		const struct rnd_shadow *s = &L->shadow;
		struct rnd_light_plan *lp = &out->lights[i];
		enum rnd_result r;
		if (!s->enabled) continue;
		/* Tile size: the light's resolution rounded up to a power of two (atlas tiles), else
		 * by type: a sun map covers the whole view, a spot cone less, a cube face a sixth. */
		if ((r = plan_filter(L, i, lp, err)) != RND_OK) return r;
		uint32_t want = s->resolution ? s->resolution : RND_DEFAULT_SHADOW_RESOLUTION;
		lp->size_rule = s->resolution ? RND_SIZE_ASKED : RND_SIZE_DEFAULT;
		if (L->type != RND_LIGHT_DIRECTIONAL) {
			uint8_t rule;
			uint32_t def = rnd_plan_local_want(L, lp, bounds, cam, scene->height, &rule);
			local.default_res = rnd_shadow_map_side(def, false, scene->max_shadow_resolution);
			if (!s->resolution) want = def, lp->size_rule = rule;
		}
		lp->resolution = rnd_shadow_map_side(want, s->resolution != 0, scene->max_shadow_resolution);
		if (lp->resolution < rnd_shadow_map_side(want, s->resolution != 0, 0)) lp->size_rule = RND_SIZE_CAPPED;
		uint32_t need = L->type == RND_LIGHT_POINT ? 6 : 1;
		/* More texels than the atlas holds would be halved after planning (rnd_atlas_fit)
		 * with the view kept: a point light asked for 4096 planned six faces cut to its
		 * casters at 4096, was granted 1024 and drew them with texels coarser than the
		 * default size's (issue 31: the duck under a 2 cm point light, rmse .0098 -> .0125). */
		while (L->type != RND_LIGHT_DIRECTIONAL && atlas && lp->resolution > RND_MIN_SHADOW_RESOLUTION &&
		       (uint64_t)need * lp->resolution * lp->resolution > (uint64_t)atlas * atlas) {
			lp->resolution /= 2;
			if (lp->size_rule == RND_SIZE_ASKED) lp->size_rule = RND_SIZE_ATLAS;
		}
		bool cascades = false, clipmap = false;
		uint32_t ncasc = 1;
		if (L->type == RND_LIGHT_DIRECTIONAL && s->dir_mode == RND_DIR_CLIPMAP) {
			clipmap = true;
			ncasc = s->clipmap_levels ? s->clipmap_levels : 6;
			if (ncasc > 8) ncasc = 8;
			need = ncasc;
		} else if (L->type == RND_LIGHT_DIRECTIONAL && (forced ? forced[i] != 0 : use_cascades(s, bounds, cam))) {
			cascades = true;
			ncasc = s->cascades ? s->cascades : 4;
			if (ncasc > 4) ncasc = 4;
			need = ncasc;
		}
		if (out->view_count + need > UMBRA_MAX_SHADOW_VIEWS)
			return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_LIGHT, i, "light %u: more than %d shadow views in one scene", i,
			                   UMBRA_MAX_SHADOW_VIEWS);
		lp->first_view = out->view_count;
		lp->view_count = need;
		lp->follows_camera = cascades || clipmap;
		r = L->type == RND_LIGHT_DIRECTIONAL ? plan_directional(L, i, bounds, casters, cam_pixel, cam, clipmap, cascades, ncasc, lp, out, err)
		                                     : rnd_plan_local(L, i, &local, lp, out, err);
		if (r != RND_OK) return r;
		if (lp->resolution > out->resolution) out->resolution = lp->resolution;
	}
	return RND_OK;
}
