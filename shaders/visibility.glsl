// shaders/visibility.glsl — the visibility pass's side of shading.glsl (renderer/visibility.c):
// what vis.frag stores per pixel and light, and how mesh_vis.frag finds and reads it. Included
// by shading.glsl after light_dir(); only the shader that defines UMBRA_VIS_PASS or
// UMBRA_VIS_READ compiles either half.

#ifdef UMBRA_VIS_PASS
// Walks the lights in todo that reach this pixel (reach), storing each one's visibility, with
// the code of `filters` only (a constant: sample_view's dispatch folds to those filters).
void store_walk(ivec2 px, vec3 n_shadow, uvec2 reach, uvec2 todo, uint filters)
{
	while (todo != uvec2(0u)) {
		uint i = take_light(todo);
		if (!has_light(reach, i)) continue;
		umbra_light L = lights[i];
		float atten;
		vec3 l = light_dir(L, v_pos, atten);
		uint view;
		imageStore(vis_out, ivec3(px, int(i)), vec4(shadow_visibility(L, v_pos, n_shadow, l, filters, view)));
	}
}

// vis.frag: every shadowed light's visibility at v_pos (n_shadow: the plane of its triangle, as
// the main pass hands the filters, facet.glsl) into layer i of vis_out: the filters' value
// where the light reaches (range, cone) and 1 elsewhere, so that the main pass finds a value
// for every light it shades here, at this pixel or a neighbour (vis_pixel). The same
// block-wide walk as light_all, in two: the PCSS lights, then the others. One walk ran every
// filter of the scene for every light (lavapipe runs both sides of an `if` under a mask), and
// code the light does not take still cost: studio-spots (six PCSS lights, one PCF) CPU per
// render 220 ms with PCF's code beside PCSS's, 210 in walks of their own (the same bytes).
void store_visibility(ivec2 px, vec3 n_shadow)
{
	const uint PCSS = 1u << UMBRA_FILTER_PCSS;
	uvec2 reach = uvec2(0u), soft = uvec2(0u);
	for (uint i = 0u; i < frame.mode.w; i++) {
		umbra_light L = lights[i];
		if (L.shadow.y == 0u) continue;
		if (L.shadow.z == UMBRA_FILTER_PCSS) add_light(soft, i);
		float atten = 0.0;
		if ((SC_LIGHT_TYPES & (1u << uint(L.color.w))) != 0u) light_dir(L, v_pos, atten);
		if (atten > 0.0 || frame.mode2.z != 0u) add_light(reach, i);
		else imageStore(vis_out, ivec3(px, int(i)), vec4(1.0));
	}
	uvec2 todo = subgroupOr(reach);
	store_walk(px, n_shadow, reach, todo & soft, SC_FILTERS & PCSS);
	store_walk(px, n_shadow, reach, todo & ~soft, SC_FILTERS & ~PCSS);
}
#endif
#ifdef UMBRA_VIS_READ
// The pixel of the visibility pass whose surface this fragment is: its own, unless its own
// centre shows another surface (at a silhouette, where MSAA shades a surface at pixels its
// samples only partly cover), then the 4-neighbour nearest this fragment's plane with a
// normal like its own. A surface thinner than a pixel that no pixel centre shows takes its
// neighbour's values: it covers part of one pixel. n_geo: the interpolated normal, which
// varies smoothly across the triangles of one surface (the stored normals are the triangles'
// planes; matched with the fragment's plane, a silhouette of a tessellated cylinder took a
// neighbour on another facet and came out 8 steps darker than the filters there).
void vis_candidate(ivec2 q, vec3 n_geo, inout ivec2 best, inout float best_d)
{
	q = clamp(q, ivec2(0), ivec2(frame.target.xy) - 1);
	vec4 s = texelFetch(surfaces, q, 0);
	float d = s.w == 0.0 ? 1e30 : abs(dot(n_geo, s.xyz - v_pos));
	if (s.w != 0.0 && dot(texelFetch(surface_normals, q, 0).xyz, n_geo) < 0.9) d += 1e20;
	if (d < best_d) { best_d = d; best = q; }
}

ivec2 vis_pixel(vec3 n_geo)
{
	ivec2 px = ivec2(gl_FragCoord.xy);
	float z = max(dot(v_pos - frame.camera_pos.xyz, frame.camera_fwd.xyz), 1e-4);
	float tol = 0.5 * frame.target.z * (frame.target.w > 0.5 ? 1.0 : z);   // half a pixel
	ivec2 best = px;
	float best_d = 1e30;
	vis_candidate(px, n_geo, best, best_d);
	// A loop, not four calls: lavapipe leaves it as soon as every pixel of the block has its
	// surface (inside a surface, after the own pixel), where four calls would run for all.
	for (int k = 0; k < 4; k++) {
		if (best_d <= tol) break;
		ivec2 o = ivec2(k == 0 ? -1 : k == 1 ? 1 : 0, k == 2 ? -1 : k == 3 ? 1 : 0);
		vis_candidate(px + o, n_geo, best, best_d);
	}
	return best;
}

float vis_fetch(ivec2 q, uint i)
{
	return texelFetch(vis_image, ivec3(q, int(i)), 0).r;
}
#endif
