/* tests/gpu — the environment's shadow maps' coarse caster level (renderer/caster_level.h):
 * a finely tessellated closed box (76,800 triangles) lit by an environment patch, its caster
 * level replaced by one whose error is known exactly: the box grown by e on every side (12
 * triangles; every point of either surface within e sqrt(3) of the other, at the corners).
 * The environment's maps draw the 12 triangles, and the level's bias keeps the lit faces as
 * lit as when the maps draw the full box; drawn without the bias (UMBRA_CASTER_BIAS=0), the
 * grown box stands e in front of every lit face and shadows it (self-shadow acne). The
 * reference is the same scene with the maps drawing the full mesh (UMBRA_CASTER_LEVEL=0). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "api.h"
#include "envmaps.h"
#include "gpu_util.h"
#include "models.h"
#include "test.h"
#include "util.h"

#define BOX_N 80          /* quads a side of each face: 6 x 80 x 80 x 2 = 76,800 triangles */
#define BOX_H 0.5f        /* half its side */
#define GROWN 0.012f      /* the caster level's growth: error 0.0208, within 4 texels of the maps */

/* Binary STL of the box [-h, h]^3 lifted by h (standing on y = 0), each face n x n quads
 * wound outward. */
static uint8_t *box_stl(int n, float h, size_t *len)
{
	uint32_t count = 12u * (uint32_t)n * (uint32_t)n, t = 0;
	uint8_t *d = calloc(1, 84 + 50 * (size_t)count);
	if (!d) return NULL;
	memcpy(d + 80, &count, 4);
	for (int f = 0; f < 6; f++) {
		int ax = f / 2, u = (ax + 1) % 3, v = (ax + 2) % 3;
		float sgn = f % 2 ? -1.0f : 1.0f;
		for (int i = 0; i < n; i++)
			for (int j = 0; j < n; j++) {
				float q[4][3];
				for (int c = 0; c < 4; c++) {
					q[c][ax] = sgn * h;
					q[c][u] = h * (2.0f * (float)(i + (c & 1)) / (float)n - 1.0f);
					q[c][v] = h * (2.0f * (float)(j + (c >> 1)) / (float)n - 1.0f);
					q[c][1] += h;
				}
				/* (u, v, ax) is right-handed: 0 1 3 faces +ax; the -ax face the other way */
				static const int pos[2][3] = {{0, 1, 3}, {0, 3, 2}}, neg[2][3] = {{0, 3, 1}, {0, 2, 3}};
				for (int k = 0; k < 2; k++, t++)
					for (int c = 0; c < 3; c++)
						memcpy(d + 84 + 50 * (size_t)t + 12 + 12 * c, q[(sgn > 0 ? pos : neg)[k][c]], 12);
			}
	}
	*len = 84 + 50 * (size_t)count;
	return d;
}

/* An asset root holding box.stl and patch.hdr (a 30-degree patch of 6 at azimuth 180 (the
 * map's -X), elevation 45, on 0.02). */
static const char *caster_root(void)
{
	static char root[64];
	if (root[0]) return root;
	snprintf(root, sizeof root, "/tmp/umbra_gpu_caster_XXXXXX");
	if (!mkdtemp(root)) return NULL;
	size_t n[2];
	float *map = test_patch_map(128, 64, 180, 45, 30, 6.0f, 0.02f);
	uint8_t *b[2] = {box_stl(BOX_N, BOX_H, &n[0]), test_hdr_bytes(map, 128, 64, true, &n[1])};
	const char *names[2] = {"box.stl", "patch.hdr"};
	for (int i = 0; i < 2; i++) {
		char p[128];
		snprintf(p, sizeof p, "%s/%s", root, names[i]);
		FILE *f = b[i] ? fopen(p, "wb") : NULL;
		if (f) {
			fwrite(b[i], 1, n[i], f);
			fclose(f);
		}
		free(b[i]);
	}
	free(map);
	return root;
}

/* The box grown by GROWN on every side, as a caster level: error GROWN sqrt(3) (its corners). */
static const float grown_pos[8 * 3] = {
#define G (BOX_H + GROWN)
	-G, BOX_H - G, -G, G, BOX_H - G, -G, -G, BOX_H + G, -G, G, BOX_H + G, -G,
	-G, BOX_H - G, G,  G, BOX_H - G, G,  -G, BOX_H + G, G,  G, BOX_H + G, G,
#undef G
};
static const uint32_t grown_idx[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                       2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};

/* The environment's visibility of each pixel (debug environment_shadow: 255 = unshadowed), the
 * box's caster level the grown box (levels, bias: UMBRA_CASTER_LEVEL / _BIAS, NULL unset). */
static bool render_vis(struct rnd_image *img, const char *levels, const char *bias, struct rnd_timings *t)
{
	static const char doc[] =
		"{\"width\": 96, \"height\": 96, \"camera\": {\"position\": [-2.2, 2.0, 1.3], \"target\": [0, 0.4, 0],"
		" \"fov_y\": 40}, \"environment\": {\"map\": \"patch.hdr\", \"shadow\": {\"directions\": 2}},"
		" \"objects\": [{\"shape\": \"model\", \"path\": \"box.stl\", \"format\": \"stl\"}],"
		" \"output\": {\"debug\": \"environment_shadow\", \"msaa\": 1}}";
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.asset_root = caster_root();
	struct api_scene *s = NULL;
	struct api_problem p;
	memset(img, 0, sizeof *img);
	if (!gpu_ctx() || api_scene_parse(doc, strlen(doc), &lim, &s, &p) != API_OK) {
		CHECK(0, "parse: %s %s", s ? "" : p.pointer, s ? "" : p.detail);
		return false;
	}
	if (s->scene.object_count != 1 || s->scene.objects[0].shape != RND_SHAPE_MESH) {
		CHECK(0, "one mesh: %u objects", s->scene.object_count);
		api_scene_free(s);
		return false;
	}
	static const struct rnd_caster_level grown = {grown_pos, grown_idx, 8, 36, GROWN * 1.7320508f};
	struct rnd_object *o = (struct rnd_object *)&s->scene.objects[0];
	o->caster = &grown;
	o->lods = NULL;   /* the camera draws the full box (a flat face's level would be 2 triangles) */
	o->lod_count = 0;
	if (levels) setenv("UMBRA_CASTER_LEVEL", levels, 1);
	if (bias) setenv("UMBRA_CASTER_BIAS", bias, 1);
	struct rnd_error err = {0};
	uint32_t before = rnd_context_validation_messages(gpu_ctx());
	enum rnd_result r = rnd_render(gpu_ctx(), &s->scene, img, t, &err);
	unsetenv("UMBRA_CASTER_LEVEL");
	unsetenv("UMBRA_CASTER_BIAS");
	api_scene_free(s);
	CHECK(rnd_context_validation_messages(gpu_ctx()) == before, "validation messages");
	CHECK(r == RND_OK, "render: %s", err.msg);
	return r == RND_OK;
}

/* Pixels of img at least 0.2 darker than the reference where the reference is lit (> 0.6). */
static int darker(const struct rnd_image *ref, const struct rnd_image *img, int *lit)
{
	int n = 0;
	*lit = 0;
	for (int j = 0; j < (int)ref->height; j++)
		for (int i = 0; i < (int)ref->width; i++) {
			double r = gpu_chan(ref, i, j, 0), v = gpu_chan(img, i, j, 0);
			if (r < 0.6) continue;
			(*lit)++;
			n += v < r - 0.2;
		}
	return n;
}

/* CASTER_DUMP=dir: the three images as PNGs there (for looking at them). */
static void dump(const char *name, const struct rnd_image *img)
{
	const char *dir = getenv("CASTER_DUMP");
	if (!dir || img->format != RND_PIXELS_RGBA8 || img->stride != img->width * 4) return;
	size_t len;
	uint8_t *png = test_png_rgba(img->pixels, (int)img->width, (int)img->height, &len);
	char path[512];
	snprintf(path, sizeof path, "%s/%s.png", dir, name);
	FILE *f = png ? fopen(path, "wb") : NULL;
	if (f) {
		fwrite(png, 1, len, f);
		fclose(f);
	}
	free(png);
}

TEST(env_maps_draw_the_caster_level_without_acne)
{
	struct rnd_image full = {0}, level = {0}, unbiased = {0};
	struct rnd_timings tf, tl, tu;
	bool ok = render_vis(&full, "0", NULL, &tf);
	ok = render_vis(&level, NULL, NULL, &tl) && ok;
	ok = render_vis(&unbiased, NULL, "0", &tu) && ok;
	if (ok) {
		int lit, acne_level = darker(&full, &level, &lit), acne_unbiased = darker(&full, &unbiased, &lit);
		printf("  shadow triangles: full %llu, caster level %llu; of %d lit pixels darker by 0.2: level %d, "
		       "level without its bias %d\n", (unsigned long long)tf.shadow_triangles,
		       (unsigned long long)tl.shadow_triangles, lit, acne_level, acne_unbiased);
		CHECK(tf.env_directions > 0 && tl.env_directions == tf.env_directions, "directions %u, %u", tf.env_directions,
		      tl.env_directions);
		CHECK(tl.shadow_triangles == 12ull * tl.env_directions, "the maps drew the caster level: %llu triangles",
		      (unsigned long long)tl.shadow_triangles);
		CHECK(lit > 500, "the reference lights the model's side: %d pixels", lit);
		CHECK(acne_level * 100 <= lit, "with its bias: %d of %d lit pixels shadowed", acne_level, lit);
		CHECK(acne_unbiased * 100 >= 3 * lit, "without its bias the level shadows the lit side (%d of %d pixels): "
		      "else this scene does not test the bias", acne_unbiased, lit);
		dump("caster_full", &full);
		dump("caster_level", &level);
		dump("caster_unbiased", &unbiased);
	}
	rnd_image_release(&full);
	rnd_image_release(&level);
	rnd_image_release(&unbiased);
}
