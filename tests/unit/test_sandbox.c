/* tests — the sandboxed importer (api/sandbox.h) and the decoder of its replies
 * (api/model_wire.h): files that crash or hang Assimp become 400/422 for that model while other
 * imports go on; memory limit; FIFOs under the asset root; malformed replies refused. Every
 * input is built here. */
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>
#include "api.h"
#include "arena.h"
#include "model.h"
#include "model_wire.h"
#include "sandbox.h"
#include "sandbox_stats.h"
#include "test.h"
#include "util.h"

/* ---- inputs ---- */

#define PLY_HEADER "ply\nformat %s 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n" \
                   "element face 2\nproperty list uchar int vertex_indices\n%s\n"

/* An ASCII PLY whose end_header is misspelled: Assimp 5.2 reads it for ever. */
static size_t ply_hanging(char *buf, size_t n)
{
	int k = snprintf(buf, n, PLY_HEADER "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n", "ascii", "end_headr");
	return (size_t)k;
}

/* A binary PLY whose end_header keyword is damaged ("end_heade\x8a"): Assimp 5.2 dereferences
 * a bad pointer reading it (found by mutating the valid file below). */
static size_t ply_crashing(uint8_t *buf, size_t n)
{
	int k = snprintf((char *)buf, n, PLY_HEADER, "binary_little_endian", "end_heade\x8a");
	size_t at = (size_t)k;
	const float v[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
	memcpy(buf + at, v, sizeof v);
	at += sizeof v;
	const int32_t f[2][3] = {{0, 1, 2}, {0, 2, 3}};
	for (int i = 0; i < 2; i++) {
		buf[at++] = 3;
		memcpy(buf + at, f[i], 12);
		at += 12;
	}
	return at;
}

static const char OBJ_TRI[] = "v -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nf 1 2 3\n";

/* Binary STL of n triangles (a strip of slivers, all distinct vertices). */
static uint8_t *stl_triangles(uint32_t n, size_t *len)
{
	*len = 84 + (size_t)n * 50;
	uint8_t *d = calloc(1, *len);
	memcpy(d + 80, &n, 4);
	for (uint32_t i = 0; i < n; i++) {
		float t[12] = {0, 0, 1, (float)i, 0, 0, (float)i + 1, 0, 0, (float)i, 1, (float)(i % 7)};
		memcpy(d + 84 + (size_t)i * 50, t, sizeof t);
	}
	return d;
}

static struct api_limits limits(uint32_t timeout_ms)
{
	struct api_limits l;
	api_limits_defaults(&l);
	api_model_cache_set_limit(0);   /* every import runs in the sandbox (model_cache sets it back) */
	l.import_timeout_ms = timeout_ms;
	return l;
}

/* ---- crash, hang, no global lock ---- */

/* ended[model][how] - before (api/sandbox_stats.h); the tests run one at a time. */
static uint64_t ended_since(const struct api_sandbox_stats *before, enum api_sbx_outcome how)
{
	struct api_sandbox_stats now;
	api_sandbox_stats(&now);
	return now.ended[API_SBX_JOB_MODEL][how] - before->ended[API_SBX_JOB_MODEL][how];
}

TEST(sandbox_crashing_ply_is_400)
{
	uint8_t buf[1024];
	size_t n = ply_crashing(buf, sizeof buf);
	struct api_limits l = limits(20000);   /* wide: under ASan the helper's crash report takes seconds */
	struct api_model *m = NULL;
	char err[400];
	int st = 0;
	struct api_sandbox_stats s0, s1;
	api_sandbox_stats(&s0);
	CHECK(api_model_get(buf, n, API_MODEL_PLY, &l, &m, &st, err, sizeof err) == API_ERR && !m);
	CHECK(st == 400, "status %d: %s", st, err);
	CHECK(ended_since(&s0, API_SBX_OUT_CRASHED) == 1, "counted as crashed");
	/* The process that asked is still here, and the next import works. */
	CHECK(api_model_get((const uint8_t *)OBJ_TRI, strlen(OBJ_TRI), API_MODEL_OBJ, &l, &m, &st, err, sizeof err) ==
	      API_OK, "%s", err);
	CHECK(m && m->triangles == 1);
	api_model_release(m);
	api_sandbox_stats(&s1);
	CHECK(ended_since(&s0, API_SBX_OUT_OK) == 1 && s1.started[API_SBX_JOB_MODEL] - s0.started[API_SBX_JOB_MODEL] == 2);
	CHECK(s1.job_seconds[API_SBX_JOB_MODEL].count - s0.job_seconds[API_SBX_JOB_MODEL].count == 2);
	CHECK(s1.stage_seconds[API_IMPORT_PARSE].count - s0.stage_seconds[API_IMPORT_PARSE].count == 1,
	      "the stages of the one import that succeeded");
}

struct hang_arg {
	atomic_int done;
	int status;
	enum api_result rc;
	char err[400];
};

static void *import_hanging(void *p)
{
	struct hang_arg *a = p;
	char buf[1024];
	size_t n = ply_hanging(buf, sizeof buf);
	struct api_limits l = limits(3000);
	struct api_model *m = NULL;
	a->rc = api_model_get((const uint8_t *)buf, n, API_MODEL_PLY, &l, &m, &a->status, a->err, sizeof a->err);
	api_model_release(m);
	atomic_store(&a->done, 1);
	return NULL;
}

/* A hanging import ends as a 422 at its time limit; meanwhile another import (same process,
 * another thread) completes: no lock is held across an import. */
TEST(sandbox_hanging_ply_is_422_and_others_go_on)
{
	struct hang_arg a = {0};
	pthread_t t;
	REQUIRE(pthread_create(&t, NULL, import_hanging, &a) == 0);
	/* Let the hanging import get under way first: a lock held across imports would then make
	 * the one below wait (without the pause it could win the race and hide such a lock). */
	struct timespec pause = {0, 300 * 1000 * 1000};
	nanosleep(&pause, NULL);
	struct api_limits l = limits(5000);
	struct api_model *m = NULL;
	char err[400];
	int st;
	/* Different bytes from every other test, so this is a real import, not a cache hit. */
	static const char obj[] = "v -2 0 -1\nv 1 0 -1\nv 0 1.5 0\nf 1 2 3\n";
	enum api_result rc = api_model_get((const uint8_t *)obj, strlen(obj), API_MODEL_OBJ, &l, &m, &st, err, sizeof err);
	int hang_done_when_ok = atomic_load(&a.done);
	CHECK(rc == API_OK && m && m->triangles == 1, "%s", err);
	CHECK(!hang_done_when_ok, "the other import waited for the hanging one");
	api_model_release(m);
	pthread_join(t, NULL);
	CHECK(a.rc == API_ERR && a.status == 422 && strstr(a.err, "time limit"), "status %d: %s", a.status, a.err);
	/* The CLI's limits (no import_flags): it says that umbra-render has no option, and umbrad's. */
	CHECK(strstr(a.err, "umbra-render, which has no option for it; umbrad sets it with --import-timeout-ms"), "%s",
	      a.err);
}

TEST(sandbox_memory_limit_is_422)
{
	if (API_SBX_SANITIZED) return; /* no RLIMIT_AS under the sanitizers (see api/sandbox.h) */
	size_t n;
	uint8_t *stl = stl_triangles(400000, &n);
	struct api_limits l = limits(20000);
	l.import_memory = 64u << 20;
	struct api_model *m = NULL;
	char err[400];
	int st;
	struct api_sandbox_stats s0;
	api_sandbox_stats(&s0);
	CHECK(api_model_get(stl, n, API_MODEL_STL, &l, &m, &st, err, sizeof err) == API_ERR && !m);
	CHECK(st == 422 && strstr(err, "memory limit"), "status %d: %s", st, err);
	CHECK(strstr(err, "umbrad sets it with --import-memory"), "%s", err);
	CHECK(ended_since(&s0, API_SBX_OUT_OVER_MEMORY) == 1, "counted as over memory");
	l.import_flags = true;   /* umbrad's: its own flag named */
	CHECK(api_model_get(stl, n, API_MODEL_STL, &l, &m, &st, err, sizeof err) == API_ERR && st == 422 &&
	      strstr(err, "(this server's --import-memory)"), "%d %s", st, err);
	/* The same file under the default limit imports. */
	l.import_memory = 0;
	CHECK(api_model_get(stl, n, API_MODEL_STL, &l, &m, &st, err, sizeof err) == API_OK, "%d %s", st, err);
	CHECK(m && m->triangles == 400000);
	api_model_release(m);
	free(stl);
}

/* A malformed ASCII STL (a facet of two vertices): Assimp 5.2's STL importer throws without
 * freeing the mesh and node it allocated (~2.4 KB per import; LeakSanitizer in make test-asan
 * saw it in this process before imports moved into the sandbox). Now the child that leaked is
 * gone after the import and this process has nothing to leak. */
TEST(sandbox_malformed_ascii_stl_is_400_without_leak)
{
	static const char stl[] = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n"
	                          "endfacet\nendsolid x\n";
	struct api_limits l = limits(5000);
	for (int i = 0; i < 4; i++) {
		struct api_model *m = NULL;
		char err[400];
		int st;
		CHECK(api_model_get((const uint8_t *)stl, strlen(stl), API_MODEL_STL, &l, &m, &st, err, sizeof err) == API_ERR);
		CHECK(st == 400 && !m, "status %d: %s", st, err);
	}
}

TEST(sandbox_image_decode)
{
	struct api_limits l = limits(5000);
	uint8_t *px = NULL;
	uint32_t w, h;
	char err[300];
	int st;
	static const uint8_t not_png[] = "\x89PNG\r\n\x1a\nthis is no png at all";
	CHECK(api_sandbox_decode_image(not_png, sizeof not_png, 0, &l, &px, &w, &h, &st, err, sizeof err) == API_ERR);
	CHECK(st == 400 && !px, "status %d: %s", st, err);
}

/* ---- scene documents: the pointer names the member ---- */


static char *scene_with(const char *model_member)
{
	static const char fmt[] =
		"{\"width\": 16, \"height\": 16, \"camera\": {\"type\": \"perspective\", \"position\": [3, 3, 3], "
		"\"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 40}, \"objects\": [{\"shape\": \"box\"}, "
		"{\"shape\": \"model\", %s}], \"lights\": [{\"type\": \"directional\", \"direction\": [0, -1, 0]}]}";
	size_t n = sizeof fmt + strlen(model_member);
	char *s = malloc(n);
	snprintf(s, n, fmt, model_member);
	return s;
}

TEST(sandbox_scene_crash_and_hang_pointers)
{
	/* The crash with sandbox_crashing_ply_is_400's limit: a crash is told from a timeout by how the
	 * helper ended, and under ASan the helper's report alone takes 2-6 s on a loaded machine. */
	struct api_limits l = limits(20000);
	uint8_t buf[1024];
	size_t n = ply_crashing(buf, sizeof buf);
	char *enc = test_b64(buf, n), member[2048];
	snprintf(member, sizeof member, "\"data\": \"%s\", \"format\": \"ply\"", enc);
	free(enc);
	char *doc = scene_with(member);
	struct api_scene *s = NULL;
	struct api_problem p;
	CHECK(api_scene_parse(doc, strlen(doc), &l, &s, &p) == API_ERR && !s);
	CHECK(p.status == 400 && !strcmp(p.pointer, "/objects/1/data"), "%d %s: %s", p.status, p.pointer, p.detail);
	free(doc);

	n = ply_hanging((char *)buf, sizeof buf);
	l = limits(1000);   /* the hang takes the whole limit */
	enc = test_b64(buf, n);
	snprintf(member, sizeof member, "\"data\": \"%s\"", enc);
	free(enc);
	doc = scene_with(member);
	CHECK(api_scene_parse(doc, strlen(doc), &l, &s, &p) == API_ERR && !s);
	CHECK(p.status == 422 && !strcmp(p.pointer, "/objects/1/data"), "%d %s: %s", p.status, p.pointer, p.detail);
	free(doc);
}

/* A FIFO under the asset root: refused at once (opening it used to wait for a writer). */
TEST(sandbox_asset_fifo_is_400)
{
	char dir[] = "/tmp/umbra-fifo.XXXXXX", fifo[64];
	REQUIRE(mkdtemp(dir));
	snprintf(fifo, sizeof fifo, "%s/pipe.obj", dir);
	REQUIRE(mkfifo(fifo, 0600) == 0);
	struct api_limits l = limits(1000);
	l.asset_root = dir;
	char *doc = scene_with("\"path\": \"pipe.obj\"");
	struct api_scene *s = NULL;
	struct api_problem p;
	CHECK(api_scene_parse(doc, strlen(doc), &l, &s, &p) == API_ERR && !s);
	CHECK(p.status == 400 && !strcmp(p.pointer, "/objects/1/path") && strstr(p.detail, "not a regular file"),
	      "%d %s: %s", p.status, p.pointer, p.detail);
	free(doc);
	unlink(fifo);
	rmdir(dir);
}

/* ---- the reply decoder ---- */

static void wire_model(struct api_wire_buf *b, uint32_t index2, float x0)
{
	static uint8_t px[2 * 2 * 4] = {255, 0, 0, 255};
	static struct rnd_texture tex = {px, 2, 2};
	float pos[9] = {x0, 0, 0, 1, 0, 0, 0, 1, 0}, nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1}, uv[6] = {0};
	uint32_t idx[3] = {0, 1, index2};
	struct rnd_material mat;
	rnd_material_defaults(&mat);
	mat.base_color_texture = &tex;
	struct api_model_mesh mesh = {.positions = pos, .normals = nrm, .uvs = uv, .indices = idx, .vertex_count = 3,
	                              .index_count = 3, .material = 0};
	struct api_model_instance inst = {0, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
	struct api_model m = {.meshes = &mesh, .mesh_count = 1, .instances = &inst, .instance_count = 1,
	                      .materials = &mat, .material_count = 1};
	api_wire_put_header(b, API_WIRE_MODEL, API_WIRE_OK, NULL);
	api_wire_put_model(b, &m);
}

/* Decoded both ways (copied, and in place): the same answer, or API_ERR with err. */
static enum api_result decode(const uint8_t *d, size_t n, struct api_model *m, char *err, size_t errsize)
{
	enum api_wire_kind k;
	enum api_wire_status st;
	const uint8_t *body;
	size_t blen, bytes;
	if (api_wire_header(d, n, &k, &st, NULL, 0, &body, &blen, err, errsize) != API_OK) return API_ERR;
	enum api_result rc[2];
	for (unsigned f = 0; f < 2; f++) {
		struct api_arena *a = api_arena_create();
		rc[f] = api_wire_decode_model(body, blen, f ? API_WIRE_IN_PLACE : 0, a, 1u << 20, m, &bytes, err, errsize);
		api_arena_destroy(a); /* m's arrays die here: callers look only at counts */
	}
	CHECK(rc[0] == rc[1], "copied %d, in place %d", rc[0], rc[1]);
	return rc[1];
}

TEST(sandbox_reply_decoder_refuses_malformed)
{
	struct api_wire_buf b = {0};
	wire_model(&b, 2, 0);
	REQUIRE(!b.failed);
	struct api_model m;
	char err[300];
	CHECK(decode(b.data, b.len, &m, err, sizeof err) == API_OK, "%s", err);
	CHECK(m.mesh_count == 1 && m.instance_count == 1 && m.material_count == 1 && m.triangles == 1);
	/* Every truncation, and one byte too many, is refused. */
	int accepted = 0;
	for (size_t cut = 0; cut < b.len; cut++) accepted += decode(b.data, cut, &m, err, sizeof err) == API_OK;
	CHECK(accepted == 0, "%d truncations accepted", accepted);
	uint8_t *longer = malloc(b.len + 1);
	memcpy(longer, b.data, b.len);
	longer[b.len] = 0;
	CHECK(decode(longer, b.len + 1, &m, err, sizeof err) == API_ERR);
	free(longer);
	/* Counts that lie: each of the four count fields set to 0xffffffff (after the header, the
	 * stage times and the texture sizes). */
	size_t counts = 24 + 16 + 8;
	for (int f = 0; f < 4; f++) {
		uint32_t save, lie = 0xffffffffu;
		memcpy(&save, b.data + counts + 4 * f, 4);
		memcpy(b.data + counts + 4 * f, &lie, 4);
		CHECK(decode(b.data, b.len, &m, err, sizeof err) == API_ERR, "count %d", f);
		memcpy(b.data + counts + 4 * f, &save, 4);
	}
	api_wire_buf_release(&b);
	/* Counts that fit 8 bytes an item but not the items' real wire sizes (an instance is 68
	 * bytes): refused at the counts, before arrays larger than the reply are allocated. */
	enum { BODY = 1 << 16 };
	uint8_t *body = calloc(1, BODY);
	REQUIRE(body);
	uint32_t lie_counts[4] = {0, 1, 1, BODY / 8 - 2};
	memcpy(body + 24, lie_counts, sizeof lie_counts);   /* after the stage times and texture sizes */
	struct api_arena *a = api_arena_create();
	size_t bytes;
	err[0] = 0;
	CHECK(api_wire_decode_model(body, BODY, 0, a, 1u << 20, &m, &bytes, err, sizeof err) == API_ERR &&
	      strstr(err, "0 textures, 1 materials, 1 meshes, 8190 instances"), "%s", err);
	api_arena_destroy(a);
	free(body);
	/* An index past the vertices, a NaN position. */
	wire_model(&b, 3, 0);
	CHECK(decode(b.data, b.len, &m, err, sizeof err) == API_ERR && strstr(err, "index"), "%s", err);
	api_wire_buf_release(&b);
	wire_model(&b, 2, NAN);
	CHECK(decode(b.data, b.len, &m, err, sizeof err) == API_ERR && strstr(err, "finite"), "%s", err);
	api_wire_buf_release(&b);
}

/* Indices 0..n-1 (an STL's corners) do not cross the wire (flag 512): the daemon counts them
 * out; a reply that claims them for a mesh whose index count is not its vertex count is refused. */
TEST(sandbox_reply_identity_indices)
{
	struct api_wire_buf id = {0}, other = {0};
	wire_model(&id, 2, 0);      /* indices 0 1 2 */
	wire_model(&other, 0, 0);   /* indices 0 1 0 */
	REQUIRE(!id.failed && !other.failed);
	CHECK(id.len + 12 == other.len, "identity %zu bytes, other %zu", id.len, other.len);
	const uint8_t *body;
	size_t blen, bytes;
	enum api_wire_kind k;
	enum api_wire_status st;
	char err[300];
	REQUIRE(api_wire_header(id.data, id.len, &k, &st, NULL, 0, &body, &blen, err, sizeof err) == API_OK, "%s", err);
	for (unsigned f = 0; f < 2; f++) {
		struct api_arena *a = api_arena_create();
		struct api_model m;
		REQUIRE(api_wire_decode_model(body, blen, f ? API_WIRE_IN_PLACE : 0, a, 1u << 20, &m, &bytes, err,
		                              sizeof err) == API_OK, "%s", err);
		const uint32_t *ix = m.meshes[0].indices;
		CHECK(m.meshes[0].index_count == 3 && ix[0] == 0 && ix[1] == 1 && ix[2] == 2);
		api_arena_destroy(a);
	}
	/* The mesh's counts (3 vertices, 3 indices, material 0, flags 1|2|512): index count 6 lies. */
	uint32_t head[4] = {3, 3, 0, 1 | 2 | 512};
	uint8_t *at = NULL;
	for (size_t o = 0; o + sizeof head <= id.len && !at; o += 4)
		if (!memcmp(id.data + o, head, sizeof head)) at = id.data + o;
	REQUIRE(at, "the mesh's counts are not on the wire");
	uint32_t six = 6;
	memcpy(at + 4, &six, 4);
	struct api_model m;
	CHECK(decode(id.data, id.len, &m, err, sizeof err) == API_ERR && strstr(err, "6 indices"), "%s", err);
	api_wire_buf_release(&id);
	api_wire_buf_release(&other);
}

/* A reply of 900 corners: the checks run in blocks of 256 there, and an index past the vertices
 * or a NaN deep inside a block (not in the tail) is refused as at the start. */
/* m written as a model reply into b, and its body found (api_wire_header): false with err. */
static bool wire_model_body(const struct api_model *m, struct api_wire_buf *b, const uint8_t **body, size_t *blen,
                            char *err, size_t errsize)
{
	enum api_wire_kind k;
	enum api_wire_status st;
	api_wire_put_header(b, API_WIRE_MODEL, API_WIRE_OK, NULL);
	api_wire_put_model(b, m);
	if (b->failed) return snprintf(err, errsize, "out of memory"), false;
	return api_wire_header(b->data, b->len, &k, &st, NULL, 0, body, blen, err, errsize) == API_OK;
}

static void wire_long(struct api_wire_buf *b, size_t bad_index_at, size_t nan_at)
{
	enum { NV = 900 };
	static float pos[NV * 3], nrm[NV * 3];
	static uint32_t idx[NV];
	for (uint32_t v = 0; v < NV; v++) {
		pos[3 * v] = (float)(v % 30);
		pos[3 * v + 1] = (float)(v / 30);
		pos[3 * v + 2] = (float)(v % 3);
		nrm[3 * v] = nrm[3 * v + 1] = 0.0f;
		nrm[3 * v + 2] = 1.0f;
		idx[v] = v;
	}
	if (bad_index_at < NV) idx[bad_index_at] = NV;
	if (nan_at < NV * 3) pos[nan_at] = NAN;
	struct rnd_material mat;
	rnd_material_defaults(&mat);
	struct api_model_mesh mesh = {.positions = pos, .normals = nrm, .indices = idx, .vertex_count = NV,
	                              .index_count = NV, .material = 0};
	struct api_model_instance inst = {0, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
	struct api_model m = {.meshes = &mesh, .mesh_count = 1, .instances = &inst, .instance_count = 1,
	                      .materials = &mat, .material_count = 1};
	api_wire_put_header(b, API_WIRE_MODEL, API_WIRE_OK, NULL);
	api_wire_put_model(b, &m);
}

TEST(sandbox_reply_decoder_checks_long_arrays_in_blocks)
{
	struct api_wire_buf b = {0};
	struct api_model m;
	char err[300];
	wire_long(&b, SIZE_MAX, SIZE_MAX);
	REQUIRE(!b.failed);
	CHECK(decode(b.data, b.len, &m, err, sizeof err) == API_OK && m.triangles == 300, "%s", err);
	api_wire_buf_release(&b);
	wire_long(&b, 700, SIZE_MAX);
	CHECK(decode(b.data, b.len, &m, err, sizeof err) == API_ERR && strstr(err, "index 700 refers to vertex 900"), "%s", err);
	api_wire_buf_release(&b);
	wire_long(&b, SIZE_MAX, 2000);
	CHECK(decode(b.data, b.len, &m, err, sizeof err) == API_ERR && strstr(err, "finite"), "%s", err);
	api_wire_buf_release(&b);
}

/* The second uv set (glTF TEXCOORD_1), in a mesh and in its level, and a slot's choice of it
 * cross the wire as they were; every truncation of such a reply is refused, and so is a uv1
 * that is not finite. */
TEST(sandbox_reply_second_uv_set_round_trip)
{
	static uint8_t px[2 * 2 * 4] = {255, 0, 0, 255};
	static struct rnd_texture tex = {px, 2, 2};
	float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, uv[8] = {0};
	float uv1[8] = {0.25f, 0.5f, 1, 0.5f, 0.25f, 1, 0, 0}, lv_uv1[6] = {0.5f, 0.75f, 1, 0, 0, 1};
	uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
	struct rnd_mesh_lod level = {pos, nrm, uv, idx, 3, 3, 0.5f, lv_uv1};
	struct rnd_material mat;
	rnd_material_defaults(&mat);
	mat.base_color_texture = mat.occlusion_texture = &tex;
	mat.sampling[RND_TEX_OCCLUSION].uv_set = 1;
	struct api_model_mesh mesh = {.positions = pos, .normals = nrm, .uvs = uv, .uvs1 = uv1, .indices = idx,
	                              .vertex_count = 4, .index_count = 6, .material = 0, .lods = &level, .lod_count = 1};
	struct api_model_instance inst = {0, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
	struct api_model m = {.meshes = &mesh, .mesh_count = 1, .instances = &inst, .instance_count = 1,
	                      .materials = &mat, .material_count = 1};
	for (int nan = 0; nan < 2; nan++) {
		uv1[3] = nan ? NAN : 0.5f;
		mat.sampling[RND_TEX_BASE].transform[0] = 1.0f;
		struct api_wire_buf b = {0};
		const uint8_t *body;
		size_t blen, bytes;
		char err[300];
		REQUIRE(wire_model_body(&m, &b, &body, &blen, err, sizeof err), "%s", err);
		struct api_arena *a = api_arena_create();
		struct api_model out;
		unsigned in_place = (unsigned)nan ^ 1u;   /* the good reply decoded in place, the bad one copied */
		enum api_result rc = api_wire_decode_model(body, blen, in_place, a, 1u << 20, &out, &bytes, err, sizeof err);
		if (nan) {
			CHECK(rc == API_ERR && strstr(err, "finite"), "a NaN uv1: %d %s", rc, err);
		} else {
			REQUIRE(rc == API_OK, "%s", err);
			CHECK(out.meshes[0].uvs1 && !memcmp(out.meshes[0].uvs1, uv1, sizeof uv1), "uvs1 changed on the wire");
			const uint8_t *u = (const uint8_t *)out.meshes[0].uvs1, *t = out.materials[0].base_color_texture->rgba;
			CHECK(u > body && u < body + blen && t > body && t < body + blen, "in place: the arrays are the reply's");
			CHECK(out.meshes[0].lod_count == 1 && out.meshes[0].lods[0].uvs1 &&
			      !memcmp(out.meshes[0].lods[0].uvs1, lv_uv1, sizeof lv_uv1), "the level's uvs1 changed on the wire");
			CHECK(out.materials[0].sampling[RND_TEX_OCCLUSION].uv_set == 1 &&
			      out.materials[0].sampling[RND_TEX_BASE].uv_set == 0, "uv sets %u %u",
			      out.materials[0].sampling[RND_TEX_BASE].uv_set, out.materials[0].sampling[RND_TEX_OCCLUSION].uv_set);
			int accepted = 0;
			for (size_t cut = 0; cut < b.len; cut++) {
				struct api_model part;
				accepted += decode(b.data, cut, &part, err, sizeof err) == API_OK;
			}
			CHECK(accepted == 0, "%d truncations accepted", accepted);
		}
		api_arena_destroy(a);
		api_wire_buf_release(&b);
	}
}

/* A level's vertex colours and tangents cross the wire as they were; a level with colours or
 * tangents for a mesh without them is refused (they could never be drawn: renderer/lod.c), and
 * so is a tangent that is not finite; every truncation of the good reply is refused. */
TEST(sandbox_reply_level_colours_and_tangents_round_trip)
{
	float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
	uint8_t col[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 9, 9, 9, 255};
	uint8_t lv_col[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
	float tan[16] = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
	float lv_tan[12] = {1, 0, 0, 1, 0.6f, 0.8f, 0, -1, 0, 1, 0, 1};
	uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
	struct rnd_mesh_lod level = {pos, nrm, NULL, idx, 3, 3, 0.5f, NULL, lv_col, lv_tan};
	struct rnd_material mat;
	rnd_material_defaults(&mat);
	struct api_model_mesh mesh = {.positions = pos, .normals = nrm, .indices = idx, .vertex_count = 4, .index_count = 6,
	                              .material = 0, .lods = &level, .lod_count = 1};
	struct api_model_instance inst = {0, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
	struct api_model m = {.meshes = &mesh, .mesh_count = 1, .instances = &inst, .instance_count = 1,
	                      .materials = &mat, .material_count = 1};
	/* 0: as it should be; 1: no colours on the mesh; 2: no tangents on it; 3: a NaN tangent */
	for (int k = 0; k < 4; k++) {
		mesh.colors = k == 1 ? NULL : col;
		mesh.tangents = k == 2 ? NULL : tan;
		lv_tan[5] = k == 3 ? NAN : 0.0f;
		struct api_wire_buf b = {0};
		const uint8_t *body;
		size_t blen, bytes;
		char err[300];
		REQUIRE(wire_model_body(&m, &b, &body, &blen, err, sizeof err), "%s", err);
		struct api_arena *a = api_arena_create();
		struct api_model out;
		enum api_result rc = api_wire_decode_model(body, blen, 0, a, 1u << 20, &out, &bytes, err, sizeof err);
		if (k) {
			CHECK(rc == API_ERR && strstr(err, "level 0"), "case %d: %d %s", k, rc, err);
		} else {
			REQUIRE(rc == API_OK, "%s", err);
			const struct rnd_mesh_lod *got = out.meshes[0].lod_count == 1 ? &out.meshes[0].lods[0] : NULL;
			CHECK(got && got->colors && !memcmp(got->colors, lv_col, sizeof lv_col) && got->tangents &&
			      !memcmp(got->tangents, lv_tan, sizeof lv_tan), "the level's colours or tangents changed on the wire");
			int accepted = 0;
			for (size_t cut = 0; cut < b.len; cut++) {
				struct api_model part;
				accepted += decode(b.data, cut, &part, err, sizeof err) == API_OK;
			}
			CHECK(accepted == 0, "%d truncations accepted", accepted);
		}
		api_arena_destroy(a);
		api_wire_buf_release(&b);
	}
}

/* A binary STL whose stored facet normal opposes its winding (common from some exporters):
 * the normal follows the winding (counter-clockwise seen from the front, as glTF and the
 * renderer's culling assume), so the model is not shaded from behind. */
TEST(sandbox_stl_normals_follow_the_winding)
{
	uint8_t d[84 + 50] = {0};
	uint32_t one = 1;
	memcpy(d + 80, &one, 4);
	/* Triangle in the z = 0 plane, counter-clockwise seen from +z; stored normal -z. */
	float t[12] = {0, 0, -1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
	memcpy(d + 84, t, sizeof t);
	struct api_limits l = limits(5000);
	struct api_model *m = NULL;
	char err[400];
	int st;
	REQUIRE(api_model_get(d, sizeof d, API_MODEL_STL, &l, &m, &st, err, sizeof err) == API_OK && m, "%s", err);
	REQUIRE(m->mesh_count == 1 && m->meshes[0].vertex_count >= 3);
	int up = 0;
	for (uint32_t v = 0; v < m->meshes[0].vertex_count; v++) up += m->meshes[0].normals[3 * v + 2] > 0.99f;
	CHECK(up == (int)m->meshes[0].vertex_count, "%d of %u normals along +z (the winding's side)", up,
	      m->meshes[0].vertex_count);
	api_model_release(m);
}

/* The line of /proc/self/maps whose range holds p, into line ("" when none). */
static void mapping_of(const void *p, char *line, size_t n)
{
	FILE *f = fopen("/proc/self/maps", "r");
	line[0] = 0;
	while (f && fgets(line, (int)n, f)) {
		unsigned long lo, hi;
		if (sscanf(line, "%lx-%lx", &lo, &hi) == 2 && (uintptr_t)p >= lo && (uintptr_t)p < hi) break;
		line[0] = 0;
	}
	if (f) fclose(f);
}

/* The importer's reply comes back in a sealed memfd that the model's (sent) arrays stay in, mapped
 * read-only and shared (no copy): a write through them would fault; and the mapping goes with
 * the model. */
TEST(sandbox_reply_is_mapped_read_only)
{
	size_t len;
	uint8_t *d = stl_triangles(50, &len);
	struct api_limits l = limits(5000);
	struct api_arena *a = api_arena_create();
	struct api_model m;
	size_t bytes;
	char err[400], line[512];
	int st;
	REQUIRE(api_sandbox_import_model(d, len, API_MODEL_STL, &l, a, &m, &bytes, &st, err, sizeof err) == API_OK, "%s", err);
	const void *pos = m.meshes[0].positions;
	mapping_of(pos, line, sizeof line);
	CHECK(strstr(line, "memfd:umbra-import-reply") != NULL, "positions in: %s", line);
	CHECK(strstr(line, " r--s ") != NULL, "mapped read-only, shared: %s", line);
	/* An STL's corners are each their own vertex: its indices 0..n-1 do not cross the wire
	 * (flag 512), the daemon counts them out into its arena. */
	mapping_of(m.meshes[0].indices, line, sizeof line);
	CHECK(!strstr(line, "memfd:umbra-import-reply"), "indices in: %s", line);
	for (uint32_t k = 0; k < m.meshes[0].index_count; k++) CHECK(m.meshes[0].indices[k] == k, "index %u", k);
	api_arena_destroy(a);
	mapping_of(pos, line, sizeof line);
	CHECK(!strstr(line, "memfd:umbra-import-reply"), "unmapped with the arena: %s", line);
	free(d);
}

/* ---- the helper's environment ---- */

TEST(sandbox_helper_env_asks_for_huge_pages)
{
	char *plain[] = {"PATH=/bin", "HOME=/x", NULL}, *tuned[] = {"A=1", "GLIBC_TUNABLES=glibc.malloc.arena_max=2", "B=2", NULL};
	char *own = NULL, **env = api_sbx_helper_env(plain, &own);
	REQUIRE(env && own);
	CHECK(!strcmp(env[0], "PATH=/bin") && !strcmp(env[1], "HOME=/x"), "the rest kept: %s %s", env[0], env[1]);
	CHECK(!strcmp(env[2], "GLIBC_TUNABLES=" API_SBX_TUNABLES) && !env[3], "added: %s", env[2]);
	free(env);
	free(own);
	env = api_sbx_helper_env(tuned, &own);
	REQUIRE(env && own);
	CHECK(!strcmp(env[0], "A=1") && !strcmp(env[1], "B=2") && !env[3], "the rest kept, once each");
	CHECK(!strcmp(env[2], "GLIBC_TUNABLES=glibc.malloc.arena_max=2:" API_SBX_TUNABLES), "appended: %s", env[2]);
	free(env);
	free(own);
}

/* A binary STL cone of 200 facets: its apex joins 200 corners, sorted by key in the sandbox
 * (glibc's qsort asks the system how much memory there is first: a call the filter allowed
 * only once the join began to sort). */
TEST(sandbox_stl_cone_apex_joins)
{
	enum { N = 200 };
	size_t len = 84 + (size_t)N * 50;
	uint8_t *d = calloc(1, len);
	uint32_t n = N;
	memcpy(d + 80, &n, 4);
	for (uint32_t i = 0; i < N; i++) {
		float a0 = 6.2831853f * (float)i / N, a1 = 6.2831853f * (float)(i + 1) / N;
		float t[12] = {0, 0, 0, 0, 2, 0, cosf(a1), 0, sinf(a1), cosf(a0), 0, sinf(a0)};
		memcpy(d + 84 + (size_t)i * 50, t, sizeof t);
	}
	struct api_limits l = limits(5000);
	struct api_arena *a = api_arena_create();
	struct api_model m;
	size_t bytes;
	char err[400];
	int st;
	CHECK(api_sandbox_import_model(d, len, API_MODEL_STL, &l, a, &m, &bytes, &st, err, sizeof err) == API_OK, "%s", err);
	api_arena_destroy(a);
	free(d);
}
