/*
 * api/gltf_decode — what Assimp 5.2 cannot read of a glTF document's data, made readable
 * before it reads it (inside the sandboxed importer):
 *   - EXT_meshopt_compression: every compressed bufferView decoded with meshoptimizer
 *     (ATTRIBUTES, TRIANGLES, INDICES; filters OCTAHEDRAL, QUATERNION, EXPONENTIAL) into the
 *     made buffer (api/gltf_buffers.h), the view pointed at it; the fallback buffers the
 *     extension leaves without data are then dropped (api_gltf_drop_fallbacks);
 *   - KHR_draco_mesh_compression (api/gltf_draco.c): every compressed primitive decoded with
 *     libdraco (api/draco.h), its indices (as UNSIGNED_INT) and the attributes the extension
 *     names written in their accessors' types into the made buffer, the accessors pointed
 *     there, the extension removed from the primitive (Assimp 5.2's own Draco path drops
 *     UNSIGNED_INT indices, and reads a JOINTS_0 the skins pass removed);
 *   - KHR_mesh_quantization, and any vertex attribute stored as integers (glTF core allows
 *     normalized TEXCOORD_n and COLOR_n; Draco's decoded ones too): the accessor rewritten as
 *     floats (Assimp 5.2 read a quantized POSITION as garbage, "triangles have no area").
 * The extensions are then removed from extensionsUsed / extensionsRequired.
 *
 * Usage: n = api_gltf_decode(&bufs, err, errsize): n < 0 refused (err says why; bufs.oom when
 * an allocation failed), n > 0 the document changed. After api_gltf_bufs_finish:
 * api_gltf_drop_fallbacks(root).
 * Threading: no shared state.
 */
#ifndef UMBRA_API_GLTF_DECODE_H
#define UMBRA_API_GLTF_DECODE_H

#include <stdbool.h>
#include <stddef.h>
#include <jansson.h>
#include "gltf_buffers.h"

/* The most bytes one decoded bufferView may take (count x byteStride). */
#define API_GLTF_MAX_DECODED_VIEW ((size_t)1 << 30)

int api_gltf_decode(struct api_gltf_bufs *b, char *err, size_t errsize);
/* The Draco part of api_gltf_decode: the primitives decoded (0: none), or -1 with err. */
long api_gltf_decode_draco(struct api_gltf_bufs *b, char *err, size_t errsize);
/* Removes the buffers no bufferView names any more and that have no uri (meshopt's
 * fallbacks), renumbering the views' buffer indices. */
void api_gltf_drop_fallbacks(json_t *root);
/* Skins are not applied (meshes are drawn in their bind pose, and the model says so): drops
 * every primitive's JOINTS_n and WEIGHTS_n and every node's skin before Assimp reads the
 * document. Assimp 5.2 refused the common unsigned-short JOINTS_0 of skinned files
 * ("elemSize 16 > targetElemSize 8": CesiumMan, Fox, BrainStem, RiggedFigure). Returns
 * whether it changed root. */
bool api_gltf_drop_skins(json_t *root);
/* Whether every primitive of every mesh has indices (after api_gltf_decode: a Draco
 * primitive's decoded accessor is in its "indices"): its vertices are then the exporter's
 * own, one per distinct set of attributes, and Assimp's join of identical vertices has
 * nothing to join (api/model_import.c leaves it out). */
bool api_gltf_all_indexed(json_t *root);

#endif
