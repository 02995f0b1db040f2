#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Alpha-tested depth passes (shadow maps and the camera's depth pre-pass) of alpha_mode MASK
// and BLEND materials: position through pc.view_proj, plus what alpha depends on (texture
// coordinates and the vertex colour's alpha).
layout(push_constant) uniform PushBlock { umbra_push pc; };
layout(location = 0) in vec3 a_pos;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec4 a_color;
layout(location = UMBRA_LOCATION_UV1) in vec2 a_uv1;
layout(location = 2) out vec2 v_uv;
layout(location = 3) out float v_alpha;
layout(location = UMBRA_LOCATION_UV1) out vec2 v_uv1;
void main()
{
	v_uv = a_uv;
	v_alpha = a_color.a;
	v_uv1 = a_uv1;
	precise vec4 clip = pc.view_proj * vec4(a_pos, 1.0);
	gl_Position = clip;
}
