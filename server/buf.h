/*
 * umbrad growable text buffer (git's strbuf, smaller) for the metrics exposition, and the
 * JSON string escaper of the logs and the CLI report.
 *
 * Zero-initialised = empty. An allocation failure sets `failed` and later appends do nothing,
 * so callers check once at the end. srv_buf_detach() hands the malloc'd, NUL-terminated text
 * to the caller (you now own it; free()) and leaves the buffer empty.
 */
#ifndef UMBRA_SRV_BUF_H
#define UMBRA_SRV_BUF_H

#include <stdbool.h>
#include <stddef.h>

struct srv_buf {
	char *data;
	size_t len, cap;
	bool failed;
};

void srv_buf_printf(struct srv_buf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void srv_buf_puts(struct srv_buf *b, const char *s);
char *srv_buf_detach(struct srv_buf *b, size_t *len);  /* NULL if an append failed */
void srv_buf_release(struct srv_buf *b);

/* Writes src escaped for a JSON string (without the quotes) into dst, truncated to fit size
 * (a whole escape or nothing): quote, backslash, control characters and DEL as \u00XX. */
void srv_json_escape(char *dst, size_t size, const char *src);

#endif
