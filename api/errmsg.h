/*
 * api/errmsg.h — filling a caller's error sentence buffer (char *err, size_t errsize), as the
 * model and import functions report failures. Header-only; thread-safe.
 */
#ifndef UMBRA_API_ERRMSG_H
#define UMBRA_API_ERRMSG_H

#include <stdarg.h>
#include <stdio.h>
#include "api.h"

/* printf into err (NULL or size 0: nothing); returns API_ERR. */
static inline enum api_result api_err_set(char *err, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static inline enum api_result api_err_set(char *err, size_t n, const char *fmt, ...)
{
	if (err && n) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(err, n, fmt, ap);
		va_end(ap);
	}
	return API_ERR;
}

#endif
