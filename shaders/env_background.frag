#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// The environment map behind the scene (environment.background "map"): a fullscreen triangle at
// the far plane drawn after the scene where nothing covers a sample (renderer/record.c), the
// pixel's ray through the camera's inverse view-projection, tone mapped like the scene.
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_FRAME) uniform FrameBlock { umbra_frame frame; };
layout(std140, set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV) uniform EnvBlock { umbra_env env; };
layout(set = UMBRA_SET_FRAME, binding = UMBRA_BINDING_ENV_MAP) uniform sampler2D env_map;
layout(constant_id = UMBRA_SC_LINEAR) const uint SC_LINEAR = 0u;
layout(constant_id = UMBRA_SC_TONEMAP) const uint SC_TONEMAP = 0u;
layout(location = 0) in vec2 v_uv;
layout(location = 0) out vec4 o_color;
#define UMBRA_ENV_READ
#include "env_common.glsl"
#include "display.glsl"

void main()
{
	vec2 ndc = 2.0 * gl_FragCoord.xy / frame.target.xy - 1.0;
	vec4 a = env.inv_view_proj * vec4(ndc, 1.0, 1.0), b = env.inv_view_proj * vec4(ndc, 0.5, 1.0);
	vec3 d = normalize(b.xyz / b.w - a.xyz / a.w);
	o_color = vec4(display(env_background(d) * frame.params.x), 1.0);
}
