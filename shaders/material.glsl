// shaders/material.glsl — what the main pass (shading.glsl) and the alpha-tested depth passes
// (masked.frag) share about materials: texture coordinates per slot, texture reads with their
// mip level, the dither of alpha mode BLEND, and (main and AOV passes: not where the includer
// defines UMBRA_MATERIAL_DEPTH_PASS) the normal-mapped shading normal. Included after
// umbra_shared.h (and, in the main passes, after normal_texture and v_tangent).

// The uv that texture slot `slot` reads: KHR_texture_transform as two rows (identity when the
// material has none).
vec2 material_uv(umbra_material m, uint slot, vec2 uv)
{
	vec4 r0 = m.uvx[2u * slot], r1 = m.uvx[2u * slot + 1u];
	return vec2(dot(r0.xy, uv) + r0.z, dot(r1.xy, uv) + r1.z);
}

// The screen-space derivatives of the interpolated uv, taken once by material_derivatives()
// at the top of main(), in uniform control flow, before any branch on the material. Textures
// have mip chains, so the level comes from these: implicit derivatives inside `if (the
// material has this texture)` are undefined where a 2x2 quad's helper lanes do not take the
// branch, and on lavapipe a helper lane reads the material buffer as zeros, which put a
// coarse level on every pixel along a triangle edge. Zero (never taken): level 0.
// The second uv set's (uv1) only where the scene's materials read it (UMBRA_TEXBIT_UV1).
vec2 material_dx = vec2(0.0), material_dy = vec2(0.0);
vec2 material_dx1 = vec2(0.0), material_dy1 = vec2(0.0);

void material_derivatives(vec2 uv, vec2 uv1)
{
	material_dx = dFdx(uv);
	material_dy = dFdy(uv);
	if ((SC_TEXTURES & UMBRA_TEXBIT_UV1) != 0u) {
		material_dx1 = dFdx(uv1);
		material_dy1 = dFdy(uv1);
	}
}

// Whether slot `slot` of m samples the second uv set: one bit of the draw's material (the
// same for the whole draw: a select, not a divergent branch), folded away in scenes that
// have none.
bool material_reads_uv1(umbra_material m, uint slot)
{
	return (SC_TEXTURES & UMBRA_TEXBIT_UV1) != 0u && (m.tex.x & (1u << (UMBRA_TEX_UV1_SHIFT + slot))) != 0u;
}

// Texture slot `slot` at its uv set's coordinate (uv or uv1, through the slot's transform),
// its gradients carried through the same (affine) transform.
vec4 material_texture(sampler2D s, umbra_material m, uint slot, vec2 uv, vec2 uv1)
{
	bool one = material_reads_uv1(m, slot);
	vec4 r0 = m.uvx[2u * slot], r1 = m.uvx[2u * slot + 1u];
	mat2 t = mat2(r0.x, r1.x, r0.y, r1.y);
	return textureGrad(s, material_uv(m, slot, one ? uv1 : uv), t * (one ? material_dx1 : material_dx),
	                   t * (one ? material_dy1 : material_dy));
}

// What of the coverage a see-through texture (UMBRA_TEX_TRANSMISSION, its R) leaves: 1 - the
// material's see-through share (the float bits `share`, umbra_material.ext.z) x R.
float see_through_keep(sampler2D s, umbra_material m, uint share, vec2 uv, vec2 uv1)
{
	return 1.0 - uintBitsToFloat(share) * material_texture(s, m, UMBRA_TEX_TRANSMISSION, uv, uv1).r;
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

#ifndef UMBRA_MATERIAL_DEPTH_PASS
// The shading normal: the normal map (tangent space, xy times normalTexture.scale) in the
// frame of the interpolated tangent when `mapped`, else the geometric normal. The main pass
// shades with it and the AOV pass writes it (N.X/Y/Z), so both show the same surface.
// A tangent-space normal map's normal (texture slot `slot` of m, xy times scale) in the frame of
// the interpolated tangent around n_geo; n_geo where the uvs give no usable tangent.
vec3 tangent_normal(sampler2D s, umbra_material m, uint slot, vec3 n_geo, float scale)
{
	vec3 t = v_tangent.xyz - n_geo * dot(n_geo, v_tangent.xyz);
	float tl = length(t);
	if (tl < 1e-4) return n_geo;   // no usable tangent here (degenerate uvs)
	t /= tl;
	vec3 b = cross(n_geo, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
	vec3 tn = material_texture(s, m, slot, v_uv, v_uv1).xyz * 2.0 - 1.0;
	tn.xy *= scale;
	vec3 n = t * tn.x + b * tn.y + n_geo * tn.z;
	float nl = length(n);
	return nl > 1e-6 ? n / nl : n_geo;
}

vec3 material_normal(umbra_material m, vec3 n_geo, bool mapped)
{
	if (!mapped) return n_geo;
	return tangent_normal(normal_texture, m, UMBRA_TEX_NORMAL, n_geo, m.params.z);
}
#endif
