/* tests/fuzz/fuzz_model_obj.c — libFuzzer target: obj files through the sandboxed import
 * (see fuzz_model.h). */
#define FUZZ_FORMAT API_MODEL_OBJ
#include "fuzz_model.h"
