/*
 * umbrad metrics — Prometheus text exposition (version 0.0.4) for GET /metrics.
 *
 *   umbra_requests_total{route,status}          counter, every answered request
 *   umbra_request_duration_seconds{route}       histogram, arrival to answer queued
 *   umbra_stage_seconds{stage}                  histogram, parse/upload/shadow/main/readback/encode
 *   umbra_queue_wait_seconds{priority}          histogram, time a render waited in the queue
 *   umbra_queue_depth, umbra_queue_depth_by_priority{priority}, umbra_queue_capacity, umbra_renders_in_flight, umbra_workers,
 *   umbra_ready, umbra_draining                 gauges
 *   umbra_renders_total{result}, umbra_shadow_maps_rendered_total,
 *   umbra_shadow_maps_reused_total (the renderer's shadow cache hits), umbra_not_modified_total
 *   (ETag hits), umbra_queue_rejected_total, umbra_deadline_exceeded_total,
 *   umbra_device_lost_total, umbra_response_bytes_total, umbra_model_cache_hits_total,
 *   umbra_model_cache_misses_total    counters; umbra_model_cache_bytes gauge
 *   umbra_result_cache_hits_total, _misses_total, _rendered_again_total counters;
 *   umbra_result_cache_bytes, _scene_bytes, _images, _capacity_bytes gauges (server/results.h)
 *   umbra_atlas_size_texels, umbra_atlas_occupancy_ratio, umbra_atlas_tiles, umbra_shadow_cache_maps
 *   gauges and umbra_shadow_cache_hits_total / _misses_total counters (rnd_context_stats)
 *   umbra_validation_messages, umbra_build_info{version,device,driver}, process_resident_memory_bytes,
 *   process_open_fds                            gauges
 *   umbra_memory_admitted_bytes, umbra_memory_admitted_peak_bytes, umbra_memory_budget_bytes  gauges
 *   umbra_connections_open, umbra_connection_ranges, umbra_connections_per_range_limit gauges;
 *   umbra_connections_refused_total{reason="range_share"} counter (server/ranges.h)
 *   umbra_import_jobs_started_total{job}, umbra_import_jobs_total{job,result},
 *   umbra_import_server_restarts_total counters; umbra_import_job_seconds{job},
 *   umbra_import_seconds{stage} histograms (the import sandbox: api/sandbox_stats.h)
 *
 * Threading: every function is safe from any thread (one mutex; updates are a few adds).
 */
#ifndef UMBRA_SRV_METRICS_H
#define UMBRA_SRV_METRICS_H

#include "srv.h"

enum srv_counter {
	SRV_CTR_RENDER_OK, SRV_CTR_RENDER_FAILED, SRV_CTR_NOT_MODIFIED, SRV_CTR_QUEUE_REJECTED,
	SRV_CTR_DEADLINE, SRV_CTR_DEVICE_LOST, SRV_CTR_SHADOW_RENDERED, SRV_CTR_SHADOW_REUSED,
	SRV_CTR_BYTES_OUT, SRV_CTR_RESULT_HIT, SRV_CTR_RESULT_MISS, SRV_CTR_RESULT_RENDERED_AGAIN, SRV_CTR_RSS_TRIM,
	SRV_CTR_COUNT
};

struct srv_metrics *srv_metrics_create(void);
void srv_metrics_destroy(struct srv_metrics *m);   /* NULL-safe */

void srv_metrics_request(struct srv_metrics *m, enum srv_route route, int status, double seconds,
                         uint64_t bytes);
void srv_metrics_stage(struct srv_metrics *m, enum srv_stage stage, double seconds);
void srv_metrics_queue_wait(struct srv_metrics *m, enum srv_priority prio, double seconds);
void srv_metrics_add(struct srv_metrics *m, enum srv_counter c, uint64_t n);

/* The exposition text, malloc'd (you free it); NULL when out of memory. */
char *srv_metrics_text(struct srv_server *s, size_t *len);

#endif
