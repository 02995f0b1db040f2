/*
 * server/negotiate — the pure parts of HTTP negotiation for POST /v1/render: which Content-Types
 * a render takes, which image format an Accept header prefers, and the ETag (how it is built,
 * written and matched against If-None-Match). No libmicrohttpd, no I/O, no state: every
 * function is thread-safe and unit-tested (tests/unit/test_negotiate.c).
 *
 * Usage (server/render_route.c and server/worker.c):
 *   if (!srv_json_content_type(ct) && !srv_multipart_content_type(ct)) -> 415
 *   enum srv_accept a = srv_accept_choice(accept);          // SRV_ACCEPT_NONE -> 406
 *   // after parsing (the ETag depends on the parsed scene, never on the body's bytes):
 *   uint64_t h = srv_etag_of(sc->scene_hash, sc->asset_hash, api_format_mime(sc->format),
 *                            device_name, driver_info);     // + the build's version
 *   srv_etag_format(req->etag, sizeof req->etag, h);        // "\"%016llx\""
 *   srv_etag_matches(if_none_match, req->etag)              // POST -> 412, GET -> 304
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

/* What an Accept header asks of a render: the format of highest q among PNG, EXR (image/x-exr),
 * WebP (image/webp) and AVIF (image/avif); PNG without the header, and on a tie PNG, then WebP,
 * then AVIF, then EXR; or none (every candidate at q = 0 or not named, no wildcard): a 406.
 * Wildcards count with their q for each format not named. */
enum srv_accept { SRV_ACCEPT_PNG, SRV_ACCEPT_EXR, SRV_ACCEPT_NONE, SRV_ACCEPT_WEBP, SRV_ACCEPT_AVIF };
enum srv_accept srv_accept_choice(const char *accept);

/* The ETag of a render, and the name of its stored result (GET /v1/renders/{hash}.{ext}): the
 * only place that decides what a render's identity is. scene_hash: api_scene.scene_hash (the
 * canonical document with its preset merged, and its multipart parts); asset_hash:
 * api_scene.asset_hash (the files read under --asset-root, 0 = none); format: the negotiated
 * format's media type ("image/png"); then the build (UMBRA_VERSION) and the device. */
uint64_t srv_etag_of(uint64_t scene_hash, uint64_t asset_hash, const char *format, const char *device_name,
                     const char *driver_info);
/* The file extension of a format's media type in GET /v1/renders/{hash}.{ext}: its subtype
 * without "x-" ("image/png" -> "png", "image/x-exr" -> "exr"); points into mime. */
const char *srv_format_ext(const char *mime);
/* Writes the GET form's path of a render, "/v1/renders/{hash as 16 hex digits}.{ext of mime}"
 * (the Location of POST /v1/renders; n >= 64 holds any), and reads one back: true for
 * "/v1/renders/{16 lower-case hex digits}.{ext}" (ext: a-z, shorter than extsize). */
void srv_result_name(char *out, size_t n, uint64_t hash, const char *mime);
bool srv_result_path(const char *url, uint64_t *hash, char *ext, size_t extsize);
/* Writes the strong ETag header value ("0123456789abcdef", quotes included); n >= 19. */
void srv_etag_format(char *out, size_t n, uint64_t h);
/* True when an If-None-Match value lists etag (strong comparison; "*" never matches). */
bool srv_etag_matches(const char *if_none_match, const char *etag);

#endif
