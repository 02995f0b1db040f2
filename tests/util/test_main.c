/* tests — runner for the TEST() harness (see test.h). */
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "test.h"

#define MAX_TESTS 1024
static struct { const char *name; test_fn fn; } tests[MAX_TESTS];
static int ntests, cur_failed;

void test_register(const char *name, test_fn fn)
{
	if (ntests < MAX_TESTS) { tests[ntests].name = name; tests[ntests].fn = fn; ntests++; }
}

void test_fail_at(const char *file, int line, const char *cond, const char *fmt, ...)
{
	va_list ap;
	fprintf(stdout, "  %s:%d: %s", file, line, cond);
	va_start(ap, fmt);
	vfprintf(stdout, fmt, ap);
	va_end(ap);
	fputc('\n', stdout);
	cur_failed++;
}

static int by_name(const void *a, const void *b)
{
	return strcmp(*(const char *const *)a, *(const char *const *)b);
}

int main(int argc, char **argv)
{
	const char *filter = argc > 1 ? argv[1] : NULL;
	int passed = 0, failed = 0;
	/* Constructors run in link order; sort so the output is stable. */
	qsort(tests, (size_t)ntests, sizeof tests[0], by_name);
	for (int i = 0; i < ntests; i++) {
		if (filter && !strstr(tests[i].name, filter)) continue;
		struct timespec t0, t1;
		clock_gettime(CLOCK_MONOTONIC, &t0);
		cur_failed = 0;
		tests[i].fn();
		clock_gettime(CLOCK_MONOTONIC, &t1);
		double ms = (t1.tv_sec - t0.tv_sec) * 1e3 + (t1.tv_nsec - t0.tv_nsec) / 1e6;
		if (cur_failed) { failed++; printf("FAIL - %s (%.0f ms)\n", tests[i].name, ms); }
		else { passed++; printf("ok - %s (%.0f ms)\n", tests[i].name, ms); }
		fflush(stdout);
	}
	printf("%d passed, %d failed\n", passed, failed);
	return failed ? 1 : 0;
}
