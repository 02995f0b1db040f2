/*
 * umbrad main: configuration, start-up order and graceful shutdown.
 *
 * Start-up: listen first (so /healthz answers and /readyz says 503 during start-up), then
 * create the renderer context, warm up its pipelines, start the workers, and only then
 * report ready. SIGTERM/SIGINT: /readyz turns 503, the listening socket closes, queued and
 * in-flight renders finish and are answered, the pipeline cache is saved, exit 0.
 * Exit codes: 0 clean, 1 start-up failure, 2 bad flags, 3 validation-layer messages seen.
 */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>
#include <unistd.h>

#include "imports.h"
#include "log.h"
#include "metrics.h"
#include "queue.h"
#include "results.h"
#include "srv.h"

/* Waits until every begun request has been answered and completed, or the timeout. */
static void wait_pending(struct srv_server *s, double timeout_s)
{
	double end = srv_now() + timeout_s;
	while (atomic_load(&s->pending) > 0 && srv_now() < end) {
		struct timespec ts = { 0, 10 * 1000 * 1000 };
		nanosleep(&ts, NULL);
	}
	unsigned left = atomic_load(&s->pending);
	if (left)
		srv_log(SRV_LOG_WARN, "drain: %u requests still open after %.0f s; closing them", left, timeout_s);
}

/* Signals, the context lock and the request-id seed, before any thread starts. */
/* --drain-grace-ms: /readyz says 503 while renders are still taken, so a balancer that checks
 * it (deploy/haproxy.cfg.in: 2 failed checks a second apart) stops sending before the drain
 * refuses anything; a second signal ends the grace. */
static void grace(struct srv_server *s, const sigset_t *sigs, int sig)
{
	atomic_store(&s->leaving, true);
	unsigned ms = s->cfg.drain_grace_ms;
	if (!ms) return;
	srv_log(SRV_LOG_INFO, "%s: /readyz 503, still answering for %u ms before the drain", sig == SIGINT ? "SIGINT" : "SIGTERM",
	        ms);
	struct timespec t = { (time_t)(ms / 1000), (long)(ms % 1000) * 1000000L };
	siginfo_t info;
	while (sigtimedwait(sigs, &info, &t) < 0 && errno == EINTR)
		;
}

static void process_init(struct srv_server *s, sigset_t *sigs)
{
	/* Every thread (libmicrohttpd's, the workers', the driver's) inherits this mask; the
	 * main thread takes the signals with sigwait(). */
	sigemptyset(sigs);
	sigaddset(sigs, SIGTERM);
	sigaddset(sigs, SIGINT);
	pthread_sigmask(SIG_BLOCK, sigs, NULL);
	signal(SIGPIPE, SIG_IGN);

	pthread_rwlockattr_t rwa;
	pthread_rwlockattr_init(&rwa);
	pthread_rwlockattr_setkind_np(&rwa, PTHREAD_RWLOCK_PREFER_WRITER_NONRECURSIVE_NP);
	pthread_rwlock_init(&s->ctx_lock, &rwa);
	pthread_rwlockattr_destroy(&rwa);
	if (getrandom(&s->id_seed, sizeof s->id_seed, 0) != sizeof s->id_seed)
		s->id_seed = (uint64_t)time(NULL) ^ ((uint64_t)getpid() << 32);
}

/* The daemon's parts that need no device: metrics, queue, admission, gate, import slots and
 * the results cache (parts_destroy gives back what was made). */
static int parts_create(struct srv_server *s)
{
	s->metrics = srv_metrics_create();
	s->queue = srv_queue_create(s->cfg.queue);
	srv_admit_init(&s->admit, s->cfg.max_memory);
	srv_gate_init(&s->gate, s->cfg.workers);
	s->imports = srv_imports_create(s->cfg.import_slots);
	s->results = srv_results_create((uint64_t)s->cfg.result_cache_mb << 20);
	if (!s->metrics || !s->queue || !s->imports || (s->cfg.result_cache_mb && !s->results)) {
		srv_log(SRV_LOG_ERROR, "out of memory at start-up");
		return -1;
	}
	return 0;
}

static void parts_destroy(struct srv_server *s)
{
	api_model_cache_clear();
	srv_queue_destroy(s->queue);
	srv_imports_destroy(s->imports);
	srv_results_destroy(s->results);
	srv_metrics_destroy(s->metrics);
	srv_admit_destroy(&s->admit);
	pthread_rwlock_destroy(&s->ctx_lock);
	srv_gate_destroy(&s->gate);
}

/* Ready: until SIGTERM or SIGINT, then the grace (--drain-grace-ms). */
static void wait_for_signal(struct srv_server *s, sigset_t *sigs)
{
	int sig = 0;
	while (sigwait(sigs, &sig) != 0)
		;
	grace(s, sigs, sig);
	srv_log(SRV_LOG_INFO, "%s: draining (%u queued, %u rendering)", sig == SIGINT ? "SIGINT" : "SIGTERM",
	        srv_queue_depth(s->queue), atomic_load(&s->in_flight));
}

int main(int argc, char **argv)
{
	static struct srv_server srv;
	struct srv_server *s = &srv;
	int exit_code = 1;

	int rc = srv_config_load(&s->cfg, argc, argv);
	if (rc > 0)
		return 0;
	if (rc < 0)
		return 2;
	srv_log_init(s->cfg.log_format);
	srv_heap_policy();
	api_model_cache_set_limit(s->cfg.model_cache_bytes);

	sigset_t sigs;
	process_init(s, &sigs);

	if (parts_create(s) != 0)
		goto out_free;
	srv_log(SRV_LOG_INFO, "umbrad %s starting: %u workers, queue %u, max body %llu, deadline %u ms",
	        UMBRA_VERSION, s->cfg.workers, s->cfg.queue, (unsigned long long)s->cfg.max_body, s->cfg.deadline_ms);
	if (srv_http_start(s) != 0)
		goto out_free;
	if (srv_context_open(s) != 0)
		goto out_http;
	if (srv_warmup(s) != 0)
		goto out_context;
	srv_rss_bound_settle(s);
	if (srv_workers_start(s) != 0)
		goto out_workers;
	/* Tests only: counted from here, so the warm-up's own submits never hit it. */
	if (srv_fault_arm(s) != 0)
		goto out_workers;
	atomic_store(&s->ready, true);
	srv_log(SRV_LOG_INFO, "ready");

	wait_for_signal(s, &sigs);
	exit_code = 0;

out_workers:
	atomic_store(&s->draining, true);
	srv_http_quiesce(s);
	srv_queue_close(s->queue);
	srv_workers_join(s);
	wait_pending(s, s->cfg.drain_timeout_s);
out_context:
	atomic_store(&s->draining, true);
	srv_http_stop(s);
	{
		int msgs = srv_context_close(s);
		if (msgs > 0) {
			srv_log(SRV_LOG_ERROR, "the Vulkan validation layer reported %d messages", msgs);
			if (exit_code == 0)
				exit_code = 3;
		}
	}
	goto out_free;
out_http:
	srv_http_stop(s);
out_free:
	parts_destroy(s);
	if (exit_code == 0)
		srv_log(SRV_LOG_INFO, "stopped");
	return exit_code;
}
