// shaders/shade.glsl — the colour of one surface point as the main pass writes it: shading of
// every light (shading.glsl light_all), ambient, the environment map's light and shadows
// (ibl.glsl), emissive, the debug views, the shadow catcher, tone map and encoding.
// mesh_main.glsl calls it per fragment; vis_shade.frag once per pixel centre (pixel shading,
// renderer/deferred.c), with the surface read from the surfaces pass instead of interpolated.
// Included after shading.glsl; v_pos, v_uv and v_uv1 are the point's (globals or inputs).
#include "ibl.glsl"

// bc: the base colour (shading.glsl base_color: material x texture x vertex colour); n_geo the
// interpolated normal facing the viewer; p_shadow, n_shadow where the shadow lookups look and
// the plane of the triangle (facet.glsl).
vec4 shade(umbra_material m, uint flags, vec4 bc, vec3 n_geo, vec3 p_shadow, vec3 n_shadow)
{
	vec3 N = material_normal(m, n_geo, has_tex(m, UMBRA_TEX_NORMAL));
	vec3 V = frame.camera_pos.w > 0.5 ? -frame.camera_fwd.xyz : normalize(frame.camera_pos.xyz - v_pos);
	vec3 base = bc.rgb;
	float rough = m.emissive.a, metal = m.params.x;
	if (has_tex(m, UMBRA_TEX_METAL_ROUGH)) {
		vec4 mr = material_texture(metal_rough_texture, m, UMBRA_TEX_METAL_ROUGH, v_uv, v_uv1);
		rough *= mr.g;   // glTF: G roughness, B metalness (linear)
		metal *= mr.b;
	}
	rough = clamp(rough, 0.03, 1.0);
	metal = clamp(metal, 0.0, 1.0);
	vec3 f0 = mix(vec3(0.04), base, metal);
	vec3 c_diff = base * (1.0 - metal);
	float f0_ambient = metal;   // the ambient reflects a metal's F0 ...
	if (SC_MATERIAL_EXT != 0u) {
		f0 = ext_surface_at(m, N, n_geo, V, base, metal, f0);
		// ... and a specular-glossiness surface's, whose diffuse keeps 1 - max(F0) (the sample viewer's)
		c_diff *= 1.0 - ext_s.spec_gloss * ext_max3(f0);
		f0_ambient = max(metal, ext_s.spec_gloss);
	}
	bool receive = (flags & UMBRA_DRAW_RECEIVE_SHADOWS) != 0u;
	vec3 lit, unshadowed;
	float debug_vis;
	uint debug_view;
	light_all(N, n_geo, n_shadow, p_shadow, V, c_diff, f0, rough, receive, lit, unshadowed, debug_vis, debug_view);
	float hemi = N.y * 0.5 + 0.5;
	// Occlusion darkens the ambient (indirect) light only: direct light has its shadows.
	float ao = 1.0;
	if (has_tex(m, UMBRA_TEX_OCCLUSION))
		ao = 1.0 + m.params.w * (material_texture(occlusion_texture, m, UMBRA_TEX_OCCLUSION, v_uv, v_uv1).r - 1.0);
	vec3 ambient = mix(frame.ambient_ground.rgb, frame.ambient_sky.rgb, hemi) * (c_diff + f0 * f0_ambient) * ao;
	if (SC_MATERIAL_EXT != 0u) ambient = ext_ambient(ambient, mix(frame.ambient_ground.rgb, frame.ambient_sky.rgb, hemi) * ao, N, V);
	// The environment map's light and its shadows (ibl.glsl; folded away without a map).
	float env_vis = 1.0;
	vec3 env_open = vec3(0.0);
	if (SC_ENV != 0u) {
		if (receive) env_vis = env_shadow(p_shadow, n_shadow, N);
		ambient += env_light(N, V, c_diff, f0, rough, ao, env_vis, env_open);
	}
	vec3 emissive = m.emissive.rgb;
	if (has_tex(m, UMBRA_TEX_EMISSIVE))
		emissive *= material_texture(emissive_texture, m, UMBRA_TEX_EMISSIVE, v_uv, v_uv1).rgb;
	vec3 radiance = (ambient + lit + emissive) * frame.params.x;

	const uint debug = SC_DEBUG;
	if (debug == UMBRA_DEBUG_SHADOW) return vec4(vec3(debug_vis), 1.0);
	if (debug == UMBRA_DEBUG_ENV_SHADOW) return vec4(vec3(env_vis), 1.0);
	if (debug == UMBRA_DEBUG_NORMALS) return vec4(N * 0.5 + 0.5, 1.0);
	if (debug == UMBRA_DEBUG_DEPTH) {
		float z = dot(v_pos - frame.camera_pos.xyz, frame.camera_fwd.xyz);
		return vec4(vec3(clamp((z - frame.params.y) / (frame.params.z - frame.params.y), 0.0, 1.0)), 1.0);
	}
	if (debug == UMBRA_DEBUG_CASCADES) return vec4(display(radiance) * cascade_tint(debug_view), 1.0);
	if (SC_CATCHER != 0u && (flags & UMBRA_DRAW_SHADOW_CATCHER) != 0u) {
		// Not drawn itself: the share of light removed by shadows darkens the background.
		vec3 amb_c = mix(frame.ambient_ground.rgb, frame.ambient_sky.rgb, hemi) * c_diff;
		float full = dot(unshadowed + amb_c + env_open, vec3(0.2126, 0.7152, 0.0722));
		float kept = dot(lit + amb_c + env_open * env_vis, vec3(0.2126, 0.7152, 0.0722));
		float ratio = full > 1e-6 ? clamp(kept / full, 0.0, 1.0) : 1.0;
		if (frame.mode2.y != 0u) return vec4(0.0, 0.0, 0.0, 1.0 - ratio);
		if ((SC_ENV & UMBRA_ENV_BACKGROUND) != 0u)   // the map behind it, tone mapped like the scene
			return vec4(display(env_background(-V) * frame.params.x * ratio), 1.0);
		vec3 bg = frame.background.rgb * ratio;
		return vec4(SC_LINEAR != 0u ? bg : srgb_encode(bg), 1.0);
	}
	return vec4(display(radiance), 1.0);
}
