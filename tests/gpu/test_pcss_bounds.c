/* tests/gpu — PCSS depth bounds (shaders/minmax.comp, pcss_bounds() in shaders/shading.glsl):
 * where the atlas's per-block depth bounds prove that the blocker search would find nothing
 * (lit) or that every tap is shadowed (umbra), pcss() skips the search and filter. That is an
 * optimisation with no visible effect, so the tests hold it to exactly that:
 *   - a caster smaller than one bounds block (UMBRA_BOUNDS_BLOCK texels) still casts its
 *     shadow (the bounds must never hide a small caster);
 *   - every light type and debug view gives the same bytes with the bounds read and with them
 *     left unread (UMBRA_PCSS_BOUNDS=0, read per render), on a scene with small and large
 *     casters, sloped receivers and caster edges near tile edges;
 *   - a cached map reused by a later render (after other renders wrote other tiles and their
 *     bounds) gives the same bytes as when it was drawn. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "test.h"

/* Renders doc with the bounds read, then with them unread; fails when a byte differs. */
static void same_with_and_without(const char *what, const char *doc)
{
	struct rnd_image on, off;
	if (!gpu_render(&on, "%s", doc)) return;
	setenv("UMBRA_PCSS_BOUNDS", "0", 1);
	bool ok = gpu_render(&off, "%s", doc);
	unsetenv("UMBRA_PCSS_BOUNDS");
	if (ok) {
		size_t first = 0;
		long diff = gpu_bytes_differ(&on, &off, &first);
		CHECK(diff == 0, "%s: the depth bounds changed %ld bytes (first at byte %zu)", what, diff, first);
		rnd_image_release(&off);
	}
	rnd_image_release(&on);
}

/* A spot light aimed at the origin from `light`, radius 2 cm, and a 3 cm box centred at `box`:
 * at the spot's 1024² map the box is ~7 texels across, under half a bounds block. A top-down
 * orthographic camera 0.2 m wide over where the box's centre shadows the floor. */
TEST(pcss_bounds_small_caster_still_shadowed)
{
	const double lx = 1.2, ly = 4.0, lz = 0.6, by = 0.5;
	double t = ly / (ly - by);
	double px = lx - t * lx, pz = lz - t * lz;   /* the box is at (0, by, 0) */
	char doc[2048];
	snprintf(doc, sizeof doc,
	         "{'width':64,'height':64,"
	         "'camera':{'type':'orthographic','position':[%.9g,3,%.9g],'target':[%.9g,0,%.9g],'up':[0,0,-1],'height':0.2},"
	         "'objects':[{'shape':'plane','size':[10,10]},"
	         "{'shape':'box','size':[0.03,0.03,0.03],'transform':{'translation':[0,%.9g,0]}}],"
	         "'lights':[{'type':'spot','position':[%.9g,%.9g,%.9g],'direction':[%.9g,%.9g,%.9g],"
	         "'outer_angle':30,'inner_angle':20,'radius':0.02,'intensity':10,"
	         "'shadow':{'filter':'pcss','resolution':1024}}],"
	         "'output':{'debug':'shadow','msaa':1}}",
	         px, pz, px, pz, by, lx, ly, lz, -lx, -ly, -lz);
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "%s", doc));
	/* 3.4 cm of shadow (~11 px) with ~2 px of penumbra: its middle is umbra. */
	double centre = 1.0, corner = 0.0;
	for (int j = 30; j <= 33; j++)
		for (int i = 30; i <= 33; i++) centre = fmin(centre, gpu_px8(&img, i, j)[0] / 255.0);
	for (int k = 0; k < 4; k++) corner = fmax(corner, 1.0 - gpu_px8(&img, k % 2 ? 63 : 0, k / 2 ? 63 : 0)[0] / 255.0);
	CHECK(centre < 0.1, "the 3 cm box's shadow is gone: visibility %.3f under its centre", centre);
	CHECK(corner < 0.01, "the floor 10 cm from the small shadow is shadowed (%.3f)", corner);
	rnd_image_release(&img);
	/* The same image without the bounds (the exact search everywhere). */
	same_with_and_without("small caster", doc);
}

/* A floor, a tilted ramp (sloped receiver), a large thin slab (umbra several bounds blocks
 * wide), a sphere, a thin pole, a 2 cm cube and a box near the floor's edge; a soft sun, two
 * spots of different sizes and a point light (six faces, caster edges across face borders),
 * all PCSS. `output`: the output member. */
static void bounds_doc(char *buf, size_t n, double shift, const char *output)
{
	snprintf(buf, n,
	         "{'width':160,'height':120,"
	         "'camera':{'type':'perspective','position':[6,5,7],'target':[%.9g,0.3,0],'up':[0,1,0],'fov_y':50},"
	         "'objects':[{'shape':'plane','size':[12,12]},"
	         "{'shape':'plane','size':[2,2],'transform':{'translation':[2.5,0.5,-1.5],'rotation':[0,0,0.2164396,0.9762960]}},"
	         "{'shape':'box','size':[2.2,0.04,1.6],'transform':{'translation':[%.9g,0.9,1]}},"
	         "{'shape':'sphere','radius':0.5,'transform':{'translation':[1.5,0.5,1.5]}},"
	         "{'shape':'cylinder','radius':0.015,'height':1.4,'transform':{'translation':[0.3,0.7,-0.8]}},"
	         "{'shape':'box','size':[0.02,0.02,0.02],'transform':{'translation':[-0.6,0.3,-0.2]}},"
	         "{'shape':'box','size':[0.4,0.8,0.4],'transform':{'translation':[-5.6,0.4,-2]}}],"
	         "'lights':[{'type':'directional','direction':[-0.4,-1,-0.3],'intensity':1,'angular_diameter':2},"
	         "{'type':'spot','position':[-2,4,-1.5],'direction':[0.45,-1,0.35],'outer_angle':40,'inner_angle':25,"
	         "'range':15,'intensity':40,'radius':0.05},"
	         "{'type':'spot','position':[2.5,3,2.5],'direction':[-0.6,-1,-0.6],'outer_angle':35,'inner_angle':25,"
	         "'range':15,'intensity':30,'radius':0.6},"
	         "{'type':'point','position':[0,2.2,0.2],'intensity':12,'range':10,'radius':0.12}],"
	         "'shadows':{'filter':'pcss'},'output':%s}",
	         shift, -0.5 + shift, output);
}

TEST(pcss_bounds_change_no_byte)
{
	char doc[4096];
	bounds_doc(doc, sizeof doc, 0.0, "{'msaa':4}");
	same_with_and_without("beauty", doc);
	for (int l = 0; l < 4; l++) {
		char out[96], what[48];
		snprintf(out, sizeof out, "{'debug':'shadow','debug_light':%d,'msaa':1}", l);
		snprintf(what, sizeof what, "debug shadow of light %d", l);
		bounds_doc(doc, sizeof doc, 0.0, out);
		same_with_and_without(what, doc);
	}
}

TEST(pcss_bounds_cached_map_same_bytes)
{
	/* A layout no other test draws, so that its spot and point maps are drawn fresh here. */
	char doc[4096], other[4096];
	bounds_doc(doc, sizeof doc, 0.37, "{'debug':'shadow','debug_light':3,'msaa':1}");
	struct rnd_image fresh, again;
	REQUIRE(gpu_render(&fresh, "%s", doc));
	CHECK(gpu_last_timings.shadow_maps_rendered >= 8, "expected fresh maps, %u rendered",
	      gpu_last_timings.shadow_maps_rendered);
	/* Another render draws other maps (other tiles, their bounds) in between; one, so that the
	 * atlas keeps room for both and evicts nothing. */
	struct rnd_image tmp;
	bounds_doc(other, sizeof other, 0.48, "{'msaa':1}");
	if (gpu_render(&tmp, "%s", other)) rnd_image_release(&tmp);
	if (gpu_render(&again, "%s", doc)) {
		CHECK(gpu_last_timings.shadow_maps_reused >= 8, "expected the cached maps, %u reused",
		      gpu_last_timings.shadow_maps_reused);
		size_t first = 0;
		long diff = gpu_bytes_differ(&fresh, &again, &first);
		CHECK(diff == 0, "a reused map gave %ld other bytes (first at byte %zu)", diff, first);
		rnd_image_release(&again);
	}
	rnd_image_release(&fresh);
	same_with_and_without("reused maps", doc);
}
