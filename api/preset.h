/*
 * api/preset — named defaults a scene document builds on (root member "preset").
 *
 * Usage (api/scene_parse.c, right after the document is loaded):
 *   if (api_preset_apply(&root, p) < 0) { json_decref(root); return API_ERR; }  // p: 400 at /preset
 *
 * "preset": "thumbnail" (the only one so far) gives a framed model on a self-placing shadow-
 * catcher ground lit by the studio environment and its shadows (preset.c). The document's own
 * members override the preset's as an RFC 7396 merge patch: objects merge member by member,
 * arrays and values replace, null removes a preset member ("environment": {"map": null} drops
 * the studio). Two exceptions: `objects` are the document's own followed by the preset's ground
 * (left out when the document has its own plane with placement "ground"); a `camera` with
 * `position` or `target` replaces the preset's fitted camera as a whole. The document's `lights`
 * are its own (the preset has none). The document's own members keep their JSON Pointers (its
 * objects stay first), so problems still point at what the user wrote.
 *
 * Ownership: *root is replaced by the merged document (the old one released). Thread-safe.
 * This header is internal to api/ (it exposes jansson).
 */
#ifndef UMBRA_API_PRESET_H
#define UMBRA_API_PRESET_H

#include <jansson.h>
#include "api.h"

/* The preset's document as JSON text (NULL when there is no such preset). */
const char *api_preset_text(const char *name);
/* Applies the root member "preset" of *root, if any. 0, or -1 with p filled. */
int api_preset_apply(json_t **root, struct api_problem *p);

#endif
