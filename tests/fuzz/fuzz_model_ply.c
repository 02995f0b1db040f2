/* tests/fuzz/fuzz_model_ply.c — libFuzzer target: ply files through the sandboxed import
 * (see fuzz_model.h). */
#define FUZZ_FORMAT API_MODEL_PLY
#include "fuzz_model.h"
