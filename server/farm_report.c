/*
 * server/farm_report — the farm's JSON-lines report (one line per input, input order) and its
 * reading back for --resume: an input whose earlier line says ok with the same content hash,
 * and whose output file is still there, is not rendered again. While a run goes the report is
 * a journal (a line per finished job, flushed), so even a farm killed by SIGKILL can resume.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "buf.h"
#include "farm_internal.h"

static void json_str(FILE *fp, const char *s)
{
	size_t n = strlen(s) * 6 + 1;   /* every byte may become \u00XX */
	char *e = malloc(n);
	if (e) srv_json_escape(e, n, s);
	fprintf(fp, "\"%s\"", e ? e : "");
	free(e);
}

/* An ok job's stages in ms, named as in umbrad's Server-Timing (parse: what parsing spent
 * besides the models' stages; writing the file is the rest of "ms"). */
static void write_stages(FILE *fp, const struct job_result *r)
{
	double in_models = 0;
	for (int k = 0; k < API_IMPORT_STAGES; k++) in_models += r->imp.ms[k];
	fprintf(fp, ",\"stages\":{\"parse\":%.2f", r->parse_ms > in_models ? r->parse_ms - in_models : 0.0);
	if (r->imp.imports || r->imp.ms[API_IMPORT_READ] > 0)
		for (int k = 0; k < API_IMPORT_STAGES; k++) fprintf(fp, ",\"%s\":%.2f", API_IMPORT_STAGE_NAMES[k], (double)r->imp.ms[k]);
	if (r->env) fprintf(fp, ",\"environment\":%.2f", r->tm.env_ms);   /* as umbrad's Server-Timing */
	fprintf(fp, ",\"upload\":%.2f,\"targets\":%.2f", r->tm.upload_ms, r->tm.targets_ms);
	if (r->tm.compile_ms > 0) fprintf(fp, ",\"compile\":%.2f", r->tm.compile_ms);
	fprintf(fp, ",\"shadow\":%.2f,\"main\":%.2f,\"readback\":%.2f,\"encode\":%.2f}", r->tm.shadow_ms, r->tm.main_ms,
	        r->tm.readback_ms, r->encode_ms);
}

/* A remote job's stages: the daemon's Server-Timing ("parse;dur=0.4, upload;dur=1.2, ...")
 * as the same object. */
static void write_remote_stages(FILE *fp, const char *timing)
{
	fputs(",\"stages\":{", fp);
	int n = 0;
	for (const char *p = timing; *p;) {
		p += strspn(p, " ,");
		size_t nl = strcspn(p, ";, ");
		const char *dur = strstr(p, "dur=");
		const char *next = p + strcspn(p, ",");
		if (nl && nl < 48 && dur && dur < next)
			fprintf(fp, "%s\"%.*s\":%.2f", n++ ? "," : "", (int)nl, p, strtod(dur + 4, NULL));
		p = next;
	}
	fputc('}', fp);
}

static void write_line(FILE *fp, const struct farm *f, size_t i)
{
	const struct job_result *r = &f->res[i];
	fputs("{\"file\":", fp);
	json_str(fp, farm_label(&f->jobs[i]));
	fputs(",\"output\":", fp);
	if (r->status == JOB_OK) json_str(fp, r->out);
	else fputs("null", fp);
	fprintf(fp, ",\"status\":\"%s\",\"ms\":%.1f,\"error\":", FARM_STATUS[r->status], r->ms);
	if (r->error[0]) json_str(fp, r->error);
	else fputs("null", fp);
	fputs(",\"warnings\":", fp);   /* what of a model's material is not drawn (Umbra-Warnings) */
	if (r->warnings[0]) json_str(fp, r->warnings);
	else fputs("null", fp);
	if (r->hash[0]) fprintf(fp, ",\"hash\":\"%s\"", r->hash);
	if (r->resumed) fputs(",\"resumed\":true", fp);
	if (r->attempts) fprintf(fp, ",\"attempts\":%u", r->attempts);
	if (r->status == JOB_OK && !r->resumed) {
		if (f->o->server) write_remote_stages(fp, r->timing);
		else write_stages(fp, r);
	}
	fputs("}\n", fp);
}

void farm_journal_line(struct farm *f, size_t i)
{
	if (!f->journal) return;
	write_line(f->journal, f, i);
	fflush(f->journal);
}

int farm_write_report(const struct farm *f, const char *path)
{
	/* Through a temporary name: a report being replaced (--resume) is never left half written. */
	char tmp[PATH_MAX + 16];
	snprintf(tmp, sizeof tmp, "%s.tmp", path);
	FILE *fp = fopen(tmp, "w");
	if (!fp) {
		fprintf(stderr, "umbra-render: cannot write report '%s': %s\n", tmp, strerror(errno));
		return -1;
	}
	for (size_t i = 0; i < f->n; i++) write_line(fp, f, i);
	if (fclose(fp) != 0 || rename(tmp, path) != 0) {
		fprintf(stderr, "umbra-render: cannot write report '%s': %s\n", path, strerror(errno));
		unlink(tmp);
		return -1;
	}
	return 0;
}

/* ---- --resume ---- */

struct resume_entry {
	struct api_report_entry e;
	size_t order;                  /* line number: a later line for the same file wins */
};

struct farm_resume {
	struct resume_entry *e;        /* the earlier report's ok lines with a hash, by file */
	size_t n;
};

static int by_file(const void *a, const void *b)
{
	const struct resume_entry *x = a, *y = b;
	int c = strcmp(x->e.file, y->e.file);
	return c ? c : (x->order > y->order) - (x->order < y->order);
}

static int by_file_only(const void *key, const void *b)
{
	return strcmp(key, ((const struct resume_entry *)b)->e.file);
}

/* Keeps the last line of each file (sorted by file, then line). */
static void keep_last(struct farm_resume *rs)
{
	size_t m = 0;
	for (size_t k = 0; k < rs->n; k++) {
		if (k + 1 < rs->n && !strcmp(rs->e[k].e.file, rs->e[k + 1].e.file)) {
			api_report_entry_release(&rs->e[k].e);
			continue;
		}
		rs->e[m++] = rs->e[k];
	}
	rs->n = m;
}

struct farm_resume *farm_resume_load(const char *path)
{
	struct farm_resume *rs = calloc(1, sizeof *rs);
	if (!rs) return NULL;
	size_t len = 0, cap = 0, order = 0;
	char *text = farm_read_file(path, &len);
	if (!text) {
		if (errno != ENOENT) fprintf(stderr, "umbra-render: --resume: cannot read '%s': %s (rendering all)\n", path,
		                             strerror(errno));
		return rs;
	}
	for (char *line = text, *next; line && *line; line = next) {
		next = strchr(line, '\n');
		if (next) *next++ = 0;
		struct api_report_entry e;
		struct api_problem p;
		order++;
		if (api_report_line(line, strlen(line), &e, &p) != API_OK) continue;   /* a line cut short */
		if (rs->n == cap) {
			struct resume_entry *ne = realloc(rs->e, (cap = cap ? 2 * cap : 64) * sizeof *ne);
			if (!ne) {
				api_report_entry_release(&e);
				break;
			}
			rs->e = ne;
		}
		rs->e[rs->n++] = (struct resume_entry){e, order};
	}
	free(text);
	if (rs->n) qsort(rs->e, rs->n, sizeof *rs->e, by_file);
	keep_last(rs);
	return rs;
}

void farm_resume_free(struct farm_resume *rs)
{
	if (!rs) return;
	for (size_t k = 0; k < rs->n; k++) api_report_entry_release(&rs->e[k].e);
	free(rs->e);
	free(rs);
}

bool farm_resume_hit(const struct farm_resume *rs, const struct farm *f, size_t i)
{
	struct job_result *r = &f->res[i];
	const struct farm_job *j = &f->jobs[i];
	const struct resume_entry *re = rs->n ? bsearch(farm_label(j), rs->e, rs->n, sizeof *rs->e, by_file_only) : NULL;
	const struct api_report_entry *e = re ? &re->e : NULL;
	/* The file's last line: ok, for these bytes. */
	if (!e || strcmp(e->status, "ok") || !e->hash || !e->output || strcmp(e->hash, r->hash)) return false;
	/* The same output this run would write: the explicit name, or the default stem + extension. */
	size_t sl = strlen(r->stem);
	if (j->out ? strcmp(e->output, j->out) : strncmp(e->output, r->stem, sl) || e->output[sl] != '.' ||
	                                            strchr(e->output + sl, '/'))
		return false;
	struct stat st;
	if (stat(e->output, &st) != 0 || !S_ISREG(st.st_mode) || !st.st_size) return false;
	snprintf(r->out, sizeof r->out, "%s", e->output);
	return true;
}
