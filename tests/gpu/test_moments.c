/* tests/gpu — moment shadow maps (VSM, EVSM): the blur of moments.comp. A unit box on a floor
 * under a sun 45 degrees from straight down, seen from straight above (orthographic, 64 px per
 * metre): its shadow on the floor ends in an edge 1 m beside the box, and the blur's width in
 * texels (shadow.vsm.blur) sets how wide that edge's ramp is. Read on the debug shadow view. */
#include <stdio.h>
#include <stdlib.h>
#include "gpu_util.h"
#include "test.h"

/* The shadow row through the box's centre, x from the box's side (0.5 m) to 2 m: how many
 * pixels lie strictly between lit and shadowed, and the values in the middle of the shadow
 * (x = 1 m) and well past its edge (x = 1.9 m). False when the render failed. */
static bool edge_ramp(const char *filter, double blur, int *ramp, int *inside, int *outside, int line)
{
	struct rnd_image img;
	if (!gpu_render_at(__FILE__, line, &img,
	                   "{'width':256,'height':256,"
	                   "'camera':{'type':'orthographic','position':[0,10,0],'target':[0,0,0],'up':[0,0,-1],'height':4},"
	                   "'objects':[{'shape':'plane','size':[4,4]},"
	                   "{'shape':'box','size':[1,1,1],'transform':{'translation':[0,0.5,0]}}],"
	                   "'lights':[{'type':'directional','direction':[1,-1,0]}],"
	                   "'shadows':{'filter':'%s','vsm':{'blur':%g},'directional':{'mode':'fit'}},"
	                   "'output':{'debug':'shadow','msaa':1}}",
	                   filter, blur))
		return false;
	/* x = (i + 0.5 - 128) / 64 m; the row j = 128 is z = 0 */
	*ramp = 0;
	for (int i = 128 + 32; i < 128 + 128; i++) {
		int v = gpu_px8(&img, i, 128)[0];
		if (v > 12 && v < 243) (*ramp)++;
	}
	*inside = gpu_px8(&img, 128 + 64, 128)[0];
	*outside = gpu_px8(&img, 128 + 122, 128)[0];
	rnd_image_release(&img);
	printf("    %s blur %g: %d ramp px, %d in the shadow, %d past it\n", filter, blur, *ramp, *inside, *outside);
	return true;
}

/* A wider blur, a wider ramp, up to the widest a scene may ask (RND_MAX_VSM_BLUR, wider than
 * the box's whole map tile): the blur reads its rows' texels beyond the workgroup's own from
 * workgroup memory, so a wide one must still read the right ones. */
TEST(moments_blur_widens_the_shadow_edge_up_to_the_widest)
{
	static const char *filters[] = {"vsm", "evsm"};
	const double blurs[] = {0.5, 8, RND_MAX_VSM_BLUR};
	for (int f = 0; f < 2; f++) {
		int ramp[3], inside[3], outside[3];
		bool ok = true;
		for (int b = 0; b < 3 && ok; b++)
			ok = edge_ramp(filters[f], blurs[b], &ramp[b], &inside[b], &outside[b], __LINE__);
		if (!ok) continue;
		CHECK(ramp[0] <= 4, "%s: blur 0.5 texels gives a %d px ramp", filters[f], ramp[0]);
		CHECK(ramp[1] > ramp[0] && ramp[2] > ramp[1] + 5, "%s: ramps %d, %d, %d px for blurs 0.5, 8, %u",
		      filters[f], ramp[0], ramp[1], ramp[2], RND_MAX_VSM_BLUR);
		for (int b = 0; b < 2; b++)
			CHECK(inside[b] < 40 && outside[b] > 240, "%s blur %g: %d inside the shadow, %d past it", filters[f],
			      blurs[b], inside[b], outside[b]);
	}
}
