/* tests/gpu — light culling (shading.glsl light_all): a pixel shades only the lights whose range
 * and cone reach it and that face its surface. Such a light adds exactly zero, so culling must
 * not change a single byte: every scene here renders with culling on and with it forced off
 * (UMBRA_LIGHT_CULL=0, read per render) and the two images are compared byte for byte.
 *
 * The scenes are built so that culling does cull: narrow spots and short-range points over a
 * wide floor (most pixels outside most lights), an unbounded point (range 0 reaches
 * everything), every shadow filter, a shadow catcher (which also needs the unshadowed light),
 * the shadow debug view of a light that reaches only part of the frame, and an EXR (linear).
 * The main pass's own filters run here (UMBRA_VISIBILITY=0): with the visibility pass a pixel
 * at a silhouette may read a neighbour's value, which that pass computed only where the light
 * reaches the neighbour (test_visibility.c holds that pass to the filters' image). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "test.h"

/* 14 lights over a 24 m floor: 6 spots (35° cones) and 6 points (range 3..5.5 m) on a ring,
 * an unbounded point and a sun with cascades. filter: a "shadows" filter name. */
static void cull_doc(char *buf, size_t n, const char *filter, const char *output)
{
	size_t len = (size_t)snprintf(buf, n,
	        "{'width':160,'height':120,"
	        "'camera':{'type':'perspective','position':[9,7,10],'target':[0,0,0],'up':[0,1,0],'fov_y':55},"
	        "'materials':{'m':{'base_color':[0.7,0.6,0.5],'roughness':0.4},'c':{'shadow_catcher':true}},"
	        "'objects':[{'shape':'plane','size':[24,24]},"
	        "{'shape':'sphere','radius':0.6,'segments':24,'transform':{'translation':[2,0.6,0]},'material':'m'},"
	        "{'shape':'box','size':[0.8,1.4,0.8],'transform':{'translation':[-2,0.7,1]},'material':'m'},"
	        "{'shape':'cylinder','radius':0.3,'height':1.6,'segments':16,'transform':{'translation':[0,0.8,-3]}},"
	        "{'shape':'plane','size':[3,3],'transform':{'translation':[4,0.01,4]},'material':'c'}],"
	        "'lights':[{'type':'directional','direction':[-0.4,-1,-0.2],'intensity':0.4,"
	        "'shadow':{'directional':{'mode':'cascades'}}},"
	        "{'type':'point','position':[0,4,0],'intensity':3,'radius':0.1}");
	for (int k = 0; k < 12; k++) {
		double x = (k % 4) * 4.0 - 6.0, z = (k / 4) * 4.0 - 4.0;
		if (k % 2 == 0)
			len += (size_t)snprintf(buf + len, n - len,
			                        ",{'type':'spot','position':[%g,3,%g],'direction':[0.2,-1,0.1],'outer_angle':35,"
			                        "'inner_angle':20,'range':%g,'intensity':25,'radius':0.05,'color':[1,0.8,0.6]}",
			                        x, z, 6.0 + k % 3);
		else
			len += (size_t)snprintf(buf + len, n - len,
			                        ",{'type':'point','position':[%g,1.2,%g],'range':%g,'intensity':6,'color':[0.5,0.7,1]}",
			                        x, z, 3.0 + 0.5 * (k % 6));
	}
	snprintf(buf + len, n - len, "],'shadows':{'filter':'%s'},'output':%s}", filter, output);
}

/* Renders doc with culling on and off; fails when a byte differs or a render fails. */
static void same_with_and_without(const char *what, const char *doc)
{
	struct rnd_image on, off;
	memset(&on, 0, sizeof on);
	memset(&off, 0, sizeof off);
	setenv("UMBRA_VISIBILITY", "0", 1);
	bool ok = gpu_render(&on, "%s", doc);
	setenv("UMBRA_LIGHT_CULL", "0", 1);
	ok = ok && gpu_render(&off, "%s", doc);
	unsetenv("UMBRA_LIGHT_CULL");
	unsetenv("UMBRA_VISIBILITY");
	if (ok) {
		size_t bytes = (size_t)on.height * on.stride;
		CHECK(on.width == off.width && on.height == off.height && on.stride == off.stride, "%s: image sizes differ", what);
		long diff = 0;
		size_t first = 0;
		const unsigned char *a = on.pixels, *b = off.pixels;
		if (on.height == off.height && on.stride == off.stride)
			for (size_t i = 0; i < bytes; i++)
				if (a[i] != b[i] && !diff++) first = i;
		CHECK(diff == 0, "%s: culling changed %ld of %zu bytes (first at byte %zu)", what, diff, bytes, first);
	}
	rnd_image_release(&off);
	rnd_image_release(&on);
}

TEST(lights_cull_image_unchanged_every_filter)
{
	static const char *const filters[] = {"pcss", "pcf", "hard", "vsm", "evsm"};
	char doc[8192];
	for (size_t f = 0; f < sizeof filters / sizeof filters[0]; f++) {
		cull_doc(doc, sizeof doc, filters[f], "{'msaa':4}");
		same_with_and_without(filters[f], doc);
	}
}

TEST(lights_cull_image_unchanged_outputs)
{
	char doc[8192];
	/* Transparent PNG: the catcher's alpha comes from the lit / unshadowed ratio. */
	cull_doc(doc, sizeof doc, "pcss", "{'transparent':true}");
	same_with_and_without("transparent", doc);
	/* Linear EXR (scene-referred floats: no 8-bit rounding to hide a difference). */
	cull_doc(doc, sizeof doc, "pcf", "{'format':'exr'}");
	same_with_and_without("exr", doc);
	/* The shadow debug view of spot 3 (light index 4), which reaches a corner of the frame:
	 * the debug light is shaded everywhere. */
	cull_doc(doc, sizeof doc, "pcss", "{'debug':'shadow','debug_light':4,'msaa':1}");
	same_with_and_without("debug shadow", doc);
}
