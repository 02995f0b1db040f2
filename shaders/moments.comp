#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Moment shadow maps (VSM, EVSM2) from a depth layer, with a separable Gaussian blur.
// Pass 0: depth -> moments, horizontal blur -> tmp. Pass 1: vertical blur tmp -> moments.
// One implementation for every light type: it works on whichever layer it is given.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_DEPTH) uniform sampler2DArray depth_map;
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_TMP, rg32f) uniform image2DArray tmp_img;
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_OUT) writeonly uniform image2DArray out_img;
layout(push_constant) uniform Push {
	uvec4 info;   // x layer, y pass, z radius (texels), w resolution
	vec4 params;  // x exponent (0 = VSM: plain depth), y sigma (texels)
} pc;

vec2 to_moments(float d)
{
	if (pc.params.x <= 0.0) return vec2(d, d * d);
	float e = exp(pc.params.x * d);   // EVSM2: positive exponential warp
	return vec2(e, e * e);
}

void main()
{
	ivec2 p = ivec2(gl_GlobalInvocationID.xy);
	int res = int(pc.info.w);
	if (p.x >= res || p.y >= res) return;
	int layer = int(pc.info.x);
	int r = int(pc.info.z);
	float sigma = max(pc.params.y, 0.5);
	vec2 sum = vec2(0.0);
	float wsum = 0.0;
	for (int k = -r; k <= r; k++) {
		float w = exp(-0.5 * float(k * k) / (sigma * sigma));
		vec2 m;
		if (pc.info.y == 0u) {
			ivec2 q = ivec2(clamp(p.x + k, 0, res - 1), p.y);
			m = to_moments(texelFetch(depth_map, ivec3(q, layer), 0).r);
		} else {
			ivec2 q = ivec2(p.x, clamp(p.y + k, 0, res - 1));
			m = imageLoad(tmp_img, ivec3(q, layer)).xy;
		}
		sum += w * m;
		wsum += w;
	}
	vec4 v = vec4(sum / wsum, 0.0, 1.0);
	if (pc.info.y == 0u) imageStore(tmp_img, ivec3(p, layer), v);
	else imageStore(out_img, ivec3(p, layer), v);
}
