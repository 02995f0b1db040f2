/*
 * server/farm — umbra-render's batch runner: many scenes or models in one warm process.
 *
 * Usage (server/cli.c):
 *   struct farm_job jobs[n] = {{.input = "a.json", .out = "DIR/a.png"}, ...};  // or .model = true
 *   struct farm_opts o = {.threads = 0, .report = "DIR/report.jsonl"};
 *   int code = farm_run(jobs, n, &o);    // exit status: 0 all rendered, 1 some failed, 130 interrupted
 *
 * One renderer context; `threads` threads take the next job and parse it (a model's sandboxed
 * import included) while render threads (one on a CPU device, `threads` on a GPU) render the
 * parsed ones and write their files (renamed into place when complete): server/farm_local.c.
 * So every core is busy and the device, pipelines and shadow atlas are set up once. A model job renders the
 * file with `"preset": "thumbnail"` (api/preset.h) as a multipart part, with the files it refers
 * to (a .gltf's .bin and images, an .obj's .mtl and textures) read from the model's own
 * directory as further parts (api/model_refs.h's rules, that directory as the root). Progress goes to
 * stderr: a bar (done/total, images/s, ETA) on a terminal, one line per finished job otherwise.
 * opts.server: no renderer here; each job is POSTed to umbrad (or a balancer) with the same
 * document and parts, `threads` requests in flight, retried when the connection was lost or a
 * balancer said 502/503/504 (server/farm_remote.c). opts.resume: a job whose earlier report
 * line says ok for the same content hash, and whose output is there, is not rendered again;
 * while the run goes the report holds a line per finished job (flushed), so a farm killed by
 * SIGKILL resumes too, and it is rewritten in input order at the end.
 * SIGINT / SIGTERM: no new job starts; the renders in flight finish and are written; the rest
 * are reported "skipped". The report (JSON lines, input order) has file, output, status (ok,
 * invalid: a bad scene or model, or an input that is a directory or an empty model file;
 * failed, skipped), ms, error, hash (of the input's files). opts.up gives every model object
 * that `up` (Z-up STL files); opts.format and opts.quality every thumbnail that output.format
 * and output.quality.
 *
 * Ownership: jobs and their strings belong to the caller. farm_run() is not reentrant (signal
 * handlers); call it once per process.
 */
#ifndef UMBRA_FARM_H
#define UMBRA_FARM_H

#include <stdbool.h>
#include <stddef.h>

struct farm_job {
	const char *input;       /* scene file (or "-"), or model file when model is set */
	const char *json;        /* inline scene document instead of input's bytes (manifest), or NULL */
	const char *label;       /* name in progress and report (NULL: input) */
	const char *out;         /* output path; NULL: from input's name in opts.dir with the scene's format */
	bool model;
};

struct farm_opts {
	const char *dir;          /* output directory (created if missing) */
	const char *report;       /* JSON-lines report path, NULL: none */
	const char *device;       /* Vulkan device name filter, NULL: first */
	const char *asset_root;   /* directory models' `path` is relative to, NULL: none (a 400) */
	unsigned threads;         /* 0: one per core */
	unsigned size;            /* thumbnails: width = height (0: the preset's 512) */
	bool transparent;         /* thumbnails: transparent background */
	const char *up;           /* thumbnails: every model's `up` ("+z", ...), NULL: the file's own (+y) */
	const char *format;       /* thumbnails: output.format ("png", "webp", "exr"), NULL: the preset's (png) */
	bool lossy;               /* thumbnails: output.quality = quality (lossy WebP); false: none (lossless) */
	float quality;            /* 0..100, with lossy */
	int progress;             /* -1 auto (bar on a tty), 0 plain lines, 1 bar */
	const char *server;       /* http://HOST:PORT of umbrad or a balancer: render there, not here */
	bool resume;              /* skip inputs the report already has as ok, same hash, output there */
	unsigned shard_k, shard_n; /* shard_n > 1: only inputs k, k+N, k+2N, ... (0-based input order) */
};

int farm_run(struct farm_job *jobs, size_t n, const struct farm_opts *o);

/* Whole file (or stdin for "-"), malloc'd; NULL with errno set. */
char *farm_read_file(const char *path, size_t *len);
double farm_now_ms(void);

#endif
