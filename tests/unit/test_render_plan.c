/* tests/unit — the render plan (renderer/render_plan.c) without a GPU: the decisions one
 * render makes, made once from the scene and a described device, and how a change of request
 * moves them the way docs/renderer.md says (a bigger output: bigger maps for a hard light; a
 * soft light: PCSS; a cached map: not drawn; a later view: no second fit map; an environment
 * map's directions: lights of their own, a map each, the environment pass). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "atlas.h"
#include "envmaps.h"
#include "render_plan.h"
#include "test.h"
#include "thumb_scene.h"

/* lavapipe's figures (rnd_plan_create fills these from the context). */
static void device(struct rnd_plan_device *d)
{
	memset(d, 0, sizeof *d);
	d->max_width = d->max_height = 8192;
	d->max_image_dimension = 16384;
	d->atlas_size = 4096;
	d->max_allocation = 1ull << 32;
	d->max_textures = 256;
	d->moments_max_res = 4096;
	d->moments = d->pcss_bounds = true;
	d->evsm_max_exponent = 42.0f;
	d->evsm_max_exponent_fp16 = 5.54f;
	d->visibility_pass = true;
	d->visibility_force = -1;
	d->env_pass_force = -1;
}

static uint64_t cached_key;
static bool cache_holds(void *user, uint64_t key, uint32_t tiles, uint32_t res)
{
	(void)user; (void)tiles; (void)res;
	return key == cached_key;
}

/* What most tests plan: thumb_scene (sc, obj, sun) at size x size on lavapipe's figures (dev). */
#define THUMB_PLAN(size)                       \
	struct rnd_scene sc;                   \
	struct rnd_object obj[2];              \
	struct rnd_light sun;                  \
	thumb_scene(&sc, obj, &sun, (size));   \
	struct rnd_plan_device dev;            \
	device(&dev)

/* Shadow views view v draws (not skipped). */
static uint32_t drawn(const struct rnd_plan *p, uint32_t v)
{
	uint32_t n = 0;
	for (uint32_t k = 0; k < p->views[v].shadow_views; k++) n += p->views[v].skip[k] == RND_SKIP_NONE;
	return n;
}

TEST(render_plan_of_a_thumbnail)
{
	THUMB_PLAN(256);
	struct rnd_plan p;
	struct rnd_error err = {0};
	REQUIRE(rnd_plan_build(&sc, &dev, &p, &err) == RND_OK, "%s", err.msg);
	CHECK(p.nviews == 1 && p.nmaps == 1 && p.maps[0].tiles == 1, "%u views, %u maps", p.nviews, p.nmaps);
	/* The sun's one fit map, cut to the sphere's box: a smaller tile with the default's texels. */
	CHECK(p.maps[0].key != 0 && p.maps[0].res < RND_DEFAULT_SHADOW_RESOLUTION && p.maps[0].res >= 256,
	      "fit map %u texels, key %llx", p.maps[0].res, (unsigned long long)p.maps[0].key);
	CHECK(p.views[0].lights[0].size_rule == RND_SIZE_CASTERS, "size rule %u", p.views[0].lights[0].size_rule);
	/* The ground shadows nothing (the sphere rests on its lit side): out of the shadow pass. */
	CHECK(!p.draws[0].cast && p.cast_why[0] == RND_CAST_LIT_SIDE, "ground cast %d why %u", p.draws[0].cast, p.cast_why[0]);
	CHECK(p.draws[1].cast && p.cast_why[1] == RND_CAST_YES, "sphere");
	/* The sphere: fewer segments than its 316 (the output shows no more), a proxy for the camera. */
	CHECK(p.lod[1] >= 16 && p.lod[1] < 316, "sphere segments %u", p.lod[1]);
	CHECK(p.sphere_proxies == 1 && p.proxies[1].outline > 0, "proxy %u", p.sphere_proxies);
	CHECK(p.draws[1].cam_first_index >= p.draws[1].first_index + p.draws[1].index_count, "the proxy after the meshes");
	/* Its counts add up: the camera draws the ground and the proxy; the map the sphere's mesh. */
	CHECK(p.views[0].camera_triangles == p.draws[0].index_count / 3 + p.draws[1].cam_index_count / 3, "%llu",
	      (unsigned long long)p.views[0].camera_triangles);
	CHECK(p.views[0].map_tris[0] == p.draws[1].index_count / 3, "map triangles %llu", (unsigned long long)p.views[0].map_tris[0]);
	CHECK(drawn(&p, 0) == 1 && p.views[0].map_ms[0] > 0 && p.views[0].row_ms > 0 && p.views[0].band_ms > 0, "estimates");
	/* The estimate is the scene's (admission reads this one). */
	struct rnd_estimate e;
	rnd_estimate_scene(&sc, dev.atlas_size, &e);
	CHECK(!memcmp(&e, &p.est, sizeof e), "estimate differs");
	/* The same request, the same plan. */
	struct rnd_plan q;
	REQUIRE(rnd_plan_build(&sc, &dev, &q, &err) == RND_OK, "%s", err.msg);
	CHECK(q.maps[0].key == p.maps[0].key && q.maps[0].res == p.maps[0].res && q.lod[1] == p.lod[1], "not the same");
	CHECK(!memcmp(q.views[0].views, p.views[0].views, sizeof *p.views[0].views), "shadow view differs");
	rnd_plan_release(&q);
	rnd_plan_release(&p);
}

/* A hard spot light's map is sized so that its PCF kernel spans at most a pixel where the
 * camera sees its casters (plan_local.c: hard_light_res, then the cone cut to the casters): a
 * bigger output asks for a bigger map. */
TEST(render_plan_bigger_output_bigger_hard_light_maps)
{
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light spot;
	thumb_scene(&sc, obj, &spot, 16);
	rnd_light_defaults(&spot, RND_LIGHT_SPOT);
	float pos[3] = {2, 4, 1}, dir[3] = {-0.4f, -1, -0.2f};
	memcpy(spot.position, pos, sizeof pos);
	memcpy(spot.direction, dir, sizeof dir);
	struct rnd_plan_device dev;
	device(&dev);
	struct rnd_plan small, big;
	struct rnd_error err = {0};
	REQUIRE(rnd_plan_build(&sc, &dev, &small, &err) == RND_OK, "%s", err.msg);
	sc.width = sc.height = 128;
	REQUIRE(rnd_plan_build(&sc, &dev, &big, &err) == RND_OK, "%s", err.msg);
	CHECK(big.maps[0].res > small.maps[0].res, "16²: %u texels, 128²: %u", small.maps[0].res, big.maps[0].res);
	CHECK(big.views[0].lights[0].size_rule == RND_SIZE_HARD_EDGE || big.views[0].lights[0].size_rule == RND_SIZE_CASTERS,
	      "rule %u", big.views[0].lights[0].size_rule);
	CHECK(big.views[0].lights[0].filter == UMBRA_FILTER_PCF, "filter %u", big.views[0].lights[0].filter);
	rnd_plan_release(&small);
	rnd_plan_release(&big);
}

/* A light with a size (radius, angular diameter) and the `auto` filter gets PCSS; its map the
 * depth bounds that let PCSS skip its search. */
TEST(render_plan_soft_light_gets_pcss)
{
	THUMB_PLAN(256);
	struct rnd_plan hard, soft;
	struct rnd_error err = {0};
	REQUIRE(rnd_plan_build(&sc, &dev, &hard, &err) == RND_OK, "%s", err.msg);
	sun.angular_diameter = 2.0f * (float)M_PI / 180.0f;
	REQUIRE(rnd_plan_build(&sc, &dev, &soft, &err) == RND_OK, "%s", err.msg);
	CHECK(hard.views[0].lights[0].filter == UMBRA_FILTER_PCF, "hard sun: %u", hard.views[0].lights[0].filter);
	CHECK(soft.views[0].lights[0].filter == UMBRA_FILTER_PCSS, "soft sun: %u", soft.views[0].lights[0].filter);
	CHECK(soft.maps[0].key != hard.maps[0].key, "a PCSS map must not reuse the PCF one");
	/* its per-pixel work is dearer: the main pass's estimate per row grows */
	CHECK(soft.views[0].row_ms > hard.views[0].row_ms, "%g vs %g", soft.views[0].row_ms, hard.views[0].row_ms);
	rnd_plan_release(&hard);
	rnd_plan_release(&soft);
}

/* A map the cache holds is planned as not drawn; one it does not hold is drawn. */
TEST(render_plan_cached_map_is_not_drawn)
{
	THUMB_PLAN(256);
	dev.cached = cache_holds;
	struct rnd_plan first, again;
	struct rnd_error err = {0};
	cached_key = 0;
	REQUIRE(rnd_plan_build(&sc, &dev, &first, &err) == RND_OK, "%s", err.msg);
	CHECK(!first.maps[0].cached && drawn(&first, 0) == 1, "an empty cache: drawn");
	cached_key = first.maps[0].key;
	REQUIRE(rnd_plan_build(&sc, &dev, &again, &err) == RND_OK, "%s", err.msg);
	CHECK(again.maps[0].cached && drawn(&again, 0) == 0 && again.views[0].skip[0] == RND_SKIP_CACHED,
	      "cached: %d, drawn %u", again.maps[0].cached, drawn(&again, 0));
	rnd_plan_release(&first);
	rnd_plan_release(&again);
	/* another object moves: another key, drawn again */
	obj[1].model[12] = 0.5f;
	REQUIRE(rnd_plan_build(&sc, &dev, &again, &err) == RND_OK, "%s", err.msg);
	CHECK(!again.maps[0].cached && again.maps[0].key != cached_key, "a moved caster kept the key");
	rnd_plan_release(&again);
}

/* Several views: a map that does not follow the camera (a fit sun map, a spot) is drawn by view
 * 0 only; cascades follow each camera and are drawn in every view. */
TEST(render_plan_views_draw_fixed_maps_once)
{
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light lights[2];
	thumb_scene(&sc, obj, &lights[0], 128);
	lights[0].shadow.dir_mode = RND_DIR_CASCADES;
	rnd_light_defaults(&lights[1], RND_LIGHT_SPOT);
	float pos[3] = {2, 4, 1}, dir[3] = {-0.4f, -1, -0.2f};
	memcpy(lights[1].position, pos, sizeof pos);
	memcpy(lights[1].direction, dir, sizeof dir);
	sc.lights = lights;
	sc.light_count = 2;
	struct rnd_camera views[3];
	for (int v = 0; v < 3; v++) {
		views[v] = sc.camera;
		views[v].position[0] = 4.0f - 2.0f * (float)v;
	}
	sc.views = views;
	sc.view_count = 3;
	struct rnd_plan_device dev;
	device(&dev);
	struct rnd_plan p;
	struct rnd_error err = {0};
	REQUIRE(rnd_plan_build(&sc, &dev, &p, &err) == RND_OK, "%s", err.msg);
	REQUIRE(p.nviews == 3 && p.nmaps == 2, "%u views %u maps", p.nviews, p.nmaps);
	CHECK(p.maps[0].key == 0 && p.maps[0].tiles == 4 && p.maps[1].key != 0 && p.maps[1].tiles == 1, "maps");
	CHECK(drawn(&p, 0) == 5 && drawn(&p, 1) == 4 && drawn(&p, 2) == 4, "drawn %u %u %u", drawn(&p, 0), drawn(&p, 1),
	      drawn(&p, 2));
	const struct rnd_light_plan *spot = &p.views[1].lights[1];
	CHECK(p.views[1].skip[spot->first_view] == RND_SKIP_EARLIER_VIEW, "the spot's map in view 1");
	/* no proxies with several views (each camera would need its own) */
	CHECK(p.sphere_proxies == 0 && p.draws[1].cam_index_count == p.draws[1].index_count, "proxies %u", p.sphere_proxies);
	rnd_plan_release(&p);
}

/* The errors the render would fail with, from the plan: the same codes and members. */
TEST(render_plan_fails_as_the_render_would)
{
	THUMB_PLAN(256);
	struct rnd_plan p;
	struct rnd_error err = {0};
	sun.direction[0] = sun.direction[1] = sun.direction[2] = 0;
	CHECK(rnd_plan_build(&sc, &dev, &p, &err) == RND_ERR_INVALID && strstr(err.msg, "direction is zero"), "%s", err.msg);
	CHECK(p.mem == NULL, "a failed plan holds memory");
	sun.direction[1] = -1;
	/* VSM on a device without the moment atlas */
	sun.shadow.filter = RND_FILTER_VSM;
	dev.moments = false;
	CHECK(rnd_plan_build(&sc, &dev, &p, &err) == RND_ERR_INVALID && strstr(err.msg, "vsm/evsm"), "%s", err.msg);
	sun.shadow.filter = RND_FILTER_AUTO;
	/* 40 point lights' cube faces in a 512² atlas: not even at 64² */
	static struct rnd_light many[40];
	for (int i = 0; i < 40; i++) {
		rnd_light_defaults(&many[i], RND_LIGHT_POINT);
		many[i].position[1] = 3.0f + (float)i;
	}
	sc.lights = many;
	sc.light_count = 40;
	dev.atlas_size = 512;
	memset(&err, 0, sizeof err);
	CHECK(rnd_plan_build(&sc, &dev, &p, &err) == RND_ERR_LIMIT && err.at == RND_AT_LIGHTS, "%s", err.msg);
	/* one allocation over the device's limit */
	sc.lights = &sun;
	sc.light_count = 1;
	dev.max_allocation = 1 << 20;
	sc.width = sc.height = 2048;
	CHECK(rnd_plan_build(&sc, &dev, &p, &err) == RND_ERR_LIMIT && err.at == RND_AT_SIZE, "%s", err.msg);
}

/* Map sizes: the request's alone, the largest halved until everything fits, never below the
 * smallest tile. */
TEST(render_plan_atlas_fit_halves_the_largest_first)
{
	uint32_t tiles[3] = {1, 6, 4}, want[3] = {4096, 512, 1024}, res[3];
	CHECK(rnd_atlas_fit(tiles, want, 3, 8192, 64, res) && res[0] == 4096 && res[1] == 512 && res[2] == 1024,
	      "fits as asked: %u %u %u", res[0], res[1], res[2]);
	CHECK(rnd_atlas_fit(tiles, want, 3, 4096, 64, res) && res[0] == 2048 && res[1] == 512 && res[2] == 1024,
	      "4096 atlas: %u %u %u", res[0], res[1], res[2]);
	uint32_t t2[1] = {8}, w2[1] = {64};
	CHECK(!rnd_atlas_fit(t2, w2, 1, 128, 64, res), "8 tiles of 64 in 128²");
	uint32_t w3[2] = {8192, 8192}, t3[2] = {1, 1};
	CHECK(rnd_atlas_fit(t3, w3, 2, 4096, 64, res) && res[0] == 2048 && res[1] == 2048, "clamped then halved: %u %u",
	      res[0], res[1]);
}

/* The plan measures each draw before the upload writes it (rnd_mesh_measure): its bounds must
 * be the very floats rnd_mesh_write grows (the cameras' near and far and the shadow maps' fit
 * come from them), and its area the one rnd_mesh_area finds in what was written. */
static void measure_is_write(const struct rnd_object *o, const char *what)
{
	uint32_t nv, ni;
	rnd_mesh_counts(o, &nv, &ni);
	struct rnd_vertex *v = malloc(nv * sizeof *v), *kv = malloc(nv * sizeof *kv);
	uint32_t *x = malloc(ni * sizeof *x), *kx = malloc(ni * sizeof *kx);
	struct rnd_aabb wb, mb, kb;
	rnd_aabb_empty(&wb);
	rnd_aabb_empty(&mb);
	rnd_aabb_empty(&kb);
	struct rnd_error err;
	double area, karea;
	CHECK(rnd_mesh_write(o, v, x, 0, &wb, &err) == RND_OK, "%s: %s", what, err.msg);
	CHECK(rnd_mesh_measure(o, NULL, NULL, &mb, &area, &err) == RND_OK, "%s: %s", what, err.msg);
	CHECK(!memcmp(&wb, &mb, sizeof wb), "%s: measured bounds differ from the written ones", what);
	CHECK(area == rnd_mesh_area(v, x, ni), "%s: area %.9g, written %.9g", what, area, rnd_mesh_area(v, x, ni));
	if (o->shape != RND_SHAPE_MESH) {   /* kept for the upload to copy: the write itself */
		CHECK(rnd_mesh_measure(o, kv, kx, &kb, &karea, &err) == RND_OK, "%s: %s", what, err.msg);
		CHECK(!memcmp(kv, v, nv * sizeof *v) && !memcmp(kx, x, ni * sizeof *x) && karea == area, "%s: kept differs", what);
	}
	free(v); free(kv); free(x); free(kx);
}

TEST(render_plan_measure_is_what_the_upload_writes)
{
	static const float pos[] = {0, 0, 0, 1, 0.2f, 0, 0.3f, 1.1f, 0.1f, -0.7f, 0.4f, 2.3f, 5, 5, 5};
	static const float nrm[] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
	static const uint32_t idx[] = {0, 1, 2, 0, 2, 3, 1, 3, 2};
	const float r = 0.7f;
	for (int mirror = 0; mirror < 2; mirror++) {
		struct rnd_object o;
		rnd_object_defaults(&o);
		float s[3] = {mirror ? -1.3f : 1.3f, 0.8f, 2.1f}, t[3] = {0.3f, -1.7f, 4.1f}, q[4] = {0.2f, 0.5f, -0.1f, 0.8f};
		rnd_mat4_trs(o.model, t, q, s);
		const char *tag = mirror ? "mirrored" : "rotated";
		o.shape = RND_SHAPE_SPHERE; o.radius = r; o.segments = 37;
		measure_is_write(&o, tag);
		o.shape = RND_SHAPE_CYLINDER; o.height = 2.5f; o.segments = 19;
		measure_is_write(&o, tag);
		o.shape = RND_SHAPE_BOX; o.size[0] = 1; o.size[1] = 2; o.size[2] = 3;
		measure_is_write(&o, tag);
		o.shape = RND_SHAPE_PLANE;
		measure_is_write(&o, tag);
		o.shape = RND_SHAPE_MESH; o.positions = pos; o.vertex_count = 5;   /* vertex 4 unused by the indices */
		o.indices = idx; o.index_count = 9;
		measure_is_write(&o, "mesh, indexed, no normals");
		o.normals = nrm;
		measure_is_write(&o, "mesh, indexed, normals");
		o.indices = NULL; o.index_count = 0; o.vertex_count = 3;
		measure_is_write(&o, "mesh, triangle list");
	}
	/* the same errors as the write */
	struct rnd_object bad;
	rnd_object_defaults(&bad);
	bad.shape = RND_SHAPE_MESH; bad.positions = pos; bad.vertex_count = 3; bad.indices = idx; bad.index_count = 9;
	struct rnd_aabb b;
	double area;
	struct rnd_error err;
	rnd_aabb_empty(&b);
	CHECK(rnd_mesh_measure(&bad, NULL, NULL, &b, &area, &err) == RND_ERR_INVALID && strstr(err.msg, "missing vertex"),
	      "%s", err.msg);
}

/* The environment's shadow directions are planned lights: a map each (fitted to the casters,
 * keyed like any sun's), after the scene's own; a ground keeps those below it out of the maps;
 * the rotation turns them; the environment pass is the plan's decision. */
TEST(render_plan_environment_directions_are_planned_lights)
{
	static struct rnd_env_bins bins;
	float *m = test_patch_map(256, 128, 30, 40, 8, 50.0f, 0.05f);
	REQUIRE(m != NULL, "no map");
	rnd_env_bin(m, 256, 128, &bins);
	free(m);
	struct rnd_scene sc;
	struct rnd_object obj[2];
	struct rnd_light sun;
	thumb_scene(&sc, obj, &sun, 256);
	sc.environment.source = RND_ENV_MAP;
	sc.environment.shadow_directions = 6;
	struct rnd_plan_device dev;
	device(&dev);
	struct rnd_plan none, p, turned, perfrag;
	struct rnd_error err = {0};
	REQUIRE(rnd_plan_build(&sc, &dev, &none, &err) == RND_OK, "%s", err.msg);   /* no bins: no directions */
	CHECK(none.env.mapped == 0 && none.nmaps == 1 && none.esc.light_count == 1 && !none.views[0].env_pass,
	      "without a map: %u directions, %u maps", none.env.mapped, none.nmaps);
	dev.env_bins = &bins;
	REQUIRE(rnd_plan_build(&sc, &dev, &p, &err) == RND_OK, "%s", err.msg);
	/* The ground holds the sphere: 6 directions above it get maps, 4 below are only weighed. */
	CHECK(p.env.ground && p.env.mapped == 6 && p.env.ndirs == 10, "ground %d, %u mapped of %u", p.env.ground,
	      p.env.mapped, p.env.ndirs);
	CHECK(p.esc.light_count == 7 && p.nmaps == 7, "%u lights as the shadow passes see them, %u maps", p.esc.light_count,
	      p.nmaps);
	for (uint32_t k = 1; k < p.nmaps; k++) {
		const struct rnd_light *L = &p.esc.lights[p.maps[k].light];
		CHECK(p.maps[k].light == k && L->shadow.dir_mode == RND_DIR_CASTERS && L->intensity == 0 && p.maps[k].key,
		      "map %u: light %u, mode %d", k, p.maps[k].light, (int)L->shadow.dir_mode);
		CHECK(L->direction[1] < 0, "direction %u points up: %g", k, L->direction[1]);
	}
	CHECK(p.views[0].env_pass && p.views[0].shadow_views == 7, "env pass %d, %u shadow views", p.views[0].env_pass,
	      p.views[0].shadow_views);
	/* Turned by a quarter: the same regions, their directions turned about +Y. */
	sc.environment.rotation = (float)(3.14159265358979323846 / 2);
	REQUIRE(rnd_plan_build(&sc, &dev, &turned, &err) == RND_OK, "%s", err.msg);
	const float *a = p.env.dirs[0].dir, *b = turned.env.dirs[0].dir;
	CHECK(fabsf(b[0] - a[2]) < 1e-4f && fabsf(b[2] + a[0]) < 1e-4f && fabsf(b[1] - a[1]) < 1e-6f,
	      "(%g %g %g) turned is (%g %g %g)", a[0], a[1], a[2], b[0], b[1], b[2]);
	CHECK(turned.maps[1].key != p.maps[1].key, "a turned direction's map is another map");
	/* UMBRA_ENV_PASS=0: the same maps, the shadows per fragment. */
	dev.env_pass_force = 0;
	REQUIRE(rnd_plan_build(&sc, &dev, &perfrag, &err) == RND_OK, "%s", err.msg);
	CHECK(!perfrag.views[0].env_pass && perfrag.nmaps == 7, "env pass %d", perfrag.views[0].env_pass);
	rnd_plan_release(&none);
	rnd_plan_release(&p);
	rnd_plan_release(&turned);
	rnd_plan_release(&perfrag);
}
