// shaders/facet.glsl — the surface the shadow maps hold at a fragment, for the stages that draw
// triangles (mesh_main.glsl, aov.frag, surface.frag): included after the position input.

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
