/* tests/fuzz/fuzz_model_stl.c — libFuzzer target: stl files through the sandboxed import
 * (see fuzz_model.h). */
#define FUZZ_FORMAT API_MODEL_STL
#include "fuzz_model.h"
