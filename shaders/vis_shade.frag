#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
#define UMBRA_VIS_PASS    // shading.glsl: surface inputs are globals set here, not varyings
#define UMBRA_VIS_SHADE   // light_all filters the shadows itself (nothing reads a visibility image)
#include "shading.glsl"
#include "shade.glsl"
#include "octahedral.glsl"
// Pixel shading (renderer/deferred.c): the visibility pass's fullscreen triangle shading, once
// per pixel centre, the surface the surfaces pass left there (surface_shade.frag) with the very
// function the main pass calls per fragment (shade.glsl), into an image of the output's colour
// format; resolve.frag then gives each of a pixel's samples the colour of the pixel centre
// nearby that shows its surface. lavapipe shades a 4x4 block once per triangle touching it, and
// with MSAA once per triangle covering any sample: a 100k-triangle mesh in a 256^2 thumbnail
// ran the whole shading ~6 times a pixel. The same depth test as vis.frag: nothing drawn,
// nothing shaded.
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SURFACE_SHADING) uniform usampler2D surface_shading;
layout(early_fragment_tests) in;
layout(location = 0) out vec4 o_color;

void main()
{
	ivec2 px = ivec2(gl_FragCoord.xy);
	vis_frag_xy = gl_FragCoord.xy;
	v_pos = texelFetch(surfaces, px, 0).xyz;
	vec3 n_shadow = texelFetch(surface_normals, px, 0).xyz;
	uvec4 g = texelFetch(surface_shading, px, 0);
	vec3 n_geo = oct_decode(unpackSnorm2x16(g.x));
	v_color = vec4(unpackUnorm2x16(g.y), unpackUnorm2x16(g.z));
	umbra_material m = materials[g.w & ((1u << UMBRA_SHADING_MATERIAL_BITS) - 1u)];
	// the vertex colour is white where the mesh has none (mesh.vert): one variant for both
	vec4 bc = m.base_color * v_color;
	o_color = shade(m, g.w >> UMBRA_SHADING_MATERIAL_BITS, bc, n_geo, v_pos, n_shadow);
}
