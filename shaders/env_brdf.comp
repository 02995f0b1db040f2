#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// The split-sum table (renderer/env_build.c): for n.v (x) and perceptual roughness (y) the scale
// A and bias B of f0 in the specular lobe's integral over the hemisphere, (f0 A + B) = the
// integral of GGX D x the height-correlated Smith visibility (the direct lights' terms in
// shading.glsl) x Schlick's Fresnel x n.l, by importance sampling of D (Karis 2013).
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = UMBRA_ENVC_BINDING_OUT, rgba16f) uniform writeonly image2D table;
layout(push_constant) uniform Push {
	uvec4 info;   // x table side, y samples
	vec4 params;
} pc;

const float PI = 3.14159265358979;

void main()
{
	ivec2 id = ivec2(gl_GlobalInvocationID.xy);
	float side = float(pc.info.x);
	float ndv = (float(id.x) + 0.5) / side, rough = (float(id.y) + 0.5) / side;
	float a = rough * rough, a2 = a * a;
	vec3 V = vec3(sqrt(1.0 - ndv * ndv), 0.0, ndv);
	float A = 0.0, B = 0.0;
	uint n = pc.info.y;
	for (uint i = 0u; i < n; i++) {
		vec2 xi = vec2(float(i) / float(n), float(bitfieldReverse(i)) * 2.3283064365386963e-10);
		float phi = 2.0 * PI * xi.x;
		// clamped: an inexact divide (a GPU's) can put ct a rounding above 1, and st at NaN
		float ct = min(sqrt((1.0 - xi.y) / (1.0 + (a2 - 1.0) * xi.y)), 1.0), st = sqrt(max(1.0 - ct * ct, 0.0));
		vec3 H = vec3(st * cos(phi), st * sin(phi), ct);
		vec3 L = 2.0 * dot(V, H) * H - V;
		float ndl = L.z, vdh = max(dot(V, H), 0.0);
		if (ndl <= 0.0) continue;
		float vis = 0.5 / (ndl * sqrt(ndv * ndv * (1.0 - a2) + a2) + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2));
		float g = vis * 4.0 * ndl * vdh / max(ct, 1e-6);
		float fc = pow(1.0 - vdh, 5.0);
		A += (1.0 - fc) * g;
		B += fc * g;
	}
	imageStore(table, id, vec4(A / float(n), B / float(n), 0.0, 1.0));
}
