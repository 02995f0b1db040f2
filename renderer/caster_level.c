/*
 * renderer/caster_level.c — the environment's shadow maps' coarse caster levels (see
 * caster_level.h).
 */
#include <math.h>
#include <string.h>
#include "caster_level.h"

bool rnd_caster_level_wanted(const struct rnd_scene *sc, const struct rnd_object *o, uint32_t index_count)
{
	if (o->shape != RND_SHAPE_MESH || !o->caster || !o->cast_shadows || !o->caster->index_count) return false;
	if (sc->material_count) {
		const struct rnd_material *m = &sc->materials[o->material];
		if (m->alpha_mode != RND_ALPHA_OPAQUE || m->shadow_catcher) return false;
	}
	return (uint64_t)o->caster->index_count * 2 <= index_count;
}

float rnd_caster_world_error(const struct rnd_object *o)
{
	return o->caster ? o->caster->error * rnd_mat4_max_axis_scale(o->model) : 0.0f;
}

bool rnd_caster_level_used(const struct rnd_light *L, const struct umbra_shadow_view *sv, bool ortho,
                           const struct draw *d)
{
	return d->env_index_count && L->shadow.dir_mode == RND_DIR_CASTERS && ortho &&
	       d->env_error <= RND_CASTER_MAX_TEXELS * sv->params[0];
}

struct draw rnd_caster_view_draw(const struct rnd_shadow_plan *sp, const struct rnd_light *lights, uint32_t v,
                                 const struct draw *d, int *cull, float *raise)
{
	struct draw out = *d;
	*raise = 0.0f;
	if (!rnd_caster_level_used(&lights[sp->view_light[v]], &sp->views[v], sp->view_ortho[v], d)) return out;
	out.first_index = d->env_first_index;
	out.index_count = d->env_index_count;
	*cull = 0;
	*raise = d->env_raise;
	return out;
}

void rnd_caster_view_proj(const float view_proj[16], float raise, float out[16])
{
	memcpy(out, view_proj, 16 * sizeof *out);
	/* column-major: row 2 is (m[2], m[6], m[10], m[14]); w is 1 in an orthographic map */
	float g = sqrtf(view_proj[2] * view_proj[2] + view_proj[6] * view_proj[6] + view_proj[10] * view_proj[10]);
	out[14] += raise * g;
}

float rnd_caster_slope_bias(float raise, float texel)
{
	float s = texel > 0.0f ? 1.41421356f * raise / texel : 0.0f;
	if (!(s > 0.0f)) return 0.0f;
	/* up to the ladder's next step (caster_level.h): never less than asked */
	float k = ceilf(RND_CASTER_BIAS_STEPS * log2f(s));
	if (k > RND_CASTER_BIAS_RANGE) return s;   /* past the ladder: e / texel is 4 at most */
	k = fmaxf(k, -RND_CASTER_BIAS_RANGE);
	float q = exp2f(k / RND_CASTER_BIAS_STEPS);
	return q >= s ? q : exp2f((k + 1.0f) / RND_CASTER_BIAS_STEPS);
}

void rnd_caster_write(const struct rnd_object *o, struct rnd_vertex *vtx, uint32_t *idx, uint32_t base)
{
	const struct rnd_caster_level *c = o->caster;
	for (uint32_t v = 0; v < c->vertex_count; v++) {
		memset(&vtx[v], 0, sizeof vtx[v]);
		rnd_mat4_mul_point(vtx[v].pos, o->model, c->positions + 3 * (size_t)v);
	}
	for (uint32_t k = 0; k < c->index_count; k++) idx[k] = c->indices[k] + base;
}
