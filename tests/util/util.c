/* tests/util/util.c — see util.h. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <string.h>

#include "api.h"
#include "util.h"

void test_b64_into(const void *data, size_t n, char *out)
{
	static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	const uint8_t *d = data;
	char *p = out;
	size_t i = 0;
	for (; i + 2 < n; i += 3) {
		uint32_t v = (uint32_t)d[i] << 16 | (uint32_t)d[i + 1] << 8 | d[i + 2];
		*p++ = tab[v >> 18]; *p++ = tab[(v >> 12) & 63]; *p++ = tab[(v >> 6) & 63]; *p++ = tab[v & 63];
	}
	if (i < n) {
		uint32_t v = (uint32_t)d[i] << 16 | (i + 1 < n ? (uint32_t)d[i + 1] << 8 : 0);
		*p++ = tab[v >> 18]; *p++ = tab[(v >> 12) & 63];
		*p++ = i + 1 < n ? tab[(v >> 6) & 63] : '=';
		*p++ = '=';
	}
	*p = 0;
}

char *test_b64(const void *data, size_t n)
{
	char *o = malloc(n / 3 * 4 + 8);
	if (o) test_b64_into(data, n, o);
	return o;
}

char *test_vdoc(const char *fmt, va_list ap)
{
	char *doc = NULL;
	if (vasprintf(&doc, fmt, ap) < 0) return NULL;
	for (char *p = doc; *p; p++) if (*p == '\'') *p = '"';
	return doc;
}

void test_put_file(const char *dir, const char *name, const char *text)
{
	char p[1024];
	snprintf(p, sizeof p, "%s/%s", dir, name);
	FILE *f = fopen(p, "wb");
	if (f) {
		fputs(text, f);
		fclose(f);
	}
}

char *test_model_doc(const uint8_t *d, size_t n, const char *format)
{
	char *enc = test_b64(d, n);
	size_t cap = (enc ? strlen(enc) : 0) + 256;
	char *doc = enc ? malloc(cap) : NULL;
	if (doc)
		snprintf(doc, cap, "{\"camera\":{\"position\":[0,0,30]},\"objects\":[{\"shape\":\"model\",\"format\":\"%s\","
		         "\"data\":\"%s\"}]}", format, enc);
	free(enc);
	return doc;
}

struct api_scene *test_parse_scene(const char *doc, struct api_problem *p)
{
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	return api_scene_parse(doc, strlen(doc), NULL, &s, p) == API_OK ? s : NULL;
}

struct api_scene *test_parse_model(const uint8_t *d, size_t n, const char *format, struct api_problem *p)
{
	char *doc = test_model_doc(d, n, format);
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	if (!doc || api_scene_parse(doc, strlen(doc), NULL, &s, p) != API_OK) s = NULL;
	free(doc);
	return s;
}

uint8_t *test_read_file(const char *path, size_t *len)
{
	FILE *f = fopen(path, "rb");
	if (!f) return NULL;
	fseek(f, 0, SEEK_END);
	long n = ftell(f);
	fseek(f, 0, SEEK_SET);
	uint8_t *b = n >= 0 ? malloc((size_t)n + 1) : NULL;
	if (b && fread(b, 1, (size_t)n, f) != (size_t)n) { free(b); b = NULL; }
	fclose(f);
	if (b) { b[n] = 0; *len = (size_t)n; }
	return b;
}

double test_now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

double test_median(double *t, int n)
{
	qsort(t, (size_t)n, sizeof *t, cmp_double);
	return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}
