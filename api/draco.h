/*
 * api/draco — a C interface to libdraco's mesh decoder (Debian libdraco-dev, C++ only), for
 * glTF's KHR_draco_mesh_compression (api/gltf_draco.c). The only C++ in umbra: libdraco has
 * no C API, and Assimp 5.2's own Draco path cannot read a primitive whose indices are
 * UNSIGNED_INT (it drops the decoded indices: "Invalid accessor without data"), which every
 * Draco mesh of more than 65,536 vertices has (docs/design.md).
 *
 * Usage (inside the sandboxed importer):
 *   struct api_draco *d;
 *   if (api_draco_decode(bytes, n, &d, err, errsize) != API_DRACO_OK) ...refuse...;
 *   api_draco_indices(d, idx);            // 3 x api_draco_faces(d) uint32s
 *   api_draco_attribute(d, uid, 5126, 3, out, err, errsize);   // points x 3 floats
 *   api_draco_free(d);
 * Ownership: *out of api_draco_decode is yours (api_draco_free, NULL-safe); the bytes are
 * copied by the decoder and may go once it returns. Errors: a C++ exception never leaves
 * these functions (an allocation that fails is API_DRACO_NO_MEMORY). Threading: no shared
 * state.
 */
#ifndef UMBRA_API_DRACO_H
#define UMBRA_API_DRACO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum api_draco_result { API_DRACO_OK = 0, API_DRACO_BAD, API_DRACO_NO_MEMORY };

struct api_draco;

/* Decodes a Draco mesh (a triangle mesh: a point cloud is API_DRACO_BAD) from src[0..n). */
enum api_draco_result api_draco_decode(const uint8_t *src, size_t n, struct api_draco **out, char *err,
                                       size_t errsize);
void api_draco_free(struct api_draco *d);
uint32_t api_draco_points(const struct api_draco *d);
uint32_t api_draco_faces(const struct api_draco *d);
/* Every face's three point indices into out (3 x api_draco_faces). */
void api_draco_indices(const struct api_draco *d, uint32_t *out);
/* The components per value of the attribute of unique id uid, or 0 when the mesh has none. */
int api_draco_components(const struct api_draco *d, uint32_t uid);
/* The attribute of unique id uid for every point, comps values each (its own component
 * count), converted to the glTF componentType ct (5120 BYTE .. 5126 FLOAT; libdraco's
 * conversion: normalized integers to and from floats as the attribute says) into out
 * (points x comps x the type's size bytes). */
enum api_draco_result api_draco_attribute(const struct api_draco *d, uint32_t uid, int ct, int comps, void *out,
                                          char *err, size_t errsize);

#ifdef __cplusplus
}
#endif

#endif
