/* tests — api/scene_environment.c: `environment.map` (path, part, preset), its rotation,
 * intensity and shadows, the map background, and their problems (status, pointer, detail). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "api.h"
#include "env_map.h"
#include "envmaps.h"
#include "test.h"
#include "util.h"

static char root[64];
static uint8_t *sky;
static size_t sky_len;

/* An asset root holding sky.hdr (64 x 32) and not_a_map.hdr. */
static void make_root(void)
{
	if (root[0]) return;
	snprintf(root, sizeof root, "/tmp/umbra_env_XXXXXX");
	if (!mkdtemp(root)) return;
	float *m = test_patch_map(64, 32, 30, 40, 10, 20.0f, 0.5f);
	sky = test_hdr_bytes(m, 64, 32, true, &sky_len);
	free(m);
	char p[128];
	snprintf(p, sizeof p, "%s/sky.hdr", root);
	FILE *f = fopen(p, "wb");
	if (f) {
		fwrite(sky, 1, sky_len, f);
		fclose(f);
	}
	test_put_file(root, "not_a_map.hdr", "hello");
}

/* parses a document (' for ") with the asset root and a part "sky" */
static struct api_scene *parse_env(struct api_problem *p, const char *fmt, ...)
{
	make_root();
	va_list ap;
	va_start(ap, fmt);
	char *doc = test_vdoc(fmt, ap);
	va_end(ap);
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = root;
	struct api_part parts[1] = {{"sky", sky, sky_len}};
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	if (api_scene_parse_parts(doc, strlen(doc), &lim, parts, 1, &s, p) != API_OK) s = NULL;
	free(doc);
	return s;
}

#define SCENE "{'camera':{'position':[0,0,5]},'objects':[],"

TEST(env_parse_map_sources)
{
	struct api_problem p;
	struct api_scene *s = parse_env(&p, SCENE "'environment':{'map':'sky.hdr'}}");
	REQUIRE(s, "%s: %s", p.pointer, p.detail);
	const struct rnd_environment *e = &s->scene.environment;
	CHECK(e->source == RND_ENV_MAP && e->map.width == 64 && e->map.height == 32 && e->map.rgb && e->map.key,
	      "a path: %d %ux%u", (int)e->source, e->map.width, e->map.height);
	CHECK(e->ambient_intensity == 0, "with a map the ambient is off unless given (%g)", e->ambient_intensity);
	CHECK(e->shadow_directions == RND_DEFAULT_ENV_DIRECTIONS && e->intensity == 1 && e->rotation == 0, "defaults");
	CHECK(s->asset_hash != 0, "the file is in the answer's hash");
	uint64_t key = e->map.key;
	api_scene_free(s);
	s = parse_env(&p, SCENE "'environment':{'map':{'part':'sky','rotation':90,'intensity':0.5},'background':'map',"
	                        "'ambient':{'intensity':0.2},'shadow':{'directions':20,'resolution':256}}}");
	REQUIRE(s, "%s: %s", p.pointer, p.detail);
	e = &s->scene.environment;
	CHECK(e->source == RND_ENV_MAP && e->map.key == key, "the part's bytes are the file's: the same map");
	CHECK(fabsf(e->rotation - (float)M_PI / 2) < 1e-6f && e->intensity == 0.5f && e->background_map, "members");
	CHECK(e->ambient_intensity == 0.2f && e->shadow_directions == 20 && e->shadow_resolution == 256, "ambient, shadow");
	api_scene_free(s);
	s = parse_env(&p, SCENE "'environment':{'map':{'preset':'studio'},'shadow':false}}");
	REQUIRE(s, "%s: %s", p.pointer, p.detail);
	CHECK(s->scene.environment.source == RND_ENV_STUDIO && s->scene.environment.shadow_directions == 0, "studio");
	api_scene_free(s);
	/* the root's shadows off turns the map's off, unless it says otherwise */
	s = parse_env(&p, SCENE "'shadows':false,'environment':{'map':'sky.hdr'}}");
	REQUIRE(s, "%s: %s", p.pointer, p.detail);
	CHECK(s->scene.environment.shadow_directions == 0, "shadows: false");
	api_scene_free(s);
	s = parse_env(&p, SCENE "'shadows':false,'environment':{'map':'sky.hdr','shadow':true}}");
	REQUIRE(s, "%s: %s", p.pointer, p.detail);
	CHECK(s->scene.environment.shadow_directions == RND_DEFAULT_ENV_DIRECTIONS, "its own shadow: true wins");
	api_scene_free(s);
	s = parse_env(&p, SCENE "'environment':{'map':'sky.hdr'},'output':{'debug':'environment_shadow'}}");
	REQUIRE(s, "%s: %s", p.pointer, p.detail);
	CHECK(s->scene.output.debug == RND_DEBUG_ENV_SHADOW, "debug environment_shadow");
	api_scene_free(s);
}

static const struct {
	const char *doc;
	int status;
	const char *pointer, *detail;
} BAD[] = {
	{SCENE "'environment':{'map':3}}", 400, "/environment/map", "a file's path or an object"},
	{SCENE "'environment':{'map':{}}}", 400, "/environment/map", "one of path"},
	{SCENE "'environment':{'map':{'path':'sky.hdr','part':'sky'}}}", 400, "/environment/map/part", "one source"},
	{SCENE "'environment':{'map':{'preset':'beach'}}}", 400, "/environment/map/preset", "\"studio\""},
	{SCENE "'environment':{'map':{'path':'sky.hdr','rotaton':3}}}", 400, "/environment/map/rotaton", "unknown member"},
	{SCENE "'environment':{'map':{'path':'sky.hdr','intensity':-1}}}", 400, "/environment/map/intensity", ""},
	{SCENE "'environment':{'map':'nothere.hdr'}}", 400, "/environment/map", "nothere.hdr"},
	{SCENE "'environment':{'map':'../sky.hdr'}}", 400, "/environment/map", ""},
	{SCENE "'environment':{'map':'not_a_map.hdr'}}", 400, "/environment/map", "cannot be read"},
	{SCENE "'environment':{'map':{'part':'moon'}}}", 400, "/environment/map/part", "not a part"},
	{SCENE "'environment':{'background':'map'}}", 400, "/environment/background", "give environment.map"},
	{SCENE "'environment':{'background':'sky'}}", 400, "/environment/background", "\"map\""},
	{SCENE "'environment':{'map':'sky.hdr','shadow':{'directions':33}}}", 400, "/environment/shadow/directions",
	 "between 0 and 32"},
	{SCENE "'environment':{'map':'sky.hdr','shadow':{'resolution':32}}}", 400, "/environment/shadow/resolution", ""},
	{SCENE "'environment':{'map':'sky.hdr','shadow':{'count':3}}}", 400, "/environment/shadow/count", "unknown member"},
	{SCENE "'environment':{'map':'sky.hdr','shadow':1}}", 400, "/environment/shadow", "boolean or an object"},
	{SCENE "'environment':{'map':'sky.hdr','background':'map'},'output':{'transparent':true}}", 400,
	 "/environment/background", "transparent"},
	{SCENE "'output':{'debug':'environment_shadow'}}", 400, "/output/debug", "give environment.map"},
};

TEST(env_parse_problems)
{
	for (size_t i = 0; i < sizeof BAD / sizeof BAD[0]; i++) {
		struct api_problem p;
		struct api_scene *s = parse_env(&p, BAD[i].doc);
		CHECK(!s, "case %zu parsed", i);
		api_scene_free(s);
		CHECK(p.status == BAD[i].status, "case %zu: status %d (%s)", i, p.status, p.detail);
		CHECK(!strcmp(p.pointer, BAD[i].pointer), "case %zu: pointer %s, want %s", i, p.pointer, BAD[i].pointer);
		CHECK(strstr(p.detail, BAD[i].detail) != NULL, "case %zu: detail \"%s\" lacks \"%s\"", i, p.detail, BAD[i].detail);
	}
}

/* The ETag's scene hash (api/scene_hash.c): the map by its pixels, never its address; its
 * members by their parsed values. */
TEST(env_parse_scene_hash)
{
	/* Every slot of the map cache held by other maps: each parse decodes the sky anew, so two
	 * scenes alive at once hold its pixels at two addresses. */
	struct api_env_map *held[8] = {0};
	for (int i = 0; i < 8; i++) {
		float *m = test_patch_map(16, 8, 45.0f * (float)i, 0, 60, 2.0f + (float)i, 0.5f);   /* 8 different maps */
		size_t n = 0;
		uint8_t *b = m ? test_hdr_bytes(m, 16, 8, false, &n) : NULL;
		int status;
		char err[128];
		CHECK(b && api_env_map_get(b, n, &held[i], &status, err, sizeof err) == API_OK, "map %d", i);
		free(m);
		free(b);
	}
	struct api_problem p;
	struct api_scene *a = parse_env(&p, SCENE "'environment':{'map':{'part':'sky'}}}");
	REQUIRE(a, "%s: %s", p.pointer, p.detail);
	struct api_scene *b = parse_env(&p, SCENE "'environment':{'map':{'part':'sky','rotation':0,'intensity':1}}}");
	REQUIRE(b, "%s: %s", p.pointer, p.detail);
	CHECK(a->scene.environment.map.rgb != b->scene.environment.map.rgb, "decoded twice");
	CHECK(a->scene_hash == b->scene_hash, "the same map, defaults written or not: one hash");
	api_scene_free(b);
	for (int i = 0; i < 8; i++) api_env_map_release(held[i]);
	const char *other[] = {SCENE "'environment':{'map':{'part':'sky','rotation':90}}}",
	                       SCENE "'environment':{'map':{'preset':'studio'}}}",
	                       SCENE "'environment':{'map':{'part':'sky'},'shadow':false}}"};
	for (size_t i = 0; i < sizeof other / sizeof other[0]; i++) {
		b = parse_env(&p, other[i]);
		REQUIRE(b, "%s: %s", p.pointer, p.detail);
		CHECK(a->scene_hash != b->scene_hash, "case %zu hashes apart", i);
		api_scene_free(b);
	}
	api_scene_free(a);
}
