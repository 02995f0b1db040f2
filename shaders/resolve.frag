#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Pixel shading's resolve (renderer/deferred.c): a fullscreen triangle over the view writing the
// final colour of each pixel from its four depth samples (the main pass drawn depth-only, MSAA 4)
// and the colours shaded at pixel centres (vis_shade.frag). Each sample takes the colour of the
// pixel centre, among its own and its four neighbours', whose surface (the plane of its
// triangle, from the surfaces pass) passes nearest to where the sample's depth puts it; a
// sample with nothing drawn takes the background. The mean of the four is the pixel, as the
// MSAA resolve of per-fragment shading makes it; inside a surface every sample takes its own
// pixel's colour. A surface thinner than a pixel that no centre shows takes a neighbour's.
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_FRAME) uniform FrameBlock { umbra_frame frame; };
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SURFACES) uniform sampler2D surfaces;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SURFACE_NORMALS) uniform sampler2D surface_normals;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SHADED) uniform sampler2D shaded;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_VIEW_DEPTH_MS) uniform sampler2DMS view_depth;
layout(location = 0) out vec4 o_color;

// Vulkan's standard locations of 4 samples (renderer/deferred.c requires standardSampleLocations).
const vec2 SAMPLE_AT[4] = vec2[4](vec2(0.375, 0.125), vec2(0.875, 0.375), vec2(0.125, 0.625), vec2(0.625, 0.875));
const ivec2 AROUND[5] = ivec2[5](ivec2(0, 0), ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));

void main()
{
	ivec2 px = ivec2(gl_FragCoord.xy), last = ivec2(frame.target.xy) - 1;
	vec4 at[5];
	vec3 nrm[5];
	ivec2 q[5];
	for (int k = 0; k < 5; k++) {
		q[k] = clamp(px + AROUND[k], ivec2(0), last);
		at[k] = texelFetch(surfaces, q[k], 0);
		nrm[k] = texelFetch(surface_normals, q[k], 0).xyz;
	}
	vec4 sum = vec4(0.0);
	for (int s = 0; s < 4; s++) {
		float d = texelFetch(view_depth, px, s).r;   // reversed Z: 0 where nothing was drawn
		vec2 ndc = (vec2(px) + SAMPLE_AT[s]) / frame.target.xy * 2.0 - 1.0;
		vec4 h = frame.inv_view_proj * vec4(ndc, d, 1.0);
		vec3 w = h.xyz / h.w;
		// Its own pixel's surface where it passes within half a pixel (as vis_pixel takes it),
		// else the candidate nearest the sample: inside a surface a sample never takes a
		// neighbour's colour (a dense mesh's triangles lean off the centre's plane by more than
		// the plane of a neighbour pixel does).
		float z = max(dot(w - frame.camera_pos.xyz, frame.camera_fwd.xyz), 1e-4);
		float tol = 0.5 * frame.target.z * (frame.target.w > 0.5 ? 1.0 : z);
		int best = -1;
		float best_d = 3.4e38;
		for (int k = 0; k < 5; k++) {
			float e = at[k].w != 0.0 ? abs(dot(nrm[k], w - at[k].xyz)) : 3.4e38;
			if (k == 0 && e <= tol) e = 0.0;
			if (e < best_d) { best_d = e; best = k; }
		}
		sum += d > 0.0 && best >= 0 ? texelFetch(shaded, q[max(best, 0)], 0) : frame.clear;
	}
	o_color = sum * 0.25;
}
