/*
 * api/scene_parse — scene documents (contract v1, JSON) to renderer scenes.
 *
 * One pass over the document with jansson: every member is checked for type and range, and
 * every object for unknown members (except `extras` and `x-*`), while the rnd_scene is filled.
 * The first error wins and is reported as a 400 problem whose pointer is the RFC 6901 path of
 * the offending member, kept in pctx.ptr as the walk descends. Things that are valid but over
 * a limit, or not supported by the renderer yet, are 422s; they are deferred until the whole
 * document has been validated, so a 400 anywhere always takes precedence.
 *
 * This file holds the root and the model sources (base64 `data`, a `path` under the asset root,
 * a multipart `part`); each member family has its own module (scene_internal.h lists them).
 * Every array the rnd_scene points to lives in the scene's arena (api/arena.h), except the
 * geometry and textures of imported models: those live in the (immutable, cached) model
 * (api/model.h), of which the scene holds a reference until api_scene_free().
 */
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "big_strings.h"
#include "asset.h"
#include "gltf_variants.h"
#include "env_map.h"
#include "model.h"
#include "model_paths.h"
#include "model_refs.h"
#include "preset.h"
#include "scene_hash.h"
#include "scene_internal.h"

/* A reference to an imported model, released in api_scene_free() (the node is in the arena). */
struct model_ref {
	struct model_ref *next;
	struct api_model *model;
};

static void model_refs_release(struct model_ref *r)
{
	for (; r; r = r->next) api_model_release(r->model);
}

/* Reads `path` (checked by api_asset_check_path) under the asset root (api/asset.h) into a
 * malloc'd buffer, with the file's stamp (api/model_paths.h). 0 or -1 (400 at the current
 * pointer, 500 when the root itself is unusable). */
static int read_asset(struct pctx *c, const char *path, unsigned char **out, size_t *len,
                      struct api_asset_stamp *stamp)
{
	char err[300];
	int status;
	if (api_asset_read_stamped(c->lim->asset_root, path, out, len, stamp, &status, err, sizeof err) != API_OK) {
		api_problem_set(c->p, status, c->ptr, "%s", err);
		return -1;
	}
	return 0;
}

/* The model file's bytes from its one source member `first` (v its value, the pointer already
 * at it): base64 `data`, a `path` under the asset root (malloc'd: the caller frees it; its
 * extension may give the format: *f, *given), or a multipart `part` (the request's bytes). */
static int model_bytes(struct pctx *c, const char *first, json_t *v, const char *const *formats, int *f,
                       bool *given, unsigned char **out, size_t *out_len, struct api_asset_stamp *stamp)
{
	int rc = 0;
	unsigned char *b = NULL;
	size_t len = 0;
	if (!json_is_string(v)) {
		rc = api_fail(c, "%s must be a string, not %s", first, api_type_name(v));
	} else if (!strcmp(first, "data")) {
		if (api_decode_b64_member(c, "data", v, &b, &len) < 0) rc = -1;
		else if (!len) rc = api_fail(c, "data must not be empty");
	} else if (!strcmp(first, "path")) {
		const char *s = json_string_value(v);
		rc = api_path_bytes(c, s, &b, &len, stamp);
		if (!rc && !*given) { /* the extension says what the bytes may not (obj, ascii stl) */
			const char *dot = strrchr(s, '.');
			for (int i = 0; dot && formats[i]; i++)
				if (!strcasecmp(dot + 1, formats[i])) { *f = i; *given = true; }
		}
	} else {
		const uint8_t *pb;
		rc = api_part_bytes(c, v, &pb, &len);
		b = (unsigned char *)pb;
	}
	*out = b;
	*out_len = len;
	return rc;
}

int api_path_bytes(struct pctx *c, const char *path, unsigned char **out, size_t *len, struct api_asset_stamp *stamp)
{
	char perr[200];
	*out = NULL;
	*len = 0;
	if (api_asset_check_path(path, perr, sizeof perr) != API_OK) return api_fail(c, "%s", perr);
	return read_asset(c, path, out, len, stamp);
}

int api_part_bytes(struct pctx *c, json_t *v, const uint8_t **out, size_t *len)
{
	*out = NULL;
	*len = 0;
	if (!json_is_string(v)) return api_fail(c, "part must be a string, not %s", api_type_name(v));
	if (!json_string_length(v)) return api_fail(c, "part must name a part of the multipart request");
	const char *name = json_string_value(v);
	size_t i = 0;
	while (i < c->nparts && (!c->parts[i].name || strcmp(c->parts[i].name, name))) i++;
	if (i == c->nparts) return api_fail(c, "part \"%.64s\" is not a part of this request", name);
	if (!c->parts[i].len) return api_fail(c, "part \"%.64s\" is empty", name);
	*out = c->parts[i].data;
	*len = c->parts[i].len;
	return 0;
}

/* Makes m (one reference, given to the scene) the current model. */
static int attach_model(struct pctx *c, struct api_model *m)
{
	struct model_ref *ref = api_arena_alloc(c->arena, sizeof *ref);
	if (!ref) {
		api_model_release(m);
		return api_fail(c, "out of memory");
	}
	ref->model = m;
	ref->next = c->models;
	c->models = ref;
	c->cur_model = m;
	return 0;
}

/* A model by path imported before from files that have not changed since (api/model_paths.h):
 * attached without reading them, 1; 0 when there is none (the caller reads and imports). */
static int model_remembered(struct pctx *c, json_t *v, const struct api_model_path_key *k)
{
	char perr[200];
	if (!json_is_string(v) || !k->root || !k->root[0] ||
	    api_asset_check_path(json_string_value(v), perr, sizeof perr) != API_OK)
		return 0;
	uint64_t h;
	struct api_model *m = api_model_paths_find(k, c->lim, &h);
	if (!m) return 0;
	c->import.hits++;
	api_asset_hash(&c->asset_hash, NULL, (const uint8_t *)&h, 8);
	return attach_model(c, m) < 0 ? -1 : 1;
}

/* The object's name, else its path, else NULL: what a problem about its model names. */
static const char *model_label(json_t *j, const char *first, json_t *v)
{
	json_t *nm = json_object_get(j, "name");
	return json_is_string(nm) ? json_string_value(nm) : !strcmp(first, "path") ? json_string_value(v) : NULL;
}

/* The files a model in b[0..len) refers to (a .gltf's buffers and images, an .obj's .mtl and
 * textures): read beside the model or among the request's parts (api/model_refs.h). */
static int model_refs(struct pctx *c, json_t *j, const char *first, json_t *v, const uint8_t *b, size_t len,
                      enum api_model_format f, struct api_model_refs *refs)
{
	struct api_ref_source src = {.root = c->lim->asset_root, .path = !strcmp(first, "path") ? json_string_value(v)
	                             : NULL, .parts = c->parts, .nparts = c->nparts};
	char err[400];
	int status;
	if (api_model_refs_collect(b, len, f == API_MODEL_SNIFF ? api_model_sniff(b, len) : f, &src, refs, &status, err,
	                           sizeof err) != API_OK) {
		const char *what = model_label(j, first, v);
		if (what) api_problem_set(c->p, status, c->ptr, "model \"%.128s\" cannot be imported: %s", what, err);
		else api_problem_set(c->p, status, c->ptr, "the model in %s cannot be imported: %s", first, err);
		return -1;
	}
	if (refs->warning[0]) api_warn(c, "%s: %s", c->ptr, refs->warning);
	return 0;
}

/* The model's bytes with its glTF material variant `variant` applied (api/gltf_variants.h),
 * into *out (malloc'd); a problem at the object's "variant" (the pointer is popped to the
 * object's: `obj`). */
static int pick_variant(struct pctx *c, size_t obj, const char *variant, const uint8_t *b, size_t len,
                        enum api_model_format fmt, uint8_t **out, size_t *out_len)
{
	char err[400];
	bool oom;
	if (fmt == API_MODEL_GLB || fmt == API_MODEL_GLTF)
		*out = api_gltf_pick_variant(b, len, fmt == API_MODEL_GLB, variant, out_len, &oom, err, sizeof err);
	else snprintf(err, sizeof err, "variant picks a glTF material variant (KHR_materials_variants); this model is %s %s "
	              "file", fmt == API_MODEL_OBJ ? "an" : "a", api_model_format_name(fmt));
	if (*out) return 0;
	api_ptr_pop(c, obj);
	return api_fail_at(c, "variant", "%s", err);
}

/* A model object's members that say what to import: its one source (data, path or part:
 * *first), the glTF material variant (*variant, NULL: none) and the format hint (*f, an index of
 * formats; -1: none). 0, or -1 with the problem set. */
static int model_source(struct pctx *c, json_t *j, const char *const *formats, const char **first,
                        const char **variant, int *f)
{
	static const char *const sources[] = {"data", "path", "part"};
	*first = NULL;
	for (int i = 0; i < 3; i++) {
		if (!json_object_get(j, sources[i])) continue;
		if (*first)
			return api_fail_at(c, sources[i], "%s cannot be combined with %s: a model has one source", sources[i],
			                   *first);
		*first = sources[i];
	}
	if (!*first) return api_fail(c, "a model needs one of data (base64 file), path or part");
	*variant = NULL;
	if (api_get_string(c, j, "variant", variant) < 0) return -1;
	/* A hint for the importer, not a value of the parsed scene: checked, not recorded as read
	 * (scene_internal.h), so that it stays in the ETag's hash as written. */
	*f = -1;
	json_t *fv = json_object_get(j, "format");
	if (!fv) return 0;
	size_t o2 = api_ptr_push(c, "format");
	int frc = api_check_enum(c, "format", fv, formats, f);
	api_ptr_pop(c, o2);
	return frc < 0 ? -1 : 0;
}

/* A model imported by path (its bytes b[0..len), the files it names in refs): the answer
 * depends on the files, not only on the request, so the ETag's hash takes them; a model with
 * nothing to say (quiet: no warning about its files or its format, no variant) is remembered
 * for later requests (api/model_paths.h), which attach it without its bytes. */
static void model_by_path(struct pctx *c, const struct api_model_path_key *key, const struct api_asset_stamp *stamp,
                          const uint8_t *b, size_t len, const struct api_model_refs *refs, bool quiet,
                          struct api_model *m)
{
	uint64_t h = 0;
	api_asset_hash(&h, key->path, b, len);
	if (refs->asset_hash) api_asset_hash(&h, NULL, (const uint8_t *)&refs->asset_hash, 8);
	api_asset_hash(&c->asset_hash, NULL, (const uint8_t *)&h, 8);
	if (quiet && !refs->warning[0]) api_model_paths_remember(key, stamp, refs->origins, refs->norigins, m, h);
}

int api_parse_model(struct pctx *c, json_t *j)
{
	static const char *const formats[] = {"glb", "gltf", "obj", "stl", "ply", NULL};
	const char *first, *variant;
	int f;
	if (model_source(c, j, formats, &first, &variant, &f) < 0) return -1;
	bool given = f >= 0;
	json_t *v = json_object_get(j, first);
	size_t old = api_ptr_push(c, first);
	bool by_path = !strcmp(first, "path");
	struct api_model_path_key key = {c->lim->asset_root, json_string_value(v), given ? f : -1};
	/* A variant is another model (api/gltf_variants.h): found in the cache by its own bytes. */
	int rc = by_path && !variant ? model_remembered(c, v, &key) : 0;
	if (rc != 0) {
		api_ptr_pop(c, old);
		return rc < 0 ? -1 : 0;
	}
	unsigned char *b = NULL;
	size_t len = 0;
	struct api_asset_stamp stamp;
	double t0 = api_clock_ms();
	rc = model_bytes(c, first, v, formats, &f, &given, &b, &len, &stamp);
	/* The format or extension is a hint: the bytes decide where they can (a .glb renamed .stl). */
	char said[300];
	enum api_model_format fmt = api_model_settle_format(b, len, given ? (enum api_model_format)f : API_MODEL_SNIFF,
	                                                    said, sizeof said);
	if (rc == 0 && said[0]) api_warn(c, "%s: %s", c->ptr, said);
	struct api_model_refs refs = {0};
	if (rc == 0) rc = model_refs(c, j, first, v, b, len, fmt, &refs);
	c->import.ms[API_IMPORT_READ] += (float)(api_clock_ms() - t0);   /* the model and the files it names */
	uint8_t *vb = NULL;
	size_t vlen = 0;
	if (rc == 0 && variant) rc = pick_variant(c, old, variant, b, len, fmt, &vb, &vlen);
	struct api_model *m = NULL;
	char err[400];
	int status;
	if (rc == 0 && api_model_get_timed(vb ? vb : b, vb ? vlen : len, refs.files, refs.count, fmt, c->lim, &m,
	                                   &c->import, &status, err, sizeof err) != API_OK) {
		/* 400 for a bad file, 422 over the import time/memory limit, 500 when the importer cannot run. */
		const char *what = model_label(j, first, v);
		if (what)
			api_problem_set(c->p, status, c->ptr, "model \"%.128s\" (%s) could not be imported: %s", what, first, err);
		else api_problem_set(c->p, status, c->ptr, "the model in %s could not be imported: %s", first, err);
		rc = -1;
	}
	if (rc == 0 && by_path) model_by_path(c, &key, &stamp, b, len, &refs, !said[0] && !variant, m);
	if (rc == 0) rc = attach_model(c, m);
	free(vb);
	api_model_refs_release(&refs);
	if (by_path) free(b);
	api_ptr_pop(c, old);
	return rc < 0 ? -1 : 0;
}

static const char *const ROOT_MEMBERS[] = {"width", "height", "camera", "environment", "materials", "objects",
                                           "lights", "shadows", "output", "views", "turntable", "preset", NULL};

/* The root, member family by member family, in an order where each finds what it needs: objects
 * are counted first (they size the material array: inline materials), the cameras come before
 * the objects and the turntable's cameras after them (they circle the objects), the root
 * shadow settings before the lights that start from them, the lights before output.debug_light. */
static int parse_root(struct pctx *c, json_t *root, struct api_scene *s)
{
	struct rnd_scene *sc = &s->scene;
	if (!json_is_object(root)) return api_fail(c, "the scene document must be a JSON object, not %s", api_type_name(root));
	if (api_check_members(c, root, ROOT_MEMBERS, NULL, "the scene") < 0) return -1;
	if (api_get_u32(c, root, "width", 1, RND_MAX_DIMENSION, &sc->width) < 0 ||
	    api_get_u32(c, root, "height", 1, RND_MAX_DIMENSION, &sc->height) < 0)
		return -1;
	/* Models imported for this request need show no more than its images can (api.h). */
	c->lim_own = *c->lim;
	c->lim_own.output_side = sc->width > sc->height ? sc->width : sc->height;
	c->lim = &c->lim_own;
	json_t *objs = json_object_get(root, "objects");
	if (!objs) return api_fail_at(c, "objects", "objects is required (it may be an empty array)");
	if (!json_is_array(objs)) return api_fail_at(c, "objects", "objects must be an array, not %s", api_type_name(objs));
	if (api_parse_materials(c, root, json_array_size(objs)) < 0) return -1;
	struct turntable tt = {0};
	if (api_parse_cameras(c, root, sc, &tt) < 0) return -1;
	json_t *env = json_object_get(root, "environment");
	if (env) {
		size_t old = api_ptr_push(c, "environment");
		int rc = api_parse_environment(c, env, &sc->environment);
		api_ptr_pop(c, old);
		if (rc < 0) return -1;
	}
	if (api_parse_objects(c, objs, s) < 0) return -1;
	if (tt.frames && api_turntable_views(c, &tt, sc) < 0) return -1;
	/* `fit` (scene or objects) stays for the renderer: it frames the bounds tightly to the
	 * margin, leaving planes and shadow catchers out for `objects`. */
	struct rnd_shadow root_shadow;
	if (api_parse_root_shadow(c, root, &root_shadow) < 0) return -1;
	if (api_parse_lights(c, root, sc, &root_shadow) < 0) return -1;
	if (api_parse_root_output(c, root, s) < 0) return -1;
	if (api_check_environment(c, &root_shadow, sc) < 0) return -1;
	api_set_pixels(s);
	api_check_size(c, root, sc);
	sc->materials = c->mats;
	sc->material_count = c->mat_count;
	return api_check_textures(c, sc);
}

enum api_result api_scene_parse(const char *json, size_t len, const struct api_limits *limits,
                                struct api_scene **out, struct api_problem *p)
{
	return api_scene_parse_parts(json, len, limits, NULL, 0, out, p);
}

enum api_result api_scene_parse_parts(const char *json, size_t len, const struct api_limits *limits,
                                      const struct api_part *parts, size_t nparts,
                                      struct api_scene **out, struct api_problem *p)
{
	struct api_problem scratch;
	struct api_limits deflim;
	if (!p) p = &scratch;
	if (!out) return api_problem_set(p, 500, "", "api_scene_parse: no output pointer");
	*out = NULL;
	if (!limits) {
		api_limits_defaults(&deflim);
		limits = &deflim;
	}
	if (!json) json = "", len = 0;

	json_error_t je;
	/* The scene's base64 members, read only by api_decode_b64_member: big ones stay in json. */
	static const char *const b64_members[] = {"data", "positions", "indices", "normals", "uvs",
	                                          "base_color_texture", NULL};
	struct api_big_strings big;
	json_t *root = api_json_load(json, len, JSON_REJECT_DUPLICATES, &je, b64_members, &big);
	if (!root) {
		api_problem_set(p, 400, "", "malformed JSON at line %d, column %d: %s", je.line, je.column, je.text);
		snprintf(p->type, sizeof p->type, PROBLEMS "malformed-json");
		snprintf(p->title, sizeof p->title, "Malformed JSON");
		return API_ERR;
	}
	if (api_preset_apply(&root, p) < 0) {
		json_decref(root);
		api_big_strings_free(&big);
		return API_ERR;
	}
	struct pctx c = {.p = p, .lim = limits, .default_mat = UINT32_MAX, .parts = parts, .nparts = nparts, .big = &big};
	c.arena = api_arena_create();
	struct api_scene *s = c.arena ? api_arena_alloc(c.arena, sizeof *s) : NULL;
	if (!s) {
		json_decref(root);
		api_big_strings_free(&big);
		api_arena_destroy(c.arena);
		return api_problem_set(p, 500, "", "out of memory parsing the scene");
	}
	s->arena_ = c.arena;
	rnd_scene_defaults(&s->scene);
	s->scene.max_shadow_resolution = limits->max_shadow_resolution;   /* the renderer's own choices too */
	s->format = API_FORMAT_PNG;
	s->bit_depth = 8;
	s->png_level = -1;
	s->quality = -1;

	int rc = parse_root(&c, root, s);
	if (rc == 0 && c.pending) {
		*p = c.pend;
		rc = -1;
	}
	/* The parsed scene with its defaults, and what of the document it does not hold. */
	if (rc == 0) {
		memcpy(s->warnings, c.warnings, sizeof s->warnings);
		s->scene_hash = api_scene_hash(root, &big, parts, nparts, c.reads_lost ? NULL : c.reads, c.nreads, s);
	}
	free(c.reads);
	json_decref(c.mat_index);
	json_decref(root);
	api_big_strings_free(&big);
	if (rc < 0) {
		model_refs_release(c.models);
		api_env_map_release(c.env_map);
		api_arena_destroy(c.arena);
		return API_ERR;
	}
	s->models_ = c.models;
	s->env_map_ = c.env_map;
	s->object_source_ = c.object_source;
	s->views_key_ = c.views_key;
	s->asset_hash = c.asset_hash;
	s->import = c.import;
	api_set_pixels(s);   /* again: the format's own warnings follow the document's */
	*out = s;
	return API_OK;
}

void api_scene_free(struct api_scene *s)
{
	/* The scene itself lives in its arena; the models it points into are referenced. */
	if (!s) return;
	model_refs_release(s->models_);
	api_env_map_release(s->env_map_);
	api_arena_destroy(s->arena_);
}

enum api_result api_scene_check_output(const struct api_scene *s, struct api_problem *p)
{
	struct api_problem scratch;
	if (!p) p = &scratch;
	if (!s) return API_OK;
	const char *label = api_format_label(s->format);
	if (s->format != API_FORMAT_EXR && s->scene.output.aovs)
		return api_problem_set(p, 400, "/output/aovs", "aovs need an EXR answer (output.format \"exr\", "
		                       "Accept: image/x-exr, or an .exr output file): %s has no room for AOV channels",
		                       s->format == API_FORMAT_PNG ? "the default format PNG" : label);
	if (!api_format_lossy(s->format) && s->quality >= 0)
		return api_problem_set(p, 400, "/output/quality", "quality (lossy WebP or AVIF, 0..100) needs a WebP or "
		                       "AVIF answer (output.format \"webp\" or \"avif\", Accept: image/webp or image/avif, "
		                       "or a .webp or .avif output file), not %s", label);
	/* A sheet of views may pass WebP's or AVIF's bound (one view cannot: 8192 a side at most). */
	uint32_t cols = 1, rows = 1, side = api_format_max_side(s->format);
	if (s->scene.view_count > 1) rnd_sheet_layout(s->scene.view_count, &cols, &rows);
	char at[16];
	snprintf(at, sizeof at, "/%s", s->views_key_ ? s->views_key_ : "width");
	if (side && ((uint64_t)s->scene.width * cols > side || (uint64_t)s->scene.height * rows > side))
		return api_problem_set(p, 422, at, "%s is at most %u pixels a side; this image is %llux%llu (a sheet of %u x "
		                       "%u views)", label, side, (unsigned long long)s->scene.width * cols,
		                       (unsigned long long)s->scene.height * rows, cols, rows);
	return API_OK;
}

enum api_result api_scene_set_format(struct api_scene *s, enum api_format f, struct api_problem *p)
{
	struct api_problem scratch;
	if (!p) p = &scratch;
	if (!s) return api_problem_set(p, 500, "", "api_scene_set_format: no scene");
	if (f != API_FORMAT_EXR && s->scene.output.aovs)
		return api_problem_set(p, 400, "/output/aovs", "aovs need format \"exr\": %s has no room for AOV "
		                       "channels", api_format_label(f));
	s->format = f;
	s->format_explicit = 1;
	api_set_pixels(s);
	return API_OK;
}
