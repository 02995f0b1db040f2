/*
 * umbrad logging (see log.h).
 */
#include "log.h"
#include "buf.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static enum srv_log_format log_format = SRV_LOG_TEXT;

static const char *const level_names[] = { "error", "warn", "info" };

void srv_log_init(enum srv_log_format format)
{
	log_format = format;
}

static void log_timestamp(char *buf, size_t size)
{
	struct timespec ts;
	struct tm tm;
	clock_gettime(CLOCK_REALTIME, &ts);
	gmtime_r(&ts.tv_sec, &tm);
	size_t n = strftime(buf, size, "%Y-%m-%dT%H:%M:%S", &tm);
	snprintf(buf + n, size - n, ".%03ldZ", ts.tv_nsec / 1000000);
}

/* Writes the whole line at once; a short write to stderr is not worth a retry loop. */
static void log_write(char *line, size_t len, size_t cap)
{
	if (len >= cap - 1)
		len = cap - 2;
	line[len++] = '\n';
	ssize_t w = write(STDERR_FILENO, line, len);
	(void)w;
}

void srv_log(enum srv_log_level level, const char *fmt, ...)
{
	char ts[40], msg[1024], line[2300];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	log_timestamp(ts, sizeof ts);
	int n;
	if (log_format == SRV_LOG_JSON) {
		char esc[2048];
		srv_json_escape(esc, sizeof esc, msg);
		n = snprintf(line, sizeof line, "{\"ts\":\"%s\",\"level\":\"%s\",\"msg\":\"%s\"}", ts,
		             level_names[level], esc);
	} else {
		/* One event, one line: a multi-line message (validation layer) is folded. */
		char *o = msg;
		for (const char *i = msg; *i; i++) {
			if (*i == '\n' || *i == '\r' || *i == '\t') {
				while (i[1] == ' ' || i[1] == '\t' || i[1] == '\n' || i[1] == '\r')
					i++;
				if (o > msg && o[-1] != ' ')
					*o++ = ' ';
			} else {
				*o++ = *i;
			}
		}
		*o = 0;
		n = snprintf(line, sizeof line, "%s %-5s %s", ts, level_names[level], msg);
	}
	if (n > 0)
		log_write(line, (size_t)n, sizeof line);
}

static enum srv_log_level access_level(int status)
{
	return status == 500 ? SRV_LOG_ERROR : status >= 500 ? SRV_LOG_WARN : SRV_LOG_INFO;
}

void srv_log_request(const struct srv_access *a)
{
	char ts[40], line[1700], epath[400], eid[200], emethod[40], eclient[80], edetail[520] = "", eptr[260] = "";
	log_timestamp(ts, sizeof ts);
	srv_json_escape(epath, sizeof epath, a->path);
	srv_json_escape(eid, sizeof eid, a->request_id);
	srv_json_escape(emethod, sizeof emethod, a->method);
	srv_json_escape(eclient, sizeof eclient, a->client && *a->client ? a->client : "-");
	const char *level = level_names[access_level(a->status)];
	bool problem = a->detail && *a->detail;
	if (problem) {
		srv_json_escape(edetail, sizeof edetail, a->detail);
		srv_json_escape(eptr, sizeof eptr, a->pointer ? a->pointer : "");
	}
	int n;
	if (log_format == SRV_LOG_JSON)
		n = snprintf(line, sizeof line,
		             "{\"ts\":\"%s\",\"level\":\"%s\",\"msg\":\"request\",\"method\":\"%s\","
		             "\"path\":\"%s\",\"route\":\"%s\",\"status\":%d,\"bytes\":%llu,\"ms\":%.3f,"
		             "\"request_id\":\"%s\",\"client\":\"%s\"%s%s%s%s%s}",
		             ts, level, emethod, epath, a->route, a->status, (unsigned long long)a->bytes, a->ms, eid,
		             eclient, problem ? ",\"pointer\":\"" : "", eptr, problem ? "\",\"detail\":\"" : "", edetail,
		             problem ? "\"" : "");
	else
		n = snprintf(line, sizeof line, "%s %-5s %s %s %d %lluB %.1fms route=%s id=%s client=%s%s%s%s%s%s", ts,
		             level, emethod, epath, a->status, (unsigned long long)a->bytes, a->ms, a->route, eid, eclient,
		             problem ? " pointer=" : "", problem ? (a->pointer && *a->pointer ? eptr : "\"\"") : "",
		             problem ? " detail=\"" : "", edetail, problem ? "\"" : "");
	if (n > 0)
		log_write(line, (size_t)n, sizeof line);
}
