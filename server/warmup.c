/*
 * umbrad warm-up: one tiny render per common pipeline variant before /readyz says 200
 * (srv_warmup, called at start-up and after a lost device is recovered, from one thread; it
 * renders through srv_render() on the shared context, on as many threads as render slots).
 */
#include <malloc.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "srv.h"

/* lavapipe compiles each pipeline at its first use, and the renderer specialises the main
 * pipeline by MSAA, output (8-bit / linear), the set of light types, the set of shadow filters
 * and cascades. Render one tiny scene per common combination before /readyz says 200. The first
 * must succeed; the others only warn (a renderer without some feature still serves the rest).
 * Each variant lavapipe keeps costs ~14 MB of resident memory (its JIT's code and state), so by
 * default only the contract's defaults are warmed (MSAA 4, PNG: what a request that names no
 * output gets, and every bench scene; and the thumbnail preset, the farms' request); MSAA 1,
 * EXR and VSM/EVSM compile at first use, in 0.1-0.4 s on the 2-core machine (`--warm-up all`
 * warms them too). */
#define WARM_SCENE(lights, output) \
	"{\"width\":32,\"height\":32," \
	"\"camera\":{\"type\":\"perspective\",\"position\":[3,2,3],\"target\":[0,0.5,0],\"fov_y\":45}," \
	"\"objects\":[{\"shape\":\"plane\",\"size\":[4,4]}," \
	"{\"shape\":\"box\",\"size\":[1,1,1],\"transform\":{\"translation\":[0,0.5,0]}}," \
	"{\"shape\":\"sphere\",\"radius\":0.4,\"segments\":8,\"transform\":{\"translation\":[1,0.4,0]}}]," \
	"\"lights\":[" lights "],\"shadows\":{\"resolution\":64},\"output\":" output "}"
#define WARM_DIR "{\"type\":\"directional\",\"direction\":[-0.5,-1,-0.3]}"
#define WARM_SUN "{\"type\":\"directional\",\"direction\":[-0.5,-1,-0.3],\"angular_diameter\":0.53}"
#define WARM_CSM "{\"type\":\"directional\",\"direction\":[-0.5,-1,-0.3],\"angular_diameter\":0.53," \
	"\"shadow\":{\"directional\":{\"mode\":\"cascades\",\"cascades\":4}}}"
#define WARM_SPOT "{\"type\":\"spot\",\"position\":[2,3,1],\"direction\":[-2,-3,-1],\"radius\":0.1}"
#define WARM_POINT "{\"type\":\"point\",\"position\":[-1,2,1],\"radius\":0.1}"
#define WARM_POINT_HARD "{\"type\":\"point\",\"position\":[-1,2,1]}"
#define WARM_VSM "{\"type\":\"directional\",\"direction\":[-0.5,-1,-0.3],\"shadow\":{\"filter\":\"vsm\"}}"
#define WARM_EVSM "{\"type\":\"spot\",\"position\":[2,3,1],\"direction\":[-2,-3,-1],\"shadow\":{\"filter\":\"evsm\"}}"
/* the moments blur's other two variants (renderer/moments.c): evsm in a sun's map, vsm in a spot's */
#define WARM_EVSM_SUN "{\"type\":\"directional\",\"direction\":[0.5,-1,0.3],\"shadow\":{\"filter\":\"evsm\"}}"
#define WARM_VSM_SPOT "{\"type\":\"spot\",\"position\":[-2,3,1],\"direction\":[2,-3,-1],\"shadow\":{\"filter\":\"vsm\"}}"
#define PNG1 "{\"format\":\"png\",\"msaa\":1}"
#define PNG4 "{\"format\":\"png\",\"msaa\":4}"
#define EXR4 "{\"format\":\"exr\",\"msaa\":4}"
/* The thumbnail preset: the studio environment (its maps, built once per process, and the
 * environment's compute, shadow and pass pipelines) with its 12 shadow directions. */
#define WARM_THUMBNAIL \
	"{\"preset\":\"thumbnail\",\"width\":32,\"height\":32,\"objects\":[" \
	"{\"shape\":\"box\",\"size\":[1,1,1],\"transform\":{\"translation\":[0,0.5,0]}}," \
	"{\"shape\":\"sphere\",\"radius\":0.4,\"segments\":8,\"transform\":{\"translation\":[1,0.4,0]}}]}"

/* The thumbnail preset over a model: a dense plain mesh, so the plan shades it once per pixel
 * (renderer/visibility_plan.c) as it does an untextured imported model: its pixel shading,
 * resolve and environment-pass variants (0.25-0.35 s of compiling on lavapipe otherwise paid
 * by a farm's first model). Its "positions" are written by warm_mesh(). */
#define WARM_MODEL_HEAD \
	"{\"preset\":\"thumbnail\",\"width\":32,\"height\":32,\"objects\":[{\"shape\":\"mesh\",\"positions\":["
#define WARM_MODEL_TAIL "]}]}"
/* ... and the same dome with uvs and a base colour texture (a 2x2 PNG): a textured model's
 * material is shaded in the main pass (no pixel shading), a variant of its own that a farm's
 * first textured glTF compiled (150-180 ms on the 2-core machine, in the farm benchmark's
 * first textured request every run). */
#define WARM_TEXTURE "iVBORw0KGgoAAAANSUhEUgAAAAIAAAACCAIAAAD91JpzAAAAE0lEQVR42mM4UREQteAEAxADWQAungal0+71zgAAAABJRU5ErkJggg=="
#define WARM_TEXTURED_TAIL "],\"material\":{\"base_color_texture\":\"" WARM_TEXTURE "\"}}]}"
#define WARM_MESH_SIDE 10

/* The contract's defaults first (WARM_DEFAULTS of them), then what `--warm-up all` adds. */
static const struct { const char *name, *json; int mesh; } warm_scenes[] = {   /* mesh: warm_mesh's, 0 plain, 1 textured */
	{ "msaa 4, directional pcf", WARM_SCENE(WARM_DIR, PNG4) },
	{ "msaa 4, directional pcss", WARM_SCENE(WARM_SUN, PNG4) },
	{ "msaa 4, cascades pcss", WARM_SCENE(WARM_CSM, PNG4) },
	{ "msaa 4, directional+spot+point pcss/pcf", WARM_SCENE(WARM_SUN "," WARM_SPOT "," WARM_POINT "," WARM_POINT_HARD, PNG4) },
	{ "thumbnail preset, studio environment", WARM_THUMBNAIL },
	{ "thumbnail preset, a model", NULL, 0 },
	{ "thumbnail preset, a textured model", NULL, 1 },
	{ "msaa 1, directional pcf", WARM_SCENE(WARM_DIR, PNG1) },
	{ "msaa 1, directional pcss", WARM_SCENE(WARM_SUN, PNG1) },
	{ "msaa 1, directional+spot+point pcss/pcf", WARM_SCENE(WARM_SUN "," WARM_SPOT "," WARM_POINT "," WARM_POINT_HARD, PNG1) },
	{ "msaa 4, exr", WARM_SCENE(WARM_DIR, EXR4) },
	{ "msaa 4, vsm+evsm", WARM_SCENE(WARM_VSM "," WARM_EVSM "," WARM_EVSM_SUN "," WARM_VSM_SPOT, PNG4) },
};

#define WARM_DEFAULTS 7u
#define WARM_ALL (unsigned)(sizeof warm_scenes / sizeof warm_scenes[0])

static int warm_one(struct srv_server *s, size_t i, char *const mesh[2])
{
	const char *json = warm_scenes[i].json ? warm_scenes[i].json : mesh ? mesh[warm_scenes[i].mesh] : NULL;
	double t1 = srv_now();
	struct api_scene *sc = NULL;
	struct api_problem p = { 0 };
	struct api_limits lim = { 0 };
	struct rnd_image img = { 0 };
	struct rnd_timings t = { 0 };
	struct rnd_error err = { 0 };
	uint8_t *bytes = NULL;
	size_t len = 0;
	int ok = 0;
	if (!json) {
		srv_log(SRV_LOG_WARN, "warm-up '%s': out of memory", warm_scenes[i].name);
	} else if (api_scene_parse(json, strlen(json), &lim, &sc, &p) != API_OK) {
		char msg[700];
		api_problem_format(&p, msg, sizeof msg);
		srv_log(SRV_LOG_WARN, "warm-up '%s': %s", warm_scenes[i].name, msg);
	} else if (srv_render(s, &sc->scene, NULL, &img, &t, &err, NULL) != RND_OK) {
		srv_log(SRV_LOG_WARN, "warm-up '%s': %s", warm_scenes[i].name, err.msg);
	} else if (api_encode(sc, &img, &bytes, &len, &p) != API_OK) {
		srv_log(SRV_LOG_WARN, "warm-up '%s': encode: %s", warm_scenes[i].name, p.detail);
	} else {
		ok = 1;
		srv_log(SRV_LOG_INFO, "warm-up '%s': %.0f ms", warm_scenes[i].name, (srv_now() - t1) * 1000);
	}
	free(bytes);
	rnd_image_release(&img);
	api_scene_free(sc);
	return ok ? 0 : -1;
}

struct warm_state {
	struct srv_server *srv;
	char *mesh[2];         /* warm_mesh()'s scenes: plain, textured */
	atomic_uint next;
	unsigned count;
};

static void *warm_thread(void *arg)
{
	struct warm_state *w = arg;
	unsigned i;
	while ((i = atomic_fetch_add(&w->next, 1)) < w->count)
		warm_one(w->srv, i, w->mesh);
	return NULL;
}

/* A dome of WARM_MESH_SIDE^2 quads as a triangle list (WARM_MODEL_HEAD ... TAIL): the scene of
 * "thumbnail preset, a model"; textured: with uvs and WARM_TEXTURE. NULL when out of memory. */
static char *warm_mesh(bool textured)
{
	size_t cap = strlen(WARM_MODEL_HEAD WARM_TEXTURED_TAIL ",\"uvs\":[") +
	             (size_t)WARM_MESH_SIDE * WARM_MESH_SIDE * 6 * 5 * 12 + 1;
	char *json = malloc(cap);
	if (!json) return NULL;
	size_t n = (size_t)snprintf(json, cap, "%s", WARM_MODEL_HEAD);
	static const int corner[6][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
	for (int pass = 0; pass < (textured ? 2 : 1); pass++) {
		if (pass) n += (size_t)snprintf(json + n, cap - n, "],\"uvs\":[");
		size_t first = n;
		for (int y = 0; y < WARM_MESH_SIDE; y++)
			for (int x = 0; x < WARM_MESH_SIDE; x++)
				for (int k = 0; k < 6; k++) {
					double s = (double)(x + corner[k][0]) / WARM_MESH_SIDE, t = (double)(y + corner[k][1]) / WARM_MESH_SIDE;
					double u = s * 2 - 1, v = t * 2 - 1, h = 1 - 0.5 * (u * u + v * v);
					const char *sep = n > first ? "," : "";
					n += pass ? (size_t)snprintf(json + n, cap - n, "%s%.2f,%.2f", sep, s, t)
					          : (size_t)snprintf(json + n, cap - n, "%s%.2f,%.2f,%.2f", sep, u, h, v);
				}
	}
	snprintf(json + n, cap - n, "%s", textured ? WARM_TEXTURED_TAIL : WARM_MODEL_TAIL);
	return json;
}

int srv_warmup(struct srv_server *s)
{
	double t0 = srv_now();
	/* The basic scene alone first, so a renderer that cannot render at all fails fast. */
	if (warm_one(s, 0, NULL) != 0) {
		srv_log(SRV_LOG_ERROR, "warm-up failed: the renderer cannot render the basic scene");
		return -1;
	}
	/* The rest on as many threads as there are render slots: pipeline compilation (LLVM in
	 * lavapipe) is single-threaded per pipeline. */
	struct warm_state w = { .srv = s, .mesh = { warm_mesh(false), warm_mesh(true) }, .count = s->cfg.warm_up && !strcmp(s->cfg.warm_up, "all") ? WARM_ALL : WARM_DEFAULTS };
	atomic_init(&w.next, 1);
	pthread_t th[16];
	unsigned n = s->cfg.workers < 16 ? s->cfg.workers : 16, started = 0;
	for (unsigned i = 1; i < n; i++)
		if (pthread_create(&th[started], NULL, warm_thread, &w) == 0)
			started++;
	warm_thread(&w);
	for (unsigned i = 0; i < started; i++)
		pthread_join(th[i], NULL);
	free(w.mesh[0]);
	free(w.mesh[1]);
	/* Pipeline compilation leaves tens of MB free in malloc's arenas: give them back. */
	malloc_trim(0);
	srv_log(SRV_LOG_INFO, "warm-up done in %.0f ms", (srv_now() - t0) * 1000);
	return 0;
}
