/*
 * tests/bench/import_bench.c — what the import sandbox (api/sandbox.h) costs per model: the
 * same binary STL imported cold N times in-process (api_model_import_local, no isolation) and
 * through the sandbox (one forked, rlimited, seccomp-filtered child per import, the reply
 * validated), medians in ms. The models are generated here (a grid of quads).
 *
 *   build/tests/import_bench [-n N] TRIANGLES...      (default 1000 100000)
 *   build/tests/import_bench --stages [-n N] [--side S] FILE...
 *       each model file (format from its extension) imported through the sandbox N times for
 *       images of S pixels (default 256), as a request would: the median of each stage the
 *       import names (Server-Timing's model-*) and of the whole call.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "api.h"
#include "arena.h"
#include "model_import.h"
#include "sandbox.h"
#include "util.h"

/* A binary STL of about `tris` triangles: a k x k grid of quads (shared vertices). */
static uint8_t *grid_stl(uint32_t tris, size_t *len)
{
	uint32_t k = 1;
	while (2ull * (k + 1) * (k + 1) <= tris) k++;
	uint32_t n = 2 * k * k;
	*len = 84 + (size_t)n * 50;
	uint8_t *d = calloc(1, *len);
	memcpy(d + 80, &n, 4);
	uint8_t *p = d + 84;
	for (uint32_t y = 0; y < k; y++)
		for (uint32_t x = 0; x < k; x++) {
			float a[3] = {(float)x, 0, (float)y}, b[3] = {(float)x + 1, 0, (float)y};
			float c[3] = {(float)x + 1, 0, (float)y + 1}, e[3] = {(float)x, 0, (float)y + 1};
			const float *t[2][3] = {{a, c, b}, {a, e, c}};
			for (int i = 0; i < 2; i++, p += 50) {
				float nrm[3] = {0, 1, 0};
				memcpy(p, nrm, 12);
				for (int v = 0; v < 3; v++) memcpy(p + 12 + 12 * v, t[i][v], 12);
			}
		}
	return d;
}

/* One cold import of d as fmt (sandboxed, or in-process without isolation), its ms; *m gets
 * its triangles and stage times. Exits on failure. */
static double import_once(const uint8_t *d, size_t len, int fmt, const struct api_limits *lim, int sandboxed,
                          const char *name, struct api_model *m)
{
	struct api_arena *a = api_arena_create();
	size_t bytes;
	char err[400];
	int st;
	double t0 = test_now_ms();
	int ok = sandboxed ? api_sandbox_import_model(d, len, (enum api_model_format)fmt, lim, a, m, &bytes, &st, err,
	                                              sizeof err) == API_OK
	                   : api_model_import_local(d, len, (enum api_model_format)fmt, a, m, &bytes, err, sizeof err) ==
	                         API_WIRE_OK;
	double ms = test_now_ms() - t0;
	if (!ok) {
		fprintf(stderr, "import_bench: %s: %s\n", name, err);
		exit(1);
	}
	api_arena_destroy(a);   /* (m's counts and times stay valid) */
	return ms;
}

static double run(const uint8_t *d, size_t len, int sandboxed, int n, uint64_t *tris)
{
	double *t = calloc((size_t)n, sizeof *t);
	for (int i = -1; i < n; i++) {
		struct api_model m;
		double ms = import_once(d, len, API_MODEL_STL, NULL, sandboxed, "grid", &m);
		*tris = m.triangles;
		if (i >= 0) t[i] = ms;   /* run -1 starts the fork server / warms caches */
	}
	double med = test_median(t, n);
	free(t);
	return med;
}

/* --stages: per-stage medians of sandboxed imports of real files. */
static int stages(int argc, char **argv)
{
	int n = 5, i = 2;
	uint32_t side = 256;
	for (; i + 1 < argc && argv[i][0] == '-'; i += 2) {
		if (!strcmp(argv[i], "-n")) n = atoi(argv[i + 1]);
		else if (!strcmp(argv[i], "--side")) side = (uint32_t)strtoul(argv[i + 1], NULL, 10);
	}
	if (n < 1) n = 1;
	static const char *const ext[] = {"glb", "gltf", "obj", "stl", "ply"};
	printf("%-32s", "model (ms, median)");
	for (int k = API_IMPORT_PARSE; k <= API_IMPORT_VALIDATE; k++) printf(" %9s", API_IMPORT_STAGE_NAMES[k] + 6);
	printf(" %9s\n", "total");
	for (; i < argc; i++) {
		size_t len = 0;
		uint8_t *d = test_read_file(argv[i], &len);
		const char *dot = strrchr(argv[i], '.');
		int fmt = -1;
		for (int k = 0; dot && k < 5; k++)
			if (!strcmp(dot + 1, ext[k])) fmt = k;
		if (!d || fmt < 0) { fprintf(stderr, "import_bench: cannot read %s\n", argv[i]); return 1; }
		double t[API_IMPORT_STAGES + 1][64];
		int runs = n > 64 ? 64 : n;
		struct api_limits lim;
		api_limits_defaults(&lim);
		lim.output_side = side;
		for (int r = -1; r < runs; r++) {
			struct api_model m;
			double ms = import_once(d, len, fmt, &lim, 1, argv[i], &m);
			if (r < 0) continue;   /* the first starts the fork server */
			for (int k = 0; k < API_IMPORT_STAGES; k++) t[k][r] = m.times.ms[k];
			t[API_IMPORT_STAGES][r] = ms;
		}
		const char *base = strrchr(argv[i], '/');
		printf("%-32.32s", base ? base + 1 : argv[i]);
		for (int k = API_IMPORT_PARSE; k <= API_IMPORT_VALIDATE; k++) printf(" %9.1f", test_median(t[k], runs));
		printf(" %9.1f\n", test_median(t[API_IMPORT_STAGES], runs));
		free(d);
	}
	return 0;
}

int main(int argc, char **argv)
{
	if (argc > 1 && !strcmp(argv[1], "--stages")) return stages(argc, argv);
	int n = 9, first = 1;
	if (argc > 2 && !strcmp(argv[1], "-n")) { n = atoi(argv[2]); first = 3; }
	if (n < 1) n = 1;
	static const char *const def[] = {"1000", "100000"};
	const char *const *sizes = first < argc ? (const char *const *)argv + first : def;
	int count = first < argc ? argc - first : 2;
	printf("cold binary-STL import, median of %d (ms): in-process vs sandboxed (%s)\n", n, api_sandbox_helper_path());
	printf("%-12s %10s %12s %12s %12s\n", "triangles", "bytes", "in-process", "sandboxed", "cost");
	for (int i = 0; i < count; i++) {
		size_t len;
		uint8_t *d = grid_stl((uint32_t)strtoul(sizes[i], NULL, 10), &len);
		uint64_t tris = 0;
		double local = run(d, len, 0, n, &tris), sbx = run(d, len, 1, n, &tris);
		printf("%-12llu %10zu %12.2f %12.2f %+12.2f\n", (unsigned long long)tris, len, local, sbx, sbx - local);
		free(d);
	}
	return 0;
}
