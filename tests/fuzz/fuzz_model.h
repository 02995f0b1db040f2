/*
 * tests/fuzz/fuzz_model.h — body of the libFuzzer targets fuzz_model_<fmt>.c: one model format
 * each (FUZZ_FORMAT), through the real sandboxed import (api/sandbox.h), so Assimp crashing,
 * looping or running out of memory on an input is a handled 400/422, never a fuzzer crash. What
 * must hold: every input gives a model or a failure with a 4xx status (a 500 means the sandbox
 * itself broke), and a model that comes back is consistent (the parent's decoder checked it;
 * this re-checks the bounds it promises).
 *
 * Coverage: libFuzzer sees only this process (the reply decoder); Assimp runs in the child and
 * is not instrumented (Debian's library), so these targets are robustness runs of the whole
 * path rather than coverage-guided exploration of Assimp.
 *
 *   make fuzz && build/fuzz/fuzz_model_ply -max_total_time=60 build/fuzz/corpus-ply tests/fuzz/corpus/fuzz_model_ply
 *   (the helper build/fuzz/umbra-import is found next to the target; UMBRA_IMPORT_HELPER overrides)
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include "api.h"
#include "arena.h"
#include "model.h"
#include "sandbox.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Outcomes over the run, printed at exit: how many inputs imported, were refused or crashed
 * the importer (400), or ran into the import limits (422: mostly Assimp's endless loops). */
static unsigned long n_ok, n_400, n_422;

__attribute__((destructor)) static void report(void)
{
	fprintf(stderr, "sandbox outcomes: %lu imported, %lu x 400, %lu x 422\n", n_ok, n_400, n_422);
}

/* What a model that comes back promises (a broken one aborts: a fuzzer crash). */
static void check_model(const struct api_model *m)
{
	if (!m->mesh_count || !m->instance_count || !m->material_count) abort();
	for (uint32_t i = 0; i < m->instance_count; i++)
		if (m->instances[i].mesh >= m->mesh_count) abort();
	for (uint32_t i = 0; i < m->mesh_count; i++) {
		const struct api_model_mesh *me = &m->meshes[i];
		if (me->material >= m->material_count || me->index_count % 3) abort();
		for (uint32_t k = 0; k < me->index_count; k++)
			if (me->indices[k] >= me->vertex_count) abort();
	}
}

#ifdef FUZZ_OWN_READER
/* The format's own reader (api/obj_import.h, api/ply_import.h) also runs here, in this
 * instrumented process: in the sandbox its crash would be a 400, hidden; here the sanitizers
 * and libFuzzer's coverage see it. */
static void own_reader(const uint8_t *data, size_t size)
{
	struct api_arena *arena = api_arena_create();
	struct api_model m;
	size_t bytes;
	char err[400];
	if (FUZZ_OWN_READER(data, size, arena, &m, &bytes, err, sizeof err) == API_WIRE_OK) check_model(&m);
	api_arena_destroy(arena);
}
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
#ifdef FUZZ_OWN_READER
	own_reader(data, size);
#endif
	struct api_limits lim;
	api_limits_defaults(&lim);
	lim.import_timeout_ms = 1000; /* hangs are common (PLY): keep each one short */
	lim.import_memory = 512u << 20;
	struct api_arena *arena = api_arena_create();
	struct api_model m;
	size_t bytes;
	int status;
	char err[400];
	if (api_sandbox_import_model(data, size, FUZZ_FORMAT, &lim, arena, &m, &bytes, &status, err, sizeof err) ==
	    API_OK) {
		n_ok++;
		check_model(&m);
	} else if (status == 400 || status == 422) {
		if (status == 400) n_400++; else n_422++;
	} else {
		abort(); /* 500: the sandbox could not run, or answered nonsense */
	}
	api_arena_destroy(arena);
	return 0;
}
