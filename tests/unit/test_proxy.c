/* tests — renderer/proxy.c: the cap a camera draws for an analytic sphere. Its vertices lie on
 * the sphere (the outline ring on the grazing circle, raised to straddle it), every triangle
 * faces the camera, its chords stay within the depth bound, the indices cover it, and it is a
 * small fraction of the tessellated sphere; and no proxy where the sphere is not what the
 * proxy assumes. Expected values are computed here in double from the scene. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"
#include "thumb_scene.h"
#include "lod.h"
#include "proxy.h"

#define PI_D 3.14159265358979323846

static void plan(const struct rnd_scene *sc, uint32_t nviews, struct rnd_proxy p[2])
{
	static struct rnd_shadow_plan scratch;
	uint32_t seg[2];
	rnd_lod_choose(sc, nviews, &scratch, seg);
	rnd_lod_proxies(sc, nviews, seg, p);
}

static double dist3(const float a[3], const double b[3])
{
	double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
	return sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

/* How far behind the unit sphere at c the triangle q lies along view rays (from eye, or along
 * fwd when orthographic) through its centroid and the middles of its sides, where they meet it. */
static double behind_along_rays(const double q[3][3], const double c[3], const double eye[3], const double fwd[3],
                                bool ortho)
{
	double worst = 0.0;
	for (int m = 0; m < 4; m++) {
		double x[3], o[3], dir[3], ld = 0.0;
		for (int a = 0; a < 3; a++) {
			x[a] = m == 3 ? (q[0][a] + q[1][a] + q[2][a]) / 3.0 : 0.5 * (q[m][a] + q[(m + 1) % 3][a]);
			dir[a] = ortho ? fwd[a] : x[a] - eye[a];
			ld += dir[a] * dir[a];
		}
		ld = sqrt(ld);
		double b = 0.0, cc = 0.0;
		for (int a = 0; a < 3; a++) {
			dir[a] /= ld;
			o[a] = x[a] - c[a];
			b += o[a] * dir[a];
			cc += o[a] * o[a];
		}
		double disc = b * b - (cc - 1.0);
		if (disc < 0.0) continue;   /* past the outline: nothing of the sphere on that ray */
		double behind = b + sqrt(disc);   /* from the sphere's near side forward to x */
		if (behind > worst) worst = behind;
	}
	return worst;
}

/* Checks sc's sphere (object 1, radius 1 at (0, 1, 0)) and its proxy; returns its triangles. */
static uint32_t check_proxy(const char *what, const struct rnd_scene *sc)
{
	struct rnd_proxy p[2];
	plan(sc, 1, p);
	CHECK(p[0].outline == 0, "%s: the plane has no proxy", what);
	if (p[1].outline == 0) {
		CHECK(0, "%s: the sphere has no proxy", what);
		return 0;
	}
	uint32_t nv, ni;
	rnd_proxy_counts(&p[1], &nv, &ni);
	struct rnd_vertex *v = malloc(nv * sizeof *v);
	uint32_t *idx = malloc(ni * sizeof *idx);
	unsigned char *used = calloc(nv, 1);
	rnd_proxy_write(&p[1], v, idx, 7);
	const double c[3] = {0, 1, 0};
	bool ortho = sc->camera.type == RND_CAMERA_ORTHOGRAPHIC;
	double eye[3], fwd[3], lf = 0.0, d = 0.0;
	for (int a = 0; a < 3; a++) {
		eye[a] = sc->camera.position[a];
		fwd[a] = sc->camera.target[a] - eye[a];
		lf += fwd[a] * fwd[a];
		d += (eye[a] - c[a]) * (eye[a] - c[a]);
	}
	lf = sqrt(lf);
	d = sqrt(d);
	for (int a = 0; a < 3; a++) fwd[a] /= lf;
	/* a pixel at the sphere's nearest depth along the view, as lod.c measures it */
	double w = (c[0] - eye[0]) * fwd[0] + (c[1] - eye[1]) * fwd[1] + (c[2] - eye[2]) * fwd[2] - 1.0;
	double pw = ortho ? sc->camera.height / sc->height : 2.0 * w * tan(0.5 * sc->camera.fov_y) / sc->height;
	/* The mesh the level of detail gives the shadow passes, for scale. */
	struct rnd_object lo = sc->objects[1];
	static struct rnd_shadow_plan scratch;
	uint32_t seg[2], mv, mi;
	rnd_lod_choose(sc, 1, &scratch, seg);
	rnd_lod_apply(&lo, seg[1]);
	rnd_mesh_counts(&lo, &mv, &mi);
	/* The tessellated sphere's own error along the view rays, front faces only, for scale. */
	struct rnd_vertex *mvx = malloc(mv * sizeof *mvx);
	uint32_t *mix = malloc(mi * sizeof *mix);
	struct rnd_aabb mb;
	struct rnd_error merr;
	rnd_aabb_empty(&mb);
	double mesh_ray = 0.0;
	if (rnd_mesh_write(&lo, mvx, mix, 0, &mb, &merr) == RND_OK)
		for (uint32_t t = 0; t < mi; t += 3) {
			double q[3][3], to_eye = 0.0, u[3], x[3];
			for (int k = 0; k < 3; k++)
				for (int a = 0; a < 3; a++) q[k][a] = mvx[mix[t + k]].pos[a];
			for (int a = 0; a < 3; a++) u[a] = q[1][a] - q[0][a], x[a] = q[2][a] - q[0][a];
			double n[3] = {u[1] * x[2] - u[2] * x[1], u[2] * x[0] - u[0] * x[2], u[0] * x[1] - u[1] * x[0]};
			for (int a = 0; a < 3; a++) to_eye += n[a] * (ortho ? -fwd[a] : eye[a] - q[0][a]);
			if (to_eye <= 0.0) continue;
			double br = behind_along_rays((const double(*)[3])q, c, eye, fwd, ortho);
			if (br > mesh_ray) mesh_ray = br;
		}
	free(mvx);
	free(mix);
	/* Outline: where the camera's rays graze the sphere, at acos(R / d) from the axis. */
	double edge = ortho ? 0.5 * PI_D : acos(1.0 / d), rho = sin(edge);
	CHECK(fabs(p[1].edge - edge) < 1e-5, "%s: outline at %g rad, expected %g", what, p[1].edge, edge);
	double e = pw / 32.0, out_mid = p[1].outline_radius * cos(PI_D / p[1].outline);
	CHECK(p[1].outline_radius - rho <= e * 1.01 && rho - out_mid <= e * 1.01 && p[1].outline_radius > rho,
	      "%s: outline ring radius %g, chord middles %g, grazing circle %g: not straddling within %g", what,
	      p[1].outline_radius, out_mid, rho, e);
	uint32_t bad_pos = 0, bad_attr = 0;
	for (uint32_t i = 0; i < nv; i++) {
		double r = dist3(v[i].pos, c);
		double ctr[3] = {v[i].pos[0] - v[i].nrm[0], v[i].pos[1] - v[i].nrm[1], v[i].pos[2] - v[i].nrm[2]};
		if (fabs(ctr[0] - c[0]) + fabs(ctr[1] - c[1]) + fabs(ctr[2] - c[2]) > 1e-5 || v[i].uv[0] != 1.0f ||
		    v[i].uv[1] != p[1].lift)
			bad_attr++;
		if (i >= nv - p[1].outline) {
			/* on the raised grazing circle, whose plane lies R cos(edge) along the axis */
			double along = 0.0;
			for (int a = 0; a < 3; a++) along += (v[i].pos[a] - c[a]) * (ortho ? -fwd[a] : (eye[a] - c[a]) / d);
			double across = sqrt(fmax(r * r - along * along, 0.0));
			if (fabs(along - cos(edge)) > 1e-5 || fabs(across - p[1].outline_radius) > 1e-5) bad_pos++;
		} else if (fabs(r - 1.0) > 1e-5) {
			bad_pos++;
		}
	}
	CHECK(bad_attr == 0, "%s: %u vertices do not carry the sphere (normal = position - centre, uv = (R, lift))", what,
	      bad_attr);
	CHECK(bad_pos == 0, "%s: %u vertices off the sphere or off the outline", what, bad_pos);
	CHECK(p[1].lift >= 0.0f && p[1].lift <= 1.0f - cosf((float)PI_D / (float)seg[1]), "%s: lift %g", what, p[1].lift);
	uint32_t back = 0, deep = 0, out_of_range = 0;
	double worst = 0.0, ray_worst = 0.0;
	for (uint32_t t = 0; t < ni; t += 3) {
		double q[3][3];
		for (int k = 0; k < 3; k++) {
			uint32_t j = idx[t + k] - 7;
			if (j >= nv) { out_of_range++; j = 0; }
			used[j] = 1;
			for (int a = 0; a < 3; a++) q[k][a] = v[j].pos[a];
		}
		double u[3], x[3], n[3];
		for (int a = 0; a < 3; a++) u[a] = q[1][a] - q[0][a], x[a] = q[2][a] - q[0][a];
		n[0] = u[1] * x[2] - u[2] * x[1], n[1] = u[2] * x[0] - u[0] * x[2], n[2] = u[0] * x[1] - u[1] * x[0];
		double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), to_eye = 0.0;
		for (int a = 0; a < 3; a++) to_eye += n[a] * (ortho ? -fwd[a] : eye[a] - q[0][a]);
		if (!(to_eye > 0.0)) back++;
		/* how far behind the sphere the proxy lies along the view ray (what the depth test
		 * compares) */
		double br = behind_along_rays((const double(*)[3])q, c, eye, fwd, ortho);
		if (br > ray_worst) ray_worst = br;
		/* how far inside the sphere the triangle's plane dips: R - distance of the centre */
		double plane = fabs(n[0] * (c[0] - q[0][0]) + n[1] * (c[1] - q[0][1]) + n[2] * (c[2] - q[0][2])) / ln;
		if (1.0 - plane > worst) worst = 1.0 - plane;
		if (1.0 - plane > RND_PROXY_STEP_PIXELS * pw * 1.01) deep++;
	}
	uint32_t unused = 0;
	for (uint32_t i = 0; i < nv; i++) unused += !used[i];
	printf("    %s: proxy %u triangles (outline %u segments), mesh %u; deepest chord %.2f pixel, along the"
	       " view ray %.2f (the mesh's %.2f; bound %.2f)\n",
	       what, ni / 3, p[1].outline, mi / 3, worst / pw, ray_worst / pw, mesh_ray / pw, RND_PROXY_STEP_PIXELS);
	/* Near the outline the view rays graze the sphere and any chord lies far behind it along
	 * them (what the depth test compares): no farther than the tessellated sphere's chords. */
	CHECK(ray_worst <= mesh_ray * 1.01, "%s: the proxy lies %g pixel behind the sphere along a view ray, the mesh %g",
	      what, ray_worst / pw, mesh_ray / pw);
	CHECK(out_of_range == 0 && unused == 0, "%s: %u indices out of range, %u vertices unused", what, out_of_range, unused);
	CHECK(back == 0, "%s: %u of %u triangles face away from the camera", what, back, ni / 3);
	CHECK(deep == 0, "%s: %u triangles dip deeper than the bound (deepest %g pixel)", what, deep, worst / pw);
	CHECK(ni / 3 * 4 < mi / 3, "%s: proxy %u triangles, not well under the mesh's %u", what, ni / 3, mi / 3);
	free(v);
	free(idx);
	free(used);
	return ni / 3;
}

TEST(proxy_of_a_sphere_lies_on_it_and_faces_the_camera)
{
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light sun;
	thumb_scene(&sc, obj, &sun, 512);
	uint32_t t512 = check_proxy("thumb-512", &sc);
	CHECK(t512 > 0 && t512 < 1500, "thumb-512: %u triangles", t512);
	thumb_scene(&sc, obj, &sun, 128);
	check_proxy("128 px", &sc);
	thumb_scene(&sc, obj, &sun, 2048);
	check_proxy("2048 px", &sc);
	thumb_scene(&sc, obj, &sun, 512);
	float close[3] = {1.3f, 1.9f, 1.1f};
	memcpy(sc.camera.position, close, sizeof close);
	memcpy(sc.camera.target, (float[3]){0, 1, 0}, sizeof close);
	check_proxy("close up", &sc);
	thumb_scene(&sc, obj, &sun, 512);
	sc.camera.type = RND_CAMERA_ORTHOGRAPHIC;
	sc.camera.height = 3;
	check_proxy("orthographic", &sc);
}

/* Plans sc's proxies (nviews views) and checks whether the sphere (object 1) got one. */
static void expect_proxy(const struct rnd_scene *sc, uint32_t nviews, bool want, const char *what)
{
	struct rnd_proxy p[2];
	plan(sc, nviews, p);
	CHECK((p[1].outline > 0) == want, "%s: %s", what, want ? "no proxy" : "a proxy");
}

TEST(proxy_only_where_the_sphere_is_what_it_seems)
{
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light sun;
	struct rnd_proxy p[2];
	struct rnd_material m;
	thumb_scene(&sc, obj, &sun, 512);
	struct rnd_camera views[2] = {sc.camera, sc.camera};
	views[1].position[0] = -4.0f;
	sc.views = views;
	sc.view_count = 2;
	expect_proxy(&sc, 2, false, "two views: no proxy");
	sc.views = NULL;
	sc.view_count = 0;
	sc.camera.near = 5.0f;   /* the sphere's centre is 5.4 away: the near plane cuts it */
	expect_proxy(&sc, 1, false, "a near plane through the sphere: no proxy");
	sc.camera.near = 0.0f;
	expect_proxy(&sc, 1, true, "the same camera with a derived near plane: a proxy");
	sc.exact_segments = true;
	expect_proxy(&sc, 1, false, "exact segments: no proxy");
	sc.exact_segments = false;
	obj[1].segments = 24;   /* fewer than a 120-pixel outline needs: the facets were asked for */
	expect_proxy(&sc, 1, false, "24 segments asked: no proxy");
	obj[1].segments = 316;
	obj[1].model[0] = 1.5f;   /* an ellipsoid */
	expect_proxy(&sc, 1, false, "non-uniform scale: no proxy");
	obj[1].model[0] = obj[1].model[5] = obj[1].model[10] = 1.5f;
	plan(&sc, 1, p);
	CHECK(p[1].outline > 0 && fabsf(p[1].radius - 1.5f) < 1e-6f, "uniform scale 1.5: proxy of radius %g", p[1].radius);
	obj[1].model[0] = obj[1].model[5] = obj[1].model[10] = 1.0f;
	rnd_material_defaults(&m);
	sc.materials = &m;
	sc.material_count = 1;
	obj[0].material = obj[1].material = 0;
	expect_proxy(&sc, 1, true, "plain material: proxy");
	m.alpha_mode = RND_ALPHA_BLEND;
	expect_proxy(&sc, 1, false, "blended material: no proxy");
	m.alpha_mode = RND_ALPHA_OPAQUE;
	m.textures[RND_TEX_NORMAL] = (const struct rnd_texture *)&m;   /* only its presence is read */
	expect_proxy(&sc, 1, false, "textured material: no proxy");
	m.textures[RND_TEX_NORMAL] = NULL;
	sun.shadow.contact_enabled = true;
	expect_proxy(&sc, 1, false, "contact shadows: no proxy");
	sun.shadow.contact_enabled = false;
	setenv("UMBRA_SPHERE_PROXY", "0", 1);
	plan(&sc, 1, p);
	unsetenv("UMBRA_SPHERE_PROXY");
	CHECK(p[1].outline == 0, "UMBRA_SPHERE_PROXY=0: no proxy");
	float inside[3] = {0, 1.2f, 0.1f};
	memcpy(sc.camera.position, inside, sizeof inside);
	expect_proxy(&sc, 1, false, "camera inside the sphere: no proxy");
	float pos[3] = {4, 3, 4};
	memcpy(sc.camera.position, pos, sizeof pos);
	/* A fitted camera: planned from the estimated bounds; the render keeps the proxy only where
	 * its own camera is that one (rnd_proxy_fits). */
	sc.camera.fit = RND_FIT_OBJECTS;
	float dir[3] = {-1, -0.6f, -1};
	memcpy(sc.camera.fit_direction, dir, sizeof dir);
	plan(&sc, 1, p);
	CHECK(p[1].outline > 0, "framed on the objects: a proxy");
	struct rnd_camera_plan cam;
	struct rnd_error err;
	struct rnd_aabb b;
	rnd_aabb_empty(&b);
	float lo[3] = {-1, 0, -1}, hi[3] = {1, 2, 1};
	rnd_aabb_add_point(&b, lo);
	rnd_aabb_add_point(&b, hi);
	if (rnd_camera_plan(&sc.camera, sc.width, sc.height, &b, &cam, &err) == RND_OK) {
		CHECK(rnd_proxy_fits(&p[1], &cam), "the camera fitted to the sphere's own box: the planned one");
		cam.pos[0] += 0.01f;
		CHECK(!rnd_proxy_fits(&p[1], &cam), "a camera 1 cm away: not the planned one");
		/* Placed again for it: the same counts, the outline where its rays graze the sphere. */
		struct rnd_proxy q = p[1];
		uint32_t nv0, ni0, nv1, ni1;
		rnd_proxy_counts(&q, &nv0, &ni0);
		bool moved = false;
		CHECK(rnd_proxy_refit(&q, &cam, &moved) && moved && rnd_proxy_fits(&q, &cam), "refit for the camera 1 cm away");
		rnd_proxy_counts(&q, &nv1, &ni1);
		CHECK(nv0 == nv1 && ni0 == ni1, "refit keeps the counts: %u/%u then %u/%u", nv0, ni0, nv1, ni1);
		double dd = 0.0;
		for (int k = 0; k < 3; k++) dd += (cam.pos[k] - (k == 1)) * (cam.pos[k] - (k == 1));
		CHECK(fabs(q.edge - acos(1.0 / sqrt(dd))) < 1e-6, "refit outline at %g rad, expected %g", q.edge,
		      acos(1.0 / sqrt(dd)));
		struct rnd_camera_plan inside = cam;
		float centre[3] = {0, 1, 0};
		memcpy(inside.pos, centre, sizeof centre);
		CHECK(!rnd_proxy_refit(&q, &inside, &moved) && q.outline == 0, "refit for a camera inside the sphere: none");
		cam.ortho = true;
		CHECK(!rnd_proxy_fits(&p[1], &cam), "an orthographic camera: not the planned one");
	} else {
		CHECK(0, "camera plan: %s", err.msg);
	}
	sc.camera.fit = RND_FIT_NONE;
	sc.camera.type = RND_CAMERA_ORTHOGRAPHIC;
	sc.camera.height = 3;
	plan(&sc, 1, p);
	CHECK(p[1].outline > 0 && fabsf(p[1].edge - (float)(PI_D / 2)) < 1e-6f,
	      "orthographic: a proxy out to the equator (%g rad)", p[1].edge);
	float in_ortho[3] = {0, 1, 0.5f}, ahead[3] = {0, 1, -1};
	memcpy(sc.camera.position, in_ortho, sizeof in_ortho);
	memcpy(sc.camera.target, ahead, sizeof ahead);
	expect_proxy(&sc, 1, false, "orthographic camera whose near plane cuts the sphere: no proxy");
}
