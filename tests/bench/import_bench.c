/*
 * tests/bench/import_bench.c — what the import sandbox (api/sandbox.h) costs per model: the
 * same binary STL imported cold N times in-process (api_model_import_local, no isolation) and
 * through the sandbox (one forked, rlimited, seccomp-filtered child per import, the reply
 * validated), medians in ms. The models are generated here (a grid of quads).
 *
 *   build/tests/import_bench [-n N] TRIANGLES...      (default 1000 100000)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "api.h"
#include "arena.h"
#include "model_import.h"
#include "sandbox.h"

static double now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static int cmp(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

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

static double run(const uint8_t *d, size_t len, int sandboxed, int n, uint64_t *tris)
{
	double *t = calloc((size_t)n, sizeof *t);
	for (int i = -1; i < n; i++) {
		struct api_arena *a = api_arena_create();
		struct api_model m;
		size_t bytes;
		char err[400];
		int st;
		double t0 = now_ms();
		int ok = sandboxed ? api_sandbox_import_model(d, len, API_MODEL_STL, NULL, a, &m, &bytes, &st, err, sizeof err) == API_OK
		                   : api_model_import_local(d, len, API_MODEL_STL, a, &m, &bytes, err, sizeof err) == API_WIRE_OK;
		double t1 = now_ms();
		if (!ok) { fprintf(stderr, "import_bench: %s\n", err); exit(1); }
		*tris = m.triangles;
		api_arena_destroy(a);
		if (i >= 0) t[i] = t1 - t0;   /* run -1 starts the fork server / warms caches */
	}
	qsort(t, (size_t)n, sizeof *t, cmp);
	double med = n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
	free(t);
	return med;
}

int main(int argc, char **argv)
{
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
