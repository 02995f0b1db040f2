/*
 * api/arena — a bump allocator that owns every array of one parsed scene.
 *
 * Usage: struct api_arena *a = api_arena_create(); p = api_arena_alloc(a, n); ...
 * api_arena_destroy(a) frees everything at once (NULL-safe). Allocations are 16-byte aligned
 * and zeroed. Big allocations get a chunk of their own, so one huge mesh does not waste a
 * chunk's tail. Not thread-safe: one arena belongs to one request.
 */
#ifndef UMBRA_API_ARENA_H
#define UMBRA_API_ARENA_H

#include <stddef.h>

struct api_arena;

struct api_arena *api_arena_create(void);
void api_arena_destroy(struct api_arena *a);
/* Zeroed, 16-byte aligned; NULL when out of memory or when n overflows. */
void *api_arena_alloc(struct api_arena *a, size_t n);
/* n * size bytes with an overflow check. */
void *api_arena_calloc(struct api_arena *a, size_t n, size_t size);
char *api_arena_strdup(struct api_arena *a, const char *s);
/* From now on the arena owns the mapping p[0..len) (mmap's): api_arena_destroy() unmaps it.
 * 0, or -1 when out of memory (the caller still owns it then). */
int api_arena_own_mapping(struct api_arena *a, void *p, size_t len);

#endif
