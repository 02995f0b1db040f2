/*
 * api/model_wire_put — the writer of the importer's reply (the sandboxed child's side; the
 * daemon's reader is api/model_wire.c). See model_wire.h for the layout.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "model_wire.h"

void api_wire_buf_release(struct api_wire_buf *b)
{
	if (!b) return;
	free(b->data);
	memset(b, 0, sizeof *b);
}

/* Sink: what is staged, written out to b->fd. */
static void sink_write(struct api_wire_buf *b, const uint8_t *p, size_t n)
{
	while (n && !b->failed) {
		ssize_t w = write(b->fd, p, n);
		if (w < 0 && errno == EINTR) continue;
		if (w <= 0) b->failed = 1;
		else p += w, n -= (size_t)w;
	}
}

int api_wire_flush(struct api_wire_buf *b)
{
	if (b->fd > 0 && b->staged) sink_write(b, b->data, b->staged);
	b->staged = 0;
	return b->failed ? -1 : 0;
}

static void put(struct api_wire_buf *b, const void *p, size_t n)
{
	if (b->failed || !n) return;
	if (b->fd > 0) {
		/* Small puts gather in a staging buffer; big arrays go straight from where they are. */
		enum { STAGE = 64 * 1024 };
		if (!b->data && !(b->data = malloc(STAGE))) { b->failed = 1; return; }
		if (b->staged + n > STAGE) api_wire_flush(b);
		if (n >= STAGE) sink_write(b, p, n);
		else memcpy(b->data + b->staged, p, n), b->staged += n;
		b->len += n;
		return;
	}
	if (n > b->cap - b->len) {
		size_t cap = b->cap ? b->cap : 4096;
		while (cap - b->len < n) {
			if (cap > SIZE_MAX / 2) { b->failed = 1; return; }
			cap *= 2;
		}
		uint8_t *d = realloc(b->data, cap);
		if (!d) { b->failed = 1; return; }
		b->data = d;
		b->cap = cap;
	}
	memcpy(b->data + b->len, p, n);
	b->len += n;
}

static void put_u32(struct api_wire_buf *b, uint32_t v)
{
	put(b, &v, 4);
}

void api_wire_put_header(struct api_wire_buf *b, enum api_wire_kind kind, enum api_wire_status st, const char *msg)
{
	size_t n = msg ? strlen(msg) : 0;
	if (n > API_WIRE_MAX_MESSAGE) n = API_WIRE_MAX_MESSAGE;
	put(b, API_WIRE_MAGIC, 8);
	put_u32(b, API_WIRE_VERSION);
	put_u32(b, (uint32_t)kind);
	put_u32(b, (uint32_t)st);
	put_u32(b, (uint32_t)n);
	put(b, msg, n);
}

void api_wire_put_image(struct api_wire_buf *b, const uint8_t *rgba, uint32_t w, uint32_t h)
{
	put_u32(b, w);
	put_u32(b, h);
	put(b, rgba, (size_t)w * h * 4);
}

static void put_material(struct api_wire_buf *b, const struct rnd_material *mt, const struct rnd_texture *const *tex,
                         uint32_t ntex)
{
	float f[13] = {mt->base_color[0], mt->base_color[1], mt->base_color[2], mt->base_color[3], mt->roughness,
	               mt->metallic, mt->emissive[0], mt->emissive[1], mt->emissive[2], mt->alpha_cutoff,
	               mt->normal_scale, mt->occlusion_strength, mt->see_through};
	put(b, f, sizeof f);
	put_u32(b, (uint32_t)mt->alpha_mode);
	for (uint32_t s = 0; s < RND_TEX_SLOTS; s++) {
		int32_t ti = -1;
		for (uint32_t k = 0; mt->textures[s] && k < ntex; k++)
			if (tex[k] == mt->textures[s]) ti = (int32_t)k;
		put(b, &ti, 4);
	}
	for (uint32_t s = 0; s < RND_TEX_SLOTS; s++) {
		const struct rnd_texture_sampling *ts = &mt->sampling[s];
		put_u32(b, (uint32_t)ts->wrap_s | (uint32_t)ts->wrap_t << 2 | (uint32_t)ts->mag_nearest << 4 |
		           (uint32_t)ts->min_nearest << 5 | (uint32_t)ts->transformed << 6 | (uint32_t)(ts->mip % 3u) << 7 |
		           (uint32_t)(ts->uv_set == 1) << 9);
		put(b, ts->transform, sizeof ts->transform);
	}
	put_u32(b, mt->extensions | (mt->specular.spec_gloss ? API_WIRE_SPEC_GLOSS : 0));
	float e[11] = {mt->clearcoat.factor, mt->clearcoat.roughness, mt->clearcoat.normal_scale, mt->sheen.color[0],
	               mt->sheen.color[1], mt->sheen.color[2], mt->sheen.roughness, mt->specular.factor,
	               mt->specular.color[0], mt->specular.color[1], mt->specular.color[2]};
	put(b, e, sizeof e);
	put(b, &mt->specular.ior, 4);
}

static void put_mesh_levels(struct api_wire_buf *b, const struct api_model_mesh *me)
{
	put_u32(b, me->lod_count);
	for (uint32_t l = 0; l < me->lod_count; l++) {
		const struct rnd_mesh_lod *lv = &me->lods[l];
		put_u32(b, lv->vertex_count);
		put_u32(b, lv->index_count);
		put_u32(b, (lv->uvs ? 1u : 0u) | (lv->uvs1 ? 2u : 0u) | (lv->colors ? 4u : 0u) | (lv->tangents ? 8u : 0u));
		put(b, &lv->error, 4);
		put(b, lv->positions, (size_t)lv->vertex_count * 12);
		put(b, lv->normals, (size_t)lv->vertex_count * 12);
		if (lv->uvs) put(b, lv->uvs, (size_t)lv->vertex_count * 8);
		if (lv->uvs1) put(b, lv->uvs1, (size_t)lv->vertex_count * 8);
		if (lv->colors) put(b, lv->colors, (size_t)lv->vertex_count * 4);
		if (lv->tangents) put(b, lv->tangents, (size_t)lv->vertex_count * 16);
		put(b, lv->indices, (size_t)lv->index_count * 4);
	}
}

/* Whether a mesh's indices are 0, 1, ..., n-1 (each corner its own vertex, as an STL's facets
 * are): then none cross the wire and the daemon counts them out itself (flag 512). */
static int indices_identity(const struct api_model_mesh *me)
{
	if (me->index_count != me->vertex_count) return 0;
	for (uint32_t k = 0; k < me->index_count; k++)
		if (me->indices[k] != k) return 0;
	return 1;
}

void api_wire_put_model(struct api_wire_buf *b, const struct api_model *m)
{
	/* Textures are shared between materials by pointer: each goes once, by its first index. */
	const struct rnd_texture *tex[API_WIRE_MAX_TEXTURES];
	uint32_t ntex = 0;
	for (uint32_t i = 0; i < m->material_count; i++) {
		for (uint32_t s = 0; s < RND_TEX_SLOTS; s++) {
			const struct rnd_texture *t = m->materials[i].textures[s];
			uint32_t k = 0;
			while (t && k < ntex && tex[k] != t) k++;
			if (t && k == ntex) {
				if (ntex == API_WIRE_MAX_TEXTURES) { b->failed = 1; return; }
				tex[ntex++] = t;
			}
		}
	}
	size_t wlen = m->warnings ? strlen(m->warnings) : 0;
	if (wlen > API_MODEL_MAX_WARNINGS) wlen = API_MODEL_MAX_WARNINGS;
	put(b, &m->times.ms[API_IMPORT_PARSE], 4 * sizeof(float));   /* parse, textures, closed, level */
	put_u32(b, m->texture_side);
	put_u32(b, m->texture_max);
	put_u32(b, ntex);
	put_u32(b, m->material_count);
	put_u32(b, m->mesh_count);
	put_u32(b, m->instance_count);
	put_u32(b, (uint32_t)wlen);
	put(b, m->warnings, wlen);
	static const uint8_t zero[4];
	put(b, zero, (4 - wlen % 4) % 4);   /* what follows stays 4-byte aligned */
	for (uint32_t i = 0; i < ntex; i++) api_wire_put_image(b, tex[i]->rgba, tex[i]->width, tex[i]->height);
	for (uint32_t i = 0; i < m->material_count; i++) put_material(b, &m->materials[i], tex, ntex);
	for (uint32_t i = 0; i < m->mesh_count; i++) {
		const struct api_model_mesh *me = &m->meshes[i];
		int identity = indices_identity(me);
		put_u32(b, me->vertex_count);
		put_u32(b, me->index_count);
		put_u32(b, me->material);
		put_u32(b, (me->normals ? 1u : 0u) | (me->uvs ? 2u : 0u) | (me->colors ? 4u : 0u) | (me->tangents ? 8u : 0u) |
		           (me->single_sided ? 16u : 0u) | (me->closed ? 32u : 0u) | (me->lod_count ? 64u : 0u) |
		           (me->uvs1 ? 128u : 0u) | (me->caster ? 256u : 0u) | (identity ? 512u : 0u));
		put(b, me->positions, (size_t)me->vertex_count * 12);
		if (me->normals) put(b, me->normals, (size_t)me->vertex_count * 12);
		if (me->uvs) put(b, me->uvs, (size_t)me->vertex_count * 8);
		if (me->uvs1) put(b, me->uvs1, (size_t)me->vertex_count * 8);
		if (me->colors) put(b, me->colors, (size_t)me->vertex_count * 4);
		if (me->tangents) put(b, me->tangents, (size_t)me->vertex_count * 16);
		if (!identity) put(b, me->indices, (size_t)me->index_count * 4);
		if (me->lod_count) put_mesh_levels(b, me);
		if (me->caster) {
			const struct rnd_caster_level *c = me->caster;
			put_u32(b, c->vertex_count);
			put_u32(b, c->index_count);
			put(b, &c->error, 4);
			put(b, c->positions, (size_t)c->vertex_count * 12);
			put(b, c->indices, (size_t)c->index_count * 4);
		}
	}
	for (uint32_t i = 0; i < m->instance_count; i++) {
		put_u32(b, m->instances[i].mesh);
		put(b, m->instances[i].model, 64);
	}
}

void api_wire_put_levels(struct api_wire_buf *b, const struct api_model *m)
{
	put_u32(b, m->mesh_count);
	for (uint32_t i = 0; i < m->mesh_count; i++) put_mesh_levels(b, &m->meshes[i]);
}
