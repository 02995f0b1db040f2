/*
 * umbrad's renderer context (see srv.h): the shared rnd_context — created from the flags,
 * recovered after a lost device (the first worker to see the loss recreates it and warms it up
 * again, server/warmup.c), its pipeline cache saved at exit — and srv_plan() and srv_render(),
 * the one way a worker plans and renders on it.
 */
#include <malloc.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "log.h"
#include "metrics.h"
#include "srv.h"

static void rnd_log_cb(void *user, int level, const char *msg)
{
	(void)user;
	srv_log(level <= 0 ? SRV_LOG_ERROR : level == 1 ? SRV_LOG_WARN : SRV_LOG_INFO, "renderer: %s", msg);
}

static int context_create(struct srv_server *s, struct rnd_context **out)
{
	struct rnd_context_desc cd = { 0 };
	struct rnd_error err = { 0 };
	cd.device_name = s->cfg.device;
	cd.validation = s->cfg.validation;
	cd.pipeline_cache_path = s->cfg.pipeline_cache;
	cd.slots = s->cfg.workers;
	cd.atlas_size = s->cfg.atlas_size;
	cd.max_textures = s->cfg.limits.max_textures;
	cd.log = rnd_log_cb;
	enum rnd_result r = rnd_context_create(&cd, out, &err);
	if (r != RND_OK) {
		srv_log(SRV_LOG_ERROR, "cannot create the renderer context: %s (%s)", err.msg, rnd_result_str(r));
		*out = NULL;
		return -1;
	}
	return 0;
}

int srv_context_open(struct srv_server *s)
{
	struct rnd_context *ctx;
	if (context_create(s, &ctx) != 0)
		return -1;
	pthread_rwlock_wrlock(&s->ctx_lock);
	s->ctx = ctx;
	rnd_context_info(ctx, &s->info);
	/* --max-textures as the device grants it: the parser's 422 then comes before the renderer's. */
	if (s->cfg.limits.max_textures != s->info.max_textures) s->cfg.limits.max_textures = s->info.max_textures;
	pthread_rwlock_unlock(&s->ctx_lock);
	unsigned renders = s->cfg.device_renders ? s->cfg.device_renders : s->info.is_cpu ? 1 : s->cfg.workers;
	if (renders > s->cfg.workers) renders = s->cfg.workers;
	srv_gate_set_limit(&s->gate, renders);
	srv_log(SRV_LOG_INFO, "device \"%s\", driver \"%s\" %s%s, %u render slots, %u on the device at once%s",
	        s->info.device_name, s->info.driver_name, s->info.driver_info, s->info.is_cpu ? " (CPU)" : "",
	        s->cfg.workers, renders, s->cfg.validation ? ", validation on" : "");
	return 0;
}

/* After RND_ERR_DEVICE_LOST from the context of generation `gen`: the first worker to get
 * here waits for the other renders to leave, then destroys and recreates the context and warms
 * it up again; the others see a newer generation and do nothing. /readyz answers 503 from the
 * moment the loss was seen until the new context is warm. */
static bool context_recover_once(struct srv_server *s, unsigned gen, unsigned *new_gen)
{
	pthread_rwlock_wrlock(&s->ctx_lock);
	if (s->ctx_gen != gen) {
		pthread_rwlock_unlock(&s->ctx_lock);
		return true;
	}
	atomic_store(&s->ready, false);
	srv_metrics_add(s->metrics, SRV_CTR_DEVICE_LOST, 1);
	srv_log(SRV_LOG_ERROR, "device lost: recreating the renderer context");
	if (s->ctx)
		s->validation_lost += rnd_context_validation_messages(s->ctx);
	rnd_context_destroy(s->ctx);
	s->ctx = NULL;
	s->ctx_gen++;
	unsigned my_gen = *new_gen = s->ctx_gen;
	struct rnd_context *ctx;
	bool created = context_create(s, &ctx) == 0;
	if (created) {
		s->ctx = ctx;
		rnd_context_info(ctx, &s->info);
	}
	pthread_rwlock_unlock(&s->ctx_lock);
	if (!created)
		return true;   /* renders answer 503 "could not be recreated"; nothing more to try */
	srv_log(SRV_LOG_INFO, "renderer context recreated on \"%s\"; warming up again", s->info.device_name);
	/* The warm-up renders take the lock for reading like any render; requests that reach a
	 * worker meanwhile render on the new context (compiling what they need). */
	bool warm = srv_warmup(s) == 0;
	pthread_rwlock_rdlock(&s->ctx_lock);
	bool mine = s->ctx_gen == my_gen;   /* else lost again and recovered by another worker */
	if (warm && mine && s->ctx && !atomic_load(&s->draining))
		atomic_store(&s->ready, true);
	pthread_rwlock_unlock(&s->ctx_lock);
	if (!warm)
		srv_log(SRV_LOG_ERROR, "warm-up after the device loss failed");
	return warm || !mine;
}

/* A loss during the new warm-up would leave the daemon not ready with no request reaching a
 * worker to notice: try again a few times. */
void srv_context_recover(struct srv_server *s, unsigned gen)
{
	for (int attempt = 0; attempt < 3; attempt++) {
		unsigned new_gen = gen;
		if (context_recover_once(s, gen, &new_gen) || new_gen == gen)
			return;
		gen = new_gen;
	}
	srv_log(SRV_LOG_ERROR, "the renderer could not be brought back after a device loss: staying not ready");
}

enum rnd_result srv_plan(struct srv_server *s, const struct rnd_scene *scene, struct srv_plan *out,
                         struct rnd_error *err)
{
	enum rnd_result r = RND_ERR_DEVICE_LOST;
	memset(err, 0, sizeof *err);
	out->plan = NULL;
	pthread_rwlock_rdlock(&s->ctx_lock);
	out->gen = s->ctx_gen;
	if (s->ctx) r = rnd_plan_create(s->ctx, scene, &out->plan, err);
	pthread_rwlock_unlock(&s->ctx_lock);
	return r;
}

void srv_plan_release(struct srv_plan *p)
{
	rnd_plan_destroy(p->plan);
	p->plan = NULL;
}

/* Renders on the shared context. On RND_ERR_DEVICE_LOST, *lost_gen (if given) is the lost
 * context's generation + 1 for context_recover(), and the daemon is marked not ready before
 * the lock is let go (so a recovery cannot finish before this mark). */
enum rnd_result srv_render(struct srv_server *s, const struct rnd_scene *scene, struct srv_plan *plan,
                           struct rnd_image *img, struct rnd_timings *t, struct rnd_error *err, unsigned *lost_gen)
{
	pthread_rwlock_rdlock(&s->ctx_lock);
	unsigned gen = s->ctx_gen;
	enum rnd_result r;
	if (!s->ctx) {
		memset(err, 0, sizeof *err);
		err->code = r = RND_ERR_DEVICE_LOST;
		snprintf(err->msg, sizeof err->msg, "the renderer context could not be recreated after a lost device");
	} else {
		atomic_fetch_add(&s->in_flight, 1);
		if (plan && (!plan->plan || plan->gen != gen)) {
			/* made on a context lost since (or never): made again on this one */
			srv_plan_release(plan);
			plan->gen = gen;
			r = rnd_plan_create(s->ctx, scene, &plan->plan, err);
		} else {
			r = RND_OK;
		}
		if (r == RND_OK)
			r = plan ? rnd_render_plan(s->ctx, plan->plan, img, t, err) : rnd_render(s->ctx, scene, img, t, err);
		atomic_fetch_sub(&s->in_flight, 1);
		if (r == RND_ERR_DEVICE_LOST) {
			atomic_store(&s->ready, false);
			if (lost_gen)
				*lost_gen = gen + 1;
		}
	}
	pthread_rwlock_unlock(&s->ctx_lock);
	return r;
}

uint64_t srv_context_trim(struct srv_server *s, double idle_s)
{
	uint64_t released = 0;
	pthread_rwlock_rdlock(&s->ctx_lock);
	if (s->ctx)
		released = rnd_context_trim(s->ctx, idle_s);
	pthread_rwlock_unlock(&s->ctx_lock);
	malloc_trim(0);
	return released;
}

uint64_t srv_rss_bytes(void)
{
	long pages_total = 0, pages_rss = 0;
	FILE *f = fopen("/proc/self/statm", "r");
	if (!f)
		return 0;
	if (fscanf(f, "%ld %ld", &pages_total, &pages_rss) != 2)
		pages_rss = 0;
	fclose(f);
	long page = sysconf(_SC_PAGESIZE);
	return pages_rss > 0 && page > 0 ? (uint64_t)pages_rss * (uint64_t)page : 0;
}

/* issue 28: a warm daemon under 200 MB after any mix of requests (lavapipe: ~150 MB ready) */
#define RSS_DEFAULT_BOUND (192ull << 20)

/* The main-pass variants a trim keeps (the most recently used): what a thumbnail farm's requests
 * use between them (an untextured model's main and pixel shading, a textured one's main,
 * resolve, environment pass; server/warmup.c warms eight) and one more. Four dropped one of a
 * mixed corpus's five at every trim, and lavapipe compiled it again (0.2-0.8 s, every render
 * waiting for the device meanwhile): three of the corpus's four compiles over HTTP. */
#define RSS_KEEP_VARIANTS 6u

/* The heap between requests. Buffers of 32 MiB and more (a 1M-triangle model's bytes and
 * arrays) come straight from mmap and go back to the system when freed; smaller ones are
 * served from the heaps, each of which keeps up to 16 MiB free at its top for the next
 * request. It was the other way (mmap from 1 MiB, glibc's 128 KiB trim threshold): every
 * request mapped its buffers anew and each heap gave its top back after every free, and the
 * next request faulted them all in again, lavapipe's own allocations included. On the 2-core
 * VM a page fault is dear: a new model's 12 environment maps drew in 90-130 ms against
 * 35-50, and a warm thumbnail took 90-230 ms against 46-64. Not 64 MiB: malloc_trim (the
 * first step of --max-rss below) gives back a thread arena's free chunks but not the free
 * top of its heap, which only a free past this threshold shrinks; at 64 MiB a daemon kept
 * ~210 MB after the farm corpus, at 16 MiB 164-171 MB (147 before). */
#define HEAP_MMAP_THRESHOLD (32 << 20)
#define HEAP_TRIM_THRESHOLD (16 << 20)

void srv_heap_policy(void)
{
	mallopt(M_MMAP_THRESHOLD, HEAP_MMAP_THRESHOLD);
	mallopt(M_TRIM_THRESHOLD, HEAP_TRIM_THRESHOLD);
}

/* One step of srv_context_fit_rss: the free heap first, then what the renderer keeps, by how
 * dear it is to make again. Every step ends with malloc_trim (below). */
static void rss_step(struct srv_server *s, int step)
{
	pthread_rwlock_rdlock(&s->ctx_lock);
	if (s->ctx && step == 1)
		rnd_context_trim(s->ctx, 0);                       /* maps nobody holds, atlas pages */
	if (s->ctx && step == 2)
		rnd_context_trim_slots(s->ctx);                    /* idle slots' targets and buffers */
	if (s->ctx && step == 3)
		rnd_context_trim_pipelines(s->ctx, RSS_KEEP_VARIANTS); /* JIT code: ~14 MB a variant on lavapipe */
	pthread_rwlock_unlock(&s->ctx_lock);
	if (step == 4) {
		/* every cached model nobody uses (an import is the dearest thing to make again) */
		api_model_cache_set_limit(0);
		api_model_cache_set_limit(s->cfg.model_cache_bytes);
	}
	malloc_trim(0);
}

void srv_rss_bound_settle(struct srv_server *s)
{
	if (s->cfg.max_rss_given)
		return;
	uint64_t ready = srv_rss_bytes(), bound = ready + ready / 4;
	s->cfg.max_rss = bound > RSS_DEFAULT_BOUND ? bound : RSS_DEFAULT_BOUND;
	srv_log(SRV_LOG_INFO, "resident memory %.0f MB ready; --max-rss %.0f MB", ready / 1048576.0,
	        s->cfg.max_rss / 1048576.0);
}

void srv_context_fit_rss(struct srv_server *s)
{
	static pthread_mutex_t one = PTHREAD_MUTEX_INITIALIZER;
	if (!s->cfg.max_rss || srv_rss_bytes() <= s->cfg.max_rss || pthread_mutex_trylock(&one) != 0)
		return;
	uint64_t before = srv_rss_bytes();
	int step = 0;
	for (; step < 5 && srv_rss_bytes() > s->cfg.max_rss; step++)
		rss_step(s, step);
	srv_metrics_add(s->metrics, SRV_CTR_RSS_TRIM, 1);
	uint64_t after = srv_rss_bytes();
	pthread_mutex_unlock(&one);
	srv_log(after > s->cfg.max_rss ? SRV_LOG_WARN : SRV_LOG_INFO,
	        "resident memory %.0f MB over --max-rss %.0f MB: gave back in %d step%s, now %.0f MB", before / 1048576.0,
	        s->cfg.max_rss / 1048576.0, step, step == 1 ? "" : "s", after / 1048576.0);
}

int srv_fault_arm(struct srv_server *s)
{
	const char *f = s->cfg.test_fault;
	if (!f)
		return 0;
	unsigned n = 0;
	char kind[8] = "";
	if (sscanf(f, "submit:%u:%7s", &n, kind) != 2 || n == 0 || (strcmp(kind, "lost") && strcmp(kind, "oom"))) {
		srv_log(SRV_LOG_ERROR, "--test-fault '%s': want submit:N:lost or submit:N:oom (N >= 1)", f);
		return -1;
	}
	pthread_rwlock_rdlock(&s->ctx_lock);
	if (s->ctx)
		rnd_context_inject_fault(s->ctx, strcmp(kind, "lost") ? RND_FAULT_OUT_OF_MEMORY : RND_FAULT_DEVICE_LOST, n);
	pthread_rwlock_unlock(&s->ctx_lock);
	srv_log(SRV_LOG_WARN, "test fault armed: queue submit %u from now returns %s", n,
	        strcmp(kind, "lost") ? "out of device memory" : "device lost");
	return 0;
}

int srv_context_close(struct srv_server *s)
{
	pthread_rwlock_wrlock(&s->ctx_lock);
	uint32_t msgs = s->validation_lost;
	if (s->ctx) {
		struct rnd_error err = { 0 };
		if (s->cfg.pipeline_cache) {
			if (rnd_context_save_cache(s->ctx, &err) != RND_OK)
				srv_log(SRV_LOG_WARN, "cannot save the pipeline cache '%s': %s", s->cfg.pipeline_cache, err.msg);
			else
				srv_log(SRV_LOG_INFO, "pipeline cache saved to '%s'", s->cfg.pipeline_cache);
		}
		msgs += rnd_context_validation_messages(s->ctx);
		rnd_context_destroy(s->ctx);
		s->ctx = NULL;
	}
	pthread_rwlock_unlock(&s->ctx_lock);
	return (int)msgs;
}

