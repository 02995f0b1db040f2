/*
 * api/model_io.h — Assimp's file system for one import (see model_io.c): the model's bytes and
 * the files the daemon found for its references (api/model_refs.h), all in memory, so the
 * importer never reads a disk (the sandbox's system-call filter would refuse an open anyway).
 * Private to api/model_import.c and api/model_material.c.
 *
 * Ownership: the api_mem_io and the buffers it names are the caller's and must outlive the
 * import; each opened aiFile is freed by Assimp's close. Threading: one import at a time per
 * api_mem_io.
 */
#ifndef UMBRA_API_MODEL_IO_H
#define UMBRA_API_MODEL_IO_H

#include <stddef.h>
#include <stdint.h>
#include <assimp/cfileio.h>
#include "model.h"

struct api_mem_io {
	const uint8_t *data;
	size_t len;
	char name[32];
	const struct api_model_file *files;  /* the files the model refers to (api/model_refs.h) */
	size_t nfiles;
};

/* Points io at mi: Assimp then opens mi->name (with any directory before it) and the files. */
void api_mem_io_init(struct api_mem_io *mi, struct aiFileIO *io);
/* The index in files[0..n) of the file named `name`, or -1. Names compare as the model writes
 * them: "\\" as "/", no leading "./", %XX decoded (glTF URIs). */
long api_model_file_index(const struct api_model_file *files, size_t n, const char *name);

#endif
