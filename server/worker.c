/*
 * umbrad workers: the threads that turn a queued request into an answer (the shared
 * rnd_context they render on is server/context.c, its warm-up server/warmup.c):
 *   deadline check -> api_scene_parse -> Accept -> deadline check -> rnd_render -> api_encode
 *   -> deadline check -> srv_request_finish().
 * A worker never touches the request after srv_request_finish().
 *
 * Deadlines: --deadline-ms counts from when the request was queued. The renderer gets it as an
 * absolute time and stops between submits once it has passed (504). A render also yields
 * (504) when a request has waited in the queue for half the deadline, so that one huge
 * request cannot make every request behind it miss its deadline; one render yields per waiter.
 *
 * Device loss: the render that saw it marks the daemon not ready (/readyz 503) before its own
 * 503 answer goes out; its worker then recreates the context (srv_context_recover) and runs
 * the warm-up again, and only then is the daemon ready again.
 */
#include <malloc.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "explain.h"
#include "imports.h"
#include "log.h"
#include "metrics.h"
#include "negotiate.h"
#include "queue.h"
#include "results.h"
#include "srv.h"

/* ---- jobs ---- */

static void job_problem(struct srv_request *req, const struct api_problem *p)
{
	req->status = p->status;
	req->content_type = "application/problem+json";
	srv_request_note_problem(req, p);
	char *json = api_problem_json(p);
	req->out = (uint8_t *)json;
	req->out_len = json ? strlen(json) : 0;
}

static bool past_deadline(const struct srv_server *s, const struct srv_request *req, double now)
{
	return s->cfg.deadline_ms && (now - req->t_queued) * 1000.0 > (double)s->cfg.deadline_ms;
}

static void job_deadline(struct srv_server *s, struct srv_request *req, const char *when, double now)
{
	struct api_problem p;
	api_problem_set(&p, 504, "", "the render passed its deadline of %u ms %s (%.0f ms since it was queued)",
	                s->cfg.deadline_ms, when, (now - req->t_queued) * 1000.0);
	srv_metrics_add(s->metrics, SRV_CTR_DEADLINE, 1);
	job_problem(req, &p);
}

/* After a request admitted this big its memory goes back to the system at once
 * (srv_context_trim: shadow maps nobody holds, atlas pages, the heap), not at the idle trim. */
#define BIG_REQUEST_BYTES (64ull << 20)
/* Nothing less than that is trimmed per request: a thumbnail farm sends a model of a few MB
 * every request. Dropping every map after each (with the atlas pages, faulted in again by the
 * next render) made a model sent again draw all its maps again; a malloc_trim after each gave
 * back the free heap srv_heap_policy keeps, for the next request to fault in again (the corpus
 * over HTTP at c=4, 4 alternated pairs: 6.4-7.9 images/s with it, 6.6-8.5 without; RSS 1 s after
 * the run 163-177 MB either way). --max-rss and the idle trim bound what stays. */

static int render_status(enum rnd_result r)
{
	switch (r) {
	case RND_ERR_INVALID: return 400;
	case RND_ERR_LIMIT: return 422;
	case RND_ERR_TIMEOUT: return 504;
	case RND_ERR_OOM: return 503;
	case RND_ERR_DEVICE_LOST: return 503;   /* the context is recreated: a retry can succeed */
	default: return 500;
	}
}

/* Admission by memory: the render plan's estimate of what the scene allocates (the plan the
 * render then executes: made once, here), against --max-memory (admit.h). held: what its
 * parse holds already (api_memory_gate). 0 admitted (*need, held included, to release); -1
 * refused (p is filled; held still to release); -2 no plan (*r, *err: the render's error, a
 * limit no retry can cure among them: one allocation over the device's). */
static int admit(struct srv_server *s, const struct srv_request *req, const struct api_scene *sc, uint64_t held,
                 struct srv_plan *plan, uint64_t *need, enum rnd_result *r, struct rnd_error *err, struct api_problem *p)
{
	struct rnd_estimate est;
	*r = srv_plan(s, &sc->scene, plan, err);
	if (*r == RND_ERR_DEVICE_LOST) return 0; /* the render itself reports it */
	if (*r != RND_OK) return -2;
	rnd_plan_estimate(plan->plan, &est);
	uint64_t n = est.device_bytes + est.host_bytes;
	double deadline = s->cfg.deadline_ms ? req->t_queued + s->cfg.deadline_ms / 1000.0 : 0;
	if (srv_admit_grow(&s->admit, sc, held, n, deadline, p) != 0) {
		if (p->status == 504) srv_metrics_add(s->metrics, SRV_CTR_DEADLINE, 1);
		return -1;
	}
	*need = held + n;
	return 0;
}

/* The renderer's cancel callback: yield to a request that has waited half its deadline. */
struct render_watch {
	struct srv_server *srv;
	bool yielded;
};

static bool render_should_yield(void *user)
{
	struct render_watch *w = user;
	struct srv_server *s = w->srv;
	double oldest = srv_queue_oldest(s->queue), gated = srv_gate_oldest(&s->gate);
	if (gated > 0 && (oldest <= 0 || gated < oldest)) oldest = gated;
	if (oldest <= 0 || srv_now() < oldest + s->cfg.deadline_ms / 2000.0)
		return false;
	uint_fast64_t mark = (uint_fast64_t)(oldest * 1e9), prev = atomic_load(&s->yield_mark);
	/* One render yields per waiter: the one that moves the mark. */
	if (prev == mark || !atomic_compare_exchange_strong(&s->yield_mark, &prev, mark))
		return false;
	w->yielded = true;
	return true;
}

/* What a parse may take (api.h's gates): the import of a model the cache lacks, on an import
 * thread only (server/imports.h; on a worker the request goes to them: refused), and memory,
 * admitted against --max-memory as it goes (reserved: what it holds, released with the render's). */
struct parse_ticket {
	struct api_import_gate imports;
	struct api_memory_gate memory;
	struct srv_server *s;
	double deadline;
	bool importer, refused;
	uint64_t reserved;
};

static bool ticket_import(void *user)
{
	struct parse_ticket *t = user;
	if (!t->importer) t->refused = true;
	return t->importer;
}

static bool ticket_memory(void *user, uint64_t bytes, struct api_problem *p)
{
	struct parse_ticket *t = user;
	if (srv_admit_grow(&t->s->admit, NULL, t->reserved, bytes, t->deadline, p) != 0) {
		if (p->status == 504) srv_metrics_add(t->s->metrics, SRV_CTR_DEADLINE, 1);
		return false;
	}
	t->reserved += bytes;
	return true;
}

static void ticket_init(struct parse_ticket *t, struct srv_server *s, const struct srv_request *req, bool importer)
{
	*t = (struct parse_ticket){ .imports = { ticket_import, t }, .memory = { ticket_memory, t }, .s = s,
	                            .deadline = s->cfg.deadline_ms ? req->t_queued + s->cfg.deadline_ms / 1000.0 : 0,
	                            .importer = importer };
}

/* The render's identity once its scene is parsed and its format settled: the ETag (negotiate.h
 * srv_etag_of), and what follows from it before anything is rendered. 0: go on; 1: answered
 * (412 for a POST whose If-None-Match lists it; for POST /v1/renders a 303 when its image is
 * stored already; for GET /v1/renders/{hash} a 404 when the scene no longer makes that hash). */
static int job_identity(struct srv_server *s, struct srv_request *req, const struct api_scene *sc)
{
	struct api_problem p = { 0 };
	const char *mime = api_format_mime(sc->format);
	if (req->route == SRV_ROUTE_EXPLAIN)
		return 0;   /* a plan is no image: no ETag, no condition, nothing stored */
	pthread_rwlock_rdlock(&s->ctx_lock);
	req->etag_hash = srv_etag_of(sc->scene_hash, sc->asset_hash, mime, s->info.device_name, s->info.driver_info);
	pthread_rwlock_unlock(&s->ctx_lock);
	srv_etag_format(req->etag, sizeof req->etag, req->etag_hash);
	if (req->route == SRV_ROUTE_RESULT && req->etag_hash != req->result_hash) {
		api_problem_set(&p, 404, "", "no stored render %s: its scene now makes another image (a file it reads "
		                "under --asset-root changed); POST the scene to /v1/renders again", req->path);
		req->etag[0] = 0;
		job_problem(req, &p);
		return 1;
	}
	if (req->route != SRV_ROUTE_RESULT && srv_etag_matches(req->if_none_match, req->etag)) {
		/* RFC 9110 §13.1.2: a POST whose condition fails is a 412, not a 304. */
		srv_metrics_add(s->metrics, SRV_CTR_NOT_MODIFIED, 1);
		api_problem_set(&p, 412, "", "If-None-Match lists %s, this scene's ETag: the image the caller holds is "
		                "this render's, so nothing was rendered", req->etag);
		job_problem(req, &p);
		return 1;
	}
	if (req->route == SRV_ROUTE_RENDERS &&
	    srv_results_get(s->results, req->etag_hash, srv_format_ext(mime), NULL, NULL) == SRV_RESULT_IMAGE) {
		srv_metrics_add(s->metrics, SRV_CTR_RESULT_HIT, 1);
		srv_result_name(req->location, sizeof req->location, req->etag_hash, mime);
		req->status = 303;
		return 1;
	}
	return 0;
}

/* Parses the request's body and parts into *scp and settles what the answer depends on (its
 * warnings, its format, its ETag: job_identity). 0: go on and render; 1: the request is
 * answered already (a problem, 412, 303); 2: parked for an import thread (a worker's parse
 * reached a model to import): not this thread's any more. *scp, when set, is the caller's to
 * free either way. */
static int job_parse(struct srv_server *s, struct srv_request *req, struct parse_ticket *t, struct api_scene **scp,
                     double *parse_s)
{
	struct api_problem p = { 0 };
	double t0 = srv_now();
	struct api_part parts[64];
	size_t nparts = req->part_count < 64 ? req->part_count : 64;
	for (size_t i = 0; i < nparts; i++)
		parts[i] = (struct api_part){ req->parts[i].name, req->parts[i].data, req->parts[i].len };
	struct api_limits lim = s->cfg.limits;
	lim.import_gate = &t->imports;
	lim.memory_gate = &t->memory;
	enum api_result pr = api_scene_parse_parts(req->body, req->body_len, &lim, parts, nparts, scp, &p);
	if (pr != API_OK && t->refused) {
		api_scene_free(*scp);
		*scp = NULL;
		srv_admit_release(&s->admit, t->reserved);   /* its import thread parses it again */
		t->reserved = 0;
		srv_imports_park(s->imports, req);
		return 2;
	}
	/* The body and parts are no longer needed (but for the result cache, which keeps a small
	 * scene to render its image again): give their memory back before the render. */
	if (pr == API_OK && req->route != SRV_ROUTE_RENDER && s->results && !req->kept.body)
		srv_scene_keep(&req->kept, req);
	srv_request_drop_body(req);
	if (pr != API_OK) {
		job_problem(req, &p);
		return 1;
	}
	struct api_scene *sc = *scp;
	/* A header value is one line of printable ASCII: file names from a model may hold anything. */
	for (size_t i = 0; i + 1 < sizeof req->warnings && (req->warnings[i] = sc->warnings[i]); i++)
		if ((unsigned char)req->warnings[i] < 0x20 || (unsigned char)req->warnings[i] > 0x7e) req->warnings[i] = '?';
	enum api_format accepted = req->want == SRV_ACCEPT_EXR    ? API_FORMAT_EXR
	                           : req->want == SRV_ACCEPT_AVIF ? API_FORMAT_AVIF
	                                                          : API_FORMAT_WEBP;
	if ((req->want != SRV_ACCEPT_PNG && !sc->format_explicit && api_scene_set_format(sc, accepted, &p) != API_OK) ||
	    api_scene_check_output(sc, &p) != API_OK) {
		job_problem(req, &p);
		return 1;
	}
	if (job_identity(s, req, sc))
		return 1;
	*parse_s = srv_now() - t0;
	srv_metrics_stage(s->metrics, SRV_STAGE_PARSE, *parse_s);
	return 0;
}

/* The encoded image of a render route: POST /v1/render answers it; POST /v1/renders stores it
 * (with its kept scene) and answers 303 to its GET form, or the image itself (200) when it
 * cannot be stored (larger than --result-cache-mb); GET /v1/renders/{hash} stores and answers it.
 * Takes bytes. */
static void job_answer(struct srv_server *s, struct srv_request *req, const struct api_scene *sc, uint8_t *bytes,
                       size_t len)
{
	const char *mime = api_format_mime(sc->format), *ext = srv_format_ext(mime);
	req->status = 200;
	req->out = bytes;
	req->out_len = len;
	req->content_type = mime;
	if (req->route == SRV_ROUTE_RENDER)
		return;
	bool stored = srv_results_put(s->results, req->etag_hash, ext,
	                              &(struct srv_result_image){ bytes, len, mime, req->warnings }, &req->kept);
	if (!stored || req->route != SRV_ROUTE_RENDERS)
		return;
	srv_result_name(req->location, sizeof req->location, req->etag_hash, mime);
	req->status = 303;
	req->out = NULL;
	req->out_len = 0;
	req->content_type = NULL;
	free(bytes);
}

/* The problem a failed render answers: 504 past the deadline (said differently when the render
 * was stopped for the requests waiting behind it), 503 on device loss, else the renderer's own
 * error mapped to its member. */
static void job_render_failed(struct srv_server *s, struct srv_request *req, const struct api_scene *sc,
                              enum rnd_result r, const struct rnd_error *err, bool yielded)
{
	struct api_problem p = { 0 };
	double tf = srv_now();
	srv_metrics_add(s->metrics, SRV_CTR_RENDER_FAILED, 1);
	if (r == RND_ERR_TIMEOUT)
		srv_metrics_add(s->metrics, SRV_CTR_DEADLINE, 1);
	if (r == RND_ERR_TIMEOUT && yielded)
		api_problem_set(&p, 504, "", "the render was stopped %.0f ms after it was queued (%s) so that requests "
		                "waiting behind it can meet their deadline of %u ms", (tf - req->t_queued) * 1000.0,
		                err->msg, s->cfg.deadline_ms);
	else if (r == RND_ERR_TIMEOUT)
		api_problem_set(&p, 504, "", "the render passed its deadline of %u ms and was stopped %.0f ms after it "
		                "was queued (%s)", s->cfg.deadline_ms, (tf - req->t_queued) * 1000.0, err->msg);
	else if (r == RND_ERR_DEVICE_LOST)
		api_problem_set(&p, 503, "", "the GPU device was lost (%s); the renderer is being recreated, retry",
		                err->msg);
	else
		api_problem_from_render(&p, sc, err, render_status(r));
	srv_log(SRV_LOG_WARN, "request %s: render failed: %s (%s)", req->id, err->msg, rnd_result_str(r));
	job_problem(req, &p);
}

static void job_render_stages(struct srv_server *s, const struct rnd_timings *t)
{
	srv_metrics_add(s->metrics, SRV_CTR_RENDER_OK, 1);
	srv_metrics_add(s->metrics, SRV_CTR_SHADOW_RENDERED, t->shadow_maps_rendered);
	srv_metrics_add(s->metrics, SRV_CTR_SHADOW_REUSED, t->shadow_maps_reused);
	srv_metrics_stage(s->metrics, SRV_STAGE_UPLOAD, t->upload_ms / 1000.0);
	srv_metrics_stage(s->metrics, SRV_STAGE_SHADOW, t->shadow_ms / 1000.0);
	srv_metrics_stage(s->metrics, SRV_STAGE_MAIN, t->main_ms / 1000.0);
	srv_metrics_stage(s->metrics, SRV_STAGE_READBACK, t->readback_ms / 1000.0);
}

/* Server-Timing: every stage of the request, the models' imports among them (api.h,
 * api_import_stage: only with a model read or imported), `parse` what is left of parsing (the
 * JSON, the checks, the cache look-ups), `device-wait` the wait for the device (one render at a
 * time on a CPU device: server/gate.h), so that the stages add up to all but the gaps between
 * them. `plan` is the render plan's (made at admission, before the device wait). */
/* Appends to a Server-Timing header of cap bytes at *n; past the end it is cut (and stays terminated). */
__attribute__((format(printf, 4, 5)))
static void timing_append(char *buf, size_t cap, size_t *n, const char *fmt, ...)
{
	if (*n >= cap) return;
	va_list ap;
	va_start(ap, fmt);
	int w = vsnprintf(buf + *n, cap - *n, fmt, ap);
	va_end(ap);
	if (w > 0) *n = (size_t)w < cap - *n ? *n + (size_t)w : cap;
}

static void format_timing(struct srv_request *req, const struct api_scene *sc, const struct rnd_timings *t,
                          double queue_ms, double parse_ms, double gate_ms, double encode_ms, double total_ms)
{
	char *h = req->server_timing;
	size_t cap = sizeof req->server_timing, n = 0;
	double in_models = 0;
	bool models = sc->import.imports || sc->import.ms[API_IMPORT_READ] > 0;
	if (models)
		for (int k = 0; k < API_IMPORT_STAGES; k++) in_models += sc->import.ms[k];
	/* `receive`: from the request's headers to its whole body (a 50 MB model part: ~0.2 s on
	 * the 2-core machine, unnamed before); `total` counts from there too. */
	double receive_ms = (req->t_queued - req->t_start) * 1000.0;
	timing_append(h, cap, &n, "receive;dur=%.3f, queue;dur=%.3f, parse;dur=%.3f", receive_ms, queue_ms,
	              parse_ms > in_models ? parse_ms - in_models : 0.0);
	if (models)
		for (int k = 0; k < API_IMPORT_STAGES; k++)
			timing_append(h, cap, &n, ", %s;dur=%.3f", API_IMPORT_STAGE_NAMES[k], (double)sc->import.ms[k]);
	timing_append(h, cap, &n, ", plan;dur=%.3f, device-wait;dur=%.3f", t->plan_ms, gate_ms);
	/* The environment map: the CPU's share of preparing it (0 once it is kept) and the shadow
	 * directions drawn (their maps and the environment pass are in `shadow`). */
	if (sc->scene.environment.source != RND_ENV_AMBIENT)
		timing_append(h, cap, &n, ", environment;dur=%.3f;desc=\"%u directions\"", t->env_ms, t->env_directions);
	timing_append(h, cap, &n, ", upload;dur=%.3f, targets;dur=%.3f", t->upload_ms, t->targets_ms);
	/* compiling a pipeline variant at its first use (the warm-up's are compiled before ready) */
	if (t->compile_ms > 0) timing_append(h, cap, &n, ", compile;dur=%.3f", t->compile_ms);
	timing_append(h, cap, &n, ", shadow;dur=%.3f, main;dur=%.3f, readback;dur=%.3f, encode;dur=%.3f, total;dur=%.3f",
	              t->shadow_ms, t->main_ms, t->readback_ms, encode_ms, total_ms);
}

/* After a render: the image encoded and answered (with its plan for ?explain=1: explain.c),
 * unless the deadline passed meanwhile; Server-Timing. ms: queue, parse and device-wait. */
static void job_encode(struct srv_server *s, struct srv_request *req, const struct api_scene *sc,
                       const struct srv_plan *plan, const struct rnd_image *img, const struct rnd_timings *t,
                       const double ms[3])
{
	struct api_problem p = { 0 };
	uint8_t *bytes = NULL;
	size_t len = 0;
	double t2 = srv_now();
	if (api_encode(sc, img, &bytes, &len, &p) != API_OK) {
		job_problem(req, &p);
		return;
	}
	double encode_s = srv_now() - t2;
	srv_metrics_stage(s->metrics, SRV_STAGE_ENCODE, encode_s);
	double t3 = srv_now();
	if (past_deadline(s, req, t3)) {
		free(bytes);
		job_deadline(s, req, "while rendering", t3);
		return;
	}
	if (!req->explain) {
		job_answer(s, req, sc, bytes, len);
	} else {
		struct api_plan_times pt = { ms[1], encode_s * 1000.0, (t3 - req->t_queued) * 1000.0 };
		if (!srv_explain_multipart(req, sc, plan->plan, &pt, bytes, len)) {
			api_problem_set(&p, 503, "", "out of memory for the render's plan; retry, or ask without explain");
			job_problem(req, &p);
			return;
		}
	}
	format_timing(req, sc, t, ms[0], ms[1], ms[2], encode_s * 1000.0, (t3 - req->t_start) * 1000.0);
}

/* One request from the queue: parse, admit by memory, render, encode, answer (POST
 * /v1/explain: parse and plan, explain.c). Answers req (or, on a worker, parks it for an import thread: *parked). Returns the lost
 * context's generation + 1 after a device loss, else 0. */
static unsigned job_run(struct srv_server *s, struct srv_request *req, bool importer, bool *parked)
{
	unsigned lost_gen = 0;
	double t_pop = srv_now();
	srv_metrics_queue_wait(s->metrics, req->priority, t_pop - req->t_queued);
	if (past_deadline(s, req, t_pop)) {
		job_deadline(s, req, "while waiting in the queue", t_pop);
		return 0;
	}

	struct api_scene *sc = NULL;
	struct api_problem p = { 0 };
	struct rnd_image img = { 0 };
	struct rnd_timings t = { 0 };
	struct rnd_error err = { 0 };
	struct srv_plan plan = { 0 };
	uint64_t admitted = 0;        /* bytes admitted by memory, released when the answer is ready */
	double parse_s = 0;
	struct parse_ticket ticket;
	ticket_init(&ticket, s, req, importer);
	int pr = job_parse(s, req, &ticket, &sc, &parse_s);
	/* an import thread's import is over: the next model's may start while this one renders */
	if (importer) srv_imports_imported(s->imports);
	admitted = ticket.reserved;
	*parked = pr == 2;
	if (pr) goto out;
	if (req->route == SRV_ROUTE_EXPLAIN) {
		srv_explain_answer(s, req, sc, parse_s * 1000.0);
		goto out;
	}

	double t1 = srv_now();
	if (past_deadline(s, req, t1)) {
		job_deadline(s, req, "before rendering", t1);
		goto out;
	}
	enum rnd_result r = RND_OK;
	int ar = admit(s, req, sc, admitted, &plan, &admitted, &r, &err, &p);
	if (ar == -2) job_render_failed(s, req, sc, r, &err, false);
	else if (ar != 0) job_problem(req, &p);
	if (ar != 0) goto out;
	struct render_watch watch = { .srv = s };
	if (s->cfg.deadline_ms) {
		sc->scene.deadline_ns = (uint64_t)((req->t_queued + s->cfg.deadline_ms / 1000.0) * 1e9);
		sc->scene.cancel = render_should_yield;
		sc->scene.cancel_user = &watch;
	}
	/* One render at a time on a CPU device (server/gate.h); parse and encode stay parallel. */
	struct srv_gate_waiter gw;
	double t_gate = srv_now();
	if (!srv_gate_enter_prio(&s->gate, &gw, (unsigned)req->priority, req->t_queued,
	                    s->cfg.deadline_ms ? req->t_queued + s->cfg.deadline_ms / 1000.0 : 0)) {
		job_deadline(s, req, "while waiting for the device", srv_now());
		goto out;
	}
	double gate_ms = (srv_now() - t_gate) * 1000.0;
	r = srv_render(s, &sc->scene, &plan, &img, &t, &err, &lost_gen);
	srv_gate_leave(&s->gate);
	if (r != RND_OK) {
		job_render_failed(s, req, sc, r, &err, watch.yielded);
		goto out;
	}
	job_render_stages(s, &t);
	job_encode(s, req, sc, &plan, &img, &t, (double[]){ (t_pop - req->t_queued) * 1000.0, parse_s * 1000.0, gate_ms });
out:
	rnd_image_release(&img);
	srv_plan_release(&plan);
	api_scene_free(sc);
	srv_admit_release(&s->admit, admitted);
	/* After an enormous request, its memory back to the system now: its freed heap, and its
	 * shadow maps (and any other nobody holds) with the atlas pages. */
	if (!*parked && admitted > BIG_REQUEST_BYTES) srv_context_trim(s, 0);
	return lost_gen;
}

/* Idle for --idle-trim seconds: cached shadow maps nobody used for as long go, and with them
 * the atlases' pages (rnd_context_trim); then the heap's free pages go back to the system
 * (LLVM's compile-time memory and freed image memory stay in malloc's arenas otherwise). */
static void idle_trim(void *arg)
{
	struct srv_server *s = arg;
	uint64_t released = srv_context_trim(s, s->cfg.idle_trim_s);
	if (released)
		srv_log(SRV_LOG_INFO, "idle: shadow maps unused for %u s dropped, the atlases' pages given back (%.0f MB mapped)",
		        s->cfg.idle_trim_s, released / 1048576.0);
}

static void *worker_main(void *arg)
{
	struct srv_server *s = arg;
	struct srv_request *req;
	while ((req = srv_queue_pop_idle(s->queue, s->cfg.idle_trim_s, idle_trim, s))) {
		bool parked = false;
		unsigned lost_gen = job_run(s, req, false, &parked);
		if (!parked) srv_request_finish(req);
		srv_queue_done(s->queue);
		/* answered: now back under --max-rss (context.c) */
		if (!parked) srv_context_fit_rss(s);
		/* After the answer: the client learns of the failure at once, /readyz is already 503. */
		if (lost_gen)
			srv_context_recover(s, lost_gen - 1);
	}
	return NULL;
}

/* An import thread (server/imports.h): the requests the workers parked, to the end. */
static void *importer_main(void *arg)
{
	struct srv_server *s = arg;
	struct srv_request *req;
	while ((req = srv_imports_take(s->imports))) {
		bool parked = false;
		uint64_t client = req->client;
		unsigned lost_gen = job_run(s, req, true, &parked);
		srv_request_finish(req);
		srv_imports_done(s->imports, client);
		srv_context_fit_rss(s);
		if (lost_gen)
			srv_context_recover(s, lost_gen - 1);
	}
	return NULL;
}

static unsigned import_threads(const struct srv_server *s)
{
	return srv_imports_threads(s->cfg.import_slots);
}

int srv_workers_start(struct srv_server *s)
{
	unsigned n = s->cfg.workers + import_threads(s);
	s->threads = calloc(n, sizeof *s->threads);
	if (!s->threads) {
		srv_log(SRV_LOG_ERROR, "cannot allocate %u worker threads", n);
		return -1;
	}
	for (unsigned i = 0; i < n; i++) {
		int e = pthread_create(&s->threads[i], NULL, i < s->cfg.workers ? worker_main : importer_main, s);
		if (e != 0) {
			srv_log(SRV_LOG_ERROR, "cannot start worker thread %u: %s", i, strerror(e));
			return -1; /* srv_workers_join() joins those started */
		}
		s->thread_count++;
	}
	return 0;
}

void srv_workers_join(struct srv_server *s)
{
	/* The workers first (the queue is closed): none parks a request after that, and the import
	 * threads then answer what is parked and end. */
	unsigned w = s->thread_count < s->cfg.workers ? s->thread_count : s->cfg.workers;
	for (unsigned i = 0; i < w; i++)
		pthread_join(s->threads[i], NULL);
	srv_imports_close(s->imports);
	for (unsigned i = w; i < s->thread_count; i++)
		pthread_join(s->threads[i], NULL);
	free(s->threads);
	s->threads = NULL;
	s->thread_count = 0;
}
