/* tests/gpu — buffer memory: the CPU mirror of vertex and index buffers (renderer/memory.c).
 *
 * On a GPU the vertex and index buffers live in device-local BAR memory, which the CPU must not
 * read (tessellation transforms in place, areas and the shadow cache's key read it back): there
 * the renderer writes a heap mirror and publishes it. lavapipe's memory is host-cached, so the
 * mirror is forced here (rnd_context_desc.mirror_buffers) and must give the same bytes. */
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "gpu_util.h"
#include "test.h"

/* A sphere, a box, an inline mesh without normals (un-indexed, flat), a cylinder and a ground
 * plane under a soft sun: seen from three cameras (a sheet), and by one fitted camera, which
 * draws the sphere as its proxy (renderer/proxy.h: written after the meshes, and again where
 * the render's own framing moves it). */
#define MIRROR_OBJECTS                                                                                \
	"'objects':[{'shape':'plane','size':[8,8]},"                                                      \
	"{'shape':'sphere','radius':0.8,'segments':64,'transform':{'translation':[0,0.8,0]},"            \
	"'material':{'base_color':[0.8,0.2,0.2]}},"                                                       \
	"{'shape':'box','size':[0.6,0.6,0.6],'transform':{'translation':[1.5,0.3,0.5]}},"                 \
	"{'shape':'cylinder','radius':0.3,'height':1,'transform':{'translation':[-1.4,0.5,-0.4]}},"       \
	"{'shape':'mesh','positions':[0,0,1.5, 1,0,1.5, 0.5,1.2,1.2],'indices':[0,1,2],'double_sided':true}]," \
	"'lights':[{'type':'directional','direction':[-0.4,-1,-0.3],'intensity':3,'angular_diameter':3}]"
static const char *const mirror_docs[] = {
	"{'width':96,'height':96,'output':{'msaa':1},'views':[{'position':[0,3,6],'target':[0,0.8,0],'fov_y':40},"
	"{'position':[5,1,1],'target':[0,0.5,0],'fov_y':30},{'position':[-2,6,-3],'target':[0,0,0],'fov_y':50}],"
	MIRROR_OBJECTS "}",
	"{'width':128,'height':96,'camera':{'direction':[-1,-2,-5],'fit':'objects'}," MIRROR_OBJECTS "}",
};

static bool render_with(struct rnd_context *ctx, const char *json, struct rnd_image *img)
{
	char *doc = strdup(json);
	for (char *p = doc; *p; p++)
		if (*p == '\'') *p = '"';
	struct api_limits lim;
	api_limits_defaults(&lim);
	struct api_scene *s = NULL;
	struct api_problem prob = {0};
	bool ok = api_scene_parse(doc, strlen(doc), &lim, &s, &prob) == API_OK;
	CHECK(ok, "parse: %s: %s", prob.pointer, prob.detail);
	free(doc);
	if (!ok) return false;
	struct rnd_error err = {0};
	uint32_t before = rnd_context_validation_messages(ctx);
	enum rnd_result r = rnd_render(ctx, &s->scene, img, NULL, &err);
	CHECK(r == RND_OK, "render: %s", err.msg);
	CHECK(rnd_context_validation_messages(ctx) == before, "validation messages during the render");
	api_scene_free(s);
	return r == RND_OK;
}

TEST(memory_cpu_mirror_gives_the_same_bytes)
{
	struct rnd_context *plain = gpu_ctx();
	REQUIRE(plain);
	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {0};
	cd.validation = v && strcmp(v, "1") == 0;
	cd.mirror_buffers = true;
	struct rnd_context *mirrored = NULL;
	struct rnd_error err = {0};
	REQUIRE(rnd_context_create(&cd, &mirrored, &err) == RND_OK);
	for (size_t d = 0; d < sizeof mirror_docs / sizeof mirror_docs[0]; d++) {
		struct rnd_image a = {0}, b = {0}, c = {0};
		/* Twice on the mirrored context: the second render reuses the slot's grown buffers. */
		if (render_with(plain, mirror_docs[d], &a) && render_with(mirrored, mirror_docs[d], &b) &&
		    render_with(mirrored, mirror_docs[d], &c)) {
			size_t first = 0;
			long n = gpu_bytes_differ(&a, &b, &first);
			CHECK(n == 0, "scene %zu: %ld bytes differ between plain and mirrored buffers (first at %zu)", d, n, first);
			n = gpu_bytes_differ(&a, &c, &first);
			CHECK(n == 0, "scene %zu: %ld bytes differ on the mirrored context's second render (first at %zu)", d, n,
			      first);
		}
		rnd_image_release(&a);
		rnd_image_release(&b);
		rnd_image_release(&c);
	}
	rnd_context_destroy(mirrored);
}
