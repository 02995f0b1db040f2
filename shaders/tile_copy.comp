#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Copies a shadow map from the slot's scratch depth image (drawn at the origin) into its tile
// of the depth atlas. The atlas is an R32F storage image, always in GENERAL layout, because
// other renders sample other tiles of it while this one writes.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_DEPTH) uniform sampler2D scratch;
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_ATLAS, r32f) writeonly uniform image2D depth_atlas;
layout(push_constant) uniform Push {
	uvec4 info;   // x, y: tile offset in the atlas; z unused; w unused
	vec4 params;  // z tile size
	vec4 proj;
} pc;
void main()
{
	ivec2 p = ivec2(gl_GlobalInvocationID.xy);
	int res = int(pc.params.z);
	if (p.x >= res || p.y >= res) return;
	imageStore(depth_atlas, ivec2(pc.info.xy) + p, vec4(texelFetch(scratch, p, 0).r));
}
