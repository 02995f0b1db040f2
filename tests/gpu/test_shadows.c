/* tests/gpu — shadow correctness against analytic ray-traced references (contract §1, §3, §4,
 * §7): debug "shadow" view of a sphere above a plane, compared pixel by pixel with visibility
 * computed here by intersecting the camera ray and the shadow ray with the exact sphere. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "test.h"

enum { L_DIR, L_POINT, L_SPOT };

struct ana {
	/* camera */
	bool ortho;
	v3 cam_pos, cam_target, cam_up;
	double fov_or_height;
	int w, h;
	/* scene: plane y = 0 of half size plane_half, sphere centre sc radius sr */
	double plane_half;
	v3 sc;
	double sr;
	/* light */
	int light;
	v3 ldir, lpos;
	double outer_deg;
	const char *shadow; /* members of the root `shadows` object */
	const char *label;
};

static void fmt_v3(char *b, size_t n, v3 v) { snprintf(b, n, "[%.9g,%.9g,%.9g]", v.x, v.y, v.z); }

/* Renders the debug shadow view of a and compares it with the analytic classification.
 * Returns the agreement fraction over ground pixels away from class edges (-1 on failure). */
static double analytic_check(const struct ana *a, int line)
{
	struct gpu_cam cam;
	if (a->ortho) gpu_cam_ortho(&cam, a->cam_pos, a->cam_target, a->cam_up, a->fov_or_height, a->w, a->h);
	else gpu_cam_persp(&cam, a->cam_pos, a->cam_target, a->cam_up, a->fov_or_height, a->w, a->h);

	char cp[96], ct[96], cu[96], sc[96], ld[96], lp[96], cam_json[512], light_json[512];
	fmt_v3(cp, sizeof cp, a->cam_pos);
	fmt_v3(ct, sizeof ct, a->cam_target);
	fmt_v3(cu, sizeof cu, a->cam_up);
	fmt_v3(sc, sizeof sc, a->sc);
	fmt_v3(ld, sizeof ld, a->ldir);
	fmt_v3(lp, sizeof lp, a->lpos);
	if (a->ortho)
		snprintf(cam_json, sizeof cam_json,
		         "{'type':'orthographic','position':%s,'target':%s,'up':%s,'height':%.9g}", cp, ct, cu,
		         a->fov_or_height);
	else
		snprintf(cam_json, sizeof cam_json,
		         "{'type':'perspective','position':%s,'target':%s,'up':%s,'fov_y':%.9g}", cp, ct, cu,
		         a->fov_or_height);
	if (a->light == L_DIR)
		snprintf(light_json, sizeof light_json, "{'type':'directional','direction':%s}", ld);
	else if (a->light == L_POINT)
		snprintf(light_json, sizeof light_json, "{'type':'point','position':%s}", lp);
	else
		snprintf(light_json, sizeof light_json,
		         "{'type':'spot','position':%s,'direction':%s,'outer_angle':%.9g,'inner_angle':%.9g}", lp, ld,
		         a->outer_deg, a->outer_deg * 0.8);

	struct rnd_image img;
	if (!gpu_render_at(__FILE__, line, &img,
	                   "{'width':%d,'height':%d,'camera':%s,"
	                   "'objects':[{'shape':'plane','size':[%.9g,%.9g]},"
	                   "{'shape':'sphere','radius':%.9g,'segments':128,'transform':{'translation':%s}}],"
	                   "'lights':[%s],'shadows':{%s},'output':{'debug':'shadow','msaa':1}}",
	                   a->w, a->h, cam_json, 2 * a->plane_half, 2 * a->plane_half, a->sr, sc, light_json,
	                   a->shadow))
		return -1;

	int w = a->w, h = a->h;
	uint8_t *cls = calloc((size_t)w * h, 1);
	v3 L = v3_norm(v3_scale(a->ldir, -1));
	double cos_lim = cos((a->outer_deg - 3) * GPU_DEG);
	for (int j = 0; j < h; j++) {
		for (int i = 0; i < w; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			double ts = gpu_ray_sphere(o, d, a->sc, a->sr, 0);
			double tg = gpu_ray_ground(o, d, 0, 0, 0, a->plane_half);
			uint8_t k;
			if (ts < 0 && tg < 0) k = GPU_CLS_BG;
			else if (ts > 0 && (tg < 0 || ts < tg)) k = GPU_CLS_OBJ;
			else {
				v3 p = v3_add(o, v3_scale(d, tg));
				bool shadowed;
				if (a->light == L_DIR) {
					shadowed = gpu_ray_sphere(p, L, a->sc, a->sr, 1e-9) > 0;
				} else {
					v3 to = v3_sub(a->lpos, p);
					double t = gpu_ray_sphere(p, to, a->sc, a->sr, 1e-9);
					shadowed = t > 0 && t < 1;
				}
				k = shadowed ? GPU_CLS_SHADOW : GPU_CLS_LIT;
				if (a->light == L_SPOT) {
					v3 from = v3_norm(v3_sub(p, a->lpos));
					if (v3_dot(from, v3_norm(a->ldir)) < cos_lim) k = GPU_CLS_SKIP;
				}
			}
			cls[(size_t)j * w + i] = k;
		}
	}
	long n = 0, agree = 0, n_shadow = 0, n_lit = 0, bg = 0, bg_ok = 0;
	long lit_as_shadow = 0, shadow_as_lit = 0;
	for (int j = 0; j < h; j++) {
		for (int i = 0; i < w; i++) {
			uint8_t k = cls[(size_t)j * w + i];
			if (gpu_near_edge(cls, w, h, i, j, 2)) continue;
			const uint8_t *px = gpu_px8(&img, i, j);
			if (k == GPU_CLS_BG) { bg++; bg_ok += px[0] == 255; continue; }
			if (k != GPU_CLS_LIT && k != GPU_CLS_SHADOW) continue;
			bool lit = px[0] > 127;
			n++;
			if (k == GPU_CLS_LIT) n_lit++; else n_shadow++;
			if (lit == (k == GPU_CLS_LIT)) agree++;
			else if (lit) shadow_as_lit++;
			else lit_as_shadow++;
		}
	}
	double frac = n ? (double)agree / n : 0;
	printf("    [%s] agreement %.3f%% over %ld ground px (%ld lit, %ld shadow; mismatches: %ld lit-read-as-shadow, "
	       "%ld shadow-read-as-lit); background %ld/%ld = 255\n",
	       a->label, 100 * frac, n, n_lit, n_shadow, lit_as_shadow, shadow_as_lit, bg_ok, bg);
	if (n_shadow < 100 || n_lit < 100)
		test_fail_at(__FILE__, line, "coverage", " [%s] too few classified pixels (%ld lit, %ld shadow)", a->label,
		             n_lit, n_shadow);
	if (frac < 0.995)
		test_fail_at(__FILE__, line, "agreement >= 99.5%", " [%s] got %.3f%%", a->label, 100 * frac);
	if (bg_ok != bg)
		test_fail_at(__FILE__, line, "background == 255", " [%s] %ld of %ld background px", a->label, bg - bg_ok, bg);
	free(cls);
	rnd_image_release(&img);
	return frac;
}

/* Steep and low (25 degree elevation) suns. */
static v3 sun_dir(double elev_deg, double az_deg)
{
	double e = elev_deg * GPU_DEG, az = az_deg * GPU_DEG;
	return v3_make(cos(e) * cos(az), -sin(e), cos(e) * sin(az));
}

static void sun_cases(const char *shadow, const char *label, bool ortho, int line)
{
	struct ana a = {0};
	a.w = a.h = 256;
	a.plane_half = 10;
	a.sc = v3_make(0, 1.5, 0);
	a.sr = 1;
	a.light = L_DIR;
	a.shadow = shadow;
	if (ortho) {
		a.ortho = true;
		a.cam_pos = v3_make(1.5, 10, 7);
		a.cam_target = v3_make(1.5, 0, 0.5);
		a.cam_up = v3_make(0, 1, 0);
		a.fov_or_height = 11;
	} else {
		a.cam_pos = v3_make(1.5, 11, 9);
		a.cam_target = v3_make(1.5, 0, 0.5);
		a.cam_up = v3_make(0, 1, 0);
		a.fov_or_height = 50;
	}
	char lab[128];
	a.ldir = sun_dir(68, 200); /* steep: light travels -x mostly, shadow falls toward -x */
	snprintf(lab, sizeof lab, "%s, steep sun 68deg", label);
	a.label = lab;
	analytic_check(&a, line);
	a.ldir = sun_dir(25, 10); /* low: long shadow toward +x */
	snprintf(lab, sizeof lab, "%s, low sun 25deg", label);
	analytic_check(&a, line);
}

TEST(shadow_analytic_fit_hard)
{
	sun_cases("'filter':'hard','directional':{'mode':'fit'}", "fit/hard", false, __LINE__);
}

TEST(shadow_analytic_fit_pcf)
{
	sun_cases("'filter':'pcf','pcf_radius':1,'directional':{'mode':'fit'}", "fit/pcf1", false, __LINE__);
}

TEST(shadow_analytic_cascades_hard)
{
	sun_cases("'filter':'hard','directional':{'mode':'cascades'}", "cascades/hard", false, __LINE__);
}

TEST(shadow_analytic_cascades_pcf)
{
	sun_cases("'filter':'pcf','pcf_radius':1,'directional':{'mode':'cascades'}", "cascades/pcf1", false, __LINE__);
}

TEST(shadow_analytic_clipmap_hard)
{
	sun_cases("'filter':'hard','directional':{'mode':'clipmap','clipmap_levels':4,'clipmap_extent':4}", "clipmap/hard",
	          false, __LINE__);
}

TEST(shadow_analytic_clipmap_pcf)
{
	sun_cases("'filter':'pcf','pcf_radius':1,'directional':{'mode':'clipmap'}", "clipmap/pcf1", false, __LINE__);
}

TEST(shadow_analytic_cascades_blend_fade)
{
	/* A wide blend band and a fade that starts beyond the scene: blending two cascades of the
	 * same geometry must not move the shadow. */
	sun_cases("'filter':'pcf','pcf_radius':1,'directional':{'mode':'cascades','blend':0.5,'max_distance':60,'fade':0.1}",
	          "cascades/pcf1 blend 0.5", false, __LINE__);
}

TEST(shadow_analytic_ortho_camera)
{
	sun_cases("'filter':'hard','directional':{'mode':'fit'}", "ortho fit/hard", true, __LINE__);
	sun_cases("'filter':'pcf','pcf_radius':1,'directional':{'mode':'cascades'}", "ortho cascades/pcf1", true,
	          __LINE__);
}

TEST(shadow_analytic_point)
{
	struct ana a = {0};
	a.w = a.h = 256;
	a.plane_half = 10;
	a.sc = v3_make(0, 1.2, 0);
	a.sr = 0.8;
	a.cam_pos = v3_make(0.5, 9, 8);
	a.cam_target = v3_make(0, 0, 0);
	a.cam_up = v3_make(0, 1, 0);
	a.fov_or_height = 45;
	a.light = L_POINT;
	a.lpos = v3_make(-0.8, 3.5, 0.6);
	a.shadow = "'filter':'hard'";
	a.label = "point/hard";
	analytic_check(&a, __LINE__);
	a.shadow = "'filter':'pcf','pcf_radius':1";
	a.label = "point/pcf1";
	analytic_check(&a, __LINE__);
}

TEST(shadow_analytic_spot)
{
	struct ana a = {0};
	a.w = a.h = 256;
	a.plane_half = 10;
	a.sc = v3_make(0, 1.2, 0);
	a.sr = 0.8;
	a.cam_pos = v3_make(0.5, 9, 8);
	a.cam_target = v3_make(0, 0, 0);
	a.cam_up = v3_make(0, 1, 0);
	a.fov_or_height = 45;
	a.light = L_SPOT;
	a.lpos = v3_make(-0.8, 4, 0.6);
	a.ldir = v3_make(0.25, -1, -0.2);
	a.outer_deg = 50;
	a.shadow = "'filter':'hard'";
	a.label = "spot/hard";
	analytic_check(&a, __LINE__);
	a.shadow = "'filter':'pcf','pcf_radius':1";
	a.label = "spot/pcf1";
	analytic_check(&a, __LINE__);
}

/* ---- 3. acne and peter-panning with the renderer's default bias ---- */

static double debug_frac_lit_ground(const char *shadow, double *out_frac, int line)
{
	/* Sun 5 degrees above a 100 x 100 plane with nothing on it: every ground pixel is lit. */
	struct gpu_cam cam;
	gpu_cam_persp(&cam, v3_make(0, 6, 12), v3_make(0, 0, -10), v3_make(0, 1, 0), 60, 128, 128);
	v3 sun = sun_dir(5, 30);
	struct rnd_image img;
	if (!gpu_render_at(__FILE__, line, &img,
	                   "{'width':128,'height':128,"
	                   "'camera':{'type':'perspective','position':[0,6,12],'target':[0,0,-10],'up':[0,1,0],'fov_y':60},"
	                   "'objects':[{'shape':'plane','size':[100,100]}],"
	                   "'lights':[{'type':'directional','direction':[%.9g,%.9g,%.9g]}],'shadows':{%s},"
	                   "'output':{'debug':'shadow','msaa':1}}",
	                   sun.x, sun.y, sun.z, shadow))
		return -1;
	long n = 0, lit = 0, minv = 255;
	for (int j = 0; j < 128; j++)
		for (int i = 0; i < 128; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			if (gpu_ray_ground(o, d, 0, 0, 0, 49.5) < 0) continue;
			int v = gpu_px8(&img, i, j)[0];
			n++;
			lit += v > 127;
			if (v < minv) minv = v;
		}
	rnd_image_release(&img);
	*out_frac = n ? (double)lit / n : 0;
	printf("    [grazing sun 5deg, %s] %ld ground px, %.3f%% lit, min value %ld\n", shadow[0] ? shadow : "defaults", n,
	       100 * *out_frac, minv);
	if (n < 5000) test_fail_at(__FILE__, line, "coverage", " %ld ground px", n);
	return *out_frac;
}

TEST(no_acne_grazing_sun)
{
	const char *cases[] = {"", "'filter':'hard','directional':{'mode':'fit'}",
	                       "'filter':'hard','directional':{'mode':'cascades'}",
	                       "'filter':'pcf','directional':{'mode':'cascades'}"};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		double f;
		if (debug_frac_lit_ground(cases[k], &f, __LINE__) < 0) continue;
		CHECK(f >= 0.999, "[%s] only %.3f%% of the ground is lit (shadow acne)", cases[k], 100 * f);
	}
}

TEST(no_peter_panning_thin_pole)
{
	/* Pole: cylinder r = 0.015 m, height 1, standing on y = 0; sun at 45 degrees travelling +X.
	 * Its shadow is the strip 0.015 < x < 1.015 (+ the radius), |z| < 0.015 on the ground.
	 * Top-down orthographic camera 0.6 m tall over 240 px: 2.5 mm per pixel. */
	const int W = 240, H = 120;
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(0.25, 5, 0), v3_make(0.25, 0, 0), v3_make(0, 0, -1), 0.3, W, H);
	const char *shadow[] = {"", "'filter':'hard'", "'filter':'pcf','directional':{'mode':'cascades'}"};
	for (size_t k = 0; k < sizeof shadow / sizeof shadow[0]; k++) {
		struct rnd_image img;
		if (!gpu_render(&img,
		                "{'width':%d,'height':%d,"
		                "'camera':{'type':'orthographic','position':[0.25,5,0],'target':[0.25,0,0],'up':[0,0,-1],'height':0.3},"
		                "'objects':[{'shape':'plane','size':[4,4]},"
		                "{'shape':'cylinder','radius':0.015,'height':1,'segments':32,'transform':{'translation':[0,0.5,0]}}],"
		                "'lights':[{'type':'directional','direction':[1,-1,0]}],'shadows':{%s},"
		                "'output':{'debug':'shadow','msaa':1}}",
		                W, H, shadow[k]))
			continue;
		/* Ground points on the shadow's centre line z = 0, from 1 cm to 20 cm past the pole's
		 * surface, must be shadowed; points 5 cm to the side (z = +-0.05) lit. */
		int bad = 0, first_lit_mm = -1;
		for (int mm = 25; mm <= 215; mm += 5) {
			double px, py;
			gpu_cam_project(&cam, v3_make(mm / 1000.0, 0, 0), &px, &py);
			int v = gpu_px8(&img, (int)px, (int)py)[0];
			if (v > 127) { bad++; if (first_lit_mm < 0) first_lit_mm = mm; }
		}
		int side_bad = 0;
		for (int mm = 25; mm <= 215; mm += 10)
			for (int s = -1; s <= 1; s += 2) {
				double px, py;
				gpu_cam_project(&cam, v3_make(mm / 1000.0, 0, s * 0.05), &px, &py);
				side_bad += gpu_px8(&img, (int)px, (int)py)[0] <= 127;
			}
		/* Distance from the pole's axis to where the shadow visibly starts along z = 0. */
		int start = -1;
		for (int i = 0; i < W; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, H / 2.0, &o, &d);
			if (o.x <= 0.015) continue;
			if (gpu_px8(&img, i, H / 2)[0] <= 127) { start = i; break; }
		}
		v3 so, sd;
		gpu_cam_ray(&cam, start + 0.5, H / 2.0, &so, &sd);
		printf("    [pole, %s] shadow starts %.1f mm from the axis (surface at 15 mm); %d of 39 centre-line points "
		       "lit; %d of 40 side points shadowed\n",
		       shadow[k][0] ? shadow[k] : "defaults", start >= 0 ? so.x * 1000 : -1.0, bad, side_bad);
		CHECK(bad == 0, "[%s] detached shadow: ground at x = %d mm on the shadow line is lit", shadow[k],
		      first_lit_mm);
		CHECK(side_bad == 0, "[%s] %d side points shadowed", shadow[k], side_bad);
		rnd_image_release(&img);
	}
}

/* ---- 4. PCSS penumbra width ---- */

/* Fraction of a uniform disk of radius 1 beyond a chord at distance a from the centre. */
static double disk_cut(double a)
{
	if (a >= 1) return 0;
	if (a <= -1) return 1;
	return (acos(a) - a * sqrt(1 - a * a)) / GPU_PI;
}

/* 10%..90% width of the penumbra of a straight edge under a uniform disk, as a fraction of the
 * full (0..100%) width. */
static double disk_10_90_fraction(void)
{
	double lo = 0, hi = 1;
	for (int k = 0; k < 60; k++) { double m = (lo + hi) / 2; if (disk_cut(m) > 0.1) lo = m; else hi = m; }
	return lo; /* a where 10% is cut: the 10..90 span is 2a of the full 2 */
}

/* Measures the 10..90% penumbra width (m) of the shadow of a slab edge at height h (top face)
 * under a 3-degree sun tilted 30 degrees toward +X. */
static double pcss_width(double h, double *pred_full, int line)
{
	const double tilt = 30 * GPU_DEG, ang = 3 * GPU_DEG;
	double edge_x = h * tan(tilt);           /* where the top edge's shadow lands */
	const int W = 256, H = 64;
	double view_w = 0.4;
	struct gpu_cam cam;
	v3 pos = v3_make(edge_x, 5, 0), tgt = v3_make(edge_x, 0, 0), up = v3_make(0, 0, -1);
	gpu_cam_ortho(&cam, pos, tgt, up, view_w * H / W, W, H);
	/* Slab x in [-2, 0], z in [-1.5, 1.5], 1 cm thick, top face at h. */
	struct rnd_image img;
	if (!gpu_render_at(__FILE__, line, &img,
	                   "{'width':%d,'height':%d,"
	                   "'camera':{'type':'orthographic','position':[%.9g,5,0],'target':[%.9g,0,0],'up':[0,0,-1],'height':%.9g},"
	                   "'objects':[{'shape':'plane','size':[8,8]},"
	                   "{'shape':'box','size':[2,0.01,3],'transform':{'translation':[-1,%.9g,0]}}],"
	                   "'lights':[{'type':'directional','direction':[%.9g,%.9g,0],'angular_diameter':3,"
	                   "'shadow':{'filter':'pcss'}}],"
	                   "'output':{'debug':'shadow','msaa':1}}",
	                   W, H, edge_x, edge_x, view_w * H / W, h - 0.005, sin(tilt), -cos(tilt)))
		return -1;
	/* Full penumbra on the ground: angular spread ang in the plane of the ray, projected onto the
	 * ground at incidence `tilt`, over the distance h / cos(tilt) to the edge. */
	*pred_full = h / cos(tilt) * ang / cos(tilt);
	/* Average the visibility over the middle rows, then find the 10% and 90% crossings. */
	double prof[256];
	for (int i = 0; i < W; i++) {
		double s = 0;
		for (int j = H / 4; j < 3 * H / 4; j++) s += gpu_px8(&img, i, j)[0] / 255.0;
		prof[i] = s / (H / 2);
	}
	rnd_image_release(&img);
	if (getenv("GPU_TEST_VERBOSE")) {
		printf("    [pcss h=%.2f] profile (x relative to the edge's shadow, m : visibility):\n     ", h);
		for (int i = 0; i < W; i += 4) printf(" %+.3f:%.2f", (i + 0.5 - W / 2.0) * view_w / W, prof[i]);
		printf("\n");
	}
	double x10 = NAN, x90 = NAN;
	for (int i = 1; i < W; i++) {
		if (isnan(x10) && prof[i - 1] < 0.1 && prof[i] >= 0.1) x10 = i - 1 + (0.1 - prof[i - 1]) / (prof[i] - prof[i - 1]);
		if (isnan(x90) && prof[i - 1] < 0.9 && prof[i] >= 0.9) x90 = i - 1 + (0.9 - prof[i - 1]) / (prof[i] - prof[i - 1]);
	}
	if (isnan(x10) || isnan(x90)) {
		test_fail_at(__FILE__, line, "penumbra", " h %.2f: profile never crosses 10%%/90%% (ends %.2f .. %.2f)", h,
		             prof[0], prof[W - 1]);
		return -1;
	}
	double m_per_px = view_w / W;
	double width = (x90 - x10) * m_per_px;
	double centre = ((x10 + x90) / 2 + 0.5 - W / 2.0) * m_per_px; /* relative to the predicted edge */
	printf("    [pcss h=%.2f] 10-90%% width %.4f m (full-width prediction %.4f m, uniform-disk 10-90 %.4f m); "
	       "edge centre offset %.4f m\n",
	       h, width, *pred_full, *pred_full * disk_10_90_fraction(), centre);
	if (fabs(centre) > 0.25 * *pred_full + 2 * m_per_px)
		test_fail_at(__FILE__, line, "penumbra centre", " h %.2f: penumbra centred %.4f m from the edge's shadow", h,
		             centre);
	return width;
}

TEST(pcss_penumbra_grows_with_distance)
{
	double pl, ph;
	double wl = pcss_width(0.4, &pl, __LINE__);
	double wh = pcss_width(1.2, &ph, __LINE__);
	REQUIRE(wl > 0 && wh > 0);
	double f = disk_10_90_fraction();
	printf("    [pcss] width ratio %.3f (heights ratio 3); measured/predicted(10-90 disk) %.3f and %.3f\n", wh / wl,
	       wl / (pl * f), wh / (ph * f));
	CHECK(wh > 2 * wl, "penumbra does not grow with distance: %.4f at 0.4 m, %.4f at 1.2 m", wl, wh);
	CHECK(fabs(wl / (pl * f) - 1) <= 0.25, "h 0.4: width %.4f, predicted %.4f", wl, pl * f);
	CHECK(fabs(wh / (ph * f) - 1) <= 0.25, "h 1.2: width %.4f, predicted %.4f", wh, ph * f);
}

/* ---- shadow switches (§7): disabled shadows and receive_shadows false read 1 ---- */

TEST(shadow_disabled_reads_lit)
{
	const char *doc = "{'width':64,'height':64,"
	                  "'camera':{'type':'orthographic','position':[0,10,0],'target':[0,0,0],'up':[0,0,-1],'height':6},"
	                  "'objects':[{'shape':'plane','size':[10,10]%s},"
	                  "{'shape':'sphere','radius':1,'segments':32,'transform':{'translation':[-1,1.5,0]}}],"
	                  "'lights':[{'type':'directional','direction':[1.5,-1,0]%s}],"
	                  "'output':{'debug':'shadow','msaa':1}}";
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(0, 10, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), 6, 64, 64);
	/* Ground point in the sphere's shadow, outside the sphere's silhouette from above. */
	v3 p = v3_make(-1 + 1.5 * 1.5, 0, 0);
	REQUIRE(gpu_ray_sphere(p, v3_make(-1.5, 1, 0), v3_make(-1, 1.5, 0), 1, 1e-9) > 0);
	REQUIRE(hypot(p.x + 1, p.z) > 1.05);
	double px, py;
	gpu_cam_project(&cam, p, &px, &py);
	struct { const char *plane, *light; int expect_lit; } cases[] = {
		{"", "", 0},
		{",'receive_shadows':false", "", 1},
		{"", ",'shadow':false", 1},
		{"", ",'shadow':{'enabled':false}", 1},
	};
	for (size_t k = 0; k < 4; k++) {
		struct rnd_image img;
		if (!gpu_render(&img, doc, cases[k].plane, cases[k].light)) continue;
		int v = gpu_px8(&img, (int)px, (int)py)[0];
		if (cases[k].expect_lit) CHECK(v == 255, "case %zu (%s%s): shadowed ground reads %d, expected 255", k,
		                               cases[k].plane, cases[k].light, v);
		else CHECK(v < 64, "case 0: ground in the sphere's shadow reads %d", v);
		rnd_image_release(&img);
	}
}

/* A rough patch of tiny triangles (a 128 x 128 grid over 2 m, heights jittered by a tenth of
 * a cell, triangles under a pixel) under a sun 60 degrees up: the jitter's slopes stay far
 * under the sun's, and at MSAA 1 the patch reads lit. MSAA 4 shades a fragment at the pixel
 * centre even where its triangle covers only a corner sample, and the triangle's plane
 * extended there lies under its neighbours: before the shadow lookups moved to the covered
 * samples (facet.glsl covered_position) 268 such pixels read shadowed (the dense-model specks
 * of a 124k-triangle OBJ). Every pixel of the patch that reads lit with its 8 neighbours at
 * MSAA 1 must read lit at MSAA 4 too. */
TEST(no_specks_on_dense_rough_mesh_msaa)
{
	enum { N = 128 };
	size_t cap = (size_t)(N + 1) * (N + 1) * 40 + (size_t)N * N * 6 * 8 + 1024;
	char *pos = malloc(cap), *idx = malloc(cap);
	REQUIRE(pos && idx, "out of memory");
	size_t pn = 0, in = 0;
	uint32_t seed = 12345;
	for (int j = 0; j <= N; j++)
		for (int i = 0; i <= N; i++) {
			seed = seed * 1664525u + 1013904223u;
			double h = ((double)(seed >> 8) / 16777216.0 - 0.5) * 0.1 * (2.0 / N);
			pn += (size_t)snprintf(pos + pn, cap - pn, "%s%.6f,%.6f,%.6f", pn ? "," : "", -1.0 + 2.0 * i / N, h,
			                       -1.0 + 2.0 * j / N);
		}
	for (int j = 0; j < N; j++)
		for (int i = 0; i < N; i++) {
			int a = j * (N + 1) + i, b = a + N + 1;
			in += (size_t)snprintf(idx + in, cap - in, "%s%d,%d,%d,%d,%d,%d", in ? "," : "", a, b, a + 1, a + 1, b, b + 1);
		}
	const char *doc = "{'width':160,'height':160,'camera':{'type':'perspective','position':[0,2.2,1.6],'target':[0,0,0],"
	                  "'up':[0,1,0],'fov_y':40},'objects':[{'shape':'mesh','positions':[%s],'indices':[%s]}],"
	                  "'lights':[{'type':'directional','direction':[-0.4,-0.866,-0.3]}],"
	                  "'output':{'debug':'shadow','msaa':%d}}";
	struct rnd_image one, four;
	if (gpu_render(&one, doc, pos, idx, 1)) {
		if (gpu_render(&four, doc, pos, idx, 4)) {
			long lit = 0, specks = 0;
			int darkest = 255;
			for (int j = 1; j + 1 < 160; j++)
				for (int i = 1; i + 1 < 160; i++) {
					bool all = true;
					for (int y = j - 1; y <= j + 1 && all; y++)
						for (int x = i - 1; x <= i + 1 && all; x++) all = gpu_px8(&one, x, y)[0] == 255;
					if (!all) continue;
					lit++;
					int v = gpu_px8(&four, i, j)[0];
					if (v < 240) specks++;
					if (v < darkest) darkest = v;
				}
			printf("    %ld pixels lit with their neighbours at MSAA 1; at MSAA 4 %ld of them under 240 (darkest %d)\n", lit,
			       specks, darkest);
			CHECK(lit > 5000, "only %ld lit pixels on the patch at MSAA 1", lit);
			CHECK(specks == 0, "%ld lit pixels read shadowed at MSAA 4 (darkest %d)", specks, darkest);
			rnd_image_release(&four);
		}
		rnd_image_release(&one);
	}
	free(pos);
	free(idx);
}
