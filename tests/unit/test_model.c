/* tests — api/model.c and `shape: model` in api/scene_parse.c: models built here (obj cube,
 * binary stl tetrahedron, glb quad with an embedded PNG), imported through api_scene_parse,
 * paths under an asset root, corrupt bytes, the cache. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>
#include <png.h>
#include <pthread.h>
#include <jpeglib.h>
#include "api.h"
#include "model.h"
#include "models.h"
#include "test.h"
#include "util.h"
#include "umbra/rnd_math.h"
#include "model_util.h"

static bool near_f(float a, float b)
{
	return fabsf(a - b) <= 1e-4f * (1.0f + fabsf(b));
}

/* ---- building documents ---- */


/* A scene with one model object: `extra` goes inside the object ("" or ",'k':v" with ' for "). */
static char *model_doc(const uint8_t *d, size_t n, const char *extra)
{
	char *enc = test_b64(d, n);
	size_t cap = strlen(enc) + strlen(extra) + 512;
	char *doc = malloc(cap);
	snprintf(doc, cap, "{\"camera\":{\"position\":[0,0,5]},\"materials\":{\"grey\":{\"base_color\":[0.5,0.5,0.5]}},"
	         "\"objects\":[{\"shape\":\"model\",\"data\":\"%s\"%s}]}", enc, extra);
	for (char *p = doc; *p; p++) if (*p == '\'') *p = '"';
	free(enc);
	return doc;
}

static struct api_scene *parse_lim(const char *doc, const struct api_limits *lim, struct api_problem *p)
{
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	if (api_scene_parse(doc, strlen(doc), lim, &s, p) != API_OK) return NULL;
	return s;
}

static struct api_scene *parse_model(const uint8_t *d, size_t n, const char *extra, struct api_problem *p)
{
	char *doc = model_doc(d, n, extra);
	struct api_scene *s = parse_lim(doc, NULL, p);
	free(doc);
	return s;
}

/* World-space bounds of every object of the scene. */
static struct rnd_aabb bounds(const struct rnd_scene *sc)
{
	struct rnd_aabb b;
	rnd_aabb_empty(&b);
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct rnd_object *o = &sc->objects[i];
		for (uint32_t v = 0; v < o->vertex_count; v++) {
			float w[3];
			rnd_mat4_mul_point(w, o->model, o->positions + 3 * v);
			rnd_aabb_add_point(&b, w);
		}
	}
	return b;
}

static uint64_t triangles(const struct rnd_scene *sc)
{
	uint64_t t = 0;
	for (uint32_t i = 0; i < sc->object_count; i++) t += sc->objects[i].index_count / 3;
	return t;
}

/* ---- models ---- */

static const char CUBE_OBJ[] =
	"# cube\n"
	"o cube\n"
	"v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
	"f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";

static size_t tetra_stl(uint8_t *out /* 284 bytes */)
{
	static const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	return test_tetra_stl(out, p);
}

/* ---- tests ---- */

#define DEFAULT_CACHE (256ull << 20)

TEST(model_obj_cube)
{
	struct api_problem p;
	struct api_scene *s = parse_model((const uint8_t *)CUBE_OBJ, strlen(CUBE_OBJ),
	                                  ",'transform':{'translation':[10,0,0]}", &p);
	REQUIRE(s, "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	const struct rnd_scene *sc = &s->scene;
	REQUIRE(sc->object_count == 1, "%u objects", sc->object_count);
	const struct rnd_object *o = &sc->objects[0];
	CHECK(o->shape == RND_SHAPE_MESH);
	CHECK(o->index_count == 36, "%u indices", o->index_count);
	CHECK(o->vertex_count >= 8 && o->vertex_count <= 36, "%u vertices", o->vertex_count);
	CHECK(o->normals != NULL);
	CHECK(s->triangles == 12, "%llu triangles", (unsigned long long)s->triangles);
	struct rnd_aabb b = bounds(sc);
	CHECK(near_f(b.min[0], 9) && near_f(b.max[0], 11) && near_f(b.min[1], -1) && near_f(b.max[2], 1),
	      "bounds %g..%g %g..%g", b.min[0], b.max[0], b.min[1], b.max[1]);
	/* No mtl: the contract's default material. */
	const struct rnd_material *m = &sc->materials[o->material];
	CHECK(near_f(m->base_color[0], 0.8f) && m->base_color_texture == NULL);
	for (uint32_t i = 0; i < o->index_count; i++) CHECK(o->indices[i] < o->vertex_count);
	api_scene_free(s);
}

TEST(model_stl_tetrahedron_sniffed)
{
	uint8_t stl[284];
	size_t n = tetra_stl(stl);
	CHECK(api_model_sniff(stl, n) == API_MODEL_STL);
	struct api_problem p;
	struct api_scene *s = parse_model(stl, n, ",'cast_shadows':false,'double_sided':false", &p);
	REQUIRE(s, "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	const struct rnd_scene *sc = &s->scene;
	REQUIRE(sc->object_count == 1, "%u objects", sc->object_count);
	CHECK(triangles(sc) == 4, "%llu triangles", (unsigned long long)triangles(sc));
	CHECK(sc->objects[0].cast_shadows == false && sc->objects[0].double_sided == false &&
	      sc->objects[0].receive_shadows == true);
	struct rnd_aabb b = bounds(sc);
	CHECK(near_f(b.min[0], 0) && near_f(b.max[0], 1) && near_f(b.max[1], 1) && near_f(b.max[2], 1));
	api_scene_free(s);
}

TEST(model_glb_quad_texture_mask)
{
	size_t n;
	uint8_t *glb = quad_glb(&n);
	REQUIRE(glb);
	CHECK(api_model_sniff(glb, n) == API_MODEL_GLB);
	struct api_problem p;
	/* object scale 2 over the node's translation (0,2,0): y spans 2*(2-1) .. 2*(2+1) */
	struct api_scene *s = parse_model(glb, n, ",'transform':{'scale':[2,2,2]}", &p);
	REQUIRE(s, "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	const struct rnd_scene *sc = &s->scene;
	REQUIRE(sc->object_count == 1, "%u objects", sc->object_count);
	const struct rnd_object *o = &sc->objects[0];
	CHECK(o->vertex_count == 4 && o->index_count == 6, "%u vertices %u indices", o->vertex_count, o->index_count);
	struct rnd_aabb b = bounds(sc);
	CHECK(near_f(b.min[1], 2) && near_f(b.max[1], 6) && near_f(b.min[0], -2) && near_f(b.max[0], 2),
	      "bounds x %g..%g y %g..%g", b.min[0], b.max[0], b.min[1], b.max[1]);
	REQUIRE(o->uvs && o->normals);
	/* glTF uv convention kept: the vertex at (-1,-1) has uv (0,1). */
	for (uint32_t v = 0; v < o->vertex_count; v++) {
		const float *q = o->positions + 3 * v, *t = o->uvs + 2 * v;
		if (near_f(q[0], -1) && near_f(q[1], -1)) CHECK(near_f(t[0], 0) && near_f(t[1], 1), "uv %g %g", t[0], t[1]);
		if (near_f(q[0], 1) && near_f(q[1], 1)) CHECK(near_f(t[0], 1) && near_f(t[1], 0), "uv %g %g", t[0], t[1]);
		CHECK(near_f(o->normals[3 * v + 2], 1));
	}
	REQUIRE(o->material < sc->material_count);
	const struct rnd_material *m = &sc->materials[o->material];
	CHECK(near_f(m->base_color[0], 0.5f) && near_f(m->base_color[1], 0.25f) && near_f(m->base_color[2], 1) &&
	      near_f(m->base_color[3], 1), "base %g %g %g %g", m->base_color[0], m->base_color[1], m->base_color[2],
	      m->base_color[3]);
	CHECK(near_f(m->metallic, 0.3f) && near_f(m->roughness, 0.7f), "metallic %g roughness %g", m->metallic,
	      m->roughness);
	CHECK(m->alpha_mode == RND_ALPHA_MASK && near_f(m->alpha_cutoff, 0.4f), "mode %d cutoff %g", m->alpha_mode,
	      m->alpha_cutoff);
	REQUIRE(m->base_color_texture);
	CHECK(m->base_color_texture->width == 2 && m->base_color_texture->height == 2);
	CHECK(!memcmp(m->base_color_texture->rgba, TEX, sizeof TEX), "texels differ");
	/* Its mip chain built once with the model, as the base colour slot reads it (sRGB). */
	uint8_t chain[4 * (4 + 1)];
	rnd_texture_build_chain(TEX, 2, 2, true, chain);
	CHECK(m->base_color_texture->chain && m->base_color_texture->chain_srgb &&
	      !memcmp(m->base_color_texture->chain, chain + 16, 4), "no chain, or not the sRGB chain's level 1");
	api_scene_free(s);

	/* The object's own material replaces the model's. */
	s = parse_model(glb, n, ",'material':'grey'", &p);
	REQUIRE(s, "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	CHECK(near_f(s->scene.materials[s->scene.objects[0].material].base_color[0], 0.5f) &&
	      s->scene.materials[s->scene.objects[0].material].base_color_texture == NULL);
	api_scene_free(s);
	free(glb);
}

TEST(model_corrupt_bytes)
{
	struct api_problem p;
	uint8_t junk[300];
	for (size_t i = 0; i < sizeof junk; i++) junk[i] = (uint8_t)(i * 37 + 11);
	static const char *const fmts[] = {",'format':'glb'", ",'format':'gltf'", ",'format':'obj'", ",'format':'stl'",
	                                   ",'format':'ply'", ""};
	for (int i = 0; i < 6; i++) {
		struct api_scene *s = parse_model(junk, sizeof junk, fmts[i], &p);
		CHECK(!s && p.status == 400 && !strcmp(p.pointer, "/objects/0/data"), "%s: %d %s: %s", fmts[i],
		      p.status, p.pointer, p.detail);
		api_scene_free(s);
	}
	/* A glb cut short, a glb with a broken header, a glb whose texture is not an image */
	size_t n;
	uint8_t *glb = quad_glb(&n);
	REQUIRE(glb);
	struct api_scene *s = parse_model(glb, n / 2, "", &p);
	CHECK(!s && p.status == 400 && strstr(p.detail, "could not be imported"), "%d %s", p.status, p.detail);
	api_scene_free(s);
	test_put32(glb + 12, (uint32_t)n * 2);   /* JSON chunk longer than the file */
	s = parse_model(glb, n, "", &p);
	CHECK(!s && p.status == 400, "%d %s", p.status, p.detail);
	api_scene_free(s);
	uint8_t save = glb[20];
	test_put32(glb + 12, (uint32_t)(n - 40));
	glb[20] = '[';                        /* JSON that is not an object */
	s = parse_model(glb, n, "", &p);
	CHECK(!s && p.status == 400, "%d %s", p.status, p.detail);
	api_scene_free(s);
	free(glb);
	glb = quad_glb(&n);
	REQUIRE(glb);
	(void)save;
	/* an image that is not PNG/JPEG: Assimp 5.2 crashes on it unless checked first */
	uint8_t *mt = memmem(glb, n, "image/png", 9);
	REQUIRE(mt);
	memcpy(mt, "image/gif", 9);
	s = parse_model(glb, n, "", &p);
	CHECK(!s && p.status == 400 && strstr(p.detail, "PNG or JPEG"), "%d %s", p.status, p.detail);
	api_scene_free(s);
	memcpy(mt, "image/png", 9);
	memset(glb + n - 40, 0x5a, 30);    /* inside the PNG */
	s = parse_model(glb, n, ",'name':'chair'", &p);
	CHECK(!s && p.status == 400 && strstr(p.detail, "\"chair\""), "%d %s", p.status, p.detail);
	api_scene_free(s);
	free(glb);
	/* text that is no model */
	const char *txt = "hello world\n";
	s = parse_model((const uint8_t *)txt, strlen(txt), "", &p);
	CHECK(!s && p.status == 400 && strstr(p.detail, "format"), "%d %s", p.status, p.detail);
	api_scene_free(s);
}

TEST(model_triangle_limit)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.max_triangles = 11;
	char *doc = model_doc((const uint8_t *)CUBE_OBJ, strlen(CUBE_OBJ), "");
	struct api_problem p;
	struct api_scene *s = parse_lim(doc, &lim, &p);
	CHECK(!s && p.status == 422 && strstr(p.detail, "12 triangles"), "%d %s", p.status, p.detail);
	api_scene_free(s);
	free(doc);
}

static void write_file(const char *path, const void *d, size_t n)
{
	FILE *f = fopen(path, "wb");
	if (f) {
		fwrite(d, 1, n, f);
		fclose(f);
	}
}

static struct api_scene *parse_path(const char *path, const char *root, struct api_problem *p)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = root;
	char doc[1024];
	snprintf(doc, sizeof doc, "{\"camera\":{\"position\":[0,0,5]},\"objects\":[{\"shape\":\"model\",\"path\":\"%s\"}]}",
	         path);
	return parse_lim(doc, &lim, p);
}

TEST(model_path_asset_root)
{
	char base[] = "/tmp/umbra-model-XXXXXX";
	REQUIRE(mkdtemp(base));
	char root[300], out[300], f[400];
	snprintf(root, sizeof root, "%s/root", base);
	snprintf(out, sizeof out, "%s/outside", base);
	mkdir(root, 0700);
	mkdir(out, 0700);
	snprintf(f, sizeof f, "%s/sub", root);
	mkdir(f, 0700);
	snprintf(f, sizeof f, "%s/sub/cube.obj", root);
	write_file(f, CUBE_OBJ, strlen(CUBE_OBJ));
	snprintf(f, sizeof f, "%s/secret.obj", out);
	write_file(f, CUBE_OBJ, strlen(CUBE_OBJ));
	char link[400];
	snprintf(link, sizeof link, "%s/escape.obj", root);
	CHECK(symlink(f, link) == 0);
	snprintf(link, sizeof link, "%s/inside.obj", root);
	CHECK(symlink("sub/cube.obj", link) == 0);
	snprintf(link, sizeof link, "%s/up", root);
	CHECK(symlink("..", link) == 0);

	struct api_problem p;
	struct api_scene *s = parse_path("sub/cube.obj", root, &p);
	CHECK(s && s->scene.object_count == 1 && s->triangles == 12, "%d %s: %s", p.status, p.pointer, p.detail);
	api_scene_free(s);
	s = parse_path("inside.obj", root, &p);
	CHECK(s != NULL, "a link inside the root: %d %s", p.status, p.detail);
	api_scene_free(s);

	static const char *const bad[] = {"../outside/secret.obj", "sub/../../outside/secret.obj", "/etc/passwd",
	                                  "escape.obj", "up/outside/secret.obj", "missing.obj", "sub"};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		s = parse_path(bad[i], root, &p);
		CHECK(!s && p.status == 400 && !strcmp(p.pointer, "/objects/0/path"), "%s: %d %s: %s", bad[i], p.status,
		      p.pointer, p.detail);
		api_scene_free(s);
	}
	s = parse_path("escape.obj", root, &p);
	CHECK(!s && strstr(p.detail, "leaves the asset root"), "%s", p.detail);
	s = parse_path("sub/cube.obj", NULL, &p);
	CHECK(!s && p.status == 400 && strstr(p.detail, "no asset root configured") &&
	      !strcmp(p.pointer, "/objects/0/path"), "%d %s: %s", p.status, p.pointer, p.detail);

	char cmd[400];
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", base);
	CHECK(system(cmd) == 0);
}

TEST(model_parts)
{
	uint8_t stl[284];
	size_t n = tetra_stl(stl);
	struct api_part parts[2] = {{"other", (const uint8_t *)"x", 1}, {"mesh", stl, n}};
	const char *doc = "{\"camera\":{\"position\":[0,0,5]},\"objects\":[{\"shape\":\"model\",\"part\":\"mesh\"}]}";
	struct api_scene *s = NULL;
	struct api_problem p;
	CHECK(api_scene_parse_parts(doc, strlen(doc), NULL, parts, 2, &s, &p) == API_OK, "%d %s", p.status, p.detail);
	CHECK(s && triangles(&s->scene) == 4);
	api_scene_free(s);
	s = NULL;
	CHECK(api_scene_parse(doc, strlen(doc), NULL, &s, &p) == API_ERR && p.status == 400 &&
	      !strcmp(p.pointer, "/objects/0/part"), "%d %s: %s", p.status, p.pointer, p.detail);
}

TEST(model_cache)
{
	/* Bytes no other test uses: a comment makes this cube unique. */
	char obj[sizeof CUBE_OBJ + 32];
	snprintf(obj, sizeof obj, "# cache test\n%s", CUBE_OBJ);
	uint64_t h0, m0, h1, m1, bytes;
	api_model_cache_set_limit(DEFAULT_CACHE);   /* the bound is process-wide: other tests change it */
	api_model_cache_stats(&h0, &m0, NULL);
	struct api_problem p;
	struct api_scene *a = parse_model((const uint8_t *)obj, strlen(obj), "", &p);
	REQUIRE(a, "%d %s", p.status, p.detail);
	struct api_scene *b = parse_model((const uint8_t *)obj, strlen(obj), ",'transform':{'translation':[1,2,3]}", &p);
	REQUIRE(b, "%d %s", p.status, p.detail);
	api_model_cache_stats(&h1, &m1, &bytes);
	CHECK(h1 == h0 + 1 && m1 == m0 + 1, "hits %llu->%llu misses %llu->%llu", (unsigned long long)h0,
	      (unsigned long long)h1, (unsigned long long)m0, (unsigned long long)m1);
	CHECK(bytes > 0);
	/* Same geometry arrays: shared, not copied. */
	CHECK(a->scene.objects[0].positions == b->scene.objects[0].positions);
	/* Eviction while scenes use the model: their arrays stay valid until api_scene_free. */
	api_model_cache_clear();
	api_model_cache_stats(NULL, NULL, &bytes);
	CHECK(bytes == 0);
	struct rnd_aabb bb = bounds(&b->scene);
	CHECK(near_f(bb.min[0], 0) && near_f(bb.max[2], 4));
	api_scene_free(a);
	api_scene_free(b);

	/* A cache too small for the model: imported every time, nothing kept. */
	struct api_limits lim;
	api_limits_defaults(&lim);
	api_model_cache_set_limit(16);
	char *doc = model_doc((const uint8_t *)obj, strlen(obj), "");
	api_model_cache_stats(&h0, &m0, NULL);
	for (int i = 0; i < 2; i++) {
		struct api_scene *s = parse_lim(doc, &lim, &p);
		CHECK(s != NULL);
		api_scene_free(s);
	}
	api_model_cache_stats(&h1, &m1, &bytes);
	CHECK(h1 == h0 && m1 == m0 + 2 && bytes == 0);
	free(doc);

	/* LRU: a cache that fits one model evicts the older one. */
	char obj2[sizeof obj + 32];
	snprintf(obj2, sizeof obj2, "# another\n%s", obj);
	struct api_model *m_a, *m_b, *m_c;
	char err[256];
	int st;
	api_model_cache_set_limit(1u << 20);
	REQUIRE(api_model_get((const uint8_t *)obj, strlen(obj), API_MODEL_OBJ, &lim, &m_a, &st, err, sizeof err) == API_OK);
	uint64_t one;
	api_model_cache_stats(NULL, NULL, &one);
	api_model_cache_set_limit(one + one / 2);
	REQUIRE(api_model_get((const uint8_t *)obj2, strlen(obj2), API_MODEL_OBJ, &lim, &m_b, &st, err, sizeof err) ==
	        API_OK);
	api_model_cache_stats(&h0, &m0, &bytes);
	CHECK(bytes < 2 * one && bytes >= one, "bytes %llu one %llu", (unsigned long long)bytes, (unsigned long long)one);
	REQUIRE(api_model_get((const uint8_t *)obj2, strlen(obj2), API_MODEL_OBJ, &lim, &m_c, &st, err, sizeof err) ==
	        API_OK);
	api_model_cache_stats(&h1, NULL, NULL);
	CHECK(h1 == h0 + 1 && m_c == m_b);
	CHECK(m_a->triangles == 12);   /* evicted, still ours */
	api_model_release(m_a);
	api_model_release(m_b);
	api_model_release(m_c);
	api_model_cache_clear();
	api_model_cache_set_limit(DEFAULT_CACHE);
}

/* Lowering the process-wide bound evicts at once; models in use stay valid. */
TEST(model_cache_limit_is_global)
{
	char obj[sizeof CUBE_OBJ + 32];
	snprintf(obj, sizeof obj, "# global limit\n%s", CUBE_OBJ);
	api_model_cache_clear();
	api_model_cache_set_limit(DEFAULT_CACHE);
	struct api_model *m = NULL, *m2 = NULL;
	char err[256];
	int st;
	REQUIRE(api_model_get((const uint8_t *)obj, strlen(obj), API_MODEL_OBJ, NULL, &m, &st, err, sizeof err) == API_OK);
	uint64_t bytes, h0, h1;
	api_model_cache_stats(&h0, NULL, &bytes);
	CHECK(bytes > 0, "cached under the default bound");
	api_model_cache_set_limit(0);
	api_model_cache_stats(NULL, NULL, &bytes);
	CHECK(bytes == 0, "%llu bytes left after the bound went to 0", (unsigned long long)bytes);
	CHECK(m->triangles == 12, "still ours after eviction");
	REQUIRE(api_model_get((const uint8_t *)obj, strlen(obj), API_MODEL_OBJ, NULL, &m2, &st, err, sizeof err) == API_OK);
	api_model_cache_stats(&h1, NULL, &bytes);
	CHECK(h1 == h0 && bytes == 0 && m2 != m, "bound 0: imported again, not kept");
	api_model_release(m);
	api_model_release(m2);
	api_model_cache_set_limit(DEFAULT_CACHE);
}

struct stress_arg {
	const uint8_t *data[3];
	size_t len[3];
	int failures;
};

static void *stress(void *p)
{
	struct stress_arg *a = p;
	struct api_limits lim;
	api_limits_defaults(&lim);
	uint64_t one;
	api_model_cache_stats(NULL, NULL, &one);
	for (int i = 0; i < 60; i++) {
		int k = i % 3;
		char *doc = model_doc(a->data[k], a->len[k], "");
		struct api_problem pr;
		struct api_scene *s = parse_lim(doc, &lim, &pr);
		free(doc);
		if (!s || !s->scene.object_count) { a->failures++; api_scene_free(s); continue; }
		/* read every vertex while other threads evict */
		struct rnd_aabb b = bounds(&s->scene);
		if (!(b.max[0] >= b.min[0])) a->failures++;
		api_scene_free(s);
		if (i % 17 == 0) api_model_cache_clear();
	}
	return NULL;
}

TEST(model_cache_threads)
{
	uint8_t stl[284];
	size_t ns = tetra_stl(stl), ng;
	uint8_t *glb = quad_glb(&ng);
	REQUIRE(glb);
	struct stress_arg args[6];
	pthread_t th[6];
	api_model_cache_set_limit(9000);   /* about one model: constant eviction */
	for (int t = 0; t < 6; t++) {
		args[t] = (struct stress_arg){{(const uint8_t *)CUBE_OBJ, stl, glb}, {strlen(CUBE_OBJ), ns, ng}, 0};
		CHECK(pthread_create(&th[t], NULL, stress, &args[t]) == 0);
	}
	for (int t = 0; t < 6; t++) {
		pthread_join(th[t], NULL);
		CHECK(args[t].failures == 0, "thread %d: %d failures", t, args[t].failures);
	}
	free(glb);
	api_model_cache_clear();
	api_model_cache_set_limit(DEFAULT_CACHE);
	uint64_t bytes;
	api_model_cache_stats(NULL, NULL, &bytes);
	CHECK(bytes == 0);
}

/* What of a file's material the renderer does not do is listed, never dropped silently: an
 * unknown extension, a texture on a second uv set the mesh lacks and one on a third set come
 * back as the scene's warnings (the Umbra-Warnings header), each under the pointer of the
 * object that brought them; a file without such things has none. */
TEST(model_glb_unsupported_material_data_warned)
{
	size_t n;
	uint8_t *glb = quad_glb_ex(",\"texCoord\":1", ",\"extensionsUsed\":[\"KHR_materials_iridescence\"]", &n);
	REQUIRE(glb);
	struct api_problem p;
	struct api_scene *s = parse_model(glb, n, "", &p);
	free(glb);
	REQUIRE(s, "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	const char *w = s->warnings;
	CHECK(!strncmp(w, "/objects/0: ", 12) && strstr(w, "KHR_materials_iridescence") &&
	      strstr(w, "baseColorTexture reads TEXCOORD_1, which the mesh lacks: drawn with TEXCOORD_0"),
	      "warnings: %s", w[0] ? w : "(none)");
	api_scene_free(s);
	/* a third uv set: the renderer has two */
	glb = quad_glb_ex(",\"texCoord\":2", "", &n);
	REQUIRE(glb);
	s = parse_model(glb, n, "", &p);
	free(glb);
	REQUIRE(s, "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	CHECK(strstr(s->warnings, "baseColorTexture reads TEXCOORD_2, drawn with TEXCOORD_0"), "warnings: %s",
	      s->warnings[0] ? s->warnings : "(none)");
	api_scene_free(s);
	glb = quad_glb(&n);
	REQUIRE(glb);
	s = parse_model(glb, n, "", &p);
	free(glb);
	REQUIRE(s, "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	CHECK(!s->warnings[0], "warnings: %s", s->warnings);
	api_scene_free(s);
}
