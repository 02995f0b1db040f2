#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
#define UMBRA_ENV_PASS_FRAG   // shading.glsl: surface inputs are globals set here, not varyings
#include "shading.glsl"
#include "ibl.glsl"
// The environment pass (renderer/env_pass.c): a fullscreen triangle over the view's surfaces at
// 1 / env.pass.x of its pixels a side, writing the environment's visibility there
// (ibl.glsl env_visibility: a PCSS lookup per shadow direction, weighed by its light on the
// geometric normal). Its shadows are soft: computed once per pass texel, not per fragment of
// every triangle the main pass shades, and read back with a bilateral upsample (env_pass_read).
layout(location = 0) out vec4 o_vis;

void main()
{
	ivec2 px = ivec2(gl_FragCoord.xy);
	vis_frag_xy = gl_FragCoord.xy;
	vec4 s = texelFetch(env_surfaces, px, 0);
	if (s.w == 0.0) {   // nothing drawn here: every pixel of a block that returns skips the lookups
		o_vis = vec4(1.0);
		return;
	}
	v_pos = s.xyz;
	vec3 n = texelFetch(env_normals, px, 0).xyz;
	o_vis = vec4(env_visibility(v_pos, n, n));
}
