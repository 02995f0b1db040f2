/* tests/gpu/material_quad.c — the material tests' one-quad .glb and its renders (see
 * material_quad.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gpu_util.h"
#include "material_quad.h"
#include "models.h"
#include "test.h"
#include "util.h"

static const uint32_t QIDX[6] = {0, 2, 1, 0, 3, 2};

uint8_t *glb_of(const struct mglb *in, size_t *len)
{
	float us = in->uscale > 0 ? in->uscale : 1;
	float pos[12] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1}, nrm[12], uv[8];
	for (int v = 0; v < 4; v++) {
		nrm[3 * v] = 0; nrm[3 * v + 1] = 1; nrm[3 * v + 2] = 0;
		uv[2 * v] = (pos[3 * v] + 1) / 2 * us;
		uv[2 * v + 1] = (pos[3 * v + 2] + 1) / 2;
	}
	if (in->uv0) memcpy(uv, in->uv0, sizeof uv);
	/* bin: pos 48, nrm 48, uv 32, [color 64], [tangent 64], [uv1 32], idx 24, pngs (4-aligned) */
	size_t off[16], n = 0, k = 0;
	const void *src[16];
	size_t sz[16];
	src[k] = pos; sz[k++] = 48;
	src[k] = nrm; sz[k++] = 48;
	src[k] = uv; sz[k++] = 32;
	if (in->color) { src[k] = in->color; sz[k++] = 64; }
	if (in->tangent) { src[k] = in->tangent; sz[k++] = 64; }
	if (in->uv1) { src[k] = in->uv1; sz[k++] = 32; }
	src[k] = QIDX; sz[k++] = 24;
	for (int i = 0; i < in->npng; i++) { src[k] = in->png[i]; sz[k++] = in->png_len[i]; }
	for (size_t i = 0; i < k; i++) { off[i] = n; n += (sz[i] + 3) & ~(size_t)3; }
	char views[2048], accs[1024], attrs[256], imgs[512] = "";
	int vl = 0;
	for (size_t i = 0; i < k; i++)
		vl += snprintf(views + vl, sizeof views - (size_t)vl, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}",
		               i ? "," : "", off[i], sz[i]);
	int al = snprintf(accs, sizeof accs,
	                  "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[-1,0,-1],"
	                  "\"max\":[1,0,1]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
	                  "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}");
	int tl = snprintf(attrs, sizeof attrs, "\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2");
	int view = 3, acc = 3;
	if (in->color) {
		al += snprintf(accs + al, sizeof accs - (size_t)al,
		               ",{\"bufferView\":%d,\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"}", view++);
		tl += snprintf(attrs + tl, sizeof attrs - (size_t)tl, ",\"COLOR_0\":%d", acc++);
	}
	if (in->tangent) {
		al += snprintf(accs + al, sizeof accs - (size_t)al,
		               ",{\"bufferView\":%d,\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"}", view++);
		tl += snprintf(attrs + tl, sizeof attrs - (size_t)tl, ",\"TANGENT\":%d", acc++);
	}
	if (in->uv1) {
		al += snprintf(accs + al, sizeof accs - (size_t)al,
		               ",{\"bufferView\":%d,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}", view++);
		tl += snprintf(attrs + tl, sizeof attrs - (size_t)tl, ",\"TEXCOORD_1\":%d", acc++);
	}
	al += snprintf(accs + al, sizeof accs - (size_t)al,
	               ",{\"bufferView\":%d,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"}", view++);
	int idx_acc = acc++;
	if (in->npng) {
		int il = snprintf(imgs, sizeof imgs, ",\"images\":[");
		for (int i = 0; i < in->npng; i++)
			il += snprintf(imgs + il, sizeof imgs - (size_t)il, "%s{\"bufferView\":%d,\"mimeType\":\"image/png\"}",
			               i ? "," : "", view++);
		snprintf(imgs + il, sizeof imgs - (size_t)il, "]");
	}
	char json[8192];
	int jn = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
		"\"nodes\":[{\"mesh\":0,\"translation\":[0,%.9g,0]}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{%s},\"indices\":%d,\"material\":0}]}],"
		"\"materials\":[%s]%s%s%s%s%s%s%s%s,"
		"\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[%s],\"accessors\":[%s]}",
		in->y, attrs, idx_acc, in->material, in->textures ? ",\"textures\":" : "", in->textures ? in->textures : "",
		in->samplers ? ",\"samplers\":" : "", in->samplers ? in->samplers : "",
		in->extensions_used ? ",\"extensionsUsed\":" : "", in->extensions_used ? in->extensions_used : "", imgs, "",
		n, views, accs);
	uint8_t *bin = calloc(1, n ? n : 1);
	if (!bin) return NULL;
	for (size_t i = 0; i < k; i++) memcpy(bin + off[i], src[i], sz[i]);
	uint8_t *g = test_glb_pack(json, (size_t)jn, bin, n, n, len);
	free(bin);
	return g;
}

/* ---- rendering ---- */

void cam_of(struct gpu_cam *cam, bool below)
{
	if (below) gpu_cam_ortho(cam, v3_make(0, -5, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), MORTHO, MW, MH);
	else gpu_cam_ortho(cam, v3_make(0, 5, 0), v3_make(0, 0, 0), v3_make(0, 0, -1), MORTHO, MW, MH);
}

char *quad_data(const struct mglb *g)
{
	size_t n;
	uint8_t *glb = glb_of(g, &n);
	char *enc = glb ? test_b64(glb, n) : NULL;
	free(glb);
	return enc;
}

/* Renders the quad model: `light` "none" or a directional light straight down of intensity pi
 * (so a white Lambert surface facing it has radiance 1); g->ambient's ambient; no tone map. */
bool render_quad(int line, struct rnd_image *img, const struct mglb *g, bool light, bool below)
{
	char *enc = quad_data(g);
	bool ok = gpu_render_at(__FILE__, line, img,
	                        "{'width':%d,'height':%d,"
	                        "'camera':{'type':'orthographic','position':[0,%d,0],'target':[0,0,0],'up':[0,0,-1],"
	                        "'height':%.9g},"
	                        "'environment':{'background':[0,0,0],'ambient':{'intensity':%.9g}},"
	                        "'objects':[{'shape':'model','format':'glb','data':'%s'}],"
	                        "'lights':[%s],'output':{%s}}",
	                        MW, MH, below ? -5 : 5, MORTHO, g->ambient, enc,
	                        !light ? "" : g->light ? g->light : "{'type':'directional','direction':[0,-1,0],'intensity':3.14159265}",
	                        g->output ? g->output : "'tonemap':'none','msaa':1");
	free(enc);
	return ok;
}

/* Linear radiance of channel c at world point (x, 0, z) seen from the camera. */
double lin_at(const struct rnd_image *img, bool below, double x, double z, int c)
{
	struct gpu_cam cam;
	cam_of(&cam, below);
	double px, py;
	gpu_cam_project(&cam, v3_make(x, 0, z), &px, &py);
	return gpu_srgb_decode(gpu_chan(img, (int)floor(px), (int)floor(py), c));
}

/* A w x h texture of RGBA texels as PNG bytes into g->png[g->npng++]. */
void add_png(struct mglb *g, const uint8_t *texels, int w, int h)
{
	g->png[g->npng] = test_png_rgba(texels, w, h, &g->png_len[g->npng]);
	g->npng++;
}

void free_pngs(struct mglb *g)
{
	for (int i = 0; i < g->npng; i++) free((void *)g->png[i]);
	g->npng = 0;
}

/* A red quad at y = 1 (alpha 0.5 BLEND, or OPAQUE) over a blue ground, sun along (0.8, -1, 0):
 * its shadow is the quad moved 0.8 along +x. Seen from above (orthographic), the quad itself
 * covers about half its pixels (dithered) and its shadow takes about half the light. */
bool quad_over_ground(int line, struct rnd_image *img, const struct mglb *g)
{
	char *enc = quad_data(g);
	bool ok = gpu_render_at(__FILE__, line, img,
	                        "{'width':%d,'height':%d,"
	                        "'camera':{'type':'orthographic','position':[0.6,5,0],'target':[0.6,0,0],'up':[0,0,-1],"
	                        "'height':3.6},"
	                        "'environment':{'background':[0,0,0],'ambient':{'intensity':0}},"
	                        "'objects':[{'shape':'plane','size':[8,8],'material':{'base_color':[0,0,1],'roughness':1}},"
	                        "{'shape':'model','format':'glb','data':'%s'}],"
	                        "'lights':[{'type':'directional','direction':[0.8,-1,0],'intensity':3}],"
	                        "'output':{'tonemap':'none','msaa':1}}",
	                        BW, BH, enc);
	free(enc);
	return ok;
}

bool material_render(int line, struct rnd_image *img, const char *material, const char *extensions_used)
{
	struct mglb g = {.material = material, .extensions_used = extensions_used, .y = 1};
	return quad_over_ground(line, img, &g);
}

bool blend_render(int line, struct rnd_image *img, bool blend)
{
	return material_render(line, img,
	                       blend ? "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,0.5],"
	                               "\"metallicFactor\":0,\"roughnessFactor\":1},\"alphaMode\":\"BLEND\"}"
	                             : "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1],"
	                               "\"metallicFactor\":0,\"roughnessFactor\":1}}",
	                       NULL);
}

/* Mean of channel c over the world rectangle [x0, x1] x [z0, z1] at height y. */
double mean_rect(const struct rnd_image *img, double x0, double x1, double z0, double z1, double y, int c)
{
	struct gpu_cam cam;
	gpu_cam_ortho(&cam, v3_make(0.6, 5, 0), v3_make(0.6, 0, 0), v3_make(0, 0, -1), 3.6, BW, BH);
	double a0, b0, a1, b1, sum = 0;
	gpu_cam_project(&cam, v3_make(x0, y, z0), &a0, &b0);
	gpu_cam_project(&cam, v3_make(x1, y, z1), &a1, &b1);
	int n = 0;
	for (int j = (int)ceil(fmin(b0, b1)); j < (int)floor(fmax(b0, b1)); j++)
		for (int i = (int)ceil(fmin(a0, a1)); i < (int)floor(fmax(a0, a1)); i++, n++)
			sum += gpu_srgb_decode(gpu_chan(img, i, j, c));
	return n ? sum / n : -1;
}
