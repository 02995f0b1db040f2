/*
 * api/arena — bump allocator over a list of malloc'd chunks (see arena.h).
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include "api.h"
#include "arena.h"

/* api_mem_huge leaves smaller buffers alone. */
#define API_HUGE_MIN (4u << 20)

#define ARENA_CHUNK (64u * 1024u)
#define ARENA_ALIGN 16u

struct chunk {
	struct chunk *next;
	size_t size, used;
	/* Keeps data[] 16-byte aligned on every ABI we build for. */
	_Alignas(16) unsigned char data[];
};

struct mapping {
	struct mapping *next;
	void *p;
	size_t len;
};

struct api_arena {
	struct chunk *head;   /* the chunk small allocations come from */
	struct chunk *big;    /* dedicated chunks of big allocations */
	struct mapping *maps; /* api_arena_own_mapping's (their records in the chunks) */
};

struct api_arena *api_arena_create(void)
{
	return calloc(1, sizeof(struct api_arena));
}

static void free_list(struct chunk *c)
{
	while (c) {
		struct chunk *next = c->next;
		free(c);
		c = next;
	}
}

void api_arena_destroy(struct api_arena *a)
{
	if (!a) return;
	for (struct mapping *m = a->maps; m; m = m->next) munmap(m->p, m->len);
	free_list(a->head);
	free_list(a->big);
	free(a);
}

/* Transparent huge pages (where the system leaves them to madvise, as Debian does) for the whole
 * 2 MiB pages inside [p, p + len). A big buffer's first writes are mostly page faults: on the
 * 2-core VM 15 us a 4 KiB page, 4-8 ms a 2 MiB one (200 MB: 786 ms, with huge pages 400 ms); a
 * 50 MB model part arrived in 227-242 ms, with huge pages 92-103 ms. */
void api_mem_huge(void *p, size_t len)
{
	const uintptr_t huge = (uintptr_t)2 << 20;
	if (!p || len < API_HUGE_MIN) return;
	uintptr_t lo = ((uintptr_t)p + huge - 1) & ~(huge - 1), hi = ((uintptr_t)p + len) & ~(huge - 1);
	if (hi > lo) (void)madvise((void *)lo, hi - lo, MADV_HUGEPAGE);
}

/* zeroed: calloc, which for a large chunk (fresh pages from the kernel) writes nothing, where
 * malloc + memset wrote a decoded 50 MB model's pages once more before the decoder did. */
static struct chunk *chunk_new(size_t size, bool zeroed)
{
	if (size > SIZE_MAX - sizeof(struct chunk)) return NULL;
	struct chunk *c = zeroed ? calloc(1, sizeof(struct chunk) + size) : malloc(sizeof(struct chunk) + size);
	if (!c) return NULL;
	api_mem_huge(c, sizeof(struct chunk) + size);
	c->next = NULL;
	c->size = size;
	c->used = 0;
	return c;
}

void *api_arena_alloc(struct api_arena *a, size_t n)
{
	if (!a) return NULL;
	if (n == 0) n = 1;
	if (n > SIZE_MAX - ARENA_ALIGN) return NULL;
	n = (n + ARENA_ALIGN - 1) & ~(size_t)(ARENA_ALIGN - 1);
	if (n > ARENA_CHUNK / 4) {
		/* A chunk of its own: the current small chunk keeps its free tail. */
		struct chunk *c = chunk_new(n, true);
		if (!c) return NULL;
		c->used = n;
		c->next = a->big;
		a->big = c;
		return c->data;
	}
	if (!a->head || a->head->size - a->head->used < n) {
		struct chunk *c = chunk_new(ARENA_CHUNK, false);
		if (!c) return NULL;
		c->next = a->head;
		a->head = c;
	}
	void *p = a->head->data + a->head->used;
	a->head->used += n;
	memset(p, 0, n);
	return p;
}

void *api_arena_calloc(struct api_arena *a, size_t n, size_t size)
{
	if (size && n > SIZE_MAX / size) return NULL;
	return api_arena_alloc(a, n * size);
}

char *api_arena_strdup(struct api_arena *a, const char *s)
{
	size_t n = strlen(s) + 1;
	char *d = api_arena_alloc(a, n);
	if (d) memcpy(d, s, n);
	return d;
}

int api_arena_own_mapping(struct api_arena *a, void *p, size_t len)
{
	struct mapping *m = api_arena_alloc(a, sizeof *m);
	if (!m) return -1;
	*m = (struct mapping){a->maps, p, len};
	a->maps = m;
	return 0;
}
