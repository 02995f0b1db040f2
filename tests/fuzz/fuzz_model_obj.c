/* tests/fuzz/fuzz_model_obj.c — libFuzzer target: obj files through the sandboxed import, and
 * through the own OBJ reader in this process (see fuzz_model.h). */
#include "model_wire.h"
#include "obj_import.h"
#define FUZZ_FORMAT API_MODEL_OBJ
#define FUZZ_OWN_READER(d, n, a, m, b, e, es) api_obj_import(d, n, NULL, 0, 256, a, m, b, e, es)
#include "fuzz_model.h"
