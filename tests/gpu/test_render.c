/* tests/gpu — beauty renders, debug views, camera conventions, lights and exposure, checked
 * against values computed here from the contract (§1, §2, §4, §7), never against the renderer's
 * own output. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "test.h"

static double luma(const struct rnd_image *img, int i, int j)
{
	return 0.2126 * gpu_chan(img, i, j, 0) + 0.7152 * gpu_chan(img, i, j, 1) + 0.0722 * gpu_chan(img, i, j, 2);
}

/* Mean linear value (decoded sRGB) of channel c over the square of half size r around (i, j). */
static double mean_linear(const struct rnd_image *img, int i, int j, int r, int c)
{
	double s = 0;
	int n = 0;
	for (int y = j - r; y <= j + r; y++)
		for (int x = i - r; x <= i + r; x++) { s += gpu_srgb_decode(gpu_chan(img, x, y, c)); n++; }
	return s / n;
}

/* ---- 1. sphere on plane (the thumbnail scene at 256 px) ---- */

#define THUMB                                                                                          \
	"{'width':256,'height':256,"                                                                   \
	"'camera':{'type':'perspective','position':[4,3,4],'target':[0,0.8,0],'up':[0,1,0],'fov_y':40}," \
	"'environment':{'background':[0.5,0.5,0.5]},"                                                  \
	"'materials':{'grey':{'base_color':[0.7,0.7,0.7],'roughness':0.8,'metallic':0}},"              \
	"'objects':[{'shape':'plane','size':[10,10],'material':'grey'},"                               \
	"{'shape':'sphere','radius':1,'segments':128,'material':'grey','transform':{'translation':[0,1,0]}}]," \
	"'lights':[{'type':'directional','direction':[-0.5,-1,-0.3],'color':[1,1,1],'intensity':3}]," \
	"'output':{'format':'png'}}"

/* Analytic classes of the thumbnail scene's pixels. */
static void thumb_classes(uint8_t *cls, struct gpu_cam *cam)
{
	gpu_cam_persp(cam, v3_make(4, 3, 4), v3_make(0, 0.8, 0), v3_make(0, 1, 0), 40, 256, 256);
	v3 C = v3_make(0, 1, 0), L = v3_norm(v3_make(0.5, 1, 0.3));
	for (int j = 0; j < 256; j++) {
		for (int i = 0; i < 256; i++) {
			v3 o, d;
			gpu_cam_ray(cam, i + 0.5, j + 0.5, &o, &d);
			double ts = gpu_ray_sphere(o, d, C, 1, 0), tg = gpu_ray_ground(o, d, 0, 0, 0, 5);
			uint8_t k;
			if (ts < 0 && tg < 0) k = GPU_CLS_BG;
			else if (ts > 0 && (tg < 0 || ts < tg)) k = GPU_CLS_OBJ;
			else {
				v3 p = v3_add(o, v3_scale(d, tg));
				k = gpu_ray_sphere(p, L, C, 1, 1e-9) > 0 ? GPU_CLS_SHADOW : GPU_CLS_LIT;
			}
			cls[j * 256 + i] = k;
		}
	}
}

TEST(beauty_shadow_under_sphere_is_darker)
{
	static uint8_t cls[256 * 256];
	struct gpu_cam cam;
	thumb_classes(cls, &cam);
	struct rnd_image img;
	REQUIRE(gpu_render(&img, THUMB));
	REQUIRE(img.width == 256 && img.height == 256 && img.format == RND_PIXELS_RGBA8);

	/* The centre of the shadow (sphere centre projected along the light onto y = 0) is
	 * (-0.5, 0, -0.3), hidden behind the sphere from this camera; use the visible ground
	 * between the contact point and the camera, which the analytic classes call shadowed,
	 * and compare with ground far from the sphere (> 3 m from the shadow centre). */
	double sh = 0, lit = 0;
	int nsh = 0, nlit = 0;
	v3 sc = v3_make(-0.5, 0, -0.3);
	for (int j = 0; j < 256; j++) {
		for (int i = 0; i < 256; i++) {
			uint8_t k = cls[j * 256 + i];
			if ((k != GPU_CLS_SHADOW && k != GPU_CLS_LIT) || gpu_near_edge(cls, 256, 256, i, j, 3)) continue;
			if (k == GPU_CLS_SHADOW) { sh += luma(&img, i, j); nsh++; continue; }
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			v3 p = v3_add(o, v3_scale(d, gpu_ray_ground(o, d, 0, 0, 0, 5)));
			if (v3_len(v3_sub(p, sc)) > 3) { lit += luma(&img, i, j); nlit++; }
		}
	}
	/* Also the single ground point right in front of the contact point (0.35, 0, 0.35). */
	double px, py;
	gpu_cam_project(&cam, v3_make(0.35, 0, 0.35), &px, &py);
	int pi = (int)px, pj = (int)py;
	printf("    shadowed ground px %d (mean %.3f), far lit ground px %d (mean %.3f), contact px (%d,%d) class %d "
	       "value %.3f\n", nsh, nsh ? sh / nsh : 0, nlit, nlit ? lit / nlit : 0, pi, pj, cls[pj * 256 + pi],
	       luma(&img, pi, pj));
	REQUIRE(nsh >= 30 && nlit >= 1000, "shadow %d lit %d", nsh, nlit);
	sh /= nsh;
	lit /= nlit;
	CHECK(sh < 0.6 * lit, "shadowed ground %.3f is not clearly darker than lit ground %.3f", sh, lit);
	CHECK(cls[pj * 256 + pi] == GPU_CLS_SHADOW, "test geometry: contact point not in visible shadow");
	CHECK(luma(&img, pi, pj) < 0.6 * lit, "ground by the contact point %.3f vs lit %.3f", luma(&img, pi, pj), lit);
	rnd_image_release(&img);
}

TEST(beauty_background_is_srgb_of_background_colour)
{
	static uint8_t cls[256 * 256];
	struct gpu_cam cam;
	thumb_classes(cls, &cam);
	struct rnd_image img;
	REQUIRE(gpu_render(&img, THUMB));
	int expect = (int)lround(gpu_srgb_encode(0.5) * 255); /* 188 */
	/* Every corner that the analytic model says sees no geometry (top corners do). */
	int corners[4][2] = {{0, 0}, {255, 0}, {0, 255}, {255, 255}}, checked = 0;
	for (int c = 0; c < 4; c++) {
		int i = corners[c][0], j = corners[c][1];
		if (cls[j * 256 + i] != GPU_CLS_BG || gpu_near_edge(cls, 256, 256, i, j, 2)) continue;
		checked++;
		const uint8_t *p = gpu_px8(&img, i, j);
		for (int ch = 0; ch < 3; ch++)
			CHECK(abs(p[ch] - expect) <= 1, "corner (%d,%d) channel %d = %d, expected %d", i, j, ch, p[ch], expect);
		CHECK(p[3] == 255, "alpha %d", p[3]);
	}
	CHECK(checked >= 2, "only %d background corners", checked);
	rnd_image_release(&img);
}

TEST(beauty_is_deterministic)
{
	struct rnd_image a, b;
	REQUIRE(gpu_render(&a, THUMB));
	if (!gpu_render(&b, THUMB)) { rnd_image_release(&a); return; }
	REQUIRE(a.width == b.width && a.height == b.height);
	long diff = 0;
	for (uint32_t j = 0; j < a.height; j++)
		diff += memcmp((uint8_t *)a.pixels + j * a.stride, (uint8_t *)b.pixels + j * b.stride, a.width * 4) != 0;
	CHECK(diff == 0, "%ld rows differ between two renders of the same scene", diff);
	rnd_image_release(&a);
	rnd_image_release(&b);
}

/* ---- 5. debug views ---- */

TEST(debug_normals_plane_from_above)
{
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':64,'height':64,"
	                         "'camera':{'type':'perspective','position':[0.5,6,1],'target':[0,0,0],'fov_y':30},"
	                         "'objects':[{'shape':'plane','size':[10,10]}],"
	                         "'lights':[{'type':'directional','direction':[0,-1,0]}],"
	                         "'output':{'debug':'normals','msaa':1}}"));
	int bad = 0;
	for (int j = 8; j < 56; j += 4)
		for (int i = 8; i < 56; i += 4) {
			const uint8_t *p = gpu_px8(&img, i, j);
			/* normal (0,1,0) * 0.5 + 0.5 = (0.5, 1, 0.5) -> 127.5 / 255 / 127.5 */
			if (abs(p[0] - 128) > 1 || p[1] < 254 || abs(p[2] - 128) > 1) {
				if (!bad++) CHECK(0, "pixel (%d,%d) = %d %d %d, expected ~128 255 128", i, j, p[0], p[1], p[2]);
			}
		}
	CHECK(bad == 0, "%d sampled pixels off", bad);
	rnd_image_release(&img);
}

TEST(debug_depth_increases_along_ground)
{
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':64,'height':128,"
	                         "'camera':{'type':'perspective','position':[0,2,6],'target':[0,0,0],'fov_y':50},"
	                         "'objects':[{'shape':'plane','size':[40,40]}],"
	                         "'lights':[{'type':'directional','direction':[0,-1,0]}],"
	                         "'output':{'debug':'depth','msaa':1}}"));
	struct gpu_cam cam;
	gpu_cam_persp(&cam, v3_make(0, 2, 6), v3_make(0, 0, 0), v3_make(0, 1, 0), 50, 64, 128);
	/* Walk the centre column from the bottom (near ground) up while the ray still hits the plane:
	 * the view depth grows, so must the debug value (non-decreasing, and clearly increasing). */
	int first = -1, last = -1, prev = -1, decreases = 0, rows = 0;
	for (int j = 127; j >= 0; j--) {
		v3 o, d;
		gpu_cam_ray(&cam, 32.5, j + 0.5, &o, &d);
		if (gpu_ray_ground(o, d, 0, 0, 0, 19) < 0) break;
		int v = gpu_px8(&img, 32, j)[0];
		if (first < 0) first = v;
		if (prev >= 0 && v < prev) decreases++;
		prev = last = v;
		rows++;
	}
	printf("    depth column: %d ground rows, value %d (near) .. %d (far)\n", rows, first, last);
	CHECK(rows > 40, "rows %d", rows);
	CHECK(decreases == 0, "depth decreases %d times walking away from the camera", decreases);
	CHECK(last > first + 20, "depth %d near, %d far", first, last);
	rnd_image_release(&img);
}

TEST(single_sided_plane_invisible_from_below)
{
	const char *doc = "{'width':32,'height':32,'environment':{'background':[0.2,0.4,0.6]},"
	                  "'camera':{'type':'perspective','position':[0,%d,3],'target':[0,0,0],'fov_y':30},"
	                  "'objects':[{'shape':'plane','size':[4,4],'double_sided':%s}],"
	                  "'lights':[{'type':'directional','direction':[0,-1,0]}],'output':{'msaa':1}}";
	int bg[3];
	for (int c = 0; c < 3; c++) bg[c] = (int)lround(gpu_srgb_encode(0.2 * (c + 1)) * 255);
	struct rnd_image img;
	/* From below, single-sided: background. */
	REQUIRE(gpu_render(&img, doc, -3, "false"));
	const uint8_t *p = gpu_px8(&img, 16, 16);
	for (int c = 0; c < 3; c++) CHECK(abs(p[c] - bg[c]) <= 1, "below/single: ch %d = %d, bg %d", c, p[c], bg[c]);
	rnd_image_release(&img);
	/* From below, double-sided: visible. */
	REQUIRE(gpu_render(&img, doc, -3, "true"));
	p = gpu_px8(&img, 16, 16);
	CHECK(abs(p[0] - bg[0]) > 8 || abs(p[2] - bg[2]) > 8, "below/double: plane not visible (%d %d %d)", p[0], p[1], p[2]);
	rnd_image_release(&img);
	/* From above, single-sided: visible. */
	REQUIRE(gpu_render(&img, doc, 3, "false"));
	p = gpu_px8(&img, 16, 16);
	CHECK(abs(p[0] - bg[0]) > 8 || abs(p[2] - bg[2]) > 8, "above/single: plane not visible (%d %d %d)", p[0], p[1], p[2]);
	rnd_image_release(&img);
}

/* Top-down orthographic camera over the XZ plane: image right = +X, image up = -Z. */
#define TOPDOWN(h) "'camera':{'type':'orthographic','position':[0,10,0],'target':[0,0,0],'up':[0,0,-1],'height':" h "}"

TEST(spot_cone_lit_inside_black_outside)
{
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':128,'height':128," TOPDOWN("8") ","
	                         "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	                         "'objects':[{'shape':'plane','size':[10,10],'material':{'base_color':[1,1,1]}}],"
	                         "'lights':[{'type':'spot','position':[0,3,0],'direction':[0,-1,0],"
	                         "'outer_angle':30,'inner_angle':20,'intensity':5}],"
	                         "'output':{'msaa':1,'tonemap':'none'}}"));
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(0, 10, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), 8, 128, 128);
	double r_in = 3 * tan(20 * GPU_DEG), r_out = 3 * tan(30 * GPU_DEG);
	int n_in = 0, n_out = 0, bad_in = 0, bad_out = 0;
	for (int j = 0; j < 128; j++)
		for (int i = 0; i < 128; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			v3 p = v3_add(o, v3_scale(d, gpu_ray_ground(o, d, 0, 0, 0, 5)));
			double r = hypot(p.x, p.z);
			const uint8_t *px = gpu_px8(&img, i, j);
			if (r < r_in - 0.1) { n_in++; bad_in += px[0] < 40; }
			else if (r > r_out + 0.1 && fabs(p.x) < 4.9 && fabs(p.z) < 4.9) {
				n_out++;
				bad_out += px[0] != 0 || px[1] != 0 || px[2] != 0;
			}
		}
	CHECK(n_in > 100 && n_out > 1000, "coverage %d %d", n_in, n_out);
	CHECK(bad_in == 0, "%d of %d pixels inside the inner cone are dark", bad_in, n_in);
	CHECK(bad_out == 0, "%d of %d pixels outside the outer cone are not black", bad_out, n_out);
	rnd_image_release(&img);
}

TEST(point_light_inverse_square)
{
	/* Point light of intensity I at height 2 over a white Lambert plane (roughness 1):
	 * E(x) = I cos(theta) / d^2; radiance = E / pi (+ a small specular term). */
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':128,'height':128," TOPDOWN("6") ","
	                         "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	                         "'objects':[{'shape':'plane','size':[10,10],"
	                         "'material':{'base_color':[1,1,1],'roughness':1}}],"
	                         "'lights':[{'type':'point','position':[0,2,0],'intensity':5}],"
	                         "'output':{'msaa':1,'tonemap':'none','bit_depth':16}}"));
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(0, 10, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), 6, 128, 128);
	v3 pts[3] = {v3_make(0, 0, 0), v3_make(1, 0, 0), v3_make(0, 0, 2)};
	double meas[3], pred[3];
	for (int k = 0; k < 3; k++) {
		double px, py;
		gpu_cam_project(&cam, pts[k], &px, &py);
		int i = (int)floor(px), j = (int)floor(py);
		/* evaluate the analytic value at that pixel's own ground point */
		v3 o, d;
		gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
		v3 p = v3_add(o, v3_scale(d, gpu_ray_ground(o, d, 0, 0, 0, 5)));
		v3 to = v3_sub(v3_make(0, 2, 0), p);
		double d2 = v3_dot(to, to);
		pred[k] = 5 * (to.y / sqrt(d2)) / d2 / GPU_PI;
		meas[k] = gpu_srgb_decode(gpu_chan(&img, i, j, 0));
	}
	for (int k = 1; k < 3; k++) {
		double rm = meas[k] / meas[0], rp = pred[k] / pred[0];
		printf("    point (%g,0,%g): radiance %.4f (analytic %.4f), ratio to centre %.4f (analytic %.4f)\n", pts[k].x,
		       pts[k].z, meas[k], pred[k], rm, rp);
		CHECK(fabs(rm / rp - 1) < 0.10, "ratio %.4f vs analytic %.4f", rm, rp);
	}
	CHECK(fabs(meas[0] / pred[0] - 1) < 0.10, "centre radiance %.4f vs analytic %.4f", meas[0], pred[0]);
	rnd_image_release(&img);
}

/* ---- 6. orthographic pixel convention ---- */

static bool bright_centroid(const struct rnd_image *img, double *cx, double *cy, int *n)
{
	double sx = 0, sy = 0, sw = 0;
	*n = 0;
	for (uint32_t j = 0; j < img->height; j++)
		for (uint32_t i = 0; i < img->width; i++) {
			const uint8_t *p = gpu_px8(img, (int)i, (int)j);
			if (p[0] > 128) { sx += i + 0.5; sy += j + 0.5; sw += 1; (*n)++; }
		}
	if (sw == 0) return false;
	*cx = sx / sw;
	*cy = sy / sw;
	return true;
}

TEST(ortho_pixel_convention)
{
	struct {
		v3 pos, target, up;
		double height;
		int w, h;
		v3 box;
	} cases[] = {
		{{0, 10, 0}, {0, 0, 0}, {0, 0, -1}, 4, 128, 128, {1.3, 0, -0.7}},
		{{0, 10, 0}, {0, 0, 0}, {0, 0, -1}, 4, 160, 96, {-2.1, 0, 0.9}},
		{{3, 4, 5}, {0.5, 0, 0}, {0, 1, 0}, 5, 128, 96, {-0.6, 0.4, 0.8}},
	};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		struct rnd_image img;
		REQUIRE(gpu_render(&img,
		                   "{'width':%d,'height':%d,'camera':{'type':'orthographic','position':[%g,%g,%g],"
		                   "'target':[%g,%g,%g],'up':[%g,%g,%g],'height':%g},"
		                   "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
		                   "'objects':[{'shape':'box','size':[0.1,0.1,0.1],"
		                   "'material':{'base_color':[0,0,0],'emissive':[1,1,1]},"
		                   "'transform':{'translation':[%g,%g,%g]}}],'output':{'msaa':1,'tonemap':'none'}}",
		                   cases[k].w, cases[k].h, cases[k].pos.x, cases[k].pos.y, cases[k].pos.z, cases[k].target.x,
		                   cases[k].target.y, cases[k].target.z, cases[k].up.x, cases[k].up.y, cases[k].up.z,
		                   cases[k].height, cases[k].box.x, cases[k].box.y, cases[k].box.z));
		struct gpu_cam cam;
		gpu_cam_ortho(&cam, cases[k].pos, cases[k].target, cases[k].up, cases[k].height, cases[k].w, cases[k].h);
		double ex, ey, cx, cy;
		int n;
		gpu_cam_project(&cam, cases[k].box, &ex, &ey);
		if (!bright_centroid(&img, &cx, &cy, &n)) {
			CHECK(0, "case %zu: box not visible (expected at %.2f, %.2f)", k, ex, ey);
		} else {
			printf("    case %zu: box centroid (%.2f, %.2f), predicted (%.2f, %.2f), %d px\n", k, cx, cy, ex, ey, n);
			CHECK(fabs(cx - ex) <= 1 && fabs(cy - ey) <= 1, "case %zu: box at (%.2f, %.2f), predicted (%.2f, %.2f)",
			      k, cx, cy, ex, ey);
		}
		rnd_image_release(&img);
	}
}

TEST(camera_up_parallel_to_view_is_replaced)
{
	/* Looking straight down with up +Y: up becomes -Z, so +X is right and -Z is up in the image. */
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':64,'height':64,"
	                         "'camera':{'type':'orthographic','position':[0,5,0],'target':[0,0,0],'up':[0,1,0],'height':4},"
	                         "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	                         "'objects':[{'shape':'box','size':[0.2,0.2,0.2],"
	                         "'material':{'base_color':[0,0,0],'emissive':[1,1,1]},"
	                         "'transform':{'translation':[1,0,-0.5]}}],'output':{'msaa':1,'tonemap':'none'}}"));
	/* x = 1 of half width 2 -> NDC 0.5 -> px 48; z = -0.5 is image up 0.5 of half height 2 ->
	 * NDC y 0.25 -> py 24. */
	double cx, cy;
	int n;
	if (bright_centroid(&img, &cx, &cy, &n))
		CHECK(fabs(cx - 48) <= 1 && fabs(cy - 24) <= 1, "box at (%.2f, %.2f), expected (48, 24)", cx, cy);
	else
		CHECK(0, "box not visible");
	rnd_image_release(&img);
}

TEST(perspective_pixel_convention)
{
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':160,'height':120,"
	                         "'camera':{'type':'perspective','position':[2,3,6],'target':[0,0.5,0],'up':[0,1,0],'fov_y':35},"
	                         "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	                         "'objects':[{'shape':'sphere','radius':0.06,'segments':32,"
	                         "'material':{'base_color':[0,0,0],'emissive':[1,1,1]},"
	                         "'transform':{'translation':[-0.9,1.1,0.4]}}],'output':{'msaa':1,'tonemap':'none'}}"));
	struct gpu_cam cam;
	gpu_cam_persp(&cam, v3_make(2, 3, 6), v3_make(0, 0.5, 0), v3_make(0, 1, 0), 35, 160, 120);
	double ex, ey, cx, cy;
	int n;
	gpu_cam_project(&cam, v3_make(-0.9, 1.1, 0.4), &ex, &ey);
	if (bright_centroid(&img, &cx, &cy, &n))
		CHECK(fabs(cx - ex) <= 1 && fabs(cy - ey) <= 1, "sphere at (%.2f, %.2f), predicted (%.2f, %.2f)", cx, cy, ex, ey);
	else
		CHECK(0, "sphere not visible");
	rnd_image_release(&img);
}

/* ---- 7. exposure ---- */

TEST(exposure_plus_one_doubles_radiance)
{
	/* White Lambert plane facing a sun of irradiance pi * 0.2: radiance 0.2 (contract §1). */
	const char *doc2 = "{'width':32,'height':32,"
	                   "'camera':{'type':'orthographic','position':[0,10,0],'target':[0,0,0],'up':[0,0,-1],"
	                   "'height':4,'exposure':%g},"
	                   "'environment':{'ambient':{'intensity':0}},"
	                   "'objects':[{'shape':'plane','size':[10,10],'material':{'base_color':[1,1,1],'roughness':1}}],"
	                   "'lights':[{'type':'directional','direction':[0,-1,0],'intensity':%.9g}],"
	                   "'output':{'msaa':1,'tonemap':'none','bit_depth':16}}";
	double e[3];
	double evs[3] = {0, 1, -1};
	for (int k = 0; k < 3; k++) {
		struct rnd_image img;
		REQUIRE(gpu_render(&img, doc2, evs[k], GPU_PI * 0.2));
		e[k] = mean_linear(&img, 16, 16, 4, 1);
		rnd_image_release(&img);
	}
	printf("    radiance at EV 0 %.5f, EV +1 %.5f, EV -1 %.5f\n", e[0], e[1], e[2]);
	CHECK(fabs(e[1] / e[0] - 2) < 0.04, "EV+1 / EV0 = %.4f", e[1] / e[0]);
	CHECK(fabs(e[0] / e[2] - 2) < 0.04, "EV0 / EV-1 = %.4f", e[0] / e[2]);
	/* Absolute: diffuse 0.2 plus a small specular term at roughness 1 (a few percent). */
	CHECK(e[0] > 0.19 && e[0] < 0.22, "EV 0 radiance %.4f, expected ~0.2", e[0]);
}

/* ---- 8. sixteen shadowed lights ---- */

TEST(sixteen_shadowed_lights)
{
	char lights[8192];
	size_t o = 0;
	for (int k = 0; k < 16; k++) {
		double a = k * 2 * GPU_PI / 16;
		double x = 3 * cos(a), z = 3 * sin(a);
		if (k % 3 == 0)
			o += snprintf(lights + o, sizeof lights - o,
			              "%s{'type':'spot','position':[%.4f,4,%.4f],'direction':[%.4f,-4,%.4f],'intensity':4}",
			              k ? "," : "", x, z, -x, -z);
		else if (k % 3 == 1)
			o += snprintf(lights + o, sizeof lights - o, "%s{'type':'point','position':[%.4f,3,%.4f],'intensity':3}",
			              k ? "," : "", x, z);
		else
			o += snprintf(lights + o, sizeof lights - o,
			              "%s{'type':'directional','direction':[%.4f,-2,%.4f],'intensity':0.3}", k ? "," : "", -x, -z);
	}
	/* Light 15 (a spot straight above the sphere) is the debug light: under the sphere it must be
	 * shadowed, far from it lit. */
	o += snprintf(lights + o, sizeof lights - o,
	              ",{'type':'spot','position':[0,5,0],'direction':[0,-1,0],'outer_angle':60,'intensity':4}");
	const char *doc = "{'width':128,'height':128,"
	                  "'camera':{'type':'orthographic','position':[0,10,0],'target':[0,0,0],'up':[0,0,-1],'height':8},"
	                  "'objects':[{'shape':'plane','size':[10,10]},"
	                  "{'shape':'sphere','radius':0.7,'segments':64,'transform':{'translation':[1.5,1,0]}},"
	                  "{'shape':'box','size':[0.6,1.2,0.6],'transform':{'translation':[-1.5,0.6,0.5]}},"
	                  "{'shape':'cylinder','radius':0.3,'height':1.5,'transform':{'translation':[0,0.75,-1.8]}}],"
	                  "'lights':[%s],'output':{'msaa':1%s}}";
	struct rnd_image img;
	/* 17 lights: 16 of the ring plus the debug spot (at least 16 must be accepted). */
	REQUIRE(gpu_render(&img, doc, lights, ""));
	double sum = 0;
	for (int j = 0; j < 128; j += 8)
		for (int i = 0; i < 128; i += 8) sum += luma(&img, i, j);
	CHECK(sum > 1, "image is black");
	rnd_image_release(&img);
	REQUIRE(gpu_render(&img, doc, lights, ",'debug':'shadow','debug_light':16"));
	/* Ground under the sphere seen from above is hidden by the sphere; the spot at (0,5,0) casts
	 * the sphere's shadow outward: ground point (2.6, 0, 0) is on the line from the light through
	 * the sphere centre (1.5,1,0) extended to y = 0: 1.5 * 5/4 = 1.875; take (1.9, 0, 0) and check
	 * it analytically, plus a lit point at (-3.5, 0, -3). */
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(0, 10, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), 8, 128, 128);
	v3 shadow_p = v3_make(2.3, 0, 0), lit_p = v3_make(-3.5, 0, -3);
	CHECK(gpu_ray_sphere(shadow_p, v3_sub(v3_make(0, 5, 0), shadow_p), v3_make(1.5, 1, 0), 0.7, 1e-9) > 0,
	      "test geometry");
	double px, py;
	gpu_cam_project(&cam, shadow_p, &px, &py);
	int v = gpu_px8(&img, (int)px, (int)py)[0];
	CHECK(v < 64, "debug light 16: ground in the sphere's shadow reads %d", v);
	gpu_cam_project(&cam, lit_p, &px, &py);
	v = gpu_px8(&img, (int)px, (int)py)[0];
	CHECK(v > 191, "debug light 16: open ground reads %d", v);
	rnd_image_release(&img);
}

/* A flat model at its lowest point (glTF TwoSidedPlane: a quad lying down) under the thumbnail
 * preset: its self-placing ground (a shadow catcher) had sat exactly in the quad's plane and
 * z-fought with it, the white background showing through the quad in stripes. The ground now
 * sits just below (api/ground.h API_GROUND_GAP): every pixel well inside the quad is the quad. */
TEST(render_flat_model_is_not_cut_by_its_ground)
{
	static const char *doc = "{'preset': 'thumbnail', 'width': 256, 'height': 256, 'objects': [{'shape': 'mesh',"
	                         " 'positions': [-1,0,-1, 1,0,-1, 1,0,1, -1,0,1], 'indices': [0,2,1, 0,3,2]}]}";
	struct rnd_image img;
	if (!gpu_render(&img, doc, 0)) return;
	int x0 = 256, x1 = -1, y0 = 256, y1 = -1;
	for (int j = 0; j < 256; j++)
		for (int i = 0; i < 256; i++)
			if (gpu_px8(&img, i, j)[0] < 250) {
				if (i < x0) x0 = i;
				if (i > x1) x1 = i;
				if (j < y0) y0 = j;
				if (j > y1) y1 = j;
			}
	REQUIRE(x1 - x0 > 100 && y1 - y0 > 30, "the quad covers %dx%d pixels", x1 - x0, y1 - y0);
	/* The middle third of its outline's box lies inside the quad (a convex trapezoid from here). */
	int holes = 0, n = 0;
	for (int j = y0 + (y1 - y0) / 3; j <= y1 - (y1 - y0) / 3; j++)
		for (int i = x0 + (x1 - x0) / 3; i <= x1 - (x1 - x0) / 3; i++, n++) {
			const uint8_t *p = gpu_px8(&img, i, j);
			holes += p[0] >= 254 && p[1] >= 254 && p[2] >= 254;
		}
	CHECK(holes == 0, "%d of %d pixels inside the quad show the background", holes, n);
	rnd_image_release(&img);
}
