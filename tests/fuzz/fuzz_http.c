/*
 * tests/fuzz/fuzz_http.c — libFuzzer target for the daemon's request handling: the real
 * server/http.c (routes, headers, Content-Length, body reading, multipart/form-data through
 * libmicrohttpd's MHD_PostProcessor and http.c's part collection, ETag, If-None-Match, the
 * queue hand-off, suspend/resume, the answer) on a real libmicrohttpd daemon.
 *
 * Each input is the raw bytes a client sends on one connection (request line, headers, body,
 * possibly several pipelined requests). The daemon is started once with srv_http_start() as
 * umbrad starts it, listening on 127.0.0.1:0 but never connected to: each input gets a fresh
 * socketpair handed to the daemon with MHD_add_connection() (no TCP, so a million inputs use no
 * ephemeral ports on a shared machine), is written to it, the write side is shut, and the
 * answer is read until the daemon closes. A stub worker thread stands in for
 * server/worker.c: it takes each queued request off the real queue (server/queue.c), checks
 * what http.c handed over (a NUL-terminated scene body, named parts), and answers 200 without
 * parsing or rendering (POST /v1/renders: stores a fake image and answers 303, as worker.c
 * does). The result cache (server/results.c) is real and holds, from the start, an image under
 * 0123456789abcdef.png and only a scene under 00000000000000aa.png, so that GET and HEAD
 * /v1/renders/{hash} reach the 200, 304 and render-again paths. No change to server/http.c is
 * needed for this.
 *
 * Everything linked is umbrad's own code: server/main.c comes in with main() renamed (see the
 * Makefile) for srv_now(), and server/log.c writes the access log to stderr, which
 * tests/fuzz/fuzz_http.options discards with -close_fd_mask=2 (libFuzzer keeps its own output
 * and sanitizer reports on a copy of stderr; drop the flag to see the daemon's log lines).
 * With a socketpair instead of TCP, libmicrohttpd logs that TCP_NODELAY/TCP_CORK failed:
 * expected, harmless.
 *
 * What counts as a failure: a sanitizer report, a hang (libFuzzer's -timeout), a request
 * still pending after its connection closed (a leak of the request), or a queued request that
 * breaks the hand-off contract (abort).
 *
 *   make fuzz && build/fuzz/fuzz_http -dict=tests/fuzz/fuzz_http.dict $(cat tests/fuzz/fuzz_http.options) \
 *       build/fuzz/corpus/fuzz_http tests/fuzz/corpus/fuzz_http
 */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <microhttpd.h>
#include <poll.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <linux/sockios.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "log.h"
#include "metrics.h"
#include "negotiate.h"
#include "queue.h"
#include "results.h"
#include "srv.h"
#include "umbra/rnd_math.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(c) do { if (!(c)) abort(); } while (0)

static struct srv_server srv;
static pthread_t worker;

/* ---- the stub worker ---- */

/* Checks the hand-off contract of srv.h and answers like a worker would, without rendering. */
static void *worker_main(void *arg)
{
	(void)arg;
	struct srv_request *req;
	while ((req = srv_queue_pop(srv.queue)) != NULL) {
		CHECK(req->state == SRV_REQ_QUEUED && (req->route == SRV_ROUTE_RENDER || req->route == SRV_ROUTE_RENDERS ||
		                                       req->route == SRV_ROUTE_RESULT || req->route == SRV_ROUTE_EXPLAIN));
		CHECK(req->body && req->body_len > 0 && req->body_len < req->body_cap && !req->body[req->body_len]);
		CHECK(req->body_len <= srv.cfg.max_body);
		for (size_t i = 0; i < req->part_count; i++) {
			const struct srv_part *p = &req->parts[i];
			CHECK(p->name && strcmp(p->name, "scene") != 0);
			CHECK(p->data && p->len < p->cap && !p->data[p->len]);
			for (size_t j = 0; j < i; j++) CHECK(strcmp(p->name, req->parts[j].name) != 0);
		}
		if (req->route == SRV_ROUTE_RENDERS) {
			/* What worker.c does after a render: store the image (and the scene), 303. */
			uint64_t h = rnd_fnv1a(RND_FNV_SEED, req->body, req->body_len);
			srv_scene_keep(&req->kept, req);
			CHECK(srv_results_put(srv.results, h, "png", &(struct srv_result_image){ (uint8_t *)"png", 3, "image/png", "w" },
			                      &req->kept));
			srv_request_drop_body(req);
			srv_result_name(req->location, sizeof req->location, h, "image/png");
			srv_etag_format(req->etag, sizeof req->etag, h);
			req->status = 303;
			srv_request_finish(req);
			continue;
		}
		srv_request_drop_body(req);
		static const char ok[] = "{\"fuzz\":true}";
		req->out = malloc(sizeof ok - 1);
		CHECK(req->out);
		memcpy(req->out, ok, sizeof ok - 1);
		req->out_len = sizeof ok - 1;
		req->content_type = "application/json";
		req->status = 200;
		srv_request_finish(req);
	}
	return NULL;
}

/* umbrad's start-up (server/main.c) minus the renderer: ready at once. Small limits so that
 * fuzz inputs reach the over-limit paths (413) and a full queue (503). */
static void start_once(void)
{
	static int started;
	if (started) return;
	started = 1;
	srv.cfg.listen = "127.0.0.1:0";
	srv.cfg.queue = 2;
	srv.cfg.max_body = 16 << 10;
	srv.cfg.max_connections = 64;
	srv.cfg.idle_timeout_s = 30;
	/* One allowed cross-origin caller, so that Origin headers reach the CORS answers and the
	 * deferred 403s (server/origin_http.c); the Host rule is the loopback default. */
	srv.cfg.cors_origin = "http://a.example";
	api_limits_defaults(&srv.cfg.limits);
	pthread_rwlock_init(&srv.ctx_lock, NULL);
	snprintf(srv.info.device_name, sizeof srv.info.device_name, "fuzz");
	srv.id_seed = 1;
	srv.metrics = srv_metrics_create();
	srv.queue = srv_queue_create(srv.cfg.queue);
	srv.results = srv_results_create(1 << 20);
	CHECK(srv.metrics && srv.queue && srv.results);
	/* A scene whose image is gone: stored with a 600 KB image that the next one pushes out of
	 * the 1 MB cache, while the scene stays (the scenes' bound is its own). */
	struct srv_request fake = { 0 };
	struct srv_kept_scene kept = { 0 };
	fake.body = strdup("{\"objects\": []}");
	fake.body_len = strlen(fake.body);
	CHECK(fake.body && srv_scene_keep(&kept, &fake));
	static uint8_t big[600 << 10];
	CHECK(srv_results_put(srv.results, 0xaa, "png", &(struct srv_result_image){ big, sizeof big, "image/png", NULL }, &kept));
	CHECK(srv_results_put(srv.results, 0xbb, "png", &(struct srv_result_image){ big, sizeof big, "image/png", NULL }, NULL));
	CHECK(srv_results_get(srv.results, 0xaa, "png", NULL, NULL) == SRV_RESULT_SCENE);
	CHECK(srv_results_put(srv.results, 0x0123456789abcdefull, "png",
	                      &(struct srv_result_image){ (uint8_t *)"png", 3, "image/png", NULL }, NULL));
	atomic_store(&srv.ready, true);
	CHECK(srv_http_start(&srv) == 0);
	CHECK(pthread_create(&worker, NULL, worker_main, NULL) == 0);
}

/* Writes the input and reads the answer until the daemon closes the connection. */
static void converse(int fd, const uint8_t *data, size_t size)
{
	size_t off = 0;
	bool shut = false;
	char buf[16384];
	for (;;) {
		/* Half-close only once the daemon has read every byte: libmicrohttpd 0.9.75 in
		 * epoll mode misses a FIN that arrives together with the last data of an incomplete
		 * request and keeps such a connection until the idle timeout (umbrad does the same
		 * with a real client; the timeout bounds it). */
		int unread = 0;
		if (off == size && !shut && ioctl(fd, SIOCOUTQ, &unread) == 0 && unread == 0) {
			shutdown(fd, SHUT_WR);
			shut = true;
		}
		struct pollfd pfd = { fd, (short)(POLLIN | (off < size ? POLLOUT : 0)), 0 };
		/* No time limit of our own: a connection that never closes is a hang, which
		 * libFuzzer's -timeout reports with this input. Until the half-close, wake up
		 * every 50 us to look at the daemon's progress. */
		struct timespec tick = { 0, 50 * 1000 };
		if (ppoll(&pfd, 1, shut || off < size ? NULL : &tick, NULL) < 0) {
			CHECK(errno == EINTR);
			continue;
		}
		if (pfd.revents & (POLLIN | POLLHUP | POLLERR)) {
			ssize_t n = recv(fd, buf, sizeof buf, 0);
			if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR))
				return;   /* closed (or reset) by the daemon */
		}
		if (off < size && (pfd.revents & POLLOUT)) {
			ssize_t n = send(fd, data + off, size - off, MSG_NOSIGNAL);
			if (n > 0)
				off += (size_t)n;
			else if (n < 0 && errno != EAGAIN && errno != EINTR)
				off = size;   /* the daemon stopped reading (e.g. after a 413): just read */
		}
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	start_once();
	int sv[2];
	CHECK(socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) == 0);
	CHECK(fcntl(sv[0], F_SETFL, O_NONBLOCK) == 0);
	/* The daemon sees a loopback TCP peer (as umbrad's clients are); it owns sv[1] from here. */
	struct sockaddr_in peer = { .sin_family = AF_INET, .sin_port = htons(40000) };
	peer.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	CHECK(MHD_add_connection(srv.daemon, sv[1], (struct sockaddr *)&peer, sizeof peer) == MHD_YES);
	converse(sv[0], data, size);
	close(sv[0]);
	/* The completion callback ends every request of the connection; wait for it so each input
	 * stands alone (and a request never completed shows up as a hang). */
	while (atomic_load(&srv.pending) > 0) {
		struct timespec ts = { 0, 20 * 1000 };
		nanosleep(&ts, NULL);
	}
	return 0;
}
