#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Debug view `atlas`: the shadow depth atlas as a grey image (depth 0 black, 1 white: empty
// texels are white), nearest texel, the whole atlas stretched over the output.
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SHADOW_MAP) uniform sampler2D shadow_atlas;
layout(location = 0) in vec2 v_uv;
layout(location = 0) out vec4 o_color;
void main()
{
	ivec2 size = textureSize(shadow_atlas, 0);
	ivec2 t = clamp(ivec2(v_uv * vec2(size)), ivec2(0), size - 1);
	o_color = vec4(vec3(texelFetch(shadow_atlas, t, 0).r), 1.0);
}
