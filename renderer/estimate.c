/*
 * renderer/estimate.c — what a render will allocate, known before it starts: the sheet layout
 * of several views, the AOV passes, and the bytes of every target, buffer and host copy a
 * render of a scene needs. rnd_render() refuses a scene whose largest single allocation is over
 * the device's limit (a 422 naming the member, not an out-of-memory 503 that no retry cures);
 * the render plan carries the estimate (render_plan.c makes it once), and the daemon admits
 * renders by it (--max-memory).
 */
#include <string.h>
#include "error.h"
#include "estimate.h"
#include "mesh.h"
#include "umbra_shared.h"
#include "visibility_plan.h"

void rnd_sheet_layout(uint32_t view_count, uint32_t *cols, uint32_t *rows)
{
	uint32_t n = view_count ? view_count : 1, c = 1;
	while (c * c < n) c++;
	*cols = c;
	*rows = (n + c - 1) / c;
}

void rnd_sheet_init(struct rnd_sheet *sh, const struct rnd_scene *sc)
{
	memset(sh, 0, sizeof *sh);
	sh->views = sc->view_count ? sc->view_count : 1;
	rnd_sheet_layout(sh->views, &sh->cols, &sh->rows);
	sh->width = (uint64_t)sh->cols * sc->width;
	sh->height = (uint64_t)sh->rows * sc->height;
	sh->px = (size_t)rnd_pixel_bytes(sc->output.pixels);
	sh->passes = rnd_aov_passes(sc);
	sh->color_bytes = sh->width * sh->height * sh->px;
	sh->att_bytes = sh->width * sh->height * 16;
	sh->readback_bytes = sh->color_bytes + (uint64_t)sh->passes * UMBRA_AOV_ATTACHMENTS * sh->att_bytes;
}

uint32_t rnd_aov_passes(const struct rnd_scene *sc)
{
	if (!sc->output.aovs) return 0;
	/* The first pass carries depth, normal, albedo and 8 shadow planes; each further pass 16. */
	uint32_t n = (sc->output.aovs & RND_AOV_SHADOW) ? sc->light_count : 0;
	return UMBRA_AOV_PASSES(n);
}

uint64_t rnd_pixel_bytes(enum rnd_pixel_format f)
{
	return f == RND_PIXELS_RGBA8 ? 4 : f == RND_PIXELS_RGBA16 ? 8 : 16;
}

uint32_t rnd_aov_planes(const struct rnd_scene *sc)
{
	uint32_t a = sc->output.aovs;
	return (a & RND_AOV_DEPTH ? 1 : 0) + (a & RND_AOV_NORMAL ? 3 : 0) + (a & RND_AOV_ALBEDO ? 3 : 0) +
	       (a & RND_AOV_SHADOW ? sc->light_count : 0);
}

static uint64_t max64(uint64_t a, uint64_t b) { return a > b ? a : b; }

/* The material textures' full mip chains (4/3 of their texels). A texture two materials (or
 * two slots of different colour space) share counts for each: an upper bound, as admission
 * wants. */
static uint64_t texture_bytes(const struct rnd_scene *sc)
{
	uint64_t b = 0;
	for (uint32_t i = 0; i < sc->material_count; i++)
		for (uint32_t k = 0; k < RND_TEX_SLOTS; k++) {
			const struct rnd_texture *t = sc->materials[i].textures[k];
			if (t && t->width <= RND_MAX_TEXTURE_SIDE && t->height <= RND_MAX_TEXTURE_SIDE)
				b += rnd_texture_chain_bytes(t->width, t->height);
		}
	return b;
}

void rnd_estimate_scene(const struct rnd_scene *sc, uint32_t atlas_size, struct rnd_estimate *e)
{
	uint32_t cols, rows;
	rnd_sheet_layout(sc->view_count, &cols, &rows);
	uint64_t px = (uint64_t)sc->width * sc->height, sheet = px * cols * rows;
	uint64_t pb = rnd_pixel_bytes(sc->output.pixels), samples = sc->output.msaa > 1 ? sc->output.msaa : 1;
	uint32_t passes = rnd_aov_passes(sc);
	uint64_t colour = sheet * pb, aov_att = sheet * 16;
	uint64_t readback = colour + (uint64_t)passes * UMBRA_AOV_ATTACHMENTS * aov_att;

	uint64_t nv = 0, ni = 0;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		uint32_t v, x;
		rnd_mesh_counts(&sc->objects[i], &v, &x);
		nv += v; ni += x;
	}
	uint64_t geometry = nv * sizeof(struct rnd_vertex) + ni * 4;
	uint64_t textures = texture_bytes(sc);

	/* The largest shadow map drawn (its scratch image and the buffer it is copied through). */
	uint64_t res = 0;
	for (uint32_t i = 0; i < sc->light_count; i++) {
		uint32_t want = sc->lights[i].shadow.resolution;
		uint32_t r = rnd_shadow_map_side(want, want != 0, sc->max_shadow_resolution);
		res = max64(res, r > atlas_size ? atlas_size : r);
	}
	uint64_t scratch = res * res * 4 * 2;

	uint64_t targets = px * pb * (samples > 1 ? 1 + samples : 1) + px * 4 * samples;
	uint64_t aov_targets = passes ? px * (16 * UMBRA_AOV_ATTACHMENTS + 4) : 0;
	/* Each texture twice: its image and the staging buffer that carries it (both with mips). */
	e->device_bytes = targets + aov_targets + readback + geometry + scratch + 2 * textures + rnd_visibility_bytes(sc) +
	                 rnd_deferred_bytes(sc);
	/* The image handed back (colour + float AOV planes) and, at most as large, its encoding. */
	uint64_t image = colour + sheet * 4 * rnd_aov_planes(sc);
	e->host_bytes = 2 * image;
	e->largest_allocation = max64(max64(readback, geometry), max64(px * pb * samples, px * 16));
	e->readback_bytes = readback;
}

enum rnd_result rnd_check_allocation(uint64_t max, const struct rnd_scene *sc, const struct rnd_estimate *e,
                                     struct rnd_error *err)
{
	if (!max || e->largest_allocation <= max) return RND_OK;
	if (sc->output.aovs)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_AOVS, 0,
		                   "%ux%u%s with %u AOV planes needs %.2f GB in one buffer; this device allows %.2f GB: "
		                   "ask for fewer AOVs (each light's shadow is one plane) or fewer pixels",
		                   sc->width, sc->height, sc->view_count > 1 ? " per view" : "", rnd_aov_planes(sc),
		                   e->largest_allocation / 1e9, max / 1e9);
	return rnd_fail_at(err, RND_ERR_LIMIT, sc->view_count > 1 ? RND_AT_VIEWS : RND_AT_SIZE, 0,
	                   "the image needs %.2f GB in one buffer; this device allows %.2f GB: fewer pixels",
	                   e->largest_allocation / 1e9, max / 1e9);
}
