// shaders/octahedral.glsl — unit vectors as two numbers in [-1, 1] (octahedral mapping), for the
// surface-shading texel of pixel shading (umbra_shared.h UMBRA_BINDING_SURFACE_SHADING): in snorm
// 2x16 a normal comes back within ~1e-4 rad.
vec2 oct_wrap(vec2 v)
{
	return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

vec2 oct_encode(vec3 n)
{
	n /= abs(n.x) + abs(n.y) + abs(n.z);
	return n.z >= 0.0 ? n.xy : oct_wrap(n.xy);
}

vec3 oct_decode(vec2 e)
{
	vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
	if (n.z < 0.0) n.xy = oct_wrap(n.xy);
	return normalize(n);
}
