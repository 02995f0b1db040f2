/*
 * api/scene_hash — the canonical hash of a scene document: what decides that two requests
 * describe the same image, whatever their spelling.
 *
 * The document is hashed after its preset is merged (api/preset.h: the defaults a preset fills
 * are in the tree), walking the parsed jansson tree rather than the bytes, so that
 *   - member order does not matter (an object's members are hashed in byte order of their keys),
 *   - whitespace, escapes ("\u0041" is "A") and number spellings (1, 1.0, 1e0) do not matter:
 *     every number is hashed as its double's bits, -0 as 0,
 *   - a kept big string (api/big_strings.h: inline base64) is hashed by its bytes in the document;
 * and each multipart part (a model's raw bytes) by its name and bytes, in name order, whatever
 * the order the client sent them in. Files read by `path` are not here: api_scene.asset_hash.
 *
 * Each value is framed by a type tag and its length, so that no two different trees give the
 * same byte stream. The hash is the project's 64-bit FNV-1a for the framing and rnd_hash (a
 * word at a time, umbra/rnd_math.h) for the bytes.
 *
 * Usage (api/scene_parse.c, after api_preset_apply): s->scene_hash = api_scene_hash(root, &big,
 * parts, nparts). Internal to api/ (it exposes jansson). Thread-safe, no allocation but the
 * parts' order (a small array; on failure to allocate the parts are hashed in their order).
 */
#ifndef UMBRA_API_SCENE_HASH_H
#define UMBRA_API_SCENE_HASH_H

#include <jansson.h>
#include <stdint.h>

#include "api.h"
#include "big_strings.h"

uint64_t api_scene_hash(const json_t *root, const struct api_big_strings *big, const struct api_part *parts,
                        size_t nparts);

#endif
