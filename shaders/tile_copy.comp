#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Copies a shadow map from the slot's scratch buffer (the scratch depth image, drawn at the
// origin and copied out row by row) into its tile of the depth atlas. The atlas is an R32F
// storage image, always in GENERAL layout, because other renders sample other tiles of it
// while this one writes. (Sampling the depth image itself in a compute shader makes lavapipe
// allocate and convert a copy of it on every dispatch.)
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, set = 0, binding = UMBRA_MOMENTS_BINDING_DEPTH) readonly buffer Scratch { float scratch[]; };
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_ATLAS, r32f) writeonly uniform image2D depth_atlas;
layout(push_constant) uniform Push {
	uvec4 info;   // x, y: tile offset in the atlas; z unused; w unused
	vec4 params;  // z tile size
	vec4 proj;
} pc;
// Each invocation copies a 16x16 block: few, large workgroups (lavapipe's per-dispatch cost
// grows with the workgroup count).
void main()
{
	int res = int(pc.params.z);
	for (int by = 0; by < 16; by++)
		for (int bx = 0; bx < 16; bx++) {
			ivec2 p = ivec2(gl_GlobalInvocationID.xy) * 16 + ivec2(bx, by);
			if (p.x < res && p.y < res) imageStore(depth_atlas, ivec2(pc.info.xy) + p, vec4(scratch[p.y * res + p.x]));
		}
}
