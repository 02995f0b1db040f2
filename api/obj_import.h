/*
 * api/obj_import — OBJ read without Assimp, into the model the Assimp path makes (api/
 * model_import.c calls it first for an OBJ; see obj_import.c for what it leaves to Assimp).
 * Runs in the sandboxed importer like the rest of the import. Threading: no shared state.
 */
#ifndef UMBRA_API_OBJ_IMPORT_H
#define UMBRA_API_OBJ_IMPORT_H

#include <stddef.h>
#include <stdint.h>
#include "arena.h"
#include "model.h"

/* Not read here: the caller imports it through Assimp. */
#define API_OBJ_NOT_MINE (-1)

/* d[0..len) as an OBJ into *out (arena memory; *bytes what it holds), with the files it names
 * (its .mtl and textures, as api_model_import_files takes them) for images of output_side:
 * API_WIRE_OK, API_WIRE_OVER_MEMORY with a sentence in err, the status and message Assimp
 * refused the file's materials with (API_WIRE_BAD_INPUT: a texture it cannot decode, ...), or
 * API_OBJ_NOT_MINE (err then holds nothing of use). */
int api_obj_import(const uint8_t *d, size_t len, const struct api_model_file *files, size_t nfiles,
                   uint32_t output_side, struct api_arena *arena, struct api_model *out, size_t *bytes, char *err,
                   size_t errsize);

#endif
