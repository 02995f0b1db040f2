/* tests/fuzz/fuzz_model_ply.c — libFuzzer target: ply files through the sandboxed import, and
 * through the own PLY reader in this process (see fuzz_model.h). */
#include "model_wire.h"
#include "ply_import.h"
#define FUZZ_FORMAT API_MODEL_PLY
#define FUZZ_OWN_READER api_ply_import
#include "fuzz_model.h"
