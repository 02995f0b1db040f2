#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Main pass: vertices arrive in world space (tessellated and transformed on the CPU).
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_FRAME) uniform FrameBlock { umbra_frame frame; };
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec4 a_color;    // linear RGBA (glTF COLOR_0), white when none
layout(location = 4) in vec4 a_tangent;  // xyz world tangent, w bitangent sign
layout(location = UMBRA_LOCATION_UV1) in vec2 a_uv1;   // the second uv set (umbra_shared.h)
layout(location = 0) out vec3 v_pos;
layout(location = 1) out vec3 v_nrm;
layout(location = 2) out vec2 v_uv;
layout(location = 3) out vec4 v_color;
layout(location = 4) out vec4 v_tangent;
layout(location = UMBRA_LOCATION_UV1) out vec2 v_uv1;
void main()
{
	v_pos = a_pos;
	v_nrm = a_nrm;
	v_uv = a_uv;
	// Outputs a specialised fragment shader does not read are dropped when the pipeline links.
	v_color = a_color;
	v_tangent = a_tangent;
	v_uv1 = a_uv1;
	// The depth pre-pass and the main pass run this same code and must produce bit-identical
	// depth (EQUAL test): `precise` forbids contractions that could differ between pipelines.
	precise vec4 clip = frame.view_proj * vec4(a_pos, 1.0);
	gl_Position = clip;
}
