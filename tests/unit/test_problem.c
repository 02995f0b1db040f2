/* tests/unit — renderer errors become problems that name the member at fault
 * (api_problem_from_render): rnd_error.at / at_index to the document's JSON Pointer, including
 * objects that an imported model expanded into several renderer objects. */
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "test.h"
#include "util.h"


static struct api_scene *parse(const char *doc)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	struct api_scene *s = NULL;
	struct api_problem p = {0};
	CHECK(api_scene_parse(doc, strlen(doc), &lim, &s, &p) == API_OK, "%d %s: %s", p.status, p.pointer, p.detail);
	return s;
}

static const char *pointer_of(const struct api_scene *s, enum rnd_error_at at, uint32_t index)
{
	static struct api_problem p;
	struct rnd_error e = {.code = RND_ERR_LIMIT, .at = at, .at_index = index};
	snprintf(e.msg, sizeof e.msg, "over a limit");
	memset(&p, 0, sizeof p);
	CHECK(api_problem_from_render(&p, s, &e, 422) == API_ERR && p.status == 422 && !strcmp(p.detail, "over a limit"),
	      "%d %s", p.status, p.detail);
	return p.pointer;
}

TEST(problem_from_render_names_the_member)
{
	/* Two objects in one OBJ file: the model object becomes two renderer objects, so the box
	 * after it is renderer object 2 but document object 1. */
	static const char two[] = "o first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
	                          "o second\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\n";
	char *obj = test_b64(two, sizeof two - 1);
	REQUIRE(obj);
	char doc[2048];
	snprintf(doc, sizeof doc, "{\"width\":64,\"height\":32,\"camera\":{\"position\":[0,0,5]},\"objects\":["
	         "{\"shape\":\"model\",\"data\":\"%s\",\"format\":\"obj\"},{\"shape\":\"box\"}],"
	         "\"lights\":[{\"type\":\"directional\",\"direction\":[0,-1,0]},"
	         "{\"type\":\"point\",\"position\":[0,2,0]}],\"output\":{\"format\":\"exr\",\"aovs\":[\"depth\"]}}", obj);
	free(obj);
	struct api_scene *s = parse(doc);
	REQUIRE(s);
	REQUIRE(s->scene.object_count == 3, "%u renderer objects", s->scene.object_count);
	CHECK(!strcmp(pointer_of(s, RND_AT_OBJECT, 0), "/objects/0"));
	CHECK(!strcmp(pointer_of(s, RND_AT_OBJECT, 1), "/objects/0"));
	CHECK(!strcmp(pointer_of(s, RND_AT_OBJECT, 2), "/objects/1"), "%s", pointer_of(s, RND_AT_OBJECT, 2));
	CHECK(!strcmp(pointer_of(s, RND_AT_LIGHT, 1), "/lights/1"));
	CHECK(!strcmp(pointer_of(s, RND_AT_LIGHTS, 0), "/lights"));
	CHECK(!strcmp(pointer_of(s, RND_AT_AOVS, 0), "/output/aovs"));
	CHECK(!strcmp(pointer_of(s, RND_AT_SIZE, 0), "/width"));
	CHECK(!strcmp(pointer_of(s, RND_AT_MATERIALS, 0), "/materials"));
	CHECK(!strcmp(pointer_of(s, RND_AT_NONE, 0), ""));
	api_scene_free(s);

	/* A taller image names /height; several views name the member that made them. */
	s = parse("{\"width\":16,\"height\":64,\"objects\":[{\"shape\":\"box\"}],\"lights\":[],"
	          "\"turntable\":{\"frames\":4}}");
	REQUIRE(s);
	CHECK(!strcmp(pointer_of(s, RND_AT_SIZE, 0), "/height"));
	CHECK(!strcmp(pointer_of(s, RND_AT_VIEWS, 0), "/turntable"), "%s", pointer_of(s, RND_AT_VIEWS, 0));
	api_scene_free(s);
}
