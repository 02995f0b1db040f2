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
	double q_png = -1, q_exr = -1, q_webp = -1, q_wild = -1;
	bool spec_png = false, spec_exr = false, spec_webp = false;
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
		if (!strcasecmp(buf, "image/png")) {
			q_png = q;
			spec_png = true;
		} else if (!strcasecmp(buf, "image/x-exr")) {
			q_exr = q;
			spec_exr = true;
		} else if (!strcasecmp(buf, "image/webp")) {
			q_webp = q;
			spec_webp = true;
		} else if (!strcasecmp(buf, "image/*") || !strcasecmp(buf, "*/*")) {
			if (q > q_wild)
				q_wild = q;
		}
	}
	if (!spec_png)
		q_png = q_wild;
	if (!spec_exr)
		q_exr = q_wild;
	if (!spec_webp)
		q_webp = q_wild;
	if (q_png <= 0 && q_exr <= 0 && q_webp <= 0)
		return SRV_ACCEPT_NONE;
	if (q_png >= q_webp && q_png >= q_exr)
		return SRV_ACCEPT_PNG;
	return q_webp >= q_exr ? SRV_ACCEPT_WEBP : SRV_ACCEPT_EXR;
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
