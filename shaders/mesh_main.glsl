// shaders/mesh_main.glsl — the main pass's fragment shader (mesh.frag; mesh_vis.frag is the same
// reading its shadows from the visibility pass, renderer/visibility.c).
#define UMBRA_PUSH_MAIN   // the draw's material head arrives in the push constants
#include "shading.glsl"
#include "ibl.glsl"

layout(location = 0) out vec4 o_color;

// The draw's material: its head from the push constants (one load per draw), the uv
// transforms from the materials buffer only where a material of the scene has textures.
umbra_material draw_material()
{
	umbra_material m;
	m.base_color = pc.base_color;
	m.emissive = pc.emissive;
	m.params = pc.params;
	m.tex = pc.tex;
	if ((SC_TEXTURES & ~(UMBRA_TEXBIT_VERTEX_COLOR | UMBRA_TEXBIT_UV1)) != 0u) m.uvx = materials[pc.info.x].uvx;
	if (SC_MATERIAL_EXT != 0u) {   // the extensions' members, where a drawn material has one (material_ext.glsl)
		m.clearcoat = materials[pc.info.x].clearcoat;
		m.sheen = materials[pc.info.x].sheen;
		m.specular = materials[pc.info.x].specular;
		m.ext = materials[pc.info.x].ext;
	}
	return m;
}

void main()
{
	material_derivatives(v_uv, v_uv1);
	umbra_material m = draw_material();
	uint flags = pc.info.y;
	vec3 n_geo, p_shadow, n_shadow;   // before base_color's discard
	surface_at(in_pos, v_nrm, v_uv, flags, SC_SAMPLES, v_pos, n_geo, p_shadow, n_shadow);
	vec4 bc = base_color(m);
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
	if (debug == UMBRA_DEBUG_SHADOW) { o_color = vec4(vec3(debug_vis), 1.0); return; }
	if (debug == UMBRA_DEBUG_ENV_SHADOW) { o_color = vec4(vec3(env_vis), 1.0); return; }
	if (debug == UMBRA_DEBUG_NORMALS) { o_color = vec4(N * 0.5 + 0.5, 1.0); return; }
	if (debug == UMBRA_DEBUG_DEPTH) {
		float z = dot(v_pos - frame.camera_pos.xyz, frame.camera_fwd.xyz);
		o_color = vec4(vec3(clamp((z - frame.params.y) / (frame.params.z - frame.params.y), 0.0, 1.0)), 1.0);
		return;
	}
	if (debug == UMBRA_DEBUG_CASCADES) {
		vec3 c = display(radiance) * cascade_tint(debug_view);
		o_color = vec4(c, 1.0);
		return;
	}
	if (SC_CATCHER != 0u && (flags & UMBRA_DRAW_SHADOW_CATCHER) != 0u) {
		// Not drawn itself: the share of light removed by shadows darkens the background.
		vec3 amb_c = mix(frame.ambient_ground.rgb, frame.ambient_sky.rgb, hemi) * c_diff;
		float full = dot(unshadowed + amb_c + env_open, vec3(0.2126, 0.7152, 0.0722));
		float kept = dot(lit + amb_c + env_open * env_vis, vec3(0.2126, 0.7152, 0.0722));
		float ratio = full > 1e-6 ? clamp(kept / full, 0.0, 1.0) : 1.0;
		if (frame.mode2.y != 0u) { o_color = vec4(0.0, 0.0, 0.0, 1.0 - ratio); return; }
		if ((SC_ENV & UMBRA_ENV_BACKGROUND) != 0u) {   // the map behind it, tone mapped like the scene
			o_color = vec4(display(env_background(-V) * frame.params.x * ratio), 1.0);
			return;
		}
		vec3 bg = frame.background.rgb * ratio;
		o_color = vec4(SC_LINEAR != 0u ? bg : srgb_encode(bg), 1.0);
		return;
	}
	o_color = vec4(display(radiance), 1.0);
}
