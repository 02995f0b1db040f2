/*
 * tests/util/util.h — helpers shared by the unit and GPU test binaries (tests/util/util.c),
 * instead of a copy in each test file. Plain C, no GPU; every result is malloc'd and the
 * caller frees it.
 */
#ifndef UMBRA_TEST_UTIL_H
#define UMBRA_TEST_UTIL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

/* Standard base64 (with padding) of d[0..n), NUL-terminated: malloc'd, or into out (which
 * holds 4 * ceil(n / 3) + 1 bytes). */
char *test_b64(const void *d, size_t n);
void test_b64_into(const void *d, size_t n, char *out);
/* Writes text to dir/name (created or truncated); a file that cannot be written is left as
 * it is (the test's own checks then fail on what it reads). */
void test_put_file(const char *dir, const char *name, const char *text);
/* A whole file, malloc'd with a NUL after it (*len without it); NULL when it cannot be read. */
uint8_t *test_read_file(const char *path, size_t *len);
/* A scene document from a printf format in which ' stands for " (so that tests can write
 * "{'width': %d}"). NULL when out of memory. */
char *test_vdoc(const char *fmt, va_list ap);

/* A scene of one model object: the file d[0..n) inline as `data`, of `format` ("glb", ...),
 * seen by a camera at (0, 0, 30). NULL when out of memory. */
char *test_model_doc(const uint8_t *d, size_t n, const char *format);
/* That scene parsed (api_scene_parse, default limits): the scene, or NULL with *p its
 * problem. p: a struct api_problem (api.h). */
struct api_scene;
struct api_problem;
struct api_scene *test_parse_model(const uint8_t *d, size_t n, const char *format, struct api_problem *p);
/* A scene document parsed (api_scene_parse, default limits): the scene, or NULL with *p its
 * problem (*p zeroed first). */
struct api_scene *test_parse_scene(const char *doc, struct api_problem *p);

/* The monotonic clock in ms (the benchmarks' timer). */
double test_now_ms(void);
/* The median of t[0..n) (n > 0; t is sorted in place). */
double test_median(double *t, int n);

#endif
