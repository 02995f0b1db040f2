/* tests/util/models.c — see models.h. */
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "draco_encode.h"
#include "models.h"

void test_put32(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); p[2] = (uint8_t)(v >> 16); p[3] = (uint8_t)(v >> 24);
}

struct rnd_image test_rgba8_image(uint32_t w, uint32_t h, bool opaque)
{
	struct rnd_image img = {0};
	img.width = w;
	img.height = h;
	img.format = RND_PIXELS_RGBA8;
	img.stride = (size_t)w * 4 + 12;   /* padded rows: the stride is honoured */
	img.pixels = calloc(h, img.stride);
	for (uint32_t y = 0; img.pixels && y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			uint8_t *px = (uint8_t *)img.pixels + y * img.stride + 4 * x;
			double dx = x - w / 2.0, dy = y - h / 2.0, shade = dx * dx + dy * dy < w * h / 16.0 ? 0.4 : 1.0;
			px[0] = (uint8_t)(shade * (60 + 150.0 * x / w));
			px[1] = (uint8_t)(shade * (80 + 120.0 * y / h));
			px[2] = (uint8_t)(shade * 170);
			px[3] = opaque ? 255 : x < 2 || y < 2 ? 0 : (uint8_t)(128 + 127.0 * x / w);
		}
	return img;
}

double test_psnr_rgb(const struct rnd_image *img, const uint8_t *rgba, int *alpha_diff)
{
	double se = 0;
	*alpha_diff = 0;
	for (uint32_t y = 0; y < img->height; y++)
		for (uint32_t x = 0; x < img->width; x++) {
			const uint8_t *a = (const uint8_t *)img->pixels + y * img->stride + 4 * x;
			const uint8_t *b = rgba + 4 * ((size_t)y * img->width + x);
			for (int c = 0; c < 3; c++) se += (double)(a[c] - b[c]) * (a[c] - b[c]);
			if (abs(a[3] - b[3]) > *alpha_diff) *alpha_diff = abs(a[3] - b[3]);
		}
	double mse = se / (3.0 * img->width * img->height);
	return mse > 0 ? 10 * log10(255.0 * 255.0 / mse) : INFINITY;
}

uint8_t *test_png_rgba(const uint8_t *px, int w, int h, size_t *len)
{
	png_image img;
	memset(&img, 0, sizeof img);
	img.version = PNG_IMAGE_VERSION;
	img.width = (png_uint_32)w;
	img.height = (png_uint_32)h;
	img.format = PNG_FORMAT_RGBA;
	png_alloc_size_t n = 0;
	if (!png_image_write_to_memory(&img, NULL, &n, 0, px, 0, NULL)) return NULL;
	uint8_t *buf = malloc(n);
	if (!buf) return NULL;
	if (!png_image_write_to_memory(&img, buf, &n, 0, px, 0, NULL)) { free(buf); return NULL; }
	*len = n;
	return buf;
}

struct png_out {
	uint8_t *d;
	size_t n, cap;
	int bad;
};

static void png_out_write(png_structp png, png_bytep b, size_t n)
{
	struct png_out *o = png_get_io_ptr(png);
	if (o->n + n > o->cap) {
		size_t cap = (o->cap ? o->cap * 2 : 4096) + n;
		uint8_t *d = realloc(o->d, cap);
		if (!d) { o->bad = 1; return; }
		o->d = d;
		o->cap = cap;
	}
	memcpy(o->d + o->n, b, n);
	o->n += n;
}

static void png_out_flush(png_structp png)
{
	(void)png;
}

uint8_t *test_png_rgb_gamma(const uint8_t *rgb, int w, int h, double file_gamma, size_t *len)
{
	struct png_out o = {0};
	png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
	png_infop info = png ? png_create_info_struct(png) : NULL;
	if (!info || setjmp(png_jmpbuf(png))) {
		png_destroy_write_struct(&png, &info);
		free(o.d);
		return NULL;
	}
	png_set_write_fn(png, &o, png_out_write, png_out_flush);
	png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
	             PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
	png_set_gAMA(png, info, file_gamma);
	png_write_info(png, info);
	for (int y = 0; y < h; y++) png_write_row(png, (png_const_bytep)(rgb + (size_t)y * (size_t)w * 3));
	png_write_end(png, info);
	png_destroy_write_struct(&png, &info);
	if (o.bad) { free(o.d); return NULL; }
	*len = o.n;
	return o.d;
}

size_t test_tetra_stl(uint8_t *out, const float p[4][3])
{
	static const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
	memset(out, 0, 84);
	memcpy(out, "binary tetrahedron", 18);
	test_put32(out + 80, 4);
	uint8_t *q = out + 84;
	for (int i = 0; i < 4; i++, q += 50) {
		float rec[12] = {0};
		for (int k = 0; k < 3; k++) memcpy(rec + 3 + 3 * k, p[f[i][k]], sizeof p[0]);
		memcpy(q, rec, sizeof rec); /* normal 0: recomputed by the importer */
		q[48] = q[49] = 0;
	}
	return 84 + 4 * 50;
}

uint8_t *test_glb_pack(const char *json, size_t jn, const uint8_t *bin, size_t binlen, size_t binpad, size_t *len)
{
	size_t jpad = (jn + 3) & ~(size_t)3;
	size_t total = 12 + 8 + jpad + 8 + binpad;
	uint8_t *g = calloc(1, total);
	if (!g) return NULL;
	memcpy(g, "glTF", 4);
	test_put32(g + 4, 2);
	test_put32(g + 8, (uint32_t)total);
	test_put32(g + 12, (uint32_t)jpad);
	memcpy(g + 16, "JSON", 4);
	memset(g + 20, ' ', jpad);
	memcpy(g + 20, json, jn);
	uint8_t *b = g + 20 + jpad;
	test_put32(b, (uint32_t)binpad);
	memcpy(b + 4, "BIN\0", 4);
	memcpy(b + 8, bin, binlen);
	*len = total;
	return g;
}

uint8_t *test_bumpy_stl(int seg, size_t *len)
{
	uint32_t n = 2u * (uint32_t)seg * (uint32_t)seg;
	uint8_t *d = calloc(1, 84 + 50 * (size_t)n);
	if (!d) return NULL;
	memcpy(d, "solid but binary", 16);
	memcpy(d + 80, &n, 4);
	uint32_t t = 0;
	for (int i = 0; i < seg; i++)
		for (int j = 0; j < seg; j++) {
			float q[4][3];
			for (int c = 0; c < 4; c++) {
				double th = 3.14159265358979 * (i + (c >> 1)) / seg, ph = 6.28318530717959 * (j + (c & 1)) / seg;
				double r = 1.0 + 0.05 * sin(5 * th) * cos(3 * ph) + (ph > 3.0 && ph < 6.0 ? 0.1 : 0.0);
				q[c][0] = (float)(r * sin(th) * cos(ph)); q[c][1] = (float)(r * cos(th)); q[c][2] = (float)(r * sin(th) * sin(ph));
			}
			static const int tri[2][3] = {{0, 1, 2}, {1, 3, 2}};   /* wound outward */
			for (int k = 0; k < 2; k++, t++)
				for (int c = 0; c < 3; c++) memcpy(d + 84 + 50 * (size_t)t + 12 + 12 * c, q[tri[k][c]], 12);
		}
	*len = 84 + 50 * (size_t)n;
	return d;
}


uint8_t *test_glb_mesh(const struct test_glb_mesh *in, size_t *len)
{
	size_t off_pos = 0, n_pos = (size_t)in->nv * 12;
	size_t off_nrm = off_pos + n_pos, n_nrm = in->nrm ? (size_t)in->nv * 12 : 0;
	size_t off_uv = off_nrm + n_nrm, n_uv = in->uv ? (size_t)in->nv * 8 : 0;
	size_t off_idx = off_uv + n_uv, n_idx = (size_t)in->ni * 4;
	size_t off_png = off_idx + n_idx, n_png = in->png ? in->png_len : 0;
	size_t binlen = off_png + n_png, binpad = (binlen + 3) & ~(size_t)3;
	float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
	for (uint32_t v = 0; v < in->nv; v++)
		for (int k = 0; k < 3; k++) {
			lo[k] = fminf(lo[k], in->pos[3 * v + k]);
			hi[k] = fmaxf(hi[k], in->pos[3 * v + k]);
		}

	/* bufferViews / accessors in order: pos, [nrm], [uv], idx, [png view] */
	char views[1024], accs[1024], attrs[256], mat[512] = "", imgs[256] = "";
	int nview = 0, nacc = 0;
	int vl = 0, al = 0, tl = 0;
	vl += snprintf(views + vl, sizeof views - vl, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", off_pos, n_pos);
	al += snprintf(accs + al, sizeof accs - al,
	               "{\"bufferView\":%d,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\","
	               "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]}",
	               nview++, in->nv, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
	tl += snprintf(attrs + tl, sizeof attrs - tl, "\"POSITION\":%d", nacc++);
	if (in->nrm) {
		vl += snprintf(views + vl, sizeof views - vl, ",{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", off_nrm, n_nrm);
		al += snprintf(accs + al, sizeof accs - al,
		               ",{\"bufferView\":%d,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"}", nview++, in->nv);
		tl += snprintf(attrs + tl, sizeof attrs - tl, ",\"NORMAL\":%d", nacc++);
	}
	if (in->uv) {
		vl += snprintf(views + vl, sizeof views - vl, ",{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", off_uv, n_uv);
		al += snprintf(accs + al, sizeof accs - al,
		               ",{\"bufferView\":%d,\"componentType\":5126,\"count\":%u,\"type\":\"VEC2\"}", nview++, in->nv);
		tl += snprintf(attrs + tl, sizeof attrs - tl, ",\"TEXCOORD_0\":%d", nacc++);
	}
	vl += snprintf(views + vl, sizeof views - vl, ",{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", off_idx, n_idx);
	al += snprintf(accs + al, sizeof accs - al,
	               ",{\"bufferView\":%d,\"componentType\":5125,\"count\":%u,\"type\":\"SCALAR\"}", nview++, in->ni);
	int idx_acc = nacc++;
	if (in->png) {
		vl += snprintf(views + vl, sizeof views - vl, ",{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", off_png, n_png);
		snprintf(imgs, sizeof imgs,
		         ",\"textures\":[{\"source\":0}],\"images\":[{\"bufferView\":%d,\"mimeType\":\"image/png\"}]", nview++);
		snprintf(mat, sizeof mat,
		         ",\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],\"metallicFactor\":0,"
		         "\"roughnessFactor\":0.8,\"baseColorTexture\":{\"index\":0}},\"alphaMode\":\"%s\"%s}]",
		         in->mask ? "MASK" : "OPAQUE", in->mask ? ",\"alphaCutoff\":0.5" : "");
	}
	char json[4096];
	int jn = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
		"\"nodes\":[{\"mesh\":0,\"translation\":[%.9g,%.9g,%.9g]}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{%s},\"indices\":%d%s}]}]%s%s,"
		"\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[%s],\"accessors\":[%s]}",
		in->node_t[0], in->node_t[1], in->node_t[2], attrs, idx_acc, in->png ? ",\"material\":0" : "", mat, imgs,
		binpad, views, accs);
	uint8_t *b = calloc(1, binpad ? binpad : 1);
	if (!b) return NULL;
	memcpy(b + off_pos, in->pos, n_pos);
	if (in->nrm) memcpy(b + off_nrm, in->nrm, n_nrm);
	if (in->uv) memcpy(b + off_uv, in->uv, n_uv);
	memcpy(b + off_idx, in->idx, n_idx);
	if (in->png) memcpy(b + off_png, in->png, n_png);
	uint8_t *g = test_glb_pack(json, (size_t)jn, b, binpad, binpad, len);
	free(b);
	return g;
}

uint8_t *test_draco_glb(const struct test_draco_mesh *m, size_t *len)
{
	struct test_draco_attr at[3] = {{TEST_DRACO_POSITION, TEST_DRACO_FLOAT32, 3, m->pos, 0}};
	int na = 1;
	if (m->nrm) at[na++] = (struct test_draco_attr){TEST_DRACO_NORMAL, TEST_DRACO_FLOAT32, 3, m->nrm, 0};
	if (m->uv) at[na++] = (struct test_draco_attr){TEST_DRACO_TEX_COORD, TEST_DRACO_FLOAT32, 2, m->uv, 0};
	size_t n;
	uint32_t np, nf;
	uint8_t *drc = test_draco_encode(at, na, m->nv, m->idx, m->ntri, m->edgebreaker, m->position_bits, &n, &np, &nf);
	if (!drc) return NULL;
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (uint32_t v = 0; v < m->nv; v++)
		for (int k = 0; k < 3; k++) lo[k] = fminf(lo[k], m->pos[3 * v + k]), hi[k] = fmaxf(hi[k], m->pos[3 * v + k]);
	char attrs[160], ids[160], accs[640];
	int al = snprintf(attrs, sizeof attrs, "\"POSITION\":1"), il = snprintf(ids, sizeof ids, "\"POSITION\":%u", at[0].unique_id);
	int cl = snprintf(accs, sizeof accs, "{\"componentType\":%d,\"count\":%u,\"type\":\"SCALAR\"},"
	                  "{\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\",\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]}",
	                  m->short_indices ? 5123 : 5125, 3 * nf, np, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
	static const char *const names[3] = {"POSITION", "NORMAL", "TEXCOORD_0"};
	for (int a = 1; a < na; a++) {
		const char *nm = names[at[a].type == TEST_DRACO_NORMAL ? 1 : 2];
		al += snprintf(attrs + al, sizeof attrs - (size_t)al, ",\"%s\":%d", nm, a + 1);
		il += snprintf(ids + il, sizeof ids - (size_t)il, ",\"%s\":%u", nm, at[a].unique_id);
		cl += snprintf(accs + cl, sizeof accs - (size_t)cl, ",{\"componentType\":5126,\"count\":%u,\"type\":\"VEC%d\"}", np,
		               at[a].comps);
	}
	char json[2048];
	size_t pad = (n + 3) & ~(size_t)3;
	int jn = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
		"\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
		"\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{%s},\"indices\":0,\"extensions\":"
		"{\"KHR_draco_mesh_compression\":{\"bufferView\":0,\"attributes\":{%s}}}}]}],\"accessors\":[%s],"
		"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu}],\"buffers\":[{\"byteLength\":%zu}]}",
		attrs, ids, accs, n, pad);
	uint8_t *bin = calloc(1, pad ? pad : 4);
	uint8_t *g = bin ? test_glb_pack(json, (size_t)jn, (memcpy(bin, drc, n), bin), pad, pad, len) : NULL;
	free(bin);
	free(drc);
	return g;
}
