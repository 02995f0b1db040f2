/*
 * server/farm_local — the local farm in two stages: preparing threads read each input and parse
 * it (a model's sandboxed import is most of a new model's time), and render threads take the
 * parsed scenes, render, encode and write them.
 *
 * Why: with one thread per core each doing both, a thread that had imported its model rendered
 * it while the other imported or rendered too; on lavapipe two renders at once share the cores
 * a single render already uses (umbrad renders one at a time on a CPU device for the same
 * reason: server/gate.h), and a thread rendering imported nothing. Here the imports go on while
 * a render runs: on a CPU device one render thread (lavapipe spreads it over the cores) and a
 * preparing thread per core, each import its own child process; on a GPU as many render threads
 * as preparing ones. Preparing threads are bounded by memory too: each import child may take
 * the import's memory limit, and no more of them run than half the machine's memory holds.
 *
 * The ring between the stages holds at most one parsed scene per render slot and per preparing
 * thread: a preparing thread whose scene finds the ring full waits (backpressure), so parsed
 * models never pile up. SIGINT / SIGTERM: no new input is read; what is parsed is rendered.
 */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "farm_internal.h"

struct ready {
	size_t i;
	struct job_input in;
	struct api_scene *s;
	double t0;
};

struct stages {
	struct farm *f;
	pthread_mutex_t mu;
	pthread_cond_t can_put, can_get;
	struct ready *ring;
	unsigned cap, head, count;
	unsigned preparing;   /* preparing threads still running */
};

/* Renders ready job r on the farm's context and writes its file. */
static enum job_status render_ready(struct farm *f, struct ready *r)
{
	struct job_result *res = &f->res[r->i];
	struct api_scene *s = r->s;
	res->imp = s->import;
	res->env = s->scene.environment.source != RND_ENV_AMBIENT;
	struct rnd_image img = {0};
	struct rnd_timings tm;
	struct rnd_error err;
	enum rnd_result rr = rnd_render(f->ctx, &s->scene, &img, &tm, &err);
	res->tm = tm;
	if (rr != RND_OK) {
		bool fault = rr == RND_ERR_INVALID || rr == RND_ERR_LIMIT;
		if (fault) {
			struct api_problem prob;
			api_problem_from_render(&prob, s, &err, rr == RND_ERR_LIMIT ? 422 : 400);
			api_problem_format(&prob, res->error, sizeof res->error);
		} else {
			snprintf(res->error, sizeof res->error, "render failed: %s", err.msg);
		}
		return fault ? JOB_INVALID : JOB_FAILED;
	}
	snprintf(res->warnings, sizeof res->warnings, "%s", s->warnings);
	uint8_t *bytes = NULL;
	size_t n = 0;
	struct api_problem prob;
	enum job_status st = JOB_FAILED;
	double t1 = farm_now_ms();
	enum api_result enc = api_encode(s, &img, &bytes, &n, &prob);
	res->encode_ms = farm_now_ms() - t1;
	if (enc != API_OK) api_problem_format(&prob, res->error, sizeof res->error);
	else if (farm_write_file(res->out, bytes, n, res->error, sizeof res->error) == 0) st = JOB_OK;
	free(bytes);
	rnd_image_release(&img);
	return st;
}

/* Job i read and parsed into *r: true; false when it is over already (a failure, or --resume
 * found it done), farm_finish() called. */
static bool prepare(struct farm *f, size_t i, struct ready *r)
{
	r->i = i;
	r->t0 = farm_now_ms();
	r->s = NULL;
	enum job_status st = farm_job_read(f, i, &r->in);
	if (st == JOB_OK && f->resume && farm_resume_hit(f->resume, f, i)) {
		f->res[i].resumed = true;
	} else if (st == JOB_OK) {
		double t1 = farm_now_ms();
		st = farm_job_scene(f, i, &r->in, &r->s);
		f->res[i].parse_ms = farm_now_ms() - t1;
		if (st == JOB_OK) return true;
	}
	farm_job_input_release(&r->in);
	farm_finish(f, i, st, r->t0);
	return false;
}

static void *prepare_main(void *arg)
{
	struct stages *g = arg;
	struct farm *f = g->f;
	for (;;) {
		if (farm_stop) break;
		size_t i = atomic_fetch_add(&f->next, 1);
		if (i >= f->n) break;
		struct ready r;
		if (!prepare(f, i, &r)) continue;
		pthread_mutex_lock(&g->mu);
		while (g->count == g->cap) pthread_cond_wait(&g->can_put, &g->mu);
		g->ring[(g->head + g->count) % g->cap] = r;
		g->count++;
		pthread_cond_signal(&g->can_get);
		pthread_mutex_unlock(&g->mu);
	}
	pthread_mutex_lock(&g->mu);
	g->preparing--;
	pthread_cond_broadcast(&g->can_get);
	pthread_mutex_unlock(&g->mu);
	return NULL;
}

static void *render_main(void *arg)
{
	struct stages *g = arg;
	for (;;) {
		pthread_mutex_lock(&g->mu);
		while (!g->count && g->preparing) pthread_cond_wait(&g->can_get, &g->mu);
		if (!g->count) {
			pthread_mutex_unlock(&g->mu);
			break;
		}
		struct ready r = g->ring[g->head];
		g->head = (g->head + 1) % g->cap;
		g->count--;
		pthread_cond_signal(&g->can_put);
		pthread_mutex_unlock(&g->mu);
		enum job_status st = render_ready(g->f, &r);
		api_scene_free(r.s);
		farm_job_input_release(&r.in);
		farm_finish(g->f, r.i, st, r.t0);
	}
	return NULL;
}

/* Preparing threads: `threads`, and no more import children than half the machine's memory
 * holds at the import's memory limit each. */
static unsigned preparers(unsigned threads)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
	if (!lim.import_memory || pages <= 0 || page <= 0) return threads;
	uint64_t fit = (uint64_t)pages * (uint64_t)page / 2 / lim.import_memory;
	return fit < 1 ? 1 : fit < threads ? (unsigned)fit : threads;
}

void farm_run_local(struct farm *f, unsigned threads)
{
	struct rnd_info info;
	rnd_context_info(f->ctx, &info);
	unsigned nprep = preparers(threads), nrender = info.is_cpu ? 1 : threads;
	struct stages g = {.f = f, .cap = nprep + nrender};
	g.ring = calloc(g.cap, sizeof *g.ring);
	pthread_t tids[128];
	unsigned started = 0, prep_started = 0;
	if (g.ring) {
		pthread_mutex_init(&g.mu, NULL);
		pthread_cond_init(&g.can_put, NULL);
		pthread_cond_init(&g.can_get, NULL);
		/* counted before each start: a thread that ends at once counts itself down */
		for (; prep_started < nprep; prep_started++, started++) {
			pthread_mutex_lock(&g.mu);
			g.preparing++;
			pthread_mutex_unlock(&g.mu);
			if (pthread_create(&tids[started], NULL, prepare_main, &g) == 0) continue;
			pthread_mutex_lock(&g.mu);
			g.preparing--;
			pthread_mutex_unlock(&g.mu);
			break;
		}
		for (unsigned k = 0; prep_started && k < nrender && pthread_create(&tids[started], NULL, render_main, &g) == 0; k++)
			started++;
	}
	if (started == prep_started && prep_started) {
		render_main(&g);   /* no render thread could start: render on this one */
	} else if (!started) {
		/* no thread at all: both stages on this one, a job at a time */
		struct ready one;
		for (size_t i; !farm_stop && (i = atomic_fetch_add(&f->next, 1)) < f->n;) {
			if (!prepare(f, i, &one)) continue;
			enum job_status st = render_ready(f, &one);
			api_scene_free(one.s);
			farm_job_input_release(&one.in);
			farm_finish(f, i, st, one.t0);
		}
	}
	for (unsigned k = 0; k < started; k++) pthread_join(tids[k], NULL);
	if (g.ring) {
		pthread_cond_destroy(&g.can_get);
		pthread_cond_destroy(&g.can_put);
		pthread_mutex_destroy(&g.mu);
	}
	free(g.ring);
}
