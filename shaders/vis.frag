#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
#define UMBRA_VIS_PASS   // shading.glsl: surface inputs are globals set here, not varyings
#include "shading.glsl"
// The visibility pass (a fullscreen triangle over the surfaces pass's depth, single-sample,
// between the shadow maps and the main pass): each shadowed light's shadow at the surface each
// pixel shows, computed once per pixel with the very functions the main pass would run
// (shading.glsl shadow_visibility), stored for the main pass (mesh_vis.frag) to read. lavapipe
// shades whole 4x4 blocks per triangle, so the main pass ran the filters for every small
// triangle touching a block; here they run once per block of pixels.
// The depth test (LESS against the surfaces' reversed-Z depth, the triangle at 0) fails where
// nothing was drawn, before the shader: lavapipe skips a block whose pixels all fail it, and
// would otherwise run every filter there under a mask. early_fragment_tests: a shader that
// stores to an image would otherwise be tested after it runs.
layout(early_fragment_tests) in;

void main()
{
	ivec2 px = ivec2(gl_FragCoord.xy);
	vis_frag_xy = gl_FragCoord.xy;
	v_pos = texelFetch(surfaces, px, 0).xyz;
	store_visibility(px, texelFetch(surface_normals, px, 0).xyz);
}
