/* tests/gpu — outputs: several views (turntable / views sheets, multi-part EXR), EXR AOVs,
 * transparent PNGs, shadow catchers, 16-bit PNGs and base-colour textures. Expected values come
 * from the contract (§2, §4, §7) and the analytic camera/geometry model of gpu_util.h, never
 * from the renderer's own output (except where the contract says two outputs agree: the
 * `shadow.<i>` AOV and the `debug: shadow` view, 8 and 16-bit PNGs). Run: gpu_tests outputs */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <openexr.h>
#include <png.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"
#include "util.h"

/* ---- helpers ---- */

static const uint8_t *cell_px(const struct rnd_image *img, int view, int i, int j)
{
	int cols = (int)img->view_columns, x0 = view % cols * (int)img->view_width, y0 = view / cols * (int)img->view_height;
	return gpu_px8(img, x0 + i, y0 + j);
}

/* The emissive red sphere of the view scenes: clearly red, neither grey (plane) nor blue (sky). */
static bool is_red(const uint8_t *p)
{
	return p[0] > 100 && p[1] * 2 < p[0] && p[2] * 2 < p[0];
}

/* Centroid and count of the red pixels of one cell. */
static int red_centroid(const struct rnd_image *img, int view, double *cx, double *cy)
{
	double sx = 0, sy = 0;
	int n = 0;
	for (int j = 0; j < (int)img->view_height; j++)
		for (int i = 0; i < (int)img->view_width; i++)
			if (is_red(cell_px(img, view, i, j))) { sx += i + 0.5; sy += j + 0.5; n++; }
	*cx = n ? sx / n : -1;
	*cy = n ? sy / n : -1;
	return n;
}

/* A unit sphere at (0,1,0), emissive red, on a 10x10 grey plane, lit from the side. */
#define VIEW_SCENE                                                                                        \
	"'environment':{'background':[0.1,0.2,0.6]},"                                                     \
	"'objects':[{'shape':'plane','size':[10,10],'material':{'base_color':[0.5,0.5,0.5],'roughness':1}}," \
	"{'shape':'sphere','radius':1,'segments':48,'transform':{'translation':[0,1,0]},"                   \
	"'material':{'base_color':[0,0,0],'emissive':[1,0,0],'roughness':1}}],"                            \
	"'lights':[{'type':'directional','direction':[-0.5,-1,-0.3],'intensity':3}]"

/* ---- 1. turntable and views sheets ---- */

TEST(outputs_turntable_sheet)
{
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':64,'height':64," VIEW_SCENE ",'turntable':{'frames':4,'elevation':20},"
	                         "'output':{'msaa':1}}"));
	CHECK(img.width == 128 && img.height == 128, "sheet %ux%u, want 128x128", img.width, img.height);
	CHECK(img.view_count == 4 && img.view_columns == 2 && img.view_width == 64 && img.view_height == 64,
	      "views %u columns %u cell %ux%u", img.view_count, img.view_columns, img.view_width, img.view_height);
	if (img.width != 128 || img.view_count != 4 || img.view_columns != 2) { rnd_image_release(&img); return; }

	/* Framing (api: the objects' bounds, planes left out, are the sphere's box: centre (0,1,0),
	 * bounding radius sqrt(3); fov 45°, margin 0.1 => distance sqrt(3)/sin(18°)). The sphere is on
	 * the optical axis, so its silhouette is a circle centred in the cell, of angular radius
	 * asin(1/distance). */
	double dist = sqrt(3.0) / sin(18 * GPU_DEG);
	double r_px = 32 * tan(asin(1 / dist)) / tan(22.5 * GPU_DEG);
	double area = GPU_PI * r_px * r_px;
	for (int v = 0; v < 4; v++) {
		double cx, cy;
		int n = red_centroid(&img, v, &cx, &cy);
		printf("    view %d: sphere centroid (%.2f, %.2f), %d px (disc of radius %.2f: %.0f px)\n", v, cx, cy, n,
		       r_px, area);
		CHECK(fabs(cx - 32) < 1.0 && fabs(cy - 32) < 1.0, "view %d: sphere centroid (%.2f, %.2f), want (32, 32)", v,
		      cx, cy);
		CHECK(fabs(n - area) < 0.08 * area, "view %d: sphere covers %d px, want about %.0f", v, n, area);
	}
	/* The views differ (the light is fixed, the camera orbits: shading and shadow move). */
	for (int a = 0; a < 4; a++)
		for (int b = a + 1; b < 4; b++) {
			long sum = 0, differ = 0;
			for (int j = 0; j < 64; j++)
				for (int i = 0; i < 64; i++) {
					const uint8_t *p = cell_px(&img, a, i, j), *q = cell_px(&img, b, i, j);
					int d = abs(p[0] - q[0]) + abs(p[1] - q[1]) + abs(p[2] - q[2]);
					sum += d;
					differ += d > 6;
				}
			CHECK(differ > 100 && sum > 64 * 64, "views %d and %d: %ld pixels differ, mean |diff| %.2f", a, b,
			      differ, sum / (64.0 * 64.0));
		}
	rnd_image_release(&img);
}

TEST(outputs_views_sheet_layout)
{
	/* Three explicit views: a 2x2 sheet (ceil(sqrt 3) = 2 columns), the 4th cell empty (zero). */
	static const double pos[3][3] = {{0, 3, 6}, {6, 2, 0}, {-3, 4, -4}}, tgt[3][3] = {{0, 1, 0}, {0, 0, 0}, {0, 1, 1}};
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':48,'height':32," VIEW_SCENE ",'views':["
	                         "{'position':[0,3,6],'target':[0,1,0],'fov_y':40},"
	                         "{'position':[6,2,0],'target':[0,0,0],'fov_y':40},"
	                         "{'position':[-3,4,-4],'target':[0,1,1],'fov_y':40}],"
	                         "'output':{'msaa':1,'transparent':true}}"));
	CHECK(img.width == 96 && img.height == 64 && img.view_count == 3 && img.view_columns == 2 &&
	      img.view_width == 48 && img.view_height == 32, "sheet %ux%u views %u columns %u", img.width, img.height,
	      img.view_count, img.view_columns);
	if (img.width != 96 || img.height != 64) { rnd_image_release(&img); return; }
	for (int v = 0; v < 3; v++) {
		struct gpu_cam cam;
		gpu_cam_persp(&cam, v3_make(pos[v][0], pos[v][1], pos[v][2]), v3_make(tgt[v][0], tgt[v][1], tgt[v][2]),
		              v3_make(0, 1, 0), 40, 48, 32);
		double ex, ey, cx, cy;
		gpu_cam_project(&cam, v3_make(0, 1, 0), &ex, &ey);
		int n = red_centroid(&img, v, &cx, &cy);
		CHECK(n > 20 && fabs(cx - ex) < 1.5 && fabs(cy - ey) < 1.5,
		      "view %d: sphere centroid (%.2f, %.2f) over %d px, projected centre (%.2f, %.2f)", v, cx, cy, n, ex, ey);
	}
	long nonzero = 0;
	for (int j = 0; j < 32; j++)
		for (int i = 0; i < 48; i++) {
			const uint8_t *p = cell_px(&img, 3, i, j);
			nonzero += p[0] | p[1] | p[2] | p[3];
		}
	CHECK(nonzero == 0, "the unused cell is not zero (%ld pixels)", nonzero);
	rnd_image_release(&img);
}

TEST(outputs_fit_objects_leaves_planes_out)
{
	/* Camera fit "objects" frames the sphere alone (the 10x10 plane is left out): the sphere is
	 * centred and the camera backs off until the corners of its bounding box (half-size 1)
	 * project inside the frame less the margin 0.2 on each side. */
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':64,'height':64," VIEW_SCENE ",'camera':{'fit':'objects',"
	                         "'direction':[0.3,-0.4,-1],'margin':0.2,'fov_y':50},'output':{'msaa':1}}"));
	img.view_columns = img.view_columns ? img.view_columns : 1;
	double cx, cy, dist = 0;
	{
		double d[3] = {0.3, -0.4, -1}, up[3] = {0, 1, 0}, rt[3], u[3];
		double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
		for (int k = 0; k < 3; k++) d[k] /= dl;
		rt[0] = d[1] * up[2] - d[2] * up[1]; rt[1] = d[2] * up[0] - d[0] * up[2]; rt[2] = d[0] * up[1] - d[1] * up[0];
		double rl = sqrt(rt[0] * rt[0] + rt[1] * rt[1] + rt[2] * rt[2]);
		for (int k = 0; k < 3; k++) rt[k] /= rl;
		u[0] = rt[1] * d[2] - rt[2] * d[1]; u[1] = rt[2] * d[0] - rt[0] * d[2]; u[2] = rt[0] * d[1] - rt[1] * d[0];
		double t = tan(25 * GPU_DEG) * (1 - 2 * 0.2);
		for (int i = 0; i < 8; i++) {
			double c[3] = {i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1};
			double x = c[0] * rt[0] + c[1] * rt[1] + c[2] * rt[2], y = c[0] * u[0] + c[1] * u[1] + c[2] * u[2];
			double z = c[0] * d[0] + c[1] * d[1] + c[2] * d[2];
			dist = fmax(dist, fmax(fabs(x) / t - z, fabs(y) / t - z));
		}
	}
	double r_px = 32 * tan(asin(1 / dist)) / tan(25 * GPU_DEG), area = GPU_PI * r_px * r_px;
	int n = red_centroid(&img, 0, &cx, &cy);
	CHECK(fabs(cx - 32) < 1.0 && fabs(cy - 32) < 1.0 && fabs(n - area) < 0.08 * area,
	      "sphere centroid (%.2f, %.2f) over %d px, want (32, 32) over about %.0f", cx, cy, n, area);
	rnd_image_release(&img);
}

/* Reads the part names and sizes of an EXR in memory. Returns the part count or -1. */
struct exr_in { const uint8_t *data; size_t len; };
static int64_t exr_read(exr_const_context_t ctx, void *user, void *buf, uint64_t sz, uint64_t off,
                        exr_stream_error_func_ptr_t err)
{
	(void)ctx; (void)err;
	struct exr_in *in = user;
	if (off >= in->len) return 0;
	if (sz > in->len - off) sz = in->len - off;
	memcpy(buf, in->data + off, sz);
	return (int64_t)sz;
}
static int64_t exr_size(exr_const_context_t ctx, void *user) { (void)ctx; return (int64_t)((struct exr_in *)user)->len; }
static void exr_quiet(exr_const_context_t ctx, exr_result_t code, const char *msg) { (void)ctx; (void)code; (void)msg; }

static int exr_parts(const uint8_t *data, size_t len, char names[8][32], int w[8], int h[8], int nch[8])
{
	struct exr_in in = {data, len};
	exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
	init.user_data = &in;
	init.read_fn = exr_read;
	init.size_fn = exr_size;
	init.error_handler_fn = exr_quiet;
	exr_context_t ctx;
	if (exr_start_read(&ctx, "mem.exr", &init) != EXR_ERR_SUCCESS) return -1;
	int n = 0;
	exr_get_count(ctx, &n);
	for (int p = 0; p < n && p < 8; p++) {
		const char *nm = NULL;
		names[p][0] = 0;
		if (exr_get_name(ctx, p, &nm) == EXR_ERR_SUCCESS && nm) snprintf(names[p], 32, "%s", nm);
		exr_attr_box2i_t dw;
		exr_get_data_window(ctx, p, &dw);
		w[p] = dw.max.x - dw.min.x + 1;
		h[p] = dw.max.y - dw.min.y + 1;
		const exr_attr_chlist_t *chl = NULL;
		exr_get_channels(ctx, p, &chl);
		nch[p] = chl ? chl->num_channels : 0;
	}
	exr_finish(&ctx);
	return n;
}

TEST(outputs_turntable_exr_is_multipart)
{
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':32,'height':24," VIEW_SCENE ",'turntable':{'frames':3},"
	                         "'output':{'format':'exr','aovs':['depth','normal'],'msaa':1}}"));
	CHECK(img.format == RND_PIXELS_RGBA32F && img.view_count == 3 && img.width == 64 && img.height == 48 &&
	      img.aov_count == 4, "format %d views %u %ux%u aovs %u", img.format, img.view_count, img.width, img.height,
	      img.aov_count);
	uint8_t *out = NULL;
	size_t len = 0;
	struct api_problem p;
	REQUIRE(api_exr_encode(&img, &out, &len, &p) == API_OK, "%s", p.detail);
	char names[8][32];
	int w[8], h[8], nch[8];
	int n = exr_parts(out, len, names, w, h, nch);
	CHECK(n == 3, "%d parts", n);
	for (int k = 0; k < n && k < 3; k++) {
		char want[16];
		snprintf(want, sizeof want, "view%d", k);
		CHECK(!strcmp(names[k], want) && w[k] == 32 && h[k] == 24 && nch[k] == 8, "part %d: \"%s\" %dx%d, %d channels",
		      k, names[k], w[k], h[k], nch[k]);
	}
	free(out);
	rnd_image_release(&img);
}

/* ---- 2. EXR AOVs ---- */

/* Camera at (0,4,5) looking at the origin (fov 50, 96x64) over a 6x6 plane with a sphere of
 * radius 0.7 at (0.5, 0.7, 0). */
#define AOV_SCENE                                                                                          \
	"'width':96,'height':64,'camera':{'position':[0,4,5],'target':[0,0,0],'fov_y':50},"                  \
	"'environment':{'background':[0.3,0.3,0.3]},"                                                        \
	"'objects':[{'shape':'plane','size':[6,6],'material':{'base_color':[0.2,0.4,0.6],'roughness':0.9}},"  \
	"{'shape':'sphere','radius':0.7,'segments':96,'transform':{'translation':[0.5,0.7,0]},"               \
	"'material':{'base_color':[0.9,0.1,0.2]}}],"                                                         \
	"'lights':[{'type':'directional','direction':[-0.6,-1,-0.4],'shadow':{'filter':'pcf'}}]"

enum { AW = 96, AH = 64 };

/* Per pixel: class (BG, OBJ = sphere, LIT / SHADOW = ground) and the hit distance along the
 * normalised ray. */
static void aov_classes(uint8_t *cls, double *t, struct gpu_cam *cam)
{
	gpu_cam_persp(cam, v3_make(0, 4, 5), v3_make(0, 0, 0), v3_make(0, 1, 0), 50, AW, AH);
	v3 C = v3_make(0.5, 0.7, 0), L = v3_norm(v3_make(0.6, 1, 0.4));
	for (int j = 0; j < AH; j++)
		for (int i = 0; i < AW; i++) {
			v3 o, d;
			gpu_cam_ray(cam, i + 0.5, j + 0.5, &o, &d);
			double ts = gpu_ray_sphere(o, d, C, 0.7, 0), tg = gpu_ray_ground(o, d, 0, 0, 0, 3);
			uint8_t k;
			double th = -1;
			if (ts < 0 && tg < 0) k = GPU_CLS_BG;
			else if (ts > 0 && (tg < 0 || ts < tg)) { k = GPU_CLS_OBJ; th = ts; }
			else {
				v3 p = v3_add(o, v3_scale(d, tg));
				k = gpu_ray_sphere(p, L, C, 0.7, 1e-9) > 0 ? GPU_CLS_SHADOW : GPU_CLS_LIT;
				th = tg;
			}
			cls[j * AW + i] = k;
			t[j * AW + i] = th;
		}
}

static const float *aov_plane(const struct rnd_image *img, const char *name)
{
	for (uint32_t i = 0; i < img->aov_count; i++)
		if (!strcmp(img->aov_names[i], name)) return img->aov[i];
	return NULL;
}

TEST(outputs_exr_aovs)
{
	static uint8_t cls[AW * AH];
	static double th[AW * AH];
	struct gpu_cam cam;
	aov_classes(cls, th, &cam);
	struct rnd_image img, dbg;
	REQUIRE(gpu_render(&img, "{" AOV_SCENE ",'output':{'format':'exr','aovs':['shadow','depth','normal','albedo'],"
	                         "'msaa':1}}"));
	if (!gpu_render(&dbg, "{" AOV_SCENE ",'output':{'debug':'shadow','msaa':1}}")) { rnd_image_release(&img); return; }
	CHECK(img.format == RND_PIXELS_RGBA32F && img.width == AW && img.height == AH);
	CHECK(img.aov_count == 8, "aov planes %u", img.aov_count);
	const float *S = aov_plane(&img, "shadow.0"), *Z = aov_plane(&img, "Z"), *NX = aov_plane(&img, "N.X"),
	            *NY = aov_plane(&img, "N.Y"), *NZ = aov_plane(&img, "N.Z"), *AR = aov_plane(&img, "albedo.R"),
	            *AG = aov_plane(&img, "albedo.G"), *AB = aov_plane(&img, "albedo.B");
	REQUIRE(S && Z && NX && NY && NZ && AR && AG && AB, "missing AOV planes");

	int nbg = 0, nground = 0, nsphere = 0, bad_bg = 0, bad_z = 0, bad_n = 0, bad_alb = 0, bad_sn = 0;
	double max_zerr = 0;
	v3 C = v3_make(0.5, 0.7, 0);
	for (int j = 0; j < AH; j++)
		for (int i = 0; i < AW; i++) {
			size_t k = (size_t)j * AW + i;
			if (gpu_near_edge(cls, AW, AH, i, j, 1) && cls[k] != GPU_CLS_LIT && cls[k] != GPU_CLS_SHADOW) continue;
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			if (cls[k] == GPU_CLS_BG) {
				nbg++;
				if (!(isinf(Z[k]) && Z[k] > 0) || S[k] != 1.0f) bad_bg++;
				continue;
			}
			/* Analytic view depth: distance along the view axis. */
			double z = th[k] * v3_dot(d, cam.fwd);
			bool edge = gpu_near_edge(cls, AW, AH, i, j, 1);
			if (cls[k] == GPU_CLS_OBJ) {
				nsphere++;
				if (fabs(AR[k] - 0.9) > 1e-3 || fabs(AG[k] - 0.1) > 1e-3 || fabs(AB[k] - 0.2) > 1e-3) bad_alb++;
				/* Tessellated sphere: depth and normal within the facets' error. */
				v3 n = v3_norm(v3_sub(v3_add(o, v3_scale(d, th[k])), C));
				if (fabs(NX[k] - n.x) > 0.05 || fabs(NY[k] - n.y) > 0.05 || fabs(NZ[k] - n.z) > 0.05) bad_sn++;
				if (fabs(Z[k] - z) > 0.01 * z) bad_z++;
				continue;
			}
			if (edge) continue; /* ground pixels next to the sphere or the plane's border */
			nground++;
			double err = fabs(Z[k] - z) / z;
			if (err > max_zerr) max_zerr = err;
			if (err > 1e-3) bad_z++;
			if (fabs(NX[k]) > 1e-3 || fabs(NY[k] - 1) > 1e-3 || fabs(NZ[k]) > 1e-3) bad_n++;
			if (fabs(AR[k] - 0.2) > 1e-3 || fabs(AG[k] - 0.4) > 1e-3 || fabs(AB[k] - 0.6) > 1e-3) bad_alb++;
		}
	printf("    %d background, %d ground, %d sphere pixels; ground depth max rel. error %.2e\n", nbg, nground, nsphere,
	       max_zerr);
	CHECK(nbg > 200 && nground > 1500 && nsphere > 100, "classes %d %d %d", nbg, nground, nsphere);
	CHECK(bad_bg == 0, "%d background pixels without Z = +inf and visibility 1", bad_bg);
	CHECK(bad_z == 0, "%d pixels with Z off the analytic view depth (max ground rel. error %.2e)", bad_z, max_zerr);
	CHECK(bad_n == 0, "%d ground pixels with N != (0,1,0)", bad_n);
	CHECK(bad_sn == 0, "%d sphere pixels with N off the analytic normal", bad_sn);
	CHECK(bad_alb == 0, "%d pixels with albedo != base colour", bad_alb);
	/* Some of the ground is in the sphere's shadow, some lit. */
	int shadowed = 0, lit = 0;
	for (int k = 0; k < AW * AH; k++) {
		if (cls[k] == GPU_CLS_SHADOW && S[k] < 0.1f) shadowed++;
		if (cls[k] == GPU_CLS_LIT && S[k] > 0.9f) lit++;
	}
	CHECK(shadowed > 50 && lit > 1000, "shadowed %d, lit %d", shadowed, lit);

	/* shadow.0 is the debug shadow view's value (contract §4, §7). */
	CHECK(dbg.format == RND_PIXELS_RGBA8 && dbg.width == AW && dbg.height == AH);
	int agree = 0, worst = 0;
	for (int j = 0; j < AH; j++)
		for (int i = 0; i < AW; i++) {
			int want = (int)lround(S[(size_t)j * AW + i] * 255.0), got = gpu_px8(&dbg, i, j)[0];
			int dd = abs(got - want);
			if (dd <= 1) agree++;
			if (dd > worst) worst = dd;
		}
	printf("    shadow.0 vs debug shadow: %.2f%% within 1/255, worst %d\n", 100.0 * agree / (AW * AH), worst);
	CHECK(agree >= 0.99 * AW * AH, "shadow.0 agrees with the debug shadow PNG on %d of %d pixels (worst %d)", agree,
	      AW * AH, worst);
	rnd_image_release(&img);
	rnd_image_release(&dbg);
}

/* ---- 3. transparent PNG, shadow catcher, 16-bit ---- */

TEST(outputs_transparent_png_alpha)
{
	static uint8_t cls[AW * AH];
	static double th[AW * AH];
	struct gpu_cam cam;
	aov_classes(cls, th, &cam);
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{" AOV_SCENE ",'output':{'transparent':true,'msaa':1}}"));
	int bad = 0, n = 0;
	for (int j = 0; j < AH; j++)
		for (int i = 0; i < AW; i++) {
			if (gpu_near_edge(cls, AW, AH, i, j, 1)) continue;
			bool bg = cls[j * AW + i] == GPU_CLS_BG;
			const uint8_t *p = gpu_px8(&img, i, j);
			n++;
			if (p[3] != (bg ? 0 : 255)) {
				if (!bad++) CHECK(0, "pixel (%d,%d) alpha %d, want %d", i, j, p[3], bg ? 0 : 255);
			}
		}
	CHECK(bad == 0 && n > 4000, "%d of %d pixels with the wrong alpha", bad, n);
	rnd_image_release(&img);
}

/* A 6x6 shadow-catcher plane under a sphere of radius 0.7 at (0, 0.7, 0), hard shadows. */
#define CATCHER_SCENE(transparent)                                                                        \
	"{'width':96,'height':64,'camera':{'position':[0,3.5,3],'target':[0.5,0,0.3],'fov_y':50},"           \
	"'environment':{'background':[0.3,0.5,0.7]},"                                                        \
	"'objects':[{'shape':'plane','size':[6,6],'material':{'shadow_catcher':true}},"                      \
	"{'shape':'sphere','radius':0.7,'segments':96,'transform':{'translation':[0,0.7,0]},"                 \
	"'material':{'base_color':[0.8,0.8,0.8]}}],"                                                         \
	"'lights':[{'type':'directional','direction':[0.8,-1,0.3],'shadow':{'filter':'hard'}}],"            \
	"'output':{'transparent':" transparent ",'msaa':1}}"

static void catcher_classes(uint8_t *cls)
{
	struct gpu_cam cam;
	gpu_cam_persp(&cam, v3_make(0, 3.5, 3), v3_make(0.5, 0, 0.3), v3_make(0, 1, 0), 50, AW, AH);
	v3 C = v3_make(0, 0.7, 0), L = v3_norm(v3_make(-0.8, 1, -0.3));
	for (int j = 0; j < AH; j++)
		for (int i = 0; i < AW; i++) {
			v3 o, d;
			gpu_cam_ray(&cam, i + 0.5, j + 0.5, &o, &d);
			double ts = gpu_ray_sphere(o, d, C, 0.7, 0), tg = gpu_ray_ground(o, d, 0, 0, 0, 3);
			uint8_t k;
			if (ts < 0 && tg < 0) k = GPU_CLS_BG;
			else if (ts > 0 && (tg < 0 || ts < tg)) k = GPU_CLS_OBJ;
			else k = gpu_ray_sphere(v3_add(o, v3_scale(d, tg)), L, C, 0.7, 1e-9) > 0 ? GPU_CLS_SHADOW : GPU_CLS_LIT;
			cls[j * AW + i] = k;
		}
}

TEST(outputs_shadow_catcher)
{
	static uint8_t cls[AW * AH];
	catcher_classes(cls);
	struct rnd_image tr, op;
	REQUIRE(gpu_render(&tr, CATCHER_SCENE("true")));
	if (!gpu_render(&op, CATCHER_SCENE("false"))) { rnd_image_release(&tr); return; }
	int bg[3];
	for (int c = 0; c < 3; c++) bg[c] = (int)lround(gpu_srgb_encode(0.3 + 0.2 * c) * 255);
	int n[5] = {0}, bad_t[5] = {0}, bad_o[5] = {0};
	for (int j = 0; j < AH; j++)
		for (int i = 0; i < AW; i++) {
			int k = cls[j * AW + i];
			if (gpu_near_edge(cls, AW, AH, i, j, 2)) continue;
			const uint8_t *t = gpu_px8(&tr, i, j), *o = gpu_px8(&op, i, j);
			n[k]++;
			bool ok_t, ok_o;
			switch (k) {
			case GPU_CLS_BG: case GPU_CLS_LIT: /* the catcher is invisible where it is lit */
				ok_t = t[3] == 0;
				ok_o = abs(o[0] - bg[0]) <= 1 && abs(o[1] - bg[1]) <= 1 && abs(o[2] - bg[2]) <= 1 && o[3] == 255;
				break;
			case GPU_CLS_SHADOW: /* shadow: dark, opaque enough; the background darkened */
				ok_t = t[3] > 128 && t[0] <= 8 && t[1] <= 8 && t[2] <= 8;
				ok_o = o[0] * 2 <= bg[0] && o[1] * 2 <= bg[1] && o[2] * 2 <= bg[2];
				break;
			default: /* the sphere */
				ok_t = t[3] == 255;
				ok_o = o[3] == 255;
				break;
			}
			if (!ok_t && !bad_t[k]++)
				CHECK(0, "transparent: class %d pixel (%d,%d) = %d %d %d %d", k, i, j, t[0], t[1], t[2], t[3]);
			if (!ok_o && !bad_o[k]++)
				CHECK(0, "opaque: class %d pixel (%d,%d) = %d %d %d (background %d %d %d)", k, i, j, o[0], o[1], o[2],
				      bg[0], bg[1], bg[2]);
		}
	printf("    pixels: %d background, %d sphere, %d lit catcher, %d shadowed catcher\n", n[GPU_CLS_BG], n[GPU_CLS_OBJ],
	       n[GPU_CLS_LIT], n[GPU_CLS_SHADOW]);
	CHECK(n[GPU_CLS_SHADOW] > 40 && n[GPU_CLS_LIT] > 1000 && n[GPU_CLS_OBJ] > 100, "classes");
	for (int k = 0; k < 4; k++)
		CHECK(!bad_t[k] && !bad_o[k], "class %d: %d transparent and %d opaque pixels wrong of %d", k, bad_t[k], bad_o[k],
		      n[k]);
	rnd_image_release(&tr);
	rnd_image_release(&op);
}

TEST(outputs_png_16bit_matches_8bit)
{
	struct rnd_image a, b;
	REQUIRE(gpu_render(&a, "{" AOV_SCENE ",'output':{'bit_depth':8,'msaa':1,'transparent':true}}"));
	if (!gpu_render(&b, "{" AOV_SCENE ",'output':{'bit_depth':16,'msaa':1,'transparent':true}}")) {
		rnd_image_release(&a);
		return;
	}
	REQUIRE(a.format == RND_PIXELS_RGBA8 && b.format == RND_PIXELS_RGBA16 && a.width == b.width && a.height == b.height,
	        "formats %d %d", a.format, b.format);
	long bad = 0, fine = 0;
	int worst = 0;
	for (uint32_t j = 0; j < a.height; j++)
		for (uint32_t i = 0; i < a.width; i++) {
			const uint8_t *p8 = gpu_px8(&a, (int)i, (int)j);
			const uint16_t *p16 = (const uint16_t *)(const void *)((const uint8_t *)b.pixels + j * b.stride) + 4 * i;
			for (int c = 0; c < 4; c++) {
				int d = abs((int)lround(p16[c] / 257.0) - p8[c]);
				if (d > worst) worst = d;
				if (d > 1) bad++;
				if (c < 3 && p16[c] % 257) fine++; /* values between the 8-bit steps: real 16-bit output */
			}
		}
	CHECK(bad == 0, "%ld samples differ by more than 1 (worst %d)", bad, worst);
	CHECK(fine > 1000, "only %ld samples use the 16-bit precision", fine);
	rnd_image_release(&a);
	rnd_image_release(&b);
}

/* ---- 4. base-colour texture ---- */

TEST(outputs_textured_plane_checker)
{
	/* A 2x2 checker, red and blue, as a PNG written by libpng. */
	const uint8_t texels[2][2][4] = {{{255, 0, 0, 255}, {0, 0, 255, 255}}, {{0, 0, 255, 255}, {255, 0, 0, 255}}};
	png_image pi;
	memset(&pi, 0, sizeof pi);
	pi.version = PNG_IMAGE_VERSION;
	pi.width = 2;
	pi.height = 2;
	pi.format = PNG_FORMAT_RGBA;
	uint8_t png[512];
	png_alloc_size_t len = sizeof png;
	REQUIRE(png_image_write_to_memory(&pi, png, &len, 0, texels, 0, NULL), "%s", pi.message);
	char enc[1024];
	test_b64_into(png, len, enc);
	/* Straight down onto a 2x2 plane (white material, light of intensity pi: radiance = texel). */
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':64,'height':64,'camera':{'position':[0,5,0.001],'target':[0,0,0],'fov_y':30},"
	                         "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	                         "'objects':[{'shape':'plane','size':[2,2],'material':{'base_color':[1,1,1],'roughness':1,"
	                         "'base_color_texture':'%s'}}],"
	                         "'lights':[{'type':'directional','direction':[0,-1,0],'intensity':3.14159265}],"
	                         "'output':{'tonemap':'none','msaa':1}}",
	                         enc));
	struct gpu_cam cam;
	gpu_cam_persp(&cam, v3_make(0, 5, 0.001), v3_make(0, 0, 0), v3_make(0, 1, 0), 30, 64, 64);
	/* The quadrant centres (texel centres) show the texels' colours, alternating: diagonal
	 * quadrants alike, neighbours different. Not exactly pure: GGX specular adds about 0.01
	 * (sRGB 26) to every channel, and the pixel centre is a fraction of a texel off the texel
	 * centre, so bilinear filtering mixes in a little of the neighbour. */
	int colour[4];
	const double qx[4] = {-0.5, 0.5, 0.5, -0.5}, qz[4] = {-0.5, -0.5, 0.5, 0.5};
	for (int q = 0; q < 4; q++) {
		double px, py;
		gpu_cam_project(&cam, v3_make(qx[q], 0, qz[q]), &px, &py);
		const uint8_t *p = gpu_px8(&img, (int)lround(px - 0.5), (int)lround(py - 0.5)); /* nearest pixel centre */
		colour[q] = p[0] > 220 && p[1] < 60 && p[2] < 100 ? 0 : p[2] > 220 && p[0] < 100 && p[1] < 60 ? 1 : -1;
		printf("    quadrant (%+.1f, %+.1f) at pixel (%d,%d): %d %d %d\n", qx[q], qz[q], (int)px, (int)py, p[0], p[1], p[2]);
		CHECK(colour[q] >= 0, "quadrant %d is neither red nor blue: %d %d %d", q, p[0], p[1], p[2]);
	}
	CHECK(colour[0] == colour[2] && colour[1] == colour[3] && colour[0] != colour[1], "not a checker: %d %d %d %d",
	      colour[0], colour[1], colour[2], colour[3]);
	/* Both colours cover large areas (bilinear filtering blends them in between). */
	long red = 0, blue = 0, plane = 0;
	for (int j = 0; j < 64; j++)
		for (int i = 0; i < 64; i++) {
			const uint8_t *p = gpu_px8(&img, i, j);
			plane += p[0] + p[2] > 100;
			red += p[0] > p[2] + 10;
			blue += p[2] > p[0] + 10;
		}
	printf("    plane %ld px: red-dominant %ld, blue-dominant %ld\n", plane, red, blue);
	CHECK(plane > 1500 && red > plane / 3 && blue > plane / 3, "red %ld, blue %ld of %ld pixels", red, blue, plane);
	rnd_image_release(&img);
}

TEST(outputs_views_keep_view0_shadow_layout)
{
	/* `auto` picks cascades for a camera close to a big scene and one fitted map for a camera
	 * far away. In one request the views share their shadow tiles, so every view keeps view
	 * 0's choice: the far view must render (and show the box's shadow) without touching tiles
	 * it was not given. */
	struct rnd_image img;
	REQUIRE(gpu_render(&img, "{'width':48,'height':48,'views':["
	                         "{'position':[3,2,3],'target':[0,0,0]},{'position':[600,400,600],'target':[0,0,0]}],"
	                         "'objects':[{'shape':'plane','size':[400,400]},{'shape':'box','size':[1,1,1],"
	                         "'transform':{'translation':[0,0.5,0]}}],"
	                         "'lights':[{'type':'directional','direction':[0.6,-1,0.5]}],"
	                         "'output':{'debug':'shadow','msaa':1}}"));
	CHECK(img.view_count == 2 && img.width == 96 && img.height == 48, "sheet %ux%u of %u views", img.width, img.height,
	      img.view_count);
	/* The near view sees the box's shadow on the ground: some pixels read 0. */
	long dark = 0;
	for (uint32_t j = 0; j < 48; j++)
		for (uint32_t i = 0; i < 48; i++)
			dark += ((const uint8_t *)img.pixels)[j * img.stride + i * 4] < 64;
	CHECK(dark > 20, "near view: %ld shadowed px", dark);
	rnd_image_release(&img);
}
