// shaders/ibl.glsl — light from the environment map (renderer/env.c): the split-sum specular
// lobe (a prefiltered cube, a mip level per roughness step, and the DFG table), the diffuse
// irradiance by spherical harmonics, and the map's shadows (its shadow directions' maps, weighed
// by the light each brings to the surface). Included by mesh_main.glsl after shading.glsl; the
// pipelines whose UMBRA_SC_ENV is 0 compile none of it (the scene has no map).
// After the Khronos glTF sample viewer's and Filament's image-based lighting (read, not copied).

layout(std140, set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV) uniform EnvBlock { umbra_env env; };
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV_SPECULAR) uniform samplerCube env_specular;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV_MAP) uniform sampler2D env_map;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV_BRDF) uniform sampler2D env_brdf;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV_SURFACES) uniform sampler2D env_surfaces;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV_NORMALS) uniform sampler2D env_normals;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV_VIS) uniform sampler2D env_vis_image;
layout(constant_id = UMBRA_SC_ENV) const uint SC_ENV = 0u;   // UMBRA_ENV_* bits

#define UMBRA_ENV_READ
#include "env_common.glsl"

// E(n) / pi: the irradiance over pi of the map (intensity applied), from its harmonics.
vec3 env_irradiance(vec3 n)
{
	vec3 m = env_rotate_to_map(n, env.rot.x, env.rot.y);
	vec3 e = env.sh[0].rgb * 0.282095
	       + env.sh[1].rgb * (0.488603 * m.y) + env.sh[2].rgb * (0.488603 * m.z) + env.sh[3].rgb * (0.488603 * m.x)
	       + env.sh[4].rgb * (1.092548 * m.x * m.y) + env.sh[5].rgb * (1.092548 * m.y * m.z)
	       + env.sh[6].rgb * (0.315392 * (3.0 * m.z * m.z - 1.0)) + env.sh[7].rgb * (1.092548 * m.x * m.z)
	       + env.sh[8].rgb * (0.546274 * (m.x * m.x - m.y * m.y));
	return max(e, vec3(0.0));   // order 2 rings below zero opposite a bright sun
}

// sin of direction k's angular radius (four to a vec4)
float env_sin_radius(uint k)
{
	vec4 v = env.sizes[k >> 2u];
	uint c = k & 3u;
	return c == 0u ? v.x : c == 1u ? v.y : c == 2u ? v.z : v.w;
}

// The clamped cosine of a region of angular radius asin(s) around d on a surface of normal n:
// n.d where the whole region is above the surface's horizon, 0 where it is below, and across the
// horizon the smooth (n.d + s)^2 / 4s of a sphere light's "wrap" (no step at the horizon).
float env_dir_weight(vec3 n, vec3 d, float s)
{
	float c = dot(n, d);
	if (c >= s) return c;
	if (c <= -s) return 0.0;
	float t = c + s;
	return t * t / (4.0 * s);
}

// PCSS for one environment direction (view v of light L, tile-local texel p): the blocker search
// and the filter of shading.glsl's pcss() with fewer taps (9 and 16 of its 25 and 32): a dozen
// directions are averaged, which hides most of what the taps leave out. Against Cycles (four
// scenes, 12 directions, the ground's RMSE) 0.030-0.045 where pcss() gave 0.026-0.041, for
// 2.5x less time (the environment pass of a 256² thumbnail, 8 directions: 26 ms, 66 with
// pcss()). The depth bounds answer first, as there.
float env_pcss(umbra_light L, umbra_shadow_view v, vec2 p, vec4 rect, float ref, float res, vec2 grad)
{
	float zr = view_distance(v, ref), texel = v.params.x, size = L.params.y;
	float search = clamp(penumbra_texels(v, size, vec4(v.params.z), zr, texel).x, 1.0, L.shadow_params.y);
	float k = size / texel, r0 = k * (zr - v.params.z) + 1.5, r1 = k * (v.params.w - v.params.z);
	float slack = abs(grad.x) + abs(grad.y) + 1e-6, reach_max;
	int known = pcss_bounds(L, p, rect, ref, grad, slack, search * frame.params.w + 1.0, r0, r1, reach_max);
	float blockers = 0.0, sum_d = 0.0;
	float close = min(search, 3.0);
	for (int i = 0; i < (known == 0 ? 9 : 0); i++) {
		// tap 0 the point, 1..4 a close ring (low casters, contact), 5..8 the wide search
		vec2 off = i == 0 ? vec2(0.0) : i < 5 ? poisson(8 * i - 7) * close : poisson(8 * i - 34) * search;
		vec4 d = gather_tile(rect, p + off);
		vec4 b = step(d, vec4(ref + dot(grad, off) - slack)) * step(vec4(length(off)), r0 - r1 * d);
		blockers += dot(b, vec4(1.0));
		sum_d += dot(b, d);
	}
	int taps = known == 0 && blockers > 0.5 ? 16 : 0;
	float radius = clamp(penumbra_texels(v, size, vec4(view_distance(v, sum_d / max(blockers, 1.0))), zr, texel).x, 1.0,
	                     L.shadow_params.y);
	float sum = 0.0;
	for (int i = 0; i < taps; i++) {
		// the odd taps, spread over the disk: centred and scaled to a uniform disk's spread (frame.c)
		vec2 off = (poisson(2 * i + 1) - frame.env_filter_taps.xy) * (radius * frame.env_filter_taps.z);
		sum += bilinear_compare(p + off, rect, ref + dot(grad, off), res);
	}
	return known == 2 ? 0.0 : taps == 0 ? 1.0 : sum / 16.0;
}

// Visibility of the sky along environment direction light li (its one orthographic map fitted
// to the casters, PCSS with its region's angular size) at pos, geometric normal n: the normal
// offset and receiver plane of the scene's own lights (shading.glsl sample_view).
float env_dir_visibility(uint li, vec3 pos, vec3 n, vec3 d)
{
	umbra_light L = lights[li];
	umbra_shadow_view v = views[L.shadow.x];
	float res = v.rect.z, texel = v.params.x;
	vec4 lc0 = v.view_proj * vec4(pos, 1.0);
	float ndl = clamp(dot(n, d), 0.0, 1.0);
	vec3 sc = (lc0 + (v.view_proj * vec4(n, 0.0)) * (L.shadow_params.x * texel * (1.0 - 0.5 * ndl))).xyz;
	if (sc.z > 1.0 || any(greaterThan(abs(sc.xy), vec2(1.0)))) return 1.0;
	vec2 grad = receiver_gradient(v, pos, n, lc0, texel, res);
	return env_pcss(L, v, (sc.xy * 0.5 + 0.5) * res, v.rect, clamp(sc.z, 0.0, 1.0), res, grad);
}

// The share of the map's diffuse light (cosine-weighted, occluded / unoccluded) reaching pos:
// each direction's visibility weighed by its share of the map's light times its clamped cosine
// on the shading normal N (n_shadow, p_shadow: the triangle's plane, facet.glsl). Directions
// below a ground (after the mapped ones) are hidden: they weigh, with visibility 0.
float env_visibility(vec3 p_shadow, vec3 n_shadow, vec3 N)
{
	if ((SC_ENV & UMBRA_ENV_SHADOWS) == 0u) return 1.0;
	uint first = uint(env.params.z), mapped = uint(env.params.w), total = uint(env.ground.w);
	float lit = 0.0, all = 0.0;
	for (uint k = 0u; k < total; k++) {
		vec4 d = env.dirs[k];
		float w = d.w * env_dir_weight(N, d.xyz, env_sin_radius(k));
		if (w <= 0.0) continue;
		all += w;
		if (k < mapped) lit += w * env_dir_visibility(first + k, p_shadow, n_shadow, d.xyz);
	}
	return all > 0.0 ? lit / all : 1.0;
}

// The environment pass's visibility (renderer/env_pass.c) at this fragment (pos, geometric
// normal n): the four pass texels around it, each weighed bilinearly and by how well its surface
// agrees with this one (its distance from this fragment's plane, in pass texels, and its normal),
// so that shadows do not bleed across silhouettes. Where none agrees (a surface thinner than a
// pass texel): their plain bilinear mean.
float env_pass_read(vec3 pos, vec3 n)
{
	float S = env.pass.x;
	vec2 q = gl_FragCoord.xy / S - 0.5;
	ivec2 b = ivec2(floor(q)), size = textureSize(env_vis_image, 0);
	vec2 f = q - vec2(b);
	float z = max(dot(pos - frame.camera_pos.xyz, frame.camera_fwd.xyz), 1e-4);
	float texel = frame.target.z * (frame.target.w > 0.5 ? 1.0 : z) * S;   // a pass texel's world size here
	float sum = 0.0, wsum = 0.0, plain = 0.0, psum = 0.0;
	for (int k = 0; k < 4; k++) {
		ivec2 o = ivec2(k & 1, k >> 1), t = clamp(b + o, ivec2(0), size - 1);
		vec4 s = texelFetch(env_surfaces, t, 0);
		float v = texelFetch(env_vis_image, t, 0).r;
		float wb = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y) + 1e-3;
		float d = abs(dot(n, s.xyz - pos)) / texel;
		float a = max(dot(texelFetch(env_normals, t, 0).xyz, n), 0.0);
		float a2 = a * a, a4 = a2 * a2;
		float w = s.w == 0.0 ? 0.0 : wb * exp(-2.0 * d * d) * a4 * a4;
		sum += w * v;
		wsum += w;
		plain += s.w == 0.0 ? 0.0 : wb * v;
		psum += s.w == 0.0 ? 0.0 : wb;
	}
	return wsum > 1e-4 ? sum / wsum : psum > 0.0 ? plain / psum : 1.0;
}

// The environment's visibility at this fragment: from the environment pass where the view has
// one, else computed here.
float env_shadow(vec3 p_shadow, vec3 n_shadow, vec3 N)
{
	if ((SC_ENV & UMBRA_ENV_SHADOWS) == 0u) return 1.0;
	if ((SC_ENV & UMBRA_ENV_PASS) != 0u) return env_pass_read(v_pos, n_shadow);
	return env_visibility(p_shadow, n_shadow, N);
}

// The environment's light leaving the surface towards V: diffuse (c_diff) and specular (f0,
// perceptual roughness rough, split sum), both darkened by the material's occlusion ao and the
// environment's visibility vis (the specular through Lagarde's specular occlusion, "Moving
// Frostbite to PBR" 2014). *diffuse_open: the diffuse part without either (shadow catchers).
// The prefiltered light arriving along R at perceptual roughness rough (intensity applied).
vec3 env_prefiltered(vec3 R, float rough)
{
	return textureLod(env_specular, env_rotate_to_map(R, env.rot.x, env.rot.y), rough * env.rot.w).rgb * env.rot.z;
}

// Lagarde's specular occlusion from the diffuse one (occ) at N.V ndv and roughness rough.
float env_specular_occlusion(float ndv, float occ, float rough)
{
	return clamp(pow(ndv + occ, exp2(-16.0 * rough - 1.0)) - 1.0 + occ, 0.0, 1.0);
}

// The glTF extension lobes under the map (material_ext.glsl, ext_s set for this pixel; folded
// away unless a drawn material has one): KHR_materials_specular's F90 in the split sum
// (F0 A + F90 B), the sheen as its albedo x the irradiance, the coat as its own split-sum
// lobe about its normal, stacked over the base by ext_layer() as for a light.
vec3 env_light_ext(vec3 diffuse, vec3 pre, vec2 ab, vec3 f0, float so, vec3 N, vec3 V, float ndv, float occ)
{
	vec3 base = diffuse + pre * (f0 * ab.x + (EXT_SPECULAR ? ext_s.f90 : vec3(1.0)) * ab.y) * so;
	if (!EXT_SHEEN && !EXT_CLEARCOAT) return base;
	vec3 sheen = EXT_SHEEN ? ext_s.sheen * ext_sheen_albedo(ndv, ext_s.sheen_r) * env_irradiance(N) * occ : vec3(0.0);
	float coat = 0.0;
	vec3 coat_rgb = vec3(0.0);
	if (EXT_CLEARCOAT) {
		float cv = max(dot(ext_s.cc_n, V), 1e-4);
		vec2 cab = textureLod(env_brdf, vec2(cv, ext_s.cc_rough), 0.0).rg;
		coat_rgb = env_prefiltered(reflect(-V, ext_s.cc_n), ext_s.cc_rough) * (ext_s.cc_f0 * cab.x + cab.y)
		         * env_specular_occlusion(cv, occ, ext_s.cc_rough);
	}
	// ext_layer takes the coat as one number per light; here it is a colour: layered by hand.
	vec3 c = ext_layer(base, ext_s.sheen_keep, sheen, coat);
	return EXT_CLEARCOAT ? c + ext_s.cc * coat_rgb : c;
}

vec3 env_light(vec3 N, vec3 V, vec3 c_diff, vec3 f0, float rough, float ao, float vis, out vec3 diffuse_open)
{
	float ndv = max(dot(N, V), 1e-4);
	vec2 ab = textureLod(env_brdf, vec2(ndv, rough), 0.0).rg;
	vec3 pre = env_prefiltered(reflect(-V, N), rough);
	float occ = ao * vis;
	float so = env_specular_occlusion(ndv, occ, rough);
	diffuse_open = env_irradiance(N) * c_diff;
	if (SC_MATERIAL_EXT != 0u) return env_light_ext(diffuse_open * occ, pre, ab, f0, so, N, V, ndv, occ);
	return diffuse_open * occ + pre * (f0 * ab.x + ab.y) * so;
}
