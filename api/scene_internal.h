/*
 * api/scene_internal.h — what the scene parser's modules share (not part of the api).
 *
 * api_scene_parse() (scene_parse.c) walks the document once; each member family has its module:
 *   json_walk.c       the JSON Pointer of the member being checked, 400/422 problems, typed getters
 *   scene_materials.c materials (and base-colour textures), the distinct-texture count
 *   scene_objects.c   objects: shapes, mesh arrays, transforms, ground placement, model expansion
 *   scene_camera.c    one camera, and the "objects" framing sphere
 *   scene_views.c     views, turntable, output, and the size of the image or sheet
 *   scene_lights.c    lights
 *   scene_environment.c the environment: background, ambient, map (api/env_map.h), its shadows
 *   scene_shadows.c   shadow settings (root and per light)
 *   scene_parse.c     the root, model sources (data, path under the asset root, part), api_scene_*
 *
 * Conventions (every function below): a `struct pctx` carries the walk; getters return 1 when the
 * member is present and valid, 0 when absent, -1 after recording a 400 at the member's pointer
 * (the first error wins). api_defer() records a 422 that is reported only when the document has
 * no 400 anywhere. Everything allocated for the scene comes from c->arena (api/arena.h).
 *
 * Threading: a pctx belongs to one api_scene_parse() call; nothing here is shared.
 */
#ifndef UMBRA_API_SCENE_INTERNAL_H
#define UMBRA_API_SCENE_INTERNAL_H

#include <float.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <jansson.h>
#include "api.h"
#include "arena.h"
#include "big_strings.h"
#include "scene_hash.h"

#define DEG2RAD (3.14159265358979323846 / 180.0)
#define PROBLEMS "https://umbra.dev/problems/"

struct model_ref;
struct api_model;

struct pctx {
	struct api_arena *arena;
	struct api_problem *p;
	const struct api_limits *lim;
	struct api_limits lim_own;    /* *lim with this request's output_side (parse_root); lim points here then */
	uint64_t asset_hash;          /* FNV-1a of every file read under the asset root */
	struct api_import_times import;   /* the models' imports (api_scene.import) */
	char ptr[sizeof(((struct api_problem *)0)->pointer)];
	size_t len;
	/* The first deferred 422 (limit or unsupported feature). */
	bool pending;
	struct api_problem pend;
	/* Materials: named ones first (in document order), then inline ones, then the default. */
	json_t *mat_index;            /* name -> integer index */
	struct rnd_material *mats;
	uint32_t mat_count, mat_cap;
	uint32_t default_mat;         /* UINT32_MAX until an object needs it */
	/* Models: the request's binary parts, every model the scene holds a reference to, and the
	 * one the object being parsed imported (taken by api_parse_objects). */
	const struct api_part *parts;
	size_t nparts;
	struct model_ref *models;
	const uint32_t *object_source;  /* document object of each rnd object (NULL: the same index) */
	const char *views_key;          /* "views" or "turntable" when the document has either */
	struct api_model *cur_model;
	/* Ground placement (api/ground.h): margin per document object, > 0 for placement "ground". */
	float *ground_margin;
	bool *up_auto;            /* per object: a model with "up": "auto" (api/model_up.h), decided once imported */
	size_t cur_object;
	char warnings[sizeof(((struct api_scene *)0)->warnings)]; /* what is drawn other than asked ("; " between) */
	const struct api_big_strings *big;  /* base64 members left in the document (api/big_strings.h) */
	/* The environment map (api/env_map.h), a reference the scene keeps; whether the document
	 * said anything of the environment's shadows (else the root's `shadows: false` turns them off). */
	struct api_env_map *env_map;
	bool env_shadow_given;
	/* Members whose value the walk read into the parsed scene (the api_get_* getters of numbers,
	 * booleans, enums and vectors record theirs): the ETag's hash takes the parsed scene for
	 * them, so their spelling, or their being left out for the default, does not count
	 * (api/scene_hash.h). A member whose value goes elsewhere (a model's format hint, read by
	 * the importer) is checked with api_check_*, which records nothing. */
	struct api_member_read *reads;
	size_t nreads, reads_cap;
	bool reads_lost;                /* out of memory recording one: the document is hashed whole */
};

/* ---- json_walk.c: the pointer, problems, typed members ---- */

/* Appends /key (escaped per RFC 6901) or /i to the pointer; returns the length to pop back to. */
size_t api_ptr_push(struct pctx *c, const char *key);
size_t api_ptr_index(struct pctx *c, size_t i);
void api_ptr_pop(struct pctx *c, size_t old);
/* 400 at the current pointer / at its member `key`. Return -1 so callers can `return api_fail(...)`. */
int api_fail(struct pctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
int api_fail_at(struct pctx *c, const char *key, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* Records a 422 at the current pointer (plus `key` when not NULL) unless one is recorded. */
void api_defer(struct pctx *c, bool unsupported, const char *key, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* Something the scene asked for that is left out of the image, said in the answer (the
 * server's Umbra-Warnings header, the CLI's stderr) instead of silently: appended to
 * c->warnings ("; " between), cut at its size. */
void api_warn(struct pctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* "an object", "a number"...: for messages. */
const char *api_type_name(const json_t *v);
/* Records that obj's member key was read into the parsed scene (c->reads): for a member read
 * without a getter (`"shadows": false`, `aovs`). */
void api_member_read(struct pctx *c, json_t *obj, const char *key);
/* `extras` and `x-*`: members any object may carry, never checked. */
bool api_free_member(const char *key);
/* Rejects members of obj named in neither list (suggesting a near miss). `what` names obj. */
int api_check_members(struct pctx *c, json_t *obj, const char *const *list, const char *const *list2,
                      const char *what);
int api_require_object(struct pctx *c, json_t *v, const char *name);
/* Enters the sub-object `key` of j: 1 when present (pointer pushed, *old set), 0 absent, -1. */
int api_enter(struct pctx *c, json_t *j, const char *key, const char *const *members, const char *what,
              json_t **sub, size_t *old);

struct range { double lo, hi; bool lo_open, hi_open; };

static const struct range R_ANY = {-FLT_MAX, FLT_MAX, false, false};
static const struct range R_NONNEG = {0, FLT_MAX, false, false};
static const struct range R_POS = {0, FLT_MAX, true, false};
static const struct range R_UNIT = {0, 1, false, false};

enum {
	V_NONNEG = 1u << 0,   /* colours */
	V_NONZERO = 1u << 1,  /* directions, up, quaternions */
	V_NOZERO_COMP = 1u << 2, /* scale */
	V_POS = 1u << 3,      /* sizes */
	V_ALPHA01 = 1u << 4,  /* a 4th component is an alpha in 0..1 */
};

/* check_*: the value v (named `name` in messages) at the current pointer; 0 or -1.
 * get_*: the member `key` of obj; 1 present and valid, 0 absent, -1. The getters of numbers,
 * booleans, enums and vectors record a member present and valid with api_member_read(): its
 * value must then be in the parsed scene (api_scene or its rnd_scene), which the ETag hashes
 * in its place. */
int api_check_num(struct pctx *c, const char *name, json_t *v, const struct range *r, double *out);
int api_get_num(struct pctx *c, json_t *obj, const char *key, const struct range *r, double *out);
int api_get_float(struct pctx *c, json_t *obj, const char *key, const struct range *r, float *out);
/* Degrees in the document, radians in the scene. */
int api_get_angle(struct pctx *c, json_t *obj, const char *key, const struct range *r, float *out);
int api_check_int(struct pctx *c, const char *name, json_t *v, long long lo, long long hi, long long *out);
int api_get_int(struct pctx *c, json_t *obj, const char *key, long long lo, long long hi, long long *out);
int api_get_u32(struct pctx *c, json_t *obj, const char *key, long long lo, long long hi, uint32_t *out);
int api_get_bool(struct pctx *c, json_t *obj, const char *key, bool *out);
int api_get_string(struct pctx *c, json_t *obj, const char *key, const char **out);
/* names: NULL-terminated; *out is the index of the match. */
int api_check_enum(struct pctx *c, const char *name, json_t *v, const char *const *names, int *out);
int api_get_enum(struct pctx *c, json_t *obj, const char *key, const char *const *names, int *out);
/* A vector of nmin..nmax numbers (V_* flags); returns the count (> 0), 0 when absent, -1. */
int api_check_vec(struct pctx *c, const char *name, json_t *v, float *out, int nmin, int nmax, unsigned flags);
int api_get_vec(struct pctx *c, json_t *obj, const char *key, float *out, int nmin, int nmax, unsigned flags);
/* Decodes a base64 string member into the arena. 0 or -1 (400 at the current pointer). */
int api_decode_b64_member(struct pctx *c, const char *name, json_t *v, unsigned char **out, size_t *len);
/* A mesh array: flat JSON numbers, or base64 of little-endian float32 / uint32 (indices).
 * 1 with *out (arena) and *count, 0 when absent, -1. */
int api_get_data(struct pctx *c, json_t *obj, const char *key, bool indices, void **out, size_t *count);

/* ---- the member families (each 0 or -1 unless said) ---- */

/* scene_materials.c: `materials` (sizes c->mats for them, the nobj inline ones and the default). */
int api_parse_materials(struct pctx *c, json_t *root, size_t nobj);
int api_parse_material(struct pctx *c, json_t *j, struct rnd_material *m, const char *what);
int api_add_material(struct pctx *c, uint32_t *index);
/* 422 at the object that brings the scene over lim->max_textures distinct textures. */
int api_check_textures(struct pctx *c, const struct rnd_scene *sc);

/* scene_parse.c: the bytes of a file under the asset root (path checked here; *out malloc'd,
 * the caller frees it) or of a part of the multipart request (v: its name; *out the request's);
 * 0 or -1 (400 at the current pointer). */
struct api_asset_stamp;
int api_path_bytes(struct pctx *c, const char *path, unsigned char **out, size_t *len, struct api_asset_stamp *stamp);
int api_part_bytes(struct pctx *c, json_t *v, const uint8_t **out, size_t *len);

/* scene_objects.c: `objects` (an array), with models expanded and ground planes placed. */
int api_parse_objects(struct pctx *c, json_t *objs, struct api_scene *s);
/* scene_parse.c: a model object's source; sets c->cur_model. */
int api_parse_model(struct pctx *c, json_t *j);

/* scene_camera.c */
int api_parse_camera(struct pctx *c, json_t *j, struct rnd_camera *cam);
/* Centre and radius of the bounds that `fit: "objects"` frames (rnd_object_frames()). */
void api_objects_sphere(const struct rnd_scene *sc, const struct rnd_material *mats, double centre[3],
                        double *radius);

/* scene_views.c */
struct turntable {
	uint32_t frames;      /* 0 = no turntable */
	double elevation;     /* degrees */
	double distance;      /* 0 = fitted */
};
/* `camera`, `views` and `turntable` (whose cameras wait for the objects: api_turntable_views). */
int api_parse_cameras(struct pctx *c, json_t *root, struct rnd_scene *sc, struct turntable *tt);
int api_turntable_views(struct pctx *c, const struct turntable *tt, struct rnd_scene *sc);
/* `output`, checked against the lights. */
int api_parse_root_output(struct pctx *c, json_t *root, struct api_scene *s);
void api_set_pixels(struct api_scene *s);
/* 422s for an image or a sheet of views over the server's or the renderer's limits. */
void api_check_size(struct pctx *c, json_t *root, const struct rnd_scene *sc);

/* scene_lights.c */
int api_parse_lights(struct pctx *c, json_t *root, struct rnd_scene *sc, const struct rnd_shadow *root_shadow);
/* scene_environment.c: `environment` (j at the current pointer), and after the lights and the
 * output, the rules that need them (the root's shadows off, a map background and transparency). */
int api_parse_environment(struct pctx *c, json_t *j, struct rnd_environment *env);
int api_check_environment(struct pctx *c, const struct rnd_shadow *root_shadow, struct rnd_scene *sc);

/* scene_shadows.c: applies the members present in j over *s. */
int api_parse_shadow(struct pctx *c, json_t *j, struct rnd_shadow *s, const char *what);
/* The root `shadows` (object or boolean) over the renderer's defaults. */
int api_parse_root_shadow(struct pctx *c, json_t *root, struct rnd_shadow *s);
/* After the lights: shadow settings that contradict their own light (400: `directional` on a
 * spot or point light's shadow, contact shadows asked of a light whose shadows are off), and
 * warnings (api_warn) for settings no light uses (pcf_radius without pcf, vsm without a moment
 * filter, a light size without pcss, contact tuning with contact off, a root default that
 * every light overrides or none can use). */
int api_check_shadow_use(struct pctx *c, json_t *root, const struct rnd_scene *sc);

#endif
