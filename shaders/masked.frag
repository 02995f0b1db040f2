#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Alpha test of the depth-only passes: masked texels write no depth, so they cast no shadow
// and hide nothing. Opaque casters keep the fragment-shader-free pipeline.
layout(std430, set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_MATERIALS) readonly buffer Materials { umbra_material materials[]; };
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_BINDING_BASE_TEXTURE) uniform sampler2D base_texture;
layout(push_constant) uniform PushBlock { umbra_push pc; };
layout(location = 2) in vec2 v_uv;
void main()
{
	umbra_material m = materials[pc.info.x];
	float a = m.base_color.a;
	if (m.tex.x != 0u) a *= texture(base_texture, v_uv).a;
	if (a < m.params.y) discard;
}
