#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// The surfaces pass (single-sample, before the visibility pass): what the main pass will shade
// at each pixel centre, its world position (float) and the plane of its triangle (facet.glsl,
// the normal mesh_main.glsl hands the shadow lookups; 16 bits a component,
// renderer/internal.h): the shadow filters' receiver plane comes from that normal, and one
// rounded to 12-bit octahedral coordinates put acne on a face lit at a grazing angle
// (studio-spots: a box face speckled; with 16 bits the image is that of float normals).
layout(location = 0) in vec3 v_pos;
layout(location = 1) in vec3 v_nrm;
layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_normal;
#include "facet.glsl"
void main()
{
	vec3 n = normalize(v_nrm);
	if (!gl_FrontFacing) n = -n;
	o_position = vec4(v_pos, 1.0);
	o_normal = vec4(facet_normal(v_pos, n), 0.0);
}
