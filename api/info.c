/*
 * api/info — the /v1/info document (umbrad), written with jansson like every JSON answer: the
 * server describes itself through struct api_info (api.h) and never assembles JSON by hand.
 * Pure; thread-safe.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include "api.h"

static int put(json_t *o, const char *key, json_t *v)
{
	return json_object_set_new(o, key, v);
}

static json_t *strings(const char *const *list)
{
	json_t *a = json_array();
	for (; a && *list; list++)
		json_array_append_new(a, json_string(*list));
	return a;
}

static json_t *limits_object(const struct api_info *in)
{
	json_t *l = json_object();
	if (!l) return NULL;
	int bad = put(l, "max_body", json_integer((json_int_t)in->max_body)) |
	          put(l, "max_pixels", json_integer((json_int_t)in->limits.max_pixels)) |
	          put(l, "max_triangles", json_integer((json_int_t)in->limits.max_triangles)) |
	          put(l, "max_lights", json_integer(in->limits.max_lights)) |
	          put(l, "max_shadow_resolution", json_integer(in->limits.max_shadow_resolution)) |
	          put(l, "max_dimension", json_integer(in->max_dimension)) |
	          put(l, "device_max_shadow_resolution", json_integer(in->device_max_shadow_resolution)) |
	          put(l, "deadline_ms", json_integer(in->deadline_ms)) |
	          put(l, "queue", json_integer(in->queue)) |
	          put(l, "workers", json_integer(in->workers)) |
	          put(l, "max_memory", json_integer((json_int_t)in->max_memory)) |
	          put(l, "device_max_allocation", json_integer((json_int_t)in->device_max_allocation)) |
	          put(l, "import_timeout_ms", json_integer(in->limits.import_timeout_ms)) |
	          put(l, "import_memory", json_integer((json_int_t)in->limits.import_memory)) |
	          put(l, "max_textures", json_integer(in->max_textures)) |
	          put(l, "device_max_textures", json_integer(in->device_max_textures)) |
	          put(l, "max_rss", json_integer((json_int_t)in->max_rss));
	if (bad) {
		json_decref(l);
		return NULL;
	}
	return l;
}

char *api_info_json(const struct api_info *in, size_t *len)
{
	static const char *const filters[] = {"hard", "pcf", "pcss", "vsm", "evsm", NULL};
	static const char *const formats[] = {"png", "exr", "webp", "avif", NULL};
	static const char *const media[] = {"image/png", "image/x-exr", "image/webp", "image/avif", NULL};
	static const char *const priorities[] = {"interactive", "bulk", NULL};
	char vk[32];
	snprintf(vk, sizeof vk, "%u.%u.%u", (in->vulkan_api >> 22) & 0x7fu, (in->vulkan_api >> 12) & 0x3ffu,
	         in->vulkan_api & 0xfffu);
	json_t *o = json_object();
	if (!o) return NULL;
	int bad = put(o, "name", json_string("umbrad")) | put(o, "version", json_string(in->version)) |
	          put(o, "contract", json_string("scene-v1")) | put(o, "device", json_string(in->device)) |
	          put(o, "driver", json_string(in->driver)) | put(o, "driver_info", json_string(in->driver_info)) |
	          put(o, "vulkan_api", json_string(vk)) | put(o, "cpu", json_boolean(in->cpu)) |
	          put(o, "limits", limits_object(in)) | put(o, "filters", strings(filters)) |
	          put(o, "formats", strings(formats)) | put(o, "media_types", strings(media)) |
	          put(o, "priorities", strings(priorities)) | put(o, "rss", json_integer((json_int_t)in->rss));
	char *s = bad ? NULL : json_dumps(o, JSON_COMPACT | JSON_PRESERVE_ORDER);
	json_decref(o);
	if (!s) return NULL;
	/* One line, newline-terminated, as the other text answers; malloc'd for the caller. */
	size_t n = strlen(s);
	char *out = malloc(n + 2);
	if (out) {
		memcpy(out, s, n);
		out[n] = '\n';
		out[n + 1] = 0;
		if (len) *len = n + 1;
	}
	free(s);
	return out;
}
