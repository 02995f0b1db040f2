/*
 * http_bench — a small HTTP/1.1 load client for umbrad (POST /v1/render over loopback).
 *
 *   http_bench [-c 1,2,4,8] [-n REQUESTS] [-t SECONDS] [-p interactive|bulk] URL SCENE.json...
 *
 * For each scene and each concurrency C: W warm-up requests (-w, default 1), then C threads, each with its own
 * keep-alive connection, send the scene until REQUESTS (default 16, at least 2*C) have been
 * sent or SECONDS (default 15) have passed. Prints one row per (scene, C): requests, errors
 * (any status but 200), images/s (200 answers per wall second) and latency p50/p90/p99 in ms.
 * No dependencies beyond libc and pthreads: cc -O2 -pthread -o http_bench http_bench.c
 */
#include <arpa/inet.h>
#include <errno.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

struct target {
	char host[256], port[16];
};

struct run {
	const struct target *tgt;
	const char *request;       /* headers + body */
	size_t request_len;
	int total;                 /* requests to send */
	double stop_at;            /* no new request after this (monotonic seconds) */
	atomic_int next;           /* requests taken */
	double *lat_ms;            /* per request, < 0 = error */
	atomic_int errors;
	atomic_uint_fast64_t bytes;
};

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int connect_to(const struct target *t)
{
	struct addrinfo hints = { .ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM }, *ai;
	if (getaddrinfo(t->host, t->port, &hints, &ai) != 0)
		return -1;
	int fd = socket(ai->ai_family, SOCK_STREAM, 0);
	if (fd >= 0 && connect(fd, ai->ai_addr, ai->ai_addrlen) != 0) {
		close(fd);
		fd = -1;
	}
	freeaddrinfo(ai);
	if (fd >= 0) {
		int one = 1;
		setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
	}
	return fd;
}

static int write_all(int fd, const char *p, size_t n)
{
	while (n) {
		ssize_t w = send(fd, p, n, MSG_NOSIGNAL);
		if (w < 0 && errno == EINTR)
			continue;
		if (w <= 0)
			return -1;
		p += w;
		n -= (size_t)w;
	}
	return 0;
}

/* Sends one request and reads the answer. Returns the status, or -1 when the connection
 * failed; *keep is false when the server closes the connection. */
static int exchange(int fd, const struct run *r, size_t *body_len, bool *keep)
{
	static __thread char buf[1 << 16];
	if (write_all(fd, r->request, r->request_len) != 0)
		return -1;
	size_t have = 0;
	char *end = NULL;
	while (!end) {
		if (have == sizeof buf - 1)
			return -1;
		ssize_t n = recv(fd, buf + have, sizeof buf - 1 - have, 0);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			return -1;
		have += (size_t)n;
		buf[have] = 0;
		end = strstr(buf, "\r\n\r\n");
		/* skip a "100 Continue" interim answer */
		if (end && !strncmp(buf, "HTTP/1.1 100", 12)) {
			size_t skip = (size_t)(end + 4 - buf);
			memmove(buf, buf + skip, have - skip);
			have -= skip;
			buf[have] = 0;
			end = strstr(buf, "\r\n\r\n");
		}
	}
	int status = atoi(buf + 9);
	size_t hdr_len = (size_t)(end + 4 - buf);
	size_t clen = 0;
	*keep = true;
	for (char *line = strstr(buf, "\r\n") + 2; line < end; line = strstr(line, "\r\n") + 2) {
		if (!strncasecmp(line, "Content-Length:", 15))
			clen = strtoull(line + 15, NULL, 10);
		else if (!strncasecmp(line, "Connection:", 11) && strcasestr(line, "close") &&
		         strcasestr(line, "close") < strstr(line, "\r\n"))
			*keep = false;
	}
	size_t got = have - hdr_len;
	while (got < clen) {
		ssize_t n = recv(fd, buf, sizeof buf, 0);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			return -1;
		got += (size_t)n;
	}
	*body_len = clen;
	return status;
}

static void *worker(void *arg)
{
	struct run *r = arg;
	int fd = -1;
	for (;;) {
		if (now() > r->stop_at)
			break;
		int i = atomic_fetch_add(&r->next, 1);
		if (i >= r->total)
			break;
		double t0 = now();
		int status = -1;
		size_t len = 0;
		bool keep = false;
		for (int attempt = 0; attempt < 2 && status < 0; attempt++) {
			if (fd < 0)
				fd = connect_to(r->tgt);
			if (fd < 0)
				break;
			status = exchange(fd, r, &len, &keep);
			if (status < 0 || !keep) {
				close(fd);
				fd = -1;
			}
		}
		double ms = (now() - t0) * 1000.0;
		if (status == 200) {
			r->lat_ms[i] = ms;
			atomic_fetch_add(&r->bytes, len);
		} else {
			r->lat_ms[i] = -1;
			atomic_fetch_add(&r->errors, 1);
			if (status > 0 && atomic_load(&r->errors) == 1)
				fprintf(stderr, "http_bench: status %d\n", status);
		}
	}
	if (fd >= 0)
		close(fd);
	return NULL;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

static double pct(const double *v, int n, double q)
{
	if (n == 0)
		return 0;
	int i = (int)(q * n + 0.999999) - 1;
	return v[i < 0 ? 0 : i >= n ? n - 1 : i];
}

static char *read_file(const char *path, size_t *len)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	fseek(f, 0, SEEK_END);
	long n = ftell(f);
	fseek(f, 0, SEEK_SET);
	char *p = n >= 0 ? malloc((size_t)n + 1) : NULL;
	if (p && fread(p, 1, (size_t)n, f) != (size_t)n) {
		free(p);
		p = NULL;
	}
	fclose(f);
	if (p)
		*len = (size_t)n;
	return p;
}

static void usage(void)
{
	fprintf(stderr, "usage: http_bench [-c 1,2,4,8] [-n REQUESTS] [-t SECONDS] [-w WARMUP] [-p interactive|bulk] "
	                "http://HOST:PORT SCENE.json...\n");
	exit(2);
}

int main(int argc, char **argv)
{
	const char *conc_list = "1,2,4,8", *prio = "interactive";
	int requests = 16, warmup = 1;
	double seconds = 15;
	int opt;
	while ((opt = getopt(argc, argv, "c:n:t:w:p:h")) != -1) {
		switch (opt) {
		case 'c': conc_list = optarg; break;
		case 'n': requests = atoi(optarg); break;
		case 't': seconds = atof(optarg); break;
		case 'w': warmup = atoi(optarg); break;
		case 'p': prio = optarg; break;
		default: usage();
		}
	}
	if (argc - optind < 2 || requests < 1 || warmup < 1)
		usage();
	struct target tgt = { 0 };
	const char *url = argv[optind];
	if (strncmp(url, "http://", 7) != 0 || sscanf(url + 7, "%255[^:/]:%15[0-9]", tgt.host, tgt.port) != 2) {
		fprintf(stderr, "http_bench: '%s' is not http://HOST:PORT\n", url);
		return 2;
	}
	printf("%-22s %5s %5s %5s %9s %9s %9s %9s %10s\n", "scene", "conc", "n", "err", "images/s", "p50 ms",
	       "p90 ms", "p99 ms", "KiB/image");
	int rc = 0;
	for (int si = optind + 1; si < argc; si++) {
		size_t blen;
		char *body = read_file(argv[si], &blen);
		if (!body) {
			fprintf(stderr, "http_bench: cannot read '%s'\n", argv[si]);
			rc = 1;
			continue;
		}
		char head[512];
		int hl = snprintf(head, sizeof head,
		                  "POST /v1/render HTTP/1.1\r\nHost: %s:%s\r\nContent-Type: application/json\r\n"
		                  "X-Priority: %s\r\nContent-Length: %zu\r\n\r\n", tgt.host, tgt.port, prio, blen);
		char *req = malloc((size_t)hl + blen);
		memcpy(req, head, (size_t)hl);
		memcpy(req + hl, body, blen);
		free(body);
		const char *name = strrchr(argv[si], '/') ? strrchr(argv[si], '/') + 1 : argv[si];

		/* Warm-up: first-use work in the renderer, the model cache, a fresh daemon's first pages
		 * (its first few hundred thumbnails ran ~3 % slower). */
		struct run warm = { .tgt = &tgt, .request = req, .request_len = (size_t)hl + blen, .total = warmup,
		                    .stop_at = now() + 600 };
		double *wl = calloc((size_t)warmup, sizeof *wl);
		if (!wl) { free(req); return 1; }
		warm.lat_ms = wl;
		worker(&warm);
		free(wl);
		if (atomic_load(&warm.errors)) {
			fprintf(stderr, "http_bench: %s: warm-up request failed\n", name);
			rc = 1;
			free(req);
			continue;
		}

		char list[64];
		snprintf(list, sizeof list, "%s", conc_list);
		for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
			int c = atoi(tok);
			if (c < 1)
				continue;
			int total = requests > 2 * c ? requests : 2 * c;
			struct run r = { .tgt = &tgt, .request = req, .request_len = (size_t)hl + blen, .total = total };
			r.lat_ms = calloc((size_t)total, sizeof *r.lat_ms);
			for (int i = 0; i < total; i++)
				r.lat_ms[i] = -2; /* not sent */
			pthread_t th[256];
			if (c > 256)
				c = 256;
			double t0 = now();
			r.stop_at = t0 + seconds;
			for (int i = 0; i < c; i++)
				pthread_create(&th[i], NULL, worker, &r);
			for (int i = 0; i < c; i++)
				pthread_join(th[i], NULL);
			double wall = now() - t0;
			int n = 0, sent = 0;
			for (int i = 0; i < total; i++) {
				if (r.lat_ms[i] != -2)
					sent++;
				if (r.lat_ms[i] >= 0)
					r.lat_ms[n++] = r.lat_ms[i];
			}
			qsort(r.lat_ms, (size_t)n, sizeof *r.lat_ms, cmp_double);
			printf("%-22s %5d %5d %5d %9.2f %9.1f %9.1f %9.1f %10.1f\n", name, c, sent, atomic_load(&r.errors),
			       n / wall, pct(r.lat_ms, n, 0.50), pct(r.lat_ms, n, 0.90), pct(r.lat_ms, n, 0.99),
			       n ? (double)atomic_load(&r.bytes) / n / 1024.0 : 0.0);
			fflush(stdout);
			if (atomic_load(&r.errors))
				rc = 1;
			free(r.lat_ms);
		}
		free(req);
	}
	return rc;
}
