/*
 * api/model_import — Assimp import of one model file, in the calling process, with no
 * isolation at all. Private to api/: the sandboxed importer child (api/sandbox_child.c) calls
 * it on the bytes it was sent; the bench calls it to measure what the sandbox costs. The
 * daemon and the CLI never call it: they go through api_model_get() (model.h), which runs it
 * in a helper process.
 *
 * Ownership: everything *out points to is allocated in `arena` (the caller's, freed by it).
 * Threading: safe from several threads (the Assimp call itself is serialised: its C API keeps
 * the last error in one global string).
 */
#ifndef UMBRA_API_MODEL_IMPORT_H
#define UMBRA_API_MODEL_IMPORT_H

#include "arena.h"
#include "model.h"
#include "model_wire.h"

/* Imports data[0..len) as `format` (not SNIFF). Returns API_WIRE_OK with *out filled and
 * *bytes = what the arena holds for it; API_WIRE_BAD_INPUT or API_WIRE_OVER_MEMORY (an
 * allocation failed) with a sentence in err. */
enum api_wire_status api_model_import_local(const uint8_t *data, size_t len, enum api_model_format format,
                                            struct api_arena *arena, struct api_model *out, size_t *bytes,
                                            char *err, size_t errsize);

/* The same with the files the model refers to (names as the model writes them): Assimp's
 * file system and the texture lookup serve them from memory; textures decoded for images of
 * output_side (api_image_decode_fit; 0 = as stored); out->times: its parse and textures. */
enum api_wire_status api_model_import_files(const uint8_t *data, size_t len, const struct api_model_file *files,
                                            size_t nfiles, enum api_model_format format, uint32_t output_side,
                                            struct api_arena *arena, struct api_model *out, size_t *bytes, char *err,
                                            size_t errsize);
/* The same through Assimp whatever the format: api_model_import_files() reads a plain binary
 * STL itself (api/stl_import.h); tests compare the two. */
enum api_wire_status api_model_import_assimp(const uint8_t *data, size_t len, const struct api_model_file *files,
                                             size_t nfiles, enum api_model_format format, uint32_t output_side,
                                             struct api_arena *arena, struct api_model *out, size_t *bytes, char *err,
                                             size_t errsize);

/* True when some triangle of the meshes has an area (a model of only degenerate triangles
 * imports "fine" and renders nothing: it is refused instead). */
bool api_model_meshes_have_area(const struct api_model_mesh *m, uint32_t n);

#endif
