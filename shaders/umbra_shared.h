/*
 * umbra — the one header shared by C (renderer/) and GLSL (shaders/): descriptor bindings,
 * push constants, limits and the layouts of every GPU-visible struct.
 *
 * Every struct holds only vec4 / uvec4 / mat4 members, so std140, std430 and C agree with no
 * hidden padding. In C the GLSL types are plain float/uint arrays (column-major matrices).
 * Changing anything here changes both sides at once; that is the point.
 */
#ifndef UMBRA_SHARED_H
#define UMBRA_SHARED_H

#define UMBRA_SET_FRAME              0
#define UMBRA_BINDING_FRAME          0  /* uniform  umbra_frame */
#define UMBRA_BINDING_MATERIALS      1  /* storage  umbra_material[] */
#define UMBRA_BINDING_LIGHTS         2  /* uniform  umbra_light[UMBRA_MAX_LIGHTS] */
#define UMBRA_BINDING_SHADOW_VIEWS   3  /* uniform  umbra_shadow_view[UMBRA_MAX_SHADOW_VIEWS] */
#define UMBRA_BINDING_SHADOW_MAP     4  /* sampler2D, the depth atlas (R32F): one tile per shadow view */
#define UMBRA_BINDING_MOMENTS        5  /* sampler2D, the moment atlas (blurred, linear filtering) */
#define UMBRA_BINDING_COUNT          6
/* moments.comp's own set 0 */
#define UMBRA_MOMENTS_BINDING_DEPTH  0  /* storage buffer: the scratch map, res x res floats */
#define UMBRA_MOMENTS_BINDING_TMP    1
#define UMBRA_MOMENTS_BINDING_OUT    2
/* Set 1: the material's base-colour texture (sRGB), bound per draw; a white 1x1 when none. */
#define UMBRA_SET_MATERIAL           1
#define UMBRA_BINDING_BASE_TEXTURE   0

#define UMBRA_MAX_LIGHTS        64
#define UMBRA_MAX_SHADOW_VIEWS  256   /* directional 1..4 (cascades), spot 1, point 6 */
#define UMBRA_MAX_MATERIALS     4096
#define UMBRA_MAX_TEXTURES      16    /* distinct base-colour textures in one scene */
#define UMBRA_AOV_ATTACHMENTS   4     /* RGBA32F targets of one AOV pass */

/* umbra_light.color.w: light type */
#define UMBRA_LIGHT_DIRECTIONAL 0
#define UMBRA_LIGHT_SPOT        1
#define UMBRA_LIGHT_POINT       2

/* umbra_light.shadow.z: filter */
#define UMBRA_FILTER_HARD 1
#define UMBRA_FILTER_PCF  2
#define UMBRA_FILTER_PCSS 3
#define UMBRA_FILTER_MOMENTS 4   /* vsm / evsm (light.shadow_params / moment params say which) */

/* umbra_frame.mode.y: debug view */
#define UMBRA_DEBUG_NONE     0
#define UMBRA_DEBUG_SHADOW   1
#define UMBRA_DEBUG_CASCADES 2
#define UMBRA_DEBUG_NORMALS  3
#define UMBRA_DEBUG_DEPTH    4

/* umbra_frame.mode.x: tone map */
#define UMBRA_TONEMAP_NEUTRAL 0
#define UMBRA_TONEMAP_ACES    1
#define UMBRA_TONEMAP_NONE    2

/* umbra_push.info.y (main pass): per-draw flags */
#define UMBRA_DRAW_RECEIVE_SHADOWS 1u
#define UMBRA_DRAW_SHADOW_CATCHER  2u

/* Specialization constant ids of mesh.frag (see renderer/pipelines.c rnd_main_key). */
#define UMBRA_SC_FILTERS     0
#define UMBRA_SC_DEBUG       1
#define UMBRA_SC_LINEAR      2
#define UMBRA_SC_TONEMAP     3
#define UMBRA_SC_CATCHER     4
#define UMBRA_SC_LIGHT_TYPES 5
#define UMBRA_SC_CASCADES    6
#define UMBRA_SC_TEXTURES    7
#define UMBRA_SC_MASKED      8
#define UMBRA_SC_COUNT       9

/* umbra_material.params.z flags */
#define UMBRA_MATERIAL_SHADOW_CATCHER 1u

#ifdef VULKAN  /* GLSL (glslang -V defines VULKAN) */
#define U_MAT4  mat4
#define U_VEC4  vec4
#define U_UVEC4 uvec4
#else
#include <stdint.h>
typedef float U_MAT4[16];
typedef float U_VEC4[4];
typedef uint32_t U_UVEC4[4];
#endif

struct umbra_frame {
	U_MAT4 view_proj;        /* world -> clip of the camera (reversed Z: near 1, far 0) */
	U_MAT4 view;             /* world -> view */
	U_VEC4 camera_pos;       /* xyz; w = 1 orthographic, 0 perspective */
	U_VEC4 camera_fwd;       /* xyz view direction (for orthographic V) */
	U_VEC4 background;       /* linear rgba */
	U_VEC4 ambient_sky;      /* rgb already times intensity */
	U_VEC4 ambient_ground;
	U_VEC4 params;           /* x exposure multiplier, y near, z far, w unused */
	U_UVEC4 mode;            /* x tonemap, y debug, z debug light, w light count */
	U_UVEC4 mode2;           /* x 1 = linear output (no tone map / sRGB), y transparent,
	                            z 1 = light culling off (UMBRA_LIGHT_CULL=0, tests) */
	U_VEC4 poisson[16];      /* 32 Poisson-disk taps in the unit disk, two per vec4 */
};

struct umbra_material {
	U_VEC4 base_color;       /* linear rgba */
	U_VEC4 emissive;         /* rgb, a roughness */
	U_VEC4 params;           /* x metallic, y alpha cutoff */
	U_UVEC4 tex;             /* x 1 = has a base-colour texture (set 1), y 1 = alpha mask */
};

struct umbra_light {
	U_VEC4 color;            /* rgb * intensity; w type */
	U_VEC4 position;         /* xyz; w range (0 = unbounded) */
	U_VEC4 direction;        /* xyz normalised travel direction; w cos(outer) */
	U_VEC4 params;           /* x cos(inner), y size: tan(angular radius) or radius (m),
	                            z 1 = clipmap levels (else cascades), w max distance (0 = none) */
	U_UVEC4 shadow;          /* x first view, y view count (0 = unshadowed), z filter, w pcf radius */
	U_VEC4 shadow_params;    /* x normal offset (texels), y max search radius (texels),
	                            z blend band (fraction), w fade start (view depth) */
	U_VEC4 splits;           /* directional cascades: far view depth of cascade 0..3 */
	U_VEC4 moment_params;    /* x EVSM exponent (0 = VSM), y light-bleed reduction, z min variance */
};

struct umbra_shadow_view {
	U_MAT4 view_proj;        /* world -> light clip (depth 0..1, near 0) */
	U_VEC4 params;           /* x world size of one texel (ortho) or at distance 1 (perspective),
	                            y 1 = perspective, z near, w far */
	U_VEC4 rect;             /* this view's tile in the shadow atlases: x, y, size, atlas size (texels) */
};

/* One push-constant block for every pipeline (80 bytes). */
struct umbra_push {
	U_MAT4 view_proj;        /* shadow pass: light view-projection */
	U_UVEC4 info;            /* x material index, y UMBRA_DRAW_* flags, z AOV pass: first light */
};

#endif
