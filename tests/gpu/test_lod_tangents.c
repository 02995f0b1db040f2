/* tests/gpu — a normal-mapped model (glTF TANGENT and a normalTexture) gets its level of detail
 * and draws it with the level's tangents (api/model_lod.c carries them, renderer/lod.c draws a
 * level only with them): a dense unit sphere with a uniform normal map that tilts every normal
 * 45 degrees towards its tangent, drawn with its level and in full, looks the same. Before,
 * a mesh with tangents never had a level: it drew every triangle into every thumbnail. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "api.h"
#include "gpu_util.h"
#include "material_quad.h"
#include "test.h"

enum { SEG = 150 };   /* 150 x 150 quads: 45,000 triangles, over the levels' 20,000 */

/* The sphere's arrays: positions, normals, uvs, tangents (towards increasing longitude, w 1),
 * and indices; *nv vertices (a seam column repeated, poles' rows whole), *ni indices. */
static void sphere_arrays(float **pos, float **nrm, float **uv, float **tan, uint32_t **idx, uint32_t *nv, uint32_t *ni)
{
	*nv = (SEG + 1) * (SEG + 1);
	*ni = 6 * SEG * SEG;
	*pos = malloc(*nv * 12), *nrm = malloc(*nv * 12), *uv = malloc(*nv * 8), *tan = malloc(*nv * 16);
	*idx = malloc(*ni * 4);
	if (!*pos || !*nrm || !*uv || !*tan || !*idx) return;
	for (uint32_t i = 0; i <= SEG; i++)
		for (uint32_t j = 0; j <= SEG; j++) {
			uint32_t v = i * (SEG + 1) + j;
			double th = GPU_PI * i / SEG, ph = 2 * GPU_PI * j / SEG;
			float p[3] = {(float)(sin(th) * cos(ph)), (float)cos(th), (float)(-sin(th) * sin(ph))};
			memcpy(*pos + 3 * v, p, 12);
			memcpy(*nrm + 3 * v, p, 12);
			(*uv)[2 * v] = (float)j / SEG, (*uv)[2 * v + 1] = (float)i / SEG;
			float t[4] = {(float)-sin(ph), 0.0f, (float)-cos(ph), 1.0f};
			memcpy(*tan + 4 * v, t, 16);
		}
	uint32_t k = 0;
	for (uint32_t i = 0; i < SEG; i++)
		for (uint32_t j = 0; j < SEG; j++) {
			uint32_t a = i * (SEG + 1) + j, b = a + 1, c = a + SEG + 1, d = c + 1;
			uint32_t t[6] = {a, c, b, b, c, d};
			memcpy(*idx + k, t, sizeof t);
			k += 6;
		}
}

/* The sphere as a .glb at path: the arrays above and the 1 x 1 normal map (218, 128, 218). */
static bool write_sphere_glb(const char *path)
{
	float *pos, *nrm, *uv, *tan;
	uint32_t *idx, nv, ni;
	sphere_arrays(&pos, &nrm, &uv, &tan, &idx, &nv, &ni);
	static const uint8_t texel[4] = {218, 128, 218, 255};
	struct mglb g = {0};
	add_png(&g, texel, 1, 1);
	const void *src[6] = {pos, nrm, uv, tan, idx, g.png[0]};
	size_t sz[6] = {nv * 12u, nv * 12u, nv * 8u, nv * 16u, ni * 4u, g.png_len[0]}, off[6], n = 0;
	char views[1024];
	int vl = 0;
	for (int i = 0; i < 6; i++) {
		off[i] = n;
		n += (sz[i] + 3) & ~(size_t)3;
		vl += snprintf(views + vl, sizeof views - (size_t)vl, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}",
		               i ? "," : "", off[i], sz[i]);
	}
	char json[4096];
	int jn = snprintf(json, sizeof json,
		"{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2,\"TANGENT\":3},"
		"\"indices\":4,\"material\":0}]}],"
		"\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1],\"metallicFactor\":0,"
		"\"roughnessFactor\":1},\"normalTexture\":{\"index\":0}}],"
		"\"textures\":[{\"source\":0,\"sampler\":0}],\"samplers\":" NEAREST_CLAMP ","
		"\"images\":[{\"bufferView\":5,\"mimeType\":\"image/png\"}],"
		"\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[%s],\"accessors\":["
		"{\"bufferView\":0,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\",\"min\":[-1,-1,-1],\"max\":[1,1,1]},"
		"{\"bufferView\":1,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"},"
		"{\"bufferView\":2,\"componentType\":5126,\"count\":%u,\"type\":\"VEC2\"},"
		"{\"bufferView\":3,\"componentType\":5126,\"count\":%u,\"type\":\"VEC4\"},"
		"{\"bufferView\":4,\"componentType\":5125,\"count\":%u,\"type\":\"SCALAR\"}]}",
		n, views, nv, nv, nv, nv, ni);
	while (jn % 4) json[jn++] = ' ';
	uint8_t *bin = calloc(1, n);
	FILE *f = bin ? fopen(path, "wb") : NULL;
	bool ok = f != NULL;
	for (int i = 0; ok && i < 6; i++) memcpy(bin + off[i], src[i], sz[i]);
	uint32_t head[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + jn + 8 + n), (uint32_t)jn, 0x4E4F534Au};
	uint32_t bhead[2] = {(uint32_t)n, 0x004E4942u};
	ok = ok && fwrite(head, 4, 5, f) == 5 && fwrite(json, 1, (size_t)jn, f) == (size_t)jn && fwrite(bhead, 4, 2, f) == 2 &&
	     fwrite(bin, 1, n, f) == n;
	if (f) ok = fclose(f) == 0 && ok;
	free(bin);
	free_pngs(&g);
	free(pos), free(nrm), free(uv), free(tan), free(idx);
	return ok;
}

static const char *const DOC =
	"{\"width\": 256, \"height\": 256, \"camera\": {\"type\": \"perspective\", \"position\": [0, 0.5, 3.2],"
	" \"target\": [0, 0, 0], \"fov_y\": 45},"
	" \"environment\": {\"background\": [0, 0, 0]},"
	" \"objects\": [{\"shape\": \"model\", \"path\": \"nmap.glb\"}],"
	" \"lights\": [{\"type\": \"directional\", \"direction\": [0, -0.4, -1], \"intensity\": 3}],"
	" \"output\": {\"tonemap\": \"none\"}}";

/* Renders DOC from the model in root, with its level or in full (exact); *levels: the
 * model's levels at this size. */
static bool render_sphere(struct rnd_image *img, const char *root, bool exact, uint32_t *levels)
{
	memset(img, 0, sizeof *img);
	if (!gpu_ctx()) { CHECK(0, "no context"); return false; }
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = root;
	struct api_scene *s = NULL;
	struct api_problem p;
	if (api_scene_parse(DOC, strlen(DOC), &lim, &s, &p) != API_OK) {
		CHECK(0, "parse: %s %s", p.pointer, p.detail);
		return false;
	}
	*levels = s->scene.object_count == 1 && s->scene.objects[0].tangents ? s->scene.objects[0].lod_count : 0;
	s->scene.exact_segments = exact;
	struct rnd_timings t;
	struct rnd_error err = {0};
	uint32_t before = rnd_context_validation_messages(gpu_ctx());
	enum rnd_result r = rnd_render(gpu_ctx(), &s->scene, img, &t, &err);
	api_scene_free(s);
	CHECK(rnd_context_validation_messages(gpu_ctx()) == before, "validation messages");
	CHECK(r == RND_OK, "render: %s", err.msg);
	return r == RND_OK;
}

/* The level (~1/30 of the triangles at 256²) and the full sphere: the normal map's shading
 * the same (its tilt shows: the sphere's left and right halves, lit alike without it, differ),
 * within what the level's half-pixel outline and interpolated normals move. */
TEST(lod_normal_mapped_model_draws_its_level_with_tangents)
{
	char dir[] = "/tmp/umbra-lodtan-XXXXXX", path[64];
	REQUIRE(mkdtemp(dir) != NULL, "mkdtemp");
	snprintf(path, sizeof path, "%s/nmap.glb", dir);
	REQUIRE(write_sphere_glb(path), "writing %s", path);
	struct rnd_image lod, full;
	uint32_t levels = 0, full_levels = 0;
	bool ok = render_sphere(&lod, dir, false, &levels);
	if (ok && !render_sphere(&full, dir, true, &full_levels)) { rnd_image_release(&lod); ok = false; }
	remove(path);
	rmdir(dir);
	if (!ok) return;
	CHECK(levels == 1, "the normal-mapped sphere has %u levels at 256", levels);
	double sum = 0, tilt = 0;
	int big = 0;
	for (uint32_t j = 0; j < lod.height; j++)
		for (uint32_t i = 0; i < lod.width; i++) {
			double d = 0;
			for (int c = 0; c < 3; c++) d = fmax(d, fabs(gpu_chan(&lod, (int)i, (int)j, c) - gpu_chan(&full, (int)i, (int)j, c)));
			sum += d;
			if (d > 0.25) big++;
		}
	/* the tilt: mirror pixels about the centre column, on the sphere's equator band */
	for (int i = 20; i < 60; i++) tilt += fabs(gpu_chan(&full, 128 - i, 128, 0) - gpu_chan(&full, 128 + i, 128, 0)) / 40;
	double mean = sum / ((double)lod.width * lod.height);
	printf("  normal-mapped level vs full: mean abs diff %.5f, %d pixels over 1/4; the tilt's left-right %.4f\n", mean,
	       big, tilt);
	CHECK(tilt > 0.02, "the normal map shows no tilt (%.4f)", tilt);
	CHECK(mean < 2.0 / 255.0, "mean difference %.5f", mean);
	CHECK(big <= 20, "%d pixels changed by more than a quarter", big);
	rnd_image_release(&lod);
	rnd_image_release(&full);
}
