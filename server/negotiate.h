/*
 * server/negotiate — the pure parts of HTTP negotiation for POST /v1/render: which Content-Types
 * a render takes, which image format an Accept header prefers, and the ETag (how it is built,
 * written and matched against If-None-Match). No libmicrohttpd, no I/O, no state: every
 * function is thread-safe and unit-tested (tests/unit/test_negotiate.c).
 *
 * Usage (server/render_route.c and server/worker.c):
 *   if (!srv_json_content_type(ct) && !srv_multipart_content_type(ct)) -> 415
 *   enum srv_accept a = srv_accept_choice(accept);          // SRV_ACCEPT_NONE -> 406
 *   uint64_t h = srv_etag_start();  h = srv_etag_body(h, chunk, n) per chunk;
 *   h = srv_etag_finish(h, a, device_name, driver_info);    // + the build's version
 *   h = srv_etag_assets(h, scene->asset_hash);              // when the scene read files
 *   srv_etag_format(req->etag, sizeof req->etag, h);        // "\"%016llx\""
 *   srv_etag_matches(if_none_match, req->etag)              // -> 304
 */
#ifndef UMBRA_SRV_NEGOTIATE_H
#define UMBRA_SRV_NEGOTIATE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* application/json (parameters such as charset allowed) or any application/...+json type. */
bool srv_json_content_type(const char *content_type);
/* multipart/form-data (with its parameters). */
bool srv_multipart_content_type(const char *content_type);

/* What an Accept header asks of a render: the format of highest q among PNG, EXR (image/x-exr)
 * and WebP (image/webp); PNG without the header, and on a tie PNG, then WebP, then EXR; or none
 * (every candidate at q = 0 or not named, no wildcard): a 406. Wildcards count with their q for
 * each format not named. */
enum srv_accept { SRV_ACCEPT_PNG, SRV_ACCEPT_EXR, SRV_ACCEPT_NONE, SRV_ACCEPT_WEBP };
enum srv_accept srv_accept_choice(const char *accept);

/* The ETag of a render: the raw body (in chunks), the negotiated format, the build
 * (UMBRA_VERSION) and the device, then the asset files a scene read (when it read any). */
uint64_t srv_etag_start(void);
uint64_t srv_etag_body(uint64_t h, const void *data, size_t len);
uint64_t srv_etag_finish(uint64_t h, enum srv_accept format, const char *device_name, const char *driver_info);
uint64_t srv_etag_assets(uint64_t h, uint64_t asset_hash);
/* Writes the strong ETag header value ("0123456789abcdef", quotes included); n >= 19. */
void srv_etag_format(char *out, size_t n, uint64_t h);
/* True when an If-None-Match value lists etag (strong comparison; "*" never matches). */
bool srv_etag_matches(const char *if_none_match, const char *etag);

#endif
