/*
 * api/preset — named scene defaults merged under a document (see preset.h).
 */
#include <string.h>
#include "preset.h"

/* Thumbnail: 512², a three-quarter view from above fitted to the objects (planes and shadow
 * catchers left out), white background, lit by the built-in studio environment (renderer/
 * env_studio.c: a small bright key high on the camera's left, fill, rim and a dim dome) with its
 * shadows (12 directions: the soft key shadow and the contact darkening of the whole sky), and a
 * ground shadow catcher three times the objects' size that darkens the background (or writes
 * alpha when the output is transparent). No sun: the studio's key casts the shadow (a sun's
 * PCSS map and lookups cost a thumbnail's main pass about what the environment's shadows do,
 * docs/performance.md), and metals have the studio to reflect. */
static const char THUMBNAIL[] =
	"{\"width\": 512, \"height\": 512,"
	" \"camera\": {\"fit\": \"objects\", \"direction\": [-1, -0.7, -1.3], \"fov_y\": 30, \"margin\": 0.08},"
	" \"environment\": {\"background\": [1, 1, 1], \"map\": {\"preset\": \"studio\"}},"
	" \"objects\": [{\"shape\": \"plane\", \"placement\": \"ground\", \"margin\": 3,"
	"   \"material\": {\"shadow_catcher\": true}}],"
	" \"output\": {\"format\": \"png\"}}";

static const struct {
	const char *name, *text;
} PRESETS[] = {
	{"thumbnail", THUMBNAIL},
};

const char *api_preset_text(const char *name)
{
	for (size_t i = 0; name && i < sizeof PRESETS / sizeof PRESETS[0]; i++)
		if (!strcmp(PRESETS[i].name, name)) return PRESETS[i].text;
	return NULL;
}

/* RFC 7396: patch onto target, in place. 0, or -1 out of memory. */
static int merge_patch(json_t *target, json_t *patch)
{
	const char *key;
	json_t *v;
	json_object_foreach(patch, key, v) {
		json_t *t = json_object_get(target, key);
		if (json_is_null(v)) {
			json_object_del(target, key);
		} else if (json_is_object(v) && json_is_object(t)) {
			if (merge_patch(t, v) < 0) return -1;
		} else if (json_object_set(target, key, v) < 0) {
			return -1;
		}
	}
	return 0;
}

static bool has_ground(json_t *objs)
{
	size_t i;
	json_t *o;
	json_array_foreach(objs, i, o) {
		json_t *pl = json_object_get(o, "placement");
		if (json_is_string(pl) && !strcmp(json_string_value(pl), "ground")) return true;
	}
	return false;
}

/* The exceptions of preset.h, applied to the merged copy m from preset pre and document doc. */
static int merge_exceptions(json_t *m, json_t *pre, json_t *doc)
{
	json_t *objs = json_object_get(doc, "objects"), *cam = json_object_get(doc, "camera");
	if (json_is_array(objs)) {
		json_t *all = json_copy(objs);
		if (!all) return -1;
		if (!has_ground(objs) && json_array_extend(all, json_object_get(pre, "objects")) < 0) {
			json_decref(all);
			return -1;
		}
		if (json_object_set_new(m, "objects", all) < 0) return -1;
	}
	if (json_is_object(cam) && (json_object_get(cam, "position") || json_object_get(cam, "target")) &&
	    json_object_set(m, "camera", cam) < 0)
		return -1;
	return 0;
}

int api_preset_apply(json_t **root, struct api_problem *p)
{
	json_t *doc = *root, *name = json_is_object(doc) ? json_object_get(doc, "preset") : NULL;
	if (!name) return 0;
	const char *text = json_is_string(name) ? api_preset_text(json_string_value(name)) : NULL;
	if (!json_is_string(name)) {
		api_problem_set(p, 400, "/preset", "preset must be a string naming a preset (\"thumbnail\")");
		return -1;
	}
	if (!text) {
		api_problem_set(p, 400, "/preset", "unknown preset \"%.64s\" (known: \"thumbnail\")", json_string_value(name));
		return -1;
	}
	json_t *m = json_loads(text, 0, NULL), *pre = json_deep_copy(m);
	if (!m || !pre || merge_patch(m, doc) < 0 || merge_exceptions(m, pre, doc) < 0) {
		json_decref(m);
		json_decref(pre);
		api_problem_set(p, 500, "", "out of memory applying the preset");
		return -1;
	}
	json_object_del(m, "preset");
	json_decref(pre);
	json_decref(doc);
	*root = m;
	return 0;
}
