#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
#include "env_common.glsl"
// One level of the environment's specular cube (renderer/env_build.c): each texel's direction N
// (= V = R, Karis' split-sum assumption) lit by the map through a GGX lobe of this level's
// roughness, importance-sampled; each sample reads the map at the mip level whose texels have
// the sample's solid angle ("filtered importance sampling", GPU Gems 3 ch. 20), so 64 samples
// give no fireflies. Level 0 (samples 0) is the mirror: the map at the face texel's size.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = UMBRA_ENVC_BINDING_SOURCE) uniform sampler2D map;
layout(set = 0, binding = UMBRA_ENVC_BINDING_OUT, rgba16f) uniform writeonly image2DArray level_out;
layout(push_constant) uniform Push {
	uvec4 info;   // x face side, y samples (0: mirror), z map width, w map height
	vec4 params;  // x roughness, y the mirror's map level, z the map's last level
} pc;

// The direction of face texel st (0..1) of cube face f, Vulkan's face layout (spec: "Cube Map
// Face Selection"), so that sampling the cube with that direction reads this texel.
vec3 face_dir(uint f, vec2 st)
{
	float a = 2.0 * st.x - 1.0, b = 2.0 * st.y - 1.0;
	if (f == 0u) return vec3(1.0, -b, -a);
	if (f == 1u) return vec3(-1.0, -b, a);
	if (f == 2u) return vec3(a, 1.0, b);
	if (f == 3u) return vec3(a, -1.0, -b);
	if (f == 4u) return vec3(a, -b, 1.0);
	return vec3(-a, -b, -1.0);
}

vec2 hammersley(uint i, uint n)
{
	return vec2(float(i) / float(n), float(bitfieldReverse(i)) * 2.3283064365386963e-10);
}

void main()
{
	uvec3 id = gl_GlobalInvocationID;
	uint side = pc.info.x;
	if (id.x >= side || id.y >= side) return;
	vec3 N = normalize(face_dir(id.z, (vec2(id.xy) + 0.5) / float(side)));
	vec3 c;
	if (pc.info.y == 0u) {
		c = textureLod(map, env_equirect_uv(N), pc.params.y).rgb;
	} else {
		float a = pc.params.x * pc.params.x, a2 = a * a;
		vec3 up = abs(N.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
		vec3 t = normalize(cross(up, N)), b = cross(N, t);
		// a map texel's solid angle at the equator (times cos(latitude) elsewhere)
		float texel = (2.0 * ENV_PI / float(pc.info.z)) * (ENV_PI / float(pc.info.w));
		vec3 sum = vec3(0.0);
		float wsum = 0.0;
		uint n = pc.info.y;
		for (uint i = 0u; i < n; i++) {
			vec2 xi = hammersley(i, n);
			float phi = 2.0 * ENV_PI * xi.x;
			// clamped: an inexact divide (a GPU's) can put ct a rounding above 1, and st at NaN
			float ct = min(sqrt((1.0 - xi.y) / (1.0 + (a2 - 1.0) * xi.y)), 1.0), st = sqrt(max(1.0 - ct * ct, 0.0));
			vec3 H = t * (st * cos(phi)) + b * (st * sin(phi)) + N * ct;
			vec3 L = 2.0 * dot(N, H) * H - N;
			float ndl = dot(N, L);
			if (ndl <= 0.0) continue;
			float dd = ct * ct * (a2 - 1.0) + 1.0;
			float pdf = a2 / (ENV_PI * dd * dd) * 0.25;    // D(h) n.h / (4 v.h) with v = n
			float omega_s = 1.0 / (float(n) * pdf);
			float omega_p = texel * max(sqrt(max(1.0 - L.y * L.y, 0.0)), 1e-3);
			float lod = clamp(0.5 * log2(omega_s / omega_p) + 1.0, 0.0, pc.params.z);
			sum += textureLod(map, env_equirect_uv(L), lod).rgb * ndl;
			wsum += ndl;
		}
		c = sum / max(wsum, 1e-6);
	}
	imageStore(level_out, ivec3(id), vec4(c, 1.0));
}
