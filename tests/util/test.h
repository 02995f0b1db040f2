/*
 * tests — a tiny test harness shared by the unit and GPU test binaries.
 *
 *   TEST(parses_sphere) { CHECK(x == 1, "x is %d", x); }
 *
 * TEST registers the function at load time (constructor). The runner (tests/util/test_main.c)
 * runs every test, or those whose name contains argv[1], prints "ok - name" or
 * "FAIL - name" with each failed CHECK's file:line and message, and ends with the line
 * "N passed, N failed". A test fails when any CHECK in it fails; CHECK does not return.
 * REQUIRE is a CHECK that returns from the test on failure.
 */
#ifndef UMBRA_TEST_H
#define UMBRA_TEST_H

#include <stdio.h>

typedef void (*test_fn)(void);
void test_register(const char *name, test_fn fn);
void test_fail_at(const char *file, int line, const char *cond, const char *fmt, ...) __attribute__((format(printf, 4, 5)));

#define TEST(name)                                                                  \
	static void name(void);                                                     \
	__attribute__((constructor)) static void test_reg_##name(void) { test_register(#name, name); } \
	static void name(void)

#define CHECK(cond, ...)                                                            \
	do { if (!(cond)) test_fail_at(__FILE__, __LINE__, "CHECK(" #cond ")", " " __VA_ARGS__); } while (0)
#define REQUIRE(cond, ...)                                                          \
	do { if (!(cond)) { test_fail_at(__FILE__, __LINE__, "REQUIRE(" #cond ")", " " __VA_ARGS__); return; } } while (0)

#endif
