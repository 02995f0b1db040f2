/*
 * api/env_map — environment maps (`environment.map`): Radiance .hdr (RGBE, flat or RLE, api/
 * env_decode.c) and OpenEXR (scanline, R G B or Y, any compression OpenEXR's C core reads)
 * decoded to linear RGB floats, reduced on the way in (2 x 2 boxes, never more than
 * API_ENV_MAX_WIDTH wide: the renderer shows no more), and kept process-wide by the hash of the
 * file's bytes, so a repeated map is read but not decoded again.
 *
 * Usage:
 *   struct api_env_map *m; int status; char err[200];
 *   if (api_env_map_get(bytes, len, &m, &status, err, sizeof err) != API_OK) -> status, err
 *   scene.environment.map = (struct rnd_env_map){m->rgb, m->width, m->height, m->key};
 *   ... api_env_map_release(m);   (when the scene is freed)
 *
 * Ownership: each get hands out one reference. Threading: the cache has its own mutex.
 */
#ifndef UMBRA_API_ENV_MAP_H
#define UMBRA_API_ENV_MAP_H

#include <stddef.h>
#include <stdint.h>
#include "api.h"

#define API_ENV_MAX_WIDTH 2048u
#define API_ENV_MAX_SIDE 16384u      /* a file's width or height (RND_MAX_TEXTURE_SIDE) */
#define API_ENV_CACHE_BYTES (64ull << 20)

struct api_env_map {
	float *rgb;            /* width * height * 3, rows from the top (the zenith) */
	uint32_t width, height;
	uint32_t file_width, file_height;  /* before the reduction */
	uint64_t key;          /* hash of the file's bytes */
	/* private */
	uint32_t refs;
	uint64_t used;
};

/* The decoded map of the file b[0..len): found in the cache or decoded (400 for a file that is
 * neither format or is broken, with a sentence in err). */
enum api_result api_env_map_get(const uint8_t *b, size_t len, struct api_env_map **out, int *status, char *err,
                                size_t errsize);
void api_env_map_release(struct api_env_map *m);
/* Drops every cached map nobody holds (tests). */
void api_env_map_cache_clear(void);

/* ---- api/env_decode.c ---- */

/* Decoded rows are added into a reduced image: a file w x h becomes (w / f) x (h / f) with f the
 * smallest power of two that brings w to API_ENV_MAX_WIDTH or less (a remainder row or column
 * of fewer than f texels is dropped). */
struct api_env_reducer {
	uint32_t w, h, f, ow, oh;
	float *out;            /* ow * oh * 3, zeroed, malloc'd */
};
bool api_env_reducer_init(struct api_env_reducer *r, uint32_t w, uint32_t h);
/* Row y of the file (w rgb floats). */
void api_env_reducer_row(struct api_env_reducer *r, uint32_t y, const float *rgb);

bool api_env_is_hdr(const uint8_t *b, size_t len);
bool api_env_is_exr(const uint8_t *b, size_t len);
/* Into r (initialised here); API_ERR with a sentence. */
enum api_result api_env_decode_hdr(const uint8_t *b, size_t len, struct api_env_reducer *r, char *err, size_t errsize);
enum api_result api_env_decode_exr(const uint8_t *b, size_t len, struct api_env_reducer *r, char *err, size_t errsize);

#endif
