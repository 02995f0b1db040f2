/*
 * server/farm_remote — the farm's renders by umbrad or a cluster (umbra-render --server URL):
 * each job's document and parts, as the local farm would parse them, POSTed to /v1/render
 * (multipart/form-data for a model: part `scene` and the named model files; a scene as
 * application/json), and the image written as the local farm writes it.
 *
 * Retries (renders are idempotent, so sending one again is safe):
 *   - a connection refused, reset or closed without a whole answer, 502 and 504 (a balancer
 *     that lost its daemon, a deadline): at most LOST_RETRIES more tries, backing off;
 *   - 503 and 429 (busy, draining): after Retry-After (or a backoff), at most BUSY_RETRIES;
 *   - each wait has jitter (x 1 to 1.5) so that many farms do not come back at once;
 *   - any other 4xx is the input's fault: `invalid`, never sent again, with the problem's
 *     status, pointer and detail as the local farm would word it; another 5xx is `failed`.
 * X-Umbra-Affinity carries the input's content hash, so a balancer keyed on it (deploy/
 * haproxy.cfg.in) sends the same model to the same daemon and its caches.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include "farm_internal.h"

enum { LOST_RETRIES = 4, BUSY_RETRIES = 30, TIMEOUT_S = 120 };

/* A multipart body as chunks: per part its header, its bytes, "\r\n"; then the closing line. */
struct multipart {
	char boundary[48];
	char *heads;                  /* (nparts + 1) headers of 512 bytes */
	struct srv_http_chunk *chunks;
	size_t nchunks;
};

static bool part_has(const struct api_part *parts, size_t n, const char *b)
{
	for (size_t k = 0; k < n; k++)
		if (memmem(parts[k].data, parts[k].len, b, strlen(b))) return true;
	return false;
}

static int multipart_build(struct multipart *m, const struct job_input *in, unsigned *seed, char *err, size_t esize)
{
	memset(m, 0, sizeof *m);
	size_t n = in->nparts + 1;
	m->heads = malloc(n * 512 + 64);
	m->chunks = calloc(3 * n + 1, sizeof *m->chunks);
	if (!m->heads || !m->chunks) {
		snprintf(err, esize, "out of memory");
		return -1;
	}
	do   /* a boundary none of the files holds */
		snprintf(m->boundary, sizeof m->boundary, "umbra-farm-%08x%08x", (unsigned)rand_r(seed), (unsigned)rand_r(seed));
	while (part_has(in->parts, in->nparts, m->boundary) || memmem(in->doc, in->doc_len, m->boundary, 20));
	for (size_t k = 0; k < n; k++) {
		const char *name = k ? in->parts[k - 1].name : "scene";
		if (strpbrk(name, "\"\r\n") || strlen(name) > 300) {
			snprintf(err, esize, "file name '%.300s' cannot be a multipart part name", name);
			return -1;
		}
		char *h = m->heads + k * 512;
		int hl = snprintf(h, 512, "--%s\r\nContent-Disposition: form-data; name=\"%s\"%s%s%s\r\nContent-Type: %s\r\n\r\n",
		                  m->boundary, name, k ? "; filename=\"" : "", k ? name : "", k ? "\"" : "",
		                  k ? "application/octet-stream" : "application/json");
		m->chunks[m->nchunks++] = (struct srv_http_chunk){h, (size_t)hl};
		m->chunks[m->nchunks++] = k ? (struct srv_http_chunk){in->parts[k - 1].data, in->parts[k - 1].len}
		                            : (struct srv_http_chunk){in->doc, in->doc_len};
		m->chunks[m->nchunks++] = (struct srv_http_chunk){"\r\n", 2};
	}
	char *tail = m->heads + n * 512;
	int tl = snprintf(tail, 64, "--%s--\r\n", m->boundary);
	m->chunks[m->nchunks++] = (struct srv_http_chunk){tail, (size_t)tl};
	return 0;
}

static void multipart_release(struct multipart *m)
{
	free(m->heads);
	free(m->chunks);
	memset(m, 0, sizeof *m);
}

/* Sleeps ms x (1 + jitter up to 0.5) in short steps; false when the farm was stopped meanwhile. */
static bool wait_retry(double ms, unsigned *seed)
{
	double end = farm_now_ms() + ms * (1.0 + 0.5 * rand_r(seed) / (double)RAND_MAX);
	while (!farm_stop) {
		double left = end - farm_now_ms();
		if (left <= 0) return true;
		struct timespec ts = {0, (long)((left < 50 ? left : 50) * 1e6)};
		nanosleep(&ts, NULL);
	}
	return false;
}

/* The wait before try number `tries` + 1 of one kind: Retry-After when given (capped at a
 * minute), else 250 ms doubling up to 8 s. */
static double backoff_ms(const char *retry_after, unsigned tries)
{
	char *end;
	double ra = retry_after && *retry_after ? strtod(retry_after, &end) : -1;
	if (ra >= 0 && retry_after && end != retry_after) return (ra < 60 ? ra : 60) * 1e3;
	double ms = 250.0 * (1u << (tries < 5 ? tries : 5));
	return ms < 8000 ? ms : 8000;
}

/* A 200's image into the job's output (its name by the answer's type, as the local farm names
 * one by the scene's format). */
static enum job_status take_image(struct farm *f, size_t i, const struct srv_http_response *resp)
{
	const struct farm_job *j = &f->jobs[i];
	struct job_result *r = &f->res[i];
	int got = -1;
	for (int k = API_FORMAT_PNG; k < API_FORMAT_COUNT; k++) {
		const char *mime = api_format_mime((enum api_format)k);
		if (!strncasecmp(resp->content_type, mime, strlen(mime))) got = k;
	}
	if (got < 0) {
		snprintf(r->error, sizeof r->error, "the server answered 200 with '%.100s', not an image", resp->content_type);
		return JOB_FAILED;
	}
	enum api_format want;
	if (j->out && api_format_from_name(j->out, &want) && want != (enum api_format)got) {
		snprintf(r->error, sizeof r->error, "the server answered %s for '%s'", api_format_mime((enum api_format)got),
		         j->out);
		return JOB_FAILED;
	}
	if (j->out) snprintf(r->out, sizeof r->out, "%s", j->out);
	else snprintf(r->out, sizeof r->out, "%s.%s", r->stem, api_format_name((enum api_format)got));
	snprintf(r->warnings, sizeof r->warnings, "%s", resp->warnings);
	snprintf(r->timing, sizeof r->timing, "%s", resp->server_timing);
	return farm_write_file(r->out, resp->body, resp->len, r->error, sizeof r->error) == 0 ? JOB_OK : JOB_FAILED;
}

/* The request's headers: its type, the format an explicit output name asks for, the affinity. */
static int request_headers(const struct farm *f, size_t i, const struct multipart *m, char *h, size_t size)
{
	const struct farm_job *j = &f->jobs[i];
	const struct job_result *r = &f->res[i];
	char accept[64] = "";
	enum api_format want;
	if (j->out) {
		if (!api_format_from_name(j->out, &want)) return -1;
		snprintf(accept, sizeof accept, "Accept: %s\r\n", api_format_mime(want));
	}
	if (m->boundary[0])
		snprintf(h, size, "Content-Type: multipart/form-data; boundary=%s\r\n%sX-Umbra-Affinity: %s\r\n"
		         "X-Priority: bulk\r\n", m->boundary, accept, r->hash);
	else
		snprintf(h, size, "Content-Type: application/json\r\n%sX-Umbra-Affinity: %s\r\nX-Priority: bulk\r\n", accept,
		         r->hash);
	return 0;
}

enum job_status farm_remote_job(struct farm *f, size_t i, const struct job_input *in)
{
	struct job_result *r = &f->res[i];
	unsigned seed = (unsigned)(farm_now_ms() * 1000) ^ (unsigned)(i * 2654435761u);
	struct multipart m = {0};
	if (in->nparts && multipart_build(&m, in, &seed, r->error, sizeof r->error) < 0) {
		multipart_release(&m);
		return JOB_INVALID;
	}
	char headers[512];
	if (request_headers(f, i, &m, headers, sizeof headers) < 0) {
		snprintf(r->error, sizeof r->error, "output '%s' must end in .png, .exr, .webp or .avif", f->jobs[i].out);
		multipart_release(&m);
		return JOB_INVALID;
	}
	/* A scene whose output name picks the format says so in its document (umbrad lets an
	 * explicit output.format win over Accept, where the local farm lets the name win). */
	enum api_format want;
	bool named = f->jobs[i].out && api_format_from_name(f->jobs[i].out, &want);
	size_t fixed_len = 0;
	char *fixed = named && !in->nparts ? api_scene_doc_set_format(in->doc, in->doc_len, want, &fixed_len) : NULL;
	struct srv_http_chunk json = {fixed ? fixed : in->doc, fixed ? fixed_len : in->doc_len};
	unsigned lost = 0, busy = 0;
	enum job_status st = JOB_FAILED;
	for (;;) {
		struct srv_http_response resp;
		struct srv_http_error he;
		r->attempts++;
		enum srv_http_result hr = srv_http_post(&f->url, "/v1/render", headers, m.chunks ? m.chunks : &json,
		                                        m.chunks ? m.nchunks : 1, TIMEOUT_S, &resp, &he);
		int code = hr == SRV_HTTP_OK ? resp.status : 0;
		bool is_lost = hr == SRV_HTTP_ERR_CONNECT || hr == SRV_HTTP_ERR_LOST || code == 502 || code == 504;
		bool is_busy = code == 503 || code == 429;
		if (code == 200) {
			st = take_image(f, i, &resp);
		} else if (hr != SRV_HTTP_OK && !is_lost) {
			snprintf(r->error, sizeof r->error, "%s", he.msg);
		} else if (code) {   /* the problem, as the local farm words one */
			struct api_problem p;
			api_problem_parse((const char *)resp.body, resp.len, code, &p);
			api_problem_format(&p, r->error, sizeof r->error);
			if (code >= 400 && code < 500 && !is_busy) st = JOB_INVALID;
		} else {
			snprintf(r->error, sizeof r->error, "%s", he.msg);
		}
		double wait = is_busy ? backoff_ms(resp.retry_after, busy) : backoff_ms(NULL, lost);
		srv_http_response_release(&resp);
		bool again = (is_lost && lost++ < LOST_RETRIES) || (is_busy && busy++ < BUSY_RETRIES);
		if (!again) break;
		if (!wait_retry(wait, &seed)) {
			size_t l = strlen(r->error);
			snprintf(r->error + l, sizeof r->error - l, " (interrupted before trying again)");
			st = JOB_SKIPPED;
			break;
		}
	}
	if (st == JOB_OK) r->error[0] = 0;
	else if (st == JOB_FAILED && (lost > LOST_RETRIES || busy > BUSY_RETRIES)) {
		size_t l = strlen(r->error);
		snprintf(r->error + l, sizeof r->error - l, " (after %u tries)", r->attempts);
	}
	multipart_release(&m);
	free(fixed);
	return st;
}
