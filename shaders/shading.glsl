// shaders/shading.glsl — what the main pass (mesh.frag, mesh_vis.frag via mesh_main.glsl), the
// AOV pass (aov.frag) and the visibility pass (vis.frag) share: bindings, specialization
// constants, shadow filtering, lighting; with material.glsl, pcss_bounds.glsl, contact.glsl,
// visibility.glsl and display.glsl. Included after umbra_shared.h; the including shader
// declares its outputs and main().
// Main pass: metallic-roughness shading (Lambert + GGX), hemisphere ambient, directional /
// spot / point lights in the contract's units, shadow filtering, tone map and encoding.
//
// Shadow maps hold plain depth (D32), one tile of the depth atlas per shadow view. lavapipe cannot
// filter depth formats linearly, so filtering happens here: textureGather fetches 2x2 texels,
// each is compared with the receiver depth and the results are weighted bilinearly.

// subgroupOr in light_all: the lights that reach any pixel of a block.
#extension GL_KHR_shader_subgroup_arithmetic : require

layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_FRAME) uniform FrameBlock { umbra_frame frame; };
layout(std430, set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_MATERIALS) readonly buffer Materials { umbra_material materials[]; };
// Lights and shadow views are uniform blocks: every lane reads the same entry, which lavapipe
// turns into one broadcast load (storage-buffer loads are gathered lane by lane).
layout(std140, set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_LIGHTS) uniform Lights { umbra_light lights[UMBRA_MAX_LIGHTS]; };
layout(std140, set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SHADOW_VIEWS) uniform Views { umbra_shadow_view views[UMBRA_MAX_SHADOW_VIEWS]; };
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SHADOW_MAP) uniform sampler2D shadow_atlas;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_MOMENTS) uniform sampler2D moment_atlas;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SCENE_DEPTH) uniform sampler2D scene_depth;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_DEPTH_BOUNDS) uniform sampler2D depth_bounds;
#if defined(UMBRA_VIS_PASS) || defined(UMBRA_VIS_READ)
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SURFACES) uniform sampler2D surfaces;
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_SURFACE_NORMALS) uniform sampler2D surface_normals;
#endif
#ifdef UMBRA_VIS_READ
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_VISIBILITY) uniform sampler2DArray vis_image;
#endif
#ifdef UMBRA_VIS_PASS
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_VISIBILITY_OUT, r16) uniform writeonly image2DArray vis_out;
#endif
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_BINDING_BASE_TEXTURE) uniform sampler2D base_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_TEX_TRANSMISSION) uniform sampler2D transmission_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_BINDING_METAL_ROUGH_TEXTURE) uniform sampler2D metal_rough_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_BINDING_NORMAL_TEXTURE) uniform sampler2D normal_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_BINDING_OCCLUSION_TEXTURE) uniform sampler2D occlusion_texture;
layout(set = UMBRA_SET_MATERIAL, binding = UMBRA_BINDING_EMISSIVE_TEXTURE) uniform sampler2D emissive_texture;
#ifdef UMBRA_PUSH_MAIN
layout(push_constant) uniform PushBlock { umbra_push_main pc; };   // main pass (mesh.frag)
#else
layout(push_constant) uniform PushBlock { umbra_push pc; };
#endif

// Specialization constants: each pipeline variant carries only the code its scene needs.
// lavapipe executes both sides of a divergent-looking branch under a mask, so dead paths
// (other filters, debug views, tone maps) would otherwise cost every pixel.
layout(constant_id = UMBRA_SC_FILTERS) const uint SC_FILTERS = 7u;     // bit (1 << UMBRA_FILTER_*)
layout(constant_id = UMBRA_SC_DEBUG) const uint SC_DEBUG = 0u;         // UMBRA_DEBUG_*
layout(constant_id = UMBRA_SC_LINEAR) const uint SC_LINEAR = 0u;       // 1 = scene-referred output
layout(constant_id = UMBRA_SC_TONEMAP) const uint SC_TONEMAP = 0u;     // UMBRA_TONEMAP_*
layout(constant_id = UMBRA_SC_CATCHER) const uint SC_CATCHER = 0u;     // scene has shadow catchers
layout(constant_id = UMBRA_SC_LIGHT_TYPES) const uint SC_LIGHT_TYPES = 7u; // bit (1 << UMBRA_LIGHT_*)
layout(constant_id = UMBRA_SC_CASCADES) const uint SC_CASCADES = 1u;   // any directional light has cascades
layout(constant_id = UMBRA_SC_TEXTURES) const uint SC_TEXTURES = 8191u; // bit (1 << UMBRA_TEX_*) | uv1
layout(constant_id = UMBRA_SC_MASKED) const uint SC_MASKED = 6u;       // bit (1 << UMBRA_ALPHA_*)
layout(constant_id = UMBRA_SC_CONTACT) const uint SC_CONTACT = 0u;     // any light marches contact shadows
layout(constant_id = UMBRA_SC_PCF_RADIUS) const uint SC_PCF_RADIUS = 0u; // 1 + the PCF radius all lights share; 0: per light
layout(constant_id = UMBRA_SC_SAMPLES) const uint SC_SAMPLES = 1u;      // samples the pass rasterises
layout(constant_id = UMBRA_SC_MATERIAL_EXT) const uint SC_MATERIAL_EXT = 0u; // UMBRA_EXT_* lobes (material_ext.glsl)

#if defined(UMBRA_VIS_PASS) || defined(UMBRA_ENV_PASS_FRAG)
// vis.frag, env_vis.frag: the surface comes from a surfaces image, not from a triangle.
vec3 v_pos;
vec3 v_nrm;
vec2 v_uv;
vec2 v_uv1;
vec4 v_color;
vec4 v_tangent;
vec2 vis_frag_xy;        // the pixel (centre) this invocation computes, in the view
vec2 frag_xy() { return vis_frag_xy; }
#else
layout(location = 0) in vec3 in_pos;
vec3 v_pos;              // what main() shades: in_pos, or on an analytic sphere (facet.glsl surface_at)
layout(location = 1) in vec3 v_nrm;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_color;
layout(location = 4) in vec4 v_tangent;
layout(location = UMBRA_LOCATION_UV1) in vec2 v_uv1;
vec2 frag_xy() { return gl_FragCoord.xy; }

#include "facet.glsl"
#endif
#include "material.glsl"

// Whether the material samples texture slot `slot` (and any material of the scene does).
bool has_tex(umbra_material m, uint slot)
{
	return (SC_TEXTURES & (1u << slot)) != 0u && (m.tex.x & (1u << slot)) != 0u;
}

const float PI = 3.14159265358979;

#include "material_ext.glsl"

// ---- shadow sampling -------------------------------------------------------------------

// Poisson-disk taps live in the frame uniform block (a dynamically indexed constant array
// would be rebuilt per invocation by lavapipe).
vec2 poisson(int i) { vec4 v = frame.poisson[i >> 1]; return (i & 1) == 0 ? v.xy : v.zw; }

// Every shadow view is a tile of the depth atlas: rect = (x, y, size, atlas size) in texels.
// Gathers the 2x2 texels around tile-local point q, kept inside the tile so filters never
// read a neighbouring tile (views are widened by the filter footprint, so this only clamps
// at the very edge) and never a border texel: the atlas's sampler clamps to the edge.
// The 2x2 are chosen in tile space (q snapped to the texel corner between them), so the
// gather reads an exact atlas coordinate: from a fractional q, which texels it read depended
// on the rounding of the tile's position plus q, and the same request could differ by a step
// at a rare pixel between a fresh process and a daemon whose cached maps had put the tile
// elsewhere (the ogre OBJ's thumbnail: one pixel, CLI against umbrad).
vec4 gather_tile(vec4 rect, vec2 q)
{
	q = clamp(floor(q - 0.5) + 1.0, vec2(1.0), vec2(rect.z - 1.0));
	return textureGather(shadow_atlas, (rect.xy + q) / rect.w);
}

// Bilinearly weighted comparison of the 2x2 texels around texel-space point p (texel centres
// at +0.5). Outside the map everything is lit (border depth 1).
float bilinear_compare(vec2 p, vec4 rect, float ref, float res)
{
	vec2 q = p - 0.5;
	vec2 base = floor(q);
	vec2 f = q - base;
	vec4 d = gather_tile(rect, base + 1.0);
	// gather order: x = (i0,j1), y = (i1,j1), z = (i1,j0), w = (i0,j0)
	vec4 lit = step(vec4(ref), d);
	return mix(mix(lit.w, lit.z, f.x), mix(lit.x, lit.y, f.x), f.y);
}

// (2r+1)^2 bilinear PCF taps, done as (r+1)^2 gathers over the (2r+2)^2 texel footprint.
// grad: receiver depth change per texel (receiver-plane bias), so wide kernels on sloped
// receivers do not shadow the receiver itself.
// When every PCF light of the scene has the same radius, SC_PCF_RADIUS makes it a constant:
// the loops unroll and the tap weights fold (a loop with a radius read per light runs with
// lavapipe's per-lane masks and selects; thumb-512: ~5 % of the render's instructions). Not
// where PCSS lights share the code (filters: what the caller's walk dispatches, a constant):
// sample_view calls pcf() for them too under a mask (lavapipe runs an `if` for all of a block)
// with r = -1, and unrolled gathers would run for every one of them (studio-spots, measured
// when its visibility pass still walked all lights in one: CPU per render -6 % with the radius
// read per light). r < 0: no tap, and a value (0) that the caller never uses.
float pcf(vec2 p, vec4 rect, float ref, float res, int r, vec2 grad, uint filters)
{
	if (SC_PCF_RADIUS != 0u && (filters & (1u << UMBRA_FILTER_PCSS)) == 0u) r = int(SC_PCF_RADIUS) - 1;
	vec2 q = p - 0.5;
	vec2 base = floor(q);
	vec2 f = q - base;
	float sum = 0.0;
	int last = 2 * r + 1;
	for (int j = 0; j <= 2 * r; j += 2) {
		for (int i = 0; i <= 2 * r; i += 2) {
			vec2 corner = base + vec2(float(i - r), float(j - r)) + 1.0;
			float rc = ref + dot(grad, corner - p);
			vec4 lit = step(vec4(rc), gather_tile(rect, corner));
			float wx0 = i == 0 ? 1.0 - f.x : 1.0, wx1 = i + 1 == last ? f.x : 1.0;
			float wy0 = j == 0 ? 1.0 - f.y : 1.0, wy1 = j + 1 == last ? f.y : 1.0;
			sum += lit.w * wx0 * wy0 + lit.z * wx1 * wy0 + lit.x * wx0 * wy1 + lit.y * wx1 * wy1;
		}
	}
	float n = float(last);
	return sum / (n * n);
}

float hard(vec2 p, vec4 rect, float ref, float res)
{
	ivec2 t = ivec2(floor(p));
	if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, ivec2(int(res))))) return 1.0;
	return ref <= texelFetch(shadow_atlas, ivec2(rect.xy) + t, 0).r ? 1.0 : 0.0;
}


// A perspective shadow view (spot, point face). Scenes with only directional lights fold it to
// false through the specialization constant: lavapipe would otherwise run both sides of every
// such branch (the condition is read per lane), which cost ~12 % of a sun-lit thumbnail.
bool is_persp(umbra_shadow_view v)
{
	return (SC_LIGHT_TYPES & ((1u << UMBRA_LIGHT_SPOT) | (1u << UMBRA_LIGHT_POINT))) != 0u && v.params.y > 0.5;
}

// Distance along the light's axis (world units) for a stored depth of view v.
float view_distance(umbra_shadow_view v, float d)
{
	float n = v.params.z, f = v.params.w;
	if (is_persp(v)) return n * f / (f - d * (f - n));   // perspective depth 0..1 -> linear
	return n + d * (f - n);                                   // orthographic: linear
}

// Penumbra half-width, in texels at the receiver, that a blocker at distance zb casts on a
// receiver at zr, by similar triangles in the light's own projection: a sphere light of radius
// `size` seen through a perspective view, or a sun of angular radius atan(size) through an
// orthographic one.
vec4 penumbra_texels(umbra_shadow_view v, float size, vec4 zb, float zr, float texel)
{
	if (is_persp(v)) return size * (zr - zb) / (max(zb, vec4(1e-4)) * texel);
	return size * (zr - zb) / texel;
}

#include "pcss_bounds.glsl"

// PCSS: blocker search over the region that could shade this point, penumbra from the
// light's size by similar triangles, then a Poisson-disk PCF of that width. The disk is the
// same for every pixel (not rotated per pixel): across an edge its 32 bilinear taps form a
// smooth ramp rather than a dot pattern (against the traced reference the penumbrae's
// high-frequency energy fell to 40 % of the rotated disk's); thin casters under very wide
// penumbrae show faint streaks instead.
// A texel counts as a blocker only when this point lies inside the penumbra it casts (its
// offset within its own penumbra half-width): distant parts of a caster (the top of a pole
// seen from the pole's foot) would otherwise widen the penumbra where the caster touches the
// receiver.
// Cost: the 25-gather search is most of what many soft lights cost (16 spot lights: ~340 of
// ~540 ms CPU per render; the 32 filter taps ~50 ms). Fewer search taps (13 or 17) doubled the
// point light's error against the traced reference (test_truth). So the search is skipped
// where the atlas's depth bounds (pcss_bounds: one to five texel fetches) prove its answer: no
// caster near (lit, 1.0) or every texel in reach a blocker (umbra, 0.0) give the very values
// the search and filter would; only the rest, in and around shadows, runs them (CPU per
// render: studio-spots 360 -> 319 ms, 16 lights 499 -> 419 ms; lit is proved on most of what
// a light reaches, umbra only under casters wider than the search's reach).
float pcss(umbra_light L, umbra_shadow_view v, vec2 p, vec4 rect, float ref, float res, vec2 grad)
{
	float zr = view_distance(v, ref);
	float texel = is_persp(v) ? v.params.x * zr : v.params.x;   // world size of a texel at the receiver
	float size = L.params.y;                                          // tan(angular radius) or radius (m)
	// Search radius: the widest penumbra a blocker at the light's near plane could cast here, capped.
	float search = penumbra_texels(v, size, vec4(v.params.z), zr, texel).x;
	search = clamp(search, 1.0, L.shadow_params.y);
	// penumbra_texels of a stored depth d is affine in d in both projections (perspective:
	// 1 / zb = 1/n - d (f - n) / (n f); orthographic: zb = n + d (f - n)), so the reach test
	// of a tap is one multiply-add per texel instead of two divisions (view_distance and the
	// penumbra) per texel: reach(d) = r0 - r1 d, same values up to rounding.
	float n = v.params.z, f = v.params.w;
	float k = size / texel;
	float r0 = is_persp(v) ? k * (zr / n - 1.0) : k * (zr - n);
	float r1 = is_persp(v) ? k * zr * (f - n) / (n * f) : k * (f - n);
	r0 += 1.5;
	float blockers = 0.0, sum_d = 0.0;
	// Texels of the receiver's own plane must not count as blockers: compare against the
	// plane's depth at each tap, with slack for the 2x2 footprint of a gather.
	float slack = abs(grad.x) + abs(grad.y) + 1e-6;
	// Search and filter taps stay within `search` texels times the longest tap (frame.params.w,
	// renderer/frame.c): the filter's radius comes from the blockers' depth, never nearer the
	// light than the near plane the search assumed (+1 for rounding).
	float reach_max;
	int known = pcss_bounds(L, p, rect, ref, grad, slack, search * frame.params.w + 1.0, r0, r1, reach_max);
	// Tap 0 is the point itself and taps 1..8 a close ring (3 texels): where penumbrae are
	// narrower than the spacing of the wide taps (low casters, contact), they find the blockers
	// whose penumbra reaches this point; taps 9..24 cover the whole search region, in ascending
	// distance (frame.c). A tap farther than reach_max cannot find a blocker (the lowest depth
	// around p caps every texel's reach), so the search stops before the first such wide tap:
	// the same blockers and sums (test_pcss_bounds: the same bytes as with the bounds unread;
	// putting the wide taps in that order changed the order of the sums, and no picture tried
	// changed a byte). Around low casters most wide taps lie beyond it (studio-spots: CPU per
	// render -6 %; a model under one sun: no change).
	float close = min(search, 3.0);
	int wide = 0;
	while (known == 0 && wide < 16 && length(poisson(2 * wide)) * search <= reach_max) wide++;
	int search_taps = known == 0 ? 9 + wide : 0;
	for (int i = 0; i < search_taps; i++) {
		vec2 off = i == 0 ? vec2(0.0) : poisson(i < 9 ? (i - 1) * 4 + 1 : (i - 9) * 2) * (i < 9 ? close : search);
		vec4 d = gather_tile(rect, p + off);
		vec4 b = step(d, vec4(ref + dot(grad, off) - slack)) * step(vec4(length(off)), r0 - r1 * d);
		blockers += dot(b, vec4(1.0));
		sum_d += dot(b, d);
	}
	// No blocker: fully lit. The filter's trip count says so rather than an early return:
	// lavapipe executes an `if` for the whole block of pixels under a mask but leaves a loop
	// once no pixel of the block has iterations left, so a block that this light reaches
	// unoccluded skips all 32 taps (with the per-pixel light loop of light_all: 16 spot and
	// point lights half the main pass).
	int taps = blockers < 0.5 ? 0 : 32;
	float zb = view_distance(v, sum_d / max(blockers, 1.0));
	// Capped like the search: views are widened by that many texels, so taps stay in the view.
	float radius = clamp(penumbra_texels(v, size, vec4(zb), zr, texel).x, 1.0, L.shadow_params.y);
	float sum = 0.0;
	for (int i = 0; i < taps; i++) {
		vec2 off = (poisson(i) - frame.filter_taps.xy) * (radius * frame.filter_taps.z);   // a uniform disk's spread (frame.c)
		sum += bilinear_compare(p + off, rect, ref + dot(grad, off), res);
	}
	return known == 2 ? 0.0 : taps == 0 ? 1.0 : sum / 32.0;
}

// Receiver plane: how the receiver's light-space depth changes per shadow-map texel, so that
// wide kernels compare each tap with the receiver's own plane there, not with the depth at the
// centre (which shadows a sloped receiver by itself). Orthographic views: from the normal
// (the transform is affine). Perspective views (spot, point faces): a plane stays a plane under
// a projective map, so NDC depth is affine in NDC x, y on it; the gradient comes from projecting
// two points of the tangent plane (lc0: pos in clip space, h: a texel in world units at pos).
vec2 receiver_gradient(umbra_shadow_view v, vec3 pos, vec3 n, vec4 lc0, float h, float res)
{
	if (is_persp(v)) {
		vec3 t1 = normalize(cross(n, abs(n.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)));
		vec3 t2 = cross(n, t1);
		vec4 c1 = v.view_proj * vec4(pos + t1 * h, 1.0), c2 = v.view_proj * vec4(pos + t2 * h, 1.0);
		vec3 p0 = lc0.xyz / lc0.w, p1 = c1.xyz / c1.w, p2 = c2.xyz / c2.w;
		vec2 e1 = (p1.xy - p0.xy) * (0.5 * res), e2 = (p2.xy - p0.xy) * (0.5 * res);   // texels
		float det = e1.x * e2.y - e1.y * e2.x;
		if (abs(det) < 1e-12) return vec2(0.0);
		// g with dot(g, e1) = dz1 and dot(g, e2) = dz2
		float dz1 = p1.z - p0.z, dz2 = p2.z - p0.z;
		vec2 g = vec2(dz1 * e2.y - dz2 * e1.y, dz2 * e1.x - dz1 * e2.x) / det;
		return clamp(g, vec2(-0.01), vec2(0.01));
	}
	mat3 a = mat3(v.view_proj);
	vec3 r0 = vec3(a[0][0], a[1][0], a[2][0]), r1 = vec3(a[0][1], a[1][1], a[2][1]), r2 = vec3(a[0][2], a[1][2], a[2][2]);
	// Normal of the plane in light clip space: (A^-T) n = S^-2 A n for A = S R.
	vec3 ns = (a * n) / vec3(dot(r0, r0), dot(r1, r1), dot(r2, r2));
	if (abs(ns.z) < 1e-8) return vec2(0.0);
	vec2 g = -ns.xy / ns.z * (2.0 / res);
	return clamp(g, vec2(-0.01), vec2(0.01));
}

// Visibility of light L at world position pos with geometric normal n.
// Moment shadow maps (VSM / EVSM2): Chebyshev's upper bound on the blurred moments.
// The moments are blurred and filtered linearly, so the filter is as wide as the blur; the
// variance floor and light-bleed reduction trade softness against leaks.
float moments(umbra_light L, umbra_shadow_view v, vec2 uv, vec4 rect, float ref)
{
	vec2 tp = uv * rect.z;
	// A sun map fitted to its casters: no caster lies within a blur of this band along its
	// edge, where the blur's clamp skews the ground's moments (plan.c moment_edge).
	float edge = L.moment_params.w;
	if (any(lessThan(tp, vec2(edge))) || any(greaterThan(tp, vec2(rect.z - edge)))) return 1.0;
	vec2 m = texture(moment_atlas, (rect.xy + clamp(tp, vec2(0.5), vec2(rect.z - 0.5))) / rect.w).xy;
	if (is_persp(v)) ref = (view_distance(v, ref) - v.params.z) / (v.params.w - v.params.z);   // as moments.comp
	float c = L.moment_params.x;
	float t = c > 0.0 ? exp(c * ref) : ref;
	float min_var = c > 0.0 ? L.moment_params.z * c * t * c * t * 1e-4 : L.moment_params.z;
	if (t <= m.x) return 1.0;
	float var = max(m.y - m.x * m.x, min_var);
	float d = t - m.x;
	float p = var / (var + d * d);
	float lbr = L.moment_params.y;
	return clamp((p - lbr) / (1.0 - lbr), 0.0, 1.0);
}

// Visibility of light L at pos (geometric normal n) in one shadow view vi.
float sample_view(umbra_light L, uint vi, vec3 pos, vec3 n, vec3 to_light, uint filters)
{
	umbra_shadow_view v = views[vi];
	float res = v.rect.z;
	// Normal offset: move the lookup point along the normal by a few texels (world units at
	// this point), more at grazing angles where acne appears first.
	// lc = M (pos + n o) = M pos + (M n) o: one full transform and one of the normal.
	vec4 lc0 = v.view_proj * vec4(pos, 1.0);
	float dist = is_persp(v) ? max(lc0.w, 1e-4) : 1.0;
	float texel = v.params.x * dist;
	float ndl = clamp(dot(n, to_light), 0.0, 1.0);
	vec4 lc = lc0 + (v.view_proj * vec4(n, 0.0)) * (L.shadow_params.x * texel * (1.0 - 0.5 * ndl));
	vec3 sc = is_persp(v) ? lc.xyz / lc.w : lc.xyz;   // orthographic: w is exactly 1 (three divisions a lookup)
	if (sc.z > 1.0) return 1.0;            // beyond the light's far plane: nothing recorded there
	if (any(greaterThan(abs(sc.xy), vec2(1.0)))) return 1.0;   // outside this view: nothing casts
	vec2 uv = sc.xy * 0.5 + 0.5;
	vec2 tp = uv * res;
	float ref = clamp(sc.z, 0.0, 1.0);     // depth clamp: casters before the near plane pancake to 0
	vec4 rect = v.rect;
	uint filt = L.shadow.z;
	if ((filters & (1u << UMBRA_FILTER_HARD)) != 0u && filt == UMBRA_FILTER_HARD) return hard(tp, rect, ref, res);
	if ((filters & (1u << UMBRA_FILTER_PCSS)) != 0u && filt == UMBRA_FILTER_PCSS) return pcss(L, v, tp, rect, ref, res, receiver_gradient(v, pos, n, lc0, texel, res));
	if ((filters & (1u << UMBRA_FILTER_MOMENTS)) != 0u && filt == UMBRA_FILTER_MOMENTS) return moments(L, v, uv, rect, ref);
	// r -1 (no tap) for a light of another filter, which pcf() runs for under a mask (see pcf()).
	if ((filters & (1u << UMBRA_FILTER_PCF)) != 0u)
		return pcf(tp, rect, ref, res, filt == UMBRA_FILTER_PCF ? int(L.shadow.w) : -1,
		           receiver_gradient(v, pos, n, lc0, texel, res), filters);
	return 1.0;
}

// Largest |x|, |y| of pos in view vi's clip space (<= 1: inside the level).
float view_extent(uint vi, vec3 pos)
{
	vec4 c = views[vi].view_proj * vec4(pos, 1.0);
	return max(abs(c.x), abs(c.y)) / c.w;
}

// Visibility of light L at world position pos with geometric normal n: picks the cube face,
// cascade or clipmap level, blends across cascade / level borders, fades out towards the
// light's max distance. view_out: the cascade / level / face used (debug views).
float map_visibility(umbra_light L, vec3 pos, vec3 n, vec3 to_light, uint filters, out uint view_out)
{
	view_out = 0u;
	if (L.shadow.y == 0u) return 1.0;
	uint first = L.shadow.x, count = L.shadow.y;
	uint type = uint(L.color.w);
	// The view (cube face, cascade or clipmap level) is chosen first and sampled once: lavapipe
	// runs both sides of every branch under a mask, so a lookup written per kind of view cost
	// every light each kind's lookup and filter (main pass with the visibility pass,
	// studio-spots 135 -> 110 ms, 16 spot and point lights 189 -> 153 ms).
	uint c = 0u;
	float t = 0.0;   // blend into view c + 1 (cascade / clipmap borders)
	float z = dot(pos - frame.camera_pos.xyz, frame.camera_fwd.xyz);
	if ((SC_LIGHT_TYPES & (1u << UMBRA_LIGHT_POINT)) != 0u && type == UMBRA_LIGHT_POINT) {
		vec3 d = pos - L.position.xyz;
		vec3 ad = abs(d);
		c = ad.x >= ad.y && ad.x >= ad.z ? (d.x > 0.0 ? 0u : 1u)
		  : ad.y >= ad.z ? (d.y > 0.0 ? 2u : 3u) : (d.z > 0.0 ? 4u : 5u);
	} else if (SC_CASCADES != 0u && type == UMBRA_LIGHT_DIRECTIONAL && count > 1u) {
		if (L.params.z > 0.5) {
			// Clipmap: the finest level that contains the point; blend into the next level over
			// the outer `blend` fraction of this one.
			float e = view_extent(first, pos);
			while (c + 1u < count && e > 0.98) { c++; e = view_extent(first + c, pos); }
			float band = max(L.shadow_params.z, 1e-3);
			t = clamp((e - (0.98 - band)) / band, 0.0, 1.0);
		} else {
			while (c + 1u < count && z > L.splits[c]) c++;
			// Blend band at the far end of each cascade: no visible seam between cascades.
			float prev = c == 0u ? 0.0 : L.splits[c - 1u];
			float start = L.splits[c] - L.shadow_params.z * (L.splits[c] - prev);
			t = z > start ? clamp((z - start) / max(L.splits[c] - start, 1e-6), 0.0, 1.0) : 0.0;
		}
		if (c + 1u >= count) t = 0.0;
	}
	view_out = c;
	float vis = sample_view(L, first + c, pos, n, to_light, filters);
	if (SC_CASCADES != 0u && t > 0.0) vis = mix(vis, sample_view(L, first + c + 1u, pos, n, to_light, filters), t);
	// Distance fade to unshadowed before max distance, so the end of the shadows has no edge
	// (point lights have none).
	float max_d = L.params.w, fade_start = L.shadow_params.w;
	bool fades = type != UMBRA_LIGHT_POINT && max_d > 0.0;
	if (fades && z >= max_d) return 1.0;
	if (fades && z > fade_start) vis = mix(vis, 1.0, smoothstep(fade_start, max_d, z));
	return vis;
}

#include "contact.glsl"

// Visibility of light L: its shadow map, and where asked, contact shadows (the smaller of the two).
float shadow_visibility(umbra_light L, vec3 pos, vec3 n, vec3 to_light, uint filters, out uint view_out)
{
	float vis = map_visibility(L, pos, n, to_light, filters, view_out);
	if (SC_CONTACT != 0u && L.contact.w > 0.5 && vis > 0.0) vis = min(vis, contact_visibility(L, L.shadow.x + view_out, pos, n, to_light));
	return vis;
}

// ---- shading ---------------------------------------------------------------------------

// Lights as sets of bits (uvec2: UMBRA_MAX_LIGHTS = 64). light_all and the visibility pass
// walk the set of lights that reach any pixel of a block (subgroupOr) one light at a time.
void add_light(inout uvec2 set, uint i) { set[i >> 5] |= 1u << (i & 31u); }
bool has_light(uvec2 set, uint i) { return (set[i >> 5] & (1u << (i & 31u))) != 0u; }
uint take_light(inout uvec2 set)   // the lowest light of a non-empty set, taken out of it
{
	uint i = set.x != 0u ? uint(findLSB(set.x)) : 32u + uint(findLSB(set.y));
	set[i >> 5] &= ~(1u << (i & 31u));
	return i;
}

// Direction towards light L from pos and its attenuation: inverse square with the
// KHR_lights_punctual range window, and the smooth spot cone.
vec3 light_dir(umbra_light L, vec3 pos, out float atten)
{
	uint type = uint(L.color.w);
	atten = 1.0;
	// Only directional lights in the scene: the rest is folded away (it would run under a mask).
	const bool only_sun = SC_LIGHT_TYPES == (1u << UMBRA_LIGHT_DIRECTIONAL);
	if ((SC_LIGHT_TYPES & (1u << UMBRA_LIGHT_DIRECTIONAL)) != 0u && (only_sun || type == UMBRA_LIGHT_DIRECTIONAL))
		return -L.direction.xyz;
	vec3 d = L.position.xyz - pos;
	float dist2 = max(dot(d, d), 1e-8);
	vec3 l = d * inversesqrt(dist2);
	atten = 1.0 / dist2;
	if (L.position.w > 0.0) {
		float r = sqrt(dist2) / L.position.w;
		atten *= pow(clamp(1.0 - r * r * r * r, 0.0, 1.0), 2.0);
	}
	if ((SC_LIGHT_TYPES & (1u << UMBRA_LIGHT_SPOT)) != 0u && type == UMBRA_LIGHT_SPOT) {
		float cos_outer = L.direction.w, cos_inner = L.params.x;
		float cd = dot(L.direction.xyz, -l);
		float t = clamp((cd - cos_outer) / max(cos_inner - cos_outer, 1e-4), 0.0, 1.0);
		atten *= t * t;
	}
	return l;
}

#include "visibility.glsl"

// Base colour times its texture (sRGB texels decode to linear in the sampler) times the
// vertex colour, alpha times what the see-through texture leaves (material.glsl); alpha MASK
// discards below the cutoff, BLEND by the dither (material.glsl).
vec4 base_color(umbra_material m)
{
	vec4 c = m.base_color;
	if (has_tex(m, UMBRA_TEX_BASE)) c *= material_texture(base_texture, m, UMBRA_TEX_BASE, v_uv, v_uv1);
	c *= v_color;   // (white where a mesh has no colours: mesh.c)
	if (has_tex(m, UMBRA_TEX_TRANSMISSION))
		c.a *= see_through_keep(transmission_texture, m, materials[pc.info.x].ext.z, v_uv, v_uv1);
	if (SC_MASKED != 0u && m.tex.y != UMBRA_ALPHA_OPAQUE && !alpha_keep(m, c.a, gl_FragCoord.xy)) discard;
	return c;
}

// Direct light from every light: with and without shadows (the shadow catcher needs both),
// and the visibility of the debug light. N: the shading normal; n_geo: the interpolated one;
// n_shadow, p_shadow: the plane of the triangle and where on it the shadow lookups look
// (facet.glsl).
void light_all(vec3 N, vec3 n_geo, vec3 n_shadow, vec3 p_shadow, vec3 V, vec3 c_diff, vec3 f0, float rough, bool receive,
               out vec3 lit, out vec3 unshadowed, out float debug_vis, out uint debug_view)
{
	float a2 = rough * rough * rough * rough;
	float ndv = max(dot(N, V), 1e-4);
	lit = vec3(0.0);
	unshadowed = vec3(0.0);
	debug_vis = 1.0;
	debug_view = 0u;
	uint light_count = frame.mode.w;
	// Light culling per pixel. A light whose range or cone does not reach this point (atten 0)
	// or that lies behind its surface (n.l <= 0) adds exactly nothing, so only the lights in
	// `reach` are shaded, in the same order as before. lavapipe runs a block of pixels (a
	// subgroup) in lock step and executes both sides of every `if` under a mask, but it leaves
	// a loop as soon as no pixel has work left: walking the lights that reach some pixel of the
	// block (subgroupOr) costs the block only those lights, with their shadow lookups; and the
	// light index is the same for the whole block, so its light and views are read as one
	// broadcast each rather than lane by lane. frame.mode2.z != 0 turns culling off
	// (UMBRA_LIGHT_CULL=0), for the test that the image does not change.
	uvec2 reach = uvec2(0u);
	for (uint i = 0u; i < light_count; i++) {
		umbra_light L = lights[i];
		if ((SC_LIGHT_TYPES & (1u << uint(L.color.w))) == 0u) continue;
		float atten;
		vec3 l = light_dir(L, v_pos, atten);
		bool reaches = dot(N, l) > 0.0 && atten > 0.0;
		if (reaches || i == frame.mode.z || frame.mode2.z != 0u) add_light(reach, i);
	}
	uvec2 todo = subgroupOr(reach);
#ifdef UMBRA_VIS_READ
	ivec2 vis_px = receive ? vis_pixel(n_geo) : ivec2(0);
#endif
	while (todo != uvec2(0u)) {
		uint i = take_light(todo);
		if (!has_light(reach, i)) continue;
		umbra_light L = lights[i];
		float atten;
		vec3 l = light_dir(L, v_pos, atten);
		float ndl = dot(N, l);
		uint view = 0u;
		float vis = 1.0;
#if defined(UMBRA_VIS_READ)
		if (SC_FILTERS != 0u && receive && L.shadow.y != 0u) vis = vis_fetch(vis_px, i);
#elif !defined(UMBRA_VIS_PASS) || defined(UMBRA_VIS_SHADE)
		if (SC_FILTERS != 0u && receive) vis = shadow_visibility(L, p_shadow, n_shadow, l, SC_FILTERS, view);
#endif
		if (i == frame.mode.z) { debug_vis = vis; debug_view = view; }
		if (ndl <= 0.0 || atten <= 0.0) continue;
		vec3 h = normalize(l + V);
		float ndh = max(dot(N, h), 0.0), vdh = max(dot(V, h), 0.0);
		float dd = ndh * ndh * (a2 - 1.0) + 1.0;
		float D = a2 / (PI * dd * dd);
		float vis_g = 0.5 / (ndl * sqrt(ndv * ndv * (1.0 - a2) + a2) + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2));
		vec3 F = f0 + (1.0 - f0) * pow(1.0 - vdh, 5.0);
		vec3 brdf = c_diff / PI + F * (D * vis_g);
		if (SC_MATERIAL_EXT != 0u) brdf = ext_light(brdf, D * vis_g, vdh, N, V, l, ndl);
		vec3 e = L.color.rgb * atten * ndl;
		unshadowed += brdf * e;
		lit += brdf * e * vis;
	}
}

#include "display.glsl"
