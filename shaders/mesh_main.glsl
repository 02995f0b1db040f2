// shaders/mesh_main.glsl — the main pass's fragment shader (mesh.frag; mesh_vis.frag is the same
// reading its shadows from the visibility pass, renderer/visibility.c).
#define UMBRA_PUSH_MAIN   // the draw's material head arrives in the push constants
#include "shading.glsl"
#include "shade.glsl"   // and ibl.glsl

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
	if ((SC_TEXTURES & ~UMBRA_TEXBIT_UV1) != 0u) m.uvx = materials[pc.info.x].uvx;
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
	o_color = shade(m, flags, base_color(m), n_geo, p_shadow, n_shadow);
}
