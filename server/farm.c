/*
 * server/farm — the batch runner of umbra-render (see farm.h): worker threads on one renderer
 * context, progress on stderr, a JSON-lines report, a clean stop on Ctrl-C.
 */
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "api.h"
#include "buf.h"
#include "farm_internal.h"
#include "model_refs.h"
#include "umbra/rnd.h"
#include "umbra/rnd_math.h"

const char *const FARM_STATUS[] = {"pending", "ok", "invalid", "failed", "skipped"};
#define STATUS FARM_STATUS

volatile sig_atomic_t farm_stop;

static void on_signal(int sig)
{
	(void)sig;
	farm_stop = 1;
}

double farm_now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

char *farm_read_file(const char *path, size_t *len)
{
	FILE *f = strcmp(path, "-") ? fopen(path, "rb") : stdin;
	if (!f) return NULL;
	size_t cap = 1 << 16, n = 0;
	/* A file's size at once (a 50 MB model was copied by every doubling), hinted for huge pages
	 * before the read writes it (api_mem_huge); standard input grows as it comes. */
	struct stat st;
	if (f != stdin && fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && (uint64_t)st.st_size >= cap &&
	    (uint64_t)st.st_size < SIZE_MAX / 2)
		cap = (size_t)st.st_size + 1;   /* +1: the read that finds the end fits, no doubling */
	char *buf = malloc(cap + 1);
	if (buf) api_mem_huge(buf, cap + 1);
	while (buf) {
		n += fread(buf + n, 1, cap - n, f);
		if (n < cap) break;
		char *nb = realloc(buf, (cap *= 2) + 1);
		if (!nb) { free(buf); buf = NULL; errno = ENOMEM; }
		else buf = nb;
	}
	int bad = ferror(f), err = errno;
	if (f != stdin) fclose(f);
	if (bad) { free(buf); errno = err ? err : EIO; return NULL; }
	if (buf) buf[n] = 0;
	*len = n;
	return buf;
}

const char *farm_label(const struct farm_job *j)
{
	return j->label ? j->label : j->input ? j->input : "(inline)";
}

/* ---- one job ---- */

static const char *const MODEL_EXT[] = {"glb", "gltf", "obj", "stl", "ply", NULL};

/* The thumbnail document for a model file: the preset, the size, the model as part "model". */
static int thumb_doc(const struct farm_job *j, const struct farm_opts *o, char *doc, size_t size, char *err,
                     size_t esize)
{
	const char *dot = strrchr(j->input, '.'), *fmt = NULL;
	for (int i = 0; dot && !strchr(dot, '/') && MODEL_EXT[i]; i++)
		if (!strcasecmp(dot + 1, MODEL_EXT[i])) fmt = MODEL_EXT[i];
	if (!fmt) {
		snprintf(err, esize, "not a model file name (.glb, .gltf, .obj, .stl or .ply): %s", j->input);
		return -1;
	}
	char dims[64] = "", up[32] = "", out[96] = "";
	if (o->size) snprintf(dims, sizeof dims, "\"width\":%u,\"height\":%u,", o->size, o->size);
	if (o->up) snprintf(up, sizeof up, ",\"up\":\"%.4s\"", o->up);
	if (o->transparent || o->format) {
		int n = snprintf(out, sizeof out, "\"output\":{\"transparent\":%s", o->transparent ? "true" : "false");
		if (o->format) n += snprintf(out + n, sizeof out - (size_t)n, ",\"format\":\"%.4s\"", o->format);
		if (o->lossy) n += snprintf(out + n, sizeof out - (size_t)n, ",\"quality\":%g", o->quality);
		snprintf(out + n, sizeof out - (size_t)n, "},");
	}
	snprintf(doc, size, "{\"preset\":\"thumbnail\",%s%s\"objects\":[{\"shape\":\"model\",\"part\":\"model\","
	         "\"format\":\"%s\"%s}]}", dims, out, fmt, up);
	return 0;
}

/* The parts of a model job: the model as "model", then every file it refers to (a .gltf's
 * buffers and images, an .obj's .mtl and textures), read from the model's own directory with
 * api/model_refs.c's rules and that directory as the root (nothing above it, no link out), each
 * named by its reference, as a multipart request would carry them. An .obj's missing .mtl or
 * texture is left out (the parse then warns); a .gltf's missing file is the job's error.
 * 0, or -1 with err set. *parts is malloc'd; refs owns the files' bytes. */
static int model_parts(const char *input, const uint8_t *bytes, size_t len, struct api_model_refs *refs,
                       struct api_part **parts, size_t *nparts, char *err, size_t esize)
{
	static const enum api_model_format FMT[] = {API_MODEL_GLB, API_MODEL_GLTF, API_MODEL_OBJ, API_MODEL_STL,
	                                            API_MODEL_PLY};
	const char *dot = strrchr(input, '.'), *slash = strrchr(input, '/');
	enum api_model_format fmt = API_MODEL_STL;
	for (int i = 0; dot && MODEL_EXT[i]; i++)
		if (!strcasecmp(dot + 1, MODEL_EXT[i])) fmt = FMT[i];
	fmt = api_model_settle_format(bytes, len, fmt, NULL, 0);   /* the parse says so when they differ */
	char root[PATH_MAX];
	if (!slash) snprintf(root, sizeof root, ".");
	else snprintf(root, sizeof root, "%.*s", slash == input ? 1 : (int)(slash - input), input);
	struct api_ref_source src = {.root = root, .path = slash ? slash + 1 : input};
	int status;
	char why[400];
	memset(refs, 0, sizeof *refs);
	if (api_model_refs_collect(bytes, len, fmt, &src, refs, &status, why, sizeof why) != API_OK) {
		snprintf(err, esize, "%d %s: %s", status, input, why);
		return -1;
	}
	*parts = calloc(1 + refs->count, sizeof **parts);
	if (!*parts) {
		snprintf(err, esize, "out of memory");
		api_model_refs_release(refs);
		return -1;
	}
	(*parts)[0] = (struct api_part){.name = "model", .data = bytes, .len = len};
	for (size_t k = 0; k < refs->count; k++)
		(*parts)[1 + k] = (struct api_part){refs->files[k].name, refs->files[k].data, refs->files[k].len};
	*nparts = 1 + refs->count;
	return 0;
}

/* An input that is no file to render (a directory, an empty model) is the caller's mistake,
 * `invalid` (exit 2) like a bad scene, not a failure: true with r->error set. */
static bool input_refused(const struct farm_job *j, struct job_result *r)
{
	struct stat st;
	if (j->json || !strcmp(j->input, "-") || stat(j->input, &st) != 0) return false;
	const char *what = j->model ? "model" : "scene";
	if (S_ISDIR(st.st_mode))
		snprintf(r->error, sizeof r->error, "'%s' is a directory, not a %s file (name the files in it: %s/*.%s)",
		         j->input, what, j->input, j->model ? "glb" : "json");
	else if (j->model && !st.st_size)
		snprintf(r->error, sizeof r->error, "'%s' is an empty %s file (0 bytes)", j->input, what);
	else
		return false;
	return true;
}

void farm_job_input_release(struct job_input *in)
{
	free(in->bytes);
	free(in->parts);
	api_model_refs_release(&in->refs);
	memset(in, 0, sizeof *in);
}

/* Reads job i's bytes once: the scene (or the model, its thumbnail document and the files it
 * refers to) into *in, and the content hash of them all into r->hash. JOB_OK or the failure. */
enum job_status farm_job_read(struct farm *f, size_t i, struct job_input *in)
{
	const struct farm_job *j = &f->jobs[i];
	struct job_result *r = &f->res[i];
	memset(in, 0, sizeof *in);
	if (input_refused(j, r)) return JOB_INVALID;
	if (j->json) {
		in->doc = j->json;
		in->doc_len = strlen(j->json);
	} else if (!(in->bytes = farm_read_file(j->input, &in->len))) {
		snprintf(r->error, sizeof r->error, "cannot read '%s': %s", j->input, strerror(errno));
		return JOB_FAILED;
	} else {
		in->doc = in->bytes;
		in->doc_len = in->len;
	}
	uint64_t h = rnd_fnv1a(RND_FNV_SEED, in->doc, in->doc_len);
	if (j->model) {
		if (thumb_doc(j, f->o, in->thumb, sizeof in->thumb, r->error, sizeof r->error) < 0 ||
		    model_parts(j->input, (const uint8_t *)in->bytes, in->len, &in->refs, &in->parts, &in->nparts, r->error,
		                sizeof r->error) < 0) {
			farm_job_input_release(in);
			return JOB_INVALID;
		}
		for (size_t k = 1; k < in->nparts; k++) {   /* the files it refers to, by name and bytes */
			h = rnd_fnv1a(h, in->parts[k].name, strlen(in->parts[k].name) + 1);
			h = rnd_fnv1a(h, in->parts[k].data, in->parts[k].len);
		}
		in->doc = in->thumb;
		in->doc_len = strlen(in->thumb);
	}
	snprintf(r->hash, sizeof r->hash, "%016llx", (unsigned long long)h);
	return JOB_OK;
}

/* Parses the job's document into *s and settles its output path. JOB_OK or the failure. */
enum job_status farm_job_scene(struct farm *f, size_t i, const struct job_input *in, struct api_scene **s)
{
	const struct farm_job *j = &f->jobs[i];
	struct job_result *r = &f->res[i];
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = f->o->asset_root;
	struct api_problem prob;
	enum api_result ar = in->nparts ? api_scene_parse_parts(in->doc, in->doc_len, &lim, in->parts, in->nparts, s, &prob)
	                                : api_scene_parse(in->doc, in->doc_len, &lim, s, &prob);
	if (ar != API_OK) goto invalid;
	/* An explicit output name picks the format by extension; else the scene's format names it. */
	enum api_format fmt = (*s)->format;
	if (j->out) {
		if (!api_format_from_name(j->out, &fmt)) {
			snprintf(r->error, sizeof r->error, "output '%s' must end in .png, .exr, .webp or .avif", j->out);
			api_scene_free(*s);
			*s = NULL;
			return JOB_INVALID;
		}
		snprintf(r->out, sizeof r->out, "%s", j->out);
	} else {
		snprintf(r->out, sizeof r->out, "%s.%s", r->stem, api_format_name(fmt));
	}
	if (api_scene_set_format(*s, fmt, &prob) != API_OK || api_scene_check_output(*s, &prob) != API_OK)
		goto invalid;
	return JOB_OK;
invalid:
	api_scene_free(*s);   /* NULL-safe: a parse that failed left none */
	*s = NULL;
	api_problem_format(&prob, r->error, sizeof r->error);
	return JOB_INVALID;
}

int farm_write_file(const char *path, const uint8_t *b, size_t n, char *err, size_t esize)
{
	char tmp[PATH_MAX + 32];
	snprintf(tmp, sizeof tmp, "%s.tmp%ld.%lx", path, (long)getpid(), (unsigned long)pthread_self());
	FILE *fp = fopen(tmp, "wb");
	if (!fp) {
		snprintf(err, esize, "cannot write '%.400s': %s", tmp, strerror(errno));
		return -1;
	}
	size_t w = fwrite(b, 1, n, fp);
	if (fclose(fp) != 0 || w != n || rename(tmp, path) != 0) {
		snprintf(err, esize, "cannot write '%.400s': %s", path, strerror(errno));
		unlink(tmp);
		return -1;
	}
	return 0;
}

/* Job i by the server (--server): its bytes read and hashed, then skipped (--resume: an
 * earlier run made it) or sent. The local farm runs its jobs in two stages (farm_local.c). */
static enum job_status run_job(struct farm *f, size_t i)
{
	struct job_input in;
	enum job_status st = farm_job_read(f, i, &in);
	if (st != JOB_OK) return st;
	if (f->resume && farm_resume_hit(f->resume, f, i)) f->res[i].resumed = true;
	else st = farm_remote_job(f, i, &in);
	farm_job_input_release(&in);
	return st;
}

/* ---- progress ---- */

/* Called with f->mu held after job i finished. */
static void progress(struct farm *f, size_t i)
{
	/* images/s counts what was rendered now, not what an earlier run made (--resume) */
	double el = (farm_now_ms() - f->t0) / 1e3, rate = el > 0 ? (f->done - f->resumed) / el : 0;
	double eta = rate > 0 ? (f->n - f->done) / rate : 0;
	if (!f->bar) {
		fprintf(stderr, "umbra-render: [%zu/%zu] %s %s%s (%.0f ms)%s%s\n", f->done, f->n, farm_label(&f->jobs[i]),
		        STATUS[f->res[i].status], f->res[i].resumed ? " (resumed)" : "", f->res[i].ms,
		        f->res[i].error[0] ? ": " : "", f->res[i].error);
		return;
	}
	if (f->res[i].status != JOB_OK)  /* failures stay on screen above the bar */
		fprintf(stderr, "\r\033[K%s: %s: %s\n", farm_label(&f->jobs[i]), STATUS[f->res[i].status], f->res[i].error);
	char bar[31];
	size_t fill = f->n ? f->done * 30 / f->n : 30;
	for (size_t k = 0; k < 30; k++) bar[k] = k < fill ? '#' : '.';
	bar[30] = 0;
	fprintf(stderr, "\r\033[K[%s] %zu/%zu  %.2f images/s  ETA %.0fs%s", bar, f->done, f->n, rate, eta,
	        f->failed ? "  (failures above)" : "");
	if (f->done == f->n) fputc('\n', stderr);
}

void farm_finish(struct farm *f, size_t i, enum job_status st, double t0)
{
	pthread_mutex_lock(&f->mu);
	f->res[i].status = st;
	f->res[i].ms = farm_now_ms() - t0;
	f->done++;
	f->resumed += f->res[i].resumed;
	if (st != JOB_OK) f->failed++;
	farm_journal_line(f, i);   /* before the progress line: a line seen means it is in the report */
	progress(f, i);
	pthread_mutex_unlock(&f->mu);
}

static void *worker(void *arg)
{
	struct farm *f = arg;
	for (;;) {
		if (farm_stop) break;
		size_t i = atomic_fetch_add(&f->next, 1);
		if (i >= f->n) break;
		double t = farm_now_ms();
		farm_finish(f, i, run_job(f, i), t);
	}
	return NULL;
}

/* ---- the run ---- */

static void log_cb(void *user, int level, const char *msg)
{
	(void)user;
	if (level <= 1) fprintf(stderr, "umbra-render: %s\n", msg);
}

/* Default output stems: DIR/<file name without extension>, "-<k>" added when two inputs share one. */
static void name_outputs(struct farm *f)
{
	for (size_t i = 0; i < f->n; i++) {
		const char *in = f->jobs[i].input ? f->jobs[i].input : "scene";
		const char *base = strrchr(in, '/') ? strrchr(in, '/') + 1 : in;
		if (!strcmp(in, "-")) base = "stdin";
		const char *dot = strrchr(base, '.');
		int blen = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
		snprintf(f->res[i].stem, sizeof f->res[i].stem, "%s/%.*s", f->o->dir ? f->o->dir : ".", blen, base);
		for (size_t k = 0; k < i; k++)
			if (!strcmp(f->res[k].stem, f->res[i].stem)) {
				size_t l = strlen(f->res[i].stem);
				snprintf(f->res[i].stem + l, sizeof f->res[i].stem - l, "-%zu", i);
				break;
			}
	}
}

static unsigned thread_count(const struct farm_opts *o, size_t n)
{
	long cores = sysconf(_SC_NPROCESSORS_ONLN);
	unsigned t = o->threads ? o->threads : cores > 0 ? (unsigned)cores : 1;
	if (t > 64) t = 64;
	if (t > n) t = (unsigned)n;
	return t ? t : 1;
}

static int summary(const struct farm *f, unsigned threads)
{
	size_t cnt[5] = {0};
	for (size_t i = 0; i < f->n; i++) cnt[f->res[i].status]++;
	cnt[JOB_SKIPPED] += cnt[JOB_PENDING];
	double s = (farm_now_ms() - f->t0) / 1e3;
	char resumed[48] = "";
	if (f->resumed) snprintf(resumed, sizeof resumed, " (%zu from the earlier run)", f->resumed);
	fprintf(stderr, "umbra-render: %zu ok%s, %zu invalid, %zu failed, %zu skipped of %zu in %.1f s (%.2f images/s, "
	        "%u %s)%s\n", cnt[JOB_OK], resumed, cnt[JOB_INVALID], cnt[JOB_FAILED], cnt[JOB_SKIPPED], f->n, s,
	        s > 0 ? (cnt[JOB_OK] - f->resumed) / s : 0.0, threads, f->o->server ? "requests in flight" : "threads",
	        farm_stop ? ", interrupted" : "");
	if (farm_stop) return 130;
	if (cnt[JOB_FAILED]) return 1;
	return cnt[JOB_INVALID] ? 2 : 0;
}

/* --shard K/N: keeps inputs K, K+N, ... (their output names were settled over all inputs, so a
 * shard names a file as the whole run would). f->jobs becomes a malloc'd copy. */
static int take_shard(struct farm *f)
{
	unsigned k = f->o->shard_k, n = f->o->shard_n;
	struct farm_job *jobs = malloc((f->n / n + 1) * sizeof *jobs);
	if (!jobs) return -1;
	size_t m = 0;
	for (size_t i = k; i < f->n; i += n) {
		jobs[m] = f->jobs[i];
		f->res[m++] = f->res[i];
	}
	f->jobs = jobs;
	f->n = m;
	return 0;
}

/* The device (local) or the server's URL (remote), and the earlier report (--resume). */
static int farm_open(struct farm *f, unsigned threads)
{
	const struct farm_opts *o = f->o;
	if (o->server) {
		struct srv_http_error he;
		if (srv_http_url_parse(o->server, &f->url, &he) != SRV_HTTP_OK) {
			fprintf(stderr, "umbra-render: --server: %s\n", he.msg);
			return -1;
		}
	} else {
		const char *v = getenv("UMBRA_VALIDATION");
		struct rnd_context_desc cd = {.device_name = o->device, .validation = v && *v == '1', .slots = threads,
		                              .log = log_cb};
		struct rnd_error err;
		if (rnd_context_create(&cd, &f->ctx, &err) != RND_OK) {
			fprintf(stderr, "umbra-render: %s\n", err.msg);
			return -1;
		}
	}
	if (o->resume && o->report && !(f->resume = farm_resume_load(o->report))) {
		fprintf(stderr, "umbra-render: out of memory reading '%s'\n", o->report);
		return -1;
	}
	/* The report is rewritten in input order at the end; until then a line is added per
	 * finished job, in the order they finish, after the earlier report's lines when resuming
	 * (so a run killed before it reached them keeps them too; the last line of a file wins). */
	if (o->report && !(f->journal = fopen(o->report, o->resume ? "a" : "w"))) {
		fprintf(stderr, "umbra-render: cannot write report '%s': %s\n", o->report, strerror(errno));
		return -1;
	}
	return 0;
}

static void run_workers(struct farm *f, unsigned threads)
{
	struct sigaction sa = {.sa_handler = on_signal}, old_int, old_term;
	sigemptyset(&sa.sa_mask);
	sigaction(SIGINT, &sa, &old_int);
	sigaction(SIGTERM, &sa, &old_term);
	if (f->o->server) {
		pthread_t tids[64];
		unsigned started = 0;
		while (started < threads && pthread_create(&tids[started], NULL, worker, f) == 0) started++;
		if (!started) worker(f);   /* no thread could start: work on this one */
		for (unsigned k = 0; k < started; k++) pthread_join(tids[k], NULL);
	} else {
		farm_run_local(f, threads);
	}
	sigaction(SIGINT, &old_int, NULL);
	sigaction(SIGTERM, &old_term, NULL);
}

int farm_run(struct farm_job *jobs, size_t n, const struct farm_opts *o)
{
	if (o->dir && mkdir(o->dir, 0777) != 0 && errno != EEXIST) {
		fprintf(stderr, "umbra-render: cannot create '%s': %s\n", o->dir, strerror(errno));
		return 1;
	}
	struct farm f = {.jobs = jobs, .n = n, .o = o, .t0 = farm_now_ms()};
	f.res = calloc(n ? n : 1, sizeof *f.res);
	if (!f.res) return 1;
	f.bar = o->progress > 0 || (o->progress < 0 && isatty(2));
	name_outputs(&f);
	int rc = 1;
	if (o->shard_n > 1 && take_shard(&f) < 0) goto out_res;
	unsigned threads = thread_count(o, f.n);
	pthread_mutex_init(&f.mu, NULL);
	if (farm_open(&f, threads) < 0) goto out_open;
	run_workers(&f, threads);
	if (f.bar && f.done < f.n) fputc('\n', stderr);
	for (size_t i = 0; i < f.n; i++)
		if (f.res[i].status == JOB_PENDING) f.res[i].status = JOB_SKIPPED;
	rc = summary(&f, threads);
	if (f.journal) fclose(f.journal);
	f.journal = NULL;
	if (o->report && farm_write_report(&f, o->report) < 0 && rc == 0) rc = 1;
	if (f.ctx && rnd_context_validation_messages(f.ctx)) {
		fprintf(stderr, "umbra-render: %u Vulkan validation messages\n", rnd_context_validation_messages(f.ctx));
		if (rc == 0) rc = 1;
	}
out_open:
	if (f.journal) fclose(f.journal);
	farm_resume_free(f.resume);
	rnd_context_destroy(f.ctx);
	pthread_mutex_destroy(&f.mu);
	if (f.jobs != jobs) free(f.jobs);
out_res:
	free(f.res);
	return rc;
}
