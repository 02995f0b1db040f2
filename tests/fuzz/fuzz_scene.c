/*
 * tests/fuzz/fuzz_scene.c — libFuzzer target for the scene parser (api_scene_parse): any
 * bytes must give either a scene or a problem with a status, never a crash, a leak or UB.
 *
 *   make fuzz && mkdir -p build/fuzz/corpus && build/fuzz/fuzz_scene -max_total_time=60 build/fuzz/corpus tests/fuzz/corpus
 *   (new inputs go to the first directory; tests/fuzz/corpus holds the seeds)
 */
#include <stdint.h>
#include <stdlib.h>
#include "api.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	api_model_cache_set_limit(0);   /* every input stands alone */
	struct api_scene *s = NULL;
	struct api_problem p;
	if (api_scene_parse((const char *)data, size, &lim, &s, &p) == API_OK) {
		api_scene_free(s);
	} else if (p.status < 400 || p.status > 599) {
		abort();   /* a failure must always carry an HTTP status */
	}
	return 0;
}
