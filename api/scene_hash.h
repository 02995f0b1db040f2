/*
 * api/scene_hash — the canonical hash of a parsed scene: what decides that two requests
 * describe the same image, whatever their spelling (the ETag's scene part, server/negotiate.h).
 *
 * Two parts, each framed so that no two different inputs give the same byte stream:
 *   - The parsed scene (api_scene and its rnd_scene, after the preset is merged, defaults
 *     filled, models expanded and the ground placed): its structs' bytes, each pointer hashed as
 *     set or not (what it points to is hashed by its source below), and the warnings. So a
 *     member written with its default and one left out hash alike ("segments": 64 is no
 *     member), as do 45 and 45.0000000001 degrees when they parse to the same float.
 *   - What of the document the parsed scene does not hold: the document less every member
 *     the walk read into the scene (api_member_read: numbers, booleans, enums, vectors), and
 *     less the objects that leaves empty (`"shadows": {"filter": "auto"}` goes with its
 *     member). What remains is the sources of data: inline base64 and mesh arrays (a kept big
 *     string by its bytes), model paths and part names, material names, `extras`. It is
 *     hashed as a tree: members in byte order of their keys, numbers as their doubles (-0 as 0),
 *     strings unescaped, so member order, whitespace, escapes and number spellings do not
 *     matter. Then each multipart part (a model's raw bytes) by its name and bytes, in name
 *     order. Files read by `path` are not here: api_scene.asset_hash.
 *
 * The parsed structs are hashed by their bytes, so every member added to them counts without
 * a change here; their padding must be zero, which holds as every rnd_*_defaults() and the
 * arena zero them before a member is written (rnd.h). A pointer member added to an rnd_ struct
 * must be added to the pointer lists in scene_hash.c (tests/unit/test_scene_hash.c parses the
 * same scene twice and fails when a pointer's address reaches the hash).
 *
 * The hash is the project's 64-bit FNV-1a for the framing and rnd_hash (a word at a time,
 * umbra/rnd_math.h) for the structs and the parts' bytes.
 *
 * Usage (api/scene_parse.c, after a successful walk): s->scene_hash = api_scene_hash(root, &big,
 * parts, nparts, c.reads, c.nreads, s). It removes the members read from root (which the
 * caller then frees). reads NULL: the whole document is hashed (when recording them ran out of
 * memory; still canonical for one spelling). Internal to api/ (it exposes jansson).
 * Thread-safe; allocates only the parts' order (on failure the parts are hashed in their order).
 */
#ifndef UMBRA_API_SCENE_HASH_H
#define UMBRA_API_SCENE_HASH_H

#include <jansson.h>
#include <stdint.h>

#include "api.h"
#include "big_strings.h"

/* A member of the document that the walk read into the parsed scene (borrowed pointers: obj is
 * in the document, key a string constant of the parser). */
struct api_member_read {
	json_t *obj;
	const char *key;
};

uint64_t api_scene_hash(json_t *root, const struct api_big_strings *big, const struct api_part *parts,
                        size_t nparts, const struct api_member_read *reads, size_t nreads,
                        const struct api_scene *s);

#endif
