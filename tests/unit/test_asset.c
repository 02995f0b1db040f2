/*
 * tests/unit/test_asset — api/asset.c: paths and references under an asset root. Escapes by
 * "..", by an absolute path, by a symbolic link (absolute, relative, through a linked
 * directory) are refused; a FIFO and a directory are refused at once; references resolve
 * against the referring file's directory.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "asset.h"
#include "model.h"
#include "model_refs.h"
#include "sandbox.h"
#include "test.h"
#include "util.h"


/* A root with sub/a.txt, outside/secret.txt beside it, and links in and out. */
static void make_tree(char *base, char *root, size_t n)
{
	snprintf(root, n, "%s/root", base);
	char p[512];
	mkdir(root, 0700);
	snprintf(p, sizeof p, "%s/outside", base);
	mkdir(p, 0700);
	test_put_file(p, "secret.txt", "secret");
	snprintf(p, sizeof p, "%s/sub", root);
	mkdir(p, 0700);
	test_put_file(p, "a.txt", "inside");
	char target[512], link[512];
	snprintf(target, sizeof target, "%s/outside/secret.txt", base);
	snprintf(link, sizeof link, "%s/abs_out.txt", root);
	symlink(target, link);
	snprintf(link, sizeof link, "%s/rel_out.txt", root);
	symlink("../outside/secret.txt", link);
	snprintf(link, sizeof link, "%s/updir", root);
	symlink("..", link);
	snprintf(link, sizeof link, "%s/in.txt", root);
	symlink("sub/a.txt", link);
	snprintf(p, sizeof p, "%s/pipe.bin", root);
	mkfifo(p, 0600);
}

static void remove_tree(const char *base)
{
	char cmd[600];
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", base);
	CHECK(system(cmd) == 0);
}

TEST(asset_reads_inside_root)
{
	char base[] = "/tmp/umbra-asset-XXXXXX", root[300];
	REQUIRE(mkdtemp(base));
	make_tree(base, root, sizeof root);
	uint8_t *b = NULL;
	size_t n = 0;
	int st = 0;
	char err[300];
	CHECK(api_asset_read(root, "sub/a.txt", &b, &n, &st, err, sizeof err) == API_OK && n == 6 &&
	      !memcmp(b, "inside", 6), "%d %s", st, err);
	free(b);
	/* A link that stays inside the root is followed. */
	CHECK(api_asset_read(root, "in.txt", &b, &n, &st, err, sizeof err) == API_OK && n == 6, "%d %s", st, err);
	free(b);
	remove_tree(base);
}

TEST(asset_refuses_escapes)
{
	char base[] = "/tmp/umbra-asset-XXXXXX", root[300];
	REQUIRE(mkdtemp(base));
	make_tree(base, root, sizeof root);
	static const char *const out[] = {"abs_out.txt", "rel_out.txt", "updir/outside/secret.txt",
	                                  "../outside/secret.txt", "sub/../../outside/secret.txt"};
	for (size_t i = 0; i < sizeof out / sizeof out[0]; i++) {
		uint8_t *b = (uint8_t *)"x";
		size_t n = 1;
		int st = 0;
		char err[300] = "";
		CHECK(api_asset_read(root, out[i], &b, &n, &st, err, sizeof err) == API_ERR && st == 400 && !b && !n,
		      "%s: %d %s", out[i], st, err);
		CHECK(strstr(err, "leaves the asset root"), "%s: %s", out[i], err);
	}
	/* The same paths never get that far as a `path`. */
	char err[300];
	CHECK(api_asset_check_path("../outside/secret.txt", err, sizeof err) == API_ERR);
	CHECK(api_asset_check_path("sub/../a.txt", err, sizeof err) == API_ERR);
	CHECK(api_asset_check_path("/etc/passwd", err, sizeof err) == API_ERR);
	CHECK(api_asset_check_path("C:/x.obj", err, sizeof err) == API_ERR);
	CHECK(api_asset_check_path("sub\\a.txt", err, sizeof err) == API_ERR);
	CHECK(api_asset_check_path("", err, sizeof err) == API_ERR);
	CHECK(api_asset_check_path("sub/a.txt", err, sizeof err) == API_OK);
	CHECK(api_asset_check_path("..a/b..", err, sizeof err) == API_OK);
	remove_tree(base);
}

TEST(asset_refuses_fifo_directory_missing)
{
	char base[] = "/tmp/umbra-asset-XXXXXX", root[300];
	REQUIRE(mkdtemp(base));
	make_tree(base, root, sizeof root);
	static const char *const bad[] = {"pipe.bin", "sub", "missing.bin"};
	static const char *const why[] = {"not a regular file", "not a regular file", "No such file"};
	for (int i = 0; i < 3; i++) {
		uint8_t *b = NULL;
		size_t n = 0;
		int st = 0;
		char err[300] = "";
		/* The FIFO has no writer: a blocking open would never return. */
		CHECK(api_asset_read(root, bad[i], &b, &n, &st, err, sizeof err) == API_ERR && st == 400 &&
		      strstr(err, why[i]), "%s: %d %s", bad[i], st, err);
	}
	uint8_t *b = NULL;
	size_t n = 0;
	int st = 0;
	char err[300] = "";
	CHECK(api_asset_read(NULL, "sub/a.txt", &b, &n, &st, err, sizeof err) == API_ERR && st == 400 &&
	      strstr(err, "no asset root"), "%s", err);
	CHECK(api_asset_read("/nonexistent-umbra-root", "a", &b, &n, &st, err, sizeof err) == API_ERR && st == 500,
	      "%d %s", st, err);
	remove_tree(base);
}

TEST(asset_resolves_references)
{
	char out[256], err[300];
	CHECK(api_asset_resolve("models/x.gltf", "x.bin", out, sizeof out, err, sizeof err) == API_OK &&
	      !strcmp(out, "models/x.bin"), "%s", out);
	CHECK(api_asset_resolve("models/x.gltf", "./tex/../img/a.png", out, sizeof out, err, sizeof err) == API_OK &&
	      !strcmp(out, "models/img/a.png"), "%s", out);
	CHECK(api_asset_resolve("models/x.obj", "..\\shared\\t.png", out, sizeof out, err, sizeof err) == API_OK &&
	      !strcmp(out, "shared/t.png"), "%s", out);
	CHECK(api_asset_resolve("x.gltf", "a.bin", out, sizeof out, err, sizeof err) == API_OK && !strcmp(out, "a.bin"),
	      "%s", out);
	/* Above the root, absolute, with a scheme, empty, a directory. */
	CHECK(api_asset_resolve("models/x.gltf", "../../etc/passwd", out, sizeof out, err, sizeof err) == API_ERR &&
	      strstr(err, "leaves the asset root"), "%s", err);
	CHECK(api_asset_resolve("x.gltf", "../x.bin", out, sizeof out, err, sizeof err) == API_ERR);
	CHECK(api_asset_resolve("x.gltf", "/etc/passwd", out, sizeof out, err, sizeof err) == API_ERR);
	CHECK(api_asset_resolve("x.gltf", "http://example.com/a.bin", out, sizeof out, err, sizeof err) == API_ERR);
	CHECK(api_asset_resolve("x.gltf", "C:\\a.png", out, sizeof out, err, sizeof err) == API_ERR);
	CHECK(api_asset_resolve("x.gltf", "", out, sizeof out, err, sizeof err) == API_ERR);
	CHECK(api_asset_resolve("m/x.gltf", "..", out, sizeof out, err, sizeof err) == API_ERR);
}

/* A .gltf whose buffer is a separate file: imported with it, and the cache tells two
 * different .bin files apart although the .gltf's bytes are the same. */
static const char TRI_GLTF[] =
	"{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
	"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
	"\"buffers\":[{\"uri\":\"tri%20angle.bin\",\"byteLength\":36}],"
	"\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
	"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
	"\"min\":[0,0,0],\"max\":[9,9,0]}]}";

TEST(model_files_served_and_keyed)
{
	float a[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, b[9] = {0, 0, 0, 9, 0, 0, 0, 9, 0};
	struct api_model_file fa = {"tri angle.bin", (const uint8_t *)a, sizeof a};
	struct api_model_file fb = {"tri angle.bin", (const uint8_t *)b, sizeof b};
	struct api_model *ma = NULL, *mb = NULL, *mn = NULL;
	int st;
	char err[400] = "";
	const uint8_t *g = (const uint8_t *)TRI_GLTF;
	size_t n = strlen(TRI_GLTF);
	CHECK(api_model_get_files(g, n, &fa, 1, API_MODEL_GLTF, NULL, &ma, &st, err, sizeof err) == API_OK && ma,
	      "%d %s", st, err);
	CHECK(api_model_get_files(g, n, &fb, 1, API_MODEL_GLTF, NULL, &mb, &st, err, sizeof err) == API_OK && mb,
	      "%d %s", st, err);
	REQUIRE(ma && mb);
	CHECK(ma != mb && ma->meshes[0].positions[3] == 1 && mb->meshes[0].positions[3] == 9, "%g %g",
	      ma->meshes[0].positions[3], mb->meshes[0].positions[3]);
	/* Without the file the importer cannot open it (it reads no disk). */
	CHECK(api_model_get(g, n, API_MODEL_GLTF, NULL, &mn, &st, err, sizeof err) == API_ERR && !mn && st == 400,
	      "%d %s", st, err);
	api_model_release(ma);
	api_model_release(mb);
}

/* An .obj by path whose .mtl is missing: left out with a warning naming it and why (as for a
 * multipart request without it, and umbra-render thumb), and a present .mtl and its texture
 * are read from the model's directory. */
TEST(model_refs_missing_obj_files_by_path)
{
	char base[] = "/tmp/umbra-refs-XXXXXX", root[300];
	REQUIRE(mkdtemp(base));
	make_tree(base, root, sizeof root);
	test_put_file(root, "blue.mtl", "newmtl b\nKd 0 0 1\nmap_Kd sub/a.txt\nmap_Ks sub/gone.png\n");
	static const char lost[] = "mtllib gone.mtl\nv 0 0 0\n", found[] = "mtllib blue.mtl\nv 0 0 0\n";
	struct api_model_refs r;
	int st;
	char err[400];
	struct api_ref_source src = {.root = root, .path = "m.obj"};
	CHECK(api_model_refs_collect((const uint8_t *)lost, strlen(lost), API_MODEL_OBJ, &src, &r, &st, err, sizeof err) ==
	      API_OK && r.count == 0 && strstr(r.warning, "\"gone.mtl\" cannot be read") &&
	      strstr(r.warning, "No such file"), "%d %s / %s", st, err, r.warning);
	api_model_refs_release(&r);
	CHECK(api_model_refs_collect((const uint8_t *)found, strlen(found), API_MODEL_OBJ, &src, &r, &st, err,
	                             sizeof err) == API_OK && r.count == 2 && !strcmp(r.files[1].name, "sub/a.txt") &&
	      strstr(r.warning, "texture \"sub/gone.png\" cannot be read"), "%d %s: %zu files / %s", st, err, r.count,
	      r.warning);
	api_model_refs_release(&r);
	/* Still no escape: a .mtl above the root is a 400 either way. */
	static const char up[] = "mtllib ../outside/secret.txt\n";
	CHECK(api_model_refs_collect((const uint8_t *)up, strlen(up), API_MODEL_OBJ, &src, &r, &st, err, sizeof err) ==
	      API_ERR && st == 400, "%d %s", st, err);
	api_model_refs_release(&r);
	remove_tree(base);
}

/* One file under several spellings ("a.bin", "./a.bin", "a%2Ebin"), as a .gltf's buffers may
 * name it: read once, counted once, and sent to the importer once (the bundle's alias entries),
 * each name still served. A 40 MB part named 24 ways had been copied 24 times (+1 GB). */
TEST(model_refs_one_file_under_many_spellings)
{
	static const char gltf[] = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"a.bin\",\"byteLength\":4},"
	                           "{\"uri\":\"./a.bin\",\"byteLength\":4},{\"uri\":\"a%2Ebin\",\"byteLength\":4}]}";
	static const uint8_t bin[4096] = {1, 2, 3, 4};
	struct api_part parts[] = {{"a.bin", bin, sizeof bin}};
	struct api_ref_source src = {.parts = parts, .nparts = 1};
	struct api_model_refs r;
	int st;
	char err[400];
	REQUIRE(api_model_refs_collect((const uint8_t *)gltf, strlen(gltf), API_MODEL_GLTF, &src, &r, &st, err,
	                               sizeof err) == API_OK, "%d %s", st, err);
	CHECK(r.count == 3, "%zu names", r.count);
	CHECK(r.bytes == sizeof bin, "%llu bytes counted for one 4096-byte file", (unsigned long long)r.bytes);
	size_t len = 0;
	uint8_t *b = api_sbx_bundle_encode((const uint8_t *)gltf, strlen(gltf), r.files, r.count, &len);
	REQUIRE(b);
	size_t names = 0;
	for (size_t i = 0; i < r.count; i++) names += 12 + strlen(r.files[i].name) + 1;
	CHECK(len == strlen(gltf) + names + sizeof bin, "bundle of %zu bytes: the file's bytes once", len);
	struct api_model_file back[3];
	CHECK(api_sbx_bundle_decode(b, len, strlen(gltf), 3, back) == 0, "decodes");
	for (int i = 0; i < 3; i++)
		CHECK(!strcmp(back[i].name, r.files[i].name) && back[i].len == sizeof bin && !memcmp(back[i].data, bin, 4),
		      "name %d (%s) serves the file", i, r.files[i].name);
	/* an alias may only name an earlier file */
	uint64_t bad = API_SBX_ALIAS | 2;
	memcpy(b + strlen(gltf) + 12 + strlen(r.files[0].name) + 1 + sizeof bin + 4, &bad, 8);
	CHECK(api_sbx_bundle_decode(b, len, strlen(gltf), 3, back) < 0, "a forward alias is refused");
	free(b);
	api_model_refs_release(&r);
}
