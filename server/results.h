/*
 * server/results — the result cache behind POST /v1/renders and GET /v1/renders/{hash}.{ext}:
 * encoded images by their render hash (the ETag's value, negotiate.h srv_etag_of), and the
 * scenes that make them, so that an image evicted can be rendered again.
 *
 * Bounds (--result-cache-mb N): images up to N MiB together, and the scenes (the request's body
 * and its multipart parts, as sent) up to N/8 MiB together (at least 1 MiB), one scene at most
 * SRV_SCENE_KEEP_MAX bytes (larger ones are not kept: their image, once evicted, is a 404 that
 * says to POST again). Each list is evicted least recently used first; an entry with neither an
 * image nor a scene goes. N = 0: no cache (srv_results_create returns NULL, every function
 * takes NULL).
 *
 * Usage:
 *   worker (POST /v1/renders): srv_scene_keep(&req->kept, req) before the body is dropped;
 *     after the encode: srv_results_put(r, hash, "png", &(struct srv_result_image){ bytes, len,
 *     mime, req->warnings }, &req->kept)
 *   polling thread (GET): switch (srv_results_get(r, hash, "png", &img, &scene)) ...
 *
 * Ownership: put copies the image and takes the kept scene (leaving *kept empty); get hands
 * out malloc'd copies (the image, or a scene to render: srv_kept_release it or move it into a
 * request with srv_scene_give). Threading: one mutex; every function is safe from any thread.
 */
#ifndef UMBRA_SRV_RESULTS_H
#define UMBRA_SRV_RESULTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "srv.h"

#define SRV_SCENE_KEEP_MAX ((size_t)1 << 20)

struct srv_results;

struct srv_results *srv_results_create(uint64_t image_bytes);
void srv_results_destroy(struct srv_results *r);   /* NULL-safe */

/* Moves req's body and parts into *kept when they fit SRV_SCENE_KEEP_MAX (returns true); else
 * leaves both alone. With want, what the request's Accept chose (enum srv_accept). */
bool srv_scene_keep(struct srv_kept_scene *kept, struct srv_request *req);
/* Moves a kept scene into req's body and parts (req has none). */
void srv_scene_give(struct srv_kept_scene *kept, struct srv_request *req);
void srv_kept_release(struct srv_kept_scene *kept);   /* NULL-safe, leaves it empty */

/* A stored image: its bytes, its media type (a static string: api_format_mime) and the
 * Umbra-Warnings its render had ("" or NULL = none), sent again with every GET. */
struct srv_result_image {
	uint8_t *data;
	size_t len;
	const char *mime;
	const char *warnings;
};

/* Stores a copy of the image under (hash, ext), and takes *kept (may be NULL or empty). False
 * when the image alone is over the cache's size or out of memory: nothing stored, *kept
 * released. */
bool srv_results_put(struct srv_results *r, uint64_t hash, const char *ext, const struct srv_result_image *img,
                     struct srv_kept_scene *kept);

enum srv_result_found { SRV_RESULT_NONE, SRV_RESULT_IMAGE, SRV_RESULT_SCENE };
/* What the cache has for (hash, ext): the image (malloc'd copies in *img: data, and warnings
 * unless NULL; free both), or only its scene (a copy in *scene), or nothing. With img NULL,
 * only whether it knows the hash (IMAGE or SCENE), nothing copied. Out of memory for a copy:
 * NONE. */
enum srv_result_found srv_results_get(struct srv_results *r, uint64_t hash, const char *ext,
                                      struct srv_result_image *img, struct srv_kept_scene *scene);

struct srv_results_stats {
	uint64_t image_bytes, scene_bytes, images, scenes, capacity;
};
void srv_results_stats(struct srv_results *r, struct srv_results_stats *out);

#endif
