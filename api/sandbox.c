/*
 * api/sandbox — the daemon's side of the sandboxed importer (see sandbox.h): hands the fork
 * server (started by api/sandbox_server.c) one job at a time per calling thread, maps its reply
 * and turns how the job ended into an answer. The helper's side is api/sandbox_child.c.
 */
#include <errno.h>
#include <math.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "model_lod.h"
#include "model_wire.h"
#include "sandbox.h"
#include "sandbox_stats.h"
#include "umbra/rnd_math.h"
#include "workers.h"

/* The daemon waits this long past the job's timeout for the fork server to report: it kills
 * the child at the timeout, so only a stuck fork server could make the daemon wait longer. */
#define GRACE_MS 2000
#define MAX_TEXTURE_PIXELS (64ull << 20)

__attribute__((format(printf, 5, 6)))
static enum api_result fail(int *status, int code, char *err, size_t errsize, const char *fmt, ...)
{
	*status = code;
	if (err && errsize) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(err, errsize, fmt, ap);
		va_end(ap);
	}
	return API_ERR;
}

static int64_t now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* Writes the input and reads the reply at the same time until EOF or the deadline. */
static int exchange(int fd, const uint8_t *in, size_t len, int64_t deadline, size_t max_reply, uint8_t **reply,
                    size_t *rlen)
{
	size_t sent = 0, got = 0, cap = 0;
	uint8_t *buf = NULL;
	fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
	if (!len) shutdown(fd, SHUT_WR);
	for (;;) {
		int64_t left = deadline - now_ms();
		if (left <= 0) break;
		struct pollfd p = {fd, (short)(POLLIN | (sent < len ? POLLOUT : 0)), 0};
		if (poll(&p, 1, (int)(left > 1000 ? 1000 : left)) < 0 && errno != EINTR) break;
		if (sent < len && (p.revents & (POLLOUT | POLLERR))) {
			ssize_t w = send(fd, in + sent, len - sent, MSG_NOSIGNAL);
			if (w > 0 && (sent += (size_t)w) == len) shutdown(fd, SHUT_WR);
			if (w < 0 && errno != EAGAIN && errno != EINTR) sent = len; /* the child is gone: read what it said */
		}
		if (!(p.revents & (POLLIN | POLLHUP | POLLERR))) continue;
		if (got == cap) {
			size_t ncap = cap ? cap * 2 : 65536;
			if (ncap > max_reply) ncap = max_reply;
			uint8_t *n = ncap > cap ? realloc(buf, ncap) : NULL;
			if (!n) break; /* over the cap: refused below as incomplete */
			buf = n;
			cap = ncap;
		}
		ssize_t r = recv(fd, buf + got, cap - got, 0);
		if (r == 0) {
			*reply = buf;
			*rlen = got;
			return 0;
		}
		if (r > 0) got += (size_t)r;
		else if (errno != EAGAIN && errno != EINTR) break;
	}
	free(buf);
	return -1;
}

static int read_status(int fd, int64_t deadline, struct api_sbx_status *st)
{
	size_t got = 0;
	while (got < sizeof *st) {
		int64_t left = deadline - now_ms();
		struct pollfd p = {fd, POLLIN, 0};
		if (left <= 0) return -1;
		int pr = poll(&p, 1, (int)left);
		if (pr < 0 && errno == EINTR) continue;
		if (pr <= 0) return -1;
		ssize_t r = read(fd, (char *)st + got, sizeof *st - got);
		if (r < 0 && errno == EINTR) continue;
		if (r <= 0) return -1;
		got += (size_t)r;
	}
	return st->magic == API_SBX_MAGIC ? 0 : -1;
}

static const char *signal_name(int sig)
{
	switch (sig) {
	case SIGSEGV: return "segmentation fault";
	case SIGABRT: return "abort";
	case SIGBUS: return "bus error";
	case SIGFPE: return "arithmetic exception";
	case SIGILL: return "illegal instruction";
	default: return "signal";
	}
}

/* How the child ended, when it did not end well (*how says which way, for the counters); 0 when
 * it exited 0 (the reply decides). */
static int classify(const struct api_sbx_status *st, bool got_reply, const struct api_sbx_request *rq, int *status,
                    enum api_sbx_outcome *how, char *err, size_t errsize)
{
	unsigned cpu_s = (rq->timeout_ms + 999) / 1000;
	*how = API_SBX_OUT_CRASHED;
	switch (st->how) {
	case API_SBX_TIMED_OUT:
		*how = API_SBX_OUT_TIMED_OUT;
		return fail(status, 422, err, errsize, "took longer than the import time limit of %u ms", rq->timeout_ms), -1;
	case API_SBX_REFUSED:
		*how = API_SBX_OUT_ERROR;
		return fail(status, 500, err, errsize, "the model importer could not start a process (%s)",
		            strerror(st->code)), -1;
	case API_SBX_SIGNALED:
		if (st->code == SIGXCPU || st->code == SIGKILL) {
			*how = API_SBX_OUT_TIMED_OUT;
			return fail(status, 422, err, errsize, "used more than the import CPU time limit of %u s", cpu_s), -1;
		}
		if (st->code == SIGSYS)
			return fail(status, 400, err, errsize, "the importer was stopped by its sandbox (a forbidden system "
			            "call) while reading it"), -1;
		return fail(status, 400, err, errsize, "the importer crashed reading it (%s, signal %d)",
		            signal_name(st->code), st->code), -1;
	case API_SBX_EXITED:
		if (st->code == 0 && got_reply) return 0;
		*how = st->code == API_SBX_EXIT_OOM ? API_SBX_OUT_OVER_MEMORY
		     : st->code == API_SBX_EXIT_SETUP ? API_SBX_OUT_ERROR : API_SBX_OUT_CRASHED;
		if (st->code == API_SBX_EXIT_OOM)
			return fail(status, 422, err, errsize, "needed more than the import memory limit of %llu MiB",
			            (unsigned long long)(rq->memory >> 20)), -1;
		if (st->code == API_SBX_EXIT_SETUP)
			return fail(status, 500, err, errsize, "the model importer could not set up its sandbox"), -1;
		return fail(status, 400, err, errsize, "the importer failed reading it (exit status %d)", st->code), -1;
	default:
		*how = API_SBX_OUT_ERROR;
		return fail(status, 500, err, errsize, "the model importer sent an unknown status"), -1;
	}
}

/* Appends to a 422 over an import limit what changes that limit: umbrad's flag, or (a caller
 * without them: umbra-render) that nothing here does. */
static void limit_hint(const struct api_limits *lim, enum api_sbx_outcome how, char *err, size_t errsize)
{
	if (how != API_SBX_OUT_TIMED_OUT && how != API_SBX_OUT_OVER_MEMORY) return;
	const char *flag = how == API_SBX_OUT_TIMED_OUT ? "--import-timeout-ms" : "--import-memory";
	size_t n = err ? strlen(err) : 0;
	if (!err || n + 1 >= errsize) return;
	if (lim->import_flags) snprintf(err + n, errsize - n, " (this server's %s)", flag);
	else snprintf(err + n, errsize - n, " (a fixed limit in umbra-render, which has no option for it; umbrad sets it "
	              "with %s)", flag);
}

static enum api_sbx_job job_of(uint32_t kind)
{
	return kind == API_WIRE_LEVELS ? API_SBX_JOB_LEVELS : kind == API_WIRE_IMAGE ? API_SBX_JOB_IMAGE : API_SBX_JOB_MODEL;
}

/* The counters' end of a job that started at t0_ms (api_clock_ms). */
static void job_ended(uint32_t kind, enum api_sbx_outcome how, double t0_ms)
{
	api_sbx_stats_ended(job_of(kind), how, (api_clock_ms() - t0_ms) / 1e3);
}

/* A job's reply: its sealed memfd mapped read-only, and the body after the header. */
struct reply {
	void *map;              /* NULL: none */
	size_t len;
	const uint8_t *body;
	size_t body_len;
};

static void reply_release(struct reply *r)
{
	if (r->map) munmap(r->map, r->len);
	r->map = NULL;
}

/* The reply's memory hands over to arena (released with it): 0, or -1 (the caller keeps it). */
static int reply_to_arena(struct reply *r, struct api_arena *arena)
{
	if (api_arena_own_mapping(arena, r->map, r->len) != 0) return -1;
	r->map = NULL;
	return 0;
}

/* The reply file of an exited child, which says it wrote len bytes: exactly that long, sealed
 * against writing, growing and shrinking (refused while any writable mapping is left: none
 * is, the child has exited and nobody else had the file), mapped read-only. 0, or -1. */
static int map_reply(int fd, uint64_t len, struct reply *r)
{
	struct stat st;
	if (!len || len > SIZE_MAX || fstat(fd, &st) < 0 || (uint64_t)st.st_size != len ||
	    fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_WRITE | F_SEAL_SEAL) < 0)
		return -1;
	void *p = mmap(NULL, (size_t)len, PROT_READ, MAP_SHARED | MAP_POPULATE, fd, 0);
	if (p == MAP_FAILED) return -1;
	r->map = p;
	r->len = (size_t)len;
	return 0;
}

/* The reply file for a job: an empty memfd the child writes (up to its RLIMIT_FSIZE). -1 with
 * err. */
static int reply_file(int *status, char *err, size_t errsize)
{
	int fd = memfd_create("umbra-import-reply", MFD_CLOEXEC | MFD_ALLOW_SEALING);
	if (fd < 0) fail(status, 500, err, errsize, "cannot create the importer's reply file: %s", strerror(errno));
	return fd;
}

/* Hands the job to the fork server and waits for the child: 0 when it exited 0 and wrote
 * the reply's length (*len), else -1 with the failure classified (*how, *status, err). */
static int await_child(struct api_sbx_request *rq, const uint8_t *data, int reply_fd, uint64_t *len,
                       enum api_sbx_outcome *how, int *status, char *err, size_t errsize)
{
	int ds[2], ps[2];
	if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ds) < 0)
		return fail(status, 500, err, errsize, "cannot create a socket for the importer: %s", strerror(errno)), -1;
	if (pipe2(ps, O_CLOEXEC) < 0) {
		close(ds[0]);
		close(ds[1]);
		return fail(status, 500, err, errsize, "cannot create a pipe for the importer: %s", strerror(errno)), -1;
	}
	char serr[200];
	int sent = api_sbx_send(rq, ds[1], ps[1], reply_fd, serr, sizeof serr), rc = -1;
	close(ds[1]);
	close(ps[1]);
	if (sent < 0) {
		fail(status, 500, err, errsize, "%s", serr);
		goto out;
	}
	int64_t deadline = now_ms() + rq->timeout_ms + GRACE_MS;
	/* On the socket only the length (u64); a little room to see anything more. */
	uint8_t *got = NULL;
	size_t glen = 0;
	bool replied = exchange(ds[0], data, rq->input_len, deadline, 16, &got, &glen) == 0 && glen == sizeof *len;
	if (replied) memcpy(len, got, sizeof *len);
	free(got);
	/* A child that said more than it should: its writes fail at once instead of blocking it
	 * until the timeout. */
	if (!replied) shutdown(ds[0], SHUT_RDWR);
	struct api_sbx_status st;
	if (read_status(ps[0], deadline, &st) < 0) {
		if (now_ms() >= deadline) {
			*how = API_SBX_OUT_TIMED_OUT;
			fail(status, 422, err, errsize, "took longer than the import time limit of %u ms", rq->timeout_ms);
		} else {
			fail(status, 500, err, errsize, "the model importer stopped before reporting");
		}
		goto out;
	}
	rc = classify(&st, replied, rq, status, how, err, errsize);
out:
	close(ds[0]);
	close(ps[0]);
	return rc;
}

/* Jobs of this process in their child now. */
static atomic_uint jobs_running;

/* A job's threads: this machine's cores shared among the jobs running (a model's import
 * or levels; the others are single-threaded), at most 4: 1 when every core has a job. */
static uint32_t job_threads(uint32_t kind, unsigned running)
{
	static long cores;
	if (!cores) cores = sysconf(_SC_NPROCESSORS_ONLN);
	if (kind == API_WIRE_IMAGE || cores < 2) return 1;
	long t = cores / (running ? running : 1);
	return t < 1 ? 1 : t > 4 ? 4 : (uint32_t)t;
}

/* One job: its reply (mapped, header checked) or a classified failure, *how the outcome
 * (API_SBX_OUT_OK with API_OK; the caller's check of the body may still refuse it). */
static enum api_result run_job(struct api_sbx_request *rq, const uint8_t *data, const struct api_limits *lim,
                               struct reply *reply, enum api_sbx_outcome *how, int *status, char *err,
                               size_t errsize)
{
	struct api_limits def;
	if (!lim) {
		api_limits_defaults(&def);
		lim = &def;
	}
	rq->magic = API_SBX_MAGIC;
	rq->timeout_ms = lim->import_timeout_ms ? lim->import_timeout_ms : 10000;
	rq->memory = lim->import_memory;
	memset(reply, 0, sizeof *reply);
	*how = API_SBX_OUT_ERROR;
	api_sbx_stats_started(job_of(rq->kind));
	/* A reply is never bigger than the child's memory; without a limit, 4 GiB. */
	uint64_t len = 0;
	rq->reply_size = rq->memory ? rq->memory : (uint64_t)4 << 30;
	int fd = reply_file(status, err, errsize);
	enum api_result rc = API_ERR;
	rq->threads = job_threads(rq->kind, atomic_fetch_add(&jobs_running, 1) + 1);
	int awaited = fd < 0 ? -1 : await_child(rq, data, fd, &len, how, status, err, errsize);
	atomic_fetch_sub(&jobs_running, 1);
	if (awaited < 0) goto out;
	if (len > rq->reply_size || map_reply(fd, len, reply) < 0) {
		*how = API_SBX_OUT_INVALID;
		fail(status, 400, err, errsize, "the importer's reply (%llu bytes, it says) cannot be mapped",
		     (unsigned long long)len);
		goto out;
	}
	enum api_wire_kind kind = rq->kind;
	enum api_wire_status ws;
	char msg[API_WIRE_MAX_MESSAGE + 1], werr[200];
	if (api_wire_header(reply->map, reply->len, &kind, &ws, msg, sizeof msg, &reply->body, &reply->body_len, werr,
	                    sizeof werr) != API_OK || kind != rq->kind) {
		*how = API_SBX_OUT_INVALID;
		fail(status, 400, err, errsize, "%s", kind != rq->kind ? "the importer's reply is of the wrong kind" : werr);
		goto out;
	}
	*how = ws == API_WIRE_OK ? API_SBX_OUT_OK : ws == API_WIRE_OVER_MEMORY ? API_SBX_OUT_OVER_MEMORY : API_SBX_OUT_INVALID;
	if (ws == API_WIRE_BAD_INPUT) fail(status, 400, err, errsize, "%s", msg);
	else if (ws == API_WIRE_OVER_MEMORY)
		fail(status, 422, err, errsize, "needed more than the import memory limit of %llu MiB (%s)",
		     (unsigned long long)(rq->memory >> 20), msg);
	else rc = API_OK;
out:
	if (fd >= 0) close(fd);
	if (rc != API_OK) {
		reply_release(reply);
		limit_hint(lim, *how, err, errsize);
	}
	return rc;
}

enum api_result api_sandbox_import_bundle(const uint8_t *bundle, size_t bundle_len, size_t len, size_t nfiles,
                                          enum api_model_format format, const struct api_limits *lim,
                                          struct api_arena *arena, struct api_model *out, size_t *bytes,
                                          int *status, char *err, size_t errsize)
{
	*status = 0;
	struct api_sbx_request rq = {.kind = API_WIRE_MODEL, .format = (uint32_t)format,
	                             .max_pixels = MAX_TEXTURE_PIXELS, .input_len = bundle_len, .model_len = len,
	                             .file_count = (uint32_t)nfiles, .output_side = lim ? lim->output_side : 0};
	struct reply reply;
	enum api_sbx_outcome how;
	double t0 = api_clock_ms();
	if (run_job(&rq, bundle, lim, &reply, &how, status, err, errsize) != API_OK) {
		job_ended(rq.kind, how, t0);
		return API_ERR;
	}
	double t1 = api_clock_ms();
	/* The model's arrays stay in the reply's mapping, which its arena now owns. */
	enum api_result rc = reply_to_arena(&reply, arena) == 0 ? API_OK : API_ERR;
	if (rc != API_OK) fail(status, 500, err, errsize, "out of memory");
	else if ((rc = api_wire_decode_model(reply.body, reply.body_len, API_WIRE_IN_PLACE, arena, MAX_TEXTURE_PIXELS, out,
	                                     bytes, err, errsize)) != API_OK)
		*status = 400;
	job_ended(rq.kind, rc == API_OK ? API_SBX_OUT_OK : API_SBX_OUT_INVALID, t0);
	/* the round trip less what the importer says it spent (its clock is this machine's) */
	float work = 0;
	for (int k = API_IMPORT_PARSE; k <= API_IMPORT_LEVEL; k++) work += out->times.ms[k];
	out->times.ms[API_IMPORT_TRANSFER] = fmaxf((float)(t1 - t0) - work, 0.0f);
	out->times.ms[API_IMPORT_VALIDATE] = (float)(api_clock_ms() - t1);
	out->format = format;
	reply_release(&reply);
	return rc;
}

enum api_result api_sandbox_import_model(const uint8_t *data, size_t len, enum api_model_format format,
                                         const struct api_limits *lim, struct api_arena *arena,
                                         struct api_model *out, size_t *bytes, int *status, char *err,
                                         size_t errsize)
{
	return api_sandbox_import_bundle(data, len, len, 0, format, lim, arena, out, bytes, status, err, errsize);
}

enum api_result api_sandbox_build_levels(const struct api_model *m, uint32_t side, const struct api_limits *lim,
                                         struct api_arena *arena, struct api_mesh_levels *out, size_t *bytes,
                                         int *status, char *err, size_t errsize)
{
	*status = 0;
	*bytes = 0;
	memset(out, 0, m->mesh_count * sizeof *out);
	/* The input: the meshes that want levels, as a model of their own (one plain material,
	 * an instance each), in the wire format the importer answers in. */
	struct api_model_mesh *meshes = calloc(m->mesh_count, sizeof *meshes);
	const struct api_model_mesh **sent = calloc(m->mesh_count, sizeof *sent);
	struct api_model_instance *inst = calloc(m->mesh_count, sizeof *inst);
	uint32_t *which = calloc(m->mesh_count, sizeof *which), n = 0;
	struct api_mesh_levels *got = calloc(m->mesh_count, sizeof *got);
	struct rnd_material mat;
	rnd_material_defaults(&mat);
	struct api_wire_buf in = {0};
	enum api_result rc = API_ERR;
	if (!meshes || !sent || !inst || !which || !got) {
		fail(status, 500, err, errsize, "out of memory building levels of detail");
		goto out;
	}
	for (uint32_t i = 0; i < m->mesh_count; i++) {
		if (!api_mesh_wants_levels(&m->meshes[i])) continue;
		meshes[n] = m->meshes[i];
		meshes[n].material = 0;
		meshes[n].lods = NULL;
		meshes[n].lod_count = 0;
		meshes[n].caster = NULL;   /* built at import; the job builds levels only */
		sent[n] = &m->meshes[i];
		rnd_mat4_identity(inst[n].model);
		inst[n].mesh = n;
		which[n++] = i;
	}
	if (!n) {
		rc = API_OK;
		goto out;
	}
	struct api_model job = {.meshes = meshes, .mesh_count = n, .instances = inst, .instance_count = n,
	                        .materials = &mat, .material_count = 1};
	api_wire_put_model(&in, &job);
	if (in.failed) {
		fail(status, 500, err, errsize, "out of memory building levels of detail");
		goto out;
	}
	struct api_sbx_request rq = {.kind = API_WIRE_LEVELS, .max_pixels = 1, .input_len = in.len, .model_len = in.len,
	                             .output_side = side};
	struct reply reply;
	enum api_sbx_outcome how;
	double t0 = api_clock_ms();
	if (run_job(&rq, in.data, lim, &reply, &how, status, err, errsize) != API_OK) {
		job_ended(rq.kind, how, t0);
		goto out;
	}
	if (reply_to_arena(&reply, arena) != 0) {
		fail(status, 500, err, errsize, "out of memory building levels of detail");
		reply_release(&reply);
		job_ended(rq.kind, API_SBX_OUT_ERROR, t0);
		goto out;
	}
	rc = api_wire_decode_levels(reply.body, reply.body_len, API_WIRE_IN_PLACE, sent, n, arena, got, bytes, err, errsize);
	job_ended(rq.kind, rc == API_OK ? API_SBX_OUT_OK : API_SBX_OUT_INVALID, t0);
	if (rc != API_OK) {
		*status = 400;
		goto out;
	}
	for (uint32_t k = 0; k < n; k++) out[which[k]] = got[k];
out:
	api_wire_buf_release(&in);
	free(meshes);
	free(sent);
	free(inst);
	free(which);
	free(got);
	return rc;
}

enum api_result api_sandbox_decode_image(const uint8_t *data, size_t len, uint64_t max_pixels,
                                         const struct api_limits *lim, uint8_t **rgba, uint32_t *w, uint32_t *h,
                                         int *status, char *err, size_t errsize)
{
	*status = 0;
	*rgba = NULL;
	if (!max_pixels) max_pixels = MAX_TEXTURE_PIXELS;
	struct api_sbx_request rq = {.kind = API_WIRE_IMAGE, .max_pixels = max_pixels, .input_len = len};
	struct reply reply;
	enum api_sbx_outcome how;
	double t0 = api_clock_ms();
	if (run_job(&rq, data, lim, &reply, &how, status, err, errsize) != API_OK) {
		job_ended(rq.kind, how, t0);
		return API_ERR;
	}
	enum api_result rc = api_wire_decode_image(reply.body, reply.body_len, max_pixels, rgba, w, h, err, errsize);
	if (rc != API_OK) *status = 400;
	job_ended(rq.kind, rc == API_OK ? API_SBX_OUT_OK : API_SBX_OUT_INVALID, t0);
	reply_release(&reply);
	return rc;
}
