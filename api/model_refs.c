/*
 * api/model_refs — finding and reading the files a model refers to (see model_refs.h). Runs in
 * the daemon on untrusted bytes, so it only scans: jansson for the glTF JSON (never a parser
 * of binary formats), a line scan for .obj and .mtl; every name it finds is a request input
 * and goes through api/asset.c's rules before anything is opened.
 */
#include <limits.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include "asset.h"
#include "errmsg.h"
#include "gltf_buffers.h"
#include "model_refs.h"

enum ref_kind { REF_BUFFER, REF_IMAGE, REF_MTL, REF_TEXTURE };
static const char *const KIND_NAMES[] = {"buffer", "image", "material library", "texture"};

struct ctx {
	const struct api_ref_source *src;
	struct api_model_refs *out;
	char *resolved[API_MODEL_REFS_MAX];   /* each file's name as resolved (api_asset_resolve) */
	uint64_t total;
	int *status;
	char *err;
	size_t errsize;
	char missing[200];        /* why the last optional file (fetch's -2) was left out */
};

static int hex(char ch)
{
	return ch >= '0' && ch <= '9' ? ch - '0' : ch >= 'a' && ch <= 'f' ? ch - 'a' + 10
	       : ch >= 'A' && ch <= 'F' ? ch - 'A' + 10 : -1;
}

/* glTF URIs are percent-encoded ("my%20file.bin"); the file and the part have the plain name. */
static void percent_decode(const char *in, char *out, size_t n)
{
	size_t k = 0;
	for (const char *p = in; *p && k + 1 < n; p++) {
		if (p[0] == '%' && hex(p[1]) >= 0 && hex(p[2]) >= 0) {
			out[k++] = (char)(hex(p[1]) * 16 + hex(p[2]));
			p += 2;
		} else {
			out[k++] = *p;
		}
	}
	out[k] = 0;
}

__attribute__((format(printf, 2, 3)))
static void warn(struct ctx *c, const char *fmt, ...)
{
	char *w = c->out->warning;
	size_t n = strlen(w);
	if (n && n + 2 < sizeof c->out->warning) memcpy(w + n, "; ", 3), n += 2;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(w + n, sizeof c->out->warning - n, fmt, ap);
	va_end(ap);
}

static int push(struct ctx *c, const char *name, const uint8_t *data, size_t len, bool owned)
{
	struct api_model_refs *r = c->out;
	char *nm = strdup(name);
	if (r->count == r->cap_) {
		size_t cap = r->cap_ ? r->cap_ * 2 : 8;
		struct api_model_file *f = realloc(r->files, cap * sizeof *f);
		if (f) r->files = f;
		unsigned char *o = f ? realloc(r->owned_, cap) : NULL;
		if (o) r->owned_ = o;
		if (!f || !o) nm = (free(nm), NULL);
		else r->cap_ = cap;
	}
	if (!nm) {
		if (owned) free((void *)data);
		*c->status = 500;
		return api_err_set(c->err, c->errsize, "out of memory reading the model's files"), -1;
	}
	bool again = false;   /* the bytes of a file already here (another spelling of its name) */
	for (size_t i = 0; i < r->count && !again; i++) again = r->files[i].data == data && r->files[i].len == len;
	r->files[r->count] = (struct api_model_file){nm, data, len};
	r->owned_[r->count++] = owned;
	if (!again) r->bytes += len;
	return 0;
}

static int add_origin(struct ctx *c, const char *path, const struct api_asset_stamp *stamp)
{
	struct api_model_refs *r = c->out;
	struct api_asset_origin *o = realloc(r->origins, (r->norigins + 1) * sizeof *o);
	char *p = o ? strdup(path) : NULL;
	if (o) r->origins = o;
	if (!p) {
		*c->status = 500;
		return api_err_set(c->err, c->errsize, "out of memory reading the model's files"), -1;
	}
	r->origins[r->norigins++] = (struct api_asset_origin){p, *stamp};
	return 0;
}

/* Finds one reference `ref` (as written in the file at `base`), adds it under that name, and
 * returns its index; -1 with the answer set; -2 when it cannot be found in inline data (the
 * caller decides whether that is an error). */
static long fetch(struct ctx *c, enum ref_kind kind, const char *base, const char *ref)
{
	const struct api_ref_source *s = c->src;
	for (size_t i = 0; i < c->out->count; i++)
		if (!strcmp(c->out->files[i].name, ref)) return (long)i;
	if (c->out->count >= API_MODEL_REFS_MAX) {
		*c->status = 422;
		return api_err_set(c->err, c->errsize, "the model refers to more than %u files", API_MODEL_REFS_MAX), -1;
	}
	char plain[PATH_MAX], full[PATH_MAX], why[300];
	if (kind == REF_BUFFER || kind == REF_IMAGE) percent_decode(ref, plain, sizeof plain);
	else snprintf(plain, sizeof plain, "%s", ref);
	if (api_asset_resolve(s->path ? base : "", plain, full, sizeof full, why, sizeof why) != API_OK) {
		*c->status = 400;
		return api_err_set(c->err, c->errsize, "its %s \"%.128s\" cannot be used: %s", KIND_NAMES[kind], ref, why), -1;
	}
	/* The same file under another spelling ("a.bin", "./a.bin", "a%2Ebin"): one copy of its
	 * bytes, counted once; the importer sees both names (a 40 MB part named 24 ways had been
	 * sent to it 24 times: +1 GB). */
	for (size_t i = 0; i < c->out->count; i++)
		if (c->resolved[i] && !strcmp(c->resolved[i], full)) {
			const struct api_model_file *f = &c->out->files[i];
			if (push(c, ref, f->data, f->len, false) < 0) return -1;
			c->resolved[c->out->count - 1] = strdup(full);
			return (long)c->out->count - 1;
		}
	const uint8_t *data = NULL;
	uint8_t *owned = NULL;
	size_t len = 0;
	if (s->path) {
		int st;
		struct api_asset_stamp stamp;
		if (api_asset_read_stamped(s->root, full, &owned, &len, &stamp, &st, why, sizeof why) != API_OK) {
			/* As for a request that does not carry it (and the farm): the model is drawn
			 * without it, and the answer says why. */
			if (kind == REF_MTL || kind == REF_TEXTURE) {
				snprintf(c->missing, sizeof c->missing, "cannot be read under the asset root (%.150s)", why);
				return -2;
			}
			*c->status = st;
			return api_err_set(c->err, c->errsize, "its %s \"%.128s\" cannot be read: %s", KIND_NAMES[kind], ref,
			                   why), -1;
		}
		api_asset_hash(&c->out->asset_hash, full, owned, len);
		data = owned;
		if (add_origin(c, full, &stamp) < 0) return free(owned), -1;
	} else {
		size_t i = 0;
		while (i < s->nparts && (!s->parts[i].name || (strcmp(s->parts[i].name, full) && strcmp(s->parts[i].name, ref))))
			i++;
		/* An .obj's .mtl and textures are optional to Assimp: sent without them (inline, or as
		 * the only part, as the farm does) the model renders with what it has, and says so. */
		if (i == s->nparts && (!s->nparts || kind == REF_MTL || kind == REF_TEXTURE)) {
			snprintf(c->missing, sizeof c->missing, "is not in the request");
			return -2;
		}
		if (i == s->nparts) {
			*c->status = 400;
			return api_err_set(c->err, c->errsize, "its %s \"%.128s\" is not a part of this request (send it as a "
			                   "part named \"%.128s\")", KIND_NAMES[kind], ref, full), -1;
		}
		data = s->parts[i].data;
		len = s->parts[i].len;
		if (!len) {
			*c->status = 400;
			return api_err_set(c->err, c->errsize, "its %s \"%.128s\" is an empty part", KIND_NAMES[kind], ref), -1;
		}
	}
	if (c->total + len > API_ASSET_MAX_FILE) {
		free(owned);
		*c->status = 422;
		return api_err_set(c->err, c->errsize, "the model and its files are larger than %llu bytes",
		                   (unsigned long long)API_ASSET_MAX_FILE), -1;
	}
	c->total += len;
	if (push(c, ref, data, len, owned != NULL) < 0) return -1;
	c->resolved[c->out->count - 1] = strdup(full);   /* NULL when out of memory: not shared */
	return (long)c->out->count - 1;
}

/* ---- glTF ---- */

static int gltf_refs(struct ctx *c, const uint8_t *d, size_t len, bool glb)
{
	const char *json;
	size_t jlen;
	if (api_gltf_json_of(d, len, glb, &json, &jlen)) return 0;
	/* Malformed JSON is the importer's to report (with its own words): no references then. */
	json_t *root = json_loadb(json, jlen, 0, NULL);
	if (!json_is_object(root)) return json_decref(root), 0;
	static const char *const arrays[] = {"buffers", "images"};
	int rc = 0;
	for (int a = 0; a < 2 && !rc; a++) {
		json_t *arr = json_object_get(root, arrays[a]), *el;
		size_t i;
		json_array_foreach(arr, i, el) {
			json_t *uri = json_object_get(el, "uri");
			if (!json_is_string(uri) || !strncmp(json_string_value(uri), "data:", 5)) continue;
			enum ref_kind k = a ? REF_IMAGE : REF_BUFFER;
			long r = fetch(c, k, c->src->path, json_string_value(uri));
			if (r == -2) {
				*c->status = 400;
				api_err_set(c->err, c->errsize, "its %s \"%.128s\" is a separate file, which inline data cannot "
				            "carry: send the model by path under the asset root, or in a multipart request with a "
				            "part named \"%.128s\"", KIND_NAMES[k], json_string_value(uri), json_string_value(uri));
			}
			if (r < 0) { rc = -1; break; }
		}
	}
	json_decref(root);
	return rc;
}

/* ---- OBJ and MTL ---- */

/* The rest of the line after the keyword, trimmed, into out; "" when none. */
static void rest_of_line(const char *p, const char *end, char *out, size_t n)
{
	while (p < end && (*p == ' ' || *p == '\t')) p++;
	while (end > p && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r')) end--;
	size_t k = (size_t)(end - p) < n - 1 ? (size_t)(end - p) : n - 1;
	memcpy(out, p, k);
	out[k] = 0;
}

static bool keyword(const char *p, const char *end, const char *kw, const char **after)
{
	size_t n = strlen(kw);
	if ((size_t)(end - p) <= n || strncmp(p, kw, n) || (p[n] != ' ' && p[n] != '\t')) return false;
	*after = p + n;
	return true;
}

/* An .mtl texture statement's file: the last word when options ("-s 1 1 1") come first, else
 * the rest of the line (names may hold spaces). */
static void texture_name(const char *p, const char *end, char *out, size_t n)
{
	rest_of_line(p, end, out, n);
	if (out[0] != '-') return;
	char *last = strrchr(out, ' '), *tab = strrchr(out, '\t');
	if (tab > last) last = tab;
	if (last) memmove(out, last + 1, strlen(last + 1) + 1);
}

/* The line of an .obj / .mtl that starts at p: its first non-blank character (returned) and its
 * end (*eol: the newline, or e). */
static const char *line_at(const char *p, const char *e, const char **eol)
{
	*eol = memchr(p, '\n', (size_t)(e - p));
	if (!*eol) *eol = e;
	while (p < *eol && (*p == ' ' || *p == '\t')) p++;
	return p;
}

static int mtl_refs(struct ctx *c, const char *mtl_path, const uint8_t *d, size_t len)
{
	static const char *const kws[] = {"map_Kd", "map_Ka", "map_Ks", "map_Ke", "map_Ns", "map_d", "map_bump",
	                                  "map_Bump", "bump", "disp", "decal", "norm", "map_Pr", "map_Pm", NULL};
	const char *s = (const char *)d, *e = s + len;
	for (const char *p = s; p < e;) {
		const char *eol;
		p = line_at(p, e, &eol);
		const char *after;
		for (int k = 0; kws[k]; k++) {
			if (!keyword(p, eol, kws[k], &after)) continue;
			char name[PATH_MAX];
			texture_name(after, eol, name, sizeof name);
			long r = name[0] ? fetch(c, REF_TEXTURE, mtl_path, name) : 0;
			if (r == -1) return -1;
			if (r == -2) warn(c, "the obj's texture \"%.64s\" %s: drawn without it", name, c->missing);
			break;
		}
		p = eol + 1;
	}
	return 0;
}

static int obj_refs(struct ctx *c, const uint8_t *d, size_t len)
{
	const char *s = (const char *)d, *e = s + len;
	for (const char *p = s; p < e;) {
		const char *eol;
		p = line_at(p, e, &eol);
		const char *after;
		if (keyword(p, eol, "mtllib", &after)) {
			char name[PATH_MAX];
			rest_of_line(after, eol, name, sizeof name);
			long r = name[0] ? fetch(c, REF_MTL, c->src->path, name) : 0;
			if (r == -1) return -1;
			if (r == -2) {
				warn(c, "the obj's material library \"%.64s\" %s: drawn with the default material", name,
				     c->missing);
			} else if (name[0]) {
				/* The .mtl's textures resolve against the .mtl's own directory. */
				char mpath[PATH_MAX] = "", why[8];
				if (c->src->path) api_asset_resolve(c->src->path, name, mpath, sizeof mpath, why, sizeof why);
				const struct api_model_file *f = &c->out->files[r];
				if (mtl_refs(c, c->src->path ? mpath : name, f->data, f->len) < 0) return -1;
			}
		}
		p = eol + 1;
	}
	return 0;
}

enum api_result api_model_refs_collect(const uint8_t *data, size_t len, enum api_model_format format,
                                       const struct api_ref_source *src, struct api_model_refs *out, int *status,
                                       char *err, size_t errsize)
{
	memset(out, 0, sizeof *out);
	*status = 0;
	struct ctx c = {.src = src, .out = out, .total = len, .status = status, .err = err, .errsize = errsize};
	int rc = 0;
	if (format == API_MODEL_GLTF || format == API_MODEL_GLB) rc = gltf_refs(&c, data, len, format == API_MODEL_GLB);
	else if (format == API_MODEL_OBJ) rc = obj_refs(&c, data, len);
	for (size_t i = 0; i < API_MODEL_REFS_MAX; i++) free(c.resolved[i]);
	return rc < 0 ? API_ERR : API_OK;
}

void api_model_refs_release(struct api_model_refs *r)
{
	if (!r) return;
	for (size_t i = 0; i < r->count; i++) {
		free((void *)r->files[i].name);
		if (r->owned_[i]) free((void *)r->files[i].data);
	}
	free(r->files);
	free(r->owned_);
	for (size_t i = 0; i < r->norigins; i++) free(r->origins[i].path);
	free(r->origins);
	memset(r, 0, sizeof *r);
}
