/*
 * renderer/visibility_plan.c — whether a view takes its shadows from the visibility pass
 * (visibility.c says what the pass is and records it), and the memory it may take: the render
 * plan's decision (render_plan.c), made here from the scene, its shadow plan and its draws.
 * Pure: no Vulkan.
 */
#include "material_bits.h"
#include "visibility_plan.h"

/* When the pass pays (measured on lavapipe, studio-spots' objects under its seven lights, 768 x
 * 512): it runs the filters once per block of 4x4 pixels where the main pass ran them once per
 * block per triangle touching it, and costs a surfaces pass and a main pass of its own. A floor
 * alone: 15 % slower; spheres of 16 segments (~600 triangles facing the camera): 4 % faster; of
 * 32 (~2,200): 11 %; of 64 (~8,300): 20 % (4 and 16 spot lights: 23 %, 18 %). So: at least one
 * such triangle per 512 pixels. One wide light: one per 16 pixels (below).
 * Only wide filters pay for it: studio-spots' seven lights all hard made the main pass 49 ms
 * without the pass and 65 with it; PCF radius 1: 57 / 68, 2: 81 / 84, 3: 97 / 97, 5: 143 /
 * 134; PCSS: 136 / 119. A hard or moment-map lookup is one fetch, cheaper than the passes. */
#define RND_VIS_MIN_PCF_RADIUS 4
#define RND_VIS_PIXELS_PER_FACE 512u
/* One wide light pays for the passes only over dense meshes. Measured, the thumbnail preset
 * with its one PCSS sun, 512², whole render without / with the pass: the 124k-triangle ogre
 * OBJ's 49k level 115 / 101 ms, nefertiti 113 / 86, beast 88 / 73, a 100k-triangle STL sphere's
 * level 60 / 55 (main pass alone: ogre 97 / 80, nefertiti 95 / 69); about even: a sphere of
 * 128 segments (one face towards the camera per 32 pixels) 49.1 / 48.6, a 10k-triangle STL
 * (one per 52) 46.7 / 44.6 and 43.6 / 44.0, 64 segments (one per 130) 39.7 / 39.5; worse: 16
 * segments (one per 500) 31.9 / 35.1, thumb-512's tessellated sphere (one per 47) main pass
 * 17.3 / 19.4. So one per 16 pixels, where it clearly pays; and only with MSAA, which shades
 * a pixel once per triangle touching it: at MSAA 1 one triangle shades each pixel, and the
 * ogre's thumbnail took 53-57 ms without the pass, 59-60 with it. */
#define RND_VIS_PIXELS_PER_FACE_ONE_LIGHT 16u
/* The largest visibility image (bytes) a render may take: 16 lights of a 1024² view. */
#define RND_VIS_MAX_BYTES (32ull << 20)

/* A filter costly enough per pixel that running it once per pixel pays for the passes. */
static bool wide_filter(const struct rnd_light_plan *lp)
{
	return lp->filter == UMBRA_FILTER_PCSS || (lp->filter == UMBRA_FILTER_PCF && lp->pcf_radius >= RND_VIS_MIN_PCF_RADIUS);
}

uint64_t rnd_surfaces_bytes(const struct rnd_scene *sc, uint32_t lights)
{
	uint64_t px = (uint64_t)sc->width * sc->height;
	if (px * lights * 2 > RND_VIS_MAX_BYTES) return 0;
	/* rnd_slot_visibility's images: surfaces RGBA32F, normals RGBA16 SNORM, their depth D32,
	 * an R16 layer per light, at least RND_VIS_MIN_LAYERS */
	uint32_t layers = lights < RND_VIS_MIN_LAYERS ? RND_VIS_MIN_LAYERS : lights;
	return px * (16 + 8 + 4 + 2ull * layers);
}

uint64_t rnd_visibility_bytes(const struct rnd_scene *sc)
{
	if (sc->output.debug != RND_DEBUG_NONE) return 0;
	bool shadowed = false;
	for (uint32_t i = 0; i < sc->light_count; i++) shadowed |= sc->lights[i].shadow.enabled;
	return shadowed ? rnd_surfaces_bytes(sc, sc->light_count) : 0;
}

uint64_t rnd_camera_faces(const struct draw *draws, uint32_t ndraw)
{
	/* a back-face culled closed shape shows about half its triangles, a sphere's proxy all of
	 * its own */
	uint64_t faces = 0;
	for (uint32_t i = 0; i < ndraw; i++)
		faces += draws[i].cam_index_count / 3 / (draws[i].cull_back ? 2 : 1);
	return faces;
}

/* Why, for the plan's reader; returns whether that is `on`. */
static bool because(uint8_t *why, enum rnd_vis_why w)
{
	if (why) *why = (uint8_t)w;
	return w == RND_VIS_DENSE || w == RND_VIS_FORCED_ON;
}

bool rnd_visibility_wanted(bool device, int force, const struct rnd_scene *sc, const struct rnd_shadow_plan *sp,
                           const struct draw *draws, uint32_t ndraw, uint8_t *why)
{
	if (!device) return because(why, RND_VIS_NO_DEVICE);
	if (sc->output.debug != RND_DEBUG_NONE) return because(why, RND_VIS_DEBUG);
	uint32_t shadowed = 0, wide = 0;
	for (uint32_t i = 0; i < sc->light_count; i++)
		if (sp->lights[i].view_count) {
			shadowed++;
			if (wide_filter(&sp->lights[i])) wide++;
		}
	if (!shadowed) return because(why, RND_VIS_NO_SHADOWS);
	for (uint32_t i = 0; i < ndraw; i++)
		if (draws[i].index_count && draws[i].masked) return because(why, RND_VIS_MASKED);
	if (!rnd_visibility_bytes(sc)) return because(why, RND_VIS_TOO_LARGE);   /* over the size cap */
	if (force >= 0) return because(why, force == 1 ? RND_VIS_FORCED_ON : RND_VIS_FORCED_OFF);
	if (!wide) return because(why, RND_VIS_NARROW);
	uint64_t faces = rnd_camera_faces(draws, ndraw);
	uint64_t px = (uint64_t)sc->width * sc->height;
	bool dense = wide >= 2 ? faces * RND_VIS_PIXELS_PER_FACE >= px
	                       : sc->output.msaa > 1 && faces * RND_VIS_PIXELS_PER_FACE_ONE_LIGHT >= px;
	return because(why, dense ? RND_VIS_DENSE : RND_VIS_SPARSE);
}

/* ---- pixel shading (deferred.c: what it is and how it is recorded) ---- */

/* Without the visibility pass (no light with a wide shadow filter), pixel shading runs the
 * surfaces pass for itself where an environment map lights the view: its shading (the map's
 * light and the environment pass's bilateral read, ibl.glsl) is what lavapipe would otherwise run
 * per triangle per 4x4 block. It pays over dense meshes, as the visibility pass does for one wide
 * light: at least one face towards the camera per RND_DEFERRED_PIXELS_PER_FACE pixels. */
#define RND_DEFERRED_PIXELS_PER_FACE 16u

/* A draw shade.glsl can shade from the surfaces pass alone: no texture (the fullscreen pass has
 * no uv derivatives and binds no material's set), no material extension's lobe (their textures
 * and coat normal), opaque (no alpha test or dither: the surfaces pass cuts no texel out), not a
 * sphere's proxy (it shades the true sphere, not the mesh the surfaces pass keeps). */
static bool plain(const struct rnd_scene *sc, const struct draw *d)
{
	return !d->masked && !(d->tex_bits & ((1u << UMBRA_TEX_SLOTS) - 1u)) && !(d->flags & UMBRA_DRAW_SPHERE) &&
	       !(sc->material_count && rnd_material_ext_bits(&sc->materials[d->material]));
}

static bool shade_because(uint8_t *why, enum rnd_pixel_why w)
{
	if (why) *why = (uint8_t)w;
	return w == RND_PIXEL_VISIBILITY || w == RND_PIXEL_ENVIRONMENT;
}

bool rnd_pixel_shading_wanted(bool device, bool vis_device, int force, const struct rnd_scene *sc,
                              const struct draw *draws, uint32_t ndraw, bool vis, bool env_lit, uint8_t *why)
{
	if (!device) return shade_because(why, RND_PIXEL_NO_DEVICE);
	if (sc->output.msaa != 4 || sc->output.debug != RND_DEBUG_NONE) return shade_because(why, RND_PIXEL_OUTPUT);
	/* An environment map behind the scene is drawn where the main pass left the far plane
	 * (record.c, env_background.frag); the resolve writes the clear colour there. */
	if (sc->environment.source != RND_ENV_AMBIENT && sc->environment.background_map && !sc->output.transparent)
		return shade_because(why, RND_PIXEL_BACKGROUND);
	for (uint32_t i = 0; i < ndraw; i++)
		if (draws[i].index_count && !plain(sc, &draws[i])) return shade_because(why, RND_PIXEL_NOT_PLAIN);
	if (!vis) {
		if (!vis_device || !env_lit) return shade_because(why, RND_PIXEL_NO_PASS);
		if (!rnd_surfaces_bytes(sc, 0)) return shade_because(why, RND_PIXEL_TOO_LARGE);
		if (rnd_camera_faces(draws, ndraw) * RND_DEFERRED_PIXELS_PER_FACE < (uint64_t)sc->width * sc->height)
			return shade_because(why, RND_PIXEL_SPARSE);
	}
	if (force == 0) return shade_because(why, RND_PIXEL_FORCED_OFF);
	return shade_because(why, vis ? RND_PIXEL_VISIBILITY : RND_PIXEL_ENVIRONMENT);
}

uint64_t rnd_deferred_bytes(const struct rnd_scene *sc)
{
	if (sc->output.msaa != 4 || sc->output.debug != RND_DEBUG_NONE) return 0;
	/* the surfaces pass's images where the visibility pass has none (an environment map's view) */
	uint64_t surfaces = 0;
	if (!rnd_visibility_bytes(sc)) {
		if (sc->environment.source == RND_ENV_AMBIENT || !(surfaces = rnd_surfaces_bytes(sc, 0))) return 0;
	}
	/* the shading inputs (RGBA32UI) and the shaded colour (at most RGBA32F) */
	return surfaces + (uint64_t)sc->width * sc->height * (16 + 16);
}

/* rnd_visibility_wanted's reasons in words (the plan shows them). */
const char *rnd_vis_why_text(unsigned why)
{
	static const char *const text[RND_VIS_WHY_COUNT] = {
		[RND_VIS_DENSE] = "enough small triangles under wide filters for the pass to pay",
		[RND_VIS_FORCED_ON] = "UMBRA_VISIBILITY=1",
		[RND_VIS_NO_DEVICE] = "the device cannot run it",
		[RND_VIS_DEBUG] = "a debug view shows the filters' own work",
		[RND_VIS_NO_SHADOWS] = "no light has shadow maps",
		[RND_VIS_MASKED] = "an alpha-tested material",
		[RND_VIS_TOO_LARGE] = "its images would be too large",
		[RND_VIS_FORCED_OFF] = "UMBRA_VISIBILITY=0",
		[RND_VIS_NARROW] = ("no light filters widely enough (PCSS, PCF radius " RND_NUMBER_WORDS(RND_VIS_MIN_PCF_RADIUS)
		                    " or more)"),
		[RND_VIS_SPARSE] = "too few triangles for its passes to pay",
	};
	return why < RND_VIS_WHY_COUNT ? text[why] : "";
}

/* rnd_pixel_shading_wanted's reasons in words. */
const char *rnd_pixel_why_text(unsigned why)
{
	static const char *const text[RND_PIXEL_WHY_COUNT] = {
		[RND_PIXEL_VISIBILITY] = "plain draws: the visibility pass's surfaces shaded once per pixel centre",
		[RND_PIXEL_ENVIRONMENT] = "an environment map over dense plain draws: its own surfaces pass, shaded once per pixel",
		[RND_PIXEL_NO_DEVICE] = "the device cannot",
		[RND_PIXEL_OUTPUT] = "not MSAA 4, or a debug view",
		[RND_PIXEL_BACKGROUND] = "the environment map is the background",
		[RND_PIXEL_NOT_PLAIN] = "a textured, alpha-tested or extension material, or a sphere's proxy",
		[RND_PIXEL_NO_PASS] = "no visibility pass and no environment map",
		[RND_PIXEL_TOO_LARGE] = "its images would be too large",
		[RND_PIXEL_SPARSE] = "too few triangles for its passes to pay",
		[RND_PIXEL_FORCED_OFF] = "UMBRA_PIXEL_SHADING=0",
	};
	return why < RND_PIXEL_WHY_COUNT ? text[why] : "";
}
