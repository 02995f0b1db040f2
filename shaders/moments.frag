#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Moment shadow maps (VSM, EVSM2) of a shadow map just copied into its tile of the depth atlas:
// a separable Gaussian blur in two fullscreen passes (fullscreen.vert) over the tile, one
// implementation for every light type (renderer/moments.c records them).
//   pass 0: depth -> moments, blurred along x, into the slot's blur temporary at (0,0)..(res,res);
//   pass 1: the temporary blurred along y, into the view's tile of the moment atlas.
// Fragment passes rather than compute: lavapipe writes a colour attachment a block of pixels
// at a time but an image from a compute shader lane by lane, and runs a fullscreen triangle's
// blocks without a workgroup's bookkeeping (a 2048^2 sun map: ~100 ms of compute, see
// moments.c for this one's figure).
// Pass 0's variants: lavapipe runs both sides of a branch on a push constant, and the warp's
// exp and the linearisation's division per tap were a third of the pass.
layout(constant_id = 0) const uint PASS = 0u;
layout(constant_id = 1) const uint WARP = 0u;    // 1: EVSM's exponential warp (params.x)
layout(constant_id = 2) const uint PERSP = 0u;   // 1: a perspective view's depth, made linear
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_DEPTH) uniform sampler2D depth_atlas;
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_BLUR) uniform sampler2D blur_tmp;
layout(push_constant) uniform Push {
	uvec4 info;   // x, y: the tile's offset in the atlas; w blur radius (texels)
	vec4 params;  // x exponent (0 = VSM: plain depth), y sigma (texels), z tile size
	vec4 proj;    // x near, y far, z 1 = perspective view (depth is made linear first)
} pc;
layout(location = 0) out vec4 o_moments;

vec2 to_moments(float d)
{
	// Perspective depth crowds near 1: moments of it would have no variance to speak of.
	// Linear depth over near..far instead (shading.glsl's moments() does the same to its ref).
	if (PERSP != 0u) {
		float n = pc.proj.x, f = pc.proj.y;
		d = (n * f / (f - d * (f - n)) - n) / (f - n);
	}
	if (WARP == 0u) return vec2(d, d * d);
	float e = exp(pc.params.x * d);   // EVSM2: positive exponential warp
	return vec2(e, e * e);
}

void main()
{
	int res = int(pc.params.z);
	ivec2 origin = ivec2(pc.info.xy);
	// the tile's texel: pass 0 draws the temporary from (0,0), pass 1 the atlas's tile
	ivec2 p = ivec2(gl_FragCoord.xy) - (PASS == 0u ? ivec2(0) : origin);
	int r = int(pc.info.w);
	float sigma = max(pc.params.y, 0.5);
	// Gaussian weights w(k) = exp(-k^2 / (2 sigma^2)) by their ratios: w(k + 1) = w(k) q(k),
	// q(k + 1) = q(k) c, three exps a pixel instead of one a tap.
	float s2 = 2.0 * sigma * sigma;
	float w = exp(-float(r * r) / s2), q = exp(float(2 * r - 1) / s2), c = exp(-2.0 / s2);
	vec2 sum = vec2(0.0);
	float wsum = 0.0;
	for (int k = -r; k <= r; k++, w *= q, q *= c) {
		vec2 m;
		if (PASS == 0u) m = to_moments(texelFetch(depth_atlas, origin + ivec2(clamp(p.x + k, 0, res - 1), p.y), 0).r);
		else m = texelFetch(blur_tmp, ivec2(p.x, clamp(p.y + k, 0, res - 1)), 0).xy;
		sum += w * m;
		wsum += w;
	}
	o_moments = vec4(sum / wsum, 0.0, 1.0);
}
