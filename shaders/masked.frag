#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Alpha test of the depth-only passes: masked texels write no depth, so they cast no shadow
// and hide nothing; BLEND surfaces keep the dithered share of their texels, so they cast a
// shadow in proportion to their coverage once the shadow filter averages it. Opaque casters
// keep the fragment-shader-free pipeline.
layout(std430, set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_MATERIALS) readonly buffer Materials { umbra_material materials[]; };
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_BINDING_BASE_TEXTURE) uniform sampler2D base_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_TRANSMISSION) uniform sampler2D transmission_texture;
layout(push_constant) uniform PushBlock { umbra_push pc; };
// A depth pass is not specialised by the scene's textures: the uv1 bits of the material
// decide (the renderer sets them only where the scene has a second uv set).
const uint SC_TEXTURES = 0xffffffffu;
#define UMBRA_MATERIAL_DEPTH_PASS
#include "material.glsl"
layout(location = 2) in vec2 v_uv;
layout(location = 3) in float v_alpha;
layout(location = UMBRA_LOCATION_UV1) in vec2 v_uv1;
void main()
{
	material_derivatives(v_uv, v_uv1);
	umbra_material m = materials[pc.info.x];
	float a = m.base_color.a * v_alpha;
	if ((m.tex.x & (1u << UMBRA_TEX_BASE)) != 0u) a *= material_texture(base_texture, m, UMBRA_TEX_BASE, v_uv, v_uv1).a;
	if ((m.tex.x & (1u << UMBRA_TEX_TRANSMISSION)) != 0u)
		a *= see_through_keep(transmission_texture, m, m.ext.z, v_uv, v_uv1);
	if (!alpha_keep(m, a, gl_FragCoord.xy)) discard;
}
