/* tests/gpu — imported models in renders (contract §2 `model`, camera auto-framing `fit`,
 * materials alpha_mode / base_color_texture): .glb / .obj / binary .stl files built here, framed
 * with `fit` and compared with where this file's own camera math says the tightly framed bounds
 * project; a masked checkerboard quad whose shadow must be a checkerboard lined up with the
 * texture's cells (and the same quad opaque, whose shadow is the whole square). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <png.h>
#include "gpu_util.h"
#include "models.h"
#include "test.h"
#include "util.h"

/* ---- building files ---- */


/* The 8x8 checkerboard: texel (col, row) (row 0 = the image's first row) is opaque red when
 * col + row is even, transparent green (alpha 0) when odd. */
#define CHK 8
static bool chk_opaque(int col, int row) { return ((col + row) & 1) == 0; }

static uint8_t *checker_png(size_t *len)
{
	uint8_t px[CHK * CHK * 4];
	for (int r = 0; r < CHK; r++)
		for (int c = 0; c < CHK; c++) {
			uint8_t *p = px + 4 * (r * CHK + c);
			bool o = chk_opaque(c, r);
			p[0] = o ? 255 : 0; p[1] = o ? 0 : 255; p[2] = 0; p[3] = o ? 255 : 0;
		}
	return test_png_rgba(px, CHK, CHK, len);
}

/* A box [lo, hi] as 24 vertices (flat normals, outward, counter-clockwise) and 36 indices. */
static void box_mesh(const float lo[3], const float hi[3], float pos[72], float nrm[72], uint32_t idx[36])
{
	/* per face: axis, sign; corners in CCW order seen from outside */
	int v = 0, t = 0;
	for (int axis = 0; axis < 3; axis++) {
		for (int s = 0; s < 2; s++) {
			int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
			/* (a1, a2) CCW seen from +axis; flip for -axis */
			static const int q[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
			for (int k = 0; k < 4; k++) {
				int kk = s ? k : (4 - k) % 4;
				float *p = pos + 3 * (v + k), *n = nrm + 3 * (v + k);
				p[axis] = s ? hi[axis] : lo[axis];
				p[a1] = q[kk][0] ? hi[a1] : lo[a1];
				p[a2] = q[kk][1] ? hi[a2] : lo[a2];
				n[0] = n[1] = n[2] = 0;
				n[axis] = s ? 1.0f : -1.0f;
			}
			uint32_t b = (uint32_t)v;
			idx[t++] = b; idx[t++] = b + 1; idx[t++] = b + 2;
			idx[t++] = b; idx[t++] = b + 2; idx[t++] = b + 3;
			v += 4;
		}
	}
}

/* Wavefront .obj text of the box [lo, hi] (8 vertices, 6 quads). */
static char *box_obj(const float lo[3], const float hi[3])
{
	char *s = malloc(1024);
	int n = snprintf(s, 1024, "# box\no box\n");
	for (int i = 0; i < 8; i++)
		n += snprintf(s + n, 1024 - n, "v %.9g %.9g %.9g\n", i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1],
		              i & 4 ? hi[2] : lo[2]);
	/* vertex k (1-based k+1): bit0 x, bit1 y, bit2 z */
	snprintf(s + n, 1024 - n,
	         "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n");
	return s;
}

/* ---- 1. framing ---- */

#define FW 160
#define FH 120
#define FMARGIN 0.1
static const v3 FDIR = {-1, -0.7, -0.5};

/* The camera a tight fit places (contract §2 as the brief states it): looking at the bounds'
 * centre along FDIR (up +Y, fov_y 45°), at the smallest distance where all 8 bounds corners
 * project within NDC ±(1 − 2·margin). */
static void fit_camera(struct gpu_cam *cam, v3 lo, v3 hi)
{
	v3 c = v3_scale(v3_add(lo, hi), 0.5), d = v3_norm(FDIR);
	gpu_cam_persp(cam, v3_sub(c, d), c, v3_make(0, 1, 0), 45, FW, FH);
	double shrink = 1 - 2 * FMARGIN;
	double ty = tan(22.5 * GPU_DEG) * shrink, tx = ty * FW / FH;
	double dist = 1e-3;
	for (int i = 0; i < 8; i++) {
		v3 p = v3_make(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
		v3 rel = v3_sub(p, c);
		double x = v3_dot(rel, cam->right), y = v3_dot(rel, cam->up), z = v3_dot(rel, cam->fwd);
		dist = fmax(dist, fabs(x) / tx - z);
		dist = fmax(dist, fabs(y) / ty - z);
	}
	gpu_cam_persp(cam, v3_sub(c, v3_scale(d, dist)), c, v3_make(0, 1, 0), 45, FW, FH);
}

/* Silhouette rectangle in pixel-edge units: left, top, right, bottom (right/bottom exclusive). */
struct rect { double l, t, r, b; };

static bool model_px(const uint8_t *p)
{
	/* the model is red; background green, ground blue */
	return p[0] > 30 && p[0] > 2 * p[1] && p[0] > 2 * p[2];
}

/* Renders the model (world vertices `wv`) framed by `fit`, optionally over a 40 m ground plane
 * at y = ground_y, and returns the measured silhouette rectangle. Checks it against the rectangle
 * the fit camera predicts, and the margin rules. */
static bool frame_one(int line, const char *label, const char *model_json, const v3 *wv, int nv, const char *fit,
                      bool plane, double ground_y, struct rect *meas)
{
	v3 lo = wv[0], hi = wv[0];
	for (int i = 1; i < nv; i++) {
		lo = v3_make(fmin(lo.x, wv[i].x), fmin(lo.y, wv[i].y), fmin(lo.z, wv[i].z));
		hi = v3_make(fmax(hi.x, wv[i].x), fmax(hi.y, wv[i].y), fmax(hi.z, wv[i].z));
	}
	struct gpu_cam cam;
	fit_camera(&cam, lo, hi);
	struct rect pred = {1e9, 1e9, -1e9, -1e9};
	for (int i = 0; i < nv; i++) {
		double px, py;
		gpu_cam_project(&cam, wv[i], &px, &py);
		pred.l = fmin(pred.l, px); pred.r = fmax(pred.r, px);
		pred.t = fmin(pred.t, py); pred.b = fmax(pred.b, py);
	}

	char ground[160] = "";
	if (plane)
		snprintf(ground, sizeof ground,
		         "{'shape':'plane','size':[40,40],'material':{'base_color':[0.05,0.05,0.9]},"
		         "'transform':{'translation':[0,%.9g,0]}},", ground_y);
	struct rnd_image img;
	if (!gpu_render_at(__FILE__, line, &img,
	                   "{'width':%d,'height':%d,"
	                   "'camera':{'fit':'%s','direction':[%.9g,%.9g,%.9g],'margin':%.9g},"
	                   "'environment':{'background':[0,0.6,0],'ambient':{'sky':[1,1,1],'ground':[1,1,1],'intensity':0.5}},"
	                   "'objects':[%s%s],"
	                   "'lights':[{'type':'directional','direction':[0.3,-1,-0.2],'intensity':3}],"
	                   "'output':{'msaa':1}}",
	                   FW, FH, fit, FDIR.x, FDIR.y, FDIR.z, FMARGIN, ground, model_json))
		return false;
	int l = FW, t = FH, r = -1, b = -1;
	long n = 0;
	for (int j = 0; j < FH; j++)
		for (int i = 0; i < FW; i++)
			if (model_px(gpu_px8(&img, i, j))) {
				n++;
				if (i < l) l = i;
				if (i > r) r = i;
				if (j < t) t = j;
				if (j > b) b = j;
			}
	free(img.pixels);
	if (!n) {
		test_fail_at(__FILE__, line, label, " (fit %s%s): no model pixel in the image", fit, plane ? ", ground" : "");
		return false;
	}
	meas->l = l; meas->t = t; meas->r = r + 1; meas->b = b + 1;

	const double tol = 2;
	bool ok = fabs(meas->l - pred.l) <= tol && fabs(meas->r - pred.r) <= tol && fabs(meas->t - pred.t) <= tol &&
	          fabs(meas->b - pred.b) <= tol;
	if (!ok)
		test_fail_at(__FILE__, line, label,
		             " (fit %s%s): silhouette x %g..%g y %g..%g px, expected x %.2f..%.2f y %.2f..%.2f "
		             "(bounds [%g %g %g]..[%g %g %g], camera at [%.3f %.3f %.3f])",
		             fit, plane ? ", ground" : "", meas->l, meas->r, meas->t, meas->b, pred.l, pred.r, pred.t, pred.b,
		             lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, cam.pos.x, cam.pos.y, cam.pos.z);
	/* Inside the margin on all sides; touching it on at least one where the prediction does. */
	double ml = FMARGIN * FW, mr = FW - FMARGIN * FW, mt = FMARGIN * FH, mb = FH - FMARGIN * FH;
	bool inside = meas->l >= ml - tol && meas->r <= mr + tol && meas->t >= mt - tol && meas->b <= mb + tol;
	if (!inside)
		test_fail_at(__FILE__, line, label, " (fit %s%s): silhouette x %g..%g y %g..%g leaves the margin x %g..%g y %g..%g",
		             fit, plane ? ", ground" : "", meas->l, meas->r, meas->t, meas->b, ml, mr, mt, mb);
	double pgap = fmin(fmin(fabs(pred.l - ml), fabs(pred.r - mr)), fmin(fabs(pred.t - mt), fabs(pred.b - mb)));
	double mgap = fmin(fmin(fabs(meas->l - ml), fabs(meas->r - mr)), fmin(fabs(meas->t - mt), fabs(meas->b - mb)));
	if (pgap <= 0.5 && mgap > tol)
		test_fail_at(__FILE__, line, label,
		             " (fit %s%s): silhouette x %g..%g y %g..%g touches no margin limit (x %g / %g, y %g / %g): "
		             "closest by %g px",
		             fit, plane ? ", ground" : "", meas->l, meas->r, meas->t, meas->b, ml, mr, mt, mb, mgap);
	return ok && inside;
}

/* The three fits of one model: `scene` and `objects` alone, `objects` over a ground plane; the
 * plane must not change the model's extent. `touch`: the model is a box, whose silhouette must
 * reach the margin (self-check of the prediction). */
static void frame_model(int line, const char *label, const char *model_json, const v3 *wv, int nv, bool touch)
{
	if (touch) {
		/* a box: its widest bounds corner is one of its vertices, so the prediction touches */
		v3 lo = wv[0], hi = wv[0];
		for (int i = 1; i < nv; i++) {
			lo = v3_make(fmin(lo.x, wv[i].x), fmin(lo.y, wv[i].y), fmin(lo.z, wv[i].z));
			hi = v3_make(fmax(hi.x, wv[i].x), fmax(hi.y, wv[i].y), fmax(hi.z, wv[i].z));
		}
		struct gpu_cam cam;
		fit_camera(&cam, lo, hi);
		double gap = 1e9;
		for (int i = 0; i < nv; i++) {
			double px, py;
			gpu_cam_project(&cam, wv[i], &px, &py);
			gap = fmin(gap, fmin(fmin(fabs(px - FMARGIN * FW), fabs(px - (1 - FMARGIN) * FW)),
			                     fmin(fabs(py - FMARGIN * FH), fabs(py - (1 - FMARGIN) * FH))));
		}
		if (gap > 1e-6) test_fail_at(__FILE__, line, label, " self-check: predicted box silhouette misses the margin by %g", gap);
	}
	double gy = 1e9;
	for (int i = 0; i < nv; i++) gy = fmin(gy, wv[i].y);
	struct rect a, b, c;
	bool ok_scene = frame_one(line, label, model_json, wv, nv, "scene", false, 0, &a);
	bool ok_obj = frame_one(line, label, model_json, wv, nv, "objects", false, 0, &b);
	bool ok_plane = frame_one(line, label, model_json, wv, nv, "objects", true, gy - 0.25, &c);
	(void)ok_scene;
	if (ok_obj && ok_plane) {
		if (fabs(b.l - c.l) > 2 || fabs(b.r - c.r) > 2 || fabs(b.t - c.t) > 2 || fabs(b.b - c.b) > 2)
			test_fail_at(__FILE__, line, label,
			             " fit objects: the ground plane changed the framing: x %g..%g y %g..%g alone, "
			             "x %g..%g y %g..%g with the plane", b.l, b.r, b.t, b.b, c.l, c.r, c.t, c.b);
	}
}

#define RED_MAT "'material':{'base_color':[0.9,0.05,0.05],'roughness':0.8}"

TEST(models_fit_glb_box)
{
	/* a 2 x 1 x 0.5 box centred in its mesh, node translation (1.5, 1, -2), object translation
	 * (0, 0.5, 0): world [0.5, 1, -2.25] .. [2.5, 2, -1.75] */
	float lo[3] = {-1, -0.5f, -0.25f}, hi[3] = {1, 0.5f, 0.25f}, pos[72], nrm[72];
	uint32_t idx[36];
	box_mesh(lo, hi, pos, nrm, idx);
	struct test_glb_mesh in = {.pos = pos, .nrm = nrm, .nv = 24, .idx = idx, .ni = 36, .node_t = {1.5f, 1, -2}};
	size_t n;
	uint8_t *glb = test_glb_mesh(&in, &n);
	char *enc = test_b64(glb, n);
	free(glb);
	size_t cap = strlen(enc) + 256;
	char *obj = malloc(cap);
	snprintf(obj, cap, "{'shape':'model','data':'%s','transform':{'translation':[0,0.5,0]}," RED_MAT "}", enc);
	v3 wv[8];
	for (int i = 0; i < 8; i++)
		wv[i] = v3_make((i & 1 ? 1 : -1) + 1.5, (i & 2 ? 0.5 : -0.5) + 1.5, (i & 4 ? 0.25 : -0.25) - 2);
	frame_model(__LINE__, "glb box", obj, wv, 8, true);
	free(obj);
	free(enc);
}

TEST(models_fit_obj_box)
{
	/* 2 x 1 x 0.5 box at [-3, -1, 0.5] .. [-1, 0, 1] in the file, object translation (0, 0.25, 0) */
	float lo[3] = {-3, -1, 0.5f}, hi[3] = {-1, 0, 1};
	char *text = box_obj(lo, hi);
	char *enc = test_b64((const uint8_t *)text, strlen(text));
	free(text);
	size_t cap = strlen(enc) + 256;
	char *obj = malloc(cap);
	snprintf(obj, cap, "{'shape':'model','data':'%s','format':'obj','transform':{'translation':[0,0.25,0]}," RED_MAT "}",
	         enc);
	v3 wv[8];
	for (int i = 0; i < 8; i++)
		wv[i] = v3_make(i & 1 ? hi[0] : lo[0], (i & 2 ? hi[1] : lo[1]) + 0.25, i & 4 ? hi[2] : lo[2]);
	frame_model(__LINE__, "obj box", obj, wv, 8, true);
	free(obj);
	free(enc);
}

TEST(models_fit_stl_tetrahedron)
{
	/* a right-angled tetrahedron of legs 1.5 at (-2, 0.3, 1), sniffed (no format) */
	static const float p[4][3] = {{-2, 0.3f, 1}, {-0.5f, 0.3f, 1}, {-2, 1.8f, 1}, {-2, 0.3f, 2.5f}};
	uint8_t stl[284];
	size_t n = test_tetra_stl(stl, p);
	char *enc = test_b64(stl, n);
	size_t cap = strlen(enc) + 256;
	char *obj = malloc(cap);
	snprintf(obj, cap, "{'shape':'model','data':'%s'," RED_MAT "}", enc);
	v3 wv[4];
	for (int i = 0; i < 4; i++) wv[i] = v3_make(p[i][0], p[i][1], p[i][2]);
	frame_model(__LINE__, "stl tetrahedron", obj, wv, 4, false);
	free(obj);
	free(enc);
}

/* ---- 2, 3. masked checkerboard quad and its shadow ---- */

#define QW 160
#define QH 160
#define QA 0.6       /* quad half size: x, z in [-QA, QA] */
#define QY 1.0       /* quad height */
#define SUNX 1.6     /* sun direction [SUNX, -1, 0]: the shadow is the quad moved by SUNX * QY along +x */
#define QCX 0.8      /* camera centre x */
#define QORTHO 3.2   /* orthographic height: x in [-0.8, 2.4], z in [-1.6, 1.6] */

/* Quad vertices (y = 0 in the mesh; placed at QY by a transform), uv u = (x + a) / 2a,
 * v = (z + a) / 2a: texel row 0 (v near 0) is at z = -a, column 0 at x = -a. Front face +Y. */
static const float QPOS[12] = {-QA, 0, -QA, QA, 0, -QA, QA, 0, QA, -QA, 0, QA};
static const float QNRM[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
static const float QUV[8] = {0, 0, 1, 0, 1, 1, 0, 1};
static const uint32_t QIDX[6] = {0, 2, 1, 0, 3, 2};

static v3 cell_centre(int col, int row)
{
	double s = 2 * QA / CHK;
	return v3_make(-QA + (col + 0.5) * s, QY, -QA + (row + 0.5) * s);
}

static void quad_cam(struct gpu_cam *cam)
{
	gpu_cam_ortho(cam, v3_make(QCX, 5, 0), v3_make(QCX, 0, 0), v3_make(0, 0, -1), QORTHO, QW, QH);
}

static bool quad_render(int line, struct rnd_image *img, const char *quad_obj, bool debug)
{
	return gpu_render_at(__FILE__, line, img,
	                     "{'width':%d,'height':%d,"
	                     "'camera':{'type':'orthographic','position':[%.9g,5,0],'target':[%.9g,0,0],'up':[0,0,-1],"
	                     "'height':%.9g},"
	                     "'environment':{'background':[0,0,0]},"
	                     "'objects':[{'shape':'plane','size':[8,8],'material':{'base_color':[0.1,0.2,0.9]}},%s],"
	                     "'lights':[{'type':'directional','direction':[%.9g,-1,0],'intensity':3,"
	                     "'shadow':{'filter':'hard'}}],"
	                     "'shadows':{'resolution':2048},"
	                     "'output':{%s'msaa':1}}",
	                     QW, QH, QCX, QCX, QORTHO, quad_obj, SUNX, debug ? "'debug':'shadow'," : "");
}

static void px_at(const struct gpu_cam *cam, v3 p, int *i, int *j)
{
	double x, y;
	gpu_cam_project(cam, p, &x, &y);
	*i = (int)floor(x);
	*j = (int)floor(y);
}

/* Debug-shadow and beauty checks of one quad object (`masked`: the checkerboard's transparent
 * cells must let the light and the view through; else the whole square is opaque). */
static void quad_check(int line, const char *label, const char *quad_obj, bool masked)
{
	struct gpu_cam cam;
	quad_cam(&cam);
	struct rnd_image img;
	if (!quad_render(line, &img, quad_obj, true)) return;
	/* The shadow of the cell centred at (x, QY, z) lies at (x + SUNX·QY, 0, z). */
	char map[CHK * (CHK + 1) + 1], want[CHK * (CHK + 1) + 1];
	int bad = 0, k = 0;
	for (int row = 0; row < CHK; row++) {
		for (int col = 0; col < CHK; col++, k++) {
			v3 c = cell_centre(col, row);
			int i, j;
			px_at(&cam, v3_make(c.x + SUNX * QY, 0, c.z), &i, &j);
			uint8_t v = gpu_px8(&img, i, j)[0];
			bool shadow_want = !masked || chk_opaque(col, row);
			bool shadow_got = v < 128;
			map[k] = v < 20 ? '#' : v > 235 ? '.' : '?';
			want[k] = shadow_want ? '#' : '.';
			if (shadow_got != shadow_want || (v > 20 && v < 235)) bad++;
		}
		map[k] = want[k] = '/';
		k++;
	}
	map[k] = want[k] = 0;
	if (bad)
		test_fail_at(__FILE__, line, label, " debug shadow: %d of 64 shadow cells wrong (# shadow, . lit):\n"
		             "    got  %s\n    want %s", bad, map, want);
	/* Opaque quad: the whole projected square is shadowed (1 px inside its edges), and lit just
	 * outside; masked or not, the ground seen around it is lit. */
	int inner_bad = 0, inner_n = 0, outer_bad = 0, outer_n = 0;
	double px_w = QORTHO / QH;
	for (int g = 0; g <= 40; g++) {
		for (int h = 0; h <= 40; h++) {
			double x = -QA + 2 * QA * g / 40.0, z = -QA + 2 * QA * h / 40.0;
			if (!masked) {
				double xi = fmax(fmin(x, QA - 1.5 * px_w), -QA + 1.5 * px_w);
				double zi = fmax(fmin(z, QA - 1.5 * px_w), -QA + 1.5 * px_w);
				int i, j;
				px_at(&cam, v3_make(xi + SUNX * QY, 0, zi), &i, &j);
				inner_n++;
				if (gpu_px8(&img, i, j)[0] > 20) inner_bad++;
			}
			if (g == 0 || g == 40 || h == 0 || h == 40) {
				/* just outside the shadow square (3 px) */
				double xo = x + (g == 0 ? -3 : g == 40 ? 3 : 0) * px_w;
				double zo = z + (h == 0 ? -3 : h == 40 ? 3 : 0) * px_w;
				int i, j;
				px_at(&cam, v3_make(xo + SUNX * QY, 0, zo), &i, &j);
				outer_n++;
				if (gpu_px8(&img, i, j)[0] < 235) outer_bad++;
			}
		}
	}
	CHECK(inner_bad == 0, "%s debug shadow: %d of %d points inside the opaque quad's shadow are lit", label,
	      inner_bad, inner_n);
	CHECK(outer_bad == 0, "%s debug shadow: %d of %d points just outside the shadow square are not lit", label,
	      outer_bad, outer_n);
	free(img.pixels);

	/* Beauty: seen from above, the quad's opaque cells are red (texture × white), masked cells
	 * show the blue ground; with alpha_mode opaque the alpha-0 texels show their green. On the
	 * ground, shadowed cells are darker than lit ones. */
	if (!quad_render(line, &img, quad_obj, false)) return;
	int cbad = 0;
	k = 0;
	for (int row = 0; row < CHK; row++) {
		for (int col = 0; col < CHK; col++, k++) {
			int i, j;
			px_at(&cam, cell_centre(col, row), &i, &j);
			const uint8_t *p = gpu_px8(&img, i, j);
			char got;
			if (p[0] > 2 * p[1] && p[0] > 2 * p[2] && p[0] > 40) got = 'R';
			else if (p[1] > 2 * p[0] && p[1] > 2 * p[2] && p[1] > 40) got = 'G';
			else if (p[2] > 2 * p[0] && p[2] > p[1] && p[2] > 40) got = 'B';
			else got = '?';
			char w = chk_opaque(col, row) ? 'R' : masked ? 'B' : 'G';
			map[k] = got;
			want[k] = w;
			if (got != w) cbad++;
		}
		map[k] = want[k] = '/';
		k++;
	}
	map[k] = want[k] = 0;
	if (cbad)
		test_fail_at(__FILE__, line, label, " beauty: %d of 64 quad cells wrong (R quad, G alpha-0 texel, B ground):\n"
		             "    got  %s\n    want %s", cbad, map, want);
	/* ground under the shadow cells: blue channel, lit vs shadowed */
	int lit_min = 255, sh_max = 0;
	for (int row = 0; row < CHK; row++)
		for (int col = 0; col < CHK; col++) {
			v3 c = cell_centre(col, row);
			int i, j;
			px_at(&cam, v3_make(c.x + SUNX * QY, 0, c.z), &i, &j);
			int bch = gpu_px8(&img, i, j)[2];
			if (!masked || chk_opaque(col, row)) sh_max = bch > sh_max ? bch : sh_max;
			else lit_min = bch < lit_min ? bch : lit_min;
		}
	{
		int i, j;
		px_at(&cam, v3_make(QA + SUNX * QY + 0.3, 0, 0), &i, &j); /* lit ground beyond the shadow */
		int bch = gpu_px8(&img, i, j)[2];
		lit_min = bch < lit_min ? bch : lit_min;
	}
	CHECK(lit_min > sh_max + 30, "%s beauty: lit ground (blue %d at least) not brighter than shadowed ground "
	      "(blue %d at most)", label, lit_min, sh_max);
	free(img.pixels);
}

static char *mesh_quad_json(bool masked)
{
	size_t pl;
	uint8_t *png = checker_png(&pl);
	if (!png) return NULL;
	char *enc = test_b64(png, pl);
	free(png);
	char nums[4][512];
	const float *arr[3] = {QPOS, QNRM, QUV};
	int cnt[3] = {12, 12, 8};
	for (int a = 0; a < 3; a++) {
		int n = 0;
		for (int i = 0; i < cnt[a]; i++) n += snprintf(nums[a] + n, sizeof nums[a] - n, "%s%.9g", i ? "," : "", arr[a][i]);
	}
	int n = 0;
	for (int i = 0; i < 6; i++) n += snprintf(nums[3] + n, sizeof nums[3] - n, "%s%u", i ? "," : "", QIDX[i]);
	size_t cap = strlen(enc) + 4096;
	char *s = malloc(cap);
	snprintf(s, cap,
	         "{'shape':'mesh','positions':[%s],'normals':[%s],'uvs':[%s],'indices':[%s],"
	         "'transform':{'translation':[0,%.9g,0]},"
	         "'material':{'base_color':[1,1,1],'roughness':0.8,'base_color_texture':'%s','alpha_mode':'%s'%s}}",
	         nums[0], nums[1], nums[2], nums[3], QY, enc, masked ? "mask" : "opaque",
	         masked ? ",'alpha_cutoff':0.5" : "");
	free(enc);
	return s;
}

static char *glb_quad_json(bool masked)
{
	size_t pl;
	uint8_t *png = checker_png(&pl);
	if (!png) return NULL;
	struct test_glb_mesh in = {.pos = QPOS, .nrm = QNRM, .uv = QUV, .nv = 4, .idx = QIDX, .ni = 6,
	                    .node_t = {0, (float)QY, 0}, .png = png, .png_len = pl, .mask = masked};
	size_t n;
	uint8_t *glb = test_glb_mesh(&in, &n);
	free(png);
	char *enc = test_b64(glb, n);
	free(glb);
	size_t cap = strlen(enc) + 256;
	char *s = malloc(cap);
	snprintf(s, cap, "{'shape':'model','data':'%s','format':'glb'}", enc);
	free(enc);
	return s;
}

TEST(models_mask_checker_shadow_mesh)
{
	char *q = mesh_quad_json(true);
	REQUIRE(q);
	quad_check(__LINE__, "mesh quad, mask", q, true);
	free(q);
}

TEST(models_mask_checker_shadow_glb)
{
	char *q = glb_quad_json(true);
	REQUIRE(q);
	quad_check(__LINE__, "glb quad, MASK", q, true);
	free(q);
}

TEST(models_opaque_quad_shadow_mesh)
{
	char *q = mesh_quad_json(false);
	REQUIRE(q);
	quad_check(__LINE__, "mesh quad, opaque", q, false);
	free(q);
}

TEST(models_opaque_quad_shadow_glb)
{
	char *q = glb_quad_json(false);
	REQUIRE(q);
	quad_check(__LINE__, "glb quad, OPAQUE", q, false);
	free(q);
}
