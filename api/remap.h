/*
 * api/remap — the unique keys of an array, numbered in the order they first occur: what
 * meshopt_generateVertexRemap() computes (the same numbering), for the importer's joins of
 * millions of vertices. meshoptimizer 0.18 spent ~400 ns a key on a 3M-corner STL (its probe
 * chains and a memcmp a probe: 70 % of a 1M-triangle import); this keeps a 32-bit hash beside
 * each slot and compares keys only when it matches.
 *
 * Usage: uint32_t *remap = malloc(n * 4); size_t u = api_remap_keys(keys, n, 24, remap);
 * Threading: no shared state.
 */
#ifndef UMBRA_API_REMAP_H
#define UMBRA_API_REMAP_H

#include <stddef.h>
#include <stdint.h>

/* remap[i] = the number of key i's first occurrence among the distinct keys (0, 1, ... in the
 * order they first appear); returns how many distinct keys there are. Keys are key_size bytes
 * (a multiple of 4), compared byte for byte. Without memory for its table: SIZE_MAX. */
size_t api_remap_keys(const void *keys, size_t n, size_t key_size, uint32_t *remap);

#endif
