/*
 * tests/unit/thumb_scene.h — thumb-512 (../shared/bench/thumb-512.json) built in C for the unit
 * tests of the renderer's planning (test_lod.c, test_proxy.c): a 10 m plane, a 316-segment unit
 * sphere at (0, 1, 0), a sun along (-0.5, -1, -0.3), a 40-degree camera at (4, 3, 4) looking at
 * (0, 0.8, 0), size x size pixels. The scene points into the caller's obj and sun.
 */
#ifndef UMBRA_TEST_THUMB_SCENE_H
#define UMBRA_TEST_THUMB_SCENE_H

#include <string.h>
#include "umbra/rnd.h"

static inline void thumb_scene(struct rnd_scene *sc, struct rnd_object obj[2], struct rnd_light *sun, uint32_t size)
{
	rnd_scene_defaults(sc);
	sc->width = sc->height = size;
	float pos[3] = {4, 3, 4}, tgt[3] = {0, 0.8f, 0};
	memcpy(sc->camera.position, pos, sizeof pos);
	memcpy(sc->camera.target, tgt, sizeof tgt);
	sc->camera.fov_y = (float)(40 * 3.14159265358979323846 / 180);
	rnd_object_defaults(&obj[0]);
	obj[0].shape = RND_SHAPE_PLANE;
	obj[0].size[0] = obj[0].size[2] = 10;
	rnd_object_defaults(&obj[1]);
	obj[1].shape = RND_SHAPE_SPHERE;
	obj[1].radius = 1;
	obj[1].segments = 316;
	obj[1].model[13] = 1;
	rnd_light_defaults(sun, RND_LIGHT_DIRECTIONAL);
	float d[3] = {-0.5f, -1, -0.3f};
	memcpy(sun->direction, d, sizeof d);
	sc->objects = obj;
	sc->object_count = 2;
	sc->lights = sun;
	sc->light_count = 1;
}

#endif
