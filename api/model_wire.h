/*
 * api/model_wire — the byte format in which the sandboxed importer (api/sandbox_child.c)
 * hands an imported model or a decoded image back to the daemon (api/sandbox.c), and the
 * daemon's decoder of it.
 *
 * The importer runs untrusted parsers (Assimp, libpng, libjpeg) on untrusted bytes: whatever
 * it writes back may have been shaped by an attacker who took it over. So the decoder treats a
 * reply exactly like request input: every count is checked against the bytes that remain
 * before anything is allocated, every size multiplication is overflow-checked, every index is
 * bounded, every float is finite and in its range. A reply either decodes completely into the
 * caller's arena or is refused with a sentence; it never reads outside [data, data + len).
 *
 * Layout (host byte order: both ends are the same build on the same machine), all fields
 * 4 bytes:
 *   header   "UMBRAIMP" version kind status msg_len, then msg_len bytes of message
 *            (status != OK: the reply ends there)
 *   image    width height, width*height*4 bytes RGBA8
 *   model    the importer's stage times f32[4] (parse, textures, closed, level: ms, finite, >= 0),
 *            texture_side texture_max (u32: api_model's),
 *            texture_count material_count mesh_count instance_count warnings_len,
 *            warnings_len bytes of warnings (printable ASCII, at most API_MODEL_MAX_WARNINGS),
 *            zeros to a multiple of 4 bytes (every array below starts 4-byte aligned)
 *            textures:  width height, width*height*4 bytes RGBA8
 *            materials: base_color[4] roughness metallic emissive[3] alpha_cutoff normal_scale
 *                       occlusion_strength see_through (f32), alpha_mode (u32),
 *                       texture[13] (i32 per rnd_texture_slot, -1 = none), then per slot the
 *                       sampling: wrap_s | wrap_t << 2 | mag_nearest << 4 | min_nearest << 5 |
 *                       transformed << 6 | mip << 7 (u32, enum rnd_mip) | uv_set << 9 (0 or 1),
 *                       transform f32[6]; then the PBR extensions: bits (u32, RND_EXT_*, and
 *                       1 << 16 for specular.spec_gloss),
 *                       clearcoat factor roughness normal_scale, sheen colour[3] roughness,
 *                       specular factor colour[3] ior (f32)
 *            meshes:    vertex_count index_count material flags(1 normals, 2 uvs, 4 colours,
 *                       8 tangents, 16 single-sided, 32 closed, 64 levels, 128 second uv set,
 *                       256 caster level, 512 the indices are 0..v-1: index_count = v and
 *                       none are sent, the daemon counts them out),
 *                       positions f32[3v], normals f32[3v], uvs f32[2v], uvs1 f32[2v], colours
 *                       u8[4v], tangents f32[4v], indices
 *                       u32[i] (none with flag 512), then with flag 64 the mesh's levels as below (level_count ...),
 *                       then with flag 256 its caster level (api/model_caster.h): vertex_count
 *                       index_count error(f32), positions f32[3v], indices u32[i]
 *            instances: mesh (u32), model matrix f32[16] (column-major)
 *   Nothing may follow the last instance.
 *   levels   (a levels-of-detail job: its input is a model, its reply this) mesh_count, then per
 *            mesh level_count (at most API_LOD_LEVELS), per level vertex_count index_count
 *            flags(1 uvs, 2 second uv set, 4 colours, 8 tangents) error(f32), positions f32[3v],
 *            normals f32[3v], uvs f32[2v], uvs1 f32[2v], colours u8[4v] (linear RGBA), tangents
 *            f32[4v] (xyzw), indices u32[i]
 *
 * Usage (parent): api_wire_header(); then api_wire_decode_model() / _image() on the body.
 * Usage (child):  struct api_wire_buf b = {.fd = fd}; api_wire_put_model(&b, model); api_wire_flush(&b).
 * Threading: no shared state.
 */
#ifndef UMBRA_API_MODEL_WIRE_H
#define UMBRA_API_MODEL_WIRE_H

#include <stddef.h>
#include <stdint.h>
#include "arena.h"
#include "model.h"
#include "model_lod.h"

#define API_WIRE_MAGIC "UMBRAIMP"
#define API_WIRE_VERSION 11u
/* Beside the RND_EXT_* bits of a material: its specular.spec_gloss. */
#define API_WIRE_SPEC_GLOSS (1u << 16)
#define API_WIRE_MAX_MESSAGE 1024u
#define API_WIRE_MAX_TEXTURES 4096u   /* distinct textures in one reply */

enum api_wire_kind { API_WIRE_MODEL = 1, API_WIRE_IMAGE = 2, API_WIRE_LEVELS = 3 };
/* What the importer says about the input (a crash says nothing: see api/sandbox.h). */
enum api_wire_status { API_WIRE_OK = 0, API_WIRE_BAD_INPUT = 1, API_WIRE_OVER_MEMORY = 2 };

/* An output buffer (child side): growable in memory (zero-initialised), or a sink (.fd set):
 * written out to that file as it goes (the importer's reply file, api/sandbox.h), small puts
 * gathered in data, big arrays written from where they lie; len counts every byte put. Any
 * failed put (out of memory, a failed write) leaves failed set and keeps data. */
struct api_wire_buf {
	uint8_t *data;
	size_t len, cap;
	int failed;
	int fd;          /* > 0: a sink */
	size_t staged;   /* a sink's bytes in data not written yet */
};
void api_wire_buf_release(struct api_wire_buf *b);
/* A sink's staged bytes written out: 0, or -1 when any put or write failed. */
int api_wire_flush(struct api_wire_buf *b);
/* Header with a message (status != OK) or with none (OK; the body follows). */
void api_wire_put_header(struct api_wire_buf *b, enum api_wire_kind kind, enum api_wire_status st,
                         const char *msg);
void api_wire_put_model(struct api_wire_buf *b, const struct api_model *m);
void api_wire_put_image(struct api_wire_buf *b, const uint8_t *rgba, uint32_t w, uint32_t h);

/* Parses the header. On API_OK: *kind, *status, the message (NUL-terminated copy in msg) and
 * the body (what follows the header). API_ERR with a sentence in err when it is malformed. */
enum api_result api_wire_header(const uint8_t *data, size_t len, enum api_wire_kind *kind,
                                enum api_wire_status *status, char *msg, size_t msgsize,
                                const uint8_t **body, size_t *body_len, char *err, size_t errsize);

/* How the decoders keep the arrays: copied into the arena (0), or, with API_WIRE_IN_PLACE,
 * pointed to where they lie in the body when 4-byte aligned (copied when not): the caller
 * promises that the body stays, unchanged, as long as the arena (the sandbox's replies: a
 * sealed mapping the arena then owns, api/sandbox.c). Checked the same either way. */
#define API_WIRE_IN_PLACE 1u

/* Decodes a model body into arena memory: fills the public part of *out (meshes, instances,
 * materials with their textures, triangles) and *bytes (what it allocated, or for arrays kept
 * in place what they hold). max_texture_pixels bounds each texture. API_ERR with a sentence in
 * err: nothing of *out is valid then (the arena still owns whatever was allocated). */
enum api_result api_wire_decode_model(const uint8_t *body, size_t len, unsigned flags, struct api_arena *arena,
                                      uint64_t max_texture_pixels, struct api_model *out, size_t *bytes,
                                      char *err, size_t errsize);
void api_wire_put_levels(struct api_wire_buf *b, const struct api_model *m);
/* Decodes a levels body for meshes[0..nmesh) (those the job was sent, in that order; their
 * bounds set) into out[nmesh]: every level coarser than the one before, its vertices inside the
 * mesh's bounds, its error no smaller than the one before. */
enum api_result api_wire_decode_levels(const uint8_t *body, size_t len, unsigned flags,
                                       const struct api_model_mesh *const *meshes, uint32_t nmesh,
                                       struct api_arena *arena, struct api_mesh_levels *out, size_t *bytes,
                                       char *err, size_t errsize);
/* Decodes an image body into malloc'd RGBA8 (*rgba, you free it). */
enum api_result api_wire_decode_image(const uint8_t *body, size_t len, uint64_t max_pixels, uint8_t **rgba,
                                      uint32_t *w, uint32_t *h, char *err, size_t errsize);

#endif
