/*
 * tests/util/model_compare — two imports of one file compared (tests/unit/test_obj_ply.c, and
 * build/tests/import_bench --compare on real files): umbra's own OBJ and PLY readers against the
 * Assimp path (api/obj_import.h, api/ply_import.h promise the same model).
 */
#ifndef UMBRA_TEST_MODEL_COMPARE_H
#define UMBRA_TEST_MODEL_COMPARE_H

#include <stddef.h>
#include "model.h"

/* Whether a and b are the same model: meshes (vertices in order, indices, material, sides),
 * instances, materials (every factor; textures by size and texels) and warnings; normals may
 * differ by `nrm_tol` a component (the made ones are sums in another order). false: the first
 * difference as a sentence in why. */
bool test_models_equal(const struct api_model *a, const struct api_model *b, float nrm_tol, char *why, size_t whysize);

#endif
