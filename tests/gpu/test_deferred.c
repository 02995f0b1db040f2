/* tests/gpu — pixel shading (renderer/deferred.h): a view of dense, plain surfaces shaded once per
 * pixel centre, each sample then taking the colour of the pixel centre that shows its surface,
 * instead of the main pass shading every fragment. The model: a bumpy closed sphere of ~9,000
 * triangles with a colour per vertex (a binary PLY, under the level-of-detail size: drawn in
 * full), under the thumbnail preset (the studio environment and its 12 shadow directions, no
 * light of the scene's own: pixel shading runs the surfaces pass for itself; a ground shadow
 * catcher), 160^2.
 *   - it ran, and inside surfaces the picture is per-fragment shading's: pixels off the
 *     picture's edges differ by at most a few steps, rarely;
 *   - along edges it is as close to a 4x4-supersampled render of the same scene as per-fragment
 *     shading with MSAA 4 is (box-filtered down, the mean error over the reference's edge
 *     pixels), opaque and transparent (the catcher's alpha);
 *   - it stays off where the surfaces pass cannot carry what shading needs (an alpha-tested
 *     material beside the model, a debug view), without MSAA, and where the environment map is
 *     the background (the resolve draws the clear colour where nothing was drawn). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "test.h"
#include "util.h"

/* A binary little-endian PLY of a bumpy closed sphere, nu x nv quads (poles fanned), a colour
 * per vertex; malloc'd. */
static uint8_t *bumpy_ply(int nu, int nv, size_t *len)
{
	int nvert = nu * (nv - 1) + 2, nface = 2 * nu * (nv - 1);
	char head[400];
	int hl = snprintf(head, sizeof head,
	                  "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
	                  "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
	                  "element face %d\nproperty list uchar int vertex_indices\nend_header\n", nvert, nface);
	size_t n = (size_t)hl + (size_t)nvert * 15 + (size_t)nface * 13;
	uint8_t *b = malloc(n), *p = b;
	if (!b) return NULL;
	memcpy(p, head, (size_t)hl);
	p += hl;
	for (int v = 0; v < nvert; v++) {
		int j = v == 0 ? 0 : v == nvert - 1 ? nv : 1 + (v - 1) / nu, i = v == 0 || v == nvert - 1 ? 0 : (v - 1) % nu;
		double th = M_PI * j / nv, ph = 2 * M_PI * i / nu;
		double x = sin(th) * cos(ph), y = cos(th), z = sin(th) * sin(ph);
		double r = 1 + 0.07 * sin(7 * x + 3 * y) * cos(5 * z - 2 * y) + 0.03 * sin(19 * y + 9 * x);
		float f[3] = {(float)(r * x), (float)(r * y + 1.0), (float)(r * z)};
		memcpy(p, f, 12);
		p[12] = (uint8_t)(127 + 120 * sin(3 * y));
		p[13] = (uint8_t)(127 + 120 * sin(4 * x + 1));
		p[14] = (uint8_t)(127 + 120 * cos(5 * z));
		p += 15;
	}
	/* rings 1..nv-1 are vertices 1 + (ring - 1) nu ...; wound counter-clockwise from outside */
	for (int j = 0; j < nv; j++)
		for (int i = 0; i < nu; i++) {
			int i1 = (i + 1) % nu;
			int a = j == 0 ? 0 : 1 + (j - 1) * nu + i, b2 = j == 0 ? 0 : 1 + (j - 1) * nu + i1;
			int c = j == nv - 1 ? nvert - 1 : 1 + j * nu + i, d = j == nv - 1 ? nvert - 1 : 1 + j * nu + i1;
			int t[2][3] = {{a, b2, c}, {b2, d, c}};
			for (int k = 0; k < 2; k++) {
				if ((j == 0 && k == 0) || (j == nv - 1 && k == 1)) continue;
				*p++ = 3;
				int w[3] = {t[k][0], t[k][2], t[k][1]};
				memcpy(p, w, 12);
				p += 12;
			}
		}
	*len = (size_t)(p - b);
	return b;
}

static char *model_b64;

static const char *model(void)
{
	if (!model_b64) {
		size_t n = 0;
		uint8_t *ply = bumpy_ply(96, 48, &n);
		model_b64 = ply ? test_b64(ply, n) : NULL;
		free(ply);
	}
	return model_b64;
}

/* The thumbnail of the model at side x side, `extra` root members; pixel shading on ("1") or
 * off ("0"); *shaded: views shaded per pixel. */
static bool thumb(struct rnd_image *img, int side, const char *on, const char *extra, uint32_t *shaded)
{
	if (!model()) { CHECK(0, "out of memory"); return false; }
	setenv("UMBRA_PIXEL_SHADING", on, 1);
	bool ok = gpu_render(img, "{'preset':'thumbnail','width':%d,'height':%d%s,"
	                     "'objects':[{'shape':'model','format':'ply','data':'%s'}]}", side, side, extra, model());
	unsetenv("UMBRA_PIXEL_SHADING");
	*shaded = ok ? gpu_last_timings.pixel_shaded_views : 0;
	return ok;
}

/* Mean absolute error (0..1, over the four channels) of img against ref box-filtered down k x k,
 * over the pixels on an edge of the filtered reference (*n of them). */
static double edge_error(const struct rnd_image *ref, const struct rnd_image *img, int k, long *n)
{
	struct rnd_image down = *img;
	down.pixels = malloc((size_t)img->height * img->stride);
	if (!down.pixels) return INFINITY;
	for (int j = 0; j < (int)img->height; j++)
		for (int i = 0; i < (int)img->width; i++)
			for (int c = 0; c < 4; c++) {
				unsigned t = 0;
				for (int y = 0; y < k; y++)
					for (int x = 0; x < k; x++) t += gpu_px8(ref, i * k + x, j * k + y)[c];
				((uint8_t *)down.pixels)[(size_t)j * down.stride + (size_t)i * 4 + (size_t)c] =
					(uint8_t)((t + (unsigned)(k * k) / 2) / (unsigned)(k * k));
			}
	double sum = 0;
	*n = 0;
	for (int j = 0; j < (int)img->height; j++)
		for (int i = 0; i < (int)img->width; i++) {
			if (!gpu_on_edge(&down, i, j)) continue;
			for (int c = 0; c < 4; c++) sum += fabs(gpu_chan(&down, i, j, c) - gpu_chan(img, i, j, c)) / 4.0;
			(*n)++;
		}
	free(down.pixels);
	return *n ? sum / (double)*n : INFINITY;
}

/* Pixel shading against per-fragment shading and against a 4x4-supersampled reference. */
static void against_reference(const char *what, const char *extra)
{
	struct rnd_image on, off, ref;
	uint32_t von = 0, voff = 0, vref = 0;
	if (!thumb(&on, 160, "1", extra, &von)) return;
	if (!thumb(&off, 160, "0", extra, &voff)) { rnd_image_release(&on); return; }
	CHECK(von == 1 && voff == 0, "%s: shaded per pixel in %u / %u views (on / off)", what, von, voff);
	long inner = 0, worst = 0;
	for (int j = 0; j < (int)on.height; j++)
		for (int i = 0; i < (int)on.width; i++) {
			int d = gpu_px_diff(&on, i, j, &off, i, j);
			if (d <= 2 || gpu_on_edge(&off, i, j)) continue;
			inner++;
			if (d > worst) worst = d;
		}
	printf("  %s: %ld pixels off the edges differ by more than 2 steps (up to %ld)\n", what, inner, worst);
	CHECK(inner * 200 <= (long)on.width * on.height && worst <= 8,
	      "%s: %ld pixels off the picture's edges differ by more than 2 steps (up to %ld)", what, inner, worst);
	if (thumb(&ref, 640, "0", extra, &vref)) {
		long n_on = 0, n_off = 0;
		double e_on = edge_error(&ref, &on, 4, &n_on), e_off = edge_error(&ref, &off, 4, &n_off);
		printf("  %s: edge error against 4x4 supersampling, pixel shading %.4f, per fragment %.4f (%ld edge pixels)\n",
		       what, e_on, e_off, n_on);
		CHECK(n_on > 500, "%s: %ld edge pixels", what, n_on);
		CHECK(e_on <= 1.1 * e_off, "%s: edge error %.4f, per-fragment shading's %.4f", what, e_on, e_off);
		rnd_image_release(&ref);
	}
	rnd_image_release(&on);
	rnd_image_release(&off);
}

TEST(pixel_shading_is_per_fragment_shading_inside_and_as_good_at_edges)
{
	against_reference("opaque", "");
	against_reference("transparent", ",'output':{'transparent':true}");
}

TEST(pixel_shading_stays_off_where_the_surfaces_pass_cannot_shade)
{
	struct rnd_image img;
	uint32_t v = 1;
	if (thumb(&img, 96, "1", ",'output':{'msaa':1}", &v)) {
		CHECK(v == 0, "MSAA 1: shaded per pixel in %u views", v);
		rnd_image_release(&img);
	}
	v = 1;
	if (thumb(&img, 96, "1", ",'output':{'debug':'normals'}", &v)) {
		CHECK(v == 0, "a debug view: shaded per pixel in %u views", v);
		rnd_image_release(&img);
	}
	/* the preset's studio drawn behind the model: the resolve has no environment background */
	v = 1;
	if (thumb(&img, 96, "1", ",'environment':{'background':'map'}", &v)) {
		CHECK(v == 0, "the environment map as the background: shaded per pixel in %u views", v);
		rnd_image_release(&img);
	}
	/* an alpha-tested quad beside the model (the preset's objects are replaced: both given) */
	setenv("UMBRA_PIXEL_SHADING", "1", 1);
	bool ok = gpu_render(&img, "{'preset':'thumbnail','width':96,'height':96,"
	                     "'materials':{'cut':{'alpha_mode':'mask','base_color':[1,1,1,0.8]}},"
	                     "'objects':[{'shape':'model','format':'ply','data':'%s'},"
	                     "{'shape':'box','size':[0.5,0.5,0.5],'material':'cut','transform':{'translation':[1.5,0.25,0]}}]}",
	                     model());
	unsetenv("UMBRA_PIXEL_SHADING");
	if (ok) {
		CHECK(gpu_last_timings.visibility_views == 0 && gpu_last_timings.pixel_shaded_views == 0,
		      "an alpha-tested material: visibility pass / pixel shading in %u / %u views",
		      gpu_last_timings.visibility_views, gpu_last_timings.pixel_shaded_views);
		rnd_image_release(&img);
	}
}
