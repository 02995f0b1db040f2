/* tests/unit — the result cache of the GET form of renders (server/results.c): LRU eviction
 * within the image bound, scenes kept to render an evicted image again, refusals. */
#include <stdlib.h>
#include <string.h>

#include "results.h"
#include "test.h"

/* A kept scene as srv_scene_keep() would make it from a request with this body. */
static struct srv_kept_scene scene_of(const char *body)
{
	struct srv_request req = { 0 };
	struct srv_kept_scene k = { 0 };
	req.body = strdup(body);
	req.body_len = strlen(body);
	CHECK(srv_scene_keep(&k, &req) && !req.body, "the body moves into the kept scene");
	return k;
}

TEST(results_lru_within_the_bound_and_scenes_kept)
{
	struct srv_results *r = srv_results_create(1000);
	uint8_t img[400];
	memset(img, 7, sizeof img);
	for (uint64_t h = 1; h <= 3; h++) {
		struct srv_kept_scene k = scene_of("{\"width\": 8}");
		CHECK(srv_results_put(r, h, "png", &(struct srv_result_image){ img, sizeof img, "image/png", h == 3 ? "w" : "" },
		                      &k));
		CHECK(!k.body, "put takes the scene");
	}
	struct srv_results_stats st;
	srv_results_stats(r, &st);
	CHECK(st.image_bytes == 800 && st.images == 2, "two 400-byte images fit in 1000 bytes: %llu in %llu",
	      (unsigned long long)st.image_bytes, (unsigned long long)st.images);
	struct srv_result_image out = { 0 };
	struct srv_kept_scene sc = { 0 };
	CHECK(srv_results_get(r, 3, "png", &out, &sc) == SRV_RESULT_IMAGE && out.len == 400 &&
	      !strcmp(out.mime, "image/png") && out.data[0] == 7 && out.warnings && !strcmp(out.warnings, "w"),
	      "the image and its warnings");
	free(out.data);
	free((char *)out.warnings);
	CHECK(srv_results_get(r, 3, "exr", NULL, NULL) == SRV_RESULT_NONE, "the extension is part of the key");
	/* The oldest image went; its scene stays, as a deep copy to render again. */
	CHECK(srv_results_get(r, 1, "png", &out, &sc) == SRV_RESULT_SCENE);
	CHECK(sc.body && !strcmp(sc.body, "{\"width\": 8}") && sc.body_len == 12);
	srv_kept_release(&sc);
	CHECK(!sc.body, "release leaves it empty");
	CHECK(srv_results_get(r, 99, "png", NULL, NULL) == SRV_RESULT_NONE);
	srv_results_destroy(r);
}

TEST(results_refuse_what_does_not_fit)
{
	struct srv_results *r = srv_results_create(100);
	uint8_t img[200] = { 0 };
	struct srv_kept_scene k = scene_of("{}");
	CHECK(!srv_results_put(r, 1, "png", &(struct srv_result_image){ img, sizeof img, "image/png", NULL }, &k),
	      "an image over the whole bound");
	CHECK(!k.body, "a refused put still releases the scene");
	CHECK(srv_results_get(r, 1, "png", NULL, NULL) == SRV_RESULT_NONE);
	srv_results_destroy(r);
	CHECK(srv_results_create(0) == NULL, "0 MB: no cache");
	CHECK(!srv_results_put(NULL, 1, "png", &(struct srv_result_image){ img, 1, "image/png", NULL }, NULL),
	      "NULL cache refuses");
	CHECK(srv_results_get(NULL, 1, "png", NULL, NULL) == SRV_RESULT_NONE);
	srv_results_destroy(NULL);
	/* A scene over SRV_SCENE_KEEP_MAX is not kept: the request keeps its body. */
	struct srv_request req = { 0 };
	req.body_len = SRV_SCENE_KEEP_MAX + 1;
	req.body = calloc(1, req.body_len + 1);
	struct srv_kept_scene big = { 0 };
	CHECK(!srv_scene_keep(&big, &req) && req.body && !big.body);
	free(req.body);
}
