/*
 * renderer/lod.c — screen-space-error level of detail of spheres and cylinders (see lod.h).
 *
 * The bound is geometric: a UV sphere's or cylinder's chords, centred on the true surface
 * (rnd_lod_radius), deviate from it by at most half the sagitta of their segments (the latitude
 * step of a sphere equals its longitude step, so one circle rule covers both), scaled by the
 * model's largest axis scale. Centring matters: chords all inside shrink a silhouette by the
 * whole sagitta, which measurably blurs it (tests/bench/edge_error.c). That error is compared
 * with the world size of a pixel at the point of the object nearest each camera, and of a texel
 * at the point nearest each shadow view; the object gets the segments the tightest of them
 * needs, never more than asked for. (Which planes cast shadows is casters.c's.)
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "casters.h"
#include "lod.h"
#include "mesh.h"
#include "proxy.h"

#define PI_F 3.14159265358979323846f

float rnd_lod_chord_error(float radius, uint32_t segments)
{
	if (segments < 3) segments = 3;
	/* 1 - cos x = 2 sin^2(x/2), in double: no cancellation for fine tessellations. */
	double h = sin(0.5 * (double)PI_F / (double)segments);
	return (float)(fabs((double)radius) * h * h);
}

uint32_t rnd_lod_circle_segments(float radius, float max_error)
{
	if (!(max_error > 0.0f) || !isfinite(radius)) return UINT32_MAX;
	radius = fabsf(radius);
	if (max_error >= 0.5f * radius) return 4;
	/* Centred chords (rnd_lod_radius): r (1 - cos(pi/N)) / 2 <= e  <=>  N >= pi / acos(1 - 2e/r);
	 * in double: e/r can be 1e-6. */
	double n = ceil((double)PI_F / acos(1.0 - 2.0 * (double)max_error / (double)radius) - 1e-9);
	if (n > 1e9) return UINT32_MAX;
	uint32_t s = n < 4.0 ? 4u : (uint32_t)n;
	return s + (s & 1u); /* even: a sphere's latitudes are segments / 2 */
}

float rnd_lod_radius(float radius, uint32_t segments, uint32_t asked)
{
	if (segments >= asked || segments < 3) return radius;
	/* Vertices at R, chord middles at R cos(pi/S): R (1 + cos(pi/S)) / 2 = r centres them. */
	return (float)(2.0 * (double)radius / (1.0 + cos((double)PI_F / (double)segments)));
}

/* Length of row r (x, y, z) of a column-major matrix. */
static float row_len(const float m[16], int r)
{
	return sqrtf(m[r] * m[r] + m[4 + r] * m[4 + r] + m[8 + r] * m[8 + r]);
}

float rnd_lod_pixel_world(const float view_proj[16], float width, float height, const float centre[3], float radius,
                          float near_w)
{
	const float *m = view_proj;
	/* Clip x = row0 . p, w = row3 . p: moving p by d shifts NDC x by at most |row0| d / w, and a
	 * pixel is 2 / width of NDC. The nearest point of the sphere has the smallest w. */
	float w = m[3] * centre[0] + m[7] * centre[1] + m[11] * centre[2] + m[15];
	w -= radius * row_len(m, 3);
	if (w < near_w) w = near_w;
	if (w < 1e-6f) w = 1e-6f;
	float gx = row_len(m, 0) * width, gy = row_len(m, 1) * height;
	float g = gx > gy ? gx : gy;
	return g > 0.0f ? 2.0f * w / g : INFINITY;
}

/* Centre, bounding radius and largest axis scale of a sphere / cylinder / mesh with levels in
 * world space (a mesh's from its coarsest level: few vertices, the same extent within its error). */
static void object_sphere(const struct rnd_object *o, float centre[3], float *bound, float *scale)
{
	const float *m = o->model;
	float s = rnd_mat4_max_axis_scale(m), lc[3] = {0, 0, 0}, r = fabsf(o->radius);
	if (o->shape == RND_SHAPE_MESH && o->lod_count) {
		const struct rnd_mesh_lod *l = &o->lods[o->lod_count - 1];
		struct rnd_aabb b;
		rnd_aabb_empty(&b);
		for (uint32_t i = 0; i < l->vertex_count; i++) rnd_aabb_add_point(&b, l->positions + 3 * i);
		float d[3];
		for (int k = 0; k < 3; k++) { lc[k] = 0.5f * (b.min[k] + b.max[k]); d[k] = b.max[k] - lc[k]; }
		r = l->vertex_count ? rnd_v3_length(d) : 0.0f;
	}
	rnd_mat4_mul_point(centre, m, lc);
	float h = o->shape == RND_SHAPE_CYLINDER ? 0.5f * fabsf(o->height) : 0.0f;
	*bound = sqrtf(r * r + h * h) * s;
	*scale = s;
}

uint32_t rnd_lod_mesh_level(const struct rnd_object *o, float pixel_world, float error_pixels)
{
	if (o->shape != RND_SHAPE_MESH || !o->lod_count) return 0;
	float c[3], bound, scale;
	object_sphere(o, c, &bound, &scale);
	float allowed = scale > 0.0f ? error_pixels * pixel_world / scale : 0.0f;
	uint32_t level = 0;
	while (level < o->lod_count && o->lods[level].error <= allowed) level++;
	return level;
}

void rnd_lod_apply(struct rnd_object *o, uint32_t lod)
{
	if (o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_CYLINDER) {
		o->radius = rnd_lod_radius(o->radius, lod, o->segments);
		o->segments = lod;
	} else if (o->shape == RND_SHAPE_MESH && lod > 0 && lod <= o->lod_count &&
	           (!o->uvs1 || o->lods[lod - 1].uvs1) &&   /* a level without the second set: the full mesh */
	           (!o->colors || o->lods[lod - 1].colors) &&   /* nor without the colours */
	           (!o->tangents || o->lods[lod - 1].tangents)) {   /* nor without the tangents */
		const struct rnd_mesh_lod *l = &o->lods[lod - 1];
		o->positions = l->positions;
		o->normals = l->normals;
		o->uvs = l->uvs;
		o->uvs1 = l->uvs1;
		if (o->colors) o->colors = l->colors;
		if (o->tangents) o->tangents = l->tangents;
		o->indices = l->indices;
		o->vertex_count = l->vertex_count;
		o->index_count = l->index_count;
	}
}

uint32_t rnd_lod_object_segments(const struct rnd_object *o, float pixel_world, float error_pixels)
{
	uint32_t asked = o->segments < 3 ? 3 : o->segments;
	if (o->shape != RND_SHAPE_SPHERE && o->shape != RND_SHAPE_CYLINDER) return o->segments;
	float c[3], bound, scale;
	object_sphere(o, c, &bound, &scale);
	uint32_t need = rnd_lod_circle_segments(fabsf(o->radius) * scale, error_pixels * pixel_world);
	return need < asked ? need : asked;
}

static bool is_round(const struct rnd_object *o)
{
	return o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_CYLINDER;
}

static bool has_levels(const struct rnd_object *o)
{
	return o->shape == RND_SHAPE_MESH && o->lod_count > 0;
}

/* Raises need[i] to what view_proj (w x h pixels, error bounds err for round shapes and
 * mesh_err for meshes with levels, in pixels) asks of each object (only the casters when
 * casters_only); for a mesh lowers the level instead. */
static void need_in_view(const struct rnd_scene *sc, const float vp[16], float w, float h, float near_w, float err,
                         float mesh_err, bool casters_only, uint32_t *need)
{
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		if ((!is_round(o) && !has_levels(o)) || (casters_only && !o->cast_shadows)) continue;
		if (has_levels(o) && mesh_err <= 0.0f) continue;
		float c[3], bound, scale;
		object_sphere(o, c, &bound, &scale);
		float pw = rnd_lod_pixel_world(vp, w, h, c, bound, near_w);
		if (has_levels(o)) {
			uint32_t level = rnd_lod_mesh_level(o, pw, mesh_err); /* coarser is larger: keep the finest */
			if (level < need[i]) need[i] = level;
			continue;
		}
		uint32_t s = rnd_lod_object_segments(o, pw, err);
		if (s > need[i]) need[i] = s;
	}
}

/* Every object as asked (the fallback when a plan fails): its segments, a mesh in full. */
static void as_asked(const struct rnd_scene *sc, uint32_t *segments)
{
	for (uint32_t i = 0; i < sc->object_count; i++)
		segments[i] = has_levels(&sc->objects[i]) ? 0 : sc->objects[i].segments;
}

void rnd_object_bounds(const struct rnd_scene *sc, uint32_t i, const struct rnd_aabb *drawn, struct rnd_aabb *out)
{
	struct rnd_aabb lb;
	if (drawn && sc->objects[i].shape == RND_SHAPE_MESH) { *out = *drawn; return; }
	rnd_mesh_local_bounds(&sc->objects[i], &lb);
	if (rnd_aabb_is_empty(&lb)) *out = lb;
	else rnd_aabb_transform(out, &lb, sc->objects[i].model);
}

/* The bounds render.c will plan with, estimated from the objects as asked (tessellated
 * vertices lie on the shapes): all; obj, without planes and shadow catchers (what `fit:
 * objects` frames); and what casts shadows (a plane only where it may shadow the other
 * objects: tested against their union, and each other plane). */
static void estimate_bounds(const struct rnd_scene *sc, struct rnd_aabb *all, struct rnd_aabb *obj,
                            struct rnd_aabb *casters)
{
	struct rnd_aabb wb, solid, other;
	rnd_aabb_empty(all);
	rnd_aabb_empty(obj);
	rnd_aabb_empty(casters);
	rnd_aabb_empty(&solid);   /* every object but the planes */
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		rnd_object_bounds(sc, i, NULL, &wb);
		if (rnd_aabb_is_empty(&wb)) continue;
		rnd_aabb_union(all, &wb);
		bool catcher = sc->material_count && sc->materials[o->material].shadow_catcher;
		if (o->shape != RND_SHAPE_PLANE && !catcher) rnd_aabb_union(obj, &wb);
		if (o->shape == RND_SHAPE_PLANE) continue;
		rnd_aabb_union(&solid, &wb);
		if (o->cast_shadows && !catcher) rnd_aabb_union(casters, &wb);
	}
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		bool catcher = sc->material_count && sc->materials[o->material].shadow_catcher;
		if (o->shape != RND_SHAPE_PLANE || !o->cast_shadows || catcher) continue;
		/* as render.c's casters' box, on geometry alone (it also leaves out a ground whose
		 * shadow no camera sees: that map keeps the whole scene's texel size, all this needs) */
		bool cast = !rnd_planes_judged(sc) || (!rnd_aabb_is_empty(&solid) && rnd_plane_may_shadow(sc, o, &solid));
		for (uint32_t j = 0; j < sc->object_count && !cast; j++) {
			if (j == i || sc->objects[j].shape != RND_SHAPE_PLANE) continue;
			rnd_object_bounds(sc, j, NULL, &other);
			cast = !rnd_aabb_is_empty(&other) && rnd_plane_may_shadow(sc, o, &other);
		}
		if (cast) {
			rnd_object_bounds(sc, i, NULL, &wb);
			rnd_aabb_union(casters, &wb);
		}
	}
	if (rnd_aabb_is_empty(obj)) *obj = *all;
}

void rnd_lod_proxies(const struct rnd_scene *sc, uint32_t nviews, const uint32_t *segments, struct rnd_proxy *proxies)
{
	memset(proxies, 0, sc->object_count * sizeof *proxies);
	/* One camera: the proxy's outline is where its rays graze the sphere. A fitted one is placed
	 * here from the estimated bounds, as rnd_lod_choose() places it; render.c confirms that
	 * its own placement agrees (rnd_proxy_fits). */
	if (nviews != 1 || sc->view_count > 1 || sc->exact_segments || sc->output.debug == RND_DEBUG_ATLAS) return;
	const char *env = getenv("UMBRA_SPHERE_PROXY");   /* 0: the meshes (tests, comparisons) */
	if (env && strcmp(env, "0") == 0) return;
	struct rnd_aabb bounds, obj_bounds, casters;
	estimate_bounds(sc, &bounds, &obj_bounds, &casters);
	struct rnd_camera_plan cam;
	struct rnd_error err;
	const struct rnd_camera *camera = sc->view_count ? &sc->views[0] : &sc->camera;
	if (rnd_camera_plan(camera, sc->width, sc->height, camera->fit == RND_FIT_OBJECTS ? &obj_bounds : &bounds, &cam,
	                    &err) != RND_OK)
		return;
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (sc->objects[i].shape == RND_SHAPE_SPHERE)
			rnd_proxy_plan(sc, &sc->objects[i], &cam, (float)sc->width, (float)sc->height, segments[i], &proxies[i]);
}

void rnd_lod_choose(const struct rnd_scene *sc, uint32_t nviews, struct rnd_shadow_plan *scratch, uint32_t *segments)
{
	bool any = false;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		/* round: raised to the largest need; levels: lowered to the finest any view needs */
		segments[i] = is_round(o) ? 0 : has_levels(o) ? o->lod_count : o->segments;
		any |= is_round(o) || has_levels(o);
	}
	if (!any || sc->exact_segments) {
		as_asked(sc, segments);
		return;
	}
	struct rnd_aabb bounds, obj_bounds, casters;
	estimate_bounds(sc, &bounds, &obj_bounds, &casters);
	struct rnd_error err;
	for (uint32_t v = 0; v < nviews; v++) {
		const struct rnd_camera *camera = sc->view_count ? &sc->views[v] : &sc->camera;
		struct rnd_camera_plan cam;
		if (rnd_camera_plan(camera, sc->width, sc->height, camera->fit == RND_FIT_OBJECTS ? &obj_bounds : &bounds, &cam,
		                    &err) != RND_OK ||
		    rnd_shadow_plan_with(sc, &bounds, &casters, &cam, NULL, 0, scratch, &err) != RND_OK) {
			as_asked(sc, segments);
			return;
		}
		need_in_view(sc, cam.view_proj, (float)sc->width, (float)sc->height, cam.ortho ? 0.0f : cam.znear,
		             RND_LOD_PIXEL_ERROR, RND_LOD_MESH_PIXEL_ERROR, false, segments);
		for (uint32_t k = 0; k < scratch->view_count; k++) {
			const struct umbra_shadow_view *sv = &scratch->views[k];
			float res = (float)scratch->lights[scratch->view_light[k]].resolution;
			bool persp = sv->params[1] > 0.5f;
			/* Meshes keep the camera's level (mesh_err 0): see RND_LOD_MESH_TEXEL_ERROR. */
			need_in_view(sc, (const float *)&sv->view_proj, res, res, persp ? sv->params[2] : 0.0f, RND_LOD_TEXEL_ERROR,
			             RND_LOD_MESH_TEXEL_ERROR, true, segments);
		}
	}
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (is_round(&sc->objects[i]) && segments[i] < 3) segments[i] = 3;
}

const char *rnd_lod_detail(const struct rnd_object *o, uint32_t lod)
{
	if (o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_CYLINDER)
		return lod < o->segments ? "fewer segments: the output shows no more (1/32 pixel, 1/8 shadow texel)"
		                         : "the segments asked for";
	if (o->shape == RND_SHAPE_MESH && o->lod_count)
		return lod ? "a simplified level: its error within half a pixel of every camera"
		           : "the full mesh: no level's error fits the output";
	return "as given";
}
