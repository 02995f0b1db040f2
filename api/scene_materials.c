/*
 * api/scene_materials.c — the scene's materials: the named ones of `materials`, inline ones of
 * objects (scene_objects.c asks for a slot with api_add_material()), base-colour textures
 * (decoded in the sandbox, copied into the arena) and the count of distinct textures.
 * See scene_internal.h for the conventions.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sandbox.h"
#include "scene_internal.h"

/* Texels a texture may decode to (a bound on the decoder's memory, under the renderer's
 * RND_MAX_TEXTURE_SIDE squared). */
#define MAX_TEXTURE_PIXELS (64ull << 20)

static const char *const MATERIAL_MEMBERS[] = {"base_color", "base_color_texture", "alpha_mode", "alpha_cutoff",
                                               "roughness", "metallic", "emissive", "shadow_catcher", NULL};

/* What a texture's decode will take, admitted first (api_memory_gate): its reply and the
 * arena's copy, by the header's size. A JPEG of 141 bytes may claim 8192^2 texels (+512 MB
 * here, uncounted before). False: c->p says why (at the texture's member). */
static bool reserve_decode(struct pctx *c, const uint8_t *b, size_t len)
{
	const struct api_memory_gate *mg = c->lim->memory_gate;
	uint32_t w, h;
	if (!mg || !api_image_header_size(b, len, &w, &h) || (uint64_t)w * h > MAX_TEXTURE_PIXELS) return true;
	if (mg->reserve(mg->user, (uint64_t)w * h * 8, c->p)) return true;
	if (!c->p->pointer[0]) snprintf(c->p->pointer, sizeof c->p->pointer, "%s", c->ptr);
	return false;
}

int api_parse_material(struct pctx *c, json_t *j, struct rnd_material *m, const char *what)
{
	if (api_require_object(c, j, what) < 0 || api_check_members(c, j, MATERIAL_MEMBERS, NULL, "a material") < 0)
		return -1;
	rnd_material_defaults(m);
	float col[4] = {0, 0, 0, 1};
	int n = api_get_vec(c, j, "base_color", col, 3, 4, V_NONNEG | V_ALPHA01);
	if (n < 0) return -1;
	if (n > 0) memcpy(m->base_color, col, sizeof col);
	static const char *const alpha_modes[] = {"opaque", "mask", NULL};
	int mode;
	int rc = api_get_enum(c, j, "alpha_mode", alpha_modes, &mode);
	if (rc < 0) return -1;
	if (rc) m->alpha_mode = mode ? RND_ALPHA_MASK : RND_ALPHA_OPAQUE;
	if (api_get_float(c, j, "alpha_cutoff", &R_UNIT, &m->alpha_cutoff) < 0 ||
	    api_get_float(c, j, "roughness", &R_UNIT, &m->roughness) < 0 ||
	    api_get_float(c, j, "metallic", &R_UNIT, &m->metallic) < 0 ||
	    api_get_vec(c, j, "emissive", m->emissive, 3, 3, V_NONNEG) < 0 ||
	    api_get_bool(c, j, "shadow_catcher", &m->shadow_catcher) < 0)
		return -1;
	/* glTF reads alphaCutoff only in MASK mode: valid, but unused here, so said. */
	if (json_object_get(j, "alpha_cutoff") && m->alpha_mode != RND_ALPHA_MASK)
		api_warn(c, "%s/alpha_cutoff: not used, alpha_mode is not \"mask\"", c->ptr);
	json_t *tex = json_object_get(j, "base_color_texture");
	if (tex) {
		size_t old = api_ptr_push(c, "base_color_texture");
		unsigned char *b;
		size_t len;
		if (!json_is_string(tex)) {
			api_fail(c, "base_color_texture must be a base64 PNG or JPEG string, not %s", api_type_name(tex));
			api_ptr_pop(c, old);
			return -1;
		}
		if (api_decode_b64_member(c, "base_color_texture", tex, &b, &len) < 0) { api_ptr_pop(c, old); return -1; }
		bool png = len >= 8 && !memcmp(b, "\x89PNG\r\n\x1a\n", 8);
		bool jpeg = len >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff;
		if (!png && !jpeg) {
			api_fail(c, "base_color_texture must be a base64 PNG or JPEG image");
			api_ptr_pop(c, old);
			return -1;
		}
		/* Decoded now (a texture the renderer would refuse is caught here, with its pointer) and
		 * copied into the arena, which owns it with the rest of the scene. */
		uint8_t *rgba = NULL;
		uint32_t w = 0, h = 0;
		char err[300];
		int status;
		if (!reserve_decode(c, b, len)) { api_ptr_pop(c, old); return -1; }
		/* In a sandboxed helper process (api/sandbox.h): libpng/libjpeg never see request bytes here. */
		if (api_sandbox_decode_image(b, len, MAX_TEXTURE_PIXELS, c->lim, &rgba, &w, &h, &status, err, sizeof err) !=
		    API_OK) {
			api_problem_set(c->p, status, c->ptr, "base_color_texture could not be decoded: %s", err);
			api_ptr_pop(c, old);
			return -1;
		}
		struct rnd_texture *t = api_arena_alloc(c->arena, sizeof *t);
		uint8_t *px = api_arena_calloc(c->arena, (size_t)w * h, 4);
		if (!t || !px) {
			free(rgba);
			api_fail(c, "base_color_texture is too large (out of memory)");
			api_ptr_pop(c, old);
			return -1;
		}
		memcpy(px, rgba, (size_t)w * h * 4);
		free(rgba);
		t->rgba = px;
		t->width = w;
		t->height = h;
		m->base_color_texture = t;
		if (w > RND_MAX_TEXTURE_SIDE || h > RND_MAX_TEXTURE_SIDE)
			api_defer(c, false, NULL, "base_color_texture is %ux%u texels, over the limit of %u per side", w, h,
			      RND_MAX_TEXTURE_SIDE);
		api_ptr_pop(c, old);
	}
	return 0;
}

int api_add_material(struct pctx *c, uint32_t *index)
{
	if (c->mat_count >= c->mat_cap) return api_fail(c, "too many materials");
	*index = c->mat_count++;
	return 0;
}


/* Sizes c->mats for every named material, one inline material per object and the default,
 * then parses `materials` (an object mapping names to materials) into c->mat_index. */
int api_parse_materials(struct pctx *c, json_t *root, size_t nobj)
{
	json_t *mats = json_object_get(root, "materials");
	size_t nmat = 0;
	if (mats) {
		if (!json_is_object(mats))
			return api_fail_at(c, "materials", "materials must be an object mapping names to materials, not %s",
			               api_type_name(mats));
		nmat = json_object_size(mats);
	}
	if (nobj > UINT32_MAX / 2 || nmat > UINT32_MAX / 2) return api_fail(c, "the scene has too many objects");
	c->mat_cap = (uint32_t)(nmat + nobj + 1);
	c->mats = api_arena_calloc(c->arena, c->mat_cap, sizeof *c->mats);
	c->mat_index = json_object();
	if (!c->mats || !c->mat_index) return api_fail(c, "out of memory");
	if (mats) {
		size_t old = api_ptr_push(c, "materials");
		const char *name;
		json_t *m;
		int rc = 0;
		json_object_foreach(mats, name, m) {
			size_t o2 = api_ptr_push(c, name);
			uint32_t mi = 0;
			rc = api_add_material(c, &mi);
			if (!rc) rc = api_parse_material(c, m, &c->mats[mi], "a material");
			if (!rc) json_object_set_new(c->mat_index, name, json_integer(mi));
			api_ptr_pop(c, o2);
			if (rc) break;
		}
		api_ptr_pop(c, old);
		if (rc) return -1;
	}
	return 0;
}

/* Distinct textures against lim->max_textures (the server's --max-textures, capped by the
 * device): counted in object order, so the 422 names the object that brought one too many
 * (a model's object for its textures, else the object whose material has it). */
int api_check_textures(struct pctx *c, const struct rnd_scene *sc)
{
	uint32_t max = c->lim->max_textures ? c->lim->max_textures : RND_DEFAULT_MAX_TEXTURES;
	const struct rnd_texture **seen = api_arena_calloc(c->arena, c->mat_count * RND_TEX_SLOTS + 1, sizeof *seen);
	uint8_t *counted = api_arena_calloc(c->arena, c->mat_count + 1, 1);
	if (!seen || !counted) return api_fail(c, "out of memory");
	uint32_t ntex = 0;
	for (uint32_t o = 0; o < sc->object_count && c->mat_count; o++) {
		uint32_t mi = sc->objects[o].material;
		if (mi >= c->mat_count || counted[mi]) continue;
		counted[mi] = 1;
		for (uint32_t slot = 0; slot < RND_TEX_SLOTS; slot++) {
			const struct rnd_texture *t = c->mats[mi].textures[slot];
			uint32_t k = 0;
			while (t && k < ntex && seen[k] != t) k++;
			if (!t || k < ntex) continue;
			if (ntex == max) {
				size_t old = api_ptr_push(c, "objects");
				api_ptr_index(c, c->object_source ? c->object_source[o] : o);
				api_defer(c, false, NULL, "this object brings the scene over %u distinct textures (this server's "
				          "limit: --max-textures)", max);
				api_ptr_pop(c, old);
				return 0;
			}
			seen[ntex++] = t;
		}
	}
	return 0;
}
