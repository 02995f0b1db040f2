/* tests/gpu — the main pass's specialized paths draw what its general path draws. A scene's
 * light types and a PCF radius that all its lights share are specialization constants of
 * mesh.frag (renderer/record.c main_key): with only suns, the point and spot code of the
 * shadow lookup and of the light direction fold away; with one radius, the PCF loops unroll.
 * UMBRA_SPECIALIZE=0 (read per render) builds the general variant instead (every light type,
 * the radius read per light); each scene renders both ways and the images must agree byte for
 * byte. EXR (float) images agree to 1e-5: LLVM may contract a multiply-add into an FMA in one
 * variant's unrolled loop and not in the other's, which moves a float by an ulp (1.2e-7 in 6 bytes of a
 * 128x96 sun scene did once the shadow planning changed) without changing any 8-bit pixel. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "test.h"

/* Renders doc specialized and general; fails when a byte differs or a render fails. */
static void same_specialized_and_general(const char *what, const char *doc)
{
	struct rnd_image fast, general;
	memset(&fast, 0, sizeof fast);
	memset(&general, 0, sizeof general);
	if (!gpu_render(&fast, "%s", doc)) return;
	setenv("UMBRA_SPECIALIZE", "0", 1);
	bool ok = gpu_render(&general, "%s", doc);
	unsetenv("UMBRA_SPECIALIZE");
	if (ok) {
		size_t bytes = (size_t)fast.height * fast.stride;
		CHECK(fast.width == general.width && fast.height == general.height && fast.stride == general.stride,
		      "%s: image sizes differ", what);
		long diff = 0;
		size_t first = 0;
		double worst = 0;
		const unsigned char *a = fast.pixels, *b = general.pixels;
		bool floats = fast.format == RND_PIXELS_RGBA32F;
		if (fast.height == general.height && fast.stride == general.stride && floats) {
			const float *fa = fast.pixels, *fb = general.pixels;
			for (size_t i = 0; i < bytes / sizeof(float); i++) {
				double d = fabs((double)fa[i] - (double)fb[i]);
				if (d > worst) worst = d;
				if (d > 1e-5 && !diff++) first = i * sizeof(float);
			}
		} else if (fast.height == general.height && fast.stride == general.stride) {
			for (size_t i = 0; i < bytes; i++)
				if (a[i] != b[i] && !diff++) first = i;
		}
		CHECK(diff == 0, "%s: the specialized pass changed %ld of %zu bytes (first at byte %zu; largest float "
		      "difference %g)", what, diff, bytes, first, worst);
		rnd_image_release(&general);
	}
	rnd_image_release(&fast);
}

/* A floor, a sphere, a box on it; `lights` and `output` as JSON members (single quotes). */
static void spec_doc(char *buf, size_t n, const char *lights, const char *output)
{
	snprintf(buf, n,
	         "{'width':128,'height':96,"
	         "'camera':{'type':'perspective','position':[4,3,4],'target':[0,0.6,0],'up':[0,1,0],'fov_y':45},"
	         "'materials':{'m':{'base_color':[0.7,0.6,0.5],'roughness':0.5}},"
	         "'objects':[{'shape':'plane','size':[10,10]},"
	         "{'shape':'sphere','radius':0.8,'segments':32,'transform':{'translation':[0,0.8,0]},'material':'m'},"
	         "{'shape':'box','size':[0.5,1.2,0.5],'transform':{'translation':[1.4,0.6,-0.6]}}],"
	         "'lights':[%s],'output':%s}",
	         lights, output);
}

/* One sun, PCF radius 1 (the thumbnail's case): both the sun-only fold and the radius. */
TEST(specialize_sun_pcf_same_image)
{
	char doc[4096];
	const char *sun = "{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':3,'shadow':{'filter':'pcf'}}";
	spec_doc(doc, sizeof doc, sun, "{'msaa':4}");
	same_specialized_and_general("sun pcf msaa 4", doc);
	spec_doc(doc, sizeof doc, sun, "{'msaa':1,'format':'exr'}");
	same_specialized_and_general("sun pcf exr", doc);
	/* Cascades (several views per light), the default radius folded. */
	spec_doc(doc, sizeof doc,
	         "{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':3,"
	         "'shadow':{'filter':'pcf','pcf_radius':1,'directional':{'mode':'cascades'}}}",
	         "{'msaa':4}");
	same_specialized_and_general("sun cascades pcf 2", doc);
}

/* A spot and a point sharing the default radius with the sun (radius folded, light types
 * not), then shared radius 3 (only the default is folded: read per light), then three
 * different radii (read per light) and a point light's cube faces. */
TEST(specialize_mixed_lights_same_image)
{
	char doc[4096];
	spec_doc(doc, sizeof doc,
	         "{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':2,'shadow':{'filter':'pcf','pcf_radius':3}},"
	         "{'type':'spot','position':[2,3,1],'direction':[-0.5,-1,-0.2],'outer_angle':40,'intensity':30,"
	         "'shadow':{'filter':'pcf','pcf_radius':3}},"
	         "{'type':'point','position':[-1.5,2,1.5],'intensity':20,'shadow':{'filter':'pcf','pcf_radius':3}}",
	         "{'msaa':4}");
	same_specialized_and_general("shared radius 3", doc);
	spec_doc(doc, sizeof doc,
	         "{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':2,'shadow':{'filter':'pcf'}},"
	         "{'type':'spot','position':[2,3,1],'direction':[-0.5,-1,-0.2],'outer_angle':40,'intensity':30,"
	         "'shadow':{'filter':'pcf'}},"
	         "{'type':'point','position':[-1.5,2,1.5],'intensity':20,'shadow':{'filter':'pcf'}}",
	         "{'msaa':4}");
	same_specialized_and_general("shared default radius", doc);
	spec_doc(doc, sizeof doc,
	         "{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':2,'shadow':{'filter':'pcf','pcf_radius':0}},"
	         "{'type':'spot','position':[2,3,1],'direction':[-0.5,-1,-0.2],'outer_angle':40,'intensity':30,"
	         "'shadow':{'filter':'pcf','pcf_radius':2}},"
	         "{'type':'point','position':[-1.5,2,1.5],'intensity':20,'shadow':{'filter':'hard'}}",
	         "{'msaa':1,'format':'exr'}");
	same_specialized_and_general("radii 0 and 2, hard", doc);
}

/* Lights of different filters in one scene: the filters' code is shared by one variant, and
 * pcf() runs for every light under a mask with its radius read per light (-1, no tap, for the
 * others; shading.glsl sample_view). Each light's shadow (debug view) must be what it is when
 * the light is alone, where its filter is the scene's only one (PCF: the folded radius). */
TEST(specialize_mixed_filters_same_shadow)
{
	static const char *const light[3] = {
		"{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':2,'angular_diameter':3}",
		"{'type':'spot','position':[2,3,1],'direction':[-0.5,-1,-0.2],'outer_angle':40,'intensity':30,'radius':0.1}",
		"{'type':'point','position':[-1.5,2,1.5],'intensity':20}",   /* no radius: PCF, default radius */
	};
	char lights[1024], out[128], doc[4096];
	snprintf(lights, sizeof lights, "%s,%s,%s", light[0], light[1], light[2]);
	for (int k = 0; k < 3; k++) {
		struct rnd_image mixed, alone;
		snprintf(out, sizeof out, "{'debug':'shadow','debug_light':%d}", k);
		spec_doc(doc, sizeof doc, lights, out);
		if (!gpu_render(&mixed, "%s", doc)) return;
		spec_doc(doc, sizeof doc, light[k], "{'debug':'shadow','debug_light':0}");
		if (gpu_render(&alone, "%s", doc)) {
			const unsigned char *p = alone.pixels;
			long dark = 0;
			for (uint32_t y = 0; y < alone.height; y++)
				for (uint32_t x = 0; x < alone.width; x++) dark += p[(size_t)y * alone.stride + 4 * x] < 128;
			CHECK(dark > 50, "light %d: casts almost no shadow alone (%ld pixels), the test sees nothing", k, dark);
			long diff = gpu_bytes_differ(&mixed, &alone, NULL);
			CHECK(diff == 0, "light %d: its shadow beside the others differs from alone in %ld bytes", k, diff);
			rnd_image_release(&alone);
		}
		rnd_image_release(&mixed);
	}
}
