/*
 * api/gltf_buffers — a glTF document's binary data, for what umbra does to a document before
 * Assimp 5.2 reads it (api/gltf_decode.c, api/gltf_instancing.c): each buffer's bytes (a
 * glb's BIN chunk, a data: URI, a file the daemon sent with the model), a bufferView's bytes
 * inside them, an accessor read as floats, and one buffer of bytes made here (decoded
 * meshopt views, dequantized attributes) that the document then names as the file
 * API_GLTF_MADE_FILE, served to Assimp beside the model's own files.
 *
 * Usage (api/model_import.c, inside the sandboxed importer):
 *   struct api_gltf_bufs b; api_gltf_bufs_init(&b, root, data, len, glb, files, nfiles);
 *   ... api_gltf_view_bytes / api_gltf_accessor_floats / api_gltf_made_view ...
 *   api_gltf_bufs_finish(&b);            // names the made buffer in root (when there is one)
 *   api_gltf_drop_fallbacks(root);       // then buffers nothing reads any more go (gltf_decode.h)
 *   api_gltf_bufs_files(&b, &f, &nf);    // the files to import with (the made one added)
 *   ... import ...; api_gltf_bufs_release(&b);
 * Ownership: b owns the decoded data: URIs, the made buffer and the files array it returns;
 * root, data and files stay the caller's and must outlive b. Threading: no shared state.
 */
#ifndef UMBRA_API_GLTF_BUFFERS_H
#define UMBRA_API_GLTF_BUFFERS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <jansson.h>
#include "model.h"

#define API_GLTF_MADE_FILE "umbra-decoded.bin"

struct api_gltf_bytes {
	const uint8_t *p;
	size_t n;
	uint8_t *owned;   /* a decoded data: URI */
	bool loaded;
};

struct api_gltf_bufs {
	json_t *root;
	const uint8_t *data;
	size_t len;
	bool glb;
	const struct api_model_file *files;
	size_t nfiles;
	struct api_gltf_bytes *buffers;   /* per buffer of the document as it was read */
	size_t nbuffers;
	uint8_t *made;                    /* the buffer made here, and its buffer index */
	size_t made_len, made_cap;
	long made_index;                  /* -1 until the first api_gltf_made_bytes */
	struct api_gltf_bytes made_view_;  /* api_gltf_buffer(made_index): the made bytes so far */
	struct api_model_file *all_files; /* api_gltf_bufs_files */
	bool oom;                         /* an allocation failed: over the memory limit, not a bad file */
};

void api_gltf_bufs_init(struct api_gltf_bufs *b, json_t *root, const uint8_t *data, size_t len, bool glb,
                        const struct api_model_file *files, size_t nfiles);
void api_gltf_bufs_release(struct api_gltf_bufs *b);

/* Buffer `bi`'s bytes (*out->p NULL when it has none: an external file not sent, a glb
 * buffer past the BIN chunk); b->made_index: what was made so far (valid until the next
 * api_gltf_made_bytes). 0, or -1 with err (bad base64, out of memory). */
int api_gltf_buffer(struct api_gltf_bufs *b, size_t bi, const struct api_gltf_bytes **out, char *err,
                    size_t errsize);
/* bufferView `vi`'s bytes, checked inside its buffer. 0, or -1 with err naming `what`. */
int api_gltf_view_bytes(struct api_gltf_bufs *b, json_t *view, const char *what, const uint8_t **p, size_t *n,
                        char *err, size_t errsize);
/* The components of an accessor type ("SCALAR" 1 .. "MAT4" 16; 0 unknown) and the bytes of
 * a componentType (5120 BYTE .. 5126 FLOAT; 0 unknown). */
int api_gltf_type_components(const char *type);
size_t api_gltf_component_size(json_int_t component_type);
/* Accessor `acc` (an object of the document) as count x comps floats (malloc'd, yours; *count
 * its count; comps from its type, at most 16), normalized integers mapped as glTF says,
 * plain integers as their values. 0, or -1 with err naming `what` (out of its view, no
 * view, an unknown type). */
int api_gltf_accessor_floats(struct api_gltf_bufs *b, json_t *acc, const char *what, float **out, size_t *count,
                             int *comps, char *err, size_t errsize);
/* Appends n bytes (at a 4-aligned offset) to the made buffer: that offset in it (its buffer
 * index is b->made_index), or -1 (out of memory: b->oom, or past 2 GB). */
long api_gltf_made_bytes(struct api_gltf_bufs *b, const void *bytes, size_t n);
/* The same, and a bufferView of them added to the document: its index, or -1. */
long api_gltf_made_view(struct api_gltf_bufs *b, const void *bytes, size_t n);
/* Adds the made buffer to root's buffers (uri API_GLTF_MADE_FILE) if there is one. */
int api_gltf_bufs_finish(struct api_gltf_bufs *b);
/* The glTF JSON of a model file: a .glb's JSON chunk (*json, *jlen inside d), or the whole of
 * a .gltf. NULL, or what is wrong with the glb ("the glb has no JSON chunk", ...). */
const char *api_gltf_json_of(const uint8_t *d, size_t len, bool glb, const char **json, size_t *jlen);
/* The model file d with its JSON replaced by js[0..jn) (a .glb keeps its chunks after the JSON
 * one, the JSON chunk padded with spaces): malloc'd (*out_len bytes; you free it), or NULL
 * (out of memory, over 4 GB). */
uint8_t *api_gltf_with_json(const uint8_t *d, size_t len, bool glb, const char *js, size_t jn, size_t *out_len);
/* Removes `name` from root's list `key` ("extensionsUsed", "extensionsRequired") if there. */
void api_gltf_drop_extension_name(json_t *root, const char *key, const char *name);
/* The files to import with: the caller's, and the made buffer when there is one (b owns the
 * array). 0, or -1 (out of memory). */
int api_gltf_bufs_files(struct api_gltf_bufs *b, const struct api_model_file **files, size_t *nfiles);

#endif
