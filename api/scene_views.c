/*
 * api/scene_views.c — several views (`views`: cameras over the root camera's members;
 * `turntable`: cameras around the objects), `output` (format, depth, WebP quality, tonemap,
 * AOVs, debug views), and the size of the image or of the sheet of views against the limits.
 * See scene_internal.h for the conventions.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include "scene_internal.h"

static const char *const OUTPUT_MEMBERS[] = {"format", "bit_depth", "transparent", "tonemap", "msaa", "aovs",
                                             "debug", "debug_light", "png_level", "quality", NULL};
/* Output members that only a PNG answer uses, and why an EXR (or a WebP or AVIF: NULL where it
 * does use the member) has no use for them. */
static const char *const PNG_ONLY[] = {"bit_depth", "tonemap", "png_level", NULL};
static const char *const PNG_ONLY_WHY[] = {"a half-float image; bit_depth 16 is for PNG",
                                           "linear scene-referred; tonemap is for PNG", "zlib level of a PNG"};
static const char *const PNG_ONLY_8BIT_WHY[] = {"8 bits per channel; bit_depth 16 is for PNG", NULL,
                                                "zlib level of a PNG"};
static const char *const TURNTABLE_MEMBERS[] = {"frames", "elevation", "distance", NULL};

static int parse_views(struct pctx *c, json_t *views, struct rnd_scene *sc)
{
	size_t old = api_ptr_push(c, "views");
	int rc = 0;
	size_t n = json_is_array(views) ? json_array_size(views) : 0;
	struct rnd_camera *vs = NULL;
	if (!n) rc = api_fail(c, "views must be a non-empty array of cameras");
	else if (n > RND_MAX_VIEWS) rc = api_fail(c, "views has %zu cameras, at most %u are allowed", n, RND_MAX_VIEWS);
	else if (!(vs = api_arena_calloc(c->arena, n, sizeof *vs))) rc = api_fail(c, "out of memory");
	for (size_t i = 0; !rc && i < n; i++) {
		vs[i] = sc->camera;
		size_t o2 = api_ptr_index(c, i);
		rc = api_parse_camera(c, json_array_get(views, i), &vs[i]);
		api_ptr_pop(c, o2);
	}
	api_ptr_pop(c, old);
	if (rc) return -1;
	sc->views = vs;
	sc->view_count = (uint32_t)n;
	return 0;
}

static int parse_turntable(struct pctx *c, json_t *root, struct turntable *tt)
{
	json_t *sub;
	size_t old;
	int rc = api_enter(c, root, "turntable", TURNTABLE_MEMBERS, "turntable", &sub, &old);
	if (rc < 0) return -1;
	static const struct range elev = {-90, 90, false, false};
	long long frames = 0;
	double el = 20, dist = 0;
	rc = api_get_int(c, sub, "frames", 1, RND_MAX_VIEWS, &frames);
	if (rc == 0) rc = api_fail_at(c, "frames", "frames is required for a turntable");
	if (rc > 0 && (api_get_num(c, sub, "elevation", &elev, &el) < 0 || api_get_num(c, sub, "distance", &R_POS, &dist) < 0))
		rc = -1;
	api_ptr_pop(c, old);
	if (rc < 0) return -1;
	tt->frames = (uint32_t)frames;
	tt->elevation = el;
	tt->distance = dist;
	return 0;
}

/* `camera` is required unless `views` or `turntable` gives the cameras; when present with
 * them it supplies the defaults of every view (views: each member not given; turntable:
 * fov_y, near, far, exposure). */
int api_parse_cameras(struct pctx *c, json_t *root, struct rnd_scene *sc, struct turntable *tt)
{
	json_t *cam = json_object_get(root, "camera"), *views = json_object_get(root, "views"),
	       *turn = json_object_get(root, "turntable");
	if (cam) {
		size_t old = api_ptr_push(c, "camera");
		int rc = api_parse_camera(c, cam, &sc->camera);
		api_ptr_pop(c, old);
		if (rc < 0) return -1;
	} else if (!views && !turn) {
		return api_fail_at(c, "camera", "camera is required (unless views or turntable gives the cameras)");
	}
	if (views && turn) return api_fail_at(c, "turntable", "turntable cannot be combined with views");
	/* The turntable places its own perspective cameras; of the root camera it takes fov_y and
	 * exposure. Anything else there is valid but unused: said, not dropped silently. */
	static const char *const unused[] = {"type", "position", "target", "up", "height", "near", "far", "fit",
	                                     "direction", "margin", NULL};
	for (int k = 0; turn && cam && unused[k]; k++)
		if (json_object_get(cam, unused[k]) && (k || sc->camera.type == RND_CAMERA_ORTHOGRAPHIC))
			api_warn(c, "/camera/%s: not used by the turntable, whose perspective cameras circle the objects "
			         "(it takes fov_y and exposure from camera)", unused[k]);
	if (views && parse_views(c, views, sc) < 0) return -1;
	if (turn && parse_turntable(c, root, tt) < 0) return -1;
	return 0;
}

/* The turntable's cameras: frame k looks at the objects' bounds centre from azimuth 360°·k/N
 * (frame 0 on +Z, then counter-clockwise seen from above, i.e. towards +X) at the elevation,
 * from `distance`, or else from where the bounding sphere fills the frame up to a 0.1 margin
 * (as camera fit does). Perspective, up +Y, fov_y from the root camera when it is a perspective
 * one (else 45°), exposure from the root camera; near/far derived from the scene bounds (a
 * root camera's near/far were chosen for its own position). */
int api_turntable_views(struct pctx *c, const struct turntable *tt, struct rnd_scene *sc)
{
	struct rnd_camera *vs = api_arena_calloc(c->arena, tt->frames, sizeof *vs);
	if (!vs) return api_fail_at(c, "turntable", "out of memory");
	double centre[3], r;
	api_objects_sphere(sc, c->mats, centre, &r);
	const struct rnd_camera *root = &sc->camera;
	double fov = root->type == RND_CAMERA_PERSPECTIVE && root->fov_y > 0 ? root->fov_y : 45.0 * DEG2RAD;
	double dist = tt->distance;
	if (!(dist > 0)) {
		double aspect = (double)sc->width / sc->height, half = 0.5 * fov * (1.0 - 2.0 * 0.1);
		double half_x = atan(tan(half) * fmin(aspect, 1.0));
		dist = r / sin(fmin(half, half_x));
	}
	double el = tt->elevation * DEG2RAD;
	for (uint32_t k = 0; k < tt->frames; k++) {
		struct rnd_camera *v = &vs[k];
		double az = 2.0 * M_PI * k / tt->frames;
		/* Unit vector from the centre to the camera (the view direction is its opposite). */
		double d[3] = {cos(el) * sin(az), sin(el), cos(el) * cos(az)};
		v->type = RND_CAMERA_PERSPECTIVE;
		for (int i = 0; i < 3; i++) {
			v->target[i] = (float)centre[i];
			v->position[i] = (float)(centre[i] + dist * d[i]);
			v->fit_direction[i] = (float)-d[i];
		}
		v->up[0] = 0; v->up[1] = 1; v->up[2] = 0;
		v->fov_y = (float)fov;
		v->exposure = root->exposure;
		v->fit = RND_FIT_NONE;
		v->fit_margin = 0.1f;
	}
	sc->views = vs;
	sc->view_count = tt->frames;
	return 0;
}


static int parse_output(struct pctx *c, json_t *j, struct api_scene *s)
{
	struct rnd_output *o = &s->scene.output;
	if (api_require_object(c, j, "output") < 0 || api_check_members(c, j, OUTPUT_MEMBERS, NULL, "output") < 0)
		return -1;
	static const char *const formats[] = {"png", "exr", "webp", "avif", NULL};
	static const enum api_format format_values[] = {API_FORMAT_PNG, API_FORMAT_EXR, API_FORMAT_WEBP,
	                                                API_FORMAT_AVIF};
	static const char *const tonemaps[] = {"neutral", "aces", "none", NULL};
	static const enum rnd_tonemap tonemap_values[] = {RND_TONEMAP_NEUTRAL, RND_TONEMAP_ACES, RND_TONEMAP_NONE};
	static const char *const debugs[] = {"none", "shadow", "cascades", "normals", "depth", "atlas",
	                                     "environment_shadow", NULL};
	static const enum rnd_debug debug_values[] = {RND_DEBUG_NONE, RND_DEBUG_SHADOW, RND_DEBUG_CASCADES,
	                                              RND_DEBUG_NORMALS, RND_DEBUG_DEPTH, RND_DEBUG_ATLAS,
	                                              RND_DEBUG_ENV_SHADOW};
	int e, rc;
	if ((rc = api_get_enum(c, j, "format", formats, &e)) < 0) return -1;
	if (rc) {
		s->format = format_values[e];
		s->format_explicit = 1;
	}
	/* quality makes the WebP or AVIF lossy; without it they are lossless. */
	static const struct range percent = {0, 100, false, false};
	if ((rc = api_get_float(c, j, "quality", &percent, &s->quality)) < 0) return -1;
	if (rc && s->format_explicit && !api_format_lossy(s->format))
		return api_fail_at(c, "quality", "quality (lossy WebP or AVIF, 0..100) needs format \"webp\" or \"avif\", "
		                   "not \"%s\"", formats[s->format]);
	if ((rc = api_get_u32(c, j, "bit_depth", 8, 16, &s->bit_depth)) < 0) return -1;
	if (rc && s->bit_depth != 8 && s->bit_depth != 16)
		return api_fail_at(c, "bit_depth", "bit_depth must be 8 or 16 (got %u)", s->bit_depth);
	if (api_get_bool(c, j, "transparent", &o->transparent) < 0) return -1;
	if ((rc = api_get_enum(c, j, "tonemap", tonemaps, &e)) < 0) return -1;
	if (rc) o->tonemap = tonemap_values[e];
	if ((rc = api_get_u32(c, j, "msaa", 1, 4, &o->msaa)) < 0) return -1;
	if (rc && o->msaa != 1 && o->msaa != 4) return api_fail_at(c, "msaa", "msaa must be 1 or 4 (got %u)", o->msaa);
	if ((rc = api_get_enum(c, j, "debug", debugs, &e)) < 0) return -1;
	if (rc) o->debug = debug_values[e];
	if (api_get_u32(c, j, "debug_light", 0, UINT32_MAX, &o->debug_light) < 0) return -1;
	if (json_object_get(j, "debug_light") && o->debug != RND_DEBUG_SHADOW)
		return api_fail_at(c, "debug_light", "debug_light is only used with debug \"shadow\" (it names the light "
		                   "whose visibility that view shows)");
	long long lvl;
	if ((rc = api_get_int(c, j, "png_level", -1, 9, &lvl)) < 0) return -1;
	if (rc) s->png_level = (int)lvl;
	for (int k = 0; PNG_ONLY[k]; k++)
		if (json_object_get(j, PNG_ONLY[k]) && (k != 0 || s->bit_depth != 8) &&
		    (k != 1 || o->tonemap != RND_TONEMAP_NONE))
			s->png_only_ |= 1u << k;
	json_t *a = json_object_get(j, "aovs");
	if (a) {
		size_t old = api_ptr_push(c, "aovs");
		static const char *const aovs[] = {"shadow", "depth", "normal", "albedo", NULL};
		static const uint32_t aov_bits[] = {RND_AOV_SHADOW, RND_AOV_DEPTH, RND_AOV_NORMAL, RND_AOV_ALBEDO};
		rc = 0;
		if (!json_is_array(a)) rc = api_fail(c, "aovs must be an array of names, not %s", api_type_name(a));
		for (size_t i = 0; !rc && i < json_array_size(a); i++) {
			size_t o2 = api_ptr_index(c, i);
			if (api_check_enum(c, "each aov", json_array_get(a, i), aovs, &e) < 0) rc = -1;
			api_ptr_pop(c, o2);
			if (rc) break;
			if (o->aovs & aov_bits[e]) rc = api_fail(c, "aovs lists \"%s\" twice", aovs[e]);
			o->aovs |= aov_bits[e];
		}
		/* The default format is PNG, which has no room for AOVs. Without an explicit format the
		 * request may still choose EXR (Accept, the CLI's -o name): api_scene_check_output()
		 * decides once that choice is made. */
		if (!rc && o->aovs && s->format_explicit && s->format != API_FORMAT_EXR)
			rc = api_fail(c, "aovs need format \"exr\": a %s has no room for AOV channels",
			              api_format_label(s->format));
		api_ptr_pop(c, old);
		if (rc) return -1;
		api_member_read(c, j, "aovs");   /* in o->aovs */
	}
	return 0;
}

/* Adds the sentence "/output/MEMBER: not used, the answer is FORMAT (WHY)" to s->warnings
 * (on), or cuts it out with the separator next to it (off). */
static void sync_warning(struct api_scene *s, const char *member, const char *format, const char *why, bool on)
{
	char line[160];
	snprintf(line, sizeof line, "/output/%s: not used, the answer is %s (%s)", member, format, why);
	char *at = strstr(s->warnings, line);
	size_t n = strlen(s->warnings), len = strlen(line);
	if (on && !at && n + 2 + len < sizeof s->warnings) {
		snprintf(s->warnings + n, sizeof s->warnings - n, "%s%s", n ? "; " : "", line);
	} else if (!on && at) {
		/* "; " before the sentence, or after it when it is the first. */
		char *from = at, *to = at + len;
		if (from > s->warnings) from -= 2;
		else if (!strncmp(to, "; ", 2)) to += 2;
		memmove(from, to, strlen(to) + 1);
	}
}

/* Says, in s->warnings, which PNG-only output members an EXR or WebP answer leaves unused, and
 * takes the sentence back when the answer becomes another format (the format is chosen last: by
 * output.format, or by Accept / the CLI's -o name through api_scene_set_format). A warning,
 * not an error: the same document may be answered in any format. */
static void sync_png_only(struct api_scene *s)
{
	for (int k = 0; PNG_ONLY[k]; k++) {
		if (!(s->png_only_ & (1u << k))) continue;
		sync_warning(s, PNG_ONLY[k], "EXR", PNG_ONLY_WHY[k], s->format == API_FORMAT_EXR);
		if (PNG_ONLY_8BIT_WHY[k]) {
			sync_warning(s, PNG_ONLY[k], "WebP", PNG_ONLY_8BIT_WHY[k], s->format == API_FORMAT_WEBP);
			sync_warning(s, PNG_ONLY[k], "AVIF", PNG_ONLY_8BIT_WHY[k], s->format == API_FORMAT_AVIF);
		}
	}
}

void api_set_pixels(struct api_scene *s)
{
	sync_png_only(s);
	if (s->format == API_FORMAT_EXR) s->scene.output.pixels = RND_PIXELS_RGBA32F;
	else if (api_format_lossy(s->format)) s->scene.output.pixels = RND_PIXELS_RGBA8;   /* WebP, AVIF */
	else s->scene.output.pixels = s->bit_depth == 16 ? RND_PIXELS_RGBA16 : RND_PIXELS_RGBA8;
}


int api_parse_root_output(struct pctx *c, json_t *root, struct api_scene *s)
{
	struct rnd_scene *sc = &s->scene;
	json_t *out = json_object_get(root, "output");
	if (!out) return 0;
	size_t old = api_ptr_push(c, "output");
	int rc = parse_output(c, out, s);
	if (!rc) {
		bool given = json_object_get(out, "debug_light") != NULL;
		uint32_t dl = sc->output.debug_light;
		if (given && dl >= sc->light_count)
			rc = api_fail_at(c, "debug_light", "debug_light %u names no light (the scene has %u)", dl,
			             sc->light_count);
		else if (!given && sc->output.debug == RND_DEBUG_SHADOW && sc->light_count == 0)
			rc = api_fail_at(c, "debug", "debug \"shadow\" shows light debug_light (0), but the scene "
			             "has no lights");
	}
	api_ptr_pop(c, old);
	return rc < 0 ? -1 : 0;
}

void api_check_size(struct pctx *c, json_t *root, const struct rnd_scene *sc)
{
	uint64_t px = (uint64_t)sc->width * sc->height;
	if (c->lim->max_pixels && px > c->lim->max_pixels)
		api_defer(c, false, sc->height > sc->width ? "height" : "width",
		      "width x height = %llu pixels is over this server's limit of %llu", (unsigned long long)px,
		      (unsigned long long)c->lim->max_pixels);
	if (!sc->view_count) return;
	/* Several views: the whole sheet counts (the renderer's layout, unused cells included). */
	uint32_t n = sc->view_count, cols, rows;
	rnd_sheet_layout(n, &cols, &rows);
	uint64_t sw = (uint64_t)cols * sc->width, sh = (uint64_t)rows * sc->height, sheet = sw * sh;
	const char *key = json_object_get(root, "views") ? "views" : "turntable";
	c->views_key = key;
	if (c->lim->max_pixels && sheet > c->lim->max_pixels)
		api_defer(c, false, key, "%u views of %ux%u make a %llux%llu sheet (%llu pixels), over this server's "
		      "limit of %llu", n, sc->width, sc->height, (unsigned long long)sw, (unsigned long long)sh,
		      (unsigned long long)sheet, (unsigned long long)c->lim->max_pixels);
	else if (sw > RND_MAX_SHEET_SIDE || sh > RND_MAX_SHEET_SIDE || sheet > RND_MAX_SHEET_PIXELS)
		api_defer(c, false, key, "%u views of %ux%u make a %llux%llu sheet, over the renderer's limit (%u per "
		      "side, %llu pixels)", n, sc->width, sc->height, (unsigned long long)sw, (unsigned long long)sh,
		      RND_MAX_SHEET_SIDE, (unsigned long long)RND_MAX_SHEET_PIXELS);
}
