/*
 * umbrad logging — one line per event on stderr, as text or as JSON (--log-format).
 *
 * Every line goes out with one write(2), so lines from several threads never interleave.
 * srv_log_request() is the access log: method, path, route, status, bytes, ms, request id, the
 * client's address, and for problem answers the problem's detail and JSON Pointer; at level
 * info, warn for a 5xx other than 500 (503 queue full, 504 deadline), error for a 500.
 */
#ifndef UMBRA_SRV_LOG_H
#define UMBRA_SRV_LOG_H

#include <stdint.h>
#include "srv.h"

enum srv_log_level { SRV_LOG_ERROR, SRV_LOG_WARN, SRV_LOG_INFO };

void srv_log_init(enum srv_log_format format);
void srv_log(enum srv_log_level level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* One answered request. detail / pointer: the problem of a 4xx/5xx answer (NULL or "" = none),
 * so an operator sees why requests fail; client: the peer's address ("" = unknown). */
struct srv_access {
	const char *method, *path, *route, *request_id, *client, *detail, *pointer;
	int status;
	uint64_t bytes;
	double ms;
};
void srv_log_request(const struct srv_access *a);

#endif
