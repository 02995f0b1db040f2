/*
 * umbrad logging — one line per event on stderr, as text or as JSON (--log-format).
 *
 * Every line goes out with one write(2), so lines from several threads never interleave.
 * srv_log_request() is the access log: method, path, route, status, bytes, ms, request id, and
 * for problem answers the problem's detail and JSON Pointer.
 */
#ifndef UMBRA_SRV_LOG_H
#define UMBRA_SRV_LOG_H

#include <stdint.h>
#include "srv.h"

enum srv_log_level { SRV_LOG_ERROR, SRV_LOG_WARN, SRV_LOG_INFO };

void srv_log_init(enum srv_log_format format);
void srv_log(enum srv_log_level level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* detail / pointer: the problem of a 4xx/5xx answer (NULL or "" = none), so an operator sees
 * why requests fail. */
void srv_log_request(const char *method, const char *path, const char *route, int status,
                     uint64_t bytes, double ms, const char *request_id, const char *detail,
                     const char *pointer);

#endif
