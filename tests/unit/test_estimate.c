/* tests/unit — what a render is estimated to allocate (renderer/estimate.c): the daemon admits
 * renders by it (--max-memory), so it counts the visibility pass's images wherever the pass may
 * run (renderer/visibility.c), before the plan says whether it does. */
#include <string.h>
#include "estimate.h"
#include "test.h"
#include "visibility_plan.h"

TEST(estimate_counts_the_visibility_pass)
{
	struct rnd_light l[3];
	memset(l, 0, sizeof l);
	for (int i = 0; i < 3; i++) l[i].type = RND_LIGHT_DIRECTIONAL;
	struct rnd_scene sc;
	memset(&sc, 0, sizeof sc);
	sc.width = 320;
	sc.height = 200;
	sc.lights = l;
	sc.light_count = 3;
	struct rnd_estimate off, on, debug, huge_off, huge_on;
	rnd_estimate_scene(&sc, 2048, &off);                /* no light casts: no pass */
	l[1].shadow.enabled = true;
	rnd_estimate_scene(&sc, 2048, &on);
	/* surfaces RGBA32F, normals RGBA16, their depth D32, an R16 layer per light */
	uint64_t want = 320ull * 200 * (16 + 8 + 4 + 2 * 3);
	CHECK(on.device_bytes - off.device_bytes == want, "the pass adds %llu bytes, want %llu",
	      (unsigned long long)(on.device_bytes - off.device_bytes), (unsigned long long)want);
	sc.output.debug = RND_DEBUG_SHADOW;                 /* debug views show the filters' own work */
	rnd_estimate_scene(&sc, 2048, &debug);
	CHECK(debug.device_bytes == off.device_bytes, "a debug view counted the pass");
	/* over the pass's size cap it never runs, and is not counted */
	sc.output.debug = RND_DEBUG_NONE;
	sc.width = sc.height = 8192;
	l[1].shadow.enabled = false;
	rnd_estimate_scene(&sc, 2048, &huge_off);
	l[1].shadow.enabled = true;
	rnd_estimate_scene(&sc, 2048, &huge_on);
	CHECK(huge_on.device_bytes == huge_off.device_bytes && rnd_visibility_bytes(&sc) == 0,
	      "an 8192² view of three lights counted the pass");
	/* one light: the image still has two layers (rnd_slot_visibility makes an array of them) */
	sc.width = 320;
	sc.height = 200;
	sc.lights = &l[1];
	sc.light_count = 1;
	want = 320ull * 200 * (16 + 8 + 4 + 2 * 2);
	CHECK(rnd_visibility_bytes(&sc) == want, "one light: %llu bytes, want %llu",
	      (unsigned long long)rnd_visibility_bytes(&sc), (unsigned long long)want);
}

/* The largest map's scratch image and copy buffer (4 bytes a texel each) follow the sizes the
 * planner draws: a server's cap on shadow resolution bounds the default 2048 too, and an asked
 * resolution is drawn at the power of two above it. */
TEST(estimate_follows_the_map_sizes)
{
	struct rnd_light l;
	memset(&l, 0, sizeof l);
	l.type = RND_LIGHT_DIRECTIONAL;
	l.shadow.enabled = true;
	struct rnd_scene sc;
	memset(&sc, 0, sizeof sc);
	sc.width = sc.height = 64;
	sc.lights = &l;
	sc.light_count = 1;
	sc.output.debug = RND_DEBUG_SHADOW;   /* no visibility pass in the figures */
	struct rnd_estimate def, capped, asked;
	rnd_estimate_scene(&sc, 8192, &def);
	sc.max_shadow_resolution = 512;
	rnd_estimate_scene(&sc, 8192, &capped);
	CHECK(def.device_bytes - capped.device_bytes == (2048ull * 2048 - 512ull * 512) * 8,
	      "the cap took %llu bytes off", (unsigned long long)(def.device_bytes - capped.device_bytes));
	l.shadow.resolution = 1500;
	rnd_estimate_scene(&sc, 8192, &asked);
	CHECK(asked.device_bytes - capped.device_bytes == (2048ull * 2048 - 512ull * 512) * 8,
	      "1500 asked counts as a 2048 map: %llu bytes over the capped default",
	      (unsigned long long)(asked.device_bytes - capped.device_bytes));
}
