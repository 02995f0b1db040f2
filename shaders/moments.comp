#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Moment shadow maps (VSM, EVSM2) from a shadow map just drawn in the slot's scratch depth
// image (and copied to the scratch buffer), with a separable Gaussian blur. Pass 0: depth -> moments, horizontal blur -> tmp.
// Pass 1: vertical blur tmp -> the map's tile of the moment atlas. One implementation for
// every light type.
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, set = 0, binding = UMBRA_MOMENTS_BINDING_DEPTH) readonly buffer Scratch { float scratch[]; };
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_TMP, rg32f) uniform image2D tmp_img;
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_OUT) writeonly uniform image2D out_img;
layout(push_constant) uniform Push {
	uvec4 info;   // x, y: tile offset in the atlas; z pass; w blur radius (texels)
	vec4 params;  // x exponent (0 = VSM: plain depth), y sigma (texels), z tile size
	vec4 proj;    // x near, y far, z 1 = perspective view (depth is made linear first)
} pc;

vec2 to_moments(float d)
{
	// Perspective depth crowds near 1: moments of it would have no variance to speak of.
	// Linear depth over near..far instead (mesh.frag's moments() does the same to its ref).
	if (pc.proj.z > 0.5) {
		float n = pc.proj.x, f = pc.proj.y;
		d = (n * f / (f - d * (f - n)) - n) / (f - n);
	}
	if (pc.params.x <= 0.0) return vec2(d, d * d);
	float e = exp(pc.params.x * d);   // EVSM2: positive exponential warp
	return vec2(e, e * e);
}

void blur(ivec2 p);

// Each invocation blurs a 16x16 block: few, large workgroups (lavapipe's per-dispatch cost
// grows with the workgroup count).
void main()
{
	int res = int(pc.params.z);
	for (int by = 0; by < 8; by++)
		for (int bx = 0; bx < 8; bx++) {
			ivec2 p = ivec2(gl_GlobalInvocationID.xy) * 8 + ivec2(bx, by);
			if (p.x < res && p.y < res) blur(p);
		}
}

void blur(ivec2 p)
{
	int res = int(pc.params.z);
	ivec2 origin = ivec2(pc.info.xy);
	int r = int(pc.info.w);
	float sigma = max(pc.params.y, 0.5);
	vec2 sum = vec2(0.0);
	float wsum = 0.0;
	for (int k = -r; k <= r; k++) {
		float w = exp(-0.5 * float(k * k) / (sigma * sigma));
		vec2 m;
		if (pc.info.z == 0u) {
			ivec2 q = ivec2(clamp(p.x + k, 0, res - 1), p.y);
			m = to_moments(scratch[q.y * res + q.x]);
		} else {
			ivec2 q = ivec2(p.x, clamp(p.y + k, 0, res - 1));
			m = imageLoad(tmp_img, q).xy;
		}
		sum += w * m;
		wsum += w;
	}
	vec4 v = vec4(sum / wsum, 0.0, 1.0);
	if (pc.info.z == 0u) imageStore(tmp_img, p, v);
	else imageStore(out_img, origin + p, v);
}
