/*
 * umbrad configuration: contract defaults, then UMBRA_* environment variables, then flags
 * (a flag wins over its variable). Every flag --name-with-dashes has the variable
 * UMBRA_NAME_WITH_DASHES; UMBRA_VALIDATION=1 (no flag) turns the Vulkan validation layer on.
 */
#include <errno.h>
#include <getopt.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "log.h"
#include "srv.h"

enum opt_kind { OPT_STR, OPT_UINT, OPT_SIZE, OPT_LOGFMT };

struct opt_def {
	const char *name;
	enum opt_kind kind;
	const char *arg, *help;
	size_t offset;      /* into struct srv_config, or (size_t)-1 for limits below */
	uint64_t min, max;
};

#define CFG(m) offsetof(struct srv_config, m)
#define LIM(m) (offsetof(struct srv_config, limits) + offsetof(struct api_limits, m))

static const struct opt_def opts[] = {
	{ "listen", OPT_STR, "ADDR:PORT", "address to listen on (127.0.0.1:8080; port 0 = any free port)", CFG(listen), 0, 0 },
	{ "port-file", OPT_STR, "PATH", "write the bound port to PATH once listening", CFG(port_file), 0, 0 },
	{ "workers", OPT_UINT, "N", "render threads and context slots (default: online CPUs, at most the cgroup CPU quota)", CFG(workers), 1, 256 },
	{ "device-renders", OPT_UINT, "N", "renders on the device at once; the other workers parse and encode meanwhile (default 0: 1 on a CPU device such as lavapipe, whose one render already uses every core; all workers on a GPU)", CFG(device_renders), 0, 256 },
	{ "import-slots", OPT_UINT, "N", "threads that import models (sandboxed), beside the --workers threads, which never import: a request whose model the cache lacks waits for one of them holding no thread; a free one takes the request of the client address with the fewest imports running (default 0: as many as --workers, and no more than --max-memory / --import-memory); twice as many threads import, so that one whose import is done renders while the next imports", CFG(import_slots), 0, 256 },
	{ "queue", OPT_UINT, "N", "renders that may wait for a worker before 503 (64)", CFG(queue), 1, 1000000 },
	{ "max-body", OPT_SIZE, "BYTES", "largest request body, K/M/G suffixes (64M)", CFG(max_body), 1, UINT64_MAX },
	{ "max-pixels", OPT_SIZE, "N", "largest width*height, 0 = no limit (16777216)", LIM(max_pixels), 0, UINT64_MAX },
	{ "max-triangles", OPT_SIZE, "N", "most triangles after tessellation, 0 = no limit (20M)", LIM(max_triangles), 0, UINT64_MAX },
	{ "max-lights", OPT_UINT, "N", "most lights, 0 = no limit (64)", LIM(max_lights), 0, UINT32_MAX },
	{ "max-shadow-resolution", OPT_UINT, "N", "largest shadow map side, asked for or chosen by the renderer, 0 = no limit (8192)", LIM(max_shadow_resolution), 0, UINT32_MAX },
	{ "deadline-ms", OPT_UINT, "MS", "answer 504 past this time from queueing, 0 = none (30000)", CFG(deadline_ms), 0, UINT32_MAX },
	{ "asset-root", OPT_STR, "DIR", "directory that models' `path` is relative to (none: `path` is a 400)", CFG(asset_root), 0, 0 },
	{ "model-cache", OPT_SIZE, "BYTES", "cache of imported models, 0 = off (64M)", CFG(model_cache_bytes), 0, UINT64_MAX },
	{ "import-timeout-ms", OPT_UINT, "MS", "wall-clock and CPU limit of one sandboxed model import (10000)", LIM(import_timeout_ms), 1, 3600000 },
	{ "import-memory", OPT_SIZE, "BYTES", "memory limit of one sandboxed model import, 0 = none (2G)", LIM(import_memory), 0, UINT64_MAX },
	{ "max-textures", OPT_UINT, "N", "distinct textures in one scene, at most 4096; materials sharing textures are not counted twice (256)", LIM(max_textures), 1, 1000000 },
	{ "warm-up", OPT_STR, "defaults|all", "pipelines compiled before ready: the contract's defaults (MSAA 4, PNG; sun, cascades, spot, point; pcf, pcss; the thumbnail preset's studio environment), or also MSAA 1, EXR and VSM/EVSM (~14 MB each on lavapipe; otherwise compiled at first use) (defaults)", CFG(warm_up), 0, 0 },
	{ "pipeline-cache", OPT_STR, "PATH", "Vulkan pipeline cache, loaded at start, saved at exit", CFG(pipeline_cache), 0, 0 },
	{ "log-format", OPT_LOGFMT, "text|json", "stderr log lines (text)", CFG(log_format), 0, 0 },
	{ "atlas-size", OPT_UINT, "N", "texels per side of the shadow atlases, power of two (8192)", CFG(atlas_size), 0, 16384 },
	{ "device", OPT_STR, "NAME", "substring of the Vulkan device name to use", CFG(device), 0, 0 },
	{ "max-connections", OPT_UINT, "N", "concurrent connections; more wait in the listen queue until one closes (1024)", CFG(max_connections), 1, 1000000 },
	{ "max-connections-per-ip", OPT_UINT, "N", "concurrent connections from one client address, 0 = no limit (256)", CFG(max_connections_per_ip), 0, 1000000 },
	{ "max-connections-per-range", OPT_UINT, "N", "concurrent connections from one client address range (IPv4 /24, IPv6 /64; loopback too); more are closed unanswered at accept, 0 = no limit (a quarter of --max-connections)", CFG(max_connections_per_range), 0, 1000000 },
	{ "allowed-host", OPT_STR, "LIST", "Host names served, comma-separated, port ignored, * = any; others get 421 (against DNS rebinding; /healthz and /readyz always answer). Default: on a loopback --listen only localhost, 127.0.0.1, ::1 and the listen host; on other addresses any", CFG(allowed_host), 0, 0 },
	{ "cors-origin", OPT_STR, "LIST", "origins of other sites whose pages may call the daemon (CORS), comma-separated scheme://host[:port], or *; a browser request from any other origin gets 403. Default: none (curl and scripts send no Origin: unaffected)", CFG(cors_origin), 0, 0 },
	{ "idle-timeout", OPT_UINT, "S", "close connections idle this long (60)", CFG(idle_timeout_s), 1, 86400 },
	{ "max-memory", OPT_SIZE, "BYTES", "memory renders in flight may need together; a render estimated over it is a 422, others wait (half the machine's or container's memory)", CFG(max_memory), 0, UINT64_MAX },
	{ "header-timeout", OPT_UINT, "S", "close a new connection idle this long before its first request head, 0 = --idle-timeout (10)", CFG(header_timeout_s), 0, 86400 },
	{ "drain-timeout", OPT_UINT, "S", "at SIGTERM, longest wait for queued work (60)", CFG(drain_timeout_s), 1, 86400 },
	{ "drain-grace-ms", OPT_UINT, "MS", "at SIGTERM, /readyz answers 503 this long while new renders are still taken, so a load balancer's health checks take the daemon out before it refuses work; a second signal ends it (0)", CFG(drain_grace_ms), 0, 600000 },
	{ "max-rss", OPT_SIZE, "BYTES", "resident memory the daemon keeps after a request: over it, it gives back freed heap, unused shadow maps and atlas pages, idle render slots' targets, pipeline variants but the most recently used and cached models, in that order, until it is under; 0 = no bound (192M, or a quarter above the ready daemon's where that is more)", CFG(max_rss), 0, UINT64_MAX },
	{ "idle-trim", OPT_UINT, "S", "after S s without a request, drop shadow maps unused for S s and give the atlas pages and freed heap back to the system, 0 = never (30)", CFG(idle_trim_s), 0, 86400 },
	{ "result-cache-mb", OPT_UINT, "MB", "images POST /v1/renders keeps for GET /v1/renders/{hash}.{ext} (LRU), and up to an eighth as much (1 MB at least) of their scenes, each up to 1 MB, to render an evicted image again; 0 = off: both routes 404 (64)", CFG(result_cache_mb), 0, 1048576 },
	{ "cache-control", OPT_STR, "VALUE", "Cache-Control of POST /v1/render and /v1/renders answers (no-cache: a cache must revalidate; the ETag is in the answer); GET /v1/renders/{hash}.{ext} always says public, max-age=31536000, immutable", CFG(cache_control), 0, 0 },
	{ "test-fault", OPT_STR, "submit:N:lost|oom", "tests only: the Nth queue submit after warm-up fails", CFG(test_fault), 0, 0 },
};
#define OPT_COUNT (sizeof opts / sizeof opts[0])

static enum srv_log_format early_format = SRV_LOG_TEXT;

/* A configuration error on stderr: "umbrad: MESSAGE", or with --log-format json (flag or
 * UMBRA_LOG_FORMAT, read before anything else) a JSON log line like every other. */
static void config_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void config_error(const char *fmt, ...)
{
	char msg[600];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	if (early_format == SRV_LOG_JSON)
		srv_log(SRV_LOG_ERROR, "%s", msg);
	else
		fprintf(stderr, "umbrad: %s\n", msg);
}

/* The log format the flags and environment ask for, before they are parsed (the last
 * --log-format wins, as getopt will have it). */
static enum srv_log_format peek_log_format(int argc, char **argv)
{
	const char *v = getenv("UMBRA_LOG_FORMAT");
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--log-format") && i + 1 < argc)
			v = argv[++i];
		else if (!strncmp(argv[i], "--log-format=", 13))
			v = argv[i] + 13;
	}
	return v && !strcasecmp(v, "json") ? SRV_LOG_JSON : SRV_LOG_TEXT;
}

static void usage(FILE *f)
{
	fprintf(f, "usage: umbrad [FLAGS]\n"
	           "HTTP render daemon: POST /v1/render (scene JSON -> PNG/EXR), POST /v1/renders (-> 303 to\n"
	           "a cacheable GET /v1/renders/{hash}.png), GET /healthz, /readyz, /metrics, /v1/info. Every flag can also be set as UMBRA_<FLAG> (e.g. UMBRA_MAX_BODY);\n"
	           "a flag wins over its variable. UMBRA_VALIDATION=1 enables the Vulkan validation layer.\n"
	           "Models and textures are parsed in sandboxed child processes of umbra-import (found next to\n"
	           "umbrad, or UMBRA_IMPORT_HELPER=PATH): over --import-timeout-ms / --import-memory is a 422,\n"
	           "a crash of the parser a 400, for that request only.\n"
	           "Browsers: a request whose Origin is not the daemon's own is refused (403) unless\n"
	           "--cors-origin lists it; a Host not in --allowed-host is refused (421).\n\n");
	for (size_t i = 0; i < OPT_COUNT; i++) {
		char left[64];
		snprintf(left, sizeof left, "--%s %s", opts[i].name, opts[i].arg);
		fprintf(f, "  %-34s %s\n", left, opts[i].help);
	}
	fprintf(f, "  %-34s %s\n", "--no-playground", "no playground page at / and /playground (UMBRA_NO_PLAYGROUND=1)");
	fprintf(f, "  %-34s %s\n", "--help", "this text");
}

static int parse_u64(const char *s, bool suffixes, uint64_t *out)
{
	char *end;
	errno = 0;
	if (!s || !*s || *s == '-')
		return -1;
	unsigned long long v = strtoull(s, &end, 10);
	if (errno || end == s)
		return -1;
	uint64_t mul = 1;
	if (suffixes && *end) {
		switch (*end) {
		case 'k': case 'K': mul = 1ull << 10; break;
		case 'm': case 'M': mul = 1ull << 20; break;
		case 'g': case 'G': mul = 1ull << 30; break;
		default: return -1;
		}
		end++;
		if (*end == 'i' || *end == 'I')
			end++;
		if (*end == 'b' || *end == 'B')
			end++;
	}
	if (*end)
		return -1;
	if (v > UINT64_MAX / mul)
		return -1;
	*out = v * mul;
	return 0;
}

/* Applies one value; `from` names its source for the message ("--workers", "UMBRA_WORKERS"). */
static int apply(struct srv_config *cfg, const struct opt_def *o, const char *val, const char *from)
{
	char *base = (char *)cfg;
	uint64_t v;
	switch (o->kind) {
	case OPT_STR:
		if (!val || !*val) {
			config_error("%s: empty value", from);
			return -1;
		}
		*(const char **)(base + o->offset) = val;
		return 0;
	case OPT_LOGFMT:
		if (val && !strcasecmp(val, "text"))
			cfg->log_format = SRV_LOG_TEXT;
		else if (val && !strcasecmp(val, "json"))
			cfg->log_format = SRV_LOG_JSON;
		else {
			config_error("%s: '%s' is not text or json", from, val ? val : "");
			return -1;
		}
		return 0;
	case OPT_UINT:
	case OPT_SIZE:
		if (parse_u64(val, o->kind == OPT_SIZE, &v) != 0 || v < o->min || v > o->max) {
			config_error("%s: '%s' is not a number in %llu..%llu", from, val ? val : "",
			        (unsigned long long)o->min, (unsigned long long)o->max);
			return -1;
		}
		if (o->offset == CFG(max_rss)) cfg->max_rss_given = true;
		/* Members are unsigned or uint32_t (4 bytes) or uint64_t (8 bytes). */
		if (o->offset == CFG(max_body) || o->offset == LIM(max_pixels) || o->offset == LIM(max_triangles) ||
		    o->offset == CFG(model_cache_bytes) || o->offset == CFG(max_memory) || o->offset == CFG(max_rss) ||
		    o->offset == LIM(import_memory))
			*(uint64_t *)(base + o->offset) = v;
		else
			*(uint32_t *)(base + o->offset) = (uint32_t)v;
		return 0;
	}
	return -1;
}

/* The default --workers: `cpus` (the CPUs this process may run on) lowered to its cgroup's CPU
 * quota, rounded up. A container sees the host's cores in sysconf() but gets only its quota:
 * one render thread per host core would then fight over a fraction of them. Reads cgroup v2
 * `cpu.max` ("QUOTA PERIOD" or "max PERIOD") in the process's own cgroup (the "0::PATH" line of
 * `self_cgroup`, e.g. /proc/self/cgroup; a systemd CPUQuota= lands there), then at `root`
 * itself (a container's cgroup namespace), else cgroup v1 cpu/cpu.cfs_quota_us and
 * cpu.cfs_period_us (-1 = no quota). `root` is the cgroup mount (/sys/fs/cgroup); the unit
 * tests pass a fake tree. Never returns 0. */
unsigned srv_default_workers(const char *root, const char *self_cgroup, unsigned cpus)
{
	char path[4096], line[4096], rel[4096] = "";
	long long quota = 0, period = 0;
	bool found = false;
	FILE *f = self_cgroup ? fopen(self_cgroup, "r") : NULL;
	while (f && fgets(line, sizeof line, f))
		if (!strncmp(line, "0::", 3) && (sscanf(line + 3, "%4095s", rel) != 1 || !strcmp(rel, "/")))
			rel[0] = 0;
	if (f)
		fclose(f);
	/* v2: the own cgroup first, then the mount's root. "max PERIOD" = no quota. */
	const char *dirs[2] = { rel, "" };
	for (int i = 0; i < 2 && !found; i++) {
		snprintf(path, sizeof path, "%s%s/cpu.max", root, dirs[i]);
		if (!(f = fopen(path, "r")))
			continue;
		found = true;
		if (fscanf(f, "%lld %lld", &quota, &period) != 2)
			quota = 0;
		fclose(f);
	}
	/* v1: quota -1 = none. */
	for (int i = 0; i < 2 && !found; i++) {
		snprintf(path, sizeof path, "%s/cpu/cpu.cfs_%s_us", root, i ? "period" : "quota");
		if ((f = fopen(path, "r"))) {
			if (fscanf(f, "%lld", i ? &period : &quota) != 1)
				quota = 0;
			fclose(f);
		}
	}
	if (cpus == 0)
		cpus = 1;
	if (quota <= 0 || period <= 0)
		return cpus;
	long long n = (quota + period - 1) / period;
	return n < (long long)cpus ? (unsigned)n : cpus;
}

/* The contract's defaults, then UMBRA_VALIDATION and UMBRA_NO_PLAYGROUND. */
static void set_defaults(struct srv_config *cfg)
{
	memset(cfg, 0, sizeof *cfg);
	cfg->listen = "127.0.0.1:8080";
	long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
	cfg->workers = srv_default_workers("/sys/fs/cgroup", "/proc/self/cgroup",
	                                   ncpu > 0 ? (unsigned)(ncpu > 256 ? 256 : ncpu) : 1);
	cfg->queue = 64;
	/* Room for four concurrent renders of four 2048 cascades each: under that load no request
	 * has its shadow resolution lowered (which would change its bytes). */
	cfg->atlas_size = 8192;
	cfg->max_body = 64ull << 20;
	api_limits_defaults(&cfg->limits);
	cfg->limits.import_flags = true;   /* --import-timeout-ms, --import-memory: named in their 422s */
	cfg->model_cache_bytes = 64u << 20;   /* the process stays small (issue 28); more for repeated big models */
	cfg->deadline_ms = 30000;
	cfg->log_format = SRV_LOG_TEXT;
	cfg->max_connections = 1024;
	cfg->idle_timeout_s = 60;
	/* Behind a load balancer every connection comes from the balancer's address: a quarter of
	 * the connections still leaves room for a balancer's pool (haproxy's per-server maxconn
	 * is far lower) while one direct client can no longer take them all. */
	cfg->max_connections_per_ip = 256;
	cfg->max_connections_per_range = SRV_SHARE_DEFAULT;   /* a quarter of the final max_connections (conn.c) */
	cfg->header_timeout_s = 10;
	cfg->drain_timeout_s = 60;
	cfg->idle_trim_s = 30;
	cfg->result_cache_mb = 64;
	const char *v = getenv("UMBRA_VALIDATION");
	cfg->validation = v && *v && strcmp(v, "0") != 0;
	v = getenv("UMBRA_NO_PLAYGROUND");
	cfg->no_playground = v && *v && strcmp(v, "0") != 0;
}

/* Every UMBRA_<FLAG> variable of the environment into cfg (flags win: they come after). */
static int load_env(struct srv_config *cfg)
{
	for (size_t i = 0; i < OPT_COUNT; i++) {
		char env[64] = "UMBRA_";
		size_t n = strlen(env);
		for (const char *p = opts[i].name; *p && n + 1 < sizeof env; p++)
			env[n++] = *p == '-' ? '_' : (char)(*p >= 'a' && *p <= 'z' ? *p - 32 : *p);
		env[n] = 0;
		const char *val = getenv(env);
		if (val && apply(cfg, &opts[i], val, env) != 0)
			return -1;
	}
	return 0;
}

/* The command line's flags into cfg: 0, 1 after --help, -1 on a bad one. */
static int load_flags(struct srv_config *cfg, int argc, char **argv)
{
	struct option lopts[OPT_COUNT + 3];
	for (size_t i = 0; i < OPT_COUNT; i++)
		lopts[i] = (struct option){ opts[i].name, required_argument, NULL, (int)(i + 1000) };
	lopts[OPT_COUNT] = (struct option){ "help", no_argument, NULL, 'h' };
	lopts[OPT_COUNT + 1] = (struct option){ "no-playground", no_argument, NULL, 'P' };
	lopts[OPT_COUNT + 2] = (struct option){ 0 };
	optind = 1;
	for (;;) {
		int c = getopt_long(argc, argv, "h", lopts, NULL);
		if (c == -1)
			break;
		if (c == 'h') {
			usage(stdout);
			return 1;
		}
		if (c == 'P') {
			cfg->no_playground = true;
			continue;
		}
		if (c < 1000) {
			usage(stderr);
			return -1;
		}
		const struct opt_def *o = &opts[c - 1000];
		char from[64];
		snprintf(from, sizeof from, "--%s", o->name);
		if (apply(cfg, o, optarg, from) != 0)
			return -1;
	}
	if (optind < argc) {
		config_error("unexpected argument '%s'", argv[optind]);
		usage(stderr);
		return -1;
	}
	return 0;
}

/* What no single flag can check alone, and what follows from several; -1 on a bad value. */
static int check_and_derive(struct srv_config *cfg)
{
	if (cfg->limits.max_shadow_resolution && cfg->limits.max_shadow_resolution < RND_MIN_SHADOW_RESOLUTION) {
		config_error("--max-shadow-resolution: %u is under the smallest map, %u (0: no limit)",
		        cfg->limits.max_shadow_resolution, RND_MIN_SHADOW_RESOLUTION);
		return -1;
	}
	if (cfg->atlas_size & (cfg->atlas_size - 1)) {
		config_error("--atlas-size: %u is not a power of two", cfg->atlas_size);
		return -1;
	}
	if (cfg->warm_up && strcmp(cfg->warm_up, "defaults") && strcmp(cfg->warm_up, "all")) {
		config_error("--warm-up: '%s' is not defaults or all", cfg->warm_up);
		return -1;
	}
	if (cfg->asset_root && access(cfg->asset_root, R_OK | X_OK) != 0) {
		config_error("--asset-root: cannot open '%s': %s", cfg->asset_root, strerror(errno));
		return -1;
	}
	/* The lists are checked here, so that a bad entry exits 2; srv_http_start() builds them
	 * again with the listen address. */
	struct srv_origin o;
	struct srv_origin_error oerr;
	if (srv_origin_init(&o, &(struct srv_origin_config){ .allowed_hosts = cfg->allowed_host,
	                                                     .cors_origins = cfg->cors_origin }, &oerr) != SRV_ORIGIN_OK) {
		config_error("%s", oerr.msg);
		return -1;
	}
	srv_origin_release(&o);
	for (const char *p = cfg->cache_control; p && *p; p++)
		if ((unsigned char)*p < 0x20 || (unsigned char)*p > 0x7e) {
			config_error("--cache-control: not one line of printable ASCII");
			return -1;
		}
	cfg->limits.asset_root = cfg->asset_root;
	if (!cfg->max_memory) cfg->max_memory = srv_admit_default_budget();
	/* Import slots: one per worker, and no more import children than --max-memory holds at the
	 * --import-memory each may take (server/imports.h). */
	if (!cfg->import_slots) {
		uint64_t fit = cfg->limits.import_memory ? cfg->max_memory / cfg->limits.import_memory : cfg->workers;
		cfg->import_slots = fit < 1 ? 1 : fit < cfg->workers ? (unsigned)fit : cfg->workers;
	}
	return 0;
}

int srv_config_load(struct srv_config *cfg, int argc, char **argv)
{
	_Static_assert(sizeof(unsigned) == sizeof(uint32_t), "unsigned members are set as uint32_t");
	set_defaults(cfg);
	early_format = peek_log_format(argc, argv);
	srv_log_init(early_format);
	if (load_env(cfg) != 0)
		return -1;
	int rc = load_flags(cfg, argc, argv);
	if (rc != 0)
		return rc;
	return check_and_derive(cfg);
}
