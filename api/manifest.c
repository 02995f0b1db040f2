/*
 * api/manifest — one line of a JSON-lines render manifest (umbra-render --manifest), parsed
 * here because JSON stays inside api/.
 *
 * A line is {"scene": "a.json" | {scene document}, "output": "a.png"} ("output" optional; its
 * extension picks the format). Blank lines are for the caller to skip.
 */
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include "api.h"

void api_manifest_entry_release(struct api_manifest_entry *e)
{
	if (!e) return;
	free(e->scene_path);
	free(e->scene_json);
	free(e->output);
	memset(e, 0, sizeof *e);
}

enum api_result api_manifest_line(const char *line, size_t len, struct api_manifest_entry *e, struct api_problem *p)
{
	memset(e, 0, sizeof *e);
	json_error_t je;
	json_t *j = json_loadb(line, len, JSON_REJECT_DUPLICATES, &je);
	if (!j) return api_problem_set(p, 400, "", "malformed JSON at column %d: %s", je.column, je.text);
	enum api_result r = API_OK;
	const char *key;
	json_t *v;
	json_object_foreach(j, key, v) {
		if (strcmp(key, "scene") && strcmp(key, "output")) {
			r = api_problem_set(p, 400, "", "unknown member \"%.64s\" (a line has scene and output)", key);
			goto out;
		}
	}
	json_t *sc = json_object_get(j, "scene"), *out = json_object_get(j, "output");
	if (!json_is_object(j) || !sc) {
		r = api_problem_set(p, 400, "/scene", "a manifest line is an object with scene (a path or a document)");
	} else if (out && (!json_is_string(out) || !json_string_length(out) || strchr(json_string_value(out), '/'))) {
		r = api_problem_set(p, 400, "/output", "output must be a file name (no \"/\") inside the output directory");
	} else if (json_is_string(sc) && json_string_length(sc)) {
		e->scene_path = strdup(json_string_value(sc));
		if (!e->scene_path) r = api_problem_set(p, 500, "", "out of memory");
	} else if (json_is_object(sc)) {
		e->scene_json = json_dumps(sc, JSON_COMPACT);
		if (!e->scene_json) r = api_problem_set(p, 500, "", "out of memory");
	} else {
		r = api_problem_set(p, 400, "/scene", "scene must be a path or a scene document");
	}
	if (r == API_OK && out && !(e->output = strdup(json_string_value(out))))
		r = api_problem_set(p, 500, "", "out of memory");
out:
	if (r != API_OK) api_manifest_entry_release(e);
	json_decref(j);
	return r;
}

void api_report_entry_release(struct api_report_entry *e)
{
	if (!e) return;
	free(e->file);
	free(e->output);
	free(e->status);
	free(e->hash);
	memset(e, 0, sizeof *e);
}

static char *dup_member(json_t *o, const char *key)
{
	json_t *v = json_object_get(o, key);
	return json_is_string(v) ? strdup(json_string_value(v)) : NULL;
}

enum api_result api_report_line(const char *line, size_t len, struct api_report_entry *e, struct api_problem *p)
{
	memset(e, 0, sizeof *e);
	json_error_t je;
	json_t *j = json_loadb(line, len, 0, &je);
	if (!j) return api_problem_set(p, 400, "", "malformed JSON at column %d: %s", je.column, je.text);
	enum api_result r = API_OK;
	e->file = dup_member(j, "file");
	e->status = dup_member(j, "status");
	e->output = dup_member(j, "output");
	e->hash = dup_member(j, "hash");
	if (!e->file || !e->status) {
		r = api_problem_set(p, 400, "", "a report line has file and status");
		api_report_entry_release(e);
	}
	json_decref(j);
	return r;
}

char *api_scene_doc_set_format(const char *doc, size_t len, enum api_format f, size_t *out_len)
{
	json_t *j = json_loadb(doc, len, 0, NULL);
	if (!json_is_object(j)) {
		json_decref(j);
		return NULL;
	}
	json_t *out = json_object_get(j, "output");
	if (out && !json_is_object(out)) {   /* the daemon's 400 at /output says what is wrong */
		json_decref(j);
		return NULL;
	}
	if (!out) json_object_set_new(j, "output", out = json_object());
	json_object_set_new(out, "format", json_string(api_format_name(f)));
	char *s = json_dumps(j, JSON_COMPACT | JSON_PRESERVE_ORDER);
	json_decref(j);
	if (s) *out_len = strlen(s);
	return s;
}
