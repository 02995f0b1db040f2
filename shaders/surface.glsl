// shaders/surface.glsl — the surfaces pass (single-sample, before the visibility pass): what the
// main pass will shade at each pixel centre, its world position (float) and the plane of its
// triangle (facet.glsl, the normal mesh_main.glsl hands the shadow lookups; 16 bits a
// component, renderer/internal.h): the shadow filters' receiver plane comes from that normal,
// and one rounded to 12-bit octahedral coordinates put acne on a face lit at a grazing angle
// (studio-spots: a box face speckled; with 16 bits the image is that of float normals).
// surface.frag writes those two; surface_shade.frag (UMBRA_SURFACE_SHADING, pixel shading:
// renderer/deferred.c) also what shading the point needs (umbra_shared.h UMBRA_SHADING_*).
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_FRAME) uniform FrameBlock { umbra_frame frame; };
layout(push_constant) uniform PushBlock { umbra_push pc; };
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 v_nrm;
layout(location = 2) in vec2 v_uv;
layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_normal;
#ifdef UMBRA_SURFACE_SHADING
layout(location = 3) in vec4 v_color;
layout(location = 2) out uvec4 o_shading;
#include "octahedral.glsl"
#endif
#include "facet.glsl"
void main()
{
	vec3 pos, n_geo, p_shadow, n_shadow;
	surface_at(in_pos, v_nrm, v_uv, pc.info.y, 1u, pos, n_geo, p_shadow, n_shadow);
	o_position = vec4(p_shadow, 1.0);   // where its shadow lookups look: pos, or raised by a proxy's lift
	o_normal = vec4(n_shadow, 0.0);
#ifdef UMBRA_SURFACE_SHADING
	o_shading = uvec4(packSnorm2x16(oct_encode(n_geo)), packUnorm2x16(v_color.rg), packUnorm2x16(v_color.ba),
	                  (pc.info.x & ((1u << UMBRA_SHADING_MATERIAL_BITS) - 1u)) | (pc.info.y << UMBRA_SHADING_MATERIAL_BITS));
#endif
}
