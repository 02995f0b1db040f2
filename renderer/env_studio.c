/*
 * renderer/env_studio.c — the built-in studio environment (rnd_environment source STUDIO): a
 * neutral photo studio generated here, no third-party image. A grey dome brighter towards the
 * zenith, a darker floor, and four soft-edged softboxes: a small bright key high on the left of
 * the thumbnail preset's camera (which looks along (-1, -0.7, -1.3)), so that the model's
 * shadow falls where that camera sees it, a fill low on its right, a rim behind the model and a
 * strip overhead. White everywhere (no tint), so a model's colours stay its own; the softboxes
 * give metals and glossy surfaces something to reflect.
 *
 * Irradiance of an upward-facing surface: about pi (a white Lambert surface's radiance about 1
 * at intensity 1). Pure; tests/unit/test_env.c.
 */
#include <math.h>
#include "env.h"

#define PI_F 3.14159265358979f

struct softbox {
	float az, el;        /* degrees: azimuth atan2(z, x), elevation */
	float half_w, half_h;/* degrees, in the box's own frame */
	float radiance;
};

static const struct softbox BOXES[] = {
	{100.0f, 48.0f, 7.0f, 5.0f, 80.0f},    /* key: high on the left of the thumbnail camera (azimuth 52) */
	{-10.0f, 14.0f, 16.0f, 10.0f, 1.2f},   /* fill: low, on the camera's right */
	{-128.0f, 32.0f, 14.0f, 12.0f, 2.0f},  /* rim: behind the model */
	{0.0f, 90.0f, 40.0f, 9.0f, 1.0f},      /* strip overhead, along x */
};

static void dir_of(float az, float el, float d[3])
{
	float a = az * PI_F / 180.0f, e = el * PI_F / 180.0f;
	d[0] = cosf(e) * cosf(a);
	d[1] = sinf(e);
	d[2] = cosf(e) * sinf(a);
}

static float smooth_edge(float v, float edge, float soft)
{
	float t = (edge + soft - v) / (2.0f * soft);
	t = t < 0 ? 0 : t > 1 ? 1 : t;
	return t * t * (3.0f - 2.0f * t);
}

/* The box's contribution in direction d: its radiance inside, fading over 2 degrees at its edges. */
static float softbox(const struct softbox *b, const float d[3])
{
	float c[3], t1[3], t2[3];
	dir_of(b->az, b->el, c);
	/* a frame around c: t1 horizontal, t2 up the box */
	float h = sqrtf(c[0] * c[0] + c[2] * c[2]);
	if (h > 1e-4f) {
		t1[0] = -c[2] / h; t1[1] = 0; t1[2] = c[0] / h;
	} else {
		t1[0] = 1; t1[1] = 0; t1[2] = 0;
	}
	t2[0] = c[1] * t1[2] - c[2] * t1[1];
	t2[1] = c[2] * t1[0] - c[0] * t1[2];
	t2[2] = c[0] * t1[1] - c[1] * t1[0];
	float dc = d[0] * c[0] + d[1] * c[1] + d[2] * c[2];
	if (dc <= 0.05f) return 0.0f;
	float x = atan2f(d[0] * t1[0] + d[1] * t1[1] + d[2] * t1[2], dc) * 180.0f / PI_F;
	float y = atan2f(d[0] * t2[0] + d[1] * t2[1] + d[2] * t2[2], dc) * 180.0f / PI_F;
	return b->radiance * smooth_edge(fabsf(x), b->half_w, 2.0f) * smooth_edge(fabsf(y), b->half_h, 2.0f);
}

/* Radiance of the studio in direction d (unit, the map's frame). */
static float studio_radiance(const float d[3])
{
	float v;
	if (d[1] >= 0.0f) {
		v = 0.13f + 0.08f * d[1];                            /* dome: brighter towards the zenith */
		v += 0.06f * expf(-d[1] * 14.0f);                    /* the cyclorama's bright horizon */
	} else {
		v = 0.10f + 0.05f * expf(d[1] * 8.0f);               /* floor, darker away from the horizon */
	}
	for (unsigned i = 0; i < sizeof BOXES / sizeof BOXES[0]; i++) v += softbox(&BOXES[i], d);
	return v;
}

void rnd_env_studio(float *rgb, uint32_t w, uint32_t h)
{
	for (uint32_t y = 0; y < h; y++) {
		float el = (0.5f - ((float)y + 0.5f) / (float)h) * PI_F;
		for (uint32_t x = 0; x < w; x++) {
			float phi = (((float)x + 0.5f) / (float)w - 0.5f) * 2.0f * PI_F;
			float d[3] = {cosf(el) * cosf(phi), sinf(el), cosf(el) * sinf(phi)};
			float v = studio_radiance(d);
			float *o = rgb + ((size_t)y * w + x) * 3;
			o[0] = o[1] = o[2] = v;
		}
	}
}
