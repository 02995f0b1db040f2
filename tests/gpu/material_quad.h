/*
 * tests/gpu/material_quad.h — what the material tests share (test_materials.c: the core
 * material model; test_material_alpha.c: BLEND, MASK, transmission, mipmaps;
 * test_material_ext.c: the PBR extensions): one 2x2 quad in a .glb built here (its material
 * and textures given as JSON text), rendered through api_scene_parse and the renderer, and
 * the pixels read back in linear light at world points.
 */
#ifndef UMBRA_TEST_MATERIAL_QUAD_H
#define UMBRA_TEST_MATERIAL_QUAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "gpu_util.h"

/* The quad: 2x2 in XZ at height y, front face +Y, u = (x + 1) / 2 * uscale, v = (z + 1) / 2
 * (texel row 0 at z = -1, the top of the image of the camera below). */
struct mglb {
	const char *material;        /* JSON object: materials[0] */
	const char *textures;        /* JSON array, or NULL */
	const char *samplers;        /* JSON array, or NULL */
	const char *extensions_used; /* JSON array, or NULL */
	const uint8_t *png[3];
	size_t png_len[3];
	int npng;
	float uscale;                /* 0 = 1 */
	float y;                     /* node translation */
	const float *color;          /* COLOR_0 RGBA float per vertex, or NULL */
	const float *tangent;        /* TANGENT xyzw per vertex, or NULL */
	const char *output;          /* the scene's output members, or NULL: no tone map, no MSAA */
	const float *uv0;            /* TEXCOORD_0 uv per vertex instead of the one above, or NULL */
	const float *uv1;            /* TEXCOORD_1 uv per vertex, or NULL: none */
	const char *light;           /* render_quad's lit light (JSON), or NULL: straight down, intensity pi */
	float ambient;               /* render_quad's ambient intensity (0: none) */
};

#define MW 64
#define MH 64
#define MORTHO 2.2   /* orthographic height: the quad (2 wide) fills most of the image */
#define NEAREST_CLAMP "[{\"magFilter\":9728,\"minFilter\":9728,\"wrapS\":33071,\"wrapT\":33071}]"
/* The quad over a blue ground (quad_over_ground): its image's size. */
#define BW 96
#define BH 96

/* The .glb of g (malloc'd, *len bytes), or NULL. */
uint8_t *glb_of(const struct mglb *g, size_t *len);
/* The .glb of g as base64 (malloc'd), for a model object's data; NULL when out of memory. */
char *quad_data(const struct mglb *g);
/* The orthographic camera straight down on the quad (from below: `below`). */
void cam_of(struct gpu_cam *cam, bool below);
/* Renders the quad model: `light` none or a directional light straight down of intensity pi
 * (so a white Lambert surface facing it has radiance 1); the ambient of g->ambient (none by
 * default); no tone map. */
bool render_quad(int line, struct rnd_image *img, const struct mglb *g, bool light, bool below);
/* Linear radiance of channel c at world point (x, 0, z) seen from the camera. */
double lin_at(const struct rnd_image *img, bool below, double x, double z, int c);
/* A w x h texture of RGBA texels as PNG bytes into g->png[g->npng++]; free_pngs frees them. */
void add_png(struct mglb *g, const uint8_t *texels, int w, int h);
void free_pngs(struct mglb *g);
/* The quad at y = 1 (g's material) over a blue ground under a sun along (0.8, -1, 0): its
 * shadow is the quad moved 0.8 along +x; camera straight down, BW x BH. */
bool quad_over_ground(int line, struct rnd_image *img, const struct mglb *g);
/* quad_over_ground with only a material (JSON) and its extensionsUsed (or NULL). */
bool material_render(int line, struct rnd_image *img, const char *material, const char *extensions_used);
/* quad_over_ground of a red quad, alpha 0.5 BLEND or opaque. */
bool blend_render(int line, struct rnd_image *img, bool blend);
/* Mean linear channel c over the world rectangle [x0, x1] x [z0, z1] at height y of a
 * quad_over_ground image. */
double mean_rect(const struct rnd_image *img, double x0, double x1, double z0, double z1, double y, int c);

#endif
