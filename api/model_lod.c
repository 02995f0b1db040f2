/*
 * api/model_lod.c — meshoptimizer levels of detail of imported meshes (see model_lod.h).
 *
 * A mesh gets one level for each size of image it is drawn at (api_lod_import_error), each
 * simplified from the full mesh in one step: a pure function of the mesh and that size, so a
 * request draws the same triangles whether its model was just imported or long cached (the
 * same request, the same bytes). A level's
 * error is measured against the full mesh (api/lod_error.h), in object units: meshoptimizer's
 * own figure leaves out how far the new triangles' insides are from the surface. Every level
 * gets its own vertex arrays, so drawing it touches only its vertices. Simplification runs on the mesh welded by
 * position (weld), so a level's normals are computed from its own triangles with a crease angle
 * (write_level) and its uvs (both sets) those of each position's first vertex: a texture seam of a
 * coarse level can show the wrong side's uvs (a thumbnail rarely can tell).
 */
#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>
#include "lod_error.h"
#include "model_caster.h"
#include "lod_simplify.h"
#include "model_lod.h"
#include "weld.h"
#include "umbra/rnd_math.h"

/* A mesh welded by position: what the simplifier works on. meshoptimizer treats vertices at
 * the same position as attribute seams it must keep, so a flat-shaded file (an STL shares no
 * vertex between facets) would not simplify at all without this. */
struct welded {
	float *pos;           /* count unique positions */
	float *nrm;           /* their area-weighted normals over the full mesh's faces */
	uint32_t *rep;        /* the first original vertex of each (for uvs, and which side is out) */
	size_t count;
};

/* me welded by position into idx and w (api_weld_mesh: the importer's groups when its join made
 * them, me->weld_group_, else sorted now), with the welded vertices' normals. */
static bool weld(const struct api_model_mesh *me, uint32_t *idx, struct welded *w)
{
	struct api_welded wm;
	bool ok = api_weld_mesh(me->positions, me->vertex_count, me->indices, me->index_count, me->weld_group_,
	                        me->weld_groups_, idx, &wm);
	w->pos = wm.pos;
	w->rep = wm.rep;
	w->count = wm.count;
	if (!ok) return false;
	/* Vertex normals of the welded full mesh (degenerate facets, whose file normals are noise,
	 * weigh nothing); oriented like the file's. */
	w->nrm = calloc(w->count * 3, sizeof *w->nrm);
	if (!w->nrm) return false;
	for (uint32_t t = 0; t + 2 < me->index_count; t += 3) {
		float e1[3], e2[3], c[3];
		rnd_v3_sub(e1, w->pos + 3 * (size_t)idx[t + 1], w->pos + 3 * (size_t)idx[t]);
		rnd_v3_sub(e2, w->pos + 3 * (size_t)idx[t + 2], w->pos + 3 * (size_t)idx[t]);
		rnd_v3_cross(c, e1, e2);
		if (rnd_v3_dot(c, me->normals + 3 * (size_t)me->indices[t]) < 0.0f) rnd_v3_scale(c, c, -1.0f);
		for (int k = 0; k < 3; k++) rnd_v3_add(w->nrm + 3 * (size_t)idx[t + k], w->nrm + 3 * (size_t)idx[t + k], c);
	}
	for (size_t v = 0; v < w->count; v++)
		if (!rnd_v3_normalize(w->nrm + 3 * v, w->nrm + 3 * v)) memcpy(w->nrm + 3 * v, me->normals + 3 * (size_t)w->rep[v], 12);
	return true;
}

/* Crease-angle normals of a level (idx: ni indices into w), one per corner: the area-weighted
 * mean of all face normals around the corner's vertex when that is within 30 degrees of its own
 * face's (or its face is a sliver, whose own normal is noise), else the mean of those within 30
 * degrees of its face's (smooth across the fine facets of a curved surface, a crease at a real
 * edge). Face normals follow the file's normals where the winding disagrees. */
static bool corner_normals(const struct api_model_mesh *me, const struct welded *w, const uint32_t *idx, size_t ni,
                           float *nrm)
{
	size_t nt = ni / 3;
	uint32_t *start = calloc(w->count + 1, sizeof *start), *faces = malloc(ni * sizeof *faces);
	float *fn = malloc(nt * 12);
	bool ok = start && faces && fn;
	for (size_t t = 0; ok && t < nt; t++) {
		const float *a = w->pos + 3 * idx[3 * t], *b = w->pos + 3 * idx[3 * t + 1], *c = w->pos + 3 * idx[3 * t + 2];
		float e1[3], e2[3];
		rnd_v3_sub(e1, b, a);
		rnd_v3_sub(e2, c, a);
		rnd_v3_cross(fn + 3 * t, e1, e2);
		/* Winding can disagree with the file's normals: the file's normals say outside. */
		float ref[3] = {0, 0, 0};
		for (int k = 0; k < 3; k++) rnd_v3_add(ref, ref, me->normals + 3 * (size_t)w->rep[idx[3 * t + k]]);
		if (rnd_v3_dot(ref, fn + 3 * t) < 0.0f) rnd_v3_scale(fn + 3 * t, fn + 3 * t, -1.0f);
		for (int k = 0; k < 3; k++) start[idx[3 * t + k] + 1]++;
	}
	if (ok) {
		/* faces around each vertex, grouped (counting sort) */
		for (size_t v = 0; v < w->count; v++) start[v + 1] += start[v];
		for (size_t t = 0; t < nt; t++)
			for (int k = 0; k < 3; k++) faces[start[idx[3 * t + k]]++] = (uint32_t)t;
		for (size_t v = w->count; v > 0; v--) start[v] = start[v - 1];
		start[0] = 0;
	}
	const float crease = 0.866f; /* cos 30 degrees */
	for (size_t t = 0; ok && t < nt; t++) {
		float own[3], u[3], edge = 0.0f;
		if (!rnd_v3_normalize(own, fn + 3 * t)) { own[0] = 0; own[1] = 1; own[2] = 0; }
		for (int k = 0; k < 3; k++) {
			float e[3];
			rnd_v3_sub(e, w->pos + 3 * (size_t)idx[3 * t + (size_t)k], w->pos + 3 * (size_t)idx[3 * t + (size_t)(k + 1) % 3]);
			edge = max_f(edge, rnd_v3_dot(e, e));
		}
		/* A sliver's own normal is noise: it takes its vertices' normals whatever the angle. */
		bool sliver = rnd_v3_length(fn + 3 * t) < 0.02f * edge;
		for (int k = 0; k < 3; k++) {
			uint32_t v = idx[3 * t + (size_t)k];
			float all[3] = {0, 0, 0}, near[3] = {0, 0, 0}, *n = nrm + 3 * (3 * t + (size_t)k);
			for (uint32_t f = start[v]; f < start[v + 1]; f++) {
				rnd_v3_add(all, all, fn + 3 * faces[f]); /* area-weighted: slivers hardly count */
				if (rnd_v3_normalize(u, fn + 3 * faces[f]) && rnd_v3_dot(u, own) >= crease)
					rnd_v3_add(near, near, fn + 3 * faces[f]);
			}
			bool smooth = rnd_v3_normalize(all, all) && (sliver || rnd_v3_dot(all, own) >= crease);
			if (smooth) memcpy(n, all, sizeof all);
			else if (!rnd_v3_normalize(n, near)) memcpy(n, own, sizeof own);
		}
	}
	free(start);
	free(faces);
	free(fn);
	return ok;
}

/* Writes one level into the arena: corners with equal position, normal and uvs (both sets:
 * those of the position's first vertex) become one vertex again. */
static bool write_level(struct api_arena *arena, const struct api_model_mesh *me, const struct welded *w,
                        const uint32_t *idx, size_t ni, struct rnd_mesh_lod *out, size_t *bytes)
{
	const float *src[2] = {me->uvs, me->uvs1};
	float *cp = malloc(ni * 12), *cn = malloc(ni * 12), *cu[2] = {NULL, NULL}, *uv[2] = {NULL, NULL};
	unsigned int *remap = malloc(ni * sizeof *remap);
	bool ok = cp && cn && remap;
	struct meshopt_Stream st[4] = {{cp, 12, 12}, {cn, 12, 12}};
	size_t ns = 2;
	for (int k = 0; k < 2; k++)
		if (src[k] && (ok = ok && (cu[k] = malloc(ni * 8)))) st[ns++] = (struct meshopt_Stream){cu[k], 8, 8};
	if (!ok || !corner_normals(me, w, idx, ni, cn)) goto done;
	for (size_t i = 0; i < ni; i++) {
		memcpy(cp + 3 * i, w->pos + 3 * (size_t)idx[i], 12);
		for (int k = 0; k < 2; k++)
			if (cu[k]) memcpy(cu[k] + 2 * i, src[k] + 2 * (size_t)w->rep[idx[i]], 8);
	}
	size_t nv = meshopt_generateVertexRemapMulti(remap, NULL, ni, ni, st, ns);
	float *pos = api_arena_alloc(arena, nv * 12), *nrm = api_arena_alloc(arena, nv * 12);
	uint32_t *ix = api_arena_alloc(arena, ni * 4);
	ok = pos && nrm && ix;
	for (int k = 0; k < 2; k++)
		if (cu[k]) ok = ok && (uv[k] = api_arena_alloc(arena, nv * 8));
	if (!ok) goto done;
	meshopt_remapVertexBuffer(pos, cp, ni, 12, remap);
	meshopt_remapVertexBuffer(nrm, cn, ni, 12, remap);
	for (int k = 0; k < 2; k++)
		if (cu[k]) meshopt_remapVertexBuffer(uv[k], cu[k], ni, 8, remap);
	meshopt_remapIndexBuffer(ix, NULL, ni, remap);
	*out = (struct rnd_mesh_lod){pos, nrm, uv[0], ix, (uint32_t)nv, (uint32_t)ni, 0.0f, uv[1]};
	*bytes += nv * (24 + (cu[0] ? 8 : 0) + (cu[1] ? 8 : 0)) + ni * 4;
done:
	free(cp);
	free(cn);
	free(cu[0]);
	free(cu[1]);
	free(remap);
	return ok;
}

/* Removes the triangles of no area (a pole's fan collapsed onto itself): invisible, and with no
 * normal of their own. Returns the indices kept. */
static size_t drop_degenerate(const struct welded *w, uint32_t *idx, size_t ni)
{
	size_t out = 0;
	for (size_t t = 0; t + 2 < ni; t += 3) {
		float e1[3], e2[3], c[3];
		rnd_v3_sub(e1, w->pos + 3 * (size_t)idx[t + 1], w->pos + 3 * (size_t)idx[t]);
		rnd_v3_sub(e2, w->pos + 3 * (size_t)idx[t + 2], w->pos + 3 * (size_t)idx[t]);
		rnd_v3_cross(c, e1, e2);
		if (rnd_v3_dot(c, c) == 0.0f) continue;
		memmove(idx + out, idx + t, 3 * sizeof *idx);
		out += 3;
	}
	return out;
}

void api_mesh_bounds(struct api_model_mesh *me)
{
	float lo[3], hi[3];
	api_points_box(me->positions, me->vertex_count, lo, hi);
	for (int k = 0; k < 3; k++) {
		me->bounds[k] = me->vertex_count ? lo[k] : 0.0f;
		me->bounds[3 + k] = me->vertex_count ? hi[k] : 0.0f;
	}
}

/* Welds me by position into idx and w (the caller frees w's arrays); false when out of memory. */
static bool welded_mesh(const struct api_model_mesh *me, uint32_t *idx, struct welded *w)
{
	return me->normals && me->indices && me->index_count && idx && weld(me, idx, w);
}

static void welded_free(struct welded *w)
{
	free(w->pos);
	free(w->nrm);
	free(w->rep);
}

/* One level of me (welded w, indices cur) within relative error `want` as measured
 * (api_lod_measure_level), simplified in one step from the full mesh: what the request that imports the
 * model can use, without the levels in between. meshoptimizer's target is its own figure, which
 * the measure exceeds (2-3x on a bumpy sphere): aimed at a quarter of `want`, and once more,
 * closer (at most 0.3 of that aim), when that measured over. None when it would not save a
 * quarter of the triangles. */
static void mesh_one_level(struct api_model_mesh *me, const struct welded *w, const uint32_t *cur, float want,
                           struct api_arena *arena, size_t *bytes)
{
	struct rnd_mesh_lod *lod = api_arena_calloc(arena, 1, sizeof *lod);
	uint32_t *next = malloc((size_t)me->index_count * sizeof *next);
	struct api_lod_measure *measure = NULL;
	size_t ni = me->index_count;
	/* The box of the welded mesh, once: the measure's grid's, and the extent meshoptimizer's
	 * relative errors are relative to. */
	float lo[3], hi[3], extent = api_points_box(w->pos, w->count, lo, hi), target = 0.25f * want;
	if (!lod || !next || !(extent > 0.0f) ||
	    !(measure = api_lod_measure_create(w->pos, w->nrm, w->count, cur, ni, lo, hi, extent)))
		goto done;
	for (int attempt = 0; attempt < 2; attempt++) {
		size_t got = api_lod_simplify(next, cur, ni, w->pos, w->count, extent, target);
		if (got < 3 || got * 4 > ni * 3) break;
		got = drop_degenerate(w, next, got);
		float e = got >= 3 ? api_lod_measure_level(measure, next, got, false) : INFINITY;
		if (e <= want * extent || attempt == 1) {
			if (got >= 3 && e <= want * extent && write_level(arena, me, w, next, got, lod, bytes)) {
				lod->error = e;
				me->lods = lod;
				me->lod_count = 1;
			}
			break;
		}
		/* at most 0.3 of the first aim: an error that does not scale with the aim (a crease
		 * the first aim collapsed, like the 100k vase's fluted foot rim: 0.0049 at both 0.8
		 * and 0.64 of it) needs a step, else the second build is thrown away too */
		target *= fminf(0.8f * want * extent / e, 0.3f);
	}
done:
	api_lod_measure_destroy(measure);
	free(next);
}

/* The one level of every mesh of m that wants one, for images of output_side, and with
 * `closed` set too when mark_closed: one weld a mesh for both. */
static void finish(struct api_model *m, uint32_t output_side, bool mark_closed, struct api_arena *arena, size_t *bytes)
{
	for (uint32_t i = 0; i < m->mesh_count; i++) {
		struct api_model_mesh *me = (struct api_model_mesh *)&m->meshes[i]; /* ours until shared */
		bool level = output_side && api_mesh_wants_levels(me);
		if (!mark_closed && !level) continue;
		double t0 = api_clock_ms();
		uint32_t *idx = me->index_count ? malloc((size_t)me->index_count * sizeof *idx) : NULL;
		struct welded w = {0};
		bool welded = welded_mesh(me, idx, &w);
		if (mark_closed) me->closed = welded && api_mesh_closed(idx, me->index_count, w.pos, w.count);
		double t1 = api_clock_ms();
		if (welded && level) mesh_one_level(me, &w, idx, api_lod_import_error(output_side), arena, bytes);
		/* the environment's maps' caster, at import only (its time counts as the level's) */
		if (welded && mark_closed && api_mesh_wants_caster(m, me)) api_caster_build(me, idx, me->index_count, w.pos, w.count, arena, bytes);
		m->times.ms[API_IMPORT_CLOSED] += (float)(t1 - t0);
		m->times.ms[API_IMPORT_LEVEL] += (float)(api_clock_ms() - t1);
		welded_free(&w);
		free(idx);
	}
}

void api_model_finish_import(struct api_model *m, uint32_t output_side, struct api_arena *arena, size_t *bytes)
{
	finish(m, output_side, true, arena, bytes);
}

void api_model_build_level(struct api_model *m, uint32_t output_side, struct api_arena *arena, size_t *bytes)
{
	finish(m, output_side, false, arena, bytes);
}

float api_lod_import_error(uint32_t output_side)
{
	/* The renderer's bound (RND_LOD_MESH_PIXEL_ERROR, half a pixel) for a mesh that spans 70 %
	 * of the image, as a thumbnail frames it (half of extent / (0.7 side): 0.71 / side), less a
	 * margin: the thumbnail preset's camera allowed 0.68 / side on every 100k corpus model
	 * (rnd_lod_mesh_level; the mesh spans ~67 %). The renderer draws the level only where it
	 * fits its bound (pixels and shadow texels as they are), else the full mesh. This was
	 * 0.35 / side (half a pixel times 0.7, not over it): levels built to half what the renderer
	 * allows, and a level measured between the two, e.g. the 100k vase glb's 0.0039 against
	 * 0.0025 asked and 0.0046 allowed, thrown away after its build (the request drew 100k
	 * triangles into its 12 environment maps). */
	return output_side ? 0.6f / (float)output_side : 0.0f;
}

bool api_mesh_wants_levels(const struct api_model_mesh *me)
{
	return me->index_count / 3 >= API_LOD_MIN_TRIANGLES && me->normals && !me->colors && !me->tangents;
}
