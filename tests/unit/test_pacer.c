/* tests/unit — main-pass band sizing (renderer/submit.c, rnd_pacer_band_rows): pure arithmetic,
 * no GPU. The numbers are the ones a lavapipe run of 16 soft-shadowed spot lights produced:
 * cheap sky rows above, rows ~40x dearer below. */
#include "test.h"
#include <string.h>
#include <time.h>
#include "submit.h"

static struct rnd_pacer pacer(double slice_ms)
{
	struct rnd_pacer p = {0};
	p.slice_ms = slice_ms;
	return p;
}

static void measured(struct rnd_pacer *p, uint32_t rows, double ms)
{
	p->rows[0] = p->rows[1]; p->ms[0] = p->ms[1];
	p->rows[1] = rows; p->ms[1] = ms;
	p->measured++;
}

TEST(pacer_cheap_scene_is_one_band)
{
	struct rnd_pacer p = pacer(1000);
	/* thumb-512 by the estimate: ~0.7 ms a row, 60 ms of vertices */
	CHECK(rnd_pacer_band_rows(&p, 512, 1, 0.7, 60) == 512);
}

TEST(pacer_first_band_from_the_estimate)
{
	struct rnd_pacer p = pacer(1000);
	uint32_t r = rnd_pacer_band_rows(&p, 2048, 1, 150, 10);
	CHECK(r == 6, "rows %u", r);   /* (1000 - 10) / 150 */
	CHECK(rnd_pacer_band_rows(&p, 2048, 1, 5000, 10) == 1, "never below min_rows");
}

TEST(pacer_cheap_rows_do_not_make_huge_bands)
{
	/* The first bands are sky (a few ms for dozens of rows); the estimate says 150 ms a row. */
	struct rnd_pacer p = pacer(1000);
	measured(&p, 6, 2);
	uint32_t r = rnd_pacer_band_rows(&p, 2000, 1, 150, 10);
	CHECK(r <= 12, "rows %u: more than twice the last band", r);
	measured(&p, 12, 3);
	r = rnd_pacer_band_rows(&p, 2000, 1, 150, 10);
	CHECK(r <= 27, "rows %u: more than a slice at a quarter of the estimate", r);
}

TEST(pacer_follows_measured_cost)
{
	struct rnd_pacer p = pacer(1000);
	measured(&p, 20, 2000);   /* 100 ms a row: twice the estimate */
	uint32_t r = rnd_pacer_band_rows(&p, 1000, 1, 50, 0);
	CHECK(r == 10, "rows %u", r);
}

TEST(pacer_vertex_bound_bands_do_not_shrink_forever)
{
	/* 600 ms per band whatever its height, 1 ms a row on top: slicing cannot go under 600 ms,
	 * so bands take at least three times that in rows instead of one row each. */
	struct rnd_pacer p = pacer(1000);
	measured(&p, 100, 700);
	measured(&p, 200, 800);
	uint32_t r = rnd_pacer_band_rows(&p, 4000, 1, 0.1, 600);
	CHECK(r >= 400 && r <= 2000, "rows %u", r);
}

TEST(pacer_no_sliver_at_the_bottom)
{
	struct rnd_pacer p = pacer(1000);
	CHECK(rnd_pacer_band_rows(&p, 11, 4, 100, 0) == 11, "a last band of 1 row left over");
}

/* A render that cannot finish stops at once (rnd_pacer_hopeless): its worker goes to the
 * requests behind it a render's time before the deadline (issue 29, fairness under load). */
TEST(pacer_stops_a_render_that_cannot_make_its_deadline)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	uint64_t now = (uint64_t)t.tv_sec * 1000000000ull + (uint64_t)t.tv_nsec;
	struct rnd_scene sc = {0};
	struct rnd_error err = {0};
	struct rnd_pacer p = pacer(500);
	p.sc = &sc;
	measured(&p, 10, 50);   /* 5 ms a row */
	CHECK(rnd_pacer_hopeless(&p, 1000, &err) == RND_OK, "no deadline: never hopeless");
	sc.deadline_ns = now + 60ull * 1000000000ull;
	CHECK(rnd_pacer_hopeless(&p, 1000, &err) == RND_OK, "5 s of rows, a minute left");
	sc.deadline_ns = now + 2ull * 1000000000ull;
	CHECK(rnd_pacer_hopeless(&p, 1000, &err) == RND_ERR_TIMEOUT && strstr(err.msg, "1000 rows left"),
	      "5 s of rows, 2 s left: %s", err.msg);
	CHECK(rnd_pacer_hopeless(&p, 100, &err) == RND_OK, "0.5 s of rows, 2 s left");
	struct rnd_pacer fresh = pacer(500);
	fresh.sc = &sc;
	CHECK(rnd_pacer_hopeless(&fresh, 1000, &err) == RND_OK, "nothing measured yet: no judgement");
}

/* Shadow maps (renderer/submit.c): a map drawn in parts measures each part against its share of
 * the map's estimate, and that sets the scale the later groups are sized by, as a whole group's
 * measure does. Before, only whole groups fed it: after a map in parts, the groups behind it
 * were still planned with the idle-machine estimate (scale 1) and an eighth of a slice. The
 * walls are injected: no timing is asserted. */
TEST(pacer_shadow_parts_feed_the_group_scale)
{
	struct rnd_pacer p = pacer(1000);
	p.shadow_scale = 1.0;
	/* a map estimated 800 ms for 1,000 triangles: a part of 250 is 200 ms by estimate, ran 600 */
	rnd_pacer_shadow_part_measured(&p, false, 800, 250, 1000, 600);
	CHECK(p.shadow_measured, "a part's measure counts as one");
	CHECK(p.shadow_scale > 2.999 && p.shadow_scale < 3.001, "scale %g after a part 3x its estimate", p.shadow_scale);
	/* the next part ran as estimated (100 ms of 400 triangles' 320): the scale follows it */
	rnd_pacer_shadow_part_measured(&p, false, 800, 400, 1000, 640);
	CHECK(p.shadow_scale > 1.999 && p.shadow_scale < 2.001, "scale %g after a part 2x its estimate", p.shadow_scale);
	/* faster than the estimate: never planned below it */
	rnd_pacer_shadow_part_measured(&p, false, 800, 350, 1000, 10);
	CHECK(p.shadow_scale == 1.0, "scale %g after a fast part", p.shadow_scale);
}

TEST(pacer_shadow_part_with_the_prologue_does_not_count)
{
	struct rnd_pacer p = pacer(1000);
	p.shadow_scale = 1.0;
	/* the first submit also built the textures and the environment: its wall says nothing */
	rnd_pacer_shadow_part_measured(&p, true, 800, 250, 1000, 5000);
	CHECK(!p.shadow_measured && p.shadow_scale == 1.0, "measured %d, scale %g", p.shadow_measured, p.shadow_scale);
	rnd_pacer_shadow_part_measured(&p, false, 800, 0, 0, 5000);   /* an empty map: nothing to measure */
	CHECK(!p.shadow_measured, "an empty map measured");
	/* a whole group after it measures as before */
	rnd_pacer_shadow_measured(&p, false, 100, 450);
	CHECK(p.shadow_measured && p.shadow_scale > 4.499 && p.shadow_scale < 4.501, "group scale %g", p.shadow_scale);
}
