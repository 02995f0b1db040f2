/*
 * api/model_wire — the validating reader (daemon) of the importer's reply; its writer (the
 * sandboxed child) is api/model_wire_put.c. See model_wire.h for the layout and why the reader
 * trusts nothing.
 */
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "model_wire.h"

/* ---- reader ---- */

struct rd {
	const uint8_t *p;
	size_t left;
	char *err;
	size_t errsize;
};

__attribute__((format(printf, 2, 3)))
static enum api_result bad(struct rd *r, const char *fmt, ...)
{
	if (r->err && r->errsize) {
		int n = snprintf(r->err, r->errsize, "the importer's reply is malformed: ");
		va_list ap;
		va_start(ap, fmt);
		if (n > 0 && (size_t)n < r->errsize) vsnprintf(r->err + n, r->errsize - (size_t)n, fmt, ap);
		va_end(ap);
	}
	return API_ERR;
}

static bool take(struct rd *r, void *out, size_t n)
{
	if (n > r->left) return false;
	memcpy(out, r->p, n);
	r->p += n;
	r->left -= n;
	return true;
}

static bool take_u32(struct rd *r, uint32_t *v)
{
	return take(r, v, 4);
}

/* n items of `size` bytes must remain: checked before anything of that size is allocated. */
static bool fits(const struct rd *r, uint64_t n, uint64_t size)
{
	return size && n <= r->left / size;
}

/* The reply's big arrays are checked in blocks, branch-free inside one (the compiler vectorises
 * it): a 1M-triangle reply's 9M floats and 3M indices, whose element-at-a-time loops stalled on
 * every load. */
#define CHECK_BLOCK 256

static bool finite_all(const float *f, size_t n)
{
	size_t i = 0;
	for (; i + CHECK_BLOCK <= n; i += CHECK_BLOCK) {
		uint32_t inf_or_nan = 0;
		for (size_t k = 0; k < CHECK_BLOCK; k++) {
			uint32_t b;
			memcpy(&b, f + i + k, 4);
			inf_or_nan |= (b & 0x7f800000u) == 0x7f800000u;   /* an exponent of all ones */
		}
		if (inf_or_nan) return false;
	}
	for (; i < n; i++)
		if (!isfinite(f[i])) return false;
	return true;
}

/* The first of idx[0..n) that is not below nv, or n when every one is. */
static size_t first_out_of_range(const uint32_t *idx, size_t n, uint32_t nv)
{
	size_t i = 0;
	for (; i + CHECK_BLOCK <= n; i += CHECK_BLOCK) {
		uint32_t out = 0;
		for (size_t k = 0; k < CHECK_BLOCK; k++) out |= idx[i + k] >= nv;
		if (out) break;
	}
	for (; i < n; i++)
		if (idx[i] >= nv) return i;
	return n;
}

enum api_result api_wire_header(const uint8_t *data, size_t len, enum api_wire_kind *kind,
                                enum api_wire_status *status, char *msg, size_t msgsize,
                                const uint8_t **body, size_t *body_len, char *err, size_t errsize)
{
	struct rd r = {data, data ? len : 0, err, errsize};
	char magic[8];
	uint32_t ver, k, st, n;
	if (!take(&r, magic, 8) || memcmp(magic, API_WIRE_MAGIC, 8)) return bad(&r, "no header");
	if (!take_u32(&r, &ver) || !take_u32(&r, &k) || !take_u32(&r, &st) || !take_u32(&r, &n))
		return bad(&r, "the header is cut short");
	if (ver != API_WIRE_VERSION) return bad(&r, "version %u", ver);
	if (k != API_WIRE_MODEL && k != API_WIRE_IMAGE && k != API_WIRE_LEVELS) return bad(&r, "kind %u", k);
	if (st > API_WIRE_OVER_MEMORY) return bad(&r, "status %u", st);
	if (n > API_WIRE_MAX_MESSAGE || n > r.left) return bad(&r, "message of %u bytes", n);
	if (st != API_WIRE_OK && (n != r.left || !n)) return bad(&r, "a failure without (only) a message");
	if (msg && msgsize) {
		size_t c = n < msgsize - 1 ? n : msgsize - 1;
		/* Printable ASCII only: the message ends up in a JSON problem and a log line. */
		for (size_t i = 0; i < c; i++) msg[i] = r.p[i] >= 0x20 && r.p[i] < 0x7f ? (char)r.p[i] : '?';
		msg[c] = 0;
	}
	r.p += n;
	r.left -= n;
	*kind = (enum api_wire_kind)k;
	*status = (enum api_wire_status)st;
	*body = r.p;
	*body_len = r.left;
	return API_OK;
}

/* An image's size, checked against max_pixels and the bytes left: its pixels follow. */
static enum api_result read_image_size(struct rd *r, uint64_t max_pixels, uint32_t *w, uint32_t *h)
{
	if (!take_u32(r, w) || !take_u32(r, h)) return bad(r, "an image size is cut short");
	uint64_t n = (uint64_t)*w * *h;
	if (!n || n > max_pixels) return bad(r, "an image of %ux%u pixels", *w, *h);
	if (!fits(r, n, 4)) return bad(r, "an image's pixels are cut short");
	return API_OK;
}

static enum api_result read_image(struct rd *r, uint64_t max_pixels, uint32_t *w, uint32_t *h, const uint8_t **px)
{
	if (read_image_size(r, max_pixels, w, h) != API_OK) return API_ERR;
	*px = r->p;
	r->p += (size_t)*w * *h * 4;
	r->left -= (size_t)*w * *h * 4;
	return API_OK;
}

enum api_result api_wire_decode_image(const uint8_t *body, size_t len, uint64_t max_pixels, uint8_t **rgba,
                                      uint32_t *w, uint32_t *h, char *err, size_t errsize)
{
	struct rd r = {body, body ? len : 0, err, errsize};
	const uint8_t *px;
	*rgba = NULL;
	if (read_image(&r, max_pixels, w, h, &px) != API_OK) return API_ERR;
	if (r.left) return bad(&r, "%zu bytes after the image", r.left);
	size_t n = (size_t)*w * *h * 4;
	if (!(*rgba = malloc(n))) {
		snprintf(err, errsize, "out of memory");
		return API_ERR;
	}
	memcpy(*rgba, px, n);
	return API_OK;
}

struct dec {
	struct rd r;
	struct api_arena *arena;
	size_t bytes;
	unsigned flags;   /* API_WIRE_IN_PLACE */
};

static void *dec_alloc(struct dec *d, size_t n, size_t size)
{
	void *p = api_arena_calloc(d->arena, n ? n : 1, size);
	if (p) d->bytes += (n ? n : 1) * size;
	return p;
}

/* The next n * size bytes (the caller checked that they remain) as an array: where they lie
 * (API_WIRE_IN_PLACE, 4-byte aligned) or a copy in the arena; NULL when out of memory. */
static void *take_array(struct dec *d, size_t n, size_t size)
{
	void *p;
	if ((d->flags & API_WIRE_IN_PLACE) && !((uintptr_t)d->r.p & 3)) {
		p = (void *)d->r.p;
		d->bytes += n * size;
	} else if (!(p = dec_alloc(d, n, size))) {
		return NULL;
	} else {
		memcpy(p, d->r.p, n * size);
	}
	d->r.p += n * size;
	d->r.left -= n * size;
	return p;
}

static bool sampling_ok(uint32_t packed, const float *t)
{
	/* bit 9: the uv set (0 or 1) */
	if (packed > 0x3ff || (packed & 3) > RND_WRAP_MIRROR || (packed >> 2 & 3) > RND_WRAP_MIRROR ||
	    (packed >> 7 & 3) > RND_MIP_NEAREST)
		return false;
	for (int k = 0; k < 6; k++)
		if (!isfinite(t[k]) || fabsf(t[k]) > 1e6f) return false;
	return true;
}

static bool in_range(const float *v, int n, float lo, float hi)
{
	for (int k = 0; k < n; k++)
		if (!(v[k] >= lo && v[k] <= hi)) return false;   /* NaN fails */
	return true;
}

/* A material's PBR extensions: RND_EXT_* bits, then clearcoat factor roughness normal_scale,
 * sheen colour[3] roughness, specular factor colour[3] ior (f32). */
static enum api_result decode_extensions(struct dec *d, uint32_t i, struct rnd_material *m)
{
	uint32_t bits;
	float e[12];
	if (!take_u32(&d->r, &bits) || !take(&d->r, e, sizeof e)) return bad(&d->r, "material %u is cut short", i);
	m->specular.spec_gloss = bits & API_WIRE_SPEC_GLOSS;
	bits &= ~API_WIRE_SPEC_GLOSS;
	bool ok = bits <= (RND_EXT_CLEARCOAT | RND_EXT_SHEEN | RND_EXT_SPECULAR) && in_range(e, 2, 0, 1) &&
	          in_range(e + 2, 1, -1e3f, 1e3f) && in_range(e + 3, 5, 0, 1) && in_range(e + 8, 3, 0, 1e6f) &&
	          in_range(e + 11, 1, 0, 1e6f);
	if (!ok) return bad(&d->r, "material %u has an extension value out of range", i);
	m->extensions = bits;
	m->clearcoat.factor = e[0];
	m->clearcoat.roughness = e[1];
	m->clearcoat.normal_scale = e[2];
	memcpy(m->sheen.color, e + 3, 3 * sizeof(float));
	m->sheen.roughness = e[6];
	m->specular.factor = e[7];
	memcpy(m->specular.color, e + 8, 3 * sizeof(float));
	m->specular.ior = e[11];
	return API_OK;
}

static enum api_result decode_materials(struct dec *d, uint32_t nmat, struct rnd_texture *tex, uint32_t ntex,
                                        struct rnd_material *mats)
{
	for (uint32_t i = 0; i < nmat; i++) {
		float f[13], tf[RND_TEX_SLOTS][6];
		uint32_t mode, packed[RND_TEX_SLOTS];
		int32_t ti[RND_TEX_SLOTS];
		if (!take(&d->r, f, sizeof f) || !take_u32(&d->r, &mode) || !take(&d->r, ti, sizeof ti))
			return bad(&d->r, "material %u is cut short", i);
		for (uint32_t s = 0; s < RND_TEX_SLOTS; s++)
			if (!take_u32(&d->r, &packed[s]) || !take(&d->r, tf[s], sizeof tf[s]))
				return bad(&d->r, "material %u is cut short", i);
		bool ok = finite_all(f, 13) && f[12] >= 0 && f[12] <= 1;
		for (int k = 0; k < 3; k++) ok = ok && f[k] >= 0 && f[k] <= 1e6f && f[6 + k] >= 0 && f[6 + k] <= 1e6f;
		ok = ok && f[3] >= 0 && f[3] <= 1 && f[4] >= 0 && f[4] <= 1 && f[5] >= 0 && f[5] <= 1 && f[9] >= 0 &&
		     f[9] <= 1 && fabsf(f[10]) <= 1e3f && f[11] >= 0 && f[11] <= 1;
		for (uint32_t s = 0; s < RND_TEX_SLOTS; s++) ok = ok && sampling_ok(packed[s], tf[s]);
		if (!ok) return bad(&d->r, "material %u has a value out of range", i);
		if (mode > RND_ALPHA_BLEND) return bad(&d->r, "material %u alpha mode", i);
		struct rnd_material *m = &mats[i];
		rnd_material_defaults(m);
		for (uint32_t s = 0; s < RND_TEX_SLOTS; s++) {
			if (ti[s] < -1 || (ti[s] >= 0 && (uint32_t)ti[s] >= ntex))
				return bad(&d->r, "material %u texture %d", i, ti[s]);
			m->textures[s] = ti[s] >= 0 ? &tex[ti[s]] : NULL;
			struct rnd_texture_sampling *ts = &m->sampling[s];
			ts->wrap_s = (uint8_t)(packed[s] & 3);
			ts->wrap_t = (uint8_t)(packed[s] >> 2 & 3);
			ts->mag_nearest = packed[s] >> 4 & 1;
			ts->min_nearest = packed[s] >> 5 & 1;
			ts->transformed = packed[s] >> 6 & 1;
			ts->mip = (uint8_t)(packed[s] >> 7 & 3);
			ts->uv_set = (uint8_t)(packed[s] >> 9 & 1);
			memcpy(ts->transform, tf[s], sizeof tf[s]);
		}
		if (decode_extensions(d, i, m) != API_OK) return API_ERR;
		memcpy(m->base_color, f, 4 * sizeof(float));
		m->roughness = f[4];
		m->metallic = f[5];
		memcpy(m->emissive, f + 6, 3 * sizeof(float));
		m->alpha_cutoff = f[9];
		m->normal_scale = f[10];
		m->occlusion_strength = f[11];
		m->see_through = f[12];
		m->alpha_mode = (enum rnd_alpha_mode)mode;
	}
	return API_OK;
}

static enum api_result decode_mesh_levels(struct dec *d, uint32_t i, const struct api_model_mesh *me,
                                          struct api_mesh_levels *out);

/* The mesh's caster level (api/model_caster.h): coarser than the mesh, inside its bounds, with
 * a finite error. */
static enum api_result decode_caster(struct dec *d, uint32_t i, struct api_model_mesh *me)
{
	uint32_t nv, ni;
	float error;
	if (!take_u32(&d->r, &nv) || !take_u32(&d->r, &ni) || !take(&d->r, &error, 4))
		return bad(&d->r, "mesh %u caster level is cut short", i);
	if (!nv || ni < 3 || ni % 3 || ni >= me->index_count || nv > ni || !isfinite(error) || error < 0.0f)
		return bad(&d->r, "mesh %u caster level: %u vertices, %u indices, error %g", i, nv, ni, (double)error);
	if (!fits(&d->r, nv, 12) || !fits(&d->r, ni, 4) || (uint64_t)nv * 12 > d->r.left - (uint64_t)ni * 4)
		return bad(&d->r, "mesh %u caster level is cut short", i);
	const float *pos = take_array(d, nv, 12);
	const uint32_t *idx = take_array(d, ni, 4);
	struct rnd_caster_level *lv = dec_alloc(d, 1, sizeof *lv);
	if (!pos || !idx || !lv) return bad(&d->r, "out of memory");
	for (uint32_t v = 0; v < nv; v++)
		for (int k = 0; k < 3; k++) {
			float x = pos[3 * (size_t)v + (size_t)k];
			if (!isfinite(x) || x < me->bounds[k] || x > me->bounds[3 + k])
				return bad(&d->r, "mesh %u caster level: vertex %u lies outside the mesh", i, v);
		}
	size_t k = first_out_of_range(idx, ni, nv);
	if (k < ni) return bad(&d->r, "mesh %u caster level: index %zu refers to vertex %u of %u", i, k, idx[k], nv);
	*lv = (struct rnd_caster_level){pos, idx, nv, ni, error};
	me->caster = lv;
	return API_OK;
}

/* A mesh's indices 0, 1, ..., n-1 counted out here (flag 512: each corner its own vertex, as
 * in an STL; they are in range by construction). NULL when out of memory. */
static uint32_t *identity_indices(struct dec *d, uint32_t n)
{
	uint32_t *idx = dec_alloc(d, n, 4);
	for (uint32_t k = 0; idx && k < n; k++) idx[k] = k;
	return idx;
}

static enum api_result decode_mesh(struct dec *d, uint32_t i, uint32_t nmat, struct api_model_mesh *me)
{
	uint32_t nv, ni, mat, flags;
	if (!take_u32(&d->r, &nv) || !take_u32(&d->r, &ni) || !take_u32(&d->r, &mat) || !take_u32(&d->r, &flags))
		return bad(&d->r, "mesh %u is cut short", i);
	if (!nv || !ni || ni % 3 || mat >= nmat || flags > 1023 || ((flags & 512) && ni != nv))
		return bad(&d->r, "mesh %u: %u vertices, %u indices, material %u, flags %u", i, nv, ni, mat, flags);
	uint64_t per_vertex = 12 + (flags & 1 ? 12 : 0) + (flags & 2 ? 8 : 0) + (flags & 128 ? 8 : 0) + (flags & 4 ? 4 : 0) + (flags & 8 ? 16 : 0);
	/* (per_vertex <= 60 and ni * 4 fit the reply: nothing below overflows) */
	uint64_t wire_ni = flags & 512 ? 0 : ni;   /* flag 512: the indices 0..n-1, not sent */
	if (!fits(&d->r, nv, per_vertex) || wire_ni * 4 > d->r.left ||
	    (uint64_t)nv * per_vertex > d->r.left - wire_ni * 4)
		return bad(&d->r, "mesh %u is cut short", i);
	const float *pos = take_array(d, nv, 12), *nrm = flags & 1 ? take_array(d, nv, 12) : NULL;
	const float *uv = flags & 2 ? take_array(d, nv, 8) : NULL, *uv1 = flags & 128 ? take_array(d, nv, 8) : NULL;
	const uint8_t *col = flags & 4 ? take_array(d, nv, 4) : NULL;
	const float *tan = flags & 8 ? take_array(d, nv, 16) : NULL;
	const uint32_t *idx = flags & 512 ? identity_indices(d, ni) : take_array(d, ni, 4);
	if (!pos || ((flags & 1) && !nrm) || ((flags & 2) && !uv) || ((flags & 128) && !uv1) || ((flags & 4) && !col) || ((flags & 8) && !tan) || !idx)
		return bad(&d->r, "out of memory");
	if (!finite_all(pos, (size_t)nv * 3) || (nrm && !finite_all(nrm, (size_t)nv * 3)) ||
	    (uv && !finite_all(uv, (size_t)nv * 2)) || (uv1 && !finite_all(uv1, (size_t)nv * 2)) ||
	    (tan && !finite_all(tan, (size_t)nv * 4)))
		return bad(&d->r, "mesh %u has a value that is not finite", i);
	size_t k = flags & 512 ? ni : first_out_of_range(idx, ni, nv);   /* 512: in range by construction */
	if (k < ni) return bad(&d->r, "mesh %u: index %zu refers to vertex %u of %u", i, k, idx[k], nv);
	*me = (struct api_model_mesh){.positions = pos, .normals = nrm, .uvs = uv, .uvs1 = uv1, .colors = col, .tangents = tan,
	                              .indices = idx, .vertex_count = nv, .index_count = ni, .material = mat,
	                              .single_sided = (flags & 16) != 0, .closed = (flags & 32) != 0};
	api_mesh_bounds(me);
	if (flags & 64) {
		/* the level the importer built for the request (api_model_finish_import) */
		struct api_mesh_levels lv;
		if (decode_mesh_levels(d, i, me, &lv) != API_OK) return API_ERR;
		me->lods = lv.lods;
		me->lod_count = lv.count;
	}
	if ((flags & 256) && decode_caster(d, i, me) != API_OK) return API_ERR;
	return API_OK;
}

enum api_result api_wire_decode_model(const uint8_t *body, size_t len, unsigned flags, struct api_arena *arena,
                                      uint64_t max_texture_pixels, struct api_model *out, size_t *bytes,
                                      char *err, size_t errsize)
{
	struct dec d = {{body, body ? len : 0, err, errsize}, arena, 0, flags};
	uint32_t ntex, nmat, nmesh, ninst, nwarn, tside, tmax;
	float times[4];
	if (!take(&d.r, times, sizeof times) || !take_u32(&d.r, &tside) || !take_u32(&d.r, &tmax))
		return bad(&d.r, "the counts are cut short");
	for (int k = 0; k < 4; k++)
		if (!isfinite(times[k]) || times[k] < 0 || times[k] > 1e8f) return bad(&d.r, "a stage time of %g ms", (double)times[k]);
	if (!take_u32(&d.r, &ntex) || !take_u32(&d.r, &nmat) || !take_u32(&d.r, &nmesh) || !take_u32(&d.r, &ninst) ||
	    !take_u32(&d.r, &nwarn))
		return bad(&d.r, "the counts are cut short");
	if (nwarn > API_MODEL_MAX_WARNINGS || nwarn > d.r.left) return bad(&d.r, "warnings of %u bytes", nwarn);
	char *warn = NULL;
	if (nwarn) {
		if (!(warn = dec_alloc(&d, nwarn + 1, 1))) return bad(&d.r, "out of memory");
		take(&d.r, warn, nwarn);
		/* Printable ASCII only: it becomes a response header. */
		for (uint32_t k = 0; k < nwarn; k++)
			if (warn[k] < 0x20 || warn[k] > 0x7e) warn[k] = '?';
	}
	uint8_t pad[4] = {0};
	if (!take(&d.r, pad, (4 - nwarn % 4) % 4) || pad[0] || pad[1] || pad[2]) return bad(&d.r, "the warnings' padding");
	/* Each item has a smallest size on the wire (texture 8, material 488, mesh 16, instance 68
	 * bytes): counts the reply's bytes cannot hold are lies caught before allocating (the arrays
	 * are larger in memory than on the wire, and zeroed). */
	uint64_t min_wire = (uint64_t)ntex * 8 + (uint64_t)nmat * 488 + (uint64_t)nmesh * 16 + (uint64_t)ninst * 68;
	if (ntex > API_WIRE_MAX_TEXTURES || !nmat || !nmesh || !ninst || !fits(&d.r, min_wire, 1))
		return bad(&d.r, "%u textures, %u materials, %u meshes, %u instances", ntex, nmat, nmesh, ninst);
	struct rnd_texture *tex = dec_alloc(&d, ntex, sizeof *tex);
	struct rnd_material *mats = dec_alloc(&d, nmat, sizeof *mats);
	struct api_model_mesh *meshes = dec_alloc(&d, nmesh, sizeof *meshes);
	struct api_model_instance *inst = dec_alloc(&d, ninst, sizeof *inst);
	if (!tex || !mats || !meshes || !inst) return bad(&d.r, "out of memory");
	for (uint32_t i = 0; i < ntex; i++) {
		if (read_image_size(&d.r, max_texture_pixels, &tex[i].width, &tex[i].height) != API_OK) return API_ERR;
		if (!(tex[i].rgba = take_array(&d, (size_t)tex[i].width * tex[i].height, 4))) return bad(&d.r, "out of memory");
	}
	if (decode_materials(&d, nmat, tex, ntex, mats) != API_OK) return API_ERR;
	for (uint32_t i = 0; i < nmesh; i++)
		if (decode_mesh(&d, i, nmat, &meshes[i]) != API_OK) return API_ERR;
	uint64_t tris = 0;
	for (uint32_t i = 0; i < ninst; i++) {
		if (!take_u32(&d.r, &inst[i].mesh) || !take(&d.r, inst[i].model, 64))
			return bad(&d.r, "instance %u is cut short", i);
		if (inst[i].mesh >= nmesh || !finite_all(inst[i].model, 16))
			return bad(&d.r, "instance %u: mesh %u, or a matrix that is not finite", i, inst[i].mesh);
		tris += meshes[inst[i].mesh].index_count / 3;
	}
	if (d.r.left) return bad(&d.r, "%zu bytes after the last instance", d.r.left);
	out->meshes = meshes;
	out->mesh_count = nmesh;
	out->instances = inst;
	out->instance_count = ninst;
	out->materials = mats;
	out->material_count = nmat;
	out->triangles = tris;
	out->warnings = warn;
	out->texture_side = tside;
	out->texture_max = tmax;
	memset(&out->times, 0, sizeof out->times);
	memcpy(&out->times.ms[API_IMPORT_PARSE], times, sizeof times);
	out->times.imports = 1;
	*bytes = d.bytes;
	return API_OK;
}

/* ---- levels of detail (API_WIRE_LEVELS) ---- */


/* One level of mesh `me` (the one it simplifies): coarser than what it follows (fewer indices),
 * within the mesh's bounds (the renderer bounds a mesh by its full vertices), uvs (each set),
 * colours and tangents only where the mesh has them, and an error no finer than the previous level's. */
static enum api_result decode_level(struct dec *d, uint32_t i, uint32_t l, const struct api_model_mesh *me,
                                    uint32_t max_indices, float min_error, struct rnd_mesh_lod *out)
{
	uint32_t nv, ni, flags;
	float error;
	if (!take_u32(&d->r, &nv) || !take_u32(&d->r, &ni) || !take_u32(&d->r, &flags) || !take(&d->r, &error, 4))
		return bad(&d->r, "mesh %u level %u is cut short", i, l);
	if (!nv || ni < 3 || ni % 3 || ni >= max_indices || nv > ni || flags > 15 || ((flags & 1) && !me->uvs) ||
	    ((flags & 2) && !me->uvs1) || ((flags & 4) && !me->colors) || ((flags & 8) && !me->tangents) ||
	    !isfinite(error) || error < min_error)
		return bad(&d->r, "mesh %u level %u: %u vertices, %u indices, flags %u, error %g", i, l, nv, ni, flags,
		           (double)error);
	uint64_t per_vertex = 24 + (flags & 1 ? 8 : 0) + (flags & 2 ? 8 : 0) + (flags & 4 ? 4 : 0) + (flags & 8 ? 16 : 0);
	if (!fits(&d->r, nv, per_vertex) || !fits(&d->r, ni, 4) || (uint64_t)nv * per_vertex > d->r.left - (uint64_t)ni * 4)
		return bad(&d->r, "mesh %u level %u is cut short", i, l);
	const float *pos = take_array(d, nv, 12), *nrm = take_array(d, nv, 12), *uv = flags & 1 ? take_array(d, nv, 8) : NULL;
	const float *uv1 = flags & 2 ? take_array(d, nv, 8) : NULL;
	const uint8_t *col = flags & 4 ? take_array(d, nv, 4) : NULL;
	const float *tan = flags & 8 ? take_array(d, nv, 16) : NULL;
	const uint32_t *idx = take_array(d, ni, 4);
	if (!pos || !nrm || ((flags & 1) && !uv) || ((flags & 2) && !uv1) || ((flags & 4) && !col) || ((flags & 8) && !tan) ||
	    !idx)
		return bad(&d->r, "out of memory");
	if (!finite_all(pos, (size_t)nv * 3) || !finite_all(nrm, (size_t)nv * 3) || (uv && !finite_all(uv, (size_t)nv * 2)) ||
	    (uv1 && !finite_all(uv1, (size_t)nv * 2)) || (tan && !finite_all(tan, (size_t)nv * 4)))
		return bad(&d->r, "mesh %u level %u has a value that is not finite", i, l);
	for (uint32_t v = 0; v < nv; v++)
		for (int k = 0; k < 3; k++)
			if (pos[3 * (size_t)v + (size_t)k] < me->bounds[k] || pos[3 * (size_t)v + (size_t)k] > me->bounds[3 + k])
				return bad(&d->r, "mesh %u level %u: vertex %u lies outside the mesh", i, l, v);
	size_t k = first_out_of_range(idx, ni, nv);
	if (k < ni) return bad(&d->r, "mesh %u level %u: index %zu refers to vertex %u of %u", i, l, k, idx[k], nv);
	*out = (struct rnd_mesh_lod){pos, nrm, uv, idx, nv, ni, error, uv1, col, tan};
	return API_OK;
}

/* A mesh's levels (level_count, then each level) into *out. */
static enum api_result decode_mesh_levels(struct dec *d, uint32_t i, const struct api_model_mesh *me,
                                          struct api_mesh_levels *out)
{
	uint32_t count;
	if (!take_u32(&d->r, &count) || count > API_LOD_LEVELS) return bad(&d->r, "mesh %u: levels", i);
	struct rnd_mesh_lod *lv = count ? dec_alloc(d, count, sizeof *lv) : NULL;
	if (count && !lv) return bad(&d->r, "out of memory");
	uint32_t max_indices = me->index_count;
	float min_error = 0.0f;
	for (uint32_t l = 0; l < count; l++) {
		if (decode_level(d, i, l, me, max_indices, min_error, &lv[l]) != API_OK) return API_ERR;
		max_indices = lv[l].index_count;
		min_error = lv[l].error;
	}
	*out = (struct api_mesh_levels){lv, count};
	return API_OK;
}

enum api_result api_wire_decode_levels(const uint8_t *body, size_t len, unsigned flags,
                                       const struct api_model_mesh *const *meshes, uint32_t nmesh,
                                       struct api_arena *arena, struct api_mesh_levels *out, size_t *bytes,
                                       char *err, size_t errsize)
{
	struct dec d = {{body, body ? len : 0, err, errsize}, arena, 0, flags};
	uint32_t n = 0;
	if (!take_u32(&d.r, &n) || n != nmesh) return bad(&d.r, "levels of %u meshes for %u", n, nmesh);
	for (uint32_t i = 0; i < nmesh; i++)
		if (decode_mesh_levels(&d, i, meshes[i], &out[i]) != API_OK) return API_ERR;
	if (d.r.left) return bad(&d.r, "%zu bytes after the last level", d.r.left);
	*bytes = d.bytes;
	return API_OK;
}
