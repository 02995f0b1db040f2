/*
 * api/model_levels — a cached model's levels of detail for the sizes it is drawn at (the
 * levels themselves: api/model_lod.h).
 *
 * The importer builds the level of the size its request draws (api_model_finish_import, in the
 * sandbox). A cached model drawn at another size needs that size's level, which is what a
 * fresh import for that request would have built: the same request must give the same bytes
 * whatever the cache held (the ETag is strong). So on a cache hit for a new size the level is
 * built then, before the request renders, in the sandbox as a job of its own under the import's
 * time and memory limits (those of the request), and the daemon validates the reply like an
 * import's. A build over the limits is refused and that size is not tried again (the model
 * renders at full detail at that size: the one case where a fresh import, which would have
 * been over its own limit too, differs). Each size's levels are published once on a list that
 * only grows (readers need no lock); one mutex a model keeps two requests from building the
 * same size twice.
 *
 * Threading: every function is safe to call from several threads on shared models.
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "arena.h"
#include "model.h"
#include "model_levels.h"
#include "model_lod.h"
#include "sandbox.h"

/* One size's levels of a model (lv NULL: refused). */
struct api_size_levels {
	uint32_t side;
	const struct api_mesh_levels *lv;    /* per mesh */
	struct api_arena *arena;
	struct api_size_levels *next;
};

static atomic_uint_fast64_t built, refused;

static bool wants_levels(const struct api_model *m)
{
	for (uint32_t i = 0; i < m->mesh_count; i++)
		if (api_mesh_wants_levels(&m->meshes[i])) return true;
	return false;
}

static const struct api_size_levels *find(const struct api_model *m, uint32_t side)
{
	for (const struct api_size_levels *s = atomic_load_explicit(&m->levels_, memory_order_acquire); s; s = s->next)
		if (s->side == side) return s;
	return NULL;
}

const struct rnd_mesh_lod *api_model_mesh_lods(const struct api_model *m, uint32_t mesh, uint32_t side, uint32_t *count)
{
	*count = 0;
	if (!side) return NULL;
	if (side == m->level_side) {
		*count = m->meshes[mesh].lod_count;
		return m->meshes[mesh].lods;
	}
	const struct api_size_levels *s = find(m, side);
	if (!s || !s->lv) return NULL;
	*count = s->lv[mesh].count;
	return s->lv[mesh].lods;
}

/* The levels of m for `side`, through the sandbox; NULL arena and lv when refused. */
static void build(struct api_model *m, uint32_t side, const struct api_limits *lim, struct api_size_levels *out)
{
	struct api_arena *arena = api_arena_create();
	struct api_mesh_levels *lv = arena ? api_arena_calloc(arena, m->mesh_count, sizeof *lv) : NULL;
	size_t bytes = 0;
	int status;
	char err[400];
	if (!lv || api_sandbox_build_levels(m, side, lim, arena, lv, &bytes, &status, err, sizeof err) != API_OK) {
		api_arena_destroy(arena);
		atomic_fetch_add(&refused, 1);
		return;
	}
	out->arena = arena;
	out->lv = lv;
	atomic_fetch_add(&built, 1);
	api_model_charge_(m, bytes);
}

void api_levels_on_hit(struct api_model *m, const struct api_limits *lim)
{
	uint32_t side = lim ? lim->output_side : 0;
	if (!side || side == m->level_side || find(m, side) || !wants_levels(m)) return;
	pthread_mutex_lock(&m->levels_mu_);
	if (!find(m, side)) {   /* another request may have built it meanwhile */
		struct api_size_levels *s = calloc(1, sizeof *s);
		if (s) {
			s->side = side;
			build(m, side, lim, s);
			s->next = atomic_load_explicit(&m->levels_, memory_order_relaxed);
			atomic_store_explicit(&m->levels_, s, memory_order_release);
		}
	}
	pthread_mutex_unlock(&m->levels_mu_);
}

void api_levels_free(struct api_model *m)
{
	struct api_size_levels *s = atomic_load(&m->levels_);
	while (s) {
		struct api_size_levels *n = s->next;
		api_arena_destroy(s->arena);
		free(s);
		s = n;
	}
	atomic_store(&m->levels_, NULL);
}

void api_levels_stats(uint64_t *done, uint64_t *failed)
{
	if (done) *done = atomic_load(&built);
	if (failed) *failed = atomic_load(&refused);
}
