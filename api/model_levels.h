/*
 * api/model_levels — a cached model's levels of detail for the other sizes it is drawn at
 * (see model_levels.c for when and why). Private to api/: api/model.c drives it; renders read
 * the result through api_model_mesh_lods() (model.h).
 */
#ifndef UMBRA_API_MODEL_LEVELS_H
#define UMBRA_API_MODEL_LEVELS_H

#include <stdint.h>
#include "api.h"
#include "model.h"

/* A cache hit on m for a request of lim: builds the levels for lim->output_side (in the
 * sandbox, under lim's import limits) when a mesh wants them and that size has none built or
 * refused; returns once they are there. */
void api_levels_on_hit(struct api_model *m, const struct api_limits *lim);
/* What the builds left in m; model_free() calls it. */
void api_levels_free(struct api_model *m);
/* Sizes built and refused (over the limits, a bad reply) since the start. */
void api_levels_stats(uint64_t *done, uint64_t *failed);

/* api/model.c, for this module: m's cache charge grows by `bytes`. */
void api_model_charge_(struct api_model *m, size_t bytes);

#endif
