/*
 * tests/bench/bench.c — warm-process benchmark: renders each scene file given on the command
 * line N times in one process (after one warm-up render) and prints median milliseconds per
 * stage (parse, upload, shadow, main, readback, encode), the median total and images/s.
 *
 *   build/tests/bench [-n N] [-c] [-s] [-a DIR] SCENE.json...   (-c: import models cold every run;
 *                                                          -s: keep no shadow map between runs, as
 *                                                              for a model never seen before;
 *                                                          -a: models' "path" is inside DIR)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "api.h"
#include "util.h"
#include "umbra/rnd.h"

enum { S_PARSE, S_UPLOAD, S_SHADOW, S_MAIN, S_READBACK, S_ENCODE, S_TOTAL, S_VIS, S_COUNT };
static const char *names[S_COUNT] = {"parse", "upload", "shadow", "main", "readback", "encode", "total", "vis"};

int main(int argc, char **argv)
{
	int n = 15;
	int first = 1;
	int cold_models = 0;   /* -c: no model cache, every run imports its models again */
	int cold_maps = 0;     /* -s: no shadow map kept, every run draws its maps */
	int deadline_ms = 0;
	const char *asset_root = NULL;
	for (;;) {
		if (argc > first + 1 && !strcmp(argv[first], "-n")) { n = atoi(argv[first + 1]); first += 2; }
		else if (argc > first && !strcmp(argv[first], "-c")) { cold_models = 1; first += 1; }
		else if (argc > first && !strcmp(argv[first], "-s")) { cold_maps = 1; first += 1; }
		else if (argc > first + 1 && !strcmp(argv[first], "-a")) { asset_root = argv[first + 1]; first += 2; }
		/* -d MS: each render gets a deadline MS from its start (as umbrad gives one), so the
		 * submits are split as they are in the daemon. */
		else if (argc > first + 1 && !strcmp(argv[first], "-d")) { deadline_ms = atoi(argv[first + 1]); first += 2; }
		else break;
	}
	if (n < 1) n = 1;
	struct rnd_context_desc cd = {.slots = 1, .shadow_cache_texels = cold_maps ? 1 : 0};
	struct rnd_context *ctx;
	struct rnd_error err;
	if (rnd_context_create(&cd, &ctx, &err) != RND_OK) { fprintf(stderr, "bench: %s\n", err.msg); return 1; }
	struct rnd_info info;
	rnd_context_info(ctx, &info);
	printf("device: %s (%s), %d runs per scene after 1 warm-up, medians in ms\n", info.device_name, info.driver_name, n);
	/* After the times (last run): shadow maps rendered / kept from an earlier request, the
	 * texels of the maps drawn (millions), the triangles the camera's passes draw (thousands),
	 * whether the visibility pass ran (renderer/visibility.c) and shaded per pixel
	 * (renderer/deferred.h), and the median ms of that pass (part of main). */
	printf("%-22s %8s %8s %8s %8s %8s %8s %8s %8s %8s %9s %6s %8s %3s %3s %7s\n", "scene", "parse", "upload", "shadow", "main",
	       "readback", "encode", "total", "img/s", "KiB", "maps r/k", "Mtexel", "cam ktri", "vis", "px", "vis ms");
	int rc = 0;
	for (int a = first; a < argc; a++) {
		size_t len;
		char *json = (char *)test_read_file(argv[a], &len);
		if (!json) { fprintf(stderr, "bench: cannot read %s\n", argv[a]); rc = 1; continue; }
		double *t = calloc((size_t)(n * S_COUNT), sizeof *t);
		size_t bytes_out = 0;
		struct rnd_timings last = {0};   /* of the last run */
		struct api_limits lim;
		api_limits_defaults(&lim);
		lim.max_triangles = 0;
		api_model_cache_set_limit(cold_models ? 0 : 256u << 20);
		lim.asset_root = asset_root;
		for (int i = -1; i < n && rc == 0; i++) {
			double t0 = test_now_ms();
			struct api_scene *s;
			struct api_problem p;
			if (api_scene_parse(json, len, &lim, &s, &p) != API_OK) {
				fprintf(stderr, "bench: %s: %s %s\n", argv[a], p.pointer, p.detail); rc = 1; break;
			}
			double t1 = test_now_ms();
			struct rnd_image img;
			struct rnd_timings tm;
			if (deadline_ms > 0) s->scene.deadline_ns = (uint64_t)((t0 + deadline_ms) * 1e6);
			if (rnd_render(ctx, &s->scene, &img, &tm, &err) != RND_OK) {
				fprintf(stderr, "bench: %s: %s\n", argv[a], err.msg); api_scene_free(s); rc = 1; break;
			}
			double t2 = test_now_ms();
			uint8_t *out; size_t olen;
			if (api_encode(s, &img, &out, &olen, &p) != API_OK) { fprintf(stderr, "bench: encode: %s\n", p.detail); rc = 1; }
			else free(out);
			double t3 = test_now_ms();
			bytes_out = olen;
			last = tm;
			rnd_image_release(&img);
			api_scene_free(s);
			if (i < 0) continue;
			double *r = t + (size_t)i * S_COUNT;
			r[S_PARSE] = t1 - t0; r[S_UPLOAD] = tm.upload_ms; r[S_SHADOW] = tm.shadow_ms; r[S_MAIN] = tm.main_ms;
			r[S_READBACK] = tm.readback_ms; r[S_ENCODE] = t3 - t2; r[S_TOTAL] = t3 - t0;
			r[S_VIS] = tm.visibility_ms;
			(void)t2;
		}
		if (rc == 0) {
			const char *base = strrchr(argv[a], '/');
			printf("%-22s", base ? base + 1 : argv[a]);
			double col[S_COUNT];
			for (int s = 0; s < S_COUNT; s++) {
				double v[1024];
				int m = n < 1024 ? n : 1024;
				for (int i = 0; i < m; i++) v[i] = t[(size_t)i * S_COUNT + s];
				col[s] = test_median(v, m);
				if (s <= S_TOTAL) printf(" %8.2f", col[s]);
			}
			printf(" %8.1f %8zu %4u/%-4u %6.2f %8.1f %3u %3u %7.2f\n", 1000.0 / col[S_TOTAL], bytes_out / 1024,
			       last.shadow_maps_rendered, last.shadow_maps_reused, (double)last.shadow_texels / 1e6, (double)last.camera_triangles / 1e3,
			       last.visibility_views, last.pixel_shaded_views, col[S_VIS]);
		}
		free(t);
		free(json);
	}
	(void)names;
	rnd_context_destroy(ctx);
	return rc;
}
