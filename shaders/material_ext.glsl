// shaders/material_ext.glsl — the glTF 2.0 PBR extensions' lobes over the base layer, as the
// Khronos sample viewer draws them under punctual lights: KHR_materials_specular and _ior (the
// dielectric's F0, F90 and specular weight), KHR_materials_sheen (a Charlie sheen lobe; the base
// scaled by the sheen's albedo) and KHR_materials_clearcoat (a second GGX lobe with its own
// roughness and normal; the layers under it scaled by 1 - coat x Fresnel). Included by
// shading.glsl after has_tex() and PI; mesh_main.glsl calls ext_surface_at() once per pixel,
// light_all() calls ext_light() per light, main() ext_ambient() for the hemisphere light.
//
// Every entry point is folded away unless UMBRA_SC_MATERIAL_EXT has a lobe's bit (some drawn
// material has it, renderer/record.c): lavapipe runs both sides of an `if` for a whole 4x4
// block, so a scene without these extensions must not carry their code. Within a scene that
// has one, a material without it runs the lobe with a factor that makes it vanish.
//
// Hook for image-based light: ext_s holds each lobe's parameters at this pixel (the coat's
// normal, roughness and F0, the sheen's colour and roughness); ext_clearcoat_lobe() and
// ext_sheen_lobe() give a lobe's response to light from direction l, and ext_layer() stacks
// base, sheen and coat radiance the way the layers combine. An environment term adds its
// coat and sheen radiance through ext_layer() as ext_ambient() does for the hemisphere.

layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_CLEARCOAT) uniform sampler2D clearcoat_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_CLEARCOAT_ROUGHNESS) uniform sampler2D clearcoat_roughness_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_CLEARCOAT_NORMAL) uniform sampler2D clearcoat_normal_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_SHEEN_COLOR) uniform sampler2D sheen_color_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_SHEEN_ROUGHNESS) uniform sampler2D sheen_roughness_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_SPECULAR) uniform sampler2D specular_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_SPECULAR_COLOR) uniform sampler2D specular_color_texture;

const bool EXT_SPECULAR = (SC_MATERIAL_EXT & UMBRA_EXT_SPECULAR) != 0u;
const bool EXT_SHEEN = (SC_MATERIAL_EXT & UMBRA_EXT_SHEEN) != 0u;
const bool EXT_CLEARCOAT = (SC_MATERIAL_EXT & UMBRA_EXT_CLEARCOAT) != 0u;

// The lobes' parameters at this pixel (ext_surface_at).
struct ext_surface {
	vec3 f90;          // the base specular's Fresnel at grazing: the specular weight (dielectric), 1 (metal)
	vec3 sheen;        // sheen colour (0: none)
	float sheen_r;     // sheen roughness, 0.07..1 (the Charlie lobe's range)
	float sheen_keep;  // 1 - max(sheen) x E(N.V): what of the base the sheen leaves (toward the viewer)
	float cc;          // coat factor (0: none)
	vec3 cc_n;         // coat normal: its own map, else the geometric normal
	float cc_rough;    // coat roughness, 0.03..1
	float cc_f0;       // coat F0 (from the ior)
	float cc_keep;     // 1 - cc x F_coat(N_coat.V): what of the layers under the coat shows
	float spec_gloss;  // 1: the specular-glossiness model (F0 the specular colour: c_diff x (1 - max(F0)),
	                   // the ambient reflects F0)
};
ext_surface ext_s;

float ext_max3(vec3 v) { return max(v.x, max(v.y, v.z)); }

// Directional albedo E(mu, r) of the sheen lobe below (D_Charlie x the sample viewer's
// visibility, white, integrated over the hemisphere): a least-squares fit (docs/fits/sheen_albedo.py),
// exp of a quadratic in mu with cubic-in-r coefficients, within 0.06 of the integral for
// roughness >= 0.2 and 0.18 at grazing below; capped at 1. The sample viewer reads the same
// function from a lookup texture.
float ext_sheen_albedo(float mu, float r)
{
	vec4 rk = vec4(1.0, r, r * r, r * r * r);
	float c0 = dot(rk, vec4(0.5157, -3.5044, 4.5275, -1.7436));
	float c1 = dot(rk, vec4(-14.3728, 51.5035, -69.396, 30.8084));
	float c2 = dot(rk, vec4(1.1626, -15.646, 31.1757, -16.8134));
	return min(exp(c0 + mu * (c1 + mu * c2)), 1.0);
}

// Sets ext_s for material m at this pixel and returns the base layer's F0: the dielectric's
// ((ior - 1) / (ior + 1))^2 x specular colour (x its texture, capped at 1) x specular weight,
// mixed with the base colour by metalness (f0 in: the core's mix(0.04, base, metal)).
vec3 ext_surface_at(umbra_material m, vec3 N, vec3 n_geo, vec3 V, vec3 base, float metal, vec3 f0)
{
	ext_s.f90 = vec3(1.0);
	ext_s.sheen = vec3(0.0);
	ext_s.sheen_r = 1.0;
	ext_s.sheen_keep = 1.0;
	ext_s.cc = 0.0;
	ext_s.cc_n = n_geo;
	ext_s.cc_rough = 1.0;
	ext_s.cc_f0 = 0.04;
	ext_s.cc_keep = 1.0;
	ext_s.spec_gloss = 0.0;
	float ndv = max(dot(N, V), 1e-4);
	if (EXT_SPECULAR) {
		vec3 col = m.specular.rgb;
		float w = m.specular.w;
		if (has_tex(m, UMBRA_TEX_SPECULAR_COLOR))
			col *= material_texture(specular_color_texture, m, UMBRA_TEX_SPECULAR_COLOR, v_uv, v_uv1).rgb;
		if (has_tex(m, UMBRA_TEX_SPECULAR)) w *= material_texture(specular_texture, m, UMBRA_TEX_SPECULAR, v_uv, v_uv1).a;
		f0 = mix(min(col, vec3(1.0)) * w, base, metal);
		ext_s.f90 = mix(vec3(w), vec3(1.0), metal);
		ext_s.spec_gloss = m.ext.y != 0u ? 1.0 : 0.0;
	}
	if (EXT_SHEEN) {
		vec3 col = m.sheen.rgb;
		float r = m.sheen.w;
		if (has_tex(m, UMBRA_TEX_SHEEN_COLOR))
			col *= material_texture(sheen_color_texture, m, UMBRA_TEX_SHEEN_COLOR, v_uv, v_uv1).rgb;
		if (has_tex(m, UMBRA_TEX_SHEEN_ROUGHNESS))
			r *= material_texture(sheen_roughness_texture, m, UMBRA_TEX_SHEEN_ROUGHNESS, v_uv, v_uv1).a;
		ext_s.sheen = col;
		ext_s.sheen_r = clamp(r, 0.07, 1.0);
		ext_s.sheen_keep = 1.0 - ext_max3(col) * ext_sheen_albedo(ndv, ext_s.sheen_r);
	}
	if (EXT_CLEARCOAT) {
		float cc = m.clearcoat.x, r = m.clearcoat.y;
		if (has_tex(m, UMBRA_TEX_CLEARCOAT)) cc *= material_texture(clearcoat_texture, m, UMBRA_TEX_CLEARCOAT, v_uv, v_uv1).r;
		if (has_tex(m, UMBRA_TEX_CLEARCOAT_ROUGHNESS))
			r *= material_texture(clearcoat_roughness_texture, m, UMBRA_TEX_CLEARCOAT_ROUGHNESS, v_uv, v_uv1).g;
		if (has_tex(m, UMBRA_TEX_CLEARCOAT_NORMAL))
			ext_s.cc_n = tangent_normal(clearcoat_normal_texture, m, UMBRA_TEX_CLEARCOAT_NORMAL, n_geo, m.clearcoat.z);
		ext_s.cc = cc;
		ext_s.cc_rough = clamp(r, 0.03, 1.0);
		ext_s.cc_f0 = m.clearcoat.w;
		float nv = clamp(dot(ext_s.cc_n, V), 0.0, 1.0);
		ext_s.cc_keep = 1.0 - cc * (ext_s.cc_f0 + (1.0 - ext_s.cc_f0) * pow(1.0 - nv, 5.0));
	}
	return f0;
}

// The sample viewer's sheen visibility (Estevez and Kulla's lambda, fitted in alpha = r^2).
float ext_sheen_lambda_fit(float x, float ag)
{
	float t = (1.0 - ag) * (1.0 - ag);
	float a = mix(21.5473, 25.3245, t), b = mix(3.82987, 3.32435, t), c = mix(0.19823, 0.16801, t);
	float d = mix(-1.97760, -1.27393, t), e = mix(-4.32054, -4.85967, t);
	return a / (1.0 + b * pow(x, c)) + d * x + e;
}

float ext_sheen_lambda(float c, float ag)
{
	return c < 0.5 ? exp(ext_sheen_lambda_fit(c, ag))
	               : exp(2.0 * ext_sheen_lambda_fit(0.5, ag) - ext_sheen_lambda_fit(1.0 - c, ag));
}

// The sheen lobe's response to light from l seen from V (Charlie distribution x visibility x
// N.l; radiance per unit of the light's irradiance normal to it).
vec3 ext_sheen_lobe(vec3 N, vec3 V, vec3 l)
{
	vec3 h = normalize(l + V);
	float ndl = max(dot(N, l), 1e-4), ndv = max(dot(N, V), 1e-4), ndh = max(dot(N, h), 0.0);
	float ag = ext_s.sheen_r * ext_s.sheen_r, inv = 1.0 / ag;
	float D = (2.0 + inv) * pow(max(1.0 - ndh * ndh, 0.0), 0.5 * inv) / (2.0 * PI);
	float vis = clamp(1.0 / ((1.0 + ext_sheen_lambda(ndv, ag) + ext_sheen_lambda(ndl, ag)) * 4.0 * ndv * ndl), 0.0, 1.0);
	return ext_s.sheen * (D * vis * ndl);
}

// The coat's response to light from l seen from V (GGX with the coat's normal and roughness,
// Schlick Fresnel of the coat's F0, x N_coat.l; not yet x the coat factor).
float ext_clearcoat_lobe(vec3 l, vec3 V)
{
	vec3 n = ext_s.cc_n, h = normalize(l + V);
	float ndl = max(dot(n, l), 0.0), ndv = max(dot(n, V), 1e-4), ndh = max(dot(n, h), 0.0), vdh = max(dot(V, h), 0.0);
	float a = ext_s.cc_rough * ext_s.cc_rough, a2 = a * a;
	float dd = ndh * ndh * (a2 - 1.0) + 1.0;
	float D = a2 / (PI * dd * dd);
	float vis = 0.5 / max(ndl * sqrt(ndv * ndv * (1.0 - a2) + a2) + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2), 1e-8);
	float F = ext_s.cc_f0 + (1.0 - ext_s.cc_f0) * pow(1.0 - vdh, 5.0);
	return F * D * vis * ndl;
}

// The layers stacked as the sample viewer stacks them: sheen over the base (which keeps
// base_keep of itself), the coat over both.
vec3 ext_layer(vec3 base, float base_keep, vec3 sheen, float coat)
{
	vec3 c = EXT_SHEEN ? sheen + base * base_keep : base;
	return EXT_CLEARCOAT ? c * ext_s.cc_keep + ext_s.cc * coat : c;
}

// One light's BRDF with the extensions, in light_all's units (x the light's irradiance
// normal to it and the base's N.l): brdf the core's (Lambert + GGX with F90 1), spec its
// GGX D x visibility, vdh its V.H, ndl > 0 the base's N.l.
vec3 ext_light(vec3 brdf, float spec, float vdh, vec3 N, vec3 V, vec3 l, float ndl)
{
	// KHR_materials_specular: F = F0 + (F90 - F0) (1 - v.h)^5, i.e. the core's minus (1 - F90) x that power.
	if (EXT_SPECULAR) brdf -= (1.0 - ext_s.f90) * (pow(1.0 - vdh, 5.0) * spec);
	if (!EXT_SHEEN && !EXT_CLEARCOAT) return brdf;
	float keep = 1.0;
	vec3 sheen = vec3(0.0);
	if (EXT_SHEEN) {
		sheen = ext_sheen_lobe(N, V, l) / ndl;
		keep = min(ext_s.sheen_keep, 1.0 - ext_max3(ext_s.sheen) * ext_sheen_albedo(ndl, ext_s.sheen_r));
	}
	float coat = EXT_CLEARCOAT ? ext_clearcoat_lobe(l, V) / ndl : 0.0;
	return ext_layer(brdf, keep, sheen, coat);
}

// The hemisphere light (radiance `sky`, at N, occluded) with the extensions: the base's
// ambient under the sheen and the coat, plus the sheen's own (its albedo x that light). The
// coat adds none: the core's dielectric specular has no ambient term either.
vec3 ext_ambient(vec3 ambient, vec3 sky, vec3 N, vec3 V)
{
	vec3 sheen = EXT_SHEEN ? ext_s.sheen * ext_sheen_albedo(max(dot(N, V), 1e-4), ext_s.sheen_r) * sky : vec3(0.0);
	return ext_layer(ambient, ext_s.sheen_keep, sheen, 0.0);
}
