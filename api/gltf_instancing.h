/*
 * api/gltf_instancing — EXT_mesh_gpu_instancing, which Assimp 5.2 ignores (it drew one cube of
 * SimpleInstancing's grid): each node with the extension becomes a parent of one child node
 * per instance (its mesh, and the instance's TRANSLATION, ROTATION and SCALE as the child's
 * TRS), so the import draws every instance at node transform x instance transform, as the
 * extension defines. The document is changed in place before Assimp reads it (the caller
 * serialises it: api_gltf_tag_materials).
 *
 * Usage (api/model_import.c, inside the sandboxed importer):
 *   int n = api_gltf_expand_instancing(&bufs, API_GLTF_MAX_INSTANCES, err, errsize);   // api/gltf_buffers.h
 *   n < 0: the file is refused (err says why); n > 0: root changed (n instances made)
 * Ownership: nothing kept; root stays the caller's. Threading: no shared state.
 */
#ifndef UMBRA_API_GLTF_INSTANCING_H
#define UMBRA_API_GLTF_INSTANCING_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <jansson.h>
#include "gltf_buffers.h"

/* Instances one model may make: each is an object the renderer draws (and ~100 bytes of JSON
 * here before that). */
#define API_GLTF_MAX_INSTANCES 65536

/* Returns the instances made (0: no node has the extension), or -1 with err filled: an
 * accessor out of its buffer, of a type the extension does not allow, counts that disagree,
 * or over max instances. */
int api_gltf_expand_instancing(struct api_gltf_bufs *b, size_t max, char *err, size_t errsize);

#endif
