/*
 * tests/unit/parse_util — helpers the scene parser tests (tests/unit/test_parse*.c) share:
 * documents written with ' for " (q), parsing them (parse, PARSE_OK), checking a bad one's
 * problem (check_bad: status, pointer, a phrase of its detail), and small comparisons.
 */
#ifndef UMBRA_TESTS_PARSE_UTIL_H
#define UMBRA_TESTS_PARSE_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include "api.h"

#define DEG (3.14159265358979323846 / 180.0)
#define C "'camera':{'position':[0,0,5]}"
#define BASE "{" C ",'objects':[]"

/* |a - b| within 1e-5 relative; the distance of a from b. */
bool near_f(float a, float b);
double dist3(const float a[3], const double b[3]);
/* Documents are written with ' for " to stay readable; a static ring of four buffers. */
const char *q(const char *s);
/* The scene of doc (NULL and *p on a problem). */
struct api_scene *parse(const char *doc, struct api_problem *p);
/* Parses a document (in ' quotes) that must be valid; reports the problem at file:line otherwise. */
struct api_scene *parse_ok(const char *doc_q, const char *file, int line);
#define PARSE_OK(doc) parse_ok(doc, __FILE__, __LINE__)

/* A document that must fail: its status, JSON pointer and a phrase of the detail. */
struct bad {
	const char *doc;
	int status;
	const char *pointer;
	const char *phrase;
};

/* Checks that b's document fails under lim (NULL: the defaults) as it says; idx names it. */
void check_bad(const struct bad *b, const struct api_limits *lim, int idx);

#endif
