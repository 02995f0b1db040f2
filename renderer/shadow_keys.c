/*
 * renderer/shadow_keys.c — the keys of cached shadow maps (see shadow_keys.h).
 *
 * The casters' part hashes the scene's own arrays, not the triangles the upload writes from
 * them: the plan is made before anything is written (render_plan.c), and a tessellation is a
 * function of what it is made from (the shape, its segments or level, the model matrix).
 * Everything a depth-only pass reads is in it: positions and indices, the winding (the model
 * matrix's), and for an alpha-tested caster what its alpha test reads (masked.vert/.frag).
 */
#include "lod.h"
#include "shadow_keys.h"

static uint64_t hash_floats(uint64_t h, const float *p, uint64_t n)
{
	return p ? rnd_hash(h, p, (size_t)n * sizeof *p) : rnd_hash(h, "-", 1);
}

/* One caster's geometry: its shape as drawn (lod applied) and where it stands. */
static uint64_t hash_geometry(uint64_t h, const struct rnd_object *o)
{
	uint32_t shape[2] = {(uint32_t)o->shape, o->segments};
	float dims[5] = {o->size[0], o->size[1], o->size[2], o->radius, o->height};
	h = rnd_hash(h, shape, sizeof shape);
	h = rnd_hash(h, dims, sizeof dims);
	h = rnd_hash(h, o->model, sizeof o->model);
	if (o->shape != RND_SHAPE_MESH) return h;
	uint32_t counts[3] = {o->vertex_count, o->index_count, o->normals != NULL};
	h = rnd_hash(h, counts, sizeof counts);
	h = hash_floats(h, o->positions, 3ull * o->vertex_count);
	if (o->indices) h = rnd_hash(h, o->indices, (size_t)o->index_count * sizeof *o->indices);
	return h;
}

/* What the alpha test of a masked caster reads: its texture coordinates and vertex colours,
 * the material's alpha, cutoff, base colour and its texture. */
static uint64_t hash_alpha(uint64_t h, const struct rnd_object *o, const struct rnd_material *m)
{
	if (o->shape == RND_SHAPE_MESH) {
		h = hash_floats(h, o->uvs, 2ull * o->vertex_count);
		if (m->sampling[RND_TEX_BASE].uv_set == 1) h = hash_floats(h, o->uvs1, 2ull * o->vertex_count);
		h = o->colors ? rnd_hash(h, o->colors, 4ull * o->vertex_count) : rnd_hash(h, "-", 1);
	}
	h = rnd_hash(h, &m->alpha_cutoff, sizeof m->alpha_cutoff);
	h = rnd_hash(h, &m->alpha_mode, sizeof m->alpha_mode);
	h = rnd_hash(h, &m->sampling[RND_TEX_BASE], sizeof m->sampling[RND_TEX_BASE]);
	h = rnd_hash(h, m->base_color, sizeof m->base_color);
	if (m->base_color_texture)
		h = rnd_hash(h, m->base_color_texture->rgba, (size_t)m->base_color_texture->width * m->base_color_texture->height * 4);
	return h;
}

uint64_t rnd_caster_key(const struct rnd_scene *sc, const struct draw *draws, const uint32_t *lod,
                        const struct rnd_aabb *bounds)
{
	uint64_t geo = rnd_hash(0x756d627261ull, bounds, sizeof *bounds);
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct draw *d = &draws[i];
		if (!d->cast || !d->index_count) continue;
		struct rnd_object o = sc->objects[i];
		rnd_lod_apply(&o, lod[i]);
		uint32_t flags[3] = {d->single_sided, d->closed, d->masked};
		geo = rnd_hash(geo, flags, sizeof flags);
		geo = hash_geometry(geo, &o);
		/* the environment's maps may draw its caster level instead (caster_level.h) */
		float level[3] = {(float)d->env_index_count, d->env_error, d->env_raise};
		geo = rnd_hash(geo, level, sizeof level);
		if (d->masked) geo = hash_alpha(geo, &o, &sc->materials[o.material]);
	}
	return geo;
}

uint64_t rnd_map_key(uint64_t casters, const struct rnd_light *L, const struct rnd_light_plan *lp,
                     const struct umbra_shadow_view *views)
{
	float k[8] = {lp->bias_constant, lp->bias_slope, (float)lp->resolution, (float)lp->filter,
	              lp->moments ? (lp->evsm ? lp->evsm_exponent : -1.0f) : 0.0f,
	              lp->moments ? L->shadow.vsm_blur : 0.0f, (float)L->type, 0};
	uint64_t key = rnd_hash(casters, k, sizeof k);
	key = rnd_hash(key, &views[lp->first_view], lp->view_count * sizeof(struct umbra_shadow_view));
	return key ? key : 1;
}
