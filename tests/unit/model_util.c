/* tests/unit/model_util.c — models the model tests build (model_util.h): a glb quad with an
 * embedded PNG. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "models.h"
#include "util.h"
#include "model_util.h"

const uint8_t TEX[16] = {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0, 255, 255, 255, 255};

uint8_t *png_2x2(size_t *len)
{
	return test_png_rgba(TEX, 2, 2, len);
}

uint8_t *quad_glb_ex(const char *tex_extra, const char *root_extra, size_t *len)
{
	size_t pnglen;
	uint8_t *png = png_2x2(&pnglen);
	return png ? quad_glb_png(png, pnglen, tex_extra, root_extra, len) : NULL;
}

/* The same with `png` (taken: freed here) as its texture. */
uint8_t *quad_glb_png(uint8_t *png, size_t pnglen, const char *tex_extra, const char *root_extra, size_t *len)
{
	static const float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
	static const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
	static const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
	static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
	size_t binlen = 152 + pnglen, binpad = (binlen + 3) & ~(size_t)3;
	char json[2048];
	int jn = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
		"\"nodes\":[{\"mesh\":0,\"translation\":[0,2,0]}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},"
		"\"indices\":3,\"material\":0}]}],"
		"\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,1,1],\"metallicFactor\":0.3,"
		"\"roughnessFactor\":0.7,\"baseColorTexture\":{\"index\":0%s}},\"alphaMode\":\"MASK\",\"alphaCutoff\":0.4}],"
		"\"textures\":[{\"source\":0}],\"images\":[{\"bufferView\":4,\"mimeType\":\"image/png\"}]%s,"
		"\"buffers\":[{\"byteLength\":%zu}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
		"{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":32},"
		"{\"buffer\":0,\"byteOffset\":128,\"byteLength\":24},{\"buffer\":0,\"byteOffset\":152,\"byteLength\":%zu}],"
		"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
		"\"min\":[-1,-1,0],\"max\":[1,1,0]},"
		"{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
		"{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
		"{\"bufferView\":3,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"}]}",
		tex_extra, root_extra, binpad, pnglen);
	uint8_t *b = calloc(1, binpad);
	if (!b) { free(png); return NULL; }
	memcpy(b, pos, 48);
	memcpy(b + 48, nrm, 48);
	memcpy(b + 96, uv, 32);
	memcpy(b + 128, idx, 24);
	memcpy(b + 152, png, pnglen);
	free(png);
	uint8_t *g = test_glb_pack(json, (size_t)jn, b, binpad, binpad, len);
	free(b);
	return g;
}

uint8_t *quad_glb(size_t *len)
{
	return quad_glb_ex("", "", len);
}

struct api_model *model_get_for(const uint8_t *d, size_t len, enum api_model_format format, uint32_t side,
                                uint32_t timeout_ms)
{
	struct api_limits l;
	api_limits_defaults(&l);
	l.output_side = side;
	if (timeout_ms) l.import_timeout_ms = timeout_ms;
	struct api_model *m = NULL;
	char err[300];
	int st;
	if (api_model_get(d, len, format, &l, &m, &st, err, sizeof err) != API_OK) printf("    %s\n", err);
	return m;
}
