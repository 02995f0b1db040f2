/* tests/gpu — Draco-compressed models (contract §2 `model`, KHR_draco_mesh_compression): the
 * same picture as the plain glb. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <png.h>
#include "gpu_util.h"
#include "models.h"
#include "test.h"
#include "util.h"

/* KHR_draco_mesh_compression (api/gltf_draco.c): a uv sphere as a plain glb and as a Draco one
 * (libdraco's encoder, tests/util/draco_encode.h) under the thumbnail preset. Sequential
 * encoding without quantization keeps every float and the vertex order: the same picture to
 * the byte. Edgebreaker with 11-bit positions (reordered, moved up to 1/4096 of the size):
 * within a few steps on the outline. Before, a file requiring Draco was a 400. */
#define SPH_U 32
#define SPH_V 16
static void draco_sphere(float *pos, float *nrm, float *uv, uint32_t *idx)
{
	for (int v = 0; v <= SPH_V; v++)
		for (int u = 0; u <= SPH_U; u++) {
			int i = v * (SPH_U + 1) + u;
			double th = M_PI * v / SPH_V, ph = 2 * M_PI * u / SPH_U;
			float n[3] = {(float)(sin(th) * cos(ph)), (float)cos(th), (float)(sin(th) * sin(ph))};
			memcpy(nrm + 3 * i, n, sizeof n);
			memcpy(pos + 3 * i, n, sizeof n);
			uv[2 * i] = (float)u / SPH_U, uv[2 * i + 1] = (float)v / SPH_V;
		}
	int t = 0;
	for (int v = 0; v < SPH_V; v++)
		for (int u = 0; u < SPH_U; u++) {
			uint32_t a = (uint32_t)(v * (SPH_U + 1) + u), b = a + 1, c = a + SPH_U + 1, d = c + 1;
			uint32_t q[6] = {a, b, d, a, d, c};
			memcpy(idx + 6 * t++, q, sizeof q);
		}
}

static bool render_glb(int line, struct rnd_image *img, const uint8_t *glb, size_t n)
{
	char *enc = test_b64(glb, n);
	bool ok = enc && gpu_render_at(__FILE__, line, img, "{'preset':'thumbnail','width':192,'height':192,'objects':["
	                               "{'shape':'model','data':'%s','material':{'base_color':[0.8,0.3,0.1]}}]}", enc);
	free(enc);
	return ok;
}

TEST(models_draco_sphere_same_picture)
{
	enum { NV = (SPH_U + 1) * (SPH_V + 1), NT = 2 * SPH_U * SPH_V };
	static float pos[3 * NV], nrm[3 * NV], uv[2 * NV];
	static uint32_t idx[3 * NT];
	draco_sphere(pos, nrm, uv, idx);
	struct test_glb_mesh plain = {.pos = pos, .nrm = nrm, .uv = uv, .nv = NV, .idx = idx, .ni = 3 * NT};
	struct test_draco_mesh seq = {.pos = pos, .nrm = nrm, .uv = uv, .nv = NV, .idx = idx, .ntri = NT};
	struct test_draco_mesh eb = seq;
	eb.edgebreaker = 1, eb.position_bits = 11;
	size_t n[3];
	uint8_t *g[3] = {test_glb_mesh(&plain, &n[0]), test_draco_glb(&seq, &n[1]), test_draco_glb(&eb, &n[2])};
	struct rnd_image img[3] = {{0}};
	bool ok = g[0] && g[1] && g[2];
	for (int k = 0; ok && k < 3; k++) ok = render_glb(__LINE__, &img[k], g[k], n[k]);
	for (int k = 0; k < 3; k++) free(g[k]);
	REQUIRE(ok, "the glbs were not built or rendered");
	long same = gpu_bytes_differ(&img[0], &img[1], NULL);
	int lit = 0, worst = 0, changed = 0;
	for (int j = 0; j < 192; j++)
		for (int i = 0; i < 192; i++) {
			const uint8_t *a = gpu_px8(&img[0], i, j), *b = gpu_px8(&img[2], i, j);
			lit += a[0] > a[2] + 60;   /* the orange sphere */
			int d = 0;
			for (int c = 0; c < 3; c++) d = abs(a[c] - b[c]) > d ? abs(a[c] - b[c]) : d;
			worst = d > worst ? d : worst;
			changed += d > 4;
		}
	printf("  draco sphere: %d sphere pixels; sequential %ld bytes differ; edgebreaker 11-bit: %d pixels > 4 steps "
	       "(largest %d)\n", lit, same, changed, worst);
	CHECK(lit > 4000, "the sphere covers %d pixels", lit);
	CHECK(same == 0, "sequential Draco: %ld bytes differ from the plain glb", same);
	CHECK(changed < 150, "edgebreaker Draco: %d pixels differ by more than 4 steps", changed);
	for (int k = 0; k < 3; k++) rnd_image_release(&img[k]);
}
