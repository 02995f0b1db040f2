/*
 * api/scene_objects.c — the scene's `objects`: shapes (plane, box, sphere, cylinder), mesh
 * arrays, transforms, materials by name or inline, ground placement; model objects (whose
 * source scene_parse.c reads, and whose `up` turns them upright) are expanded into one mesh
 * object per instance, and the triangle limits are checked. See scene_internal.h for the conventions.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "ground.h"
#include "model.h"
#include "model_up.h"
#include "scene_internal.h"
#include "umbra/rnd_math.h"

/* ---- transforms ---- */

static const char *const TRANSFORM_MEMBERS[] = {"translation", "rotation", "scale", "matrix", NULL};

static int parse_transform(struct pctx *c, json_t *j, float model[16])
{
	if (api_require_object(c, j, "transform") < 0 ||
	    api_check_members(c, j, TRANSFORM_MEMBERS, NULL, "a transform") < 0)
		return -1;
	json_t *mj = json_object_get(j, "matrix");
	if (mj) {
		const char *other = json_object_get(j, "translation") ? "translation"
		                    : json_object_get(j, "rotation") ? "rotation"
		                    : json_object_get(j, "scale") ? "scale" : NULL;
		if (other)
			return api_fail_at(c, "matrix", "matrix cannot be combined with %s (use either matrix or "
			               "translation/rotation/scale)", other);
		float m[16];
		if (api_get_vec(c, j, "matrix", m, 16, 16, 0) < 0) return -1;
		if (m[3] != 0 || m[7] != 0 || m[11] != 0 || m[15] != 1)
			return api_fail_at(c, "matrix", "matrix must be affine: its last row (elements 3, 7, 11, 15 in "
			               "column-major order) must be 0, 0, 0, 1");
		memcpy(model, m, sizeof m);
	} else {
		float t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
		if (api_get_vec(c, j, "translation", t, 3, 3, 0) < 0 ||
		    api_get_vec(c, j, "rotation", q, 4, 4, V_NONZERO) < 0 ||
		    api_get_vec(c, j, "scale", s, 3, 3, V_NOZERO_COMP) < 0)
			return -1;
		rnd_mat4_trs(model, t, q, s);
	}
	float det = rnd_mat4_det3(model);
	if (!(fabsf(det) > 0) || !isfinite(det)) {
		const char *key = mj ? "matrix" : "scale";
		return api_fail_at(c, key, "the transform is singular or out of range (determinant %g)", (double)det);
	}
	return 0;
}

/* ---- a model's orientation ---- */

/* `up`: the file's axis that points up. Its rotation to +Y, applied before the object's own
 * transform, keeps the frame right-handed, as Blender's glTF exporter turns Z-up into Y-up:
 *   "+y" identity; "-y" 180° about X: (x, y, z) -> (x, -y, -z);
 *   "+z" -90° about X: (x, y, z) -> (x, z, -y) (a Z-up file's front, -Y, faces +Z);
 *   "-z" +90° about X: (x, y, z) -> (x, -z, y);
 *   "+x" +90° about Z: (x, y, z) -> (-y, x, z); "-x" -90° about Z: (x, y, z) -> (y, -x, z). */
static const char *const UP_AXES[] = {"+y", "-y", "+z", "-z", "+x", "-x", "auto", NULL};
enum { UP_Z = 2, UP_AUTO = 6 };
static const signed char UP_COLUMNS[][3][3] = {   /* the images of the file's x, y, z axes */
	{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{1, 0, 0}, {0, -1, 0}, {0, 0, -1}},
	{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
	{{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
};

/* model = model · the rotation of UP_AXES[up]. */
static void apply_up(int up, float model[16])
{
	if (!up) return;
	float r[16], out[16];
	rnd_mat4_identity(r);
	for (int col = 0; col < 3; col++)
		for (int row = 0; row < 3; row++) r[col * 4 + row] = UP_COLUMNS[up][col][row];
	rnd_mat4_mul(out, model, r);
	memcpy(model, out, sizeof out);
}

/* ---- objects ---- */

static const char *const OBJECT_COMMON[] = {"shape", "name", "transform", "material", "cast_shadows",
                                            "receive_shadows", "double_sided", NULL};
static const char *const SHAPES[] = {"plane", "box", "sphere", "cylinder", "mesh", "model", NULL};
enum { SHAPE_MODEL = 5 };
static const char *const SHAPE_MEMBERS[][7] = {
	{"size", "placement", "margin", NULL},
	{"size", NULL},
	{"radius", "segments", NULL},
	{"radius", "height", "segments", NULL},
	{"positions", "indices", "normals", "uvs", NULL},
	{"data", "format", "path", "part", "up", "variant", NULL},
};
#define MAX_SEGMENTS 1000000

static int parse_mesh(struct pctx *c, json_t *j, struct rnd_object *o)
{
	void *pos = NULL, *idx = NULL, *nrm = NULL, *uv = NULL;
	size_t npos = 0, nidx = 0, nnrm = 0, nuv = 0;
	int rc = api_get_data(c, j, "positions", false, &pos, &npos);
	if (rc < 0) return -1;
	if (rc == 0) return api_fail_at(c, "positions", "positions is required for a mesh");
	if (npos % 3) return api_fail_at(c, "positions", "positions must hold 3 numbers per vertex (got %zu numbers)", npos);
	if (npos / 3 > UINT32_MAX) return api_fail_at(c, "positions", "positions has too many vertices");
	uint32_t nv = (uint32_t)(npos / 3);
	if ((rc = api_get_data(c, j, "indices", true, &idx, &nidx)) < 0) return -1;
	if (rc) {
		if (nidx % 3) return api_fail_at(c, "indices", "indices must hold 3 per triangle (got %zu)", nidx);
		if (nidx > UINT32_MAX) return api_fail_at(c, "indices", "indices has too many elements");
		const uint32_t *u = idx;
		for (size_t i = 0; i < nidx; i++)
			if (u[i] >= nv)
				return api_fail_at(c, "indices", "element %zu of indices (%u) is not below the vertex count %u",
				               i, u[i], nv);
		o->indices = u;
		o->index_count = (uint32_t)nidx;
	} else if (nv % 3) {
		return api_fail_at(c, "positions", "without indices, positions must hold whole triangles (%u vertices "
		               "is not a multiple of 3)", nv);
	}
	if ((rc = api_get_data(c, j, "normals", false, &nrm, &nnrm)) < 0) return -1;
	if (rc && nnrm != npos)
		return api_fail_at(c, "normals", "normals must have one xyz per vertex: %zu numbers for %u vertices (got %zu)",
		               npos, nv, nnrm);
	if ((rc = api_get_data(c, j, "uvs", false, &uv, &nuv)) < 0) return -1;
	if (rc && nuv != (size_t)nv * 2)
		return api_fail_at(c, "uvs", "uvs must have one uv pair per vertex: %zu numbers for %u vertices (got %zu)",
		               (size_t)nv * 2, nv, nuv);
	o->positions = pos;
	o->vertex_count = nv;
	o->normals = nnrm ? nrm : NULL;
	o->uvs = nuv ? uv : NULL;
	return 0;
}


/* A plane's `placement: "ground"` (and `margin`, default 3): placed under the other objects
 * once they are all known (api/ground.h), so it takes neither a transform nor a size. */
static int parse_placement(struct pctx *c, json_t *j)
{
	static const char *const placements[] = {"ground", NULL};
	static const struct range mr = {0, 1000, true, false};
	int pl = -1;
	float margin = 3;
	if (api_get_enum(c, j, "placement", placements, &pl) < 0 || api_get_float(c, j, "margin", &mr, &margin) < 0) return -1;
	if (pl < 0 && json_object_get(j, "margin")) return api_fail_at(c, "margin", "margin is only used with placement");
	if (pl < 0) return 0;
	if (json_object_get(j, "transform"))
		return api_fail_at(c, "transform", "a plane with placement \"ground\" places itself: it takes no transform");
	if (json_object_get(j, "size"))
		return api_fail_at(c, "size", "a plane with placement \"ground\" is sized by margin, not size");
	c->ground_margin[c->cur_object] = margin;
	return 0;
}

/* The object's material: a name from `materials`, an inline material, or the default one. */
static int object_material(struct pctx *c, json_t *j, struct rnd_object *o)
{
	json_t *m = json_object_get(j, "material");
	if (json_is_string(m)) {
		json_t *ix = c->mat_index ? json_object_get(c->mat_index, json_string_value(m)) : NULL;
		if (!ix)
			return api_fail_at(c, "material", "material \"%.64s\" is not defined in materials",
			               json_string_value(m));
		o->material = (uint32_t)json_integer_value(ix);
	} else if (m) {
		size_t old = api_ptr_push(c, "material");
		uint32_t mi = 0;
		int rc = json_is_object(m) ? api_add_material(c, &mi)
		         : api_fail(c, "material must be the name of a material or a material object, not %s", api_type_name(m));
		if (rc == 0) rc = api_parse_material(c, m, &c->mats[mi], "material");
		api_ptr_pop(c, old);
		if (rc < 0) return -1;
		o->material = mi;
	} else {
		if (c->default_mat == UINT32_MAX) {
			if (api_add_material(c, &c->default_mat) < 0) return -1;
			rnd_material_defaults(&c->mats[c->default_mat]);
		}
		o->material = c->default_mat;
	}
	return 0;
}

static int parse_object(struct pctx *c, json_t *j, struct rnd_object *o)
{
	if (api_require_object(c, j, "each entry of objects") < 0) return -1;
	json_t *sv = json_object_get(j, "shape");
	if (!sv) return api_fail_at(c, "shape", "shape is required (one of \"plane\", \"box\", \"sphere\", \"cylinder\", "
	                        "\"mesh\", \"model\")");
	int shape, up = 0;
	if (api_get_enum(c, j, "shape", SHAPES, &shape) < 0) return -1;
	char what[32];
	snprintf(what, sizeof what, "a %s object", SHAPES[shape]);
	if (api_check_members(c, j, OBJECT_COMMON, SHAPE_MEMBERS[shape], what) < 0) return -1;
	rnd_object_defaults(o);
	const char *name;
	if (api_get_string(c, j, "name", &name) < 0) return -1;
	switch (shape) {
	case 0: { /* plane */
		float sz[2] = {1, 1};
		if (api_get_vec(c, j, "size", sz, 2, 2, V_POS) < 0 || parse_placement(c, j) < 0) return -1;
		o->shape = RND_SHAPE_PLANE;
		o->size[0] = sz[0]; o->size[1] = 0; o->size[2] = sz[1];
		break;
	}
	case 1: /* box */
		o->shape = RND_SHAPE_BOX;
		o->size[0] = o->size[1] = o->size[2] = 1;
		if (api_get_vec(c, j, "size", o->size, 3, 3, V_POS) < 0) return -1;
		break;
	case 2: case 3: /* sphere, cylinder */
		o->shape = shape == 2 ? RND_SHAPE_SPHERE : RND_SHAPE_CYLINDER;
		o->radius = 1;
		o->height = 1;
		o->segments = 64;
		if (api_get_float(c, j, "radius", &R_POS, &o->radius) < 0 ||
		    (shape == 3 && api_get_float(c, j, "height", &R_POS, &o->height) < 0) ||
		    api_get_u32(c, j, "segments", 3, MAX_SEGMENTS, &o->segments) < 0)
			return -1;
		break;
	case 4:
		o->shape = RND_SHAPE_MESH;
		if (parse_mesh(c, j, o) < 0) return -1;
		break;
	default:
		/* An empty mesh until parse_root expands it into one object per mesh instance;
		 * `up` is checked before the import, which may take a while. */
		o->shape = RND_SHAPE_MESH;
		if (api_get_enum(c, j, "up", UP_AXES, &up) < 0 || api_parse_model(c, j) < 0) return -1;
		break;
	}
	json_t *t = json_object_get(j, "transform");
	if (t) {
		size_t old = api_ptr_push(c, "transform");
		int rc = parse_transform(c, t, o->model);
		api_ptr_pop(c, old);
		if (rc < 0) return -1;
	}
	if (up == UP_AUTO) c->up_auto[c->cur_object] = true;   /* expand_models decides, once the model is read */
	else apply_up(up, o->model);   /* under the object's transform */
	if (object_material(c, j, o) < 0) return -1;
	if (api_get_bool(c, j, "cast_shadows", &o->cast_shadows) < 0 ||
	    api_get_bool(c, j, "receive_shadows", &o->receive_shadows) < 0 ||
	    api_get_bool(c, j, "double_sided", &o->double_sided) < 0)
		return -1;
	return 0;
}

/* Adds the models' warnings (what of their materials is not drawn as the file says) to
 * c->warnings, each prefixed with its object's pointer. */
static int collect_warnings(struct pctx *c, struct api_model *const *models, const uint32_t *source, uint32_t nobj)
{
	for (uint32_t k = 0; k < nobj; k++) {
		uint32_t i = source[k];
		if ((k && source[k - 1] == i) || !models[i] || !models[i]->warnings || !models[i]->warnings[0]) continue;
		api_warn(c, "/objects/%u: %s", i, models[i]->warnings);
	}
	return 0;
}

/* Replaces every model object by one mesh object per instance of its model, under the
 * object's transform, with the model's materials (appended to the scene's) unless the object
 * names its own. Returns 0 or -1 (out of memory / too many objects). */
static int expand_models(struct pctx *c, json_t *objs, struct api_model *const *models, struct rnd_scene *sc)
{
	uint64_t nobj = 0, nmat = c->mat_count;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		nobj += models[i] ? models[i]->instance_count : 1;
		if (models[i] && !json_object_get(json_array_get(objs, i), "material")) nmat += models[i]->material_count;
	}
	if (nobj > UINT32_MAX / 2 || nmat > UINT32_MAX / 2) return api_fail(c, "the scene has too many objects");
	struct rnd_object *objects = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *objects);
	struct rnd_material *mats = api_arena_calloc(c->arena, nmat ? nmat : 1, sizeof *mats);
	uint32_t *source = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *source);
	if (!objects || !mats || !source) return api_fail(c, "out of memory");
	c->object_source = source;
	memcpy(mats, c->mats, c->mat_count * sizeof *mats);
	uint32_t no = 0, nm = c->mat_count;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct api_model *m = models[i];
		if (!m) {
			source[no] = i;
			objects[no++] = sc->objects[i];
			continue;
		}
		bool own = json_object_get(json_array_get(objs, i), "material") != NULL;
		uint32_t base = nm;
		float top[16];   /* the object's transform, and under it "auto"'s choice */
		memcpy(top, sc->objects[i].model, sizeof top);
		if (c->up_auto[i]) {
			double cy, cz;
			char axis = api_model_auto_up(m, &cy, &cz);
			if (axis == 'z') apply_up(UP_Z, top);
			api_warn(c, "/objects/%u: up \"auto\" chose +%c (surface flat on the lowest plane, facing down: y %.2f %%, "
			         "z %.2f %%)", i, axis, 100 * cy, 100 * cz);
		}
		if (!own) {
			memcpy(mats + nm, m->materials, m->material_count * sizeof *mats);
			nm += m->material_count;
		}
		for (uint32_t k = 0; k < m->instance_count; k++) {
			const struct api_model_instance *in = &m->instances[k];
			const struct api_model_mesh *me = &m->meshes[in->mesh];
			source[no] = i;
			struct rnd_object *o = &objects[no++];
			*o = sc->objects[i];   /* shadows, sidedness, material override */
			o->shape = RND_SHAPE_MESH;
			o->positions = me->positions;
			o->vertex_count = me->vertex_count;
			o->indices = me->indices;
			o->index_count = me->index_count;
			o->normals = me->normals;
			o->uvs = me->uvs;
			o->uvs1 = me->uvs1;
			o->colors = me->colors;
			o->tangents = me->tangents;
			/* The level for this request's size (api/model_levels.h): positions, normals,
			 * uvs (both sets), vertex colours and tangents, where the mesh has them. */
			o->lods = api_model_mesh_lods(m, in->mesh, c->lim->output_side, &o->lod_count);
			o->caster = me->caster;   /* the environment's maps' level (renderer/caster_level.h) */
			o->closed = me->closed;
			o->mesh_bounds = me->vertex_count ? me->bounds : NULL;
			/* glTF doubleSided: false culls back faces (the object can only add sidedness). */
			o->double_sided = o->double_sided && !me->single_sided;
			rnd_mat4_mul(o->model, top, in->model);
			if (!own) o->material = base + me->material;
		}
	}
	c->mats = mats;
	c->mat_count = c->mat_cap = nm;
	sc->objects = objects;
	sc->object_count = no;
	return collect_warnings(c, models, source, no);
}


/* Places the planes with placement "ground" under the other objects (models expanded). */
static int place_ground(struct pctx *c, struct rnd_scene *sc)
{
	float *margin = api_arena_calloc(c->arena, sc->object_count ? sc->object_count : 1, sizeof *margin);
	if (!margin) return api_fail(c, "out of memory");
	for (uint32_t i = 0; i < sc->object_count; i++)
		margin[i] = c->ground_margin[c->object_source ? c->object_source[i] : i];
	api_ground_place((struct rnd_object *)sc->objects, sc->object_count, c->mats, margin);
	return 0;
}


/* Parses every object (the pointer is /objects/i), counting triangles against the server's
 * limit, then expands models and places ground planes. */
int api_parse_objects(struct pctx *c, json_t *objs, struct api_scene *s)
{
	struct rnd_scene *sc = &s->scene;
	size_t nobj = json_array_size(objs);
	struct rnd_object *objects = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *objects);
	c->ground_margin = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *c->ground_margin);
	c->up_auto = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *c->up_auto);
	struct api_model **models = api_arena_calloc(c->arena, nobj ? nobj : 1, sizeof *models);
	if (!objects || !c->ground_margin || !c->up_auto || !models) return api_fail(c, "out of memory");
	size_t old = api_ptr_push(c, "objects");
	uint64_t total = 0;
	int rc = 0;
	for (size_t i = 0; i < nobj; i++) {
		size_t o2 = api_ptr_index(c, i);
		c->cur_model = NULL;
		c->cur_object = i;
		rc = parse_object(c, json_array_get(objs, i), &objects[i]);
		models[i] = c->cur_model;
		if (!rc) {
			uint64_t t = models[i] ? models[i]->triangles : rnd_object_triangle_count(&objects[i]);
			total += t;
			s->triangles = total;
			uint64_t max = c->lim->max_triangles;
			if (max && t > max)
				api_defer(c, false, (objects[i].shape == RND_SHAPE_SPHERE ||
				                 objects[i].shape == RND_SHAPE_CYLINDER) ? "segments" : NULL,
				      "this object has %llu triangles, over this server's limit of %llu",
				      (unsigned long long)t, (unsigned long long)max);
			else if (max && total > max)
				api_defer(c, false, NULL, "the scene has more than %llu triangles (this server's limit) "
				      "with this object", (unsigned long long)max);
		}
		api_ptr_pop(c, o2);
		if (rc) break;
	}
	api_ptr_pop(c, old);
	if (rc) return -1;
	sc->objects = objects;
	sc->object_count = (uint32_t)nobj;
	if (c->models && expand_models(c, objs, models, sc) < 0) return -1;
	return place_ground(c, sc);
}
