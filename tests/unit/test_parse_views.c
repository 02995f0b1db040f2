/* tests — api/scene_parse.c: hostile input, problem documents, several views, turntables, the
 * views' pixel limit and base colour textures. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include <png.h>
#include "api.h"
#include "test.h"
#include "umbra/rnd_math.h"
#include "parse_util.h"
#include "util.h"

TEST(parse_hostile_input)
{
	struct api_problem p;
	struct api_scene *s = NULL;
	/* Deep nesting, in an extras member and at the root. */
	size_t depth = 100000;
	char *deep = malloc(2 * depth + 64);
	REQUIRE(deep);
	size_t n = (size_t)sprintf(deep, "{\"camera\":{},\"objects\":[],\"extras\":");
	for (size_t i = 0; i < depth; i++) deep[n++] = '[';
	for (size_t i = 0; i < depth; i++) deep[n++] = ']';
	deep[n++] = '}';
	CHECK(api_scene_parse(deep, n, NULL, &s, &p) == API_ERR && p.status == 400, "deep nesting");
	free(deep);
	/* Embedded NUL, invalid UTF-8, empty and NULL input. */
	const char nul[] = "{\"camera\":{},\"objects\":[],\"x-a\":\"a\\u0000b\"}";
	CHECK(api_scene_parse(nul, sizeof nul - 1, NULL, &s, &p) == API_ERR && p.status == 400);
	const char bad_utf8[] = "{\"camera\":{},\"objects\":[],\"x-\xff\":1}";
	CHECK(api_scene_parse(bad_utf8, sizeof bad_utf8 - 1, NULL, &s, &p) == API_ERR && p.status == 400);
	CHECK(api_scene_parse("", 0, NULL, &s, &p) == API_ERR && p.status == 400);
	CHECK(api_scene_parse(NULL, 0, NULL, &s, &p) == API_ERR && p.status == 400);
	/* A very long unknown key: the pointer is truncated, never overflowed. */
	char longkey[2000];
	memset(longkey, 'k', sizeof longkey);
	memcpy(longkey, "{\"camera\":{},\"objects\":[],\"", 27);
	memcpy(longkey + sizeof longkey - 5, "\":1}", 5);
	CHECK(api_scene_parse(longkey, strlen(longkey), NULL, &s, &p) == API_ERR && p.status == 400);
	CHECK(strlen(p.pointer) < sizeof p.pointer && p.pointer[0] == '/');
	/* Every truncation of a rich document fails cleanly. */
	const char *rich = q("{'width':64,'height':48,'camera':{'position':[4,3,4],'target':[0,0.8,0]},"
	                     "'materials':{'m':{'base_color':[1,0,0]}},"
	                     "'objects':[{'shape':'mesh','positions':'AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA',"
	                     "'indices':[0,1,2],'material':'m'},{'shape':'sphere','transform':{'rotation':[0,0,0,1]}}],"
	                     "'lights':[{'type':'spot','position':[0,3,0],'direction':[0,-1,0],'shadow':{'vsm':{}}}],"
	                     "'shadows':{'filter':'pcss'},'output':{'format':'exr','aovs':['depth']}}");
	char *buf = strdup(rich);
	size_t len = strlen(rich);
	s = NULL;
	REQUIRE(api_scene_parse(rich, len, NULL, &s, &p) == API_OK, "%s %s", p.pointer, p.detail);
	api_scene_free(s);
	for (size_t cut = 0; cut < len; cut++) {
		s = NULL;
		CHECK(api_scene_parse(rich, cut, NULL, &s, &p) == API_ERR && s == NULL && p.status == 400, "cut %zu", cut);
	}
	/* Byte mutations: whatever the outcome, no crash and a well-formed answer. */
	unsigned seed = 12345;
	static const char junk[] = "{}[]\",:0-1e9.x tfn\\/~";
	for (int iter = 0; iter < 20000; iter++) {
		memcpy(buf, rich, len);
		int edits = 1 + iter % 3;
		for (int e = 0; e < edits; e++) {
			seed = seed * 1103515245u + 12345u;
			size_t at = (seed >> 8) % len;
			seed = seed * 1103515245u + 12345u;
			buf[at] = junk[(seed >> 8) % (sizeof junk - 1)];
		}
		s = NULL;
		memset(&p, 0, sizeof p);
		if (api_scene_parse(buf, len, NULL, &s, &p) == API_OK) {
			CHECK(s != NULL);
			api_scene_free(s);
		} else {
			CHECK(s == NULL && (p.status == 400 || p.status == 422) && p.detail[0], "iter %d", iter);
			CHECK(p.pointer[0] == 0 || p.pointer[0] == '/');
			char *j = api_problem_json(&p);
			CHECK(j != NULL);
			free(j);
		}
	}
	free(buf);
}

TEST(problem_json_and_format)
{
	struct api_problem p;
	CHECK(api_problem_set(&p, 400, "/lights/0/direction", "direction must not be %s", "zero") == API_ERR);
	CHECK(!strcmp(p.type, "https://umbra.dev/problems/invalid-scene") && !strcmp(p.title, "Invalid scene"));
	char *j = api_problem_json(&p);
	REQUIRE(j);
	json_error_t e;
	json_t *o = json_loads(j, 0, &e);
	REQUIRE(o, "%s", j);
	CHECK(json_integer_value(json_object_get(o, "status")) == 400);
	CHECK(!strcmp(json_string_value(json_object_get(o, "pointer")), "/lights/0/direction"));
	CHECK(!strcmp(json_string_value(json_object_get(o, "detail")), "direction must not be zero"));
	CHECK(!strcmp(json_string_value(json_object_get(o, "type")), "https://umbra.dev/problems/invalid-scene"));
	CHECK(json_object_get(o, "title") != NULL);
	json_decref(o);
	free(j);
	char line[256];
	api_problem_format(&p, line, sizeof line);
	CHECK(!strcmp(line, "400 Invalid scene: /lights/0/direction: direction must not be zero"), "%s", line);
	api_problem_set(&p, 422, "", "too big");
	CHECK(strstr(p.type, "limit-exceeded") != NULL);
	api_problem_format(&p, line, sizeof line);
	CHECK(!strcmp(line, "422 Resource limit exceeded: too big"), "%s", line);
	api_problem_set(&p, 503, NULL, "busy");
	CHECK(strstr(p.type, "unavailable") && p.pointer[0] == 0);
	/* Invalid UTF-8 in a detail still gives a JSON document. */
	api_problem_set(&p, 400, "/a", "bad \xff byte");
	j = api_problem_json(&p);
	CHECK(j != NULL);
	free(j);
	struct api_limits l;
	api_limits_defaults(&l);
	CHECK(l.max_pixels == 16777216 && l.max_triangles == 20000000 && l.max_lights == 64 &&
	      l.max_shadow_resolution == 8192);
	CHECK(!strcmp(api_format_mime(API_FORMAT_PNG), "image/png") && !strcmp(api_format_mime(API_FORMAT_EXR), "image/x-exr"));
}

/* ---- several views, turntable, textures ---- */


TEST(parse_views)
{
	/* Each view starts from the root camera and overrides what it gives. */
	struct api_scene *s = PARSE_OK("{'camera':{'position':[0,0,5],'fov_y':30,'exposure':1},'width':40,'height':30,"
	                               "'objects':[],'views':[{},{'position':[5,0,0],'fov_y':60},"
	                               "{'fit':'objects','direction':[0,-1,-1],'margin':0.2},"
	                               "{'type':'orthographic','height':3,'position':[0,9,0],'up':[0,0,-1]}]}");
	REQUIRE(s);
	const struct rnd_scene *sc = &s->scene;
	REQUIRE(sc->view_count == 4 && sc->views, "views %u", sc->view_count);
	CHECK(sc->width == 40 && sc->height == 30, "width/height stay those of one view");
	const struct rnd_camera *v = sc->views;
	CHECK(v[0].position[2] == 5 && near_f(v[0].fov_y, (float)(30 * DEG)) && v[0].exposure == 1);
	CHECK(v[1].position[0] == 5 && v[1].position[2] == 0 && near_f(v[1].fov_y, (float)(60 * DEG)) && v[1].exposure == 1);
	CHECK(v[2].fit == RND_FIT_OBJECTS && v[2].fit_direction[1] == -1 && v[2].fit_direction[2] == -1 &&
	      near_f(v[2].fit_margin, 0.2f), "fit objects is left to the renderer");
	CHECK(v[3].type == RND_CAMERA_ORTHOGRAPHIC && v[3].height == 3 && v[3].position[1] == 9 && v[3].up[2] == -1);
	CHECK(sc->camera.position[2] == 5, "the root camera is kept");
	api_scene_free(s);

	/* No root camera: views alone are enough; defaults are the contract's camera defaults. */
	s = PARSE_OK("{'objects':[],'views':[{'position':[1,2,3]},{'position':[0,0,-4],'target':[0,1,0]}]}");
	REQUIRE(s);
	CHECK(s->scene.view_count == 2 && s->scene.views[0].position[1] == 2 && s->scene.views[1].target[1] == 1);
	CHECK(near_f(s->scene.views[0].fov_y, (float)(45 * DEG)) && s->scene.views[0].up[1] == 1);
	api_scene_free(s);

	/* A view keeps the root camera's type (and height) unless it gives its own. */
	s = PARSE_OK("{'camera':{'type':'orthographic','height':2,'position':[0,0,5]},'objects':[],"
	             "'views':[{'position':[0,1,5]},{'type':'perspective','fov_y':50}]}");
	REQUIRE(s);
	CHECK(s->scene.views[0].type == RND_CAMERA_ORTHOGRAPHIC && s->scene.views[0].height == 2);
	CHECK(s->scene.views[1].type == RND_CAMERA_PERSPECTIVE && near_f(s->scene.views[1].fov_y, (float)(50 * DEG)));
	api_scene_free(s);

	/* A single view is a sheet of one. */
	s = PARSE_OK("{'objects':[],'views':[{'position':[1,2,3]}]}");
	REQUIRE(s);
	CHECK(s->scene.view_count == 1);
	api_scene_free(s);

	/* At most 1024 views. */
	size_t cap = 16 * 1100 + 64;
	char *doc = malloc(cap);
	REQUIRE(doc);
	size_t n = (size_t)snprintf(doc, cap, "{\"objects\":[],\"views\":[");
	for (int i = 0; i < 1025; i++) n += (size_t)snprintf(doc + n, cap - n, "%s{}", i ? "," : "");
	snprintf(doc + n, cap - n, "]}");
	struct api_problem p;
	struct api_scene *bad = parse(doc, &p);
	CHECK(!bad && p.status == 400 && !strcmp(p.pointer, "/views") && strstr(p.detail, "at most 1024"), "%d %s %s",
	      p.status, p.pointer, p.detail);
	api_scene_free(bad);
	free(doc);
}

/* The camera position of turntable frame k: the centre plus distance times the unit vector
 * (cos el sin az, sin el, cos el cos az), az = 360°·k/N. */
static void tt_expect(double out[3], const double c[3], double dist, double el_deg, int k, int n)
{
	double el = el_deg * DEG, az = 2 * 3.14159265358979323846 * k / n;
	out[0] = c[0] + dist * cos(el) * sin(az);
	out[1] = c[1] + dist * sin(el);
	out[2] = c[2] + dist * cos(el) * cos(az);
}

TEST(parse_turntable)
{
	/* A sphere at (1,2,3), radius 1, on a big plane (left out of the bounds) and a shadow-catcher
	 * box (left out too): the centre is the sphere's, the radius the half diagonal of its box. */
	struct api_scene *s = PARSE_OK(
		"{'width':64,'height':64,'objects':[{'shape':'plane','size':[100,100]},"
		"{'shape':'box','size':[50,50,50],'material':{'shadow_catcher':true}},"
		"{'shape':'sphere','radius':1,'transform':{'translation':[1,2,3]}}],"
		"'turntable':{'frames':8,'elevation':30,'distance':10}}");
	REQUIRE(s);
	const struct rnd_scene *sc = &s->scene;
	REQUIRE(sc->view_count == 8 && sc->views, "views %u", sc->view_count);
	const double c[3] = {1, 2, 3};
	for (int k = 0; k < 8; k++) {
		const struct rnd_camera *v = &sc->views[k];
		double want[3];
		tt_expect(want, c, 10, 30, k, 8);
		CHECK(dist3(v->position, want) < 1e-4, "frame %d position (%g %g %g) want (%g %g %g)", k,
		      (double)v->position[0], (double)v->position[1], (double)v->position[2], want[0], want[1], want[2]);
		CHECK(dist3(v->target, c) < 1e-5, "frame %d target", k);
		CHECK(v->type == RND_CAMERA_PERSPECTIVE && v->fit == RND_FIT_NONE && v->up[1] == 1);
		CHECK(near_f(v->fov_y, (float)(45 * DEG)), "default fov");
		/* The view direction is -(cos el sin az, sin el, cos el cos az). */
		double az = 2 * 3.14159265358979323846 * k / 8, el = 30 * DEG;
		CHECK(fabs(v->fit_direction[0] + cos(el) * sin(az)) < 1e-5 && fabs(v->fit_direction[1] + sin(el)) < 1e-5 &&
		      fabs(v->fit_direction[2] + cos(el) * cos(az)) < 1e-5, "frame %d direction", k);
	}
	/* Frame 0 on +Z, frame 2 (90°) on +X, looking down at 30°. */
	CHECK(sc->views[0].position[2] > 3 && fabsf(sc->views[0].position[0] - 1) < 1e-4f);
	CHECK(sc->views[2].position[0] > 1 && fabsf(sc->views[2].position[2] - 3) < 1e-4f);
	CHECK(near_f(sc->views[5].position[1], (float)(2 + 10 * sin(30 * DEG))));
	api_scene_free(s);

	/* Fitted distance: the bounding sphere (radius = half diagonal) fills the frame up to a 0.1
	 * margin of the root camera's fov_y; default elevation 20°. A box of 2x2x2 at the origin,
	 * a transformed cylinder (radius 1, height 2, scaled 2 in y) at x = 4. */
	s = PARSE_OK("{'camera':{'position':[0,0,9],'fov_y':40,'exposure':2},'width':64,'height':32,"
	             "'objects':[{'shape':'box','size':[2,2,2]},"
	             "{'shape':'cylinder','radius':1,'height':2,'transform':{'translation':[4,0,0],'scale':[1,2,1]}}],"
	             "'turntable':{'frames':3}}");
	REQUIRE(s);
	sc = &s->scene;
	REQUIRE(sc->view_count == 3);
	/* bounds x -1..5, y -2..2, z -1..1: centre (2,0,0), half diagonal sqrt(36+16+4)/2. */
	const double c2[3] = {2, 0, 0};
	double r = sqrt(36.0 + 16 + 4) / 2, half = 0.5 * 40 * DEG * 0.8;
	double half_x = atan(tan(half) * fmin(64.0 / 32.0, 1.0));
	double dist = r / sin(fmin(half, half_x));
	for (int k = 0; k < 3; k++) {
		double want[3];
		tt_expect(want, c2, dist, 20, k, 3);
		CHECK(dist3(sc->views[k].position, want) < 1e-3, "frame %d at %g from the centre, want %g", k,
		      dist3(sc->views[k].position, c2), dist);
		CHECK(near_f(sc->views[k].fov_y, (float)(40 * DEG)) && sc->views[k].exposure == 2);
	}
	api_scene_free(s);

	/* A mesh under a rotation: its vertices' world bounds. Elevation -90 and 90 are accepted. */
	s = PARSE_OK("{'objects':[{'shape':'mesh','positions':[0,0,0, 2,0,0, 0,0,4],"
	             "'transform':{'rotation':[0,0.7071067811865476,0,0.7071067811865476],'translation':[0,1,0]}}],"
	             "'turntable':{'frames':1,'elevation':90,'distance':5}}");
	REQUIRE(s);
	/* Rotation of 90° about +Y maps (x, z) to (z, -x): x 0..4, z -2..0. Centre (2, 1, -1). */
	const double c3[3] = {2, 1, -1};
	CHECK(dist3(s->scene.views[0].target, c3) < 1e-4, "target (%g %g %g)", (double)s->scene.views[0].target[0],
	      (double)s->scene.views[0].target[1], (double)s->scene.views[0].target[2]);
	CHECK(fabsf(s->scene.views[0].position[1] - 6) < 1e-4f);
	api_scene_free(s);

	/* Only planes: their bounds are used; no objects at all: the unit sphere at the origin. */
	s = PARSE_OK("{'objects':[{'shape':'plane','size':[4,4],'transform':{'translation':[0,-1,0]}}],"
	             "'turntable':{'frames':2,'distance':3}}");
	REQUIRE(s);
	const double c4[3] = {0, -1, 0};
	CHECK(dist3(s->scene.views[0].target, c4) < 1e-5);
	api_scene_free(s);
	s = PARSE_OK("{'objects':[],'turntable':{'frames':2,'elevation':0,'distance':3}}");
	REQUIRE(s);
	CHECK(s->scene.views[0].position[2] == 3 && s->scene.views[0].target[0] == 0);
	api_scene_free(s);
}

TEST(parse_views_pixel_limit)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.max_pixels = 10000;
	/* 5 views of 40x40 make a 3x2 sheet of 120x80 = 9600 pixels: fits; 100x50 x 4 = 20000 does not. */
	struct api_problem p;
	struct api_scene *s = NULL;
	const char *ok = q("{'width':40,'height':40,'objects':[],'views':[{},{},{},{},{}]}");
	CHECK(api_scene_parse(ok, strlen(ok), &lim, &s, &p) == API_OK, "%s", p.detail);
	api_scene_free(s);
	const struct bad views = {"{'width':100,'height':50,'objects':[],'views':[{},{},{},{}]}", 422, "/views",
	                          "200x100 sheet (20000 pixels)"};
	check_bad(&views, &lim, 1);
	const struct bad turn = {"{'width':100,'height':50,'objects':[],'turntable':{'frames':3}}", 422, "/turntable",
	                         "over this server's limit of 10000"};
	check_bad(&turn, &lim, 2);
	/* One view over the limit is still reported at width/height. */
	const struct bad one = {"{'width':200,'height':100,'objects':[],'turntable':{'frames':2}}", 422, "/width",
	                        "20000 pixels"};
	check_bad(&one, &lim, 3);
	/* A 400 still wins. */
	const struct bad b400 = {"{'width':100,'height':50,'objects':[],'turntable':{'frames':4},'lights':[1]}", 400,
	                         "/lights/0", "must be an object"};
	check_bad(&b400, &lim, 4);
	/* Unlimited servers still stop at the renderer's sheet size. */
	memset(&lim, 0, sizeof lim);
	const struct bad huge = {"{'width':8192,'height':8192,'objects':[],'turntable':{'frames':16}}", 422, "/turntable",
	                         "renderer's limit"};
	check_bad(&huge, &lim, 5);
}

TEST(parse_base_color_texture)
{
	/* A 3x2 RGBA PNG written by libpng. */
	const uint8_t texels[2][3][4] = {{{255, 0, 0, 255}, {0, 255, 0, 128}, {0, 0, 255, 255}},
	                                 {{10, 20, 30, 255}, {40, 50, 60, 0}, {200, 100, 50, 255}}};
	png_image img;
	memset(&img, 0, sizeof img);
	img.version = PNG_IMAGE_VERSION;
	img.width = 3;
	img.height = 2;
	img.format = PNG_FORMAT_RGBA;
	uint8_t png[1024];
	png_alloc_size_t len = sizeof png;
	REQUIRE(png_image_write_to_memory(&img, png, &len, 0, texels, 0, NULL), "%s", img.message);
	char enc[2048], doc[8192];
	test_b64_into(png, len, enc);
	snprintf(doc, sizeof doc,
	         "{'camera':{},'materials':{'t':{'base_color':[1,0.5,1],'base_color_texture':'%s'}},"
	         "'objects':[{'shape':'plane','material':'t'},{'shape':'box','material':{'base_color_texture':'%s'}},"
	         "{'shape':'sphere'}]}", enc, enc);
	struct api_scene *s = PARSE_OK(doc);
	REQUIRE(s);
	const struct rnd_scene *sc = &s->scene;
	const struct rnd_material *m = &sc->materials[sc->objects[0].material];
	REQUIRE(m->base_color_texture, "named material has its texture");
	const struct rnd_texture *t = m->base_color_texture;
	CHECK(t->width == 3 && t->height == 2 && t->rgba);
	CHECK(!memcmp(t->rgba, texels, sizeof texels), "texels as stored, rows top to bottom");
	CHECK(m->base_color[1] == 0.5f, "base_color still multiplies");
	const struct rnd_material *mi = &sc->materials[sc->objects[1].material];
	CHECK(mi->base_color_texture && mi->base_color_texture != t && !memcmp(mi->base_color_texture->rgba, texels, sizeof texels),
	      "inline material has its own copy");
	CHECK(!sc->materials[sc->objects[2].material].base_color_texture, "default material has none");
	api_scene_free(s);

	/* A truncated PNG: 400 at the member with the decoder's message. */
	char bad[4096];
	test_b64_into(png, len / 2, enc);
	snprintf(bad, sizeof bad, "{'camera':{},'objects':[],'materials':{'t':{'base_color_texture':'%s'}}}", enc);
	struct api_problem p;
	struct api_scene *sb = parse(q(bad), &p);
	CHECK(!sb && p.status == 400 && !strcmp(p.pointer, "/materials/t/base_color_texture") &&
	      strstr(p.detail, "could not be decoded"), "%d %s %s", p.status, p.pointer, p.detail);
	api_scene_free(sb);

	/* With max_textures 16, 17 distinct textures used by objects are a 422 at the object that
	 * brought the 17th; 16 are fine, and a material no object uses does not count. */
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.max_textures = 16;
	for (int n = 16; n <= 17; n++) {
		test_b64_into(png, len, enc);
		size_t cap = 256 + (size_t)(n + 1) * (strlen(enc) + 128);
		char *d = malloc(cap);
		REQUIRE(d);
		size_t o = (size_t)snprintf(d, cap, "{\"camera\":{\"position\":[0,0,5]},\"objects\":[");
		for (int i = 0; i < n; i++)
			o += (size_t)snprintf(d + o, cap - o, "%s{\"shape\":\"sphere\",\"material\":\"m%d\"}", i ? "," : "", i);
		o += (size_t)snprintf(d + o, cap - o, "],\"materials\":{\"unused\":{\"base_color_texture\":\"%s\"}", enc);
		for (int i = 0; i < n; i++)
			o += (size_t)snprintf(d + o, cap - o, ",\"m%d\":{\"base_color_texture\":\"%s\"}", i, enc);
		snprintf(d + o, cap - o, "}}");
		struct api_scene *st = NULL;
		api_scene_parse(d, strlen(d), &lim, &st, &p);
		if (n == 16) CHECK(st != NULL, "%s", p.detail);
		else CHECK(!st && p.status == 422 && !strcmp(p.pointer, "/objects/16"), "%d %s %s", p.status, p.pointer, p.detail);
		api_scene_free(st);
		free(d);
	}
}
