#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "umbra_shared.h"
#include "shading.glsl"
// AOV pass (single-sample, after the main pass): writes what EXR outputs carry besides colour.
// Pass 0: (Z, N.x, N.y, N.z), (albedo.rgb, 1), visibility of lights 0..3, lights 4..7.
// Pass k > 0: visibility of lights UMBRA_AOV_PASS_FIRST_LIGHT(k) ... in four vec4s.
// pc.info.z = first light. The packing is umbra_shared.h's UMBRA_AOV_*.
// Visibility is the shadow test alone (no N.L, cone or range), 1 where shadows are off.

layout(location = 0) out vec4 o_aov0;
layout(location = 1) out vec4 o_aov1;
layout(location = 2) out vec4 o_aov2;
layout(location = 3) out vec4 o_aov3;

// p_shadow, n_shadow: where the lookups look (facet.glsl surface_at), as the beauty pass's.
float visibility(uint i, vec3 p_shadow, vec3 n_shadow, bool receive)
{
	if (i >= frame.mode.w || !receive || SC_FILTERS == 0u) return 1.0;
	umbra_light L = lights[i];
	if ((SC_LIGHT_TYPES & (1u << uint(L.color.w))) == 0u) return 1.0;
	float atten;
	vec3 l = light_dir(L, v_pos, atten);
	uint view;
	return shadow_visibility(L, p_shadow, n_shadow, l, SC_FILTERS, view);
}

void main()
{
	material_derivatives(v_uv, v_uv1);
	umbra_material m = materials[pc.info.x];
	vec3 n_geo, p_shadow, n_shadow;   // before base_color's discard
	surface_at(in_pos, v_nrm, v_uv, pc.info.y, 1u, v_pos, n_geo, p_shadow, n_shadow);
	vec4 bc = base_color(m);
	// N.X/Y/Z: the normal the beauty pass shades with (normal map included); shadows keep
	// testing with the triangle's plane, as the beauty pass does.
	vec3 N = material_normal(m, n_geo, has_tex(m, UMBRA_TEX_NORMAL));
	bool receive = (pc.info.y & UMBRA_DRAW_RECEIVE_SHADOWS) != 0u;
	uint first = pc.info.z;
	// One call site of visibility() in a loop the compiler keeps: written out once per light
	// (8 or 16 copies of every shadow filter), lavapipe's JIT took minutes on this shader
	// with PCSS lights, inside the render's first submit.
	float vis[UMBRA_AOV_PASS_LIGHTS];
	uint count = first == 0u ? UMBRA_AOV_FIRST_PASS_LIGHTS : UMBRA_AOV_PASS_LIGHTS;
	[[dont_unroll]] for (uint k = 0u; k < UMBRA_AOV_PASS_LIGHTS; k++)
		vis[k] = k < count ? visibility(first + k, p_shadow, n_shadow, receive) : 1.0;
	if (first == 0u) {
		float z = dot(v_pos - frame.camera_pos.xyz, frame.camera_fwd.xyz);
		o_aov0 = vec4(z, N);
		o_aov1 = vec4(bc.rgb, 1.0);
		o_aov2 = vec4(vis[0], vis[1], vis[2], vis[3]);
		o_aov3 = vec4(vis[4], vis[5], vis[6], vis[7]);
	} else {
		o_aov0 = vec4(vis[0], vis[1], vis[2], vis[3]);
		o_aov1 = vec4(vis[4], vis[5], vis[6], vis[7]);
		o_aov2 = vec4(vis[8], vis[9], vis[10], vis[11]);
		o_aov3 = vec4(vis[12], vis[13], vis[14], vis[15]);
	}
}
