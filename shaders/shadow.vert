#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Depth-only shadow pass: world-space positions through the light's view-projection.
layout(push_constant) uniform PushBlock { umbra_push pc; };
layout(location = 0) in vec3 a_pos;
void main()
{
	gl_Position = pc.view_proj * vec4(a_pos, 1.0);
}
