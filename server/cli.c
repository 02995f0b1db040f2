/*
 * server/cli.c — umbra-render: renders scenes with the renderer library, no server.
 *
 *   umbra-render SCENE.json|- [-o OUT.png|OUT.exr|OUT.webp|OUT.avif] [--timings] [--device NAME]
 *   umbra-render --explain[=analyze] [--json] SCENE.json [-o OUT]  the render plan (render_explain.c)
 *   umbra-render SCENE.json... -o DIR/ [batch options]            many scenes, one process
 *   umbra-render --manifest LIST.jsonl -o DIR/ [batch options]    {"scene": ..., "output": ...} per line
 *   umbra-render thumb MODEL... -o DIR/ [--size N] [--transparent] [--up AXIS] [--format F [--quality Q]]
 *                [batch options]
 *   batch options: -j N (threads that parse and import, default one per core), --report FILE (JSON lines,
 *                  default DIR/report.jsonl), --progress | --no-progress (default: bar on a tty),
 *                  --server URL (render by umbrad / a balancer: -j N requests in flight, default 8),
 *                  --resume (skip inputs the report has as ok for the same bytes), --shard K/N
 *
 * One scene: exit 0 on success; 2 on an invalid scene (the problem text on stderr, as the
 * server's problem+json would say it); 1 otherwise. The extension of -o picks the format,
 * overriding output.format. Without -o the image goes to standard output.
 * Batch (server/farm.c; any of: thumb, --manifest, several scenes, -o naming a directory):
 * exit 0 only when every input rendered; 2 when the only failures are invalid inputs; 1 when
 * another failure happened; 130 when stopped by Ctrl-C (the renders in flight are finished).
 * UMBRA_VALIDATION=1 turns the Vulkan validation layer on; any message then fails the run.
 */
#include <ctype.h>
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "api.h"
#include "explain_text.h"
#include "farm.h"
#include "umbra/rnd.h"

/* --explain: none, the plan alone (no render), or the plan rendered with what it measured. */
enum cli_explain { CLI_EXPLAIN_NONE, CLI_EXPLAIN_PLAN, CLI_EXPLAIN_ANALYZE };

static int usage(FILE *f, int code)
{
	fprintf(f, "usage: umbra-render SCENE.json|- [-o OUT.png|OUT.exr|OUT.webp|OUT.avif] [--timings] [--device NAME]\n"
	           "       umbra-render --explain[=analyze] [--json] SCENE.json|- [-o OUT]\n"
	           "       umbra-render SCENE.json... -o DIR/ [batch options]\n"
	           "       umbra-render --manifest LIST.jsonl -o DIR/ [batch options]\n"
	           "       umbra-render thumb MODEL... -o DIR/ [--size N] [--transparent] [--up AXIS] [--format F [--quality Q]]\n"
	           "                    [batch options]\n"
	           "  Renders scenes (contract: scene-v1). Exit 0 ok, 2 invalid input, 1 other failure, 130 interrupted.\n"
	           "  -o FILE      output file; .png, .exr, .webp or .avif picks the format (default: stdout, output.format)\n"
	           "  -o DIR/      batch: one image per input in DIR (name of the input, extension of the format)\n"
	           "  --timings    print per-stage milliseconds to stderr (one scene)\n"
	           "  --explain    print the render plan instead of rendering: every decision (views, shadow maps,\n"
	           "               levels of detail, what casts, passes, memory) as JSON (api/explain.schema.json),\n"
	           "               or as a table when stdout is a terminal; =analyze renders it too and adds what\n"
	           "               each step measured (the image into -o's file, or nowhere)\n"
	           "  --json       --explain: JSON on a terminal too\n"
	           "  --device S   use the Vulkan device whose name contains S (also $UMBRA_DEVICE)\n"
	           "  --asset-root DIR  models' \"path\" is relative to DIR and never leaves it (default: none, a 400)\n"
	           "  thumb        MODEL files (.glb .gltf .obj .stl .ply) as thumbnails: \"preset\": \"thumbnail\"\n"
	           "               (framed, lit by the studio environment and its shadows, a ground shadow catcher)\n"
	           "  --size N     thumbnail width and height (default 512)\n"
	           "  --transparent  thumbnails on a transparent background (the ground shadow in alpha)\n"
	           "  --up AXIS    thumbnails: the models' up axis, z y x -z -y -x (default y; z for most STL and\n"
	           "               CAD/3D-printing OBJ files), or auto (y or z, from where the model would touch\n"
	           "               the ground; docs/models.md): the model object's \"up\"\n"
	           "  --format F   thumbnails: png (default), webp or avif (lossless), or exr: output.format\n"
	           "  --quality Q  thumbnails with --format webp or avif: lossy at quality 0..100: output.quality\n"
	           "  --manifest F JSON lines {\"scene\": \"a.json\" | {...}, \"output\": \"a.png\"}; paths relative to F\n"
	           "  -j N         batch: threads that read, parse and import (default: one per core); renders run on\n"
	           "               one more (a CPU device) or N more (a GPU)\n"
	           "  --report F   batch: JSON-lines report (file, output, status, ms, error, stages); default DIR/report.jsonl\n"
	           "  --progress, --no-progress  batch: progress bar / plain lines on stderr (default: bar on a tty)\n"
	           "  --server URL batch: render by umbrad or a cluster at http://HOST:PORT (-j N requests in flight,\n"
	           "               default 8); same inputs, outputs, report and exit status; retries lost connections,\n"
	           "               502/504 (4 times) and 503 after Retry-After; a 4xx is `invalid`\n"
	           "  --resume     batch: skip inputs whose report line says ok for the same bytes (\"hash\") and whose\n"
	           "               output is there: after Ctrl-C, the same command with --resume renders the rest\n"
	           "  --shard K/N  batch: only inputs K, K+N, K+2N... (0-based, input order; default report\n"
	           "               DIR/report-K-of-N.jsonl), e.g. --shard $JOB_COMPLETION_INDEX/4\n");
	return code;
}

static void log_cb(void *user, int level, const char *msg)
{
	(void)user;
	if (level <= 1) fprintf(stderr, "umbra-render: %s\n", msg);
}

/* Reads and parses one scene and settles its format (the output name's extension wins).
 * 0 with *scene set, or the exit status (problem on stderr). */
static int load_scene(const char *in, const char *out, const char *asset_root, struct api_scene **scene)
{
	size_t len = 0;
	char *json = farm_read_file(in, &len);
	if (!json) {
		fprintf(stderr, "umbra-render: cannot read '%s': %s\n", in, strerror(errno));
		return 1;
	}
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = asset_root;
	struct api_problem prob;
	char line[1024];
	enum api_result r = api_scene_parse(json, len, &lim, scene, &prob);
	free(json);
	if (r == API_OK && out) {
		const char *dot = strrchr(out, '.');
		enum api_format f = (*scene)->format;
		if (!api_format_from_name(out, &f) && dot && !strchr(dot, '/'))
			r = api_problem_set(&prob, 400, "", "cannot write '%s': umbra-render writes PNG (.png), EXR (.exr), "
			                    "WebP (.webp) or AVIF (.avif)", out);
		if (r == API_OK) r = api_scene_set_format(*scene, f, &prob);
	}
	if (r == API_OK) r = api_scene_check_output(*scene, &prob);
	if (r == API_OK) {
		/* What the image leaves out of what was asked (umbrad: the Umbra-Warnings header). */
		if ((*scene)->warnings[0]) fprintf(stderr, "umbra-render: %s: warning: %s\n", in, (*scene)->warnings);
		return 0;
	}
	api_problem_format(&prob, line, sizeof line);
	fprintf(stderr, "umbra-render: %s\n", line);
	api_scene_free(*scene);
	*scene = NULL;
	return 2;
}

static struct rnd_context *open_context(const char *device)
{
	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {
		.device_name = device, .validation = v && *v == '1', .slots = 1, .log = log_cb,
	};
	struct rnd_context *ctx = NULL;
	struct rnd_error err;
	if (rnd_context_create(&cd, &ctx, &err) != RND_OK) {
		fprintf(stderr, "umbra-render: %s\n", err.msg);
		return NULL;
	}
	return ctx;
}

/* A failed plan or render on stderr; the exit status (2: the scene's fault). */
static int render_failed(const struct api_scene *scene, enum rnd_result r, const struct rnd_error *err)
{
	bool scene_fault = r == RND_ERR_INVALID || r == RND_ERR_LIMIT;
	if (scene_fault) {
		struct api_problem prob;
		char line[1024];
		api_problem_from_render(&prob, scene, err, r == RND_ERR_LIMIT ? 422 : 400);
		api_problem_format(&prob, line, sizeof line);
		fprintf(stderr, "umbra-render: %s\n", line);
	} else {
		fprintf(stderr, "umbra-render: render failed: %s\n", err->msg);
	}
	return scene_fault ? 2 : 1;
}

/* The encoded image into out (stdout without one): 0, or 1 with the reason on stderr.
 * *enc_ms: the encoding's time. */
static int write_image(const struct api_scene *scene, const struct rnd_image *img, const char *out, double *enc_ms)
{
	struct api_problem prob;
	char line[1024];
	double t0 = farm_now_ms();
	uint8_t *bytes = NULL;
	size_t nbytes = 0;
	if (api_encode(scene, img, &bytes, &nbytes, &prob) != API_OK) {
		api_problem_format(&prob, line, sizeof line);
		fprintf(stderr, "umbra-render: %s\n", line);
		return 1;
	}
	*enc_ms = farm_now_ms() - t0;
	FILE *f = out ? fopen(out, "wb") : stdout;
	int rc = 1;
	if (!f) {
		fprintf(stderr, "umbra-render: cannot write '%s': %s\n", out, strerror(errno));
	} else {
		size_t w = fwrite(bytes, 1, nbytes, f);
		if ((f != stdout ? fclose(f) : fflush(f)) != 0 || w != nbytes)
			fprintf(stderr, "umbra-render: cannot write '%s': %s\n", out ? out : "(stdout)", strerror(errno));
		else
			rc = 0;
	}
	free(bytes);
	return rc;
}

/* The plan on stdout: JSON, or on a terminal (unless json) the text table. */
static int print_plan(const struct api_scene *scene, const struct rnd_plan *plan, const struct api_plan_times *t,
                      bool json)
{
	if (!json && isatty(STDOUT_FILENO)) {
		srv_explain_text(stdout, plan);
		return fflush(stdout) ? 1 : 0;
	}
	size_t len = 0;
	char *doc = api_plan_json(scene, plan, t, &len);
	int rc = doc && fwrite(doc, 1, len, stdout) == len && fputc('\n', stdout) != EOF && !fflush(stdout) ? 0 : 1;
	if (rc) fprintf(stderr, "umbra-render: cannot write the plan\n");
	free(doc);
	return rc;
}

/* One scene, as before the batch runner: stdout or one file, --timings; with --explain its
 * plan on stdout instead of the image, and with --explain=analyze the plan rendered, with
 * what each step measured (the image into -o's file, or nowhere). */
static int render_one(const char *in, const char *out, const char *device, const char *asset_root, int timings,
                      enum cli_explain explain, bool json)
{
	double t0 = farm_now_ms();
	struct api_scene *scene = NULL;
	int rc = load_scene(in, out, asset_root, &scene);
	if (rc) return rc;
	double t_parse = farm_now_ms() - t0, t_ctx = farm_now_ms(), t_enc = 0;
	struct rnd_context *ctx = open_context(device);
	if (!ctx) {
		api_scene_free(scene);
		return 1;
	}
	t_ctx = farm_now_ms() - t_ctx;
	struct rnd_image img = {0};
	struct rnd_timings tm = {0};
	struct rnd_error err;
	struct rnd_plan *plan = NULL;
	enum rnd_result r = rnd_plan_create(ctx, &scene->scene, &plan, &err);
	if (r == RND_OK && explain != CLI_EXPLAIN_PLAN) r = rnd_render_plan(ctx, plan, &img, &tm, &err);
	if (r != RND_OK) rc = render_failed(scene, r, &err);
	else if (explain != CLI_EXPLAIN_PLAN && (out || !explain)) rc = write_image(scene, &img, out, &t_enc);
	if (!rc && explain) {
		struct api_plan_times t = {t_parse, explain == CLI_EXPLAIN_ANALYZE && out ? t_enc : -1, farm_now_ms() - t0};
		rc = print_plan(scene, plan, &t, json);
	}
	if (!rc && timings && explain != CLI_EXPLAIN_PLAN)
		fprintf(stderr, "parse %.2f ms, device %.2f ms, plan %.2f ms, upload %.2f ms, targets %.2f ms, compile %.2f ms, "
		        "shadow %.2f ms, main %.2f ms, readback %.2f ms, encode %.2f ms, total %.2f ms, %u shadow maps, "
		        "environment %.2f ms and %u directions\n",
		        t_parse, t_ctx, tm.plan_ms, tm.upload_ms, tm.targets_ms, tm.compile_ms, tm.shadow_ms, tm.main_ms,
		        tm.readback_ms, t_enc,
		        farm_now_ms() - t0, tm.shadow_maps_rendered, tm.env_ms, tm.env_directions);
	if (rnd_context_validation_messages(ctx)) {
		fprintf(stderr, "umbra-render: %u Vulkan validation messages\n", rnd_context_validation_messages(ctx));
		rc = 1;
	}
	rnd_image_release(&img);
	rnd_plan_destroy(plan);
	rnd_context_destroy(ctx);
	api_scene_free(scene);
	return rc;
}

/* ---- arguments ---- */

struct args {
	const char *out, *device, *manifest, *report;
	const char **inputs;
	size_t ninputs;
	bool thumb;
	int timings;
	enum cli_explain explain;   /* --explain[=analyze] */
	bool json;                  /* --json: the plan as JSON on a terminal too */
	enum api_format format;   /* thumb --format (PNG by default) */
	struct farm_opts farm;
};

/* Parses a positive integer option value; 0 when it is not one. */
static unsigned uint_arg(const char *s, unsigned max)
{
	char *end;
	unsigned long v = strtoul(s, &end, 10);
	return *s && !*end && v > 0 && v <= max ? (unsigned)v : 0;
}

/* --up's value: "z", "+z", "-z", ... as the scene's "+z" etc.; NULL when it is none. */
static const char *up_arg(const char *s)
{
	static const char *const axes[] = {"+y", "-y", "+z", "-z", "+x", "-x", "auto"};
	for (int i = 0; i < 7; i++)
		if (!strcasecmp(s, axes[i]) || (axes[i][0] == '+' && !strcasecmp(s, axes[i] + 1))) return axes[i];
	return NULL;
}

/* --format's value: png, webp, avif or exr (any case) as output.format names it; NULL when it is none. */
static const char *format_arg(const char *s, enum api_format *f)
{
	for (int k = API_FORMAT_PNG; k < API_FORMAT_COUNT; k++)
		if (!strcasecmp(s, api_format_name((enum api_format)k))) return api_format_name(*f = (enum api_format)k);
	return NULL;
}

/* --quality's value: a number 0..100 (output.quality). */
static bool quality_arg(const char *s, float *q)
{
	char *end;
	double v = strtod(s, &end);
	if (!*s || *end || !(v >= 0 && v <= 100)) return false;
	*q = (float)v;
	return true;
}

/* --shard K/N (0 <= K < N <= 100000); false when it is not that. */
static bool shard_arg(const char *s, struct farm_opts *o)
{
	char *end, *end2;
	unsigned long k = strtoul(s, &end, 10), n;
	if (end == s || *end != '/' || !isdigit((unsigned char)s[0])) return false;
	n = strtoul(end + 1, &end2, 10);
	if (end2 == end + 1 || *end2 || n == 0 || n > 100000 || k >= n) return false;
	o->shard_k = (unsigned)k;
	o->shard_n = (unsigned)n;
	return true;
}

/* getopt_long, as umbrad's flags.c: options and inputs in any order ("-" is an input: stdin). */
/* The long options (getopt_long). */
enum { O_TIMINGS = 1000, O_TRANSPARENT, O_PROGRESS, O_NO_PROGRESS, O_DEVICE, O_ASSET_ROOT, O_MANIFEST,
       O_REPORT, O_SIZE, O_UP, O_FORMAT, O_QUALITY, O_SERVER, O_RESUME, O_SHARD, O_EXPLAIN, O_JSON };
static const struct option cli_options[] = {
	{"help", no_argument, NULL, 'h'}, {"timings", no_argument, NULL, O_TIMINGS},
	{"transparent", no_argument, NULL, O_TRANSPARENT}, {"progress", no_argument, NULL, O_PROGRESS},
	{"no-progress", no_argument, NULL, O_NO_PROGRESS}, {"device", required_argument, NULL, O_DEVICE},
	{"asset-root", required_argument, NULL, O_ASSET_ROOT}, {"manifest", required_argument, NULL, O_MANIFEST},
	{"report", required_argument, NULL, O_REPORT}, {"size", required_argument, NULL, O_SIZE},
	{"up", required_argument, NULL, O_UP}, {"format", required_argument, NULL, O_FORMAT},
	{"quality", required_argument, NULL, O_QUALITY}, {"server", required_argument, NULL, O_SERVER},
	{"resume", no_argument, NULL, O_RESUME}, {"shard", required_argument, NULL, O_SHARD},
	{"explain", optional_argument, NULL, O_EXPLAIN}, {"json", no_argument, NULL, O_JSON}, {0},
};

static int parse_args(int argc, char **argv, struct args *a)
{
	a->farm.progress = -1;
	a->inputs = calloc((size_t)argc, sizeof *a->inputs);
	if (!a->inputs) return 1;
	optind = 1;
	if (argc > 1 && !strcmp(argv[1], "thumb")) a->thumb = true, optind = 2;
	for (int c; (c = getopt_long(argc, argv, "ho:j:", cli_options, NULL)) != -1;) {
		switch (c) {
		case 'h': return usage(stdout, 0) - 1;
		case 'o': a->out = optarg; break;
		case O_TIMINGS: a->timings = 1; break;
		case O_TRANSPARENT: a->farm.transparent = true; break;
		case O_PROGRESS: case O_NO_PROGRESS: a->farm.progress = c == O_PROGRESS; break;
		case O_DEVICE: a->device = optarg; break;
		case O_ASSET_ROOT: a->farm.asset_root = optarg; break;
		case O_MANIFEST: a->manifest = optarg; break;
		case O_REPORT: a->report = optarg; break;
		case O_SERVER: a->farm.server = optarg; break;
		case O_RESUME: a->farm.resume = true; break;
		case O_JSON: a->json = true; break;
		case O_EXPLAIN:
			a->explain = !optarg || !strcmp(optarg, "plan") ? CLI_EXPLAIN_PLAN
			             : !strcmp(optarg, "analyze")      ? CLI_EXPLAIN_ANALYZE
			                                               : CLI_EXPLAIN_NONE;
			if (a->explain) break;
			fprintf(stderr, "umbra-render: bad option --explain=%s (plan or analyze)\n", optarg);
			return usage(stderr, 1);
		case O_SHARD:
			if (shard_arg(optarg, &a->farm)) break;
			fprintf(stderr, "umbra-render: bad option --shard %s (K/N with 0 <= K < N, e.g. 0/4)\n", optarg);
			return usage(stderr, 1);
		case O_UP:
			if ((a->farm.up = up_arg(optarg))) break;
			fprintf(stderr, "umbra-render: bad option --up %s (one of z y x -z -y -x auto)\n", optarg);
			return usage(stderr, 1);
		case O_FORMAT:
			if ((a->farm.format = format_arg(optarg, &a->format))) break;
			fprintf(stderr, "umbra-render: bad option --format %s (png, webp, avif or exr)\n", optarg);
			return usage(stderr, 1);
		case O_QUALITY:
			if ((a->farm.lossy = quality_arg(optarg, &a->farm.quality))) break;
			fprintf(stderr, "umbra-render: bad option --quality %s (0..100)\n", optarg);
			return usage(stderr, 1);
		case 'j': case O_SIZE:
			if ((c == 'j' ? (a->farm.threads = uint_arg(optarg, 64)) : (a->farm.size = uint_arg(optarg, 8192))))
				break;
			fprintf(stderr, "umbra-render: bad option %s %s\n", c == 'j' ? "-j" : "--size", optarg);
			return usage(stderr, 1);
		default: return usage(stderr, 1);   /* getopt_long said what was wrong */
		}
	}
	for (int i = optind; i < argc; i++) a->inputs[a->ninputs++] = argv[i];
	if (!a->ninputs && !a->manifest) return usage(stderr, 1);
	if (a->farm.server && a->farm.asset_root) {   /* a scene's "path" is the daemon's to resolve */
		fprintf(stderr, "umbra-render: --asset-root is the daemon's with --server (umbrad --asset-root)\n");
		return usage(stderr, 1);
	}
	if (a->farm.up && !a->thumb) {   /* a scene says its models' "up" itself */
		fprintf(stderr, "umbra-render: --up is for thumb (in a scene, give the model object \"up\")\n");
		return usage(stderr, 1);
	}
	if (a->farm.format && !a->thumb) {   /* a scene's format: its output.format or the -o name */
		fprintf(stderr, "umbra-render: --format is for thumb (a scene says output.format, or -o names it)\n");
		return usage(stderr, 1);
	}
	if (a->farm.lossy && !api_format_lossy(a->format)) {
		fprintf(stderr, "umbra-render: --quality is for thumb --format webp or avif (lossy)\n");
		return usage(stderr, 1);
	}
	return 0;
}

static bool is_dir(const char *path)
{
	struct stat st;
	size_t n = strlen(path);
	return (n && path[n - 1] == '/') || (stat(path, &st) == 0 && S_ISDIR(st.st_mode));
}

/* Manifest lines become jobs (*n of them, also on failure) that own their strings. */
static int manifest_jobs(const char *path, const char *dir, struct farm_job **jobs, size_t *n)
{
	size_t len = 0;
	char *text = farm_read_file(path, &len);
	if (!text) {
		fprintf(stderr, "umbra-render: cannot read '%s': %s\n", path, strerror(errno));
		return 1;
	}
	const char *slash = strrchr(path, '/');
	int dlen = slash ? (int)(slash - path + 1) : 0;
	size_t cap = 16, line_no = 0;
	*jobs = calloc(cap, sizeof **jobs);
	for (char *line = text, *next; *jobs && line && *line; line = next) {
		next = strchr(line, '\n');
		if (next) *next++ = 0;
		line_no++;
		if (!line[strspn(line, " \t\r")]) continue;
		struct api_manifest_entry e;
		struct api_problem prob;
		if (api_manifest_line(line, strlen(line), &e, &prob) != API_OK) {
			fprintf(stderr, "umbra-render: %s:%zu: %s%s%s\n", path, line_no, prob.pointer, prob.pointer[0] ? ": " : "",
			        prob.detail);
			free(text);
			return 2;
		}
		if (*n == cap) {
			struct farm_job *nj = realloc(*jobs, (cap *= 2) * sizeof *nj);
			if (!nj) break;
			*jobs = nj;
		}
		struct farm_job *j = &(*jobs)[(*n)++];
		memset(j, 0, sizeof *j);
		char *lbl = NULL, *in = NULL, *out = NULL;
		/* A relative scene path is relative to the manifest's directory. */
		int pre = e.scene_path && e.scene_path[0] != '/' ? dlen : 0;
		if (e.scene_path && asprintf(&in, "%.*s%s", pre, path, e.scene_path) < 0) in = NULL;
		if (!e.scene_path && asprintf(&lbl, "%s:%zu", path, line_no) < 0) lbl = NULL;
		if (e.output && asprintf(&out, "%s/%s", dir, e.output) < 0) out = NULL;
		j->input = in;
		j->json = e.scene_json;
		j->label = e.scene_path ? in : lbl;
		j->out = out;
		e.scene_json = NULL;
		api_manifest_entry_release(&e);
	}
	free(text);
	if (!*jobs) return 1;
	return 0;
}

int main(int argc, char **argv)
{
	struct args a = {0};
	int rc = parse_args(argc, argv, &a);
	if (rc) {
		free(a.inputs);
		return rc < 0 ? 0 : rc;
	}
	bool batch = a.thumb || a.manifest || a.ninputs > 1 || (a.out && is_dir(a.out));
	if (!batch && (a.farm.server || a.farm.resume || a.farm.shard_n)) {
		fprintf(stderr, "umbra-render: --server, --resume and --shard are for batches (thumb, several scenes, "
		        "--manifest, -o DIR/)\n");
		free(a.inputs);
		return 1;
	}
	if (batch && a.explain) {
		fprintf(stderr, "umbra-render: --explain is for one scene\n");
		free(a.inputs);
		return 1;
	}
	if (!batch) {
		rc = render_one(a.inputs[0], a.out, a.device, a.farm.asset_root, a.timings, a.explain, a.json);
		free(a.inputs);
		return rc;
	}
	if (!a.out) {
		fprintf(stderr, "umbra-render: several images need an output directory: -o DIR/\n");
		free(a.inputs);
		return 1;
	}
	/* "DIR/" and "DIR" name the same directory; paths inside it get one slash. */
	char dir[PATH_MAX];
	snprintf(dir, sizeof dir, "%s", a.out);
	for (size_t l = strlen(dir); l > 1 && dir[l - 1] == '/'; l--) dir[l - 1] = 0;
	char report[PATH_MAX + 32];
	if (a.farm.shard_n > 1)   /* shards writing into one directory each keep their own report */
		snprintf(report, sizeof report, "%s/report-%u-of-%u.jsonl", dir, a.farm.shard_k, a.farm.shard_n);
	else
		snprintf(report, sizeof report, "%s/report.jsonl", dir);
	if (a.farm.server && !a.farm.threads) a.farm.threads = 8;
	a.farm.dir = dir;
	a.farm.report = a.report ? a.report : report;
	a.farm.device = a.device;
	struct farm_job *jobs = NULL;
	size_t n = 0;
	if (a.manifest) rc = manifest_jobs(a.manifest, dir, &jobs, &n);
	size_t nman = n;
	if (!rc && a.ninputs) {
		struct farm_job *nj = realloc(jobs, (n + a.ninputs) * sizeof *nj);
		if (!nj) rc = 1;
		else jobs = nj;
		for (size_t k = 0; !rc && k < a.ninputs; k++)
			jobs[n++] = (struct farm_job){.input = a.inputs[k], .model = a.thumb};
	}
	if (!rc) rc = farm_run(jobs, n, &a.farm);
	for (size_t k = 0; k < nman; k++) {  /* the manifest's jobs own their strings */
		if (jobs[k].label != jobs[k].input) free((char *)jobs[k].label);
		free((char *)jobs[k].input);
		free((char *)jobs[k].json);
		free((char *)jobs[k].out);
	}
	free(jobs);
	free(a.inputs);
	return rc;
}
