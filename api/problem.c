/*
 * api/problem — RFC 9457 problem details: one type URI and title per HTTP status, the
 * application/problem+json document, and the one-line form the CLI prints.
 * Also the resource-limit defaults and MIME types, which belong to no other module.
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <jansson.h>
#include "api.h"

#define PROBLEM_BASE "https://umbra.dev/problems/"

static const struct {
	int status;
	const char *type;
	const char *title;
} problem_types[] = {
	{400, "invalid-scene", "Invalid scene"},
	{403, "origin-not-allowed", "Cross-origin request not allowed"},
	{404, "not-found", "Not found"},
	{405, "method-not-allowed", "Method not allowed"},
	{406, "not-acceptable", "Not acceptable"},
	{408, "request-timeout", "Request timeout"},
	{412, "precondition-failed", "Precondition failed"},
	{413, "body-too-large", "Request body too large"},
	{415, "unsupported-media-type", "Unsupported media type"},
	{421, "host-not-allowed", "Host not allowed"},
	{422, "limit-exceeded", "Resource limit exceeded"},
	{500, "internal-error", "Internal error"},
	{503, "unavailable", "Service unavailable"},
	{504, "deadline-exceeded", "Render deadline exceeded"},
};

static void copy_str(char *dst, size_t size, const char *src)
{
	snprintf(dst, size, "%s", src ? src : "");
}

enum api_result api_problem_set(struct api_problem *p, int status, const char *pointer, const char *fmt, ...)
{
	if (!p) return API_ERR;
	const char *type = NULL, *title = NULL;
	for (size_t i = 0; i < sizeof problem_types / sizeof problem_types[0]; i++) {
		if (problem_types[i].status == status) {
			type = problem_types[i].type;
			title = problem_types[i].title;
			break;
		}
	}
	p->status = status;
	if (type) {
		snprintf(p->type, sizeof p->type, PROBLEM_BASE "%s", type);
		copy_str(p->title, sizeof p->title, title);
	} else {
		copy_str(p->type, sizeof p->type, "about:blank");
		copy_str(p->title, sizeof p->title, status >= 500 ? "Server error" : "Request error");
	}
	copy_str(p->pointer, sizeof p->pointer, pointer);
	p->detail[0] = '\0';
	if (fmt) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(p->detail, sizeof p->detail, fmt, ap);
		va_end(ap);
	}
	return API_ERR;
}

char *api_problem_json(const struct api_problem *p)
{
	if (!p) return NULL;
	json_t *o = json_object();
	if (!o) return NULL;
	/* jansson rejects invalid UTF-8; a detail or pointer truncated mid-character must still
	 * produce a document, so each string falls back to an ASCII-only copy. */
	const char *keys[] = {"type", "title", "detail", "pointer"};
	const char *vals[] = {p->type, p->title, p->detail, p->pointer};
	for (int i = 0; i < 4; i++) {
		json_t *s = json_string(vals[i]);
		if (!s) {
			char ascii[sizeof p->detail];
			size_t n = 0;
			for (const char *c = vals[i]; *c && n + 1 < sizeof ascii; c++)
				ascii[n++] = (unsigned char)*c < 0x80 ? *c : '?';
			ascii[n] = 0;
			s = json_string(ascii);
		}
		if (i == 2) json_object_set_new(o, "status", json_integer(p->status));
		json_object_set_new(o, keys[i], s);
	}
	char *s = json_dumps(o, JSON_COMPACT | JSON_PRESERVE_ORDER);
	json_decref(o);
	return s;
}

void api_problem_format(const struct api_problem *p, char *buf, size_t size)
{
	if (!buf || !size) return;
	if (!p) { buf[0] = 0; return; }
	if (p->pointer[0])
		snprintf(buf, size, "%d %s: %s: %s", p->status, p->title, p->pointer, p->detail);
	else
		snprintf(buf, size, "%d %s: %s", p->status, p->title, p->detail);
}

void api_limits_defaults(struct api_limits *l)
{
	if (!l) return;
	memset(l, 0, sizeof *l);   /* output_side, the gates: none */
	l->max_pixels = 16777216;
	l->max_triangles = 20000000;
	l->max_lights = 64;
	l->max_shadow_resolution = 8192;
	l->import_timeout_ms = 10000;
	l->import_memory = 2ull << 30;
	l->max_textures = RND_DEFAULT_MAX_TEXTURES;
}

static const char *const FORMAT_MIME[API_FORMAT_COUNT] = {"image/png", "image/x-exr", "image/webp", "image/avif"};
static const char *const FORMAT_NAME[API_FORMAT_COUNT] = {"png", "exr", "webp", "avif"};

const char *api_format_mime(enum api_format f)
{
	return (unsigned)f < API_FORMAT_COUNT ? FORMAT_MIME[f] : FORMAT_MIME[API_FORMAT_PNG];
}

const char *api_format_name(enum api_format f)
{
	return (unsigned)f < API_FORMAT_COUNT ? FORMAT_NAME[f] : FORMAT_NAME[API_FORMAT_PNG];
}

const char *api_format_label(enum api_format f)
{
	static const char *const label[API_FORMAT_COUNT] = {"a PNG", "an EXR", "a WebP", "an AVIF"};
	return (unsigned)f < API_FORMAT_COUNT ? label[f] : label[API_FORMAT_PNG];
}

bool api_format_lossy(enum api_format f)
{
	return f == API_FORMAT_WEBP || f == API_FORMAT_AVIF;
}

uint32_t api_format_max_side(enum api_format f)
{
	return f == API_FORMAT_WEBP ? API_WEBP_MAX_SIDE : f == API_FORMAT_AVIF ? API_AVIF_MAX_SIDE : 0;
}

bool api_format_from_name(const char *name, enum api_format *f)
{
	const char *dot = name ? strrchr(name, '.') : NULL;
	if (!dot || strchr(dot, '/')) return false;
	for (int k = API_FORMAT_PNG; k < API_FORMAT_COUNT; k++)
		if (!strcasecmp(dot + 1, api_format_name((enum api_format)k))) {
			*f = (enum api_format)k;
			return true;
		}
	return false;
}

enum api_result api_problem_from_render(struct api_problem *p, const struct api_scene *s, const struct rnd_error *e,
                                        int status)
{
	char ptr[64] = "";
	uint32_t i = e->at_index;
	switch (e->at) {
	case RND_AT_NONE: break;
	case RND_AT_SIZE:
		snprintf(ptr, sizeof ptr, "/%s", s && s->scene.height > s->scene.width ? "height" : "width");
		break;
	case RND_AT_VIEWS: snprintf(ptr, sizeof ptr, "/%s", s && s->views_key_ ? s->views_key_ : "width"); break;
	case RND_AT_AOVS: snprintf(ptr, sizeof ptr, "/output/aovs"); break;
	case RND_AT_LIGHTS: snprintf(ptr, sizeof ptr, "/lights"); break;
	case RND_AT_LIGHT: snprintf(ptr, sizeof ptr, "/lights/%u", i); break;
	case RND_AT_OBJECTS: snprintf(ptr, sizeof ptr, "/objects"); break;
	case RND_AT_OBJECT:
		if (s && s->object_source_ && i < s->scene.object_count) i = s->object_source_[i];
		snprintf(ptr, sizeof ptr, "/objects/%u", i);
		break;
	case RND_AT_MATERIALS: snprintf(ptr, sizeof ptr, "/materials"); break;
	}
	return api_problem_set(p, status, ptr, "%s", e->msg[0] ? e->msg : rnd_result_str(e->code));
}

void api_problem_parse(const char *body, size_t len, int status, struct api_problem *p)
{
	memset(p, 0, sizeof *p);
	json_t *j = body && len ? json_loadb(body, len, 0, NULL) : NULL;
	const char *detail = j ? json_string_value(json_object_get(j, "detail")) : NULL;
	if (!detail) {   /* not a problem document (a balancer's HTML page, ...): its first line */
		size_t n = body ? strcspn(body, "\r\n") : 0;
		api_problem_set(p, status, "", "%.*s", (int)(n < 200 ? n : 200), body ? body : "");
		if (!n) snprintf(p->detail, sizeof p->detail, "HTTP status %d without a problem document", status);
		json_decref(j);
		return;
	}
	api_problem_set(p, status, "", "%s", detail);
	const char *ptr = json_string_value(json_object_get(j, "pointer"));
	const char *title = json_string_value(json_object_get(j, "title"));
	const char *type = json_string_value(json_object_get(j, "type"));
	if (ptr) snprintf(p->pointer, sizeof p->pointer, "%s", ptr);
	if (title) snprintf(p->title, sizeof p->title, "%s", title);
	if (type) snprintf(p->type, sizeof p->type, "%s", type);
	json_decref(j);
}
