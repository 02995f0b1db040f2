#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// Moment shadow maps (VSM, EVSM2) from a shadow map just drawn in the slot's scratch depth
// image (and copied to the scratch buffer), with a separable Gaussian blur, one implementation
// for every light type. Both passes blur along rows and write their result transposed, so the
// second pass's rows are the first's columns:
//   pass 0: depth -> moments, blurred along x, into tmp at (y, x);
//   pass 1: tmp's rows (the map's columns) blurred, into the map's tile of the moment atlas at
//           (row, i) = the map's (x, y).
// A workgroup takes UMBRA_MOMENTS_ROWS rows of UMBRA_MOMENTS_SPAN texels: it turns each texel it
// needs into moments once, into workgroup memory, and every invocation then sums one column of
// outputs from there. Written per output tap (a load, the conversion with its exp or division,
// and the weight's exp for each of the 2r + 1 taps of every texel, twice), the blur took ~108 ms
// of a 2048² sun map on lavapipe, 95 % of a VSM thumbnail.
layout(local_size_x = UMBRA_MOMENTS_SPAN, local_size_y = 1) in;
layout(std430, set = 0, binding = UMBRA_MOMENTS_BINDING_DEPTH) readonly buffer Scratch { float scratch[]; };
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_TMP, rg32f) uniform image2D tmp_img;
layout(set = 0, binding = UMBRA_MOMENTS_BINDING_OUT) writeonly uniform image2D out_img;
layout(push_constant) uniform Push {
	uvec4 info;   // x, y: tile offset in the atlas; z pass; w blur radius (texels, <= UMBRA_MOMENTS_MAX_RADIUS)
	vec4 params;  // x exponent (0 = VSM: plain depth), y sigma (texels), z tile size
	vec4 proj;    // x near, y far, z 1 = perspective view (depth is made linear first)
} pc;

const int SPAN = UMBRA_MOMENTS_SPAN, ROWS = UMBRA_MOMENTS_ROWS, WIDE = SPAN + 2 * UMBRA_MOMENTS_MAX_RADIUS;
shared vec2 row_moments[ROWS][WIDE];

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

// Texel i of the pass's row `row`, clamped to the tile's edge.
vec2 source(int row, int i)
{
	int res = int(pc.params.z);
	i = clamp(i, 0, res - 1);
	if (pc.info.z == 0u) return to_moments(scratch[row * res + i]);
	return imageLoad(tmp_img, ivec2(i, row)).xy;
}

void main()
{
	int res = int(pc.params.z);
	int r = int(pc.info.w);
	int lane = int(gl_LocalInvocationID.x);
	int i0 = int(gl_WorkGroupID.x) * SPAN;      // first output texel along the row
	int row0 = int(gl_WorkGroupID.y) * ROWS;
	int n = SPAN + 2 * r;                       // texels the rows' outputs read
	for (int y = 0; y < ROWS; y++)
		for (int j = lane; j < n; j += SPAN) row_moments[y][j] = source(row0 + y, i0 - r + j);
	barrier();
	float sigma = max(pc.params.y, 0.5);
	vec2 sum[ROWS];
	for (int y = 0; y < ROWS; y++) sum[y] = vec2(0.0);
	float wsum = 0.0;
	for (int k = -r; k <= r; k++) {
		float w = exp(-0.5 * float(k * k) / (sigma * sigma));
		for (int y = 0; y < ROWS; y++) sum[y] += w * row_moments[y][lane + r + k];
		wsum += w;
	}
	int i = i0 + lane;
	for (int y = 0; y < ROWS; y++) {
		vec4 v = vec4(sum[y] / wsum, 0.0, 1.0);
		ivec2 t = ivec2(row0 + y, i);            // transposed
		if (pc.info.z == 0u) imageStore(tmp_img, t, v);
		else imageStore(out_img, ivec2(pc.info.xy) + t, v);
	}
}
