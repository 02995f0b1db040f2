/* Models by path remembered by their files' stamps (api/model_paths.h): a second request for an
 * unchanged model finds it without reading, any change to the model or a file it refers to is
 * seen at once, and the answer's asset hash (the ETag) is the same either way. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "api.h"
#include "model.h"
#include "model_paths.h"
#include "test.h"
#include "util.h"

static const char CUBE[] =
	"mtllib cube.mtl\nusemtl paint\n"
	"v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
	"f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";
static const char HALF_CUBE[] =
	"mtllib cube.mtl\nusemtl paint\n"
	"v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
	"f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\n";

/* Lets the file settle: a stamp taken within its file system's clock tick of a change is not
 * trusted (the window is longer where the file system keeps whole seconds). */
static void settle(const char *path)
{
	struct stat st;
	bool coarse = stat(path, &st) == 0 && st.st_mtim.tv_nsec == 0 && st.st_ctim.tv_nsec == 0;
	int64_t ns = (coarse ? API_ASSET_SETTLE_COARSE_NS : API_ASSET_SETTLE_NS) + 20000000;
	struct timespec t = {(time_t)(ns / 1000000000), (long)(ns % 1000000000)};
	while (nanosleep(&t, &t) != 0) {}
}

static void put(const char *dir, const char *name, const char *text)
{
	test_put_file(dir, name, text);
	char f[400];
	snprintf(f, sizeof f, "%s/%s", dir, name);
	settle(f);
}

static struct api_scene *parse_at(const char *root, struct api_problem *p)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = root;
	const char *doc = "{\"camera\":{\"position\":[0,0,5]},\"objects\":[{\"shape\":\"model\",\"path\":\"cube.obj\"}]}";
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	if (api_scene_parse(doc, strlen(doc), &lim, &s, p) != API_OK) return NULL;
	return s;
}

static float red_of(const struct api_scene *s)
{
	return s->scene.materials[s->scene.objects[0].material].base_color[0];
}

TEST(model_paths_remembered_until_a_file_changes)
{
	char root[] = "/tmp/umbra-paths-XXXXXX";
	REQUIRE(mkdtemp(root));
	put(root, "cube.obj", CUBE);
	put(root, "cube.mtl", "newmtl paint\nKd 0.8 0.1 0.1\n");
	struct api_problem p;
	uint64_t hits = api_model_paths_hits();

	struct api_scene *a = parse_at(root, &p);
	REQUIRE(a && a->triangles == 12, "%d %s", p.status, p.detail);
	CHECK(api_model_paths_hits() == hits, "the first request reads the files");
	struct api_scene *b = parse_at(root, &p);
	REQUIRE(b, "%d %s", p.status, p.detail);
	CHECK(api_model_paths_hits() == hits + 1, "an unchanged model is found without reading it");
	CHECK(b->scene.objects[0].positions == a->scene.objects[0].positions, "the same imported model");
	CHECK(b->asset_hash == a->asset_hash && a->asset_hash, "the same ETag either way");

	/* The material library it refers to changes (same size): a new import with the new colour. */
	put(root, "cube.mtl", "newmtl paint\nKd 0.2 0.1 0.1\n");
	struct api_scene *c = parse_at(root, &p);
	REQUIRE(c, "%d %s", p.status, p.detail);
	CHECK(api_model_paths_hits() == hits + 1, "a changed .mtl is read again");
	CHECK(red_of(a) > 0.5f && red_of(c) < 0.3f, "colour %g then %g", red_of(a), red_of(c));
	CHECK(c->asset_hash != a->asset_hash, "a changed file changes the ETag");
	struct api_scene *d = parse_at(root, &p);
	CHECK(d && api_model_paths_hits() == hits + 2 && d->asset_hash == c->asset_hash);

	/* The model file itself changes, then goes away. */
	put(root, "cube.obj", HALF_CUBE);
	struct api_scene *e = parse_at(root, &p);
	CHECK(e && e->triangles == 6 && api_model_paths_hits() == hits + 2, "%d %s", p.status, p.detail);
	char f[400];
	snprintf(f, sizeof f, "%s/cube.obj", root);
	CHECK(unlink(f) == 0);
	struct api_scene *g = parse_at(root, &p);
	CHECK(!g && p.status == 400 && !strcmp(p.pointer, "/objects/0/path"), "%d %s %s", p.status, p.pointer, p.detail);

	/* A file made unreadable is refused, not served from memory (chmod changes its ctime). */
	put(root, "cube.obj", CUBE);
	struct api_scene *h = parse_at(root, &p);
	CHECK(h != NULL, "%d %s", p.status, p.detail);
	api_scene_free(h);
	h = parse_at(root, &p);
	CHECK(h != NULL);
	api_scene_free(h);
	if (geteuid() != 0) {
		CHECK(chmod(f, 0) == 0);
		h = parse_at(root, &p);
		CHECK(!h && p.status == 400, "%d %s", p.status, p.detail);
		api_scene_free(h);
		chmod(f, 0600);
	}

	/* A file read right after it changed is used but not remembered (its stamp may not show a
	 * second change within the same clock tick); the next request, once settled, is. */
	char m[400];
	snprintf(m, sizeof m, "%s/cube.mtl", root);
	FILE *fp = fopen(m, "ab");
	if (fp) fputs("# touched\n", fp), fclose(fp);
	uint64_t racy = api_model_paths_hits();
	h = parse_at(root, &p);
	CHECK(h && api_model_paths_hits() == racy, "%d %s", p.status, p.detail);
	api_scene_free(h);
	h = parse_at(root, &p);
	CHECK(h && api_model_paths_hits() == racy, "not remembered from a racy read");
	api_scene_free(h);
	settle(m);
	h = parse_at(root, &p);
	api_scene_free(h);
	h = parse_at(root, &p);
	CHECK(h && api_model_paths_hits() == racy + 1, "remembered once settled");
	api_scene_free(h);

	/* The model leaves the cache: read and imported again, then remembered again. */
	api_model_cache_clear();
	uint64_t before = api_model_paths_hits();
	struct api_scene *i = parse_at(root, &p);
	CHECK(i && i->triangles == 12 && api_model_paths_hits() == before, "%d %s", p.status, p.detail);
	struct api_scene *k = parse_at(root, &p);
	CHECK(k && api_model_paths_hits() == before + 1);

	api_scene_free(a);
	api_scene_free(b);
	api_scene_free(c);
	api_scene_free(d);
	api_scene_free(e);
	api_scene_free(i);
	api_scene_free(k);
	api_model_paths_clear();
	char cmd[400];
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
	CHECK(system(cmd) == 0);
}

/* The racy-stamp rule: a stamp stands for the file's bytes only when taken a clock tick's
 * worth after the last change: 1 s, or 3 s where the file system keeps whole seconds (a second
 * write in the same second keeps every time: seen stale on an ext3 or sshfs mount). */
TEST(model_paths_stamp_settle_window)
{
	const int64_t s = 1000000000;
	struct api_asset_stamp fine = {.mtime_ns = 100 * s + 123456, .ctime_ns = 100 * s + 123456};
	fine.seen_ns = fine.mtime_ns + s / 2;
	CHECK(!api_asset_stamp_settled(&fine), "0.5 s after a change");
	fine.seen_ns = fine.mtime_ns + s + s / 10;
	CHECK(api_asset_stamp_settled(&fine), "1.1 s after a change");
	struct api_asset_stamp whole = {.mtime_ns = 100 * s, .ctime_ns = 100 * s};
	whole.seen_ns = whole.mtime_ns + s + s / 10;
	CHECK(!api_asset_stamp_settled(&whole), "whole-second times, 1.1 s after");
	whole.seen_ns = whole.mtime_ns + 3 * s + s / 10;
	CHECK(api_asset_stamp_settled(&whole), "whole-second times, 3.1 s after");
	whole.ctime_ns = 101 * s + 5;   /* one time with nanoseconds: a fine clock */
	whole.seen_ns = whole.ctime_ns + s + s / 10;
	CHECK(api_asset_stamp_settled(&whole));
}
