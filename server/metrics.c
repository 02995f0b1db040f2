/*
 * umbrad metrics (see metrics.h). Histograms use fixed latency buckets from 1 ms to 60 s, the
 * same as the import sandbox's (API_STATS_BUCKET_BOUNDS, api/sandbox_stats.h).
 */
#include "metrics.h"
#include "results.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "buf.h"
#include "imports.h"
#include "queue.h"
#include "ranges.h"
#include "sandbox_stats.h"

/* One list of bounds for every histogram on /metrics: api/'s (the sandbox's are filled there). */
#define BUCKETS API_STATS_BUCKETS

struct srv_histogram {
	uint64_t bucket[BUCKETS];   /* non-cumulative here, summed when written */
	uint64_t count;
	double sum;
};

/* Requests by (route, status): a short list, found by linear search. */
#define MAX_STATUS_SERIES 96
struct srv_status_series {
	enum srv_route route;
	int status;
	uint64_t count;
};

struct srv_metrics {
	pthread_mutex_t mu;
	struct srv_status_series series[MAX_STATUS_SERIES];
	unsigned series_count;
	struct srv_histogram duration[SRV_ROUTE_COUNT];
	struct srv_histogram stage[SRV_STAGE_COUNT];
	struct srv_histogram queue_wait[SRV_PRIO_COUNT];
	uint64_t counter[SRV_CTR_COUNT];
};

struct srv_metrics *srv_metrics_create(void)
{
	struct srv_metrics *m = calloc(1, sizeof *m);
	if (!m)
		return NULL;
	if (pthread_mutex_init(&m->mu, NULL) != 0) {
		free(m);
		return NULL;
	}
	return m;
}

void srv_metrics_destroy(struct srv_metrics *m)
{
	if (!m)
		return;
	pthread_mutex_destroy(&m->mu);
	free(m);
}

static void histogram_observe(struct srv_histogram *h, double v)
{
	size_t i = 0;
	while (i < BUCKETS && v > API_STATS_BUCKET_BOUNDS[i])
		i++;
	if (i < BUCKETS)
		h->bucket[i]++;
	h->count++;
	h->sum += v;
}

void srv_metrics_request(struct srv_metrics *m, enum srv_route route, int status, double seconds,
                         uint64_t bytes)
{
	pthread_mutex_lock(&m->mu);
	unsigned i;
	for (i = 0; i < m->series_count; i++)
		if (m->series[i].route == route && m->series[i].status == status)
			break;
	if (i == m->series_count && i < MAX_STATUS_SERIES) {
		m->series[i] = (struct srv_status_series){ .route = route, .status = status };
		m->series_count++;
	}
	if (i < m->series_count)
		m->series[i].count++;
	histogram_observe(&m->duration[route], seconds);
	m->counter[SRV_CTR_BYTES_OUT] += bytes;
	pthread_mutex_unlock(&m->mu);
}

void srv_metrics_stage(struct srv_metrics *m, enum srv_stage stage, double seconds)
{
	pthread_mutex_lock(&m->mu);
	histogram_observe(&m->stage[stage], seconds);
	pthread_mutex_unlock(&m->mu);
}

void srv_metrics_queue_wait(struct srv_metrics *m, enum srv_priority prio, double seconds)
{
	if ((unsigned)prio >= SRV_PRIO_COUNT)
		prio = SRV_PRIO_INTERACTIVE;
	pthread_mutex_lock(&m->mu);
	histogram_observe(&m->queue_wait[prio], seconds);
	pthread_mutex_unlock(&m->mu);
}

void srv_metrics_add(struct srv_metrics *m, enum srv_counter c, uint64_t n)
{
	pthread_mutex_lock(&m->mu);
	m->counter[c] += n;
	pthread_mutex_unlock(&m->mu);
}

/* One histogram's series from non-cumulative buckets (the server's and api/'s alike). */
static void write_buckets(struct srv_buf *b, const char *name, const char *labels, const uint64_t *bucket,
                          uint64_t count, double sum)
{
	uint64_t cum = 0;
	const char *sep = labels[0] ? "," : "";
	for (size_t i = 0; i < BUCKETS; i++) {
		cum += bucket[i];
		srv_buf_printf(b, "%s_bucket{%s%sle=\"%g\"} %llu\n", name, labels, sep, API_STATS_BUCKET_BOUNDS[i],
		               (unsigned long long)cum);
	}
	srv_buf_printf(b, "%s_bucket{%s%sle=\"+Inf\"} %llu\n", name, labels, sep,
	               (unsigned long long)count);
	if (labels[0]) {
		srv_buf_printf(b, "%s_sum{%s} %.9g\n", name, labels, sum);
		srv_buf_printf(b, "%s_count{%s} %llu\n", name, labels, (unsigned long long)count);
	} else {
		srv_buf_printf(b, "%s_sum %.9g\n", name, sum);
		srv_buf_printf(b, "%s_count %llu\n", name, (unsigned long long)count);
	}
}

static void write_histogram(struct srv_buf *b, const char *name, const char *labels,
                            const struct srv_histogram *h)
{
	write_buckets(b, name, labels, h->bucket, h->count, h->sum);
}

static void write_counter(struct srv_buf *b, const char *name, const char *help, uint64_t v)
{
	srv_buf_printf(b, "# HELP %s %s\n# TYPE %s counter\n%s %llu\n", name, help, name, name,
	               (unsigned long long)v);
}

static void write_gauge(struct srv_buf *b, const char *name, const char *help, double v)
{
	srv_buf_printf(b, "# HELP %s %s\n# TYPE %s gauge\n%s %.17g\n", name, help, name, name, v);
}

static long process_open_fds(void)
{
	DIR *d = opendir("/proc/self/fd");
	if (!d)
		return 0;
	long n = 0;
	struct dirent *e;
	while ((e = readdir(d)))
		if (e->d_name[0] != '.')
			n++;
	closedir(d);
	return n - 1; /* the directory stream itself */
}

/* Label values are escaped for the exposition format: backslash, quote, newline. */
static void label_escape(char *dst, size_t size, const char *src)
{
	size_t o = 0;
	for (; src && *src && o + 3 < size; src++) {
		if (*src == '\\' || *src == '"') {
			dst[o++] = '\\';
			dst[o++] = *src;
		} else if (*src == '\n') {
			dst[o++] = '\\';
			dst[o++] = 'n';
		} else {
			dst[o++] = *src;
		}
	}
	dst[o] = 0;
}

/* Requests, their durations, the render stages and the queue wait (histograms). */
static void write_requests(struct srv_buf *b, const struct srv_metrics *snap)
{
	char labels[128];
	srv_buf_puts(b, "# HELP umbra_requests_total HTTP requests answered, by route and status.\n"
	                 "# TYPE umbra_requests_total counter\n");
	for (unsigned i = 0; i < snap->series_count; i++)
		srv_buf_printf(b, "umbra_requests_total{route=\"%s\",status=\"%d\"} %llu\n",
		               srv_route_name(snap->series[i].route), snap->series[i].status,
		               (unsigned long long)snap->series[i].count);

	srv_buf_puts(b, "# HELP umbra_request_duration_seconds Time from request arrival to answer.\n"
	                 "# TYPE umbra_request_duration_seconds histogram\n");
	for (int r = 0; r < SRV_ROUTE_COUNT; r++) {
		if (!snap->duration[r].count)
			continue;
		snprintf(labels, sizeof labels, "route=\"%s\"", srv_route_name((enum srv_route)r));
		write_histogram(b, "umbra_request_duration_seconds", labels, &snap->duration[r]);
	}

	srv_buf_puts(b, "# HELP umbra_stage_seconds Time per render stage.\n"
	                 "# TYPE umbra_stage_seconds histogram\n");
	for (int st = 0; st < SRV_STAGE_COUNT; st++) {
		snprintf(labels, sizeof labels, "stage=\"%s\"", srv_stage_name((enum srv_stage)st));
		write_histogram(b, "umbra_stage_seconds", labels, &snap->stage[st]);
	}

	srv_buf_puts(b, "# HELP umbra_queue_wait_seconds Time a render waited in the queue, by X-Priority.\n"
	                 "# TYPE umbra_queue_wait_seconds histogram\n");
	write_histogram(b, "umbra_queue_wait_seconds", "priority=\"interactive\"", &snap->queue_wait[SRV_PRIO_INTERACTIVE]);
	write_histogram(b, "umbra_queue_wait_seconds", "priority=\"bulk\"", &snap->queue_wait[SRV_PRIO_BULK]);
}

/* The import sandbox (api/sandbox_stats.h): jobs, how they ended, fork-server restarts, times. */
static void write_sandbox(struct srv_buf *b)
{
	struct api_sandbox_stats st;
	char labels[128];
	api_sandbox_stats(&st);
	srv_buf_puts(b, "# HELP umbra_import_jobs_started_total Sandboxed importer jobs started, by job.\n"
	                 "# TYPE umbra_import_jobs_started_total counter\n");
	for (int j = 0; j < API_SBX_JOBS; j++)
		srv_buf_printf(b, "umbra_import_jobs_started_total{job=\"%s\"} %llu\n", API_SBX_JOB_NAMES[j],
		               (unsigned long long)st.started[j]);
	srv_buf_puts(b, "# HELP umbra_import_jobs_total Sandboxed importer jobs ended, by job and result.\n"
	                 "# TYPE umbra_import_jobs_total counter\n");
	for (int j = 0; j < API_SBX_JOBS; j++)
		for (int o = 0; o < API_SBX_OUTCOMES; o++)
			srv_buf_printf(b, "umbra_import_jobs_total{job=\"%s\",result=\"%s\"} %llu\n", API_SBX_JOB_NAMES[j],
			               API_SBX_OUTCOME_NAMES[o], (unsigned long long)st.ended[j][o]);
	write_counter(b, "umbra_import_server_restarts_total",
	              "Importer fork servers started again after one died or stopped answering.", st.server_restarts);
	srv_buf_puts(b, "# HELP umbra_import_job_seconds Wall time of a sandboxed importer job, by job.\n"
	                 "# TYPE umbra_import_job_seconds histogram\n");
	for (int j = 0; j < API_SBX_JOBS; j++) {
		const struct api_stats_histogram *h = &st.job_seconds[j];
		snprintf(labels, sizeof labels, "job=\"%s\"", API_SBX_JOB_NAMES[j]);
		write_buckets(b, "umbra_import_job_seconds", labels, h->bucket, h->count, h->sum);
	}
	srv_buf_puts(b, "# HELP umbra_import_seconds Time per stage of a model import (Server-Timing's model-*).\n"
	                 "# TYPE umbra_import_seconds histogram\n");
	for (int k = API_IMPORT_READ + 1; k < API_IMPORT_STAGES; k++) {   /* model-read is the request's */
		const struct api_stats_histogram *h = &st.stage_seconds[k];
		snprintf(labels, sizeof labels, "stage=\"%s\"", API_IMPORT_STAGE_NAMES[k]);
		write_buckets(b, "umbra_import_seconds", labels, h->bucket, h->count, h->sum);
	}
}

/* The queue and the workers, read live (gauges). */
static void write_queue(struct srv_buf *b, struct srv_server *s)
{
	unsigned qi = s->queue ? srv_queue_depth_prio(s->queue, SRV_PRIO_INTERACTIVE) : 0;
	unsigned qb = s->queue ? srv_queue_depth_prio(s->queue, SRV_PRIO_BULK) : 0;
	srv_buf_printf(b, "# HELP umbra_queue_depth Renders waiting for a worker.\n"
	                   "# TYPE umbra_queue_depth gauge\n"
	                   "umbra_queue_depth %u\n"
	                   "# HELP umbra_queue_depth_by_priority Renders waiting, by X-Priority.\n"
	                   "# TYPE umbra_queue_depth_by_priority gauge\n"
	                   "umbra_queue_depth_by_priority{priority=\"interactive\"} %u\n"
	                   "umbra_queue_depth_by_priority{priority=\"bulk\"} %u\n", qi + qb, qi, qb);
	write_gauge(b, "umbra_queue_capacity", "Most renders that may wait in the queue.",
	            s->queue ? srv_queue_capacity(s->queue) : 0);
	write_gauge(b, "umbra_renders_in_flight", "Renders running now.", atomic_load(&s->in_flight));
	write_gauge(b, "umbra_workers", "Render worker threads (context render slots).",
	            s->cfg.workers);
	write_gauge(b, "umbra_ready", "1 when /readyz answers 200.",
	            atomic_load(&s->ready) && !atomic_load(&s->leaving) && !atomic_load(&s->draining));
	write_gauge(b, "umbra_draining", "1 after SIGTERM/SIGINT.", atomic_load(&s->draining));
	unsigned running = 0, parked = 0;
	if (s->imports) srv_imports_counts(s->imports, &running, &parked);
	write_gauge(b, "umbra_imports_running", "Sandboxed model imports holding an import slot now (--import-slots).", running);
	write_gauge(b, "umbra_imports_parked", "Requests waiting for an import slot, holding no thread.", parked);

}

/* Connections per address range (server/ranges.h), read live. */
static void write_connections(struct srv_buf *b, struct srv_server *s)
{
	struct srv_ranges_stats st;
	srv_ranges_stats(s->ranges, &st);
	write_gauge(b, "umbra_connections_open", "Client connections open now (this scrape's own included).",
	            (double)st.open);
	write_gauge(b, "umbra_connection_ranges", "Client address ranges (IPv4 /24, IPv6 /64) with a connection open now.",
	            (double)st.ranges);
	write_gauge(b, "umbra_connections_per_range_limit", "--max-connections-per-range (0 = no limit).", st.share);
	srv_buf_printf(b, "# HELP umbra_connections_refused_total Connections closed unanswered at accept, by reason.\n"
	                  "# TYPE umbra_connections_refused_total counter\n"
	                  "umbra_connections_refused_total{reason=\"range_share\"} %llu\n",
	               (unsigned long long)st.refused);
}

static void write_renders(struct srv_buf *b, const struct srv_metrics *snap)
{
	srv_buf_puts(b, "# HELP umbra_renders_total Renders attempted by workers, by result.\n"
	                 "# TYPE umbra_renders_total counter\n");
	srv_buf_printf(b, "umbra_renders_total{result=\"ok\"} %llu\n",
	               (unsigned long long)snap->counter[SRV_CTR_RENDER_OK]);
	srv_buf_printf(b, "umbra_renders_total{result=\"error\"} %llu\n",
	               (unsigned long long)snap->counter[SRV_CTR_RENDER_FAILED]);
	write_counter(b, "umbra_shadow_maps_rendered_total", "Shadow maps rendered.",
	              snap->counter[SRV_CTR_SHADOW_RENDERED]);
	write_counter(b, "umbra_shadow_maps_reused_total", "Shadow maps reused from the renderer's cache.",
	              snap->counter[SRV_CTR_SHADOW_REUSED]);
	write_counter(b, "umbra_not_modified_total", "Renders whose If-None-Match listed their ETag: POST answered 412, "
	              "GET /v1/renders/{hash} 304; nothing rendered.",
	              snap->counter[SRV_CTR_NOT_MODIFIED]);
	write_counter(b, "umbra_queue_rejected_total", "Renders refused with 503 because the queue was full.",
	              snap->counter[SRV_CTR_QUEUE_REJECTED]);
	write_counter(b, "umbra_deadline_exceeded_total", "Renders answered 504.",
	              snap->counter[SRV_CTR_DEADLINE]);
	write_counter(b, "umbra_device_lost_total", "Lost devices (context recreated).",
	              snap->counter[SRV_CTR_DEVICE_LOST]);
	write_counter(b, "umbra_response_bytes_total", "Bytes of answer bodies.",
	              snap->counter[SRV_CTR_BYTES_OUT]);
	write_counter(b, "umbra_rss_trims_total", "Requests after which the daemon gave memory back to stay under --max-rss.",
	              snap->counter[SRV_CTR_RSS_TRIM]);

}

/* The result cache of the GET form of renders (server/results.h). */
static void write_results(struct srv_buf *b, struct srv_server *s, const struct srv_metrics *snap)
{
	struct srv_results_stats st;
	srv_results_stats(s->results, &st);
	write_counter(b, "umbra_result_cache_hits_total", "GET /v1/renders/{hash} answered from the result cache, and "
	              "POST /v1/renders that found its image stored.", snap->counter[SRV_CTR_RESULT_HIT]);
	write_counter(b, "umbra_result_cache_misses_total", "GET /v1/renders/{hash} without its image stored (rendered "
	              "again from its kept scene, or 404).", snap->counter[SRV_CTR_RESULT_MISS]);
	write_counter(b, "umbra_result_cache_rendered_again_total", "Evicted images rendered again from their kept scene.",
	              snap->counter[SRV_CTR_RESULT_RENDERED_AGAIN]);
	write_gauge(b, "umbra_result_cache_bytes", "Bytes of images held by the result cache (--result-cache-mb).",
	            (double)st.image_bytes);
	write_gauge(b, "umbra_result_cache_scene_bytes", "Bytes of scenes kept to render evicted images again.",
	            (double)st.scene_bytes);
	write_gauge(b, "umbra_result_cache_images", "Images held by the result cache.", (double)st.images);
	write_gauge(b, "umbra_result_cache_capacity_bytes", "--result-cache-mb in bytes (0 = off).", (double)st.capacity);
}

/* The model cache, the renderer's atlas and shadow cache, validation messages, the build. */
static void write_device(struct srv_buf *b, struct srv_server *s)
{
	uint64_t mhits = 0, mmiss = 0, mbytes = 0;
	api_model_cache_stats(&mhits, &mmiss, &mbytes);
	write_counter(b, "umbra_model_cache_hits_total", "Imported models found in the model cache.", mhits);
	write_counter(b, "umbra_model_cache_misses_total", "Imported models decoded.", mmiss);
	write_gauge(b, "umbra_model_cache_bytes", "Bytes held by the model cache.", (double)mbytes);

	uint32_t vmsg = s->validation_lost;
	char dev[300] = "", drv[300] = "";
	struct rnd_stats st = { 0 };
	if (atomic_load(&s->ready)) {
		pthread_rwlock_rdlock(&s->ctx_lock);
		if (s->ctx) {
			vmsg += rnd_context_validation_messages(s->ctx);
			rnd_context_stats(s->ctx, &st);
		}
		label_escape(dev, sizeof dev, s->info.device_name);
		label_escape(drv, sizeof drv, s->info.driver_name);
		pthread_rwlock_unlock(&s->ctx_lock);
	}
	write_gauge(b, "umbra_atlas_size_texels", "Texels per side of the shadow atlas.", st.atlas_size);
	write_gauge(b, "umbra_atlas_occupancy_ratio", "Share of shadow-atlas texels held by tiles.", st.atlas_occupancy);
	write_gauge(b, "umbra_atlas_tiles", "Tiles in the shadow atlas.", st.atlas_tiles);
	write_gauge(b, "umbra_shadow_cache_maps", "Shadow maps kept for reuse (spot, point, a sun's fit map).", st.cached_maps);
	write_counter(b, "umbra_shadow_cache_hits_total", "Lights whose shadow passes were skipped (cache hits).",
	              st.shadow_cache_hits);
	write_counter(b, "umbra_shadow_cache_misses_total", "Lights whose shadow passes were rendered (cache misses).",
	              st.shadow_cache_misses);
	write_gauge(b, "umbra_pipeline_variants", "Main-pass pipeline variants compiled and kept.", st.pipeline_variants);
	write_gauge(b, "umbra_validation_messages", "Vulkan validation-layer messages since start.", vmsg);
	srv_buf_printf(b, "# HELP umbra_build_info Build and device.\n# TYPE umbra_build_info gauge\n"
	                   "umbra_build_info{version=\"%s\",device=\"%s\",driver=\"%s\"} 1\n",
	               UMBRA_VERSION, dev, drv);
}

/* Admission by estimated memory, and the process. */
static void write_process(struct srv_buf *b, struct srv_server *s)
{
	uint64_t adm_in_use, adm_budget, adm_peak;
	srv_admit_stats(&s->admit, &adm_in_use, &adm_budget, &adm_peak);
	write_gauge(b, "umbra_memory_admitted_bytes", "Estimated memory of the renders admitted now (--max-memory).",
	            (double)adm_in_use);
	write_gauge(b, "umbra_memory_admitted_peak_bytes", "Largest estimated memory of renders in flight at once.",
	            (double)adm_peak);
	write_gauge(b, "umbra_memory_budget_bytes", "--max-memory: what renders in flight may need together.",
	            (double)adm_budget);
	write_gauge(b, "process_resident_memory_bytes", "Resident set size.", (double)srv_rss_bytes());
	write_gauge(b, "umbra_rss_limit_bytes", "--max-rss: resident memory kept after a request (0 = no bound).",
	            (double)s->cfg.max_rss);

	write_gauge(b, "process_open_fds", "Open file descriptors.", (double)process_open_fds());
}

char *srv_metrics_text(struct srv_server *s, size_t *len)
{
	struct srv_metrics *m = s->metrics;
	struct srv_metrics snap;
	struct srv_buf b = { 0 };

	pthread_mutex_lock(&m->mu);
	memcpy(&snap, m, sizeof snap);
	pthread_mutex_unlock(&m->mu);
	write_requests(&b, &snap);
	write_queue(&b, s);
	write_connections(&b, s);
	write_renders(&b, &snap);
	write_sandbox(&b);
	write_results(&b, s, &snap);
	write_device(&b, s);
	write_process(&b, s);
	return srv_buf_detach(&b, len);
}
