#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Depth bounds of a PCSS shadow map just drawn (copied to the slot's scratch buffer, res x res
// floats) into the blocks of the map's tile (layout: umbra_shared.h, UMBRA_BOUNDS_BLOCK).
// Pass 0: per block, a plane of its depths lowered until no depth lies below it, and the
// height of the highest depth above it. Pass 1: per block, the lowest and highest
// depth of it and its neighbours, from pass 0's planes. pcss() in shading.glsl reads them to
// skip its blocker search where no caster can be near and where the point lies deep in umbra.
// One invocation per block: tiles are a few dozen blocks a side, and lavapipe's per-dispatch
// cost grows with the workgroup count. (Four blocks a workgroup, an invocation per column with
// a shared-memory reduction, read memory in order but took three times as long on lavapipe:
// its barriers are expensive.)
layout(local_size_x = 8, local_size_y = 8) in;
// Read four floats at a time (rows of a block are 16-byte aligned): lavapipe loads lane by lane
// when the lanes' addresses differ, so a quarter of the loads is most of the saving.
layout(std430, set = 0, binding = UMBRA_MINMAX_BINDING_DEPTH) readonly buffer Scratch { vec4 scratch[]; };
layout(set = 0, binding = UMBRA_MINMAX_BINDING_BOUNDS, rgba32f) uniform image2D bounds_img;
layout(push_constant) uniform Push {
	uvec4 info;   // x, y: tile offset in the atlas (texels); z pass
	vec4 params;  // z tile size (texels)
	vec4 proj;    // unused
} pc;

const int B = UMBRA_BOUNDS_BLOCK;
const float HALF = 0.5 * float(B - 1);   // texel centres relative to the block centre: -HALF..HALF

ivec2 texel(ivec2 blk, int which)
{
	ivec2 a = ivec2(pc.info.xy) / B + blk;
	return ivec2(a.x * UMBRA_BOUNDS_TEXELS + which, a.y);
}

void plane(ivec2 blk, int res)
{
	int row0 = (blk.y * B * res + blk.x * B) / 4, row1 = row0 + (B - 1) * res / 4;   // in vec4s
	// The plane through the corners (exact on a flat receiver, where the bounds matter most;
	// any plane gives true bounds), then how far the depths lie from it.
	float d00 = scratch[row0].x, d10 = scratch[row0 + B / 4 - 1].w, d01 = scratch[row1].x, d11 = scratch[row1 + B / 4 - 1].w;
	vec2 g = vec2((d10 - d00) + (d11 - d01), (d01 - d00) + (d11 - d10)) / (2.0 * float(B - 1));
	float c = 0.25 * (d00 + d10 + d01 + d11);
	float lo = 1e30, hi = -1e30;
	for (int y = 0; y < B; y++) {
		float py = c + g.y * (float(y) - HALF);
		for (int x = 0; x < B; x += 4) {
			vec4 r = scratch[row0 + (y * res + x) / 4] - (py + g.x * (vec4(x, x + 1, x + 2, x + 3) - HALF));
			lo = min(lo, min(min(r.x, r.y), min(r.z, r.w)));
			hi = max(hi, max(max(r.x, r.y), max(r.z, r.w)));
		}
	}
	// Rounding here and in the reader: a little lower and a little higher (depths 0..1) keep
	// the bounds true.
	imageStore(bounds_img, texel(blk, 0), vec4(c + lo - 2e-7, g, hi - lo + 4e-7));
}

void neighbourhood(ivec2 blk, int blocks)
{
	const int R = UMBRA_BOUNDS_RING;
	vec2 r = vec2(1e30, -1e30);
	for (int y = max(blk.y - R, 0); y <= min(blk.y + R, blocks - 1); y++)
		for (int x = max(blk.x - R, 0); x <= min(blk.x + R, blocks - 1); x++) {
			vec4 p = imageLoad(bounds_img, texel(ivec2(x, y), 0));
			float tilt = (abs(p.y) + abs(p.z)) * HALF;
			r = vec2(min(r.x, p.x - tilt), max(r.y, p.x + p.w + tilt));
		}
	imageStore(bounds_img, texel(blk, 1), vec4(r.x - 2e-7, r.y + 2e-7, 0.0, 0.0));
}

void main()
{
	int res = int(pc.params.z);
	ivec2 blk = ivec2(gl_GlobalInvocationID.xy);
	if (any(greaterThanEqual(blk * B, ivec2(res)))) return;
	if (pc.info.z == 0u) plane(blk, res);
	else neighbourhood(blk, res / B);
}
