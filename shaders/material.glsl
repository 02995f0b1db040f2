// shaders/material.glsl — what the main pass (shading.glsl) and the alpha-tested depth passes
// (masked.frag) share about materials: texture coordinates per slot and the dither of alpha
// mode BLEND. Included after umbra_shared.h.

// The uv that texture slot `slot` reads: KHR_texture_transform as two rows (identity when the
// material has none).
vec2 material_uv(umbra_material m, uint slot, vec2 uv)
{
	vec4 r0 = m.uvx[2u * slot], r1 = m.uvx[2u * slot + 1u];
	return vec2(dot(r0.xy, uv) + r0.z, dot(r1.xy, uv) + r1.z);
}

// Alpha mode BLEND, dithered: an ordered 4x4 (Bayer) threshold per pixel, so a surface of
// alpha a keeps about a of its pixels (of its shadow-map texels in the depth passes) and the
// same request always gives the same pixels. True when the fragment is kept.
bool dither_keep(float alpha, vec2 frag)
{
	const float bayer[16] = float[16](0.0, 8.0, 2.0, 10.0, 12.0, 4.0, 14.0, 6.0,
	                                  3.0, 11.0, 1.0, 9.0, 15.0, 7.0, 13.0, 5.0);
	uvec2 p = uvec2(frag) & 3u;
	return alpha > (bayer[p.y * 4u + p.x] + 0.5) / 16.0;
}

// Whether alpha (base colour x texture x vertex colour) keeps the fragment under the
// material's alpha mode.
bool alpha_keep(umbra_material m, float alpha, vec2 frag)
{
	if (m.tex.y == UMBRA_ALPHA_MASK) return alpha >= m.params.y;
	if (m.tex.y == UMBRA_ALPHA_BLEND) return dither_keep(alpha, frag);
	return true;
}
