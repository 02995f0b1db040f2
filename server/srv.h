/*
 * umbrad — the HTTP render daemon (build/umbrad). Shared types of the server modules.
 *
 * Modules (prefix srv_):
 *   flags.c    srv_config: defaults, UMBRA_* environment, command-line flags, --help
 *   main.c     startup (listen, context, warm-up, workers), signals, graceful drain, exit code
 *   http.c     libmicrohttpd callbacks: dispatch, GET routes, answers (http.h)
 *   render_route.c  POST /v1/render and /v1/renders: headers, body (JSON or multipart), queueing
 *   renders_route.c GET /v1/renders/{hash}.{ext}: the stored result, or its scene rendered again
 *   results.c  the bounded result cache behind the GET form (--result-cache-mb, results.h)
 *   negotiate.c  pure rules: Content-Type, Accept, the ETag (negotiate.h)
 *   conn.c     connection limits and timeouts, HTTP/1.1 framing checks, the listen address
 *   ranges.c   connections per client address range (--max-connections-per-range), pure
 *   origin.c   pure rules: the Host allow-list, Origin / Sec-Fetch-Site checks, CORS (origin.h)
 *   origin_http.c  those rules on libmicrohttpd's requests; the headers every answer carries
 *   queue.c    the bounded two-level (interactive before bulk) job queue
 *   worker.c   worker threads: parse -> render -> encode (imports.c: the import threads)
 *   context.c  the shared rnd_context: create, recovery after a lost device, srv_render()
 *   gate.c     how many renders run on the device at once (--device-renders; 1 on lavapipe)
 *   clock.c    monotonic condition variables and deadlines for the queue, admission and gate
 *   metrics.c  Prometheus counters, gauges and histograms
 *   log.c      one line per event or request on stderr, text or JSON
 *   buf.c      growable text buffer for the metrics; the JSON string escaper (logs, CLI report)
 *
 * Threading: libmicrohttpd runs one internal polling thread (poll(): see srv_http_start) that does
 * all socket I/O and calls http.c. A POST /v1/render is read completely, then its connection is
 * suspended and the request is handed to the queue; a worker thread renders it, stores the
 * answer in the request and resumes the connection, and the polling thread sends it. Nothing
 * on the polling thread waits for a render.
 *
 * Ownership: one struct srv_request per HTTP request, created by http.c on the first call of
 * the access handler and freed by http.c when libmicrohttpd reports the request completed.
 * While a request is queued or rendering, the worker owns its result fields; it gives them back
 * by calling srv_request_finish() (which resumes the connection) and never touches the request
 * again.
 */
#ifndef UMBRA_SRV_H
#define UMBRA_SRV_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "admit.h"
#include "clock.h"
#include "gate.h"
#include "api.h"
#include "origin.h"
#include "umbra/rnd.h"

#ifndef UMBRA_VERSION
#define UMBRA_VERSION "0.1.0"
#endif

struct srv_queue;
struct srv_metrics;
struct MHD_Daemon;
struct MHD_Connection;
struct MHD_PostProcessor;

enum srv_log_format { SRV_LOG_TEXT, SRV_LOG_JSON };

/* Everything the flags and UMBRA_* variables configure. Zero-initialised = not set. */
struct srv_config {
	const char *listen;            /* ADDR:PORT, default 127.0.0.1:8080; port 0 = ephemeral */
	const char *port_file;         /* written with the bound port once listening */
	unsigned workers;              /* render threads = context slots, default: online CPUs, capped by the CPU quota */
	const char *warm_up;           /* "defaults" (NULL) or "all": server/warmup.c */
	unsigned device_renders;       /* renders on the device at once (server/gate.h); 0 = 1 on a CPU device, else workers */
	unsigned import_slots;         /* import threads: sandboxed model imports at once (server/imports.h); 0 = workers */
	unsigned queue;                /* queued renders (not counting those rendering), default 64 */
	uint64_t max_body;             /* bytes, default 64 MiB */
	struct api_limits limits;      /* 422 limits */
	unsigned deadline_ms;          /* 0 = none, default 30000 */
	const char *asset_root;        /* directory models' `path` is relative to (limits.asset_root) */
	const char *pipeline_cache;    /* pipeline cache file, loaded at start, saved at exit */
	enum srv_log_format log_format;
	const char *device;            /* substring of the Vulkan device name */
	unsigned atlas_size;           /* shadow atlas side, 0 = renderer default */
	unsigned max_connections;      /* concurrent TCP connections, default 1024 */
	unsigned max_connections_per_ip; /* concurrent connections from one address, 0 = any, default 256 */
	/* concurrent connections from one address range (IPv4 /24, IPv6 /64: server/ranges.h), 0 = any;
	 * default SRV_SHARE_DEFAULT = a quarter of max_connections, resolved by srv_conn_share_start() */
	unsigned max_connections_per_range;
	unsigned idle_timeout_s;       /* idle connection timeout, default 60 */
	unsigned header_timeout_s;     /* a new connection's first request head, 0 = idle, default 10 */
	unsigned drain_timeout_s;      /* longest wait for queued/in-flight work at exit, default 60 */
	unsigned drain_grace_ms;       /* at SIGTERM, /readyz 503 this long while renders are still taken */
	uint64_t model_cache_bytes;    /* api_model_cache_set_limit() at start, default 256 MiB */
	unsigned idle_trim_s;          /* idle this long: drop unused cached maps, give memory back; 0 = never, default 30 */
	uint64_t max_rss;              /* resident-memory bound kept after each request (srv_context_fit_rss), 0 = none */
	bool max_rss_given;            /* --max-rss set: else settled after the warm-up (srv_rss_bound_settle) */
	uint64_t max_memory;           /* bytes renders in flight may need together (admit.h); 0 = default */
	bool validation;               /* UMBRA_VALIDATION=1: Vulkan validation layer */
	bool no_playground;            /* --no-playground / UMBRA_NO_PLAYGROUND=1: no page at / */
	const char *allowed_host;      /* --allowed-host LIST (server/origin.h); NULL = by the listen address */
	const char *cors_origin;       /* --cors-origin LIST (server/origin.h); NULL = no cross-origin caller */
	const char *test_fault;        /* tests only: "submit:N:lost|oom" armed after warm-up */
	unsigned result_cache_mb;      /* --result-cache-mb: the GET form's images (results.h); 0 = off, default 64 */
	const char *cache_control;     /* --cache-control: of POST render answers, default "no-cache" */
};

#define SRV_SHARE_DEFAULT UINT32_MAX

enum srv_route {
	SRV_ROUTE_RENDER, SRV_ROUTE_HEALTHZ, SRV_ROUTE_READYZ, SRV_ROUTE_METRICS, SRV_ROUTE_INFO,
	SRV_ROUTE_PLAYGROUND,          /* GET / and /playground (server/playground.c) */
	SRV_ROUTE_RENDERS,             /* POST /v1/renders: render, store, 303 to the GET form */
	SRV_ROUTE_RESULT,              /* GET /v1/renders/{hash}.{ext} (server/renders_route.c) */
	SRV_ROUTE_EXPLAIN,             /* POST /v1/explain: the render plan, nothing rendered (explain.c) */
	SRV_ROUTE_OTHER,
	SRV_ROUTE_COUNT
};
const char *srv_route_name(enum srv_route r);
/* The routes that take a scene by POST: /v1/render, /v1/renders, /v1/explain. */
bool srv_route_posts(enum srv_route r);

enum srv_priority { SRV_PRIO_INTERACTIVE, SRV_PRIO_BULK, SRV_PRIO_COUNT };

enum srv_stage { SRV_STAGE_PARSE, SRV_STAGE_UPLOAD, SRV_STAGE_SHADOW, SRV_STAGE_MAIN,
	SRV_STAGE_READBACK, SRV_STAGE_ENCODE, SRV_STAGE_COUNT };
const char *srv_stage_name(enum srv_stage s);

/* The daemon. One per process; every module gets a pointer to it. */
struct srv_server {
	struct srv_config cfg;
	struct MHD_Daemon *daemon;
	uint16_t port;
	struct srv_queue *queue;
	struct srv_metrics *metrics;
	struct srv_ranges *ranges;     /* connections per address range (conn.c, server/ranges.h) */
	struct srv_admit admit;        /* renders admitted by estimated memory (--max-memory) */
	struct srv_gate gate;          /* renders on the device at once (--device-renders) */
	struct srv_imports *imports;   /* requests parked for an import thread (--import-slots) */
	struct srv_origin origin;      /* Host and Origin rules, set by srv_http_start() (origin.h) */
	struct srv_results *results;   /* the GET form's result cache (results.h); NULL = off */

	/* The shared renderer. Renders hold ctx_lock for reading; recovery after a lost device
	 * takes it for writing, destroys and recreates the context (ctx_gen counts recreations). */
	pthread_rwlock_t ctx_lock;
	struct rnd_context *ctx;
	unsigned ctx_gen;
	struct rnd_info info;          /* of the current context, valid once ready */
	uint32_t validation_lost;      /* validation messages of destroyed contexts */

	pthread_t *threads;
	unsigned thread_count;

	atomic_bool ready;             /* context created and warm-up done */
	atomic_bool leaving;           /* SIGTERM/SIGINT seen: /readyz 503 (renders still taken for --drain-grace-ms) */
	atomic_bool draining;          /* after the grace: no new work */
	atomic_uint pending;           /* requests begun and not yet completed by libmicrohttpd */
	atomic_uint in_flight;         /* renders running now */
	atomic_uint_fast64_t next_id;  /* request id counter */
	atomic_uint_fast64_t yield_mark; /* queue time (ns) of the waiter a render last yielded to */
	uint64_t id_seed;
};

/* A named part of a multipart/form-data render request (a model's `part`). */
struct srv_part {
	char *name;
	uint8_t *data;
	size_t len, cap;
};

/* A scene kept to render again (server/results.h): a request's body and parts as sent. */
struct srv_kept_scene {
	char *body;
	size_t body_len;
	struct srv_part *parts;
	size_t part_count;
	int want;                      /* the request's Accept choice (enum srv_accept) */
	size_t bytes;                  /* what it holds, for the cache's bound */
};

/* One HTTP request (see the ownership note at the top). */
enum srv_req_state { SRV_REQ_HEADERS, SRV_REQ_BODY, SRV_REQ_QUEUED, SRV_REQ_FINISHED, SRV_REQ_ANSWERED };

struct srv_request {
	struct srv_server *srv;
	struct MHD_Connection *conn;
	struct srv_request *next;      /* queue link */
	enum srv_req_state state;
	enum srv_route route;
	enum srv_priority priority;
	char method[16];
	char path[128];                /* for logs, truncated */
	char id[80];                   /* X-Request-Id */
	double t_start, t_queued;      /* monotonic seconds */
	uint64_t client;               /* srv_client_key() of the peer: its share of import threads */
	char client_addr[48];          /* the peer's address, for the access log ("" = unknown) */

	/* body of POST /v1/render: the scene document, or for multipart/form-data the `scene` part
	 * (moved here when the body is complete) and the other named parts */
	struct MHD_PostProcessor *post;
	struct srv_part *parts;
	size_t part_count;
	const char *part_error;        /* why the multipart body is unusable, or NULL */
	char *body;
	size_t body_len, body_cap;
	size_t content_length;         /* the request's Content-Length (0: none or not yet read) */
	uint64_t body_received;        /* raw body bytes so far (multipart included) */
	bool body_oom;                 /* a body buffer could not grow: answer 503 */
	uint64_t body_discarded;       /* bytes dropped after going over --max-body */
	uint64_t etag_hash;            /* the ETag's value, known after parsing (negotiate.h srv_etag_of) */
	char etag[40];
	char if_none_match[512];       /* checked after parsing: 412 on a POST */
	uint64_t result_hash;          /* GET /v1/renders/{hash}: the hash asked for (rendered again) */
	char result_ext[8];            /* its extension */
	struct srv_kept_scene kept;    /* POST /v1/renders: the scene for the result cache (results.h) */
	char location[64];             /* the Location of a 303 */
	int want;                      /* Accept's choice (enum srv_accept: PNG, EXR or WebP) */
	bool explain;                  /* POST /v1/render?explain=1: the image and its plan (explain.c) */
	bool explain_preferred;        /* ... asked by `Prefer: explain`: answered with Preference-Applied */
	char mime[128];                 /* content_type when it is made per answer (multipart/mixed) */
	bool close_after;              /* answer with Connection: close (framing error) */
	char cors_origin[SRV_ORIGIN_MAX]; /* an allowed cross-origin caller's Origin, echoed; "" = none */
	bool cors_private_network;     /* its preflight asked Access-Control-Request-Private-Network */
	int refused;                   /* 403/421 answered once the body is read (detail in problem_detail) */

	/* result, written by the worker before srv_request_finish() */
	int status;
	uint8_t *out;                  /* malloc'd answer body */
	size_t out_len;
	const char *content_type;
	char server_timing[640];
	char warnings[1024];           /* api_scene.warnings, sent as Umbra-Warnings on a 200; "" = none */
	/* the problem answered (4xx/5xx), for the access log */
	char problem_pointer[256];
	char problem_detail[512];
};

/* Keeps what the access log says of a problem answer (its detail and pointer). */
void srv_request_note_problem(struct srv_request *req, const struct api_problem *p);

/* Worker side: stores nothing more and resumes the connection so http.c sends the answer. */
void srv_request_finish(struct srv_request *req);
/* Frees the body and the parts (the worker calls it once the scene is parsed). */
void srv_request_drop_body(struct srv_request *req);

/* http.c */
int srv_http_start(struct srv_server *s);           /* 0 or -1 (logged) */
void srv_http_quiesce(struct srv_server *s);        /* stops accepting connections */
void srv_http_stop(struct srv_server *s);

/* context.c */
int srv_context_open(struct srv_server *s);         /* create + info; 0 or -1 (logged) */
/* After RND_ERR_DEVICE_LOST from the context of generation gen: recreates and warms it up once. */
void srv_context_recover(struct srv_server *s, unsigned gen);
int srv_warmup(struct srv_server *s);               /* 0 or -1 (logged); server/warmup.c */
/* A render plan made on the shared context (context.c), and that context's generation: a
 * render after a recovery makes its plan again on the new context. */
struct srv_plan {
	struct rnd_plan *plan;
	unsigned gen;
};
/* The plan of scene on the shared context (rnd_plan_create): RND_OK, the plan's own error, or
 * RND_ERR_DEVICE_LOST when there is no context (the render reports it). */
enum rnd_result srv_plan(struct srv_server *s, const struct rnd_scene *scene, struct srv_plan *out,
                         struct rnd_error *err);
void srv_plan_release(struct srv_plan *p);
/* Renders scene by its plan on the shared context (context.c): plan->plan made before (admission
 * reads its estimate), or made here when it is NULL or of an older context. On
 * RND_ERR_DEVICE_LOST, *lost_gen (if given) is the lost context's generation + 1, and the daemon
 * is marked not ready. */
enum rnd_result srv_render(struct srv_server *s, const struct rnd_scene *scene, struct srv_plan *plan,
                           struct rnd_image *img, struct rnd_timings *t, struct rnd_error *err, unsigned *lost_gen);
/* Memory back to the system: shadow maps unused for idle_s seconds, the atlases' pages once no
 * map is left (rnd_context_trim), then malloc's free pages. Returns the atlas bytes released. */
uint64_t srv_context_trim(struct srv_server *s, double idle_s);
/* At start: how malloc keeps memory between requests (context.c): big buffers mapped, the rest
 * served from heaps that keep what the next request will ask again. */
void srv_heap_policy(void);
/* The process's resident memory now (bytes, /proc/self/statm). */
uint64_t srv_rss_bytes(void);
/* After a request: when the process is over --max-rss, gives back what it keeps between
 * requests, cheapest to make again first, until it is under (context.c). Any thread; one at a
 * time (another thread already at it: returns). */
void srv_context_fit_rss(struct srv_server *s);
/* The default --max-rss, once the warm-up is done: 192 MiB, or a quarter above the ready
 * daemon's resident memory where that is more (a GPU driver maps more than lavapipe does, and a
 * bound under a ready daemon would trim after every request). */
void srv_rss_bound_settle(struct srv_server *s);
int srv_context_close(struct srv_server *s);        /* saves the cache; returns validation count */
int srv_fault_arm(struct srv_server *s);            /* --test-fault; 0 or -1 (logged) */
/* worker.c */
int srv_workers_start(struct srv_server *s);
void srv_workers_join(struct srv_server *s);        /* after srv_queue_close() */

/* flags.c: 0 ok, 1 --help printed (exit 0), -1 error printed (exit 2). The strings in cfg
 * point into argv or the environment: nothing to free. */
int srv_config_load(struct srv_config *cfg, int argc, char **argv);
/* Default worker count: `cpus` capped by the cgroup CPU quota found under `root` (see flags.c). */
unsigned srv_default_workers(const char *root, const char *self_cgroup, unsigned cpus);

/* server/playground.c: whether url is the playground's (/ or /playground); the page as a
 * malloc'd copy (NULL when out of memory). */
bool srv_playground_path(const char *url);
char *srv_playground_page(size_t *len);
/* The page's Content-Security-Policy, made with it at build time (hashes of its inline
 * script and style: server/www/embed.sh). */
const char *srv_playground_csp(void);

/* Small shared helpers (main.c). */

#endif
