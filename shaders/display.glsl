// shaders/display.glsl — from scene radiance to the output's pixels: tone maps, sRGB encoding,
// and the cascades debug view's tints. Included at the end of shading.glsl (SC_LINEAR and
// SC_TONEMAP come from there).

vec3 tonemap_neutral(vec3 color)
{
	const float start = 0.8 - 0.04;
	const float desat = 0.15;
	float x = min(color.r, min(color.g, color.b));
	float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
	color -= offset;
	float peak = max(color.r, max(color.g, color.b));
	if (peak < start) return color;
	const float d = 1.0 - start;
	float new_peak = 1.0 - d * d / (peak + d - start);
	color *= new_peak / peak;
	float g = 1.0 - 1.0 / (desat * (peak - new_peak) + 1.0);
	return mix(color, vec3(new_peak), g);
}

vec3 tonemap_aces(vec3 x)   // Narkowicz's fit of the ACES RRT+ODT
{
	return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 srgb_encode(vec3 c)
{
	c = clamp(c, 0.0, 1.0);
	return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

vec3 display(vec3 radiance)
{
	if (SC_LINEAR != 0u) return radiance;   // linear scene-referred output (EXR)
	vec3 c = radiance;
	if (SC_TONEMAP == UMBRA_TONEMAP_NEUTRAL) c = tonemap_neutral(c);
	else if (SC_TONEMAP == UMBRA_TONEMAP_ACES) c = tonemap_aces(c);
	return srgb_encode(c);
}

// Tint per cascade / clipmap level: 0 red, 1 green, 2 blue, 3 yellow, 4 magenta, 5 cyan, ...
vec3 cascade_tint(uint i)
{
	uint k = i % 6u;
	vec3 c = k == 0u ? vec3(1, 0.3, 0.3) : k == 1u ? vec3(0.3, 1, 0.3) : k == 2u ? vec3(0.3, 0.4, 1)
	       : k == 3u ? vec3(1, 1, 0.3) : k == 4u ? vec3(1, 0.3, 1) : vec3(0.3, 1, 1);
	return i >= 6u ? c * 0.6 : c;
}

