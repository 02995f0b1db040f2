// shaders/contact.glsl — contact shadows: a march through the camera's depth buffer towards the
// light (renderer/contact.c draws that depth). Included by shading.glsl after the shadow-map
// lookups (it reads the frame block, the views and scene_depth); shadow_visibility takes the
// smaller of the map's visibility and this one's.

// Per-pixel jitter of the contact ray's steps (interleaved gradient noise of the pixel):
// deterministic, so the same request gives the same bytes; it turns banding into fine grain.
float ign(vec2 px) { return fract(52.9829189 * fract(dot(px, vec2(0.06711056, 0.00583715)))); }

// View depth (world units along the camera's forward axis) of the scene depth texels d
// (1 - reversed-Z NDC depth, see contact.c): z_view = (B - ndc D) / (ndc C - A) with
// frame.depth_lin = (A, B, C, D), so perspective and orthographic cameras alike.
vec4 scene_view_depth(vec4 d)
{
	vec4 ndc = 1.0 - d;
	vec4 l = frame.depth_lin;
	return -(l.y - ndc * l.w) / (ndc * l.z - l.x);
}

// Whether the scene's depth at uv (tsz: the depth image's size) occludes a ray whose view depth
// runs over [lo, hi] since the previous step: a depth texel stands for a slab `thick` deep behind
// the surface it saw. Where the four texels around uv lie on one smooth surface (their range
// within `smooth_range`, what a planar receiver spans over two pixels), all four must be in front
// of the ray: a ray just above a planar receiver, whose depth they bracket, stays lit. Across a
// silhouette (a wider range), the texel nearest uv decides: a caster covers the pixels its raster
// covered. Requiring all four there too dropped a caster narrower than two pixels and a pixel of
// every wider one (issue 31: a thin pole's contact shadow lost at its edges); a blend of the four
// would widen it (rays beside a silhouette darkened). Background texels (the clear value, 1) are
// 1e20 deep, not at the far plane: a finite far plane made them a wall that rays from the
// farthest ground, marching the far cascade's texels, went behind (a band of false shadow at the
// horizon); infinite depths (an infinite far plane) are clamped so that no range is infinite. z_recv: the view depth
// of the receiver's plane under the ray's point.
bool contact_occludes(vec2 uv, vec2 tsz, float smooth_range, float lo, float hi, float thick, float z_recv)
{
	vec4 d = textureGather(scene_depth, uv);
	vec4 z = mix(min(scene_view_depth(d), vec4(1e20)), vec4(1e20), greaterThanEqual(d, vec4(1.0)));
	float range = max(max(z.x, z.y), max(z.z, z.w)) - min(min(z.x, z.y), min(z.z, z.w));
	// The receiver's own plane never shadows it (see below): on one smooth surface, a texel must
	// lie in front of that plane by more than the two pixels' slope that the four texels' centres
	// span around uv. Without it, a ray rising towards a grazing light on the camera's side was
	// occluded by the ground a pixel nearer to the camera (issue 31: false_core 0.021).
	if (range <= smooth_range)
		return all(lessThan(z, vec4(hi))) && any(greaterThan(z, vec4(lo - thick)))
			&& any(lessThan(z, vec4(z_recv - smooth_range)));
	// textureGather's order: x (i0, j1), y (i1, j1), z (i1, j0), w (i0, j0)
	vec2 f = fract(uv * tsz - 0.5);
	vec2 col = f.x < 0.5 ? z.wx : z.zy;   // (j0, j1) of the nearer column
	float zn = f.y < 0.5 ? col.x : col.y;
	// ... and the texels of its surface (within smooth_range of it) must all be in front: on a
	// receiver's edge, the nearest texel alone lies half a pixel off the ray and can be behind it.
	vec4 surf = mix(z, vec4(-1e30), greaterThan(abs(z - zn), vec4(smooth_range)));
	// The receiver's own plane never shadows it: a nearest texel within a pixel's slope of that
	// plane's depth under the ray (z_recv) is the receiver itself, seen half a pixel off (at a
	// grazing view, towards the horizon, that is far in front of the ray).
	return all(lessThan(surf, vec4(hi))) && zn > lo - thick && zn < z_recv - 0.5 * smooth_range;
}

// Contact shadows: march from pos towards the light through the view's depth buffer, over
// L.contact.x world units (0: CONTACT_TEXELS texels of the light's map at pos, the zone next
// to a caster that the map's bias and filter cannot resolve, and at least CONTACT_PX pixels).
// Every depth texel stands for a slab `thickness` deep behind the surface it saw (L.contact.z,
// world units of view depth; 0: CONTACT_THICK_PX pixels' or CONTACT_THICK_TEXELS map texels'
// world size at pos, the larger: a caster the map loses is about a texel thick, and a slab
// thinner than it let rays through a 4 cm pole seen from 3 m pass behind it); a step is
// occluded when the ray's segment since the previous step meets the slabs around its end and
// lies behind all four texels there (textureGather). Segments, not points: no step skips a
// thin slab, so the thickness can be small, and rays passing behind a thin caster (in view)
// are not taken for rays through it. All four texels: a ray beside a silhouette, or above a
// planar receiver (whose depth the four texels bracket), is never occluded by it; a caster
// narrower than two pixels casts no contact shadow (its map shadow stays). At most
// L.contact.y steps, and no more than the ray's length in pixels: a step within one pixel
// reads the same texels again.
// 12 texels, not 8 (issue 31): a 4 cm pole under a sun with a 256 map lost 53 % of the shadow
// within 8 px of its foot with 8 and a one-pixel slab, 6 % with 12 and a one-texel slab; 16
// hardened the duck's soft self-shadow near contact (rmse 0.016 -> 0.022 against Cycles).
// `view`: the map's view that lit pos (the cascade or clipmap level map_visibility chose): its
// texel sets the default length and thickness. The first cascade's (the finest) made the march
// a few centimetres long in the farther cascades, whose texels lose a thin pole (issue 31).
const float CONTACT_TEXELS = 12.0;
const float CONTACT_PX = 4;
const float CONTACT_THICK_PX = 1.0;
const float CONTACT_THICK_TEXELS = 1.0;
float contact_visibility(umbra_light L, uint view, vec3 pos, vec3 n, vec3 to_light)
{
	vec3 cam = frame.camera_pos.xyz, fwd = frame.camera_fwd.xyz;
	float z0 = max(dot(pos - cam, fwd), 1e-4);
	float px = frame.target.z * (frame.target.w > 0.5 ? 1.0 : z0);   // world size of a pixel at pos
	bool local = uint(L.color.w) != UMBRA_LIGHT_DIRECTIONAL;
	float to_l = local ? length(L.position.xyz - pos) : 1e30;
	umbra_shadow_view v = views[view];
	float texel = is_persp(v) ? v.params.x * to_l : v.params.x;
	float len = L.contact.x > 0.0 ? L.contact.x : max(CONTACT_TEXELS * texel, CONTACT_PX * px);
	len = min(len, to_l);
	float thick = L.contact.z > 0.0 ? L.contact.z : max(CONTACT_THICK_PX * px, CONTACT_THICK_TEXELS * texel);
	// Off the receiver by half a pixel along the normal, and the march begins a pixel out:
	// the receiver's own depth texels stay behind the ray.
	vec3 start = pos + n * (0.5 * px);
	float t0 = px;
	if (len <= t0) return 1.0;
	// The ray is linear in clip space and in view depth: c(t) = c0 + t dc, z(t) = zs0 + t dz.
	vec4 c0 = frame.view_proj * vec4(start, 1.0), dc = frame.view_proj * vec4(to_light, 0.0);
	float zs0 = dot(start - cam, fwd), dz = dot(to_light, fwd);
	if (dc.w < 0.0) len = min(len, (c0.w - 1e-4 * c0.w) / -dc.w);   // stop before the camera plane
	vec4 ca = c0 + dc * t0, cb = c0 + dc * len;
	vec2 size = frame.target.xy;
	float span = length((cb.xy / cb.w - ca.xy / ca.w) * 0.5 * size);
	int steps = clamp(int(ceil(span)), 1, int(L.contact.y));
	float dt = (len - t0) / float(steps);
	float jitter = ign(frag_xy());
	vec2 tsz = vec2(textureSize(scene_depth, 0));
	// The receiver's plane spans px * tan(angle to the view ray) of view depth per pixel.
	float cos_v = max(abs(dot(n, normalize(pos - cam))), 0.05);
	float smooth_range = 2.0 * px * sqrt(1.0 - cos_v * cos_v) / cos_v;
	float z_prev = zs0 + dz * t0;
	float eps = 1e-3 * px;
	// The receiver's plane (pos, n) under the ray's point p(t): the camera ray through p meets it
	// at view depth z(t) * recv_num / (recv0 + t recv_dt); no receiver there when that ratio is <= 0.
	float recv_num = dot(pos - cam, n), recv0 = dot(start - cam, n), recv_dt = dot(to_light, n);
	for (int i = 0; i < steps; i++) {
		float t = t0 + dt * (float(i) + jitter);
		vec4 c = c0 + dc * t;
		vec2 uv = c.xy / c.w * 0.5 + 0.5;
		if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) break;
		float zp = zs0 + dz * t;
		float lo = min(z_prev, zp), hi = max(z_prev, zp);
		float ratio = recv_num / (recv0 + recv_dt * t);
		float z_recv = ratio > 0.0 ? zp * ratio : 1e20;
		if (contact_occludes(uv, tsz, smooth_range, lo, hi - eps, thick, z_recv)) return 0.0;
		z_prev = zp;
	}
	return 1.0;
}
