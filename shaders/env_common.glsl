// shaders/env_common.glsl — the environment map's conventions, shared by the shaders that read
// it (ibl.glsl, env_background.frag) and the one that prefilters it (env_prefilter.comp).
// Equirectangular (renderer/include/umbra/rnd.h rnd_env_map): direction d reads the map at
// u = 0.5 + atan2(z, x) / 2pi, v = 0.5 - asin(y) / pi (v from the top row, the zenith).

const float ENV_PI = 3.14159265358979;

vec2 env_equirect_uv(vec3 d)
{
	return vec2(0.5 + atan(d.z, d.x) / (2.0 * ENV_PI), 0.5 - asin(clamp(d.y, -1.0, 1.0)) / ENV_PI);
}

// A scene direction in the map's frame: R_y(-rotation) d (c, s: cos, sin of the rotation).
vec3 env_rotate_to_map(vec3 d, float c, float s)
{
	return vec3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

#ifdef UMBRA_ENV_READ
// The shaders that read the map declare `frame` (umbra_frame), `env` (umbra_env) and `env_map`.

// The map's radiance seen along scene direction d (the background), at the mip level of this
// view's pixels (an explicit level: derivatives jump where atan wraps around).
vec3 env_background(vec3 d)
{
	vec3 m = env_rotate_to_map(d, env.rot.x, env.rot.y);
	float texel = 2.0 * ENV_PI / max(env.params.x, 1.0);
	float lod = frame.target.w > 0.5 ? 0.0 : max(log2(max(frame.target.z, 1e-6) / texel), 0.0);
	return textureLod(env_map, env_equirect_uv(m), lod).rgb * env.rot.z;
}
#endif
