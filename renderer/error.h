/* renderer/error.h — filling a caller's struct rnd_error (defined in device.c). No Vulkan. */
#ifndef UMBRA_RENDERER_ERROR_H
#define UMBRA_RENDERER_ERROR_H

#include "umbra/rnd.h"

/* Sets err (if not NULL) to code and the printf-style message; returns code. */
enum rnd_result rnd_fail(struct rnd_error *err, enum rnd_result code, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));
/* rnd_fail() that also says which part of the scene is at fault (err->at, err->at_index). */
enum rnd_result rnd_fail_at(struct rnd_error *err, enum rnd_result code, enum rnd_error_at at, uint32_t index,
                            const char *fmt, ...) __attribute__((format(printf, 5, 6)));

#endif
