/*
 * server/farm_internal — what the farm's files share (farm.c: the runner and local renders;
 * farm_remote.c: renders by a daemon or a cluster; farm_report.c: the report and --resume).
 * Not for other modules: farm.h is the farm's interface.
 */
#ifndef UMBRA_FARM_INTERNAL_H
#define UMBRA_FARM_INTERNAL_H

#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include "api.h"
#include "farm.h"
#include "http_client.h"
#include "model_refs.h"
#include "umbra/rnd.h"

enum job_status { JOB_PENDING, JOB_OK, JOB_INVALID, JOB_FAILED, JOB_SKIPPED };
extern const char *const FARM_STATUS[];

struct job_result {
	enum job_status status;
	double ms;
	char stem[PATH_MAX - 8];  /* output path without extension (default names) */
	char out[PATH_MAX];
	char error[640];
	char warnings[1024];      /* api_scene.warnings of a rendered model, "" = none */
	char hash[17];            /* content hash of the input's files (16 hex digits), "" = unread */
	bool resumed;             /* ok from an earlier run's report (--resume), not rendered now */
	unsigned attempts;        /* remote: requests sent for this input (0: local) */
	char timing[1024];        /* remote: the daemon's Server-Timing header */
	/* where a local `ok` job's time went (the report's "stages") */
	struct api_import_times imp;
	struct rnd_timings tm;
	double parse_ms, encode_ms;
	bool env;                 /* the scene had an environment map (its stage in the report) */
};

/* A job's bytes as read once: the scene document (or thumbnail document) and the parts. */
struct job_input {
	char *bytes;              /* the input file, malloc'd (NULL for an inline scene) */
	size_t len;
	const char *doc;          /* the document to parse or send */
	size_t doc_len;
	char thumb[512];          /* a model job's document */
	struct api_model_refs refs;
	struct api_part *parts;   /* a model job's parts (model + its files), malloc'd */
	size_t nparts;
};

struct farm_resume;           /* an earlier report, farm_report.c */

struct farm {
	struct farm_job *jobs;
	struct job_result *res;
	size_t n;
	const struct farm_opts *o;
	struct rnd_context *ctx;  /* local farm only */
	struct srv_http_url url;  /* remote farm only */
	struct farm_resume *resume;
	FILE *journal;            /* the report while the run goes: a line per finished job */
	atomic_size_t next;
	pthread_mutex_t mu;       /* guards done, failed and the progress output */
	size_t done, failed, resumed;
	double t0;
	bool bar;
};

/* Set by SIGINT/SIGTERM: workers take no new job (farm.c). */
extern volatile sig_atomic_t farm_stop;

const char *farm_label(const struct farm_job *j);
/* Writes bytes to path through a temporary name, so a stopped run never leaves half a file. */
int farm_write_file(const char *path, const uint8_t *b, size_t n, char *err, size_t esize);

/* farm_remote.c: renders job i by f->o->server, writes its file. */
enum job_status farm_remote_job(struct farm *f, size_t i, const struct job_input *in);

/* farm_report.c */
int farm_write_report(const struct farm *f, const char *path);
/* Job i's line to the journal (opened by farm_run at the report's path, so a farm killed with
 * SIGKILL leaves the lines of what it finished for --resume); called with f->mu held. */
void farm_journal_line(struct farm *f, size_t i);
/* Reads the earlier report at path (absent: an empty one). NULL only when out of memory. */
struct farm_resume *farm_resume_load(const char *path);
void farm_resume_free(struct farm_resume *r);
/* true when job i's earlier line says ok for the same hash and its output file is there;
 * r->out is then set. */
bool farm_resume_hit(const struct farm_resume *rs, const struct farm *f, size_t i);

#endif
