// shaders/facet.glsl — the surface a fragment shades and the one the shadow maps hold there, for
// the stages that draw triangles (mesh_main.glsl, aov.frag, surface.frag): included after the
// frame block (the camera) and their inputs (in_pos, v_nrm, v_uv). surface_at() is what they call.

// The plane of the triangle being drawn at position pos (from screen derivatives, exact for a
// flat triangle), facing like n_geo. Shadow lookups take their receiver plane and normal
// offset from it, not from the interpolated normal: on a tessellated sphere the two differ by
// up to half a facet's angle, and where the light fell straight on, PCF compared the taps
// downhill on the facet with a plane square to the light and put dark specks there (thumb-256:
// 14 pixels on the sphere). n_geo where the triangle shows edge-on or has no area, and where
// the two agree within 0.01 rad (FACET_SAME): lavapipe's derivatives of the position carry
// ~1e-3 rad of noise, and a receiver plane that noisy speckles a flat face lit at a grazing
// angle (studio-spots' red box), as 12-bit normals did in the visibility pass.
// Derivatives: call in uniform control flow, before any discard.
const float FACET_SAME = 0.99995;   // cos(0.01 rad)
vec3 facet_normal(vec3 pos, vec3 n_geo)
{
	vec3 c = cross(dFdx(pos), dFdy(pos));
	float l2 = dot(c, c);
	if (!(l2 > 1e-30 && l2 < 1e30)) return n_geo;
	c *= inversesqrt(l2);
	if (dot(c, n_geo) < 0.0) c = -c;
	return dot(c, n_geo) > FACET_SAME ? n_geo : c;
}

// Where the shadow lookups of a fragment look: pos, or with 4 samples where the fragment
// covers only some of them, the mean of the covered samples' positions (Vulkan's standard
// locations), stepped along the triangle's plane by the screen derivatives. MSAA shades a
// fragment at the pixel centre even where its triangle covers only a corner sample; there pos
// is the triangle's plane extended beyond its edges, which on a dense or concave mesh lies
// under the neighbouring triangles and read as shadowed: lines of dark specks along a 124k-
// triangle OBJ's cheek under a low sun, none at MSAA 1 or in the visibility pass, whose
// surfaces are drawn with one sample. (lavapipe's centroid interpolation and
// interpolateAtSample misplace the position and made it worse.) Derivatives: call in uniform
// control flow, before any discard.
vec3 covered_position(vec3 pos, uint samples)
{
	vec3 dx = dFdx(pos), dy = dFdy(pos);
	int m = gl_SampleMaskIn[0] & 15;
	if (samples != 4u || m == 15 || m == 0) return pos;
	vec2 o = vec2(0.0);
	o += (m & 1) != 0 ? vec2(-0.125, -0.375) : vec2(0.0);   // (0.375, 0.125) - centre
	o += (m & 2) != 0 ? vec2(0.375, -0.125) : vec2(0.0);    // (0.875, 0.375)
	o += (m & 4) != 0 ? vec2(-0.375, 0.125) : vec2(0.0);    // (0.125, 0.625)
	o += (m & 8) != 0 ? vec2(0.125, 0.375) : vec2(0.0);     // (0.625, 0.875)
	o /= float(bitCount(m));
	return pos + dx * o.x + dy * o.y;
}

// An analytic sphere's proxy (renderer/proxy.h; draws flagged UMBRA_DRAW_SPHERE): its vertices
// carry the sphere, normal = position - centre and uv = (radius, lift), so the interpolated
// position minus the interpolated normal is the centre everywhere on it.
vec4 proxy_sphere(vec3 pos, vec3 nrm, vec2 uv)
{
	return vec4(pos - nrm, uv.x);
}

// The point of sphere s nearest the camera on the view ray through p (a point of the proxy,
// which lies on that ray); where the ray passes just outside the sphere (the outline's chords
// straddle it), the sphere's point nearest the ray.
vec3 sphere_point(vec3 p, vec4 s)
{
	vec3 d = frame.camera_pos.w > 0.5 ? frame.camera_fwd.xyz : normalize(p - frame.camera_pos.xyz);
	vec3 oc = p - s.xyz;
	float b = dot(oc, d);
	float disc = b * b - (dot(oc, oc) - s.w * s.w);
	vec3 q = oc - d * (b + sqrt(max(disc, 0.0)));
	return s.xyz + q * (s.w * inversesqrt(max(dot(q, q), 1e-30)));
}

// What a fragment of a draw with `flags` shades (pos, n_geo) and where its shadow lookups look
// (p_shadow, n_shadow): as interpolated and from its triangle, or on the true sphere of a
// proxy. Derivatives: call in uniform control flow, before any discard.
void surface_at(vec3 in_p, vec3 nrm, vec2 uv, uint flags, uint samples, out vec3 pos, out vec3 n_geo,
                out vec3 p_shadow, out vec3 n_shadow)
{
	pos = in_p;
	n_geo = normalize(nrm);
	if (!gl_FrontFacing) n_geo = -n_geo;   // two-sided: back faces shade with the flipped normal
	n_shadow = facet_normal(in_p, n_geo);
	p_shadow = covered_position(in_p, samples);
	if ((flags & UMBRA_DRAW_SPHERE) != 0u) {
		vec4 s = proxy_sphere(in_p, nrm, uv);
		pos = sphere_point(in_p, s);
		n_geo = n_shadow = (pos - s.xyz) / s.w;
		// The shadow maps hold the tessellated sphere, out to `lift` beyond this one (proxy.h).
		p_shadow = sphere_point(p_shadow, s);
		p_shadow += normalize(p_shadow - s.xyz) * uv.y;
	}
}
