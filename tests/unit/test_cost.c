/* tests/unit — fragments a draw may cover in a view (renderer/cost.c), the term of the submit
 * pacer's cost model that sees geometry stacked many layers deep. Expected values worked out
 * by hand from the matrices below. */
#include <math.h>
#include <string.h>
#include "cost.h"
#include "test.h"

/* Orthographic: world x, y in [-h, h] onto clip [-1, 1]; depth along -z, w = 1. */
static void ortho(float m[16], float h)
{
	memset(m, 0, 16 * sizeof *m);
	m[0] = 1.0f / h;
	m[5] = 1.0f / h;
	m[10] = -0.01f;
	m[14] = 0.5f;
	m[15] = 1.0f;
}

/* Perspective looking down -z, 90 degrees each way: clip x = x / -z, w = -z. */
static void persp(float m[16])
{
	memset(m, 0, 16 * sizeof *m);
	m[0] = 1.0f;
	m[5] = 1.0f;
	m[10] = 0.0f;
	m[11] = -1.0f;
	m[14] = 0.1f;
}

TEST(cost_fill_orthographic_is_area_in_pixels)
{
	float m[16];
	ortho(m, 2.0f);   /* 4 world units over 100 pixels: 25 px per unit, 625 px per unit^2 */
	struct rnd_aabb b = {{-1, -1, -1}, {1, 1, -0.5f}};
	double f = rnd_cost_fill(m, 100, 100, &b, 4.0, 2, false);
	CHECK(fabs(f - 2500.0) < 1e-6, "a 2 x 2 quad: %.3f px, want 2500", f);
	/* 1,000 such quads stacked: a thousand times the fill, up to every triangle over the box */
	f = rnd_cost_fill(m, 100, 100, &b, 4000.0, 2000, false);
	CHECK(fabs(f - 2.5e6) < 1e-3, "stacked: %.1f px, want 2.5e6", f);
	/* ... and a box's triangles cannot cover more than their count times its outline */
	f = rnd_cost_fill(m, 100, 100, &b, 4000.0, 2, false);
	CHECK(fabs(f - 2.0 * 2500) < 1e-6, "two triangles over a 2500 px outline: %.1f, want 5000", f);
	/* closed: its outline twice over at most */
	f = rnd_cost_fill(m, 100, 100, &b, 4000.0, 2000, true);
	CHECK(fabs(f - 2.0 * 2500) < 1e-6, "a closed surface: %.1f, want 5000", f);
	/* clipped to the view */
	struct rnd_aabb half = {{1, -1, -1}, {3, 1, -0.5f}};
	f = rnd_cost_fill(m, 100, 100, &half, 4000.0, 2000, false);
	CHECK(fabs(f - 2000 * 1250.0) < 1e-3, "half outside: %.1f, want %.1f", f, 2000 * 1250.0);
	struct rnd_aabb away = {{5, 5, -1}, {6, 6, -0.5f}};
	CHECK(rnd_cost_fill(m, 100, 100, &away, 1.0, 2, false) == 0.0, "a box outside the view covers nothing");
	CHECK(rnd_cost_fill(m, 100, 100, &b, 4.0, 0, false) == 0.0, "no triangles, no fill");
}

TEST(cost_fill_perspective_scales_with_depth)
{
	float m[16];
	persp(m);
	/* a 0.2 x 0.2 square 1 unit away fills 0.04 clip^2 = 1% of 4 clip^2: 100 of 10,000 px */
	struct rnd_aabb near = {{-0.1f, -0.1f, -1.0f}, {0.1f, 0.1f, -1.0f}};
	double f = rnd_cost_fill(m, 100, 100, &near, 0.04, 2, false);
	CHECK(fabs(f - 100.0) < 0.01, "at depth 1: %.3f px, want 100", f);
	struct rnd_aabb far = {{-0.2f, -0.2f, -2.0f}, {0.2f, 0.2f, -2.0f}};
	f = rnd_cost_fill(m, 100, 100, &far, 0.16, 2, false);
	CHECK(fabs(f - 100.0) < 0.01, "twice the size at depth 2: %.3f px, want 100", f);
	/* a box from beside the eye to the back: its whole outline per triangle at most */
	struct rnd_aabb behind = {{-1, -1, -3}, {1, 1, 1}};
	f = rnd_cost_fill(m, 100, 100, &behind, 1.0, 4, false);
	CHECK(fabs(f - 4 * 10000.0) < 1e-6, "reaching behind the eye: %.1f, want 40000", f);
}

TEST(cost_layer_factor_leaves_ordinary_scenes_alone)
{
	CHECK(rnd_cost_layer_factor(3.3 * 256 * 256, 256, 256) == 1.0, "a thumbnail's 3.3 layers");
	double k = rnd_cost_layer_factor(800.0 * 100 * 100, 100, 100);
	CHECK(fabs(k - 800.0 / RND_COST_LAYERS_CALIBRATED) < 1e-9, "800 layers: factor %.2f", k);
	CHECK(rnd_cost_layer_factor(1.0, 0, 0) == 1.0, "an empty view");
}
