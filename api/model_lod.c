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
 * (write_level). A mesh with uvs or colours is split again where its corners at one position
 * differ in them (struct split: a texture seam, a colour edge), so that each side keeps its own
 * uvs, tangents (the shader makes them orthogonal to the level's normal) and colours; a
 * coloured level is refused unless it shows every vertex's colour within a bound
 * (api/lod_colour.h).
 */
#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>
#include "lod_colour.h"
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

/* The welded mesh split again where a level must keep attributes apart: a welded vertex whose
 * corners differ in uvs (either set: a texture seam, a chart's edge) or colour becomes one
 * vertex each, and so does one where triangles whose corners all have one colour meet
 * triangles whose corners differ (a band's edge: the row of triangles that blends one band into
 * the next). meshoptimizer keeps vertices at one position as a seam, collapsing them only along
 * it, so a seam or a colour edge stays where it was instead of moving by a collapse across it,
 * and each level vertex takes its attributes from its own side (a level of the welded mesh took
 * one side's uvs for both: a strip of the whole texture squeezed along every seam). A coloured
 * level is then measured for its colours (api/lod_colour.h) and refused when they are off. */
struct split {
	uint32_t *idx;    /* the full mesh's index_count indices into these vertices */
	float *pos;       /* count positions (their welded vertex's) */
	uint32_t *base;   /* the welded vertex of each */
	uint32_t *first;  /* a vertex of the mesh with its attributes (the first its corners met) */
	uint8_t *col;     /* linear RGBA8 of each, when the mesh has colours */
	size_t count;
};

static void split_free(struct split *s)
{
	free(s->idx);
	free(s->pos);
	free(s->base);
	free(s->first);
	free(s->col);
}

/* Whether the mesh's vertices a and b have the same uvs (each set) and colour. */
static bool same_attributes(const struct api_model_mesh *me, uint32_t a, uint32_t b)
{
	return (!me->uvs || !memcmp(me->uvs + 2 * (size_t)a, me->uvs + 2 * (size_t)b, 8)) &&
	       (!me->uvs1 || !memcmp(me->uvs1 + 2 * (size_t)a, me->uvs1 + 2 * (size_t)b, 8)) &&
	       (!me->colors || !memcmp(me->colors + 4 * (size_t)a, me->colors + 4 * (size_t)b, 4));
}

/* Whether triangle t's corners differ in colour. */
static bool blends(const struct api_model_mesh *me, size_t t)
{
	const uint8_t *c = me->colors;
	const uint32_t *v = me->indices + 3 * t;
	return memcmp(c + 4 * (size_t)v[0], c + 4 * (size_t)v[1], 4) || memcmp(c + 4 * (size_t)v[0], c + 4 * (size_t)v[2], 4);
}

/* s from me welded by position (idx, w): a split vertex per welded vertex and (uvs, colour,
 * blends) key of its corners, the welded vertex's own id for the first key its corners meet,
 * new ids after w->count for the others in the order met. False when out of memory. */
static bool split_mesh(const struct api_model_mesh *me, const struct welded *w, const uint32_t *idx, struct split *s)
{
	/* each corner makes at most one new vertex; each mesh vertex one, or two with colours
	 * (blending and not) */
	size_t ni = me->index_count, more = (me->colors ? 2u : 1u) * (size_t)me->vertex_count;
	size_t cap = w->count + (more < ni ? more : ni);
	uint32_t *chain = malloc(cap * sizeof *chain);
	uint8_t *mix = calloc(cap, 1), *set = calloc(w->count, 1);
	s->idx = malloc(ni * sizeof *s->idx);
	s->base = malloc(cap * sizeof *s->base);
	s->first = malloc(cap * sizeof *s->first);
	bool ok = chain && mix && set && s->idx && s->base && s->first;
	size_t n = w->count;
	for (size_t i = 0; ok && i < ni; i++) {
		uint32_t b = idx[i], mv = me->indices[i], u = b;
		uint8_t m = me->colors ? blends(me, i / 3) : 0;
		if (!set[b]) {
			set[b] = 1, s->first[b] = mv, mix[b] = m, chain[b] = UINT32_MAX, s->base[b] = b, s->idx[i] = b;
			continue;
		}
		while ((mix[u] != m || !same_attributes(me, s->first[u], mv)) && chain[u] != UINT32_MAX) u = chain[u];
		if (mix[u] != m || !same_attributes(me, s->first[u], mv)) {
			chain[u] = (uint32_t)n, s->first[n] = mv, mix[n] = m, chain[n] = UINT32_MAX, s->base[n] = b;
			u = (uint32_t)n++;
		}
		s->idx[i] = u;
	}
	s->count = n;
	s->pos = ok ? malloc(n * 12) : NULL;
	s->col = ok && me->colors ? malloc(n * 4) : NULL;
	ok = ok && s->pos && (s->col || !me->colors);
	for (size_t v = 0; ok && v < n; v++) {
		memcpy(s->pos + 3 * v, w->pos + 3 * (size_t)s->base[v], 12);
		if (s->col) memcpy(s->col + 4 * v, me->colors + 4 * (size_t)s->first[v], 4);
	}
	free(chain);
	free(mix);
	free(set);
	return ok;
}

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
 * edge). Face normals follow the winding, all turned when most disagree with the file's normals. */
static bool corner_normals(const struct api_model_mesh *me, const struct welded *w, const uint32_t *idx, size_t ni,
                           float *nrm)
{
	size_t nt = ni / 3;
	uint32_t *start = calloc(w->count + 1, sizeof *start), *faces = malloc(ni * sizeof *faces);
	float *fn = malloc(nt * 12);
	bool ok = start && faces && fn;
	size_t against = 0;
	for (size_t t = 0; ok && t < nt; t++) {
		const float *a = w->pos + 3 * idx[3 * t], *b = w->pos + 3 * idx[3 * t + 1], *c = w->pos + 3 * idx[3 * t + 2];
		float e1[3], e2[3];
		rnd_v3_sub(e1, b, a);
		rnd_v3_sub(e2, c, a);
		rnd_v3_cross(fn + 3 * t, e1, e2);
		float ref[3] = {0, 0, 0};
		for (int k = 0; k < 3; k++) rnd_v3_add(ref, ref, me->normals + 3 * (size_t)w->rep[idx[3 * t + k]]);
		against += rnd_v3_dot(ref, fn + 3 * t) < 0.0f;
		for (int k = 0; k < 3; k++) start[idx[3 * t + k] + 1]++;
	}
	/* The winding can disagree with the file's normals, which say outside: then every face is
	 * turned, by the vote of them all. Not face by face: a few wrong normals in a file (the
	 * corpus terrain's border rows point down) turned whole level faces over them, and the
	 * renderer, which lights a double-sided face seen from behind on its other side, drew them
	 * as dark teeth along the border. */
	if (ok && 2 * against > nt)
		for (size_t k = 0; k < 3 * nt; k++) fn[k] = -fn[k];
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

/* Writes one level into the arena: corners with equal position, normal, uvs (both sets) and
 * tangent (those of the position's first vertex) and colour (s's, of the level's split vertices sidx)
 * become one vertex again. */
static bool write_level(struct api_arena *arena, const struct api_model_mesh *me, const struct welded *w,
                        const uint32_t *idx, const struct split *s, const uint32_t *sidx, size_t ni,
                        struct rnd_mesh_lod *out, size_t *bytes)
{
	const float *src[2] = {me->uvs, me->uvs1};
	float *cp = malloc(ni * 12), *cn = malloc(ni * 12), *cu[2] = {NULL, NULL}, *uv[2] = {NULL, NULL};
	float *ct = NULL, *tan = NULL;
	unsigned int *remap = malloc(ni * sizeof *remap);
	bool ok = cp && cn && remap;
	uint8_t *cc = NULL, *col = NULL;
	struct meshopt_Stream st[6] = {{cp, 12, 12}, {cn, 12, 12}};
	size_t ns = 2;
	for (int k = 0; k < 2; k++)
		if (src[k] && (ok = ok && (cu[k] = malloc(ni * 8)))) st[ns++] = (struct meshopt_Stream){cu[k], 8, 8};
	if (s && s->col && (ok = ok && (cc = malloc(ni * 4)))) st[ns++] = (struct meshopt_Stream){cc, 4, 4};
	if (me->tangents && (ok = ok && (ct = malloc(ni * 16)))) st[ns++] = (struct meshopt_Stream){ct, 16, 16};
	if (!ok || !corner_normals(me, w, idx, ni, cn)) goto done;
	for (size_t i = 0; i < ni; i++) {
		memcpy(cp + 3 * i, w->pos + 3 * (size_t)idx[i], 12);
		uint32_t mv = s ? s->first[sidx[i]] : w->rep[idx[i]];   /* the mesh vertex it stands for */
		for (int k = 0; k < 2; k++)
			if (cu[k]) memcpy(cu[k] + 2 * i, src[k] + 2 * (size_t)mv, 8);
		if (cc) memcpy(cc + 4 * i, s->col + 4 * (size_t)sidx[i], 4);
		if (ct) memcpy(ct + 4 * i, me->tangents + 4 * (size_t)mv, 16);
	}
	size_t nv = meshopt_generateVertexRemapMulti(remap, NULL, ni, ni, st, ns);
	float *pos = api_arena_alloc(arena, nv * 12), *nrm = api_arena_alloc(arena, nv * 12);
	uint32_t *ix = api_arena_alloc(arena, ni * 4);
	ok = pos && nrm && ix;
	for (int k = 0; k < 2; k++)
		if (cu[k]) ok = ok && (uv[k] = api_arena_alloc(arena, nv * 8));
	if (cc) ok = ok && (col = api_arena_alloc(arena, nv * 4));
	if (ct) ok = ok && (tan = api_arena_alloc(arena, nv * 16));
	if (!ok) goto done;
	meshopt_remapVertexBuffer(pos, cp, ni, 12, remap);
	meshopt_remapVertexBuffer(nrm, cn, ni, 12, remap);
	for (int k = 0; k < 2; k++)
		if (cu[k]) meshopt_remapVertexBuffer(uv[k], cu[k], ni, 8, remap);
	if (cc) meshopt_remapVertexBuffer(col, cc, ni, 4, remap);
	if (ct) meshopt_remapVertexBuffer(tan, ct, ni, 16, remap);
	meshopt_remapIndexBuffer(ix, NULL, ni, remap);
	*out = (struct rnd_mesh_lod){pos, nrm, uv[0], ix, (uint32_t)nv, (uint32_t)ni, 0.0f, uv[1], col, tan};
	*bytes += nv * (24 + (cu[0] ? 8 : 0) + (cu[1] ? 8 : 0) + (cc ? 4 : 0) + (ct ? 16 : 0)) + ni * 4;
done:
	free(ct);
	free(cc);
	free(cp);
	free(cn);
	free(cu[0]);
	free(cu[1]);
	free(remap);
	return ok;
}

/* Removes the triangles of no area (a pole's fan collapsed onto itself): invisible, and with no
 * normal of their own. Returns the indices kept. */
static size_t drop_degenerate(const float *pos, uint32_t *idx, size_t ni)
{
	size_t out = 0;
	for (size_t t = 0; t + 2 < ni; t += 3) {
		float e1[3], e2[3], c[3];
		rnd_v3_sub(e1, pos + 3 * (size_t)idx[t + 1], pos + 3 * (size_t)idx[t]);
		rnd_v3_sub(e2, pos + 3 * (size_t)idx[t + 2], pos + 3 * (size_t)idx[t]);
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
 * closer (at most 0.3 of that aim), when that measured over. A vertex-coloured mesh is
 * simplified split by colour (struct split) and its level must show the mesh's colours within
 * API_LOD_COLOUR_BOUND too (api/lod_colour.h; over it, no level: a finer aim is no nearer).
 * None when it would not save a quarter of the triangles. */
static void mesh_one_level(struct api_model_mesh *me, const struct welded *w, const uint32_t *cur, float want,
                           struct api_arena *arena, size_t *bytes)
{
	struct rnd_mesh_lod *lod = api_arena_calloc(arena, 1, sizeof *lod);
	size_t ni = me->index_count;
	uint32_t *next = malloc(ni * sizeof *next), *lvl = next;
	struct api_lod_measure *measure = NULL;
	struct split sp = {0}, *s = NULL;
	/* The box of the welded mesh, once: the measure's grid's, and the extent meshoptimizer's
	 * relative errors are relative to. */
	float lo[3], hi[3], extent = api_points_box(w->pos, w->count, lo, hi), target = 0.25f * want;
	if (!lod || !next || !(extent > 0.0f) ||
	    !(measure = api_lod_measure_create(w->pos, w->nrm, w->count, cur, ni, lo, hi, extent)))
		goto done;
	if (me->colors || me->uvs || me->uvs1) {
		if (!split_mesh(me, w, cur, &sp) || !(lvl = malloc(ni * sizeof *lvl))) goto done;
		/* colours no level would show: spare the level's cost (the measure would refuse it) */
		if (sp.col && api_lod_colours_rough(sp.col, sp.count, sp.idx, ni)) goto done;
		s = &sp;
	}
	const uint32_t *full = s ? s->idx : cur;
	const float *pos = s ? s->pos : w->pos;
	size_t count = s ? s->count : w->count;
	for (int attempt = 0; attempt < 2; attempt++) {
		size_t got = api_lod_simplify(next, full, ni, pos, count, extent, target);
		if (got < 3 || got * 4 > ni * 3) break;
		got = drop_degenerate(pos, next, got);
		for (size_t i = 0; s && i < got; i++) lvl[i] = s->base[next[i]];
		/* colours first: a level they refuse is not measured (the colour measure stops at the
		 * first vertex over; the geometric one walks the level to its end) */
		float ce = s && s->col && got >= 3 ? api_lod_colour_error(s->pos, s->col, s->count, s->idx, ni, next, got, lo, hi, extent,
		                                                want * extent, API_LOD_COLOUR_BOUND)
		                         : 0.0f;
		float e = got >= 3 && ce <= API_LOD_COLOUR_BOUND ? api_lod_measure_level(measure, lvl, got, false) : INFINITY;
		bool fits = e <= want * extent && ce <= API_LOD_COLOUR_BOUND;
		/* a finer aim does not help colours (the simplifier sees positions only: the 100k
		 * bumpy variant's smooth colours measured 4.2/255 over, then 4.5 at 2.6x the triangles) */
		if (fits || attempt == 1 || ce > API_LOD_COLOUR_BOUND) {
			if (got >= 3 && fits && write_level(arena, me, w, lvl, s, next, got, lod, bytes)) {
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
	if (lvl != next) free(lvl);
	free(next);
	split_free(&sp);
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
	return me->index_count / 3 >= API_LOD_MIN_TRIANGLES && me->normals;
}
