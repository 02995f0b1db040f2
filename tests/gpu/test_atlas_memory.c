/* tests/gpu — shadow atlas memory (shadow_cache.c): the atlases are resident only while tiles
 * use them. Four concurrent renders of a sun with four 2048² cascades each fill an 8192² atlas
 * (umbrad's default) exactly; they must all succeed, rnd_context_trim must give the pages
 * back once they are done (resident memory falls, on a CPU device where device memory is this
 * process's memory), and the same renders after the trim must give the same bytes (the maps are
 * drawn again into the released, now zero, pages). And the slots and pipelines trims of a
 * memory bound, beside a render. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"

#define RENDERS 4

static const char *const CSM_DOC =
	"{\"width\":256,\"height\":256,"
	"\"camera\":{\"type\":\"perspective\",\"position\":[12,8,12],\"target\":[0,0,0],\"fov_y\":50},"
	"\"objects\":[{\"shape\":\"plane\",\"size\":[60,60]},"
	"{\"shape\":\"box\",\"size\":[1,2,1],\"transform\":{\"translation\":[0,1,0]}},"
	"{\"shape\":\"sphere\",\"radius\":0.8,\"transform\":{\"translation\":[-4,0.8,3]}}],"
	"\"lights\":[{\"type\":\"directional\",\"direction\":[-0.5,-1,-0.3],"
	"\"shadow\":{\"directional\":{\"mode\":\"cascades\",\"cascades\":4}}}],"
	"\"shadows\":{\"resolution\":2048},\"output\":{\"msaa\":1}}";

struct job {
	struct rnd_context *ctx;
	const struct rnd_scene *scene;
	struct rnd_image img;
	enum rnd_result r;
	struct rnd_error err;
};

static void *render_job(void *arg)
{
	struct job *j = arg;
	struct rnd_timings t;
	j->r = rnd_render(j->ctx, j->scene, &j->img, &t, &j->err);
	return NULL;
}

/* Resident set size of this process in kB (VmRSS), 0 when unknown. */
static long rss_kb(void)
{
	FILE *f = fopen("/proc/self/status", "r");
	if (!f) return 0;
	char line[256];
	long kb = 0;
	while (fgets(line, sizeof line, f))
		if (sscanf(line, "VmRSS: %ld kB", &kb) == 1) break;
	fclose(f);
	return kb;
}

/* Four renders at once; false (and a failed check) when one fails. */
static bool render_four(struct rnd_context *ctx, const struct rnd_scene *scene, struct job *jobs)
{
	pthread_t th[RENDERS];
	bool started[RENDERS] = {false}, ok = true;
	for (int i = 0; i < RENDERS; i++) {
		memset(&jobs[i], 0, sizeof jobs[i]);
		jobs[i].ctx = ctx;
		jobs[i].scene = scene;
		jobs[i].r = RND_ERR_INVALID;
		started[i] = pthread_create(&th[i], NULL, render_job, &jobs[i]) == 0;
		CHECK(started[i], "pthread_create %d", i);
	}
	for (int i = 0; i < RENDERS; i++) {
		if (started[i]) pthread_join(th[i], NULL);
		CHECK(jobs[i].r == RND_OK, "render %d: %s: %s", i, rnd_result_str(jobs[i].r), jobs[i].err.msg);
		ok = ok && jobs[i].r == RND_OK;
	}
	return ok;
}

static void release_four(struct job *jobs)
{
	for (int i = 0; i < RENDERS; i++)
		if (jobs[i].r == RND_OK) rnd_image_release(&jobs[i].img);
}

TEST(atlas_four_cascade_renders_fit_then_pages_go_back)
{
	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {0};
	cd.validation = v && strcmp(v, "1") == 0;
	cd.atlas_size = 8192;
	cd.slots = RENDERS;
	struct rnd_context *ctx = NULL;
	struct rnd_error err = {0};
	REQUIRE(rnd_context_create(&cd, &ctx, &err) == RND_OK);
	struct rnd_info info;
	rnd_context_info(ctx, &info);
	struct api_limits lim;
	api_limits_defaults(&lim);
	struct api_scene *s = NULL;
	struct api_problem prob = {0};
	if (api_scene_parse(CSM_DOC, strlen(CSM_DOC), &lim, &s, &prob) != API_OK) {
		CHECK(0, "parse: %s %s", prob.pointer, prob.detail);
		rnd_context_destroy(ctx);
		return;
	}
	struct job first[RENDERS], again[RENDERS];
	/* Round 1 grows the slots (scratch maps, targets) and fills the atlas. */
	if (render_four(ctx, &s->scene, first)) {
		uint64_t released = rnd_context_trim(ctx, 0);
		long rss0 = rss_kb();
		/* Round 2: the slots are grown already, so what is resident on top is the atlas. */
		bool ok = render_four(ctx, &s->scene, again);
		long rss1 = rss_kb();
		uint64_t released2 = rnd_context_trim(ctx, 0);
		long rss2 = rss_kb();
		struct rnd_stats st;
		rnd_context_stats(ctx, &st);
		printf("    [4 x 4 cascades, atlas %u] trim released %.0f MB of mappings; RSS %.0f MB idle, %.0f MB after four "
		       "renders, %.0f MB after the trim; %u cached maps left\n",
		       st.atlas_size, released2 / 1048576.0, rss0 / 1024.0, rss1 / 1024.0, rss2 / 1024.0, st.cached_maps);
		CHECK(st.atlas_tiles == 0 && st.cached_maps == 0, "after the trim: %u tiles, %u cached maps", st.atlas_tiles,
		      st.cached_maps);
		if (info.is_cpu && rss0 && rss1 && rss2) {
			CHECK(released > 0 && released2 > 0, "trim released %llu then %llu bytes", (unsigned long long)released,
			      (unsigned long long)released2);
			/* 16 maps of 2048² D32 are 256 MB; slots and heap add little in round 2. */
			CHECK(rss1 - rss0 >= 32 * 1024, "four renders added only %ld kB: is the atlas resident while idle?",
			      rss1 - rss0);
			CHECK(rss1 - rss2 >= (rss1 - rss0) * 6 / 10, "the trim gave back %ld of the %ld kB the renders added",
			      rss1 - rss2, rss1 - rss0);
		}
		if (ok)
			for (int i = 0; i < RENDERS; i++) {
				size_t bytes = (size_t)first[i].img.height * first[i].img.stride;
				CHECK(again[i].img.stride == first[i].img.stride &&
				      memcmp(again[i].img.pixels, first[i].img.pixels, bytes) == 0,
				      "render %d after the trim differs from before it", i);
			}
		release_four(again);
	}
	release_four(first);
	CHECK(rnd_context_validation_messages(ctx) == 0, "%u validation messages", rnd_context_validation_messages(ctx));
	api_scene_free(s);
	rnd_context_destroy(ctx);
}

/* What a process held to a memory bound gives back between renders (umbrad --max-rss):
 * the idle slots' targets and the pipeline variants, taken while another thread renders. A
 * variant that render recorded must outlive it (retired, destroyed once it is over), and every
 * render must give the bytes of the first: the slots' targets and the variants are made again. */
struct trimmer {
	struct rnd_context *ctx;
	volatile int stop;
	unsigned trims;
};

static void *trim_loop(void *arg)
{
	struct trimmer *t = arg;
	while (!t->stop) {
		rnd_context_trim_pipelines(t->ctx, 0);
		rnd_context_trim_slots(t->ctx);
		t->trims++;
		usleep(500);
	}
	return NULL;
}

TEST(atlas_trims_of_slots_and_pipelines_under_a_render_change_nothing)
{
	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {.slots = 2, .validation = v && strcmp(v, "1") == 0};
	struct rnd_context *ctx;
	struct rnd_error err;
	REQUIRE(rnd_context_create(&cd, &ctx, &err) == RND_OK);
	struct api_scene *s = gpu_parse(CSM_DOC);
	if (!s) { rnd_context_destroy(ctx); return; }
	struct job first = {.ctx = ctx, .scene = &s->scene};
	render_job(&first);
	CHECK(first.r == RND_OK, "first render: %s", first.err.msg);
	struct trimmer t = {.ctx = ctx};
	pthread_t th;
	REQUIRE(pthread_create(&th, NULL, trim_loop, &t) == 0);
	int same = 0;
	for (int k = 0; k < 4 && first.r == RND_OK; k++) {
		struct job j = {.ctx = ctx, .scene = &s->scene};
		render_job(&j);
		CHECK(j.r == RND_OK, "render %d beside the trims: %s", k, j.err.msg);
		if (j.r == RND_OK && !memcmp(j.img.pixels, first.img.pixels, first.img.stride * first.img.height)) same++;
		rnd_image_release(&j.img);
	}
	t.stop = 1;
	pthread_join(th, NULL);
	struct rnd_stats st;
	rnd_context_stats(ctx, &st);
	printf("  %u trims beside 4 renders; %u variants left\n", t.trims, st.pipeline_variants);
	CHECK(first.r != RND_OK || same == 4, "%d of 4 renders beside the trims gave the first's bytes", same);
	CHECK(t.trims > 0, "no trim ran");
	CHECK(rnd_context_validation_messages(ctx) == 0, "%u validation messages", rnd_context_validation_messages(ctx));
	rnd_image_release(&first.img);
	api_scene_free(s);
	rnd_context_destroy(ctx);
}
