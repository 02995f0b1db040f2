/* tests — api/scene_parse.c: parsed values: defaults, the contract's example, lights, shadows,
 * unused settings, transforms, meshes, materials, extras, cameras, outputs and shapes. */
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

TEST(parse_defaults)
{
	struct api_scene *s = PARSE_OK("{'camera':{},'objects':[]}");
	REQUIRE(s);
	const struct rnd_scene *sc = &s->scene;
	CHECK(sc->width == 512 && sc->height == 512);
	CHECK(sc->camera.type == RND_CAMERA_PERSPECTIVE);
	CHECK(near_f(sc->camera.fov_y, (float)(45 * DEG)), "fov %g", (double)sc->camera.fov_y);
	CHECK(sc->camera.near == 0 && sc->camera.far == 0 && sc->camera.exposure == 0);
	CHECK(sc->camera.fit == RND_FIT_NONE);
	CHECK(sc->object_count == 0 && sc->light_count == 0 && sc->material_count == 0);
	CHECK(s->format == API_FORMAT_PNG && !s->format_explicit && s->bit_depth == 8 && s->png_level == -1);
	CHECK(sc->output.pixels == RND_PIXELS_RGBA8 && sc->output.msaa == 4 && !sc->output.transparent);
	CHECK(sc->output.tonemap == RND_TONEMAP_NEUTRAL && sc->output.debug == RND_DEBUG_NONE && sc->output.aovs == 0);
	CHECK(sc->environment.background[3] == 1);
	CHECK(s->triangles == 0);
	api_scene_free(s);
}

/* The example of contract §2, verbatim. */
TEST(parse_contract_example)
{
	struct api_scene *s = PARSE_OK(
		"{'width': 512, 'height': 512,"
		" 'camera': {'type': 'perspective', 'position': [4,3,4], 'target': [0,0.8,0],"
		"            'up': [0,1,0], 'fov_y': 40, 'near': 0.05, 'far': 100},"
		" 'environment': {'background': [0.5,0.5,0.5], 'ambient': {'sky': [0.6,0.7,0.9],"
		"                 'ground': [0.3,0.25,0.2], 'intensity': 0.3}},"
		" 'materials': {'grey': {'base_color': [0.7,0.7,0.7], 'roughness': 0.8, 'metallic': 0}},"
		" 'objects': ["
		"   {'shape': 'plane', 'size': [10,10], 'material': 'grey'},"
		"   {'shape': 'sphere', 'radius': 1, 'segments': 128, 'material': 'grey',"
		"    'transform': {'translation': [0,1,0]}}"
		" ],"
		" 'lights': ["
		"   {'type': 'directional', 'direction': [-0.5,-1,-0.3], 'color': [1,1,1], 'intensity': 3,"
		"    'angular_diameter': 0.53, 'shadow': {'filter': 'pcss'}}"
		" ],"
		" 'shadows': {'resolution': 2048},"
		" 'output': {'format': 'png'}}");
	REQUIRE(s);
	const struct rnd_scene *sc = &s->scene;
	CHECK(near_f(sc->camera.fov_y, (float)(40 * DEG)));
	CHECK(near_f(sc->camera.near, 0.05f) && near_f(sc->camera.far, 100));
	CHECK(near_f(sc->camera.target[1], 0.8f));
	CHECK(near_f(sc->environment.ambient_ground[1], 0.25f) && near_f(sc->environment.ambient_intensity, 0.3f));
	REQUIRE(sc->material_count == 1, "materials %u", sc->material_count);
	CHECK(near_f(sc->materials[0].base_color[0], 0.7f) && near_f(sc->materials[0].roughness, 0.8f));
	CHECK(sc->materials[0].base_color[3] == 1);
	REQUIRE(sc->object_count == 2);
	const struct rnd_object *pl = &sc->objects[0], *sp = &sc->objects[1];
	CHECK(pl->shape == RND_SHAPE_PLANE && pl->size[0] == 10 && pl->size[2] == 10 && pl->material == 0);
	CHECK(sp->shape == RND_SHAPE_SPHERE && sp->radius == 1 && sp->segments == 128 && sp->material == 0);
	CHECK(sp->model[13] == 1 && sp->model[12] == 0 && sp->model[0] == 1 && sp->model[15] == 1);
	CHECK(sp->cast_shadows && sp->receive_shadows && sp->double_sided);
	CHECK(s->triangles == rnd_object_triangle_count(pl) + rnd_object_triangle_count(sp));
	REQUIRE(sc->light_count == 1);
	const struct rnd_light *l = &sc->lights[0];
	CHECK(l->type == RND_LIGHT_DIRECTIONAL && near_f(l->direction[2], -0.3f) && l->intensity == 3);
	CHECK(near_f(l->angular_diameter, (float)(0.53 * DEG)), "angular_diameter %g", (double)l->angular_diameter);
	CHECK(l->shadow.enabled && l->shadow.filter == RND_FILTER_PCSS && l->shadow.resolution == 2048);
	CHECK(s->format == API_FORMAT_PNG && s->format_explicit);
	api_scene_free(s);
}

TEST(parse_light_angles_and_defaults)
{
	struct api_scene *s = PARSE_OK(BASE ",'lights':["
	                               "{'type':'spot','position':[0,3,0],'direction':[0,-1,0],'inner_angle':20,"
	                               "'outer_angle':30,'range':10,'radius':0.1},"
	                               "{'type':'spot','position':[0,3,0],'direction':[0,-1,0]},"
	                               "{'type':'point','position':[1,2,3]},"
	                               "{'type':'directional','direction':[0,-1,0]}]}");
	REQUIRE(s);
	REQUIRE(s->scene.light_count == 4);
	const struct rnd_light *l = s->scene.lights;
	CHECK(l[0].type == RND_LIGHT_SPOT);
	CHECK(near_f(l[0].inner_angle, (float)(20 * DEG)) && near_f(l[0].outer_angle, (float)(30 * DEG)));
	CHECK(l[0].range == 10 && near_f(l[0].radius, 0.1f));
	CHECK(l[1].inner_angle == 0 && near_f(l[1].outer_angle, (float)(45 * DEG)));
	CHECK(l[1].intensity == 10 && l[1].range == 0 && l[1].radius == 0);
	CHECK(l[2].type == RND_LIGHT_POINT && l[2].intensity == 10 && l[2].position[2] == 3);
	CHECK(l[2].color[0] == 1 && l[2].color[1] == 1 && l[2].color[2] == 1);
	CHECK(l[3].intensity == 3 && l[3].angular_diameter == 0);
	api_scene_free(s);
}

TEST(parse_shadow_merge)
{
	struct api_scene *s = PARSE_OK(
		BASE ",'shadows':{'resolution':1024,'pcf_radius':2,'filter':'pcf','directional':{'cascades':3},"
		"'bias':{'constant':0.001,'slope':2,'normal':1}},"
		"'lights':["
		"{'type':'directional','direction':[0,-1,0],'shadow':{'pcf_radius':3,'directional':{'split_lambda':0.5},"
		"'bias':{'slope':1}}},"
		"{'type':'point','position':[0,1,0],'shadow':false},"
		"{'type':'point','position':[0,1,0]},"
		"{'type':'spot','position':[0,1,0],'direction':[0,-1,0],'shadow':{'filter':'evsm','vsm':{'precision':'fp16',"
		"'exponent':5},'contact':{'enabled':false,'steps':16}}}]}");
	REQUIRE(s);
	REQUIRE(s->scene.light_count == 4);
	const struct rnd_shadow *a = &s->scene.lights[0].shadow, *b = &s->scene.lights[1].shadow,
	                        *c = &s->scene.lights[2].shadow, *d = &s->scene.lights[3].shadow;
	CHECK(a->enabled && a->resolution == 1024 && a->pcf_radius == 3 && a->filter == RND_FILTER_PCF);
	CHECK(a->cascades == 3 && near_f(a->split_lambda, 0.5f), "cascades %u lambda %g", a->cascades,
	      (double)a->split_lambda);
	CHECK(a->bias_set && near_f(a->bias_constant, 0.001f) && a->bias_slope == 1 && a->bias_normal == 1);
	CHECK(!b->enabled && b->resolution == 1024, "shadow:false keeps the other settings");
	CHECK(c->enabled && c->resolution == 1024 && c->pcf_radius == 2 && c->cascades == 3 && near_f(c->split_lambda, 0.75f));
	CHECK(d->filter == RND_FILTER_EVSM && d->vsm_precision == RND_VSM_FP16 && d->vsm_exponent == 5);
	CHECK(!d->contact_enabled && d->contact_steps == 16 && d->resolution == 1024);
	api_scene_free(s);

	/* Contact shadows are rendered (shading.glsl contact_visibility): a request that asks for
	 * them parses, settings inherited from the root and overridden per light. */
	s = PARSE_OK(BASE ",'shadows':{'contact':{'enabled':true,'distance':0.3,'steps':24,'thickness':0.02}},"
	             "'lights':[{'type':'point','position':[0,1,0]},"
	             "{'type':'directional','direction':[0,-1,0],'shadow':{'contact':{'steps':8}}}]}");
	REQUIRE(s);
	a = &s->scene.lights[0].shadow;
	b = &s->scene.lights[1].shadow;
	CHECK(a->contact_enabled && near_f(a->contact_distance, 0.3f) && a->contact_steps == 24 &&
	      near_f(a->contact_thickness, 0.02f));
	CHECK(b->contact_enabled && b->contact_steps == 8 && near_f(b->contact_distance, 0.3f));
	api_scene_free(s);

	s = PARSE_OK(BASE ",'shadows':{'enabled':false},'lights':[{'type':'point','position':[0,1,0]},"
	             "{'type':'point','position':[0,1,0],'shadow':true},"
	             "{'type':'point','position':[0,1,0],'shadow':{'enabled':true}}]}");
	REQUIRE(s);
	CHECK(!s->scene.lights[0].shadow.enabled && s->scene.lights[1].shadow.enabled &&
	      s->scene.lights[2].shadow.enabled);
	api_scene_free(s);
}

/* Settings valid in general but unused by this request's other choices are parsed, and said in
 * the scene's warnings (Umbra-Warnings, the CLI's stderr) with their pointer, never dropped
 * silently (issue 13 item 4). Each document: the pointer and a phrase the warning must hold. */
TEST(parse_unused_settings_warn)
{
	static const struct { const char *doc, *pointer, *phrase; } cases[] = {
		{BASE ",'lights':[{'type':'point','position':[0,1,0],'radius':0.1,'shadow':{'pcf_radius':3}}]}",
		 "/lights/0/shadow/pcf_radius", "filter is \"pcss\""},
		{BASE ",'lights':[{'type':'point','position':[0,1,0],'shadow':{'filter':'evsm','pcf_radius':3}}]}",
		 "/lights/0/shadow/pcf_radius", "filter is \"evsm\""},
		{BASE ",'lights':[{'type':'point','position':[0,1,0],'shadow':{'vsm':{'blur':4}}}]}",
		 "/lights/0/shadow/vsm/blur", "filter is \"pcf\""},
		{BASE ",'lights':[{'type':'point','position':[0,1,0],'shadow':{'filter':'vsm','vsm':{'exponent':5}}}]}",
		 "/lights/0/shadow/vsm/exponent", "for \"evsm\""},
		{BASE ",'lights':[{'type':'point','position':[0,1,0],'radius':0.2,'shadow':{'filter':'pcf'}}]}",
		 "/lights/0/radius", "no penumbra with filter \"pcf\""},
		{BASE ",'shadows':{'filter':'hard'},'lights':[{'type':'directional','direction':[0,-1,0],"
		 "'angular_diameter':2}]}", "/lights/0/angular_diameter", "filter \"hard\""},
		{BASE ",'lights':[{'type':'point','position':[0,1,0],'shadow':{'contact':{'distance':0.2}}}]}",
		 "/lights/0/shadow/contact/distance", "contact shadows are off"},
		{BASE ",'lights':[{'type':'directional','direction':[0,-1,0],'shadow':{'directional':{'mode':'clipmap',"
		 "'cascades':2}}}]}", "/lights/0/shadow/directional/cascades", "mode is \"clipmap\""},
		{BASE ",'lights':[{'type':'point','position':[0,1,0],'shadow':{'enabled':false,'resolution':512}}]}",
		 "/lights/0/shadow", "shadows are off"},
		/* root defaults: said only when no light takes and uses them */
		{BASE ",'shadows':{'pcf_radius':2,'filter':'pcss'},'lights':[{'type':'point','position':[0,1,0]}]}",
		 "/shadows/pcf_radius", "light 0: filter is \"pcss\""},
		{BASE ",'shadows':{'directional':{'cascades':2}},'lights':[{'type':'spot','position':[0,1,0],"
		 "'direction':[0,-1,0]}]}", "/shadows/directional/cascades", "type is not directional"},
		{BASE ",'shadows':{'pcf_radius':2},'lights':[{'type':'point','position':[0,1,0],'shadow':{'pcf_radius':1}}]}",
		 "/shadows/pcf_radius", "light 0 gives its own"},
		{BASE ",'shadows':{'resolution':1024}}", "/shadows", "no lights"},
		/* the PNG-only output members when the document itself asks for EXR */
		{BASE ",'output':{'format':'exr','bit_depth':16}}", "/output/bit_depth", "answer is EXR"},
		{BASE ",'output':{'format':'exr','tonemap':'aces'}}", "/output/tonemap", "answer is EXR"},
		/* glTF's alphaCutoff means something only with alpha_mode mask */
		{BASE ",'materials':{'m':{'alpha_cutoff':0.3}}}", "/materials/m/alpha_cutoff", "alpha_mode is not \"mask\""},
		/* the turntable's cameras place themselves */
		{"{'camera':{'position':[0,0,5],'fov_y':30},'objects':[],'turntable':{'frames':2}}", "/camera/position",
		 "not used by the turntable"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		struct api_scene *s = PARSE_OK(cases[i].doc);
		if (!s) continue;
		CHECK(strstr(s->warnings, cases[i].pointer) && strstr(s->warnings, cases[i].phrase), "case %zu: \"%s\"", i,
		      s->warnings);
		api_scene_free(s);
	}

	/* What is used draws no warning: a root default one light of two uses, a filter's own
	 * settings, contact tuning with contact on, the contract's example. */
	static const char *const quiet[] = {
		BASE ",'shadows':{'pcf_radius':2,'vsm':{'blur':3}},'lights':[{'type':'point','position':[0,1,0]},"
		"{'type':'point','position':[0,1,0],'shadow':{'filter':'evsm','vsm':{'exponent':8}}}]}",
		BASE ",'lights':[{'type':'directional','direction':[0,-1,0],'angular_diameter':1,'shadow':{'contact':"
		"{'enabled':true,'steps':8},'directional':{'mode':'cascades','cascades':2}}}]}",
		BASE ",'shadows':{'enabled':false},'lights':[{'type':'point','position':[0,1,0],'shadow':true}]}",
		BASE ",'output':{'format':'exr','tonemap':'none','bit_depth':8}}",
		"{'camera':{'fov_y':30,'exposure':1},'objects':[],'turntable':{'frames':2}}",
		BASE ",'materials':{'m':{'alpha_mode':'mask','alpha_cutoff':0.3}}}",
	};
	for (size_t i = 0; i < sizeof quiet / sizeof quiet[0]; i++) {
		struct api_scene *s = PARSE_OK(quiet[i]);
		if (!s) continue;
		CHECK(!s->warnings[0], "quiet %zu: \"%s\"", i, s->warnings);
		api_scene_free(s);
	}

	/* bit_depth 16 with the format chosen later (Accept, the CLI's -o): a warning while the answer
	 * is EXR, gone again when it is a PNG; never an error that would refuse the EXR. */
	struct api_scene *s = PARSE_OK(BASE ",'lights':[{'type':'point','position':[0,1,0]}],'output':{'bit_depth':16,"
	                               "'png_level':3}}");
	REQUIRE(s);
	CHECK(!s->warnings[0], "%s", s->warnings);
	struct api_problem p;
	CHECK(api_scene_set_format(s, API_FORMAT_EXR, &p) == API_OK);
	CHECK(strstr(s->warnings, "/output/bit_depth: not used, the answer is EXR") &&
	      strstr(s->warnings, "/output/png_level"), "%s", s->warnings);
	CHECK(api_scene_set_format(s, API_FORMAT_PNG, &p) == API_OK);
	CHECK(!s->warnings[0], "\"%s\"", s->warnings);
	api_scene_free(s);
}

TEST(parse_transform_trs)
{
	/* 90 degrees about +Y, scale 2, then translate (1,2,3): x -> -z. */
	struct api_scene *s = PARSE_OK("{" C ",'objects':[{'shape':'box','transform':{'translation':[1,2,3],"
	                               "'rotation':[0,0.7071067811865476,0,0.7071067811865476],'scale':[2,2,2]}},"
	                               "{'shape':'box','transform':{'rotation':[0,2,0,2],'scale':[1,1,-1]}},"
	                               "{'shape':'box','transform':{'matrix':[2,0,0,0, 0,3,0,0, 0,0,4,0, 5,6,7,1]}}]}");
	REQUIRE(s);
	const float *m = s->scene.objects[0].model;
	const float want[16] = {0, 0, -2, 0, 0, 2, 0, 0, 2, 0, 0, 0, 1, 2, 3, 1};
	for (int i = 0; i < 16; i++) CHECK(fabsf(m[i] - want[i]) < 1e-5f, "m[%d] = %g, want %g", i, (double)m[i], (double)want[i]);
	/* Unnormalised quaternion [0,2,0,2] is the same rotation; negative scale mirrors. */
	const float *m2 = s->scene.objects[1].model;
	CHECK(fabsf(m2[2] + 1) < 1e-5f && fabsf(m2[8] + 1) < 1e-5f, "m2[2]=%g m2[8]=%g", (double)m2[2], (double)m2[8]);
	CHECK(rnd_mat4_det3(m2) < 0);
	const float *m3 = s->scene.objects[2].model;
	CHECK(m3[0] == 2 && m3[5] == 3 && m3[10] == 4 && m3[12] == 5 && m3[13] == 6 && m3[14] == 7 && m3[15] == 1);
	CHECK(s->scene.objects[0].size[0] == 1 && s->scene.objects[0].size[1] == 1, "box default size");
	api_scene_free(s);
}

static void le32(const void *src, size_t count, unsigned char *dst)
{
	const uint32_t *u = src;
	for (size_t i = 0; i < count; i++) {
		dst[4 * i] = (unsigned char)u[i];
		dst[4 * i + 1] = (unsigned char)(u[i] >> 8);
		dst[4 * i + 2] = (unsigned char)(u[i] >> 16);
		dst[4 * i + 3] = (unsigned char)(u[i] >> 24);
	}
}

TEST(parse_mesh_base64_equals_array)
{
	const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1.5f, -2.25f, 1e-3f};
	const uint32_t idx[6] = {0, 1, 2, 2, 1, 3};
	const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
	const float uv[8] = {0, 0, 1, 0, 0, 1, 1, 1};
	unsigned char bytes[48];
	char bp[80], bi[40], bn[80], bu[60];
	le32(pos, 12, bytes); test_b64_into(bytes, 48, bp);
	le32(idx, 6, bytes); test_b64_into(bytes, 24, bi);
	le32(nrm, 12, bytes); test_b64_into(bytes, 48, bn);
	le32(uv, 8, bytes); test_b64_into(bytes, 32, bu);
	char doc[2048];
	snprintf(doc, sizeof doc,
	         "{" C ",'objects':["
	         "{'shape':'mesh','positions':[0,0,0,1,0,0,0,1,0,1.5,-2.25,0.001],'indices':[0,1,2,2,1,3],"
	         "'normals':[0,0,1,0,0,1,0,0,1,0,0,1],'uvs':[0,0,1,0,0,1,1,1]},"
	         "{'shape':'mesh','positions':'%s','indices':'%s','normals':'%s','uvs':'%s'}]}",
	         bp, bi, bn, bu);
	struct api_scene *s = PARSE_OK(doc);
	REQUIRE(s);
	const struct rnd_object *a = &s->scene.objects[0], *b = &s->scene.objects[1];
	CHECK(a->vertex_count == 4 && b->vertex_count == 4 && a->index_count == 6 && b->index_count == 6);
	CHECK(!memcmp(a->positions, pos, sizeof pos) && !memcmp(b->positions, pos, sizeof pos));
	CHECK(!memcmp(a->indices, idx, sizeof idx) && !memcmp(b->indices, idx, sizeof idx));
	CHECK(!memcmp(a->normals, b->normals, sizeof nrm) && !memcmp(a->uvs, b->uvs, sizeof uv));
	CHECK(!memcmp(b->uvs, uv, sizeof uv));
	CHECK(rnd_object_triangle_count(b) == 2 && s->triangles == 4);
	api_scene_free(s);

	/* Unpadded, URL-safe and line-wrapped base64 decode the same. */
	float one[3] = {-1, 2, 0.5f};
	le32(one, 3, bytes);
	test_b64_into(bytes, 12, bp);
	char wrapped[96];
	snprintf(wrapped, sizeof wrapped, "%.8s\\n%s", bp, bp + 8);
	snprintf(doc, sizeof doc, "{" C ",'objects':[{'shape':'mesh','positions':'%s','indices':[0,0,0]}]}", wrapped);
	s = PARSE_OK(doc);
	REQUIRE(s);
	CHECK(!memcmp(s->scene.objects[0].positions, one, sizeof one));
	CHECK(s->scene.objects[0].normals == NULL && s->scene.objects[0].uvs == NULL);
	api_scene_free(s);
}

TEST(parse_materials_by_name_and_inline)
{
	struct api_scene *s = PARSE_OK("{" C ",'materials':{'a':{'roughness':0.1},'b':{'base_color':[1,0,0,0.5],"
	                               "'metallic':1,'alpha_mode':'mask','alpha_cutoff':0.25,'emissive':[2,2,2],"
	                               "'shadow_catcher':true}},"
	                               "'objects':[{'shape':'box','material':'b'},{'shape':'box','material':{'roughness':0.25}},"
	                               "{'shape':'box'},{'shape':'box','material':'a'},{'shape':'box'}]}");
	REQUIRE(s);
	const struct rnd_scene *sc = &s->scene;
	REQUIRE(sc->object_count == 5);
	for (uint32_t i = 0; i < 5; i++) REQUIRE(sc->objects[i].material < sc->material_count);
	const struct rnd_material *mb = &sc->materials[sc->objects[0].material];
	CHECK(mb->base_color[0] == 1 && mb->base_color[3] == 0.5f && mb->metallic == 1 && mb->alpha_mode == RND_ALPHA_MASK);
	CHECK(mb->alpha_cutoff == 0.25f && mb->emissive[1] == 2 && mb->shadow_catcher);
	const struct rnd_material *mi = &sc->materials[sc->objects[1].material];
	CHECK(mi->roughness == 0.25f && near_f(mi->base_color[0], 0.8f) && mi->metallic == 0);
	const struct rnd_material *md = &sc->materials[sc->objects[2].material];
	CHECK(near_f(md->base_color[1], 0.8f) && md->roughness == 0.5f && md->alpha_cutoff == 0.5f);
	CHECK(sc->objects[2].material == sc->objects[4].material, "one shared default material");
	CHECK(near_f(sc->materials[sc->objects[3].material].roughness, 0.1f));
	CHECK(sc->objects[0].material != sc->objects[3].material && sc->objects[1].material != sc->objects[2].material);
	CHECK(sc->material_count == 4, "2 named + 1 inline + 1 default, got %u", sc->material_count);
	api_scene_free(s);
}

TEST(parse_extras_and_x_members)
{
	struct api_scene *s = PARSE_OK("{" C ",'extras':{'anything':[1,{'deep':true}]},'x-trace':'abc',"
	                               "'objects':[{'shape':'box','x-id':3,'extras':null,"
	                               "'transform':{'x-note':1},'material':{'extras':{}}}],"
	                               "'lights':[{'type':'point','position':[0,1,0],'x-a':1,'shadow':{'x-b':2,"
	                               "'bias':{'extras':0}}}],'output':{'x-c':[]},'environment':{'x-d':1}}");
	CHECK(s != NULL);
	api_scene_free(s);
}

TEST(parse_camera_variants)
{
	struct api_scene *s = PARSE_OK("{'camera':{'type':'orthographic','height':4,'position':[0,10,0],"
	                               "'target':[0,0,0],'up':[0,0,-1],'exposure':-1.5},'objects':[]}");
	REQUIRE(s);
	CHECK(s->scene.camera.type == RND_CAMERA_ORTHOGRAPHIC && s->scene.camera.height == 4);
	CHECK(s->scene.camera.exposure == -1.5f && s->scene.camera.up[2] == -1);
	api_scene_free(s);

	s = PARSE_OK("{'camera':{'fit':'objects','direction':[1,-1,0],'margin':0.2,'fov_y':30},'objects':[]}");
	REQUIRE(s);
	/* fit reaches the renderer as it is (it frames the bounds; tests/unit/test_camera.c and
	 * tests/gpu/test_models.c check where the camera goes). */
	CHECK(s->scene.camera.fit == RND_FIT_OBJECTS && s->scene.camera.fit_direction[0] == 1 &&
	      s->scene.camera.fit_direction[1] == -1);
	CHECK(near_f(s->scene.camera.fit_margin, 0.2f) && near_f(s->scene.camera.fov_y, (float)(30 * DEG)));
	api_scene_free(s);

	s = PARSE_OK("{'camera':{'fit':'scene'},'objects':[]}");
	REQUIRE(s);
	CHECK(s->scene.camera.fit == RND_FIT_SCENE && rnd_v3_length(s->scene.camera.fit_direction) > 0);
	CHECK(near_f(s->scene.camera.fit_margin, 0.1f));
	api_scene_free(s);
}

TEST(parse_output_variants)
{
	struct api_scene *s = PARSE_OK(BASE ",'lights':[{'type':'point','position':[0,1,0]},{'type':'point','position':"
	                               "[0,2,0]}],'output':{'format':'exr','aovs':['shadow','depth','normal','albedo'],"
	                               "'debug':'shadow','debug_light':1,'msaa':1,'transparent':true,'tonemap':'none'}}");
	REQUIRE(s);
	const struct rnd_output *o = &s->scene.output;
	CHECK(s->format == API_FORMAT_EXR && o->pixels == RND_PIXELS_RGBA32F);
	CHECK(o->aovs == (RND_AOV_SHADOW | RND_AOV_DEPTH | RND_AOV_NORMAL | RND_AOV_ALBEDO));
	CHECK(o->debug == RND_DEBUG_SHADOW && o->debug_light == 1 && o->msaa == 1 && o->transparent);
	CHECK(o->tonemap == RND_TONEMAP_NONE);
	struct api_problem p;
	CHECK(api_scene_set_format(s, API_FORMAT_PNG, &p) == API_ERR && p.status == 400);
	CHECK(!strcmp(p.pointer, "/output/aovs"), "%s", p.pointer);
	api_scene_free(s);

	s = PARSE_OK(BASE ",'output':{'bit_depth':16,'png_level':6,'tonemap':'aces','debug':'normals'}}");
	REQUIRE(s);
	CHECK(s->scene.output.pixels == RND_PIXELS_RGBA16 && s->bit_depth == 16 && s->png_level == 6);
	CHECK(s->scene.output.tonemap == RND_TONEMAP_ACES && s->scene.output.debug == RND_DEBUG_NORMALS);
	CHECK(api_scene_set_format(s, API_FORMAT_EXR, &p) == API_OK && s->scene.output.pixels == RND_PIXELS_RGBA32F);
	CHECK(api_scene_set_format(s, API_FORMAT_PNG, &p) == API_OK && s->scene.output.pixels == RND_PIXELS_RGBA16);
	api_scene_free(s);

	/* aovs with no format: the answer is still the default PNG, which cannot carry them, until
	 * something chooses EXR (Accept, the CLI's -o name); before that it is a 400 at /output/aovs. */
	s = PARSE_OK(BASE ",'output':{'aovs':['depth']}}");
	REQUIRE(s);
	CHECK(s->format == API_FORMAT_PNG && !s->format_explicit);
	memset(&p, 0, sizeof p);
	CHECK(api_scene_check_output(s, &p) == API_ERR && p.status == 400 && !strcmp(p.pointer, "/output/aovs"),
	      "%d %s", p.status, p.pointer);
	CHECK(api_scene_set_format(s, API_FORMAT_EXR, &p) == API_OK && s->scene.output.pixels == RND_PIXELS_RGBA32F);
	CHECK(api_scene_check_output(s, &p) == API_OK);
	api_scene_free(s);

	s = PARSE_OK(BASE ",'environment':{'background':[0.1,0.2,0.3,0]}}");
	REQUIRE(s);
	CHECK(s->scene.environment.background[2] == 0.3f && s->scene.environment.background[3] == 0);
	api_scene_free(s);
}

TEST(parse_shapes)
{
	struct api_scene *s = PARSE_OK("{" C ",'objects':[{'shape':'plane'},{'shape':'box','size':[1,2,3]},"
	                               "{'shape':'sphere'},{'shape':'cylinder','radius':0.5,'height':2,'segments':16.0,"
	                               "'double_sided':false,'cast_shadows':false,'receive_shadows':false,'name':'c'}]}");
	REQUIRE(s);
	const struct rnd_object *o = s->scene.objects;
	CHECK(o[0].shape == RND_SHAPE_PLANE && o[0].size[0] == 1 && o[0].size[2] == 1);
	CHECK(o[1].shape == RND_SHAPE_BOX && o[1].size[1] == 2 && o[1].size[2] == 3);
	CHECK(o[2].shape == RND_SHAPE_SPHERE && o[2].radius == 1 && o[2].segments == 64);
	CHECK(o[3].shape == RND_SHAPE_CYLINDER && o[3].radius == 0.5f && o[3].height == 2 && o[3].segments == 16);
	CHECK(!o[3].double_sided && !o[3].cast_shadows && !o[3].receive_shadows);
	uint64_t t = 0;
	for (int i = 0; i < 4; i++) t += rnd_object_triangle_count(&o[i]);
	CHECK(s->triangles == t);
	api_scene_free(s);
}
