/*
 * api/plan_json — the render plan as the JSON document of `explain` (api/explain.schema.json):
 * `umbra-render --explain`, `POST /v1/explain`, and with `?explain=1` on a render the same plan
 * with what each step measured (EXPLAIN ANALYZE). The renderer says what it decided
 * (umbra/rnd_plan.h); this writes it down, naming each object and light by its member in the
 * request (a model's objects all name the model). Pure; thread-safe.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include "api.h"
#include "umbra/rnd_plan.h"

static int put(json_t *o, const char *key, json_t *v)
{
	return json_object_set_new(o, key, v);
}

static json_t *vec3(const float v[3])
{
	return json_pack("[fff]", (double)v[0], (double)v[1], (double)v[2]);
}

/* [[min], [max]], null when empty. */
static json_t *box(const struct rnd_aabb *b)
{
	return rnd_aabb_is_empty(b) ? json_null() : json_pack("[oo]", vec3(b->min), vec3(b->max));
}

static json_t *ms(double v)
{
	return json_real((double)(int64_t)(v * 1000.0 + 0.5) / 1000.0);
}

static json_t *image_object(const struct api_scene *s, const struct rnd_plan_info *in)
{
	return json_pack("{s:i, s:i, s:i, s:i, s:i, s:s}", "width", (json_int_t)in->width, "height", (json_int_t)in->height,
	                 "views", (json_int_t)in->views, "columns", (json_int_t)in->columns, "rows", (json_int_t)in->rows,
	                 "format", api_format_name(s->format));
}

static json_t *memory_object(const struct rnd_estimate *e)
{
	return json_pack("{s:I, s:I, s:I, s:I}", "device_bytes", (json_int_t)e->device_bytes, "host_bytes",
	                 (json_int_t)e->host_bytes, "largest_allocation", (json_int_t)e->largest_allocation, "readback_bytes",
	                 (json_int_t)e->readback_bytes);
}

static json_t *totals_object(const struct rnd_plan_info *in)
{
	return json_pack("{s:i, s:i, s:I, s:I, s:I, s:i, s:I, s:I, s:o}", "shadow_maps_drawn", (json_int_t)in->maps_drawn,
	                 "shadow_maps_cached", (json_int_t)in->maps_cached, "shadow_texels", (json_int_t)in->texels_drawn,
	                 "shadow_triangles", (json_int_t)in->shadow_triangles, "camera_triangles",
	                 (json_int_t)in->camera_triangles, "sphere_proxies", (json_int_t)in->sphere_proxies, "vertices",
	                 (json_int_t)in->vertices, "indices", (json_int_t)in->indices, "estimate_ms", ms(in->estimate_ms));
}

static json_t *camera_object(const struct rnd_plan_view_info *v)
{
	json_t *c = json_pack("{s:o, s:o, s:o, s:o, s:o, s:s}", "position", vec3(v->position), "forward", vec3(v->forward),
	                      "up", vec3(v->up), "near", json_real(v->znear), "far", json_real(v->zfar), "projection",
	                      v->orthographic ? "orthographic" : "perspective");
	if (c && v->orthographic) put(c, "height", json_real(v->ortho_height));
	else if (c) put(c, "fov_y_degrees", json_real(v->fov_y * 180.0 / 3.14159265358979323846));
	return c;
}

static json_t *view_object(const struct rnd_plan *plan, uint32_t k)
{
	struct rnd_plan_view_info v;
	rnd_plan_view(plan, k, &v);
	json_t *o = json_pack("{s:i, s:o, s:i, s:i, s:I, s:I, s:I, s:b, s:{s:b, s:s}, s:{s:o, s:o, s:o, s:o}}", "view",
	                      (json_int_t)k, "camera", camera_object(&v), "shadow_views", (json_int_t)v.shadow_views,
	                      "shadow_maps_drawn", (json_int_t)v.maps_drawn, "shadow_texels", (json_int_t)v.texels_drawn,
	                      "shadow_triangles", (json_int_t)v.shadow_triangles, "camera_triangles",
	                      (json_int_t)v.camera_triangles, "contact_shadows", v.contact, "visibility_pass", "on",
	                      v.visibility, "why", v.visibility_why, "estimate_ms", "shadows", ms(v.shadow_estimate_ms),
	                      "per_row", ms(v.row_ms), "per_band", ms(v.band_ms), "main", ms(v.main_estimate_ms));
	if (o) put(o, "environment_pass", json_boolean(v.env_pass));
	if (o) put(o, "pixel_shading", json_pack("{s:b, s:s}", "on", v.pixel_shading, "why", v.pixel_shading_why));
	if (o && v.analyzed)
		put(o, "actual_ms", json_pack("{s:o, s:o, s:i}", "shadows", ms(v.shadow_ms), "main", ms(v.main_ms), "bands",
		                              (json_int_t)v.bands));
	return o;
}

static json_t *map_object(const struct rnd_plan *plan, uint32_t k)
{
	struct rnd_plan_map_info m;
	rnd_plan_map(plan, k, &m);
	char ptr[32], key[24];
	if (m.environment >= 0) snprintf(ptr, sizeof ptr, "/environment/shadow_directions");
	else snprintf(ptr, sizeof ptr, "/lights/%u", m.light);
	snprintf(key, sizeof key, "%016llx", (unsigned long long)m.key);
	json_t *o = json_pack("{s:i, s:s, s:s, s:s, s:i, s:i, s:i, s:s, s:s, s:s, s:i, s:b, s:s, s:s, s:o, s:i, s:I, s:I, s:o}",
	                      "light", (json_int_t)m.light, "pointer", ptr, "type", m.light_type, "kind", m.kind, "tiles",
	                      (json_int_t)m.tiles, "resolution", (json_int_t)m.resolution, "asked", (json_int_t)m.asked,
	                      "size", m.size, "fitted", m.fitted, "filter", m.filter, "pcf_radius", (json_int_t)m.pcf_radius,
	                      "pcss_bounds", m.pcss_bounds, "state", m.state, "why", m.why,
	                      "key", m.key ? json_string(key) : json_null(), "drawn_in_views", (json_int_t)m.drawn_views,
	                      "texels", (json_int_t)m.texels, "triangles", (json_int_t)m.triangles, "estimate_ms",
	                      ms(m.estimate_ms));
	if (o && m.analyzed) put(o, "actual", json_pack("{s:b}", "cached", m.hit));
	if (o && m.environment >= 0)
		put(o, "environment", json_pack("{s:i, s:o, s:o}", "direction_index", (json_int_t)m.environment, "direction",
		                                vec3(m.direction), "share", json_real(m.share)));
	return o;
}

static json_t *object_object(const struct api_scene *s, const struct rnd_plan *plan, uint32_t i)
{
	struct rnd_plan_object_info b;
	rnd_plan_object(plan, i, &b);
	char ptr[32];
	snprintf(ptr, sizeof ptr, "/objects/%u", s->object_source_ ? s->object_source_[i] : i);
	json_t *o = json_pack("{s:i, s:s, s:s, s:s, s:I, s:I, s:b, s:b, s:s, s:b}", "object", (json_int_t)i, "pointer", ptr,
	                      "shape", b.shape, "detail", b.detail, "triangles", (json_int_t)b.triangles, "camera_triangles",
	                      (json_int_t)b.camera_triangles, "proxy", b.proxy, "casts", b.casts, "why", b.cast_why,
	                      "in_casters_box", b.in_casters_box);
	if (o && b.asked) {
		put(o, "segments", json_integer(b.segments));
		put(o, "asked", json_integer(b.asked));
	}
	if (o && b.levels) {
		put(o, "level", json_integer(b.level));
		put(o, "levels", json_integer(b.levels));
	}
	if (o && b.caster_triangles)
		put(o, "caster_level", json_pack("{s:I, s:f, s:i}", "triangles", (json_int_t)b.caster_triangles, "error",
		                                 (double)b.caster_error, "maps", (json_int_t)b.caster_maps));
	return o;
}

static json_t *pass_object(uint32_t step, const struct rnd_plan_pass_info *p)
{
	json_t *o = json_pack("{s:i, s:s, s:o, s:I, s:o, s:s}", "step", (json_int_t)step, "pass", p->pass, "view",
	                      p->view < 0 ? json_null() : json_integer(p->view), "triangles", (json_int_t)p->triangles,
	                      "estimate_ms", ms(p->estimate_ms), "note", p->note);
	if (o && p->map >= 0) {
		put(o, "map", json_integer(p->map));
		put(o, "light", json_integer(p->light));
		put(o, "tile", json_integer(p->tile));
		put(o, "resolution", json_integer(p->resolution));
		put(o, "texels", json_integer((json_int_t)p->texels));
	}
	return o;
}

/* What the render measured (EXPLAIN ANALYZE), with the caller's own stages where it has them. */
static json_t *actual_object(const struct rnd_plan_info *in, const struct api_plan_times *t)
{
	const struct rnd_timings *a = &in->actual;
	json_t *o = json_pack("{s:o, s:o, s:o, s:o, s:i, s:i, s:i, s:i, s:I, s:I, s:I, s:i, s:i, s:i}", "upload_ms", ms(a->upload_ms),
	                      "shadow_ms", ms(a->shadow_ms), "main_ms", ms(a->main_ms), "readback_ms", ms(a->readback_ms),
	                      "submits", (json_int_t)a->submits, "shadow_parts", (json_int_t)a->shadow_parts,
	                      "shadow_maps_drawn", (json_int_t)a->shadow_maps_rendered, "shadow_maps_reused",
	                      (json_int_t)a->shadow_maps_reused, "shadow_texels", (json_int_t)a->shadow_texels,
	                      "shadow_triangles", (json_int_t)a->shadow_triangles, "camera_triangles",
	                      (json_int_t)a->camera_triangles, "visibility_views",
	                      (json_int_t)a->visibility_views, "pixel_shaded_views", (json_int_t)a->pixel_shaded_views,
	                      "sphere_proxies", (json_int_t)a->sphere_proxies);
	if (o) put(o, "shadow_submits", json_integer((json_int_t)a->shadow_submits));
	if (o) put(o, "env_passes_reused", json_integer((json_int_t)a->env_passes_reused));
	if (o && t && t->parse_ms >= 0) put(o, "parse_ms", ms(t->parse_ms));
	if (o && t && t->encode_ms >= 0) put(o, "encode_ms", ms(t->encode_ms));
	if (o && t && t->total_ms >= 0) put(o, "total_ms", ms(t->total_ms));
	return o;
}

/* Appends n objects made by make(i) to a new array. */
static json_t *list(uint32_t n, json_t *(*make)(const struct api_scene *, const struct rnd_plan *, uint32_t),
                    const struct api_scene *s, const struct rnd_plan *plan)
{
	json_t *a = json_array();
	for (uint32_t i = 0; a && i < n; i++)
		if (json_array_append_new(a, make(s, plan, i)) != 0) {
			json_decref(a);
			return NULL;
		}
	return a;
}

static json_t *view_item(const struct api_scene *s, const struct rnd_plan *plan, uint32_t i)
{
	(void)s;
	return view_object(plan, i);
}

static json_t *map_item(const struct api_scene *s, const struct rnd_plan *plan, uint32_t i)
{
	(void)s;
	return map_object(plan, i);
}

static json_t *passes_array(const struct rnd_plan *plan, uint32_t n)
{
	struct rnd_plan_pass_info *p = calloc(n ? n : 1, sizeof *p);
	json_t *a = p ? json_array() : NULL;
	rnd_plan_passes(plan, p, n);
	for (uint32_t i = 0; a && i < n; i++)
		if (json_array_append_new(a, pass_object(i, &p[i])) != 0) {
			json_decref(a);
			a = NULL;
		}
	free(p);
	return a;
}

char *api_plan_json(const struct api_scene *s, const struct rnd_plan *plan, const struct api_plan_times *t, size_t *len)
{
	struct rnd_plan_info in;
	rnd_plan_info(plan, &in);
	json_t *doc = json_object();
	int bad = !doc;
	bad = bad || put(doc, "umbra_plan", json_integer(1)) || put(doc, "analyzed", json_boolean(in.analyzed)) ||
	      put(doc, "planning_ms", ms(in.plan_ms)) || put(doc, "image", image_object(s, &in)) ||
	      put(doc, "memory", memory_object(&in.estimate)) || put(doc, "totals", totals_object(&in)) ||
	      put(doc, "bounds", json_pack("{s:o, s:o}", "scene", box(&in.bounds), "casters", box(&in.casters))) ||
	      put(doc, "environment", json_pack("{s:i, s:i, s:b}", "shadow_directions", (json_int_t)in.env_directions,
	                                        "weighed", (json_int_t)in.env_weighed, "ground", in.env_ground)) ||
	      put(doc, "views", list(in.views, view_item, s, plan)) || put(doc, "shadow_maps", list(in.maps, map_item, s, plan)) ||
	      put(doc, "objects", list(in.objects, object_object, s, plan)) || put(doc, "passes", passes_array(plan, in.passes));
	if (!bad && in.analyzed) bad = put(doc, "actual", actual_object(&in, t));
	char *out = bad ? NULL : json_dumps(doc, JSON_COMPACT | JSON_REAL_PRECISION(7));
	json_decref(doc);
	if (out && len) *len = strlen(out);
	return out;
}
