/*
 * tests/fuzz/fuzz_import_reply.c — libFuzzer target for the daemon's decoder of the sandboxed
 * importer's replies (api/model_wire.h). A reply is untrusted: the child that wrote it parsed
 * attacker bytes and may be under the attacker's control. Any bytes must decode into a
 * consistent model / image or be refused, never read out of bounds, leak or hit UB.
 *
 *   make fuzz && build/fuzz/fuzz_import_reply -max_total_time=60 build/fuzz/corpus-reply tests/fuzz/corpus/fuzz_import_reply
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "api.h"
#include "arena.h"
#include "model_wire.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	enum api_wire_kind kind;
	enum api_wire_status st;
	const uint8_t *body;
	size_t blen;
	char msg[API_WIRE_MAX_MESSAGE + 1], err[300];
	if (api_wire_header(data, size, &kind, &st, msg, sizeof msg, &body, &blen, err, sizeof err) != API_OK ||
	    st != API_WIRE_OK)
		return 0;
	if (kind == API_WIRE_IMAGE) {
		uint8_t *px;
		uint32_t w, h;
		if (api_wire_decode_image(body, blen, 1u << 20, &px, &w, &h, err, sizeof err) == API_OK) {
			if ((uint64_t)w * h > (1u << 20)) abort();
			free(px);
		}
		return 0;
	}
	/* Copied (0) and in place, from a copy of the input that outlives the arena (the fuzzer's
	 * own buffer is not 4-byte aligned where the body starts, nor kept). */
	unsigned flags = size & 1 ? API_WIRE_IN_PLACE : 0;
	uint8_t *copy = flags ? malloc(blen ? blen : 1) : NULL;
	if (copy) {
		memcpy(copy, body, blen);
		body = copy;
	}
	struct api_arena *a = api_arena_create();
	struct api_model m;
	size_t bytes;
	if (api_wire_decode_model(body, blen, flags, a, 1u << 20, &m, &bytes, err, sizeof err) == API_OK) {
		uint64_t tris = 0;
		for (uint32_t i = 0; i < m.instance_count; i++) {
			if (m.instances[i].mesh >= m.mesh_count) abort();
			tris += m.meshes[m.instances[i].mesh].index_count / 3;
		}
		for (uint32_t i = 0; i < m.mesh_count; i++)
			for (uint32_t k = 0; k < m.meshes[i].index_count; k++)
				if (m.meshes[i].indices[k] >= m.meshes[i].vertex_count) abort();
		if (tris != m.triangles) abort();
	}
	api_arena_destroy(a);
	free(copy);
	return 0;
}
