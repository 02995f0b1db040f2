/*
 * tests/bench/import_compare.c — umbra's own OBJ and PLY readers (api/obj_import.h,
 * api/ply_import.h) against the Assimp path, on real files: each file imported both ways
 * in-process (with the .mtl and textures it names, found beside it), the two models compared
 * (tests/util/model_compare.h) and each way's median time printed.
 *
 *   build/tests/import_compare [-n N] FILE.obj|FILE.ply...
 *
 * A line a file: "same", "DIFFERENT: why", "assimp" (the own reader left it to Assimp) or
 * "refused: why" (both refused it, the same way). Exit status 1 when one differs.
 */
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "arena.h"
#include "model_compare.h"
#include "model_import.h"
#include "model_lod.h"
#include "model_refs.h"
#include "model_wire.h"
#include "obj_import.h"
#include "ply_import.h"
#include "util.h"

/* One import (own: readers first, as the importer does; else Assimp alone), finished as the
 * importer finishes it for side 0. Its status; *ms its time. */
static int import(const uint8_t *d, size_t len, const struct api_model_refs *r, int fmt, int own, struct api_arena *a,
                  struct api_model *m, double *ms, char *err, size_t errsize)
{
	size_t bytes = 0;
	double t0 = test_now_ms();
	int st = own ? api_model_import_files(d, len, r->files, r->count, fmt, 0, a, m, &bytes, err, errsize)
	             : api_model_import_assimp(d, len, r->files, r->count, fmt, 0, a, m, &bytes, err, errsize);
	if (st == API_WIRE_OK) api_model_finish_import(m, 0, a, &bytes);
	*ms = test_now_ms() - t0;
	return st;
}

/* Whether the own reader takes the file itself. */
static int own_takes(const uint8_t *d, size_t len, const struct api_model_refs *r, int fmt)
{
	struct api_arena *a = api_arena_create();
	struct api_model m;
	size_t bytes;
	char err[300];
	int st = fmt == API_MODEL_OBJ ? api_obj_import(d, len, r->files, r->count, 0, a, &m, &bytes, err, sizeof err)
	                              : api_ply_import(d, len, a, &m, &bytes, err, sizeof err);
	api_arena_destroy(a);
	return st != API_OBJ_NOT_MINE;
}

static int one_file(const char *path, int n)
{
	size_t len = 0;
	uint8_t *d = test_read_file(path, &len);
	const char *dot = strrchr(path, '.');
	int fmt = dot && !strcmp(dot, ".obj") ? API_MODEL_OBJ : dot && !strcmp(dot, ".ply") ? API_MODEL_PLY : -1;
	if (!d || fmt < 0) return fprintf(stderr, "import_compare: cannot read %s (.obj or .ply)\n", path), 1;
	char dir[4096], base[4096], err[400], err2[400];
	snprintf(dir, sizeof dir, "%s", path);
	snprintf(base, sizeof base, "%s", path);
	struct api_ref_source src = {.root = dirname(dir), .path = basename(base)};
	struct api_model_refs r;
	int status, rc = 0;
	if (api_model_refs_collect(d, len, fmt, &src, &r, &status, err, sizeof err) != API_OK) {
		printf("%-40.40s refs: %s\n", src.path, err);
		free(d);
		return 0;
	}
	double t[2][16];
	int st[2] = {0, 0};
	if (n > 16) n = 16;
	struct api_arena *keep[2] = {NULL, NULL};
	struct api_model m[2];
	for (int i = 0; i < n; i++)
		for (int w = 0; w < 2; w++) {
			struct api_arena *a = api_arena_create();
			st[w] = import(d, len, &r, fmt, w == 0, a, &m[w], &t[w][i], w ? err2 : err, sizeof err);
			if (i + 1 == n) keep[w] = a;
			else api_arena_destroy(a);
		}
	printf("%-40.40s own %8.1f ms  assimp %8.1f ms  ", src.path, test_median(t[0], n), test_median(t[1], n));
	char why[300];
	if (!own_takes(d, len, &r, fmt)) printf("assimp\n");
	else if (st[0] != API_WIRE_OK || st[1] != API_WIRE_OK) {
		bool same = st[0] == st[1] && !strcmp(err, err2);
		printf("%s: own %d \"%s\", assimp %d \"%s\"\n", same ? "refused" : "DIFFERENT", st[0], st[0] ? err : "",
		       st[1], st[1] ? err2 : "");
		rc = !same;
	} else if (test_models_equal(&m[0], &m[1], 1e-5f, why, sizeof why)) printf("same (%llu triangles)\n",
	                                                                         (unsigned long long)m[0].triangles);
	else printf("DIFFERENT: %s\n", why), rc = 1;
	api_arena_destroy(keep[0]);
	api_arena_destroy(keep[1]);
	api_model_refs_release(&r);
	free(d);
	return rc;
}

int main(int argc, char **argv)
{
	int n = 1, i = 1, rc = 0;
	if (argc > 2 && !strcmp(argv[1], "-n")) n = atoi(argv[2]), i = 3;
	if (n < 1) n = 1;
	for (; i < argc; i++) rc |= one_file(argv[i], n);
	return rc;
}
