/*
 * api/stl_import — binary STL read without Assimp, into the model the Assimp path makes
 * (api/model_import.c calls it first for an STL; see stl_import.c for what it leaves to Assimp).
 * Runs in the sandboxed importer like the rest of the import. Threading: no shared state.
 */
#ifndef UMBRA_API_STL_IMPORT_H
#define UMBRA_API_STL_IMPORT_H

#include <stddef.h>
#include <stdint.h>
#include "arena.h"
#include "model.h"
#include "model_wire.h"

/* Not read here: the caller imports it through Assimp (colours, or anything but a plain file). */
#define API_STL_NOT_MINE (-1)

/* d[0..len) as a binary STL into *out (arena memory; *bytes what it holds): API_WIRE_OK,
 * API_WIRE_OVER_MEMORY with a sentence in err, or API_STL_NOT_MINE. */
int api_stl_import_binary(const uint8_t *d, size_t len, struct api_arena *arena, struct api_model *out,
                          size_t *bytes, char *err, size_t errsize);

#endif
