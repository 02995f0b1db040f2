/* tests/fuzz/fuzz_model_gltf.c — libFuzzer target: gltf files through the sandboxed import
 * (see fuzz_model.h). */
#define FUZZ_FORMAT API_MODEL_GLTF
#include "fuzz_model.h"
