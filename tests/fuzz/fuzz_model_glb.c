/* tests/fuzz/fuzz_model_glb.c — libFuzzer target: glb files through the sandboxed import
 * (see fuzz_model.h). */
#define FUZZ_FORMAT API_MODEL_GLB
#include "fuzz_model.h"
