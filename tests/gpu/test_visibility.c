/* tests/gpu — the visibility pass (renderer/visibility.c): each shadowed light's shadow computed
 * once per pixel before the main pass, which reads it instead of running the filters itself.
 * It is an optimisation, so the tests hold it to changing nothing a viewer can see:
 *   - scenes of small triangles under several lights (every light type, soft and hard, PCF,
 *     PCSS, VSM, contact shadows, an orthographic camera, MSAA 1) rendered with the pass
 *     (UMBRA_VISIBILITY=1) and without (=0): the pass ran (rnd_timings), and no pixel differs
 *     by more than 2 8-bit steps except on edges of the picture (a neighbour 12 steps apart,
 *     at or next to the pixel) and at most two by up to 6 (silhouettes against a surface of
 *     about the same brightness, which the 12 steps do not see; the main pass's own lookups
 *     there look at the samples its fragment covers, the pass at a pixel centre):
 *     at silhouettes MSAA shades a surface at pixels whose centre shows another one, and the
 *     pass takes that surface's value from a neighbour pixel;
 *   - where it must not run (one light with a narrow filter, a debug view, alpha-tested
 *     materials) it does not;
 *   - the default choice: studio-like small triangles under two lights take the pass, a floor
 *     under the same lights does not; under one soft light only a dense mesh takes it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"

/* Renders doc with env UMBRA_VISIBILITY=value; *views: the views that used the pass. */
static bool render_vis(struct rnd_image *img, const char *value, const char *doc, uint32_t *views)
{
	if (value) setenv("UMBRA_VISIBILITY", value, 1);
	/* the pass's shadows as the per-fragment shading reads them: not shaded per pixel
	 * (renderer/deferred.h, tests/gpu/test_deferred.c) */
	setenv("UMBRA_PIXEL_SHADING", "0", 1);
	bool ok = gpu_render(img, "%s", doc);
	unsetenv("UMBRA_PIXEL_SHADING");
	unsetenv("UMBRA_VISIBILITY");
	*views = ok ? gpu_last_timings.visibility_views : 0;
	return ok;
}

/* Pixels of a and b that differ by more than 2 steps: *edge of them on an edge of b, *inner
 * the others; *worst_inner the largest difference of those. */
static void pixels_differ(const struct rnd_image *a, const struct rnd_image *b, long *edge, long *inner, int *worst_inner)
{
	*edge = *inner = 0;
	*worst_inner = 0;
	for (int j = 0; j < (int)a->height; j++)
		for (int i = 0; i < (int)a->width; i++) {
			int d = gpu_px_diff(a, i, j, b, i, j);
			if (d <= 2) continue;
			if (gpu_on_edge(b, i, j)) {
				(*edge)++;
			} else {
				(*inner)++;
				if (d > *worst_inner) *worst_inner = d;
			}
		}
}

/* Renders doc with the pass and without: the pass must have run, and its image differ from the
 * filters' own by more than 2 steps only on edges, in at most 0.5 % of the pixels, and at two
 * pixels elsewhere by up to 6. */
static void same_with_and_without(const char *what, const char *doc)
{
	struct rnd_image on, off;
	uint32_t von = 0, voff = 0;
	if (!render_vis(&on, "1", doc, &von)) return;
	if (render_vis(&off, "0", doc, &voff)) {
		CHECK(von >= 1 && voff == 0, "%s: the pass ran in %u / %u views (forced on / off)", what, von, voff);
		CHECK(on.width == off.width && on.height == off.height && on.format == RND_PIXELS_RGBA8, "%s: image sizes", what);
		long edge = 0, inner = 0;
		int worst = 0;
		pixels_differ(&on, &off, &edge, &inner, &worst);
		CHECK(inner <= 2 && worst <= 6, "%s: %ld pixels off the picture's edges differ by more than 2 steps (up to %d)",
		      what, inner, worst);
		CHECK(edge * 200 <= (long)on.width * on.height, "%s: %ld edge pixels of %u differ by more than 2 steps", what,
		      edge, on.width * on.height);
		rnd_image_release(&off);
	}
	rnd_image_release(&on);
}

/* Small triangles (spheres and cylinders), boxes and a floor; `lights`, `extra` root members. */
static void vis_doc(char *buf, size_t n, const char *camera, const char *lights, const char *extra)
{
	snprintf(buf, n,
	         "{'width':160,'height':120,'camera':%s,"
	         "'materials':{'m':{'base_color':[0.7,0.6,0.5],'roughness':0.5},"
	         "'g':{'base_color':[1,0.8,0.3],'roughness':0.3,'metallic':1}},"
	         "'objects':[{'shape':'plane','size':[10,10]},"
	         "{'shape':'sphere','radius':0.6,'segments':64,'transform':{'translation':[0,0.6,0]},'material':'m'},"
	         "{'shape':'sphere','radius':0.3,'segments':48,'transform':{'translation':[1.2,0.3,0.8]},'material':'g'},"
	         "{'shape':'cylinder','radius':0.2,'height':1.4,'segments':48,'transform':{'translation':[-1.1,0.7,0.4]}},"
	         "{'shape':'box','size':[0.5,1.0,0.5],'transform':{'translation':[0.9,0.5,-1.0]}}],"
	         "'lights':[%s]%s}",
	         camera, lights, extra);
}

static const char *persp = "{'type':'perspective','position':[4,3,4],'target':[0,0.5,0],'up':[0,1,0],'fov_y':45}";

/* Every light type: a soft sun (PCSS), soft and hard spots, soft and hard points. */
static const char *mixed =
	"{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':2,'angular_diameter':2},"
	"{'type':'spot','position':[-2,4,1],'direction':[2,-4,-1],'intensity':40,'outer_angle':40,'radius':0.1},"
	"{'type':'spot','position':[2,4,-2],'direction':[-2,-4,2],'intensity':40,'outer_angle':30},"
	"{'type':'point','position':[0.5,2.2,1.5],'intensity':12,'range':10,'radius':0.15},"
	"{'type':'point','position':[-1.5,1.8,-1],'intensity':8,'range':8}";

TEST(visibility_pass_draws_what_the_filters_draw)
{
	char doc[8192];
	vis_doc(doc, sizeof doc, persp, mixed, "");
	same_with_and_without("every light type, default filters", doc);
	vis_doc(doc, sizeof doc, persp, mixed, ",'shadows':{'filter':'pcf'}");
	same_with_and_without("every light type, pcf", doc);
	vis_doc(doc, sizeof doc, persp, mixed, ",'shadows':{'filter':'vsm'}");
	same_with_and_without("every light type, vsm", doc);
	vis_doc(doc, sizeof doc, persp, mixed, ",'shadows':{'contact':{'enabled':true}}");
	same_with_and_without("contact shadows", doc);
	vis_doc(doc, sizeof doc, "{'type':'orthographic','position':[4,3,4],'target':[0,0.5,0],'up':[0,1,0],'height':4}",
	        mixed, "");
	same_with_and_without("orthographic camera", doc);
	vis_doc(doc, sizeof doc, persp, mixed, ",'output':{'msaa':1}");
	same_with_and_without("msaa 1", doc);
}

/* Where the pass must not run, forcing it on changes nothing. */
TEST(visibility_pass_stays_off_where_it_cannot_help)
{
	char doc[8192];
	struct rnd_image img;
	uint32_t views = 0;
	const char *one = "{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':3}";
	vis_doc(doc, sizeof doc, persp, one, "");
	if (render_vis(&img, NULL, doc, &views)) {
		CHECK(views == 0, "one light: the pass ran by default");
		rnd_image_release(&img);
	}
	/* five lights over small triangles, but one-fetch filters: cheaper than the passes */
	static const char *narrow[] = {"'hard'", "'vsm'", "'pcf','pcf_radius':1"};
	for (int f = 0; f < 3; f++) {
		char extra[128];
		snprintf(extra, sizeof extra, ",'shadows':{'filter':%s}", narrow[f]);
		vis_doc(doc, sizeof doc, persp, mixed, extra);
		if (render_vis(&img, NULL, doc, &views)) {
			CHECK(views == 0, "filter %s: the pass ran by default", narrow[f]);
			rnd_image_release(&img);
		}
	}
	vis_doc(doc, sizeof doc, persp, mixed, ",'output':{'debug':'shadow','debug_light':1}");
	if (render_vis(&img, "1", doc, &views)) {
		CHECK(views == 0, "debug view: the pass ran");
		rnd_image_release(&img);
	}
	/* alpha mask: what shows through cut-out texels must keep its own shadow */
	char masked[8192];
	snprintf(masked, sizeof masked,
	         "{'width':64,'height':48,'camera':%s,"
	         "'materials':{'leaf':{'base_color':[0.3,0.7,0.3,0.4],'alpha_mode':'mask'}},"
	         "'objects':[{'shape':'plane','size':[10,10]},"
	         "{'shape':'sphere','radius':0.6,'segments':64,'transform':{'translation':[0,0.6,0]},'material':'leaf'}],"
	         "'lights':[%s]}",
	         persp, mixed);
	if (render_vis(&img, "1", masked, &views)) {
		CHECK(views == 0, "alpha-masked material: the pass ran");
		rnd_image_release(&img);
	}
}

/* A wavy patch of N x N cells (2 N² triangles of about a pixel) and a sphere over it, under
 * `lights`: a dense model's thumbnail in small. */
static char *dense_doc(int n, const char *lights)
{
	size_t cap = (size_t)(n + 1) * (n + 1) * 40 + (size_t)n * n * 6 * 8 + 2048;
	char *pos = malloc(cap), *idx = malloc(cap), *doc = malloc(2 * cap);
	if (!pos || !idx || !doc) {
		free(pos); free(idx); free(doc);
		return NULL;
	}
	size_t pn = 0, in = 0;
	for (int j = 0; j <= n; j++)
		for (int i = 0; i <= n; i++) {
			double x = -1.5 + 3.0 * i / n, z = -1.5 + 3.0 * j / n;
			pn += (size_t)snprintf(pos + pn, cap - pn, "%s%.5f,%.5f,%.5f", pn ? "," : "", x,
			                       0.12 * sin(4 * x) * cos(3 * z), z);
		}
	for (int j = 0; j < n; j++)
		for (int i = 0; i < n; i++) {
			int a = j * (n + 1) + i, b = a + n + 1;
			in += (size_t)snprintf(idx + in, cap - in, "%s%d,%d,%d,%d,%d,%d", in ? "," : "", a, b, a + 1, a + 1, b, b + 1);
		}
	snprintf(doc, 2 * cap,
	         "{'width':160,'height':120,'camera':%s,'objects':[{'shape':'mesh','positions':[%s],'indices':[%s]},"
	         "{'shape':'sphere','radius':0.4,'transform':{'translation':[0.2,0.7,0.1]}}],'lights':[%s]}",
	         persp, pos, idx, lights);
	free(pos);
	free(idx);
	return doc;
}

static const char *soft_sun = "{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':3,'angular_diameter':3}";

/* One soft light over a dense mesh: the pass pays (a thumbnail of a 124k-triangle OBJ under the
 * preset's sun: 110 -> 95 ms) and draws what the filters draw. */
TEST(visibility_pass_one_soft_light_over_a_dense_mesh)
{
	/* 104² cells: 21,632 two-sided triangles, over the depth pre-pass's 20,000, which the main
	 * pass without the visibility pass draws and the one reading it does not (record.c) */
	char *doc = dense_doc(104, soft_sun);
	REQUIRE(doc, "out of memory");
	struct rnd_image img;
	uint32_t views = 0;
	if (render_vis(&img, NULL, doc, &views)) {
		CHECK(views == 1, "21k triangles under one soft sun: the pass did not run");
		rnd_image_release(&img);
	}
	same_with_and_without("a dense mesh under one soft sun", doc);
	/* at MSAA 1 each pixel is shaded by one triangle: nothing for the pass to save */
	char *one = malloc(strlen(doc) + 64);
	REQUIRE(one, "out of memory");
	memcpy(one, doc, strlen(doc) - 1);
	strcpy(one + strlen(doc) - 1, ",'output':{'msaa':1}}");
	if (render_vis(&img, NULL, one, &views)) {
		CHECK(views == 0, "one soft sun at MSAA 1: the pass ran");
		rnd_image_release(&img);
	}
	free(one);
	free(doc);
	/* the same patch of 8 x 8 cells: the filters cost less than the passes */
	doc = dense_doc(8, soft_sun);
	REQUIRE(doc, "out of memory");
	if (render_vis(&img, NULL, doc, &views)) {
		CHECK(views == 0, "128 triangles under one soft sun: the pass ran");
		rnd_image_release(&img);
	}
	free(doc);
}

/* The default: small triangles under two lights take the pass; a floor and a box do not. */
TEST(visibility_pass_default_choice)
{
	char doc[8192];
	struct rnd_image img;
	uint32_t views = 0;
	const char *two = "{'type':'spot','position':[-2,4,1],'direction':[2,-4,-1],'intensity':40,'radius':0.1},"
	                  "{'type':'point','position':[0.5,2.2,1.5],'intensity':12,'range':10,'radius':0.15}";
	vis_doc(doc, sizeof doc, persp, two, "");
	if (render_vis(&img, NULL, doc, &views)) {
		CHECK(views == 1, "spheres under two lights: the pass did not run");
		rnd_image_release(&img);
	}
	snprintf(doc, sizeof doc,
	         "{'width':160,'height':120,'camera':%s,'objects':[{'shape':'plane','size':[10,10]},"
	         "{'shape':'box','size':[0.5,1.0,0.5],'transform':{'translation':[0.9,0.5,-1.0]}}],'lights':[%s]}",
	         persp, two);
	if (render_vis(&img, NULL, doc, &views)) {
		CHECK(views == 0, "a floor and a box: the pass ran");
		rnd_image_release(&img);
	}
}

/* A paced render draws the view in bands of rows, each with its own surfaces and visibility
 * passes: the same bytes as one submit (a pixel at a band's edge may read its neighbour in the
 * next band). */
TEST(visibility_pass_bands_give_the_same_bytes)
{
	struct rnd_context *ctx = gpu_ctx();
	REQUIRE(ctx);
	char doc[8192];
	vis_doc(doc, sizeof doc, persp, mixed, "");
	struct api_scene *s = gpu_parse(doc);
	REQUIRE(s);
	setenv("UMBRA_VISIBILITY", "1", 1);
	struct rnd_image whole = {0}, bands = {0};
	struct rnd_timings tm = {0};
	struct rnd_error err = {0};
	uint32_t before = rnd_context_validation_messages(ctx);
	CHECK(rnd_render(ctx, &s->scene, &whole, &tm, &err) == RND_OK, "one submit: %s", err.msg);
	CHECK(tm.visibility_views == 1, "the pass did not run");
	s->scene.band_rows = 7;
	CHECK(rnd_render(ctx, &s->scene, &bands, NULL, &err) == RND_OK, "bands of 7 rows: %s", err.msg);
	unsetenv("UMBRA_VISIBILITY");
	CHECK(whole.pixels && bands.pixels && whole.stride == bands.stride &&
	      !memcmp(whole.pixels, bands.pixels, (size_t)whole.height * whole.stride),
	      "bands of 7 rows changed the image");
	CHECK(rnd_context_validation_messages(ctx) == before, "validation messages");
	rnd_image_release(&whole);
	rnd_image_release(&bands);
	api_scene_free(s);
}
