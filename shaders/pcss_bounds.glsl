// shaders/pcss_bounds.glsl — PCSS's early answers from the depth bounds of the atlas
// (umbra_shared.h UMBRA_BOUNDS_BLOCK, written by minmax.comp). Included by shading.glsl just
// before pcss(), after the bindings (depth_bounds) and the light and view helpers.

// What the depth bounds (umbra_shared.h, UMBRA_BOUNDS_BLOCK) prove about the texels that PCSS
// at tile-local texel p reads (taps at most `reach` texels away): 1 = none is a blocker for
// any tap that reads it (the search finds nothing: lit), 2 = every one is a blocker for every
// tap that reads it (the search finds some and every filter tap is shadowed: 0), 0 = neither.
// Exact, not a guess; what the search and filter compare per texel is bounded per block:
//  - a blocker needs depth <= ref + grad . off - slack and |off| <= r0 - r1 depth (pcss()'s
//    reach). The lowest depth near p caps every texel's reach (rho); only texels within rho of
//    p (a few, on a receiver's own surface) can be blockers, and over just those the blocks'
//    planes must lie behind the receiver's plane. A texel t is read only by gathers at q in
//    [t - 0.5, t + 1.5) per axis, i.e. by taps whose offset lies within one texel (WIN: 1/64
//    to spare for coarse texture coordinates) of t's centre - p. Comparing planes next to p
//    rather than across whole blocks matters: the receiver's own depths lie only the bias
//    (~2 texels of its slope) behind its plane, and its gradient carries ~1 % rounding.
//  - the filter sees shadow where depth < ref + grad . off, |off| <= reach: the highest depth
//    near p must be in front of the receiver's plane everywhere in reach (and by the slack, so
//    the search's tap 0 finds blockers too).
// One fetch bounds everything near p (its block's neighbourhood); the lit test then reads the
// planes of the blocks within rho of p, usually just p's own. lavapipe: the loops' trip counts
// are 0 where the light has no bounds or the test is settled.
// reach_max: no tap farther than this from p finds a blocker (1e30 where the bounds say nothing).
int pcss_bounds(umbra_light L, vec2 p, vec4 rect, float ref, vec2 grad, float slack, float reach, float r0, float r1,
                out float reach_max)
{
	const int B = UMBRA_BOUNDS_BLOCK, T = UMBRA_BOUNDS_TEXELS;
	const float EPS = 1e-6;   // float rounding of both sides (depths 0..1), a few ulp of 1
	const float WIN = 1.0 + 1.0 / 64.0;
	float half_b = 0.5 * float(B - 1);   // texel centres of a block: its centre +- half_b
	// Taps read texels within reach + 1.5 of p per axis (gather_tile's clamp only moves them
	// nearer), all inside the neighbourhood of p's block when that reaches UMBRA_BOUNDS_RING
	// blocks out, at least B * UMBRA_BOUNDS_RING texels from p (pcss() passes its search radius,
	// plan.c's search_texels at most, times the longest tap, frame.params.w, + 1 for rounding).
	bool usable = L.shadow.w != 0u && reach + 1.5 <= float(B * UMBRA_BOUNDS_RING);
	ivec2 tile = ivec2(rect.xy) / B;
	ivec2 own = min(ivec2(p) / B, ivec2(int(rect.z) / B - 1));
	vec2 near = vec2(0.0, 1e30);   // lowest and highest depth around p
	for (int i = 0; i < (usable ? 1 : 0); i++)
		near = texelFetch(depth_bounds, ivec2((tile.x + own.x) * T + 1, tile.y + own.y), 0).xy;
	float gsum = abs(grad.x) + abs(grad.y);
	bool umbra = usable && near.y < ref - gsum * reach - slack - EPS;
	// reach(d) = r0 - r1 d is computed from terms of |r0|, |r1| (1e3 for a small light far
	// away): its rounding, relative to those, plus a little.
	float rho = max(r0 - r1 * near.x + 1e-5 * (abs(r0) + abs(r1)) + 0.01, 0.0) + WIN;
	reach_max = usable ? rho : 1e30;
	ivec2 q0 = ivec2(floor(p - rho)) / B, q1 = ivec2(floor(p + rho)) / B;
	int nx = q1.x - q0.x + 1, ny = q1.y - q0.y + 1;
	// A tap that gather_tile clamps lies more than rho from p when p is this far from the
	// tile's edge, so it cannot find a blocker whatever texel it reads.
	bool inside = all(greaterThanEqual(p, vec2(rho + 2.0))) && all(lessThanEqual(p, vec2(rect.z - rho - 2.0)));
	int n = usable && inside && !umbra && nx <= 2 && ny <= 2 ? nx * ny : 0;
	bool lit = n > 0;
	ivec2 bb = q0;
	for (int i = 0; i < n; i++) {
		vec4 pl = texelFetch(depth_bounds, ivec2((tile.x + bb.x) * T, tile.y + bb.y), 0);   // c, gx, gy, h
		vec2 ctr = vec2(bb * B) + 0.5 * float(B);
		// The block's texel centres within rho of p: min over them of depth(t) - (ref + grad . (t - p)).
		vec2 c0 = max(ctr - half_b, p - rho), c1 = min(ctr + half_b, p + rho);
		vec2 cm = 0.5 * (c0 + c1), ch = 0.5 * (c1 - c0);
		float gap = (pl.x - ref) + dot(pl.yz, cm - ctr) - dot(grad, cm - p) - dot(abs(pl.yz - grad), ch);
		lit = lit && (any(greaterThan(c0, c1)) || gap > WIN * gsum - slack + EPS);
		if (!lit) break;
		bb = bb.x == q1.x ? ivec2(q0.x, bb.y + 1) : ivec2(bb.x + 1, bb.y);
	}
	return umbra ? 2 : lit ? 1 : 0;
}
