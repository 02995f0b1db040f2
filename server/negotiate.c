/*
 * server/negotiate — Content-Type, Accept and ETag rules of the render routes (see negotiate.h).
 * Pure string work; the hash is the project's byte-stream hash, rnd_fnv1a() (umbra/rnd_math.h).
 */
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "negotiate.h"
#include "umbra/rnd_math.h"

#ifndef UMBRA_VERSION
#define UMBRA_VERSION "0.1.0"
#endif

bool srv_json_content_type(const char *ct)
{
	if (!ct)
		return false;
	while (*ct == ' ' || *ct == '\t')
		ct++;
	size_t n = strcspn(ct, "; \t");
	if (n == 16 && !strncasecmp(ct, "application/json", 16))
		return true;
	return n > 17 && !strncasecmp(ct, "application/", 12) && !strncasecmp(ct + n - 5, "+json", 5);
}

bool srv_multipart_content_type(const char *ct)
{
	if (!ct)
		return false;
	while (*ct == ' ' || *ct == '\t')
		ct++;
	return !strncasecmp(ct, "multipart/form-data", 19) && strchr("; \t", ct[19]);
}

enum srv_accept srv_accept_choice(const char *accept)
{
	if (!accept || !*accept)
		return SRV_ACCEPT_PNG;
	/* In the order a tie goes: PNG, then WebP, then AVIF, then EXR. */
	static const char *const types[] = {"image/png", "image/webp", "image/avif", "image/x-exr"};
	static const enum srv_accept choice[] = {SRV_ACCEPT_PNG, SRV_ACCEPT_WEBP, SRV_ACCEPT_AVIF, SRV_ACCEPT_EXR};
	enum { N = sizeof types / sizeof types[0] };
	double q_of[N], q_wild = -1;
	bool named[N] = {false};
	const char *p = accept;
	while (*p) {
		while (*p == ' ' || *p == ',')
			p++;
		if (!*p)
			break;
		size_t item = strcspn(p, ",");
		char buf[128];
		size_t n = item < sizeof buf - 1 ? item : sizeof buf - 1;
		memcpy(buf, p, n);
		buf[n] = 0;
		p += item;
		double q = 1;
		char *semi = strchr(buf, ';');
		if (semi) {
			*semi = 0;
			char *qs = strstr(semi + 1, "q=");
			if (qs)
				q = strtod(qs + 2, NULL);
		}
		char *end = buf + strlen(buf);
		while (end > buf && (end[-1] == ' ' || end[-1] == '\t'))
			*--end = 0;
		for (int k = 0; k < N; k++)
			if (!strcasecmp(buf, types[k])) {
				q_of[k] = q;
				named[k] = true;
			}
		if ((!strcasecmp(buf, "image/*") || !strcasecmp(buf, "*/*")) && q > q_wild)
			q_wild = q;
	}
	int best = -1;
	for (int k = 0; k < N; k++) {
		double q = named[k] ? q_of[k] : q_wild;
		if (q > 0 && (best < 0 || q > (named[best] ? q_of[best] : q_wild)))
			best = k;
	}
	return best < 0 ? SRV_ACCEPT_NONE : choice[best];
}

/* ---- ETag ---- */

uint64_t srv_etag_of(uint64_t scene_hash, uint64_t asset_hash, const char *format, const char *device_name,
                     const char *driver_info)
{
	/* The canonical scene (api/scene_hash.h: document after its preset, and the parts), the
	 * files it read under --asset-root, the negotiated format, the build and the device. */
	uint64_t h = rnd_fnv1a(RND_FNV_SEED, &scene_hash, sizeof scene_hash);
	h = rnd_fnv1a(h, &asset_hash, sizeof asset_hash);
	h = rnd_fnv1a(h, format, strlen(format) + 1);
	h = rnd_fnv1a(h, UMBRA_VERSION, strlen(UMBRA_VERSION) + 1);
	h = rnd_fnv1a(h, device_name, strlen(device_name) + 1);
	return rnd_fnv1a(h, driver_info, strlen(driver_info) + 1);
}

const char *srv_format_ext(const char *mime)
{
	const char *slash = strchr(mime, '/');
	const char *ext = slash ? slash + 1 : mime;
	return strncmp(ext, "x-", 2) ? ext : ext + 2;
}

void srv_result_name(char *out, size_t n, uint64_t hash, const char *mime)
{
	snprintf(out, n, "/v1/renders/%016llx.%s", (unsigned long long)hash, srv_format_ext(mime));
}

bool srv_result_path(const char *url, uint64_t *hash, char *ext, size_t extsize)
{
	static const char prefix[] = "/v1/renders/";
	if (strncmp(url, prefix, sizeof prefix - 1) != 0)
		return false;
	const char *h = url + sizeof prefix - 1, *dot = strchr(h, '.');
	if (!dot || dot - h != 16 || strspn(h, "0123456789abcdef") != 16)
		return false;
	size_t n = strlen(dot + 1);
	if (n == 0 || n >= extsize || strspn(dot + 1, "abcdefghijklmnopqrstuvwxyz") != n)
		return false;
	*hash = strtoull(h, NULL, 16);
	memcpy(ext, dot + 1, n + 1);
	return true;
}

void srv_etag_format(char *out, size_t n, uint64_t h)
{
	snprintf(out, n, "\"%016llx\"", (unsigned long long)h);
}

bool srv_etag_matches(const char *inm, const char *etag)
{
	if (!inm)
		return false;
	size_t el = strlen(etag);
	const char *p = inm;
	while (*p) {
		while (*p == ' ' || *p == ',' || *p == '\t')
			p++;
		if (!*p)
			break;
		/* "*" is not a match: a render always has a representation to make, and an
		 * unconditional 412 or 304 would hide it. */
		if (!strncmp(p, "W/", 2))
			p += 2;
		size_t n = strcspn(p, ", \t");
		if (n == el && !strncmp(p, etag, el))
			return true;
		p += n;
	}
	return false;
}
