/*
 * api/gltf_variants — KHR_materials_variants: a glTF model file with one of its variants
 * applied, for a model object's "variant" member (api/scene_parse.c). Each primitive whose
 * mappings name the variant takes that mapping's material; the others keep their default
 * one; the extension then leaves the document, so the importer draws it as a file without
 * variants. The daemon does this before the import: the rewritten bytes are the model (the
 * cache keys them as a model of their own), and the importer needs no new input.
 *
 * Why not carry the mappings through the importer's reply and switch materials per request?
 * Assimp 5.2 imports only the materials that primitives reference, so a variant's materials
 * would not be in the reply without rewriting the document anyway, and every import of such a
 * file would decode the textures of all its variants (the shoe: three sets of colour maps)
 * to draw one.
 *
 * Usage: bytes = api_gltf_pick_variant(d, len, glb, "Yellow", &n, err, errsize) ... free(bytes).
 * Runs in the daemon on request bytes: it only parses the JSON (jansson) and copies.
 * Threading: no shared state.
 */
#ifndef UMBRA_API_GLTF_VARIANTS_H
#define UMBRA_API_GLTF_VARIANTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <jansson.h>

/* d[0..len) (a .glb when glb, else a .gltf) with variant `name` applied: malloc'd (*out_len
 * bytes, yours), or NULL with err: the file has no variants, or not that one (err lists the
 * file's variants), its JSON does not parse, a mapping names a material it does not have, or
 * out of memory (*oom). */
uint8_t *api_gltf_pick_variant(const uint8_t *d, size_t len, bool glb, const char *name, size_t *out_len, bool *oom,
                               char *err, size_t errsize);
/* The variant names of the document root as a list for a sentence ("\"a\", \"b\", \"c\"", cut
 * with "..." to fit size), into out; "" when it has none. */
void api_gltf_variant_names(json_t *root, char *out, size_t size);

#endif
