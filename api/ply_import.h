/*
 * api/ply_import — PLY (binary either way, or ASCII) read without Assimp, into the model the
 * Assimp path makes (api/model_import.c calls it first for a PLY; see ply_import.c for what
 * it leaves to Assimp). Runs in the sandboxed importer like the rest of the import.
 * Threading: no shared state.
 */
#ifndef UMBRA_API_PLY_IMPORT_H
#define UMBRA_API_PLY_IMPORT_H

#include <stddef.h>
#include <stdint.h>
#include "arena.h"
#include "model.h"

/* Not read here: the caller imports it through Assimp. */
#define API_PLY_NOT_MINE (-1)

/* d[0..len) as a PLY into *out (arena memory; *bytes what it holds): API_WIRE_OK,
 * API_WIRE_OVER_MEMORY with a sentence in err, or API_PLY_NOT_MINE. */
int api_ply_import(const uint8_t *d, size_t len, struct api_arena *arena, struct api_model *out, size_t *bytes,
                   char *err, size_t errsize);

#endif
