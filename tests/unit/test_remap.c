/* tests/unit — api/remap.h numbers distinct keys as meshopt_generateVertexRemap() does: the
 * same remap, the same count, for 12- and 24-byte keys with many repeats. */
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>
#include "remap.h"
#include "test.h"

TEST(remap_keys_numbers_like_meshoptimizer)
{
	static const size_t sizes[2] = {12, 24};
	enum { N = 50000 };
	uint32_t *keys = malloc((size_t)N * 24), *a = malloc(N * 4), *b = malloc(N * 4);
	REQUIRE(keys && a && b);
	for (int s = 0; s < 2; s++) {
		uint32_t words = (uint32_t)(sizes[s] / 4), x = 12345;
		for (size_t i = 0; i < N; i++)
			for (uint32_t w = 0; w < words; w++) {
				x = x * 1103515245u + 12345u;
				keys[i * words + w] = (x >> 16) % 97;   /* few values a word: many equal keys */
			}
		/* and exact repeats of earlier keys */
		for (size_t i = 1000; i < N; i += 7) memcpy(keys + i * words, keys + (i / 3) * words, sizes[s]);
		size_t u = api_remap_keys(keys, N, sizes[s], a);
		size_t v = meshopt_generateVertexRemap(b, NULL, N, keys, N, sizes[s]);
		CHECK(u == v, "%zu-byte keys: %zu distinct, meshoptimizer %zu", sizes[s], u, v);
		CHECK(!memcmp(a, b, (size_t)N * 4), "%zu-byte keys: the same numbering", sizes[s]);
	}
	CHECK(api_remap_keys(keys, 0, 12, a) == 0, "no keys");
	free(keys);
	free(a);
	free(b);
}
