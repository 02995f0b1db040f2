/* tests — api/scene_parse.c: bad documents (status, pointer, detail) and parsed values. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include <png.h>
#include "api.h"
#include "test.h"
#include "umbra/rnd_math.h"

#define DEG (3.14159265358979323846 / 180.0)

static bool near_f(float a, float b)
{
	return fabsf(a - b) <= 1e-5f * (1.0f + fabsf(b));
}

static double dist3(const float a[3], const double b[3])
{
	double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
	return sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

/* Documents are written with ' for " to stay readable; a static ring of buffers. */
static const char *q(const char *s)
{
	static char bufs[4][8192];
	static int n;
	char *b = bufs[n++ & 3];
	size_t i = 0;
	for (; s[i] && i + 1 < sizeof bufs[0]; i++) b[i] = s[i] == '\'' ? '"' : s[i];
	b[i] = 0;
	return b;
}

static struct api_scene *parse(const char *doc, struct api_problem *p)
{
	struct api_scene *s = NULL;
	memset(p, 0, sizeof *p);
	if (api_scene_parse(doc, strlen(doc), NULL, &s, p) != API_OK) return NULL;
	return s;
}

/* Parses a document that must be valid; reports the problem otherwise. */
static struct api_scene *parse_ok(const char *doc_q, int line)
{
	struct api_problem p;
	struct api_scene *s = parse(q(doc_q), &p);
	if (!s) test_fail_at(__FILE__, line, "PARSE_OK", "parse failed: %d %s: %s", p.status, p.pointer, p.detail);
	return s;
}
#define PARSE_OK(doc) parse_ok(doc, __LINE__)

#define C "'camera':{'position':[0,0,5]}"
#define BASE "{" C ",'objects':[]"

struct bad {
	const char *doc;
	int status;
	const char *pointer;
	const char *phrase;
};

static const struct bad bad_docs[] = {
	/* malformed / root */
	{"{", 400, "", "line 1"},
	{"{'camera':{},\n 'objects':[],}", 400, "", "line 2"},
	{"[]", 400, "", "must be a JSON object"},
	{"{'camera':{},'objects':[],'camera':{}}", 400, "", "duplicate"},
	{"{'camera':{},'objects':[],'width':1e400}", 400, "", "malformed JSON"},
	{"{'objects':[]}", 400, "/camera", "camera is required"},
	{"{" C "}", 400, "/objects", "objects is required"},
	{BASE ",'widht':5}", 400, "/widht", "did you mean \"width\""},
	{BASE ",'colour':5}", 400, "/colour", "unknown member \"colour\""},
	{BASE ",'width':0}", 400, "/width", "between 1 and 8192"},
	{BASE ",'width':8193}", 400, "/width", "between 1 and 8192"},
	{BASE ",'height':'512'}", 400, "/height", "must be an integer"},
	{BASE ",'width':1.5}", 400, "/width", "must be an integer"},
	{BASE ",'width':1e300}", 400, "/width", "must be an integer"},
	{BASE ",'height':null}", 400, "/height", "must be an integer, not null"},
	/* camera */
	{"{'camera':{'fov_y':180},'objects':[]}", 400, "/camera/fov_y", "less than 180"},
	{"{'camera':{'fov_y':0},'objects':[]}", 400, "/camera/fov_y", "greater than 0"},
	{"{'camera':{'fov_y':true},'objects':[]}", 400, "/camera/fov_y", "must be a number, not true"},
	{"{'camera':{'type':'orthographic'},'objects':[]}", 400, "/camera/height", "requires height"},
	{"{'camera':{'type':'orthographic','height':0},'objects':[]}", 400, "/camera/height", "greater than 0"},
	{"{'camera':{'type':'fisheye'},'objects':[]}", 400, "/camera/type", "must be one of"},
	{"{'camera':{'position':[0,0]},'objects':[]}", 400, "/camera/position", "must have 3 numbers"},
	{"{'camera':{'position':[0,'a',0]},'objects':[]}", 400, "/camera/position", "must be a number"},
	{"{'camera':{'position':[1,2,3],'target':[1,2,3]},'objects':[]}", 400, "/camera/target", "must differ"},
	{"{'camera':{'near':1,'far':0.5},'objects':[]}", 400, "/camera/far", "greater than near"},
	{"{'camera':{'near':0},'objects':[]}", 400, "/camera/near", "greater than 0"},
	{"{'camera':{'up':[0,0,0]},'objects':[]}", 400, "/camera/up", "must not be zero"},
	{"{'camera':{'direction':[0,0,-1]},'objects':[]}", 400, "/camera/direction", "only used with fit"},
	{"{'camera':{'fit':'everything'},'objects':[]}", 400, "/camera/fit", "must be one of"},
	{"{'camera':{'fit':'scene','margin':1},'objects':[]}", 400, "/camera/margin", "less than 1"},
	{"{'camera':{'exposure':1000},'objects':[]}", 400, "/camera/exposure", "between -64 and 64"},
	{"{'camera':[],'objects':[]}", 400, "/camera", "must be an object"},
	{"{'camera':{'fov':40},'objects':[]}", 400, "/camera/fov", "did you mean \"fov_y\""},
	/* environment */
	{BASE ",'environment':{'background':[-1,0,0]}}", 400, "/environment/background", "negative"},
	{BASE ",'environment':{'background':[1,1,1,2]}}", 400, "/environment/background", "alpha"},
	{BASE ",'environment':{'background':[1,1]}}", 400, "/environment/background", "3 or 4 numbers"},
	{BASE ",'environment':{'ambient':{'intensity':-1}}}", 400, "/environment/ambient/intensity", "at least 0"},
	{BASE ",'environment':{'ambient':{'skye':[1,1,1]}}}", 400, "/environment/ambient/skye", "did you mean \"sky\""},
	/* materials */
	{BASE ",'materials':[]}", 400, "/materials", "must be an object"},
	{BASE ",'materials':{'grey':{'roughness':2}}}", 400, "/materials/grey/roughness", "between 0 and 1"},
	{BASE ",'materials':{'a/b~c':{'metallic':-1}}}", 400, "/materials/a~1b~0c/metallic", "between 0 and 1"},
	{BASE ",'materials':{'m':5}}", 400, "/materials/m", "must be an object"},
	{BASE ",'materials':{'m':{'alpha_mode':'blend'}}}", 400, "/materials/m/alpha_mode", "\"opaque\", \"mask\""},
	{BASE ",'materials':{'m':{'base_color_texture':'aGVsbG8='}}}", 400, "/materials/m/base_color_texture",
	 "PNG or JPEG"},
	{BASE ",'materials':{'m':{'emissive':[1,1,-1]}}}", 400, "/materials/m/emissive", "negative"},
	{BASE ",'materials':{'m':{'double_sided':true}}}", 400, "/materials/m/double_sided", "unknown member"},
	/* objects */
	{"{" C ",'objects':{}}", 400, "/objects", "must be an array"},
	{"{" C ",'objects':[3]}", 400, "/objects/0", "must be an object"},
	{"{" C ",'objects':[{'size':[1,1]}]}", 400, "/objects/0/shape", "shape is required"},
	{"{" C ",'objects':[{'shape':'torus'}]}", 400, "/objects/0/shape", "must be one of"},
	{"{" C ",'objects':[{'shape':'sphere','size':[1,1,1]}]}", 400, "/objects/0/size", "a sphere object"},
	{"{" C ",'objects':[{'shape':'sphere','radius':0}]}", 400, "/objects/0/radius", "greater than 0"},
	{"{" C ",'objects':[{'shape':'sphere','segments':2}]}", 400, "/objects/0/segments", "between 3"},
	{"{" C ",'objects':[{'shape':'cylinder','height':-1}]}", 400, "/objects/0/height", "greater than 0"},
	{"{" C ",'objects':[{'shape':'box','size':[1,0,1]}]}", 400, "/objects/0/size", "greater than 0"},
	{"{" C ",'objects':[{'shape':'plane','size':[1,1,1]}]}", 400, "/objects/0/size", "must have 2 numbers"},
	{"{" C ",'objects':[{'shape':'box','material':'nope'}]}", 400, "/objects/0/material", "\"nope\" is not defined"},
	{"{" C ",'objects':[{'shape':'box','material':5}]}", 400, "/objects/0/material", "name of a material"},
	{"{" C ",'objects':[{'shape':'box','material':{'metallic':2}}]}", 400, "/objects/0/material/metallic",
	 "between 0 and 1"},
	{"{" C ",'objects':[{'shape':'box','cast_shadows':'yes'}]}", 400, "/objects/0/cast_shadows", "true or false"},
	{"{" C ",'objects':[{'shape':'box'},{'shape':'box','name':7}]}", 400, "/objects/1/name", "must be a string"},
	/* transforms */
	{"{" C ",'objects':[{'shape':'box','transform':{'scale':[1,0,1]}}]}", 400, "/objects/0/transform/scale",
	 "must not be 0"},
	{"{" C ",'objects':[{'shape':'box','transform':{'rotation':[0,0,0,0]}}]}", 400,
	 "/objects/0/transform/rotation", "must not be zero"},
	{"{" C ",'objects':[{'shape':'box','transform':{'rotation':[0,0,1]}}]}", 400,
	 "/objects/0/transform/rotation", "must have 4 numbers"},
	{"{" C ",'objects':[{'shape':'box','transform':{'matrix':[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1],"
	 "'translation':[1,0,0]}}]}", 400, "/objects/0/transform/matrix", "cannot be combined with translation"},
	{"{" C ",'objects':[{'shape':'box','transform':{'matrix':[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0]}}]}", 400,
	 "/objects/0/transform/matrix", "16 numbers"},
	{"{" C ",'objects':[{'shape':'box','transform':{'matrix':[1,0,0,1,0,1,0,0,0,0,1,0,0,0,0,1]}}]}", 400,
	 "/objects/0/transform/matrix", "affine"},
	{"{" C ",'objects':[{'shape':'box','transform':{'matrix':[1,0,0,0,0,0,0,0,0,0,1,0,0,0,0,1]}}]}", 400,
	 "/objects/0/transform/matrix", "singular"},
	{"{" C ",'objects':[{'shape':'box','transform':{'position':[1,0,0]}}]}", 400,
	 "/objects/0/transform/position", "unknown member"},
	{"{" C ",'objects':[{'shape':'box','transform':{'translation':[1e39,0,0]}}]}", 400,
	 "/objects/0/transform/translation", "out of range"},
	/* meshes */
	{"{" C ",'objects':[{'shape':'mesh'}]}", 400, "/objects/0/positions", "required"},
	{"{" C ",'objects':[{'shape':'mesh','positions':[0,0,0,1]}]}", 400, "/objects/0/positions",
	 "3 numbers per vertex"},
	{"{" C ",'objects':[{'shape':'mesh','positions':[0,0,0,1,0,0]}]}", 400, "/objects/0/positions",
	 "whole triangles"},
	{"{" C ",'objects':[{'shape':'mesh','positions':[0,0,0,1,0,0,0,1,0],'indices':[0,1,3]}]}", 400,
	 "/objects/0/indices", "not below the vertex count 3"},
	{"{" C ",'objects':[{'shape':'mesh','positions':[0,0,0,1,0,0,0,1,0],'indices':[0,1]}]}", 400,
	 "/objects/0/indices", "3 per triangle"},
	{"{" C ",'objects':[{'shape':'mesh','positions':[0,0,0,1,0,0,0,1,0],'indices':[0,1,-2]}]}", 400,
	 "/objects/0/indices", "integer between 0"},
	{"{" C ",'objects':[{'shape':'mesh','positions':[0,0,0,1,0,0,0,1,0],'normals':[0,1,0]}]}", 400,
	 "/objects/0/normals", "one xyz per vertex"},
	{"{" C ",'objects':[{'shape':'mesh','positions':[0,0,0,1,0,0,0,1,0],'uvs':[0,0,1,0]}]}", 400,
	 "/objects/0/uvs", "one uv pair per vertex"},
	{"{" C ",'objects':[{'shape':'mesh','positions':'@@@@'}]}", 400, "/objects/0/positions", "not valid base64"},
	{"{" C ",'objects':[{'shape':'mesh','positions':'AAAAAAA='}]}", 400, "/objects/0/positions", "whole 4-byte"},
	/* 0000c07f = NaN (little-endian float32) */
	{"{" C ",'objects':[{'shape':'mesh','positions':'AADAfw=='}]}", 400, "/objects/0/positions", "not a finite"},
	{"{" C ",'objects':[{'shape':'mesh','positions':['a']}]}", 400, "/objects/0/positions", "must be a number"},
	{"{" C ",'objects':[{'shape':'mesh','positions':{}}]}", 400, "/objects/0/positions", "base64 string"},
	/* models (validated, then 422) */
	{"{" C ",'objects':[{'shape':'model'}]}", 400, "/objects/0", "needs one of"},
	{"{" C ",'objects':[{'shape':'model','data':'AAAA','path':'a.glb'}]}", 400, "/objects/0/path",
	 "cannot be combined with data"},
	{"{" C ",'objects':[{'shape':'model','path':'../etc/passwd'}]}", 400, "/objects/0/path", "inside the asset root"},
	{"{" C ",'objects':[{'shape':'model','path':'/etc/passwd'}]}", 400, "/objects/0/path", "inside the asset root"},
	{"{" C ",'objects':[{'shape':'model','path':'a.glb','format':'fbx'}]}", 400, "/objects/0/format", "\"glb\""},
	/* lights */
	{BASE ",'lights':{}}", 400, "/lights", "must be an array"},
	{BASE ",'lights':[{'direction':[0,-1,0]}]}", 400, "/lights/0/type", "type is required"},
	{BASE ",'lights':[{'type':'area'}]}", 400, "/lights/0/type", "must be one of"},
	{BASE ",'lights':[{'type':'directional','direction':[0,0,0]}]}", 400, "/lights/0/direction", "must not be zero"},
	{BASE ",'lights':[{'type':'directional'}]}", 400, "/lights/0/direction", "direction is required"},
	{BASE ",'lights':[{'type':'spot','direction':[0,-1,0]}]}", 400, "/lights/0/position", "position is required"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'direction':[0,-1,0]}]}", 400, "/lights/0/direction",
	 "a point light"},
	{BASE ",'lights':[{'type':'spot','position':[0,1,0],'direction':[0,-1,0],'outer_angle':90}]}", 400,
	 "/lights/0/outer_angle", "less than 90"},
	{BASE ",'lights':[{'type':'spot','position':[0,1,0],'direction':[0,-1,0],'inner_angle':30,'outer_angle':20}]}",
	 400, "/lights/0/inner_angle", "must not be greater than outer_angle"},
	{BASE ",'lights':[{'type':'spot','position':[0,1,0],'direction':[0,-1,0],'inner_angle':50}]}", 400,
	 "/lights/0/inner_angle", "must not be greater than outer_angle"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'color':[1,-1,1]}]}", 400, "/lights/0/color", "negative"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'color':'white'}]}", 400, "/lights/0/color",
	 "must be an array"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'intensity':-1}]}", 400, "/lights/0/intensity", "at least 0"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'range':-1}]}", 400, "/lights/0/range", "at least 0"},
	{BASE ",'lights':[{'type':'directional','direction':[0,-1,0],'angular_diameter':-0.5}]}", 400,
	 "/lights/0/angular_diameter", "at least 0"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'colour':[1,1,1]}]}", 400, "/lights/0/colour",
	 "did you mean \"color\""},
	{BASE ",'lights':[{'type':'point','position':[0,1,0]},{'type':'point','position':[0,1,0],'shadow':'yes'}]}", 400,
	 "/lights/1/shadow", "object of shadow settings or a boolean"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'shadow':{'filter':'soft'}}]}", 400,
	 "/lights/0/shadow/filter", "\"pcss\""},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'shadow':{'contact':{'steps':0}}}]}", 400,
	 "/lights/0/shadow/contact/steps", "between 1 and 256"},
	/* an orthographic camera with fit came out perspective: now a 422 at the member */
	{"{'camera':{'fit':'scene','type':'orthographic','height':2},'objects':[]}", 422, "/camera/type",
	 "orthographic fit is not supported"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0],'shadow':{'contact':{'distance':0}}}]}", 400,
	 "/lights/0/shadow/contact/distance", "greater than 0"},
	{BASE ",'shadows':{'contact':{'enabled':true,'thickness':-1}}}", 400, "/shadows/contact/thickness",
	 "greater than 0"},
	/* shadows */
	{BASE ",'shadows':{'resolution':32}}", 400, "/shadows/resolution", "between 64 and 8192"},
	{BASE ",'shadows':{'resolution':16384}}", 400, "/shadows/resolution", "between 64 and 8192"},
	{BASE ",'shadows':{'pcf_radius':6}}", 400, "/shadows/pcf_radius", "between 0 and 5"},
	{BASE ",'shadows':{'directional':{'cascades':5}}}", 400, "/shadows/directional/cascades", "between 1 and 4"},
	{BASE ",'shadows':{'directional':{'split_lambda':1.5}}}", 400, "/shadows/directional/split_lambda",
	 "between 0 and 1"},
	{BASE ",'shadows':{'directional':{'clipmap_levels':9}}}", 400, "/shadows/directional/clipmap_levels",
	 "between 1 and 8"},
	{BASE ",'shadows':{'directional':{'mode':'csm'}}}", 400, "/shadows/directional/mode", "\"cascades\""},
	{BASE ",'shadows':{'vsm':{'precision':'fp64'}}}", 400, "/shadows/vsm/precision", "\"fp16\""},
	{BASE ",'shadows':{'vsm':{'light_bleed_reduction':2}}}", 400, "/shadows/vsm/light_bleed_reduction",
	 "between 0 and 1"},
	{BASE ",'shadows':{'bias':{'offset':1}}}", 400, "/shadows/bias/offset", "unknown member"},
	{BASE ",'shadows':{'enabled':1}}", 400, "/shadows/enabled", "true or false"},
	{BASE ",'shadows':[]}", 400, "/shadows", "must be an object"},
	/* output */
	{BASE ",'output':{'format':'jpg'}}", 400, "/output/format", "\"png\", \"exr\""},
	{BASE ",'output':{'bit_depth':12}}", 400, "/output/bit_depth", "8 or 16"},
	{BASE ",'output':{'msaa':2}}", 400, "/output/msaa", "1 or 4"},
	{BASE ",'output':{'format':'png','aovs':['depth']}}", 400, "/output/aovs", "need format \"exr\""},
	{BASE ",'output':{'format':'exr','aovs':['color']}}", 400, "/output/aovs/0", "must be one of"},
	{BASE ",'output':{'format':'exr','aovs':['depth','depth']}}", 400, "/output/aovs", "twice"},
	{BASE ",'output':{'format':'exr','aovs':'depth'}}", 400, "/output/aovs", "must be an array"},
	{BASE ",'output':{'tonemap':'filmic'}}", 400, "/output/tonemap", "\"aces\""},
	{BASE ",'output':{'debug':'shadow'}}", 400, "/output/debug", "no lights"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0]}],'output':{'debug':'shadow','debug_light':1}}", 400,
	 "/output/debug_light", "names no light"},
	{BASE ",'output':{'debug_light':-1}}", 400, "/output/debug_light", "between 0"},
	{BASE ",'output':{'transparent':'no'}}", 400, "/output/transparent", "true or false"},
	{BASE ",'output':{'a~b':1}}", 400, "/output/a~0b", "unknown member"},
	/* views / turntable */
	{BASE ",'views':[{'fov_y':200}]}", 400, "/views/0/fov_y", "less than 180"},
	{BASE ",'views':[]}", 400, "/views", "non-empty array"},
	{BASE ",'views':[{}],'turntable':{'frames':4}}", 400, "/turntable", "cannot be combined with views"},
	{BASE ",'turntable':{'frames':0}}", 400, "/turntable/frames", "between 1 and 1024"},
	{BASE ",'turntable':{'frames':4,'elevation':100}}", 400, "/turntable/elevation", "between -90 and 90"},
	{BASE ",'turntable':{'frames':1025}}", 400, "/turntable/frames", "between 1 and 1024"},
	{BASE ",'turntable':{'frames':4,'distance':0}}", 400, "/turntable/distance", "greater than 0"},
	{BASE ",'turntable':{'elevation':10}}", 400, "/turntable/frames", "required"},
	{BASE ",'turntable':{'frames':4,'azimuth':10}}", 400, "/turntable/azimuth", "unknown member"},
	{BASE ",'turntable':[4]}", 400, "/turntable", "must be an object"},
	{BASE ",'views':{}}", 400, "/views", "non-empty array"},
	{BASE ",'views':[{'position':[0,0,1],'target':[0,0,1]}]}", 400, "/views/0/target", "must differ"},
	{BASE ",'views':[{},{'fit':'objects','margin':1}]}", 400, "/views/1/margin", "less than 1"},
	{BASE ",'views':[{},{'typo':1}]}", 400, "/views/1/typo", "unknown member"},
	{"{'views':[{'type':'orthographic'}],'objects':[]}", 400, "/views/0/height", "requires height"},
	{"{'objects':[],'turntable':{}}", 400, "/turntable/frames", "required"},
	/* a 400 anywhere wins over a 422 found earlier */
	{BASE ",'turntable':{'frames':4},'lights':[{'type':'spot'}]}", 400,
	 "/lights/0/direction", "required"},
	/* 422: valid, but unsupported or over a limit */
	{"{" C ",'objects':[{'shape':'model','path':'models/a.glb'}]}", 400, "/objects/0/path", "no asset root configured"},
	{"{" C ",'objects':[{'shape':'model','data':'Z2xURg==','format':'glb'}]}", 400, "/objects/0/data",
	 "could not be imported"},
	{BASE ",'materials':{'t':{'base_color_texture':'iVBORw0KGgo='}}}", 400, "/materials/t/base_color_texture",
	 "could not be decoded"},
	{"{" C ",'objects':[{'shape':'plane','material':{'base_color_texture':'/9j/4AAQ'}}]}", 400,
	 "/objects/0/material/base_color_texture", "could not be decoded"},
	{BASE ",'materials':{'t':{'base_color_texture':7}}}", 400, "/materials/t/base_color_texture", "base64 PNG"},
	{BASE ",'width':8192,'height':8192}", 422, "/width", "pixels is over"},
	{"{" C ",'objects':[{'shape':'sphere','segments':10000}]}", 422, "/objects/0/segments", "triangles"},
	{"{" C ",'objects':[{'shape':'sphere','segments':4000},{'shape':'sphere','segments':4000}]}", 422, "/objects/1",
	 "more than 20000000 triangles"},
	/* Members the document's own structure makes unused (issue 13 item 4): a 400 at the member,
	 * as direction without fit. */
	{"{'camera':{'fit':'scene','position':[1,2,3]},'objects':[]}", 400, "/camera/position", "not used with fit"},
	{"{'camera':{'fit':'objects','target':[0,0,0]},'objects':[]}", 400, "/camera/target", "not used with fit"},
	{"{'camera':{'position':[0,0,5],'height':2},'objects':[]}", 400, "/camera/height",
	 "only used by an orthographic camera"},
	{"{'camera':{'type':'orthographic','height':2,'fov_y':30},'objects':[]}", 400, "/camera/fov_y",
	 "only used by a perspective camera"},
	/* a view keeps the root camera's orthographic type, so its fov_y would be dropped */
	{"{'camera':{'type':'orthographic','height':2,'position':[0,0,5]},'objects':[],'views':[{'fov_y':30}]}", 400,
	 "/views/0/fov_y", "only used by a perspective camera"},
	{BASE ",'lights':[{'type':'spot','position':[0,2,0],'direction':[0,-1,0],'shadow':{'directional':"
	 "{'cascades':2}}}]}", 400, "/lights/0/shadow/directional", "directional lights only; this is a spot light"},
	{BASE ",'lights':[{'type':'point','position':[0,2,0],'shadow':{'directional':{}}}]}", 400,
	 "/lights/0/shadow/directional", "this is a point light"},
	{BASE ",'lights':[{'type':'point','position':[0,2,0],'shadow':{'enabled':false,'contact':{'enabled':true}}}]}",
	 400, "/lights/0/shadow/contact/enabled", "shadows, which are off"},
	{BASE ",'shadows':false,'lights':[{'type':'point','position':[0,2,0],'shadow':{'contact':{'enabled':true}}}]}",
	 400, "/lights/0/shadow/contact/enabled", "shadows, which are off"},
	{BASE ",'lights':[{'type':'point','position':[0,1,0]}],'output':{'debug_light':0}}", 400, "/output/debug_light",
	 "only used with debug \"shadow\""},
	{BASE ",'lights':[{'type':'point','position':[0,1,0]}],'output':{'debug':'normals','debug_light':0}}", 400,
	 "/output/debug_light", "only used with debug \"shadow\""},
};

static void check_bad(const struct bad *b, const struct api_limits *lim, int idx)
{
	struct api_problem p;
	struct api_scene *s = NULL;
	const char *doc = q(b->doc);
	memset(&p, 0, sizeof p);
	enum api_result r = api_scene_parse(doc, strlen(doc), lim, &s, &p);
	CHECK(r == API_ERR && s == NULL, "doc %d should fail: %s", idx, doc);
	if (r == API_OK) { api_scene_free(s); return; }
	CHECK(p.status == b->status, "doc %d: status %d, want %d (%s: %s)", idx, p.status, b->status, p.pointer, p.detail);
	CHECK(!strcmp(p.pointer, b->pointer), "doc %d: pointer \"%s\", want \"%s\" (%s)", idx, p.pointer, b->pointer,
	      p.detail);
	CHECK(strstr(p.detail, b->phrase) != NULL, "doc %d: detail \"%s\" lacks \"%s\"", idx, p.detail, b->phrase);
	CHECK(!strncmp(p.type, "https://umbra.dev/problems/", 27), "doc %d: type %s", idx, p.type);
	CHECK(p.title[0] != 0, "doc %d: no title", idx);
}

TEST(parse_bad_documents)
{
	int n = 0;
	for (size_t i = 0; i < sizeof bad_docs / sizeof bad_docs[0]; i++) {
		check_bad(&bad_docs[i], NULL, (int)i);
		n++;
	}
	CHECK(n >= 40, "only %d bad documents", n);
}

TEST(parse_limits_configured)
{
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.max_lights = 2;
	lim.max_shadow_resolution = 4096;
	lim.max_pixels = 1000;
	const struct bad lights = {BASE ",'width':10,'height':10,'lights':[{'type':'point','position':[0,1,0]},"
	                                "{'type':'point','position':[0,1,0]},{'type':'point','position':[0,1,0]}]}",
	                           422, "/lights", "3 lights"};
	check_bad(&lights, &lim, 1);
	const struct bad res = {BASE ",'width':10,'height':10,'shadows':{'resolution':8192}}", 422, "/shadows/resolution",
	                        "over this server's limit of 4096"};
	check_bad(&res, &lim, 2);
	const struct bad res2 = {BASE ",'width':10,'height':10,'lights':[{'type':'point','position':[0,1,0],"
	                              "'shadow':{'resolution':6000}}]}",
	                         422, "/lights/0/shadow/resolution", "limit of 4096"};
	check_bad(&res2, &lim, 3);
	const struct bad px = {BASE ",'width':10,'height':101}", 422, "/height", "1010 pixels"};
	check_bad(&px, &lim, 4);
	/* maps are powers of two: 3000 is drawn at 4096, over a limit of 3000 */
	lim.max_shadow_resolution = 3000;
	const struct bad round = {BASE ",'width':10,'height':10,'shadows':{'resolution':3000}}", 422,
	                          "/shadows/resolution", "drawn as 4096"};
	check_bad(&round, &lim, 5);
	lim.max_shadow_resolution = 4096;
	struct api_problem p;
	struct api_scene *s = NULL;
	const char *ok = q(BASE ",'width':10,'height':100,'shadows':{'resolution':4096}}");
	CHECK(api_scene_parse(ok, strlen(ok), &lim, &s, &p) == API_OK, "%s", p.detail);
	/* The limit also bounds what the renderer chooses where a scene gives no resolution. */
	CHECK(s && s->scene.max_shadow_resolution == 4096, "scene's cap %u", s ? s->scene.max_shadow_resolution : 0);
	api_scene_free(s);
	/* 0 = unlimited */
	memset(&lim, 0, sizeof lim);
	const char *big = q("{" C ",'objects':[{'shape':'sphere','segments':10000}],'width':8192,'height':8192}");
	s = NULL;
	CHECK(api_scene_parse(big, strlen(big), &lim, &s, &p) == API_OK, "%s", p.detail);
	if (s) CHECK(s->triangles >= 90000000ull, "triangles %llu", (unsigned long long)s->triangles);
	api_scene_free(s);
}

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

static void b64_encode(const void *data, size_t n, char *out)
{
	static const char tbl[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	const unsigned char *b = data;
	size_t o = 0;
	for (size_t i = 0; i < n; i += 3) {
		uint32_t v = (uint32_t)b[i] << 16 | (i + 1 < n ? (uint32_t)b[i + 1] << 8 : 0) | (i + 2 < n ? b[i + 2] : 0);
		out[o++] = tbl[v >> 18 & 63];
		out[o++] = tbl[v >> 12 & 63];
		out[o++] = i + 1 < n ? tbl[v >> 6 & 63] : '=';
		out[o++] = i + 2 < n ? tbl[v & 63] : '=';
	}
	out[o] = 0;
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
	le32(pos, 12, bytes); b64_encode(bytes, 48, bp);
	le32(idx, 6, bytes); b64_encode(bytes, 24, bi);
	le32(nrm, 12, bytes); b64_encode(bytes, 48, bn);
	le32(uv, 8, bytes); b64_encode(bytes, 32, bu);
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
	b64_encode(bytes, 12, bp);
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

static const char B64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/* base64 of data into out (NUL-terminated); out must hold 4*ceil(n/3)+1 bytes. */
static void b64(const uint8_t *d, size_t n, char *out)
{
	size_t o = 0;
	for (size_t i = 0; i < n; i += 3) {
		uint32_t v = (uint32_t)d[i] << 16 | (i + 1 < n ? (uint32_t)d[i + 1] << 8 : 0) | (i + 2 < n ? d[i + 2] : 0);
		out[o++] = B64[v >> 18 & 63];
		out[o++] = B64[v >> 12 & 63];
		out[o++] = i + 1 < n ? B64[v >> 6 & 63] : '=';
		out[o++] = i + 2 < n ? B64[v & 63] : '=';
	}
	out[o] = 0;
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
	b64(png, len, enc);
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
	b64(png, len / 2, enc);
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
		b64(png, len, enc);
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
