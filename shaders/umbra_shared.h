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
#define UMBRA_BINDING_SCENE_DEPTH    6  /* sampler2D, the camera view's depth (D32, 1 - reversed Z), contact shadows */
#define UMBRA_BINDING_DEPTH_BOUNDS   7  /* sampler2D, the depth bounds of the atlas (RGBA32F, texelFetch) */
/* The visibility pass (renderer/visibility.c): bound only for the renders that use it, and
 * declared only by the shaders that read or write it (vis.frag, mesh.frag built as mesh_vis). */
#define UMBRA_BINDING_SURFACES       8  /* sampler2D (RGBA32F, texelFetch): the world position of the
                                           surface each pixel centre shows, w 1 (0 = nothing drawn) */
#define UMBRA_BINDING_SURFACE_NORMALS 9 /* sampler2D (RGBA16 snorm, texelFetch): its geometric normal */
#define UMBRA_BINDING_VISIBILITY     10 /* sampler2DArray (R16 unorm, texelFetch): layer i = light i's
                                           visibility of that surface (1 where it does not reach) */
#define UMBRA_BINDING_VISIBILITY_OUT 11 /* the same image as vis.frag's storage image */
/* The environment's light (renderer/env.c, shaders/ibl.glsl): bound in every render (a 1x1 stand-in
 * where the scene has no map), read by the pipelines whose UMBRA_SC_ENV says so. */
#define UMBRA_BINDING_ENV            12 /* uniform  umbra_env */
#define UMBRA_BINDING_ENV_SPECULAR   13 /* samplerCube: the map prefiltered for GGX, a mip level per roughness step */
#define UMBRA_BINDING_ENV_MAP        14 /* sampler2D: the equirectangular map with its mip chain (background) */
#define UMBRA_BINDING_ENV_BRDF       15 /* sampler2D (RG16F): the split-sum table, x n.v, y roughness */
/* The environment pass (renderer/env_pass.c): the view's surfaces at 1 / UMBRA_ENV_PASS_SCALE of
 * its pixels a side (as the visibility pass's), and the environment's visibility there (R16). */
#define UMBRA_BINDING_ENV_SURFACES   16 /* sampler2D (RGBA32F, texelFetch): world position, w 1 (0 = nothing) */
#define UMBRA_BINDING_ENV_NORMALS    17 /* sampler2D (RGBA16 snorm, texelFetch): geometric normal */
#define UMBRA_BINDING_ENV_VIS        18 /* sampler2D (R16 unorm, texelFetch): occluded / unoccluded */
#define UMBRA_ENV_PASS_SCALE         2  /* the view's pixels per environment-pass texel, a side, at least
                                           (larger views take more: env_pass.c rnd_env_pass_scale) */
/* env_prefilter.comp's and env_brdf.comp's own set 0 */
#define UMBRA_ENVC_BINDING_SOURCE    0  /* sampler2D: the equirectangular map (prefilter) */
#define UMBRA_ENVC_BINDING_OUT       1  /* storage image: a cube level as a 2D array (rgba16f) / the table (rg16f) */
#define UMBRA_ENV_BRDF_SIZE          64 /* texels a side of the split-sum table */
#define UMBRA_MAX_ENV_DIRECTIONS     32 /* environment shadow directions (rnd.h RND_MAX_ENV_DIRECTIONS) */
/* umbra_env.flags / UMBRA_SC_ENV bits */
#define UMBRA_ENV_LIGHT              1u /* the map lights the scene (split-sum specular, SH diffuse) */
#define UMBRA_ENV_SHADOWS            2u /* ... with its shadow directions */
#define UMBRA_ENV_BACKGROUND         4u /* the map is the background (shadow catchers darken it) */
#define UMBRA_ENV_PASS               8u /* its shadows come from the environment pass (env_pass.c) */
/* Pixel shading (renderer/deferred.c): bound for every render like the environment's (small
 * placeholders where unused), declared by the shaders of that path only. */
#define UMBRA_BINDING_SURFACE_SHADING 19 /* usampler2D (RGBA32UI, texelFetch): what the shading pass needs
                                           of the surface at each pixel centre (UMBRA_SHADING_*) */
#define UMBRA_BINDING_SHADED         20 /* sampler2D (the output's colour format, texelFetch): the colour
                                           shaded at each pixel centre */
#define UMBRA_BINDING_VIEW_DEPTH_MS  21 /* sampler2DMS (D32): the main view's depth per sample */
#define UMBRA_BINDING_COUNT          22
/* The surface-shading texel (surface_shade.frag writes it, vis_shade.frag reads it): x the
 * interpolated normal, octahedral in snorm 2x16; y, z the vertex colour, unorm 2x16 each; w the
 * material index (low 16 bits) and the draw's UMBRA_DRAW_* flags (high 16). */
#define UMBRA_SHADING_MATERIAL_BITS  16
/* moments.frag's own set 0 (renderer/moments.c) */
#define UMBRA_MOMENTS_BINDING_DEPTH  0  /* sampler2D: the depth atlas (pass 0 reads the view's tile) */
#define UMBRA_MOMENTS_BINDING_BLUR   1  /* sampler2D: the slot's blur temporary (pass 1 reads it) */
/* minmax.comp's own set 0 */
#define UMBRA_MINMAX_BINDING_DEPTH   0  /* storage buffer: the scratch map, res x res floats */
#define UMBRA_MINMAX_BINDING_BOUNDS  1  /* the depth-bounds image */
#define UMBRA_BOUNDS_TEXELS 2           /* texels per block in the depth-bounds image */
/* Depth bounds of the depth atlas, for PCSS: per UMBRA_BOUNDS_BLOCK² block of atlas texels (blocks
 * never straddle tiles: tiles are at least 64 texels and aligned to their size), two texels of
 * a (2 atlas / block) x (atlas / block) RGBA32F image, block (x, y) at (2x, y) and (2x + 1, y):
 *   (c, gx, gy, h): the lowest plane under the block's depths and how far the highest lies above
 *     it: for every texel centre t of the block, m its centre,
 *     c + gx (t.x - m.x) + gy (t.y - m.y) <= depth(t) <= that + h.
 *     A plane rather than a plain min / max: a sloped receiver's own depths vary by its slope
 *     times the block size, which a plain minimum confuses with a caster.
 *   (lo, hi, 0, 0): the lowest and highest depth of the blocks of the tile up to
 *     UMBRA_BOUNDS_RING blocks away, so that one fetch bounds everything within that many
 *     blocks' widths of a point.
 * Written by minmax.comp right after each PCSS map is drawn (record.c); kept with the atlas,
 * so a cached map keeps its bounds. */
#define UMBRA_BOUNDS_BLOCK 16
#define UMBRA_BOUNDS_RING  2    /* the neighbourhood: blocks this many out (PCSS's taps reach ~30 texels, pcss_bounds) */
/* Set 1: the material's textures, bound per draw (one set per textured material); a white 1x1
 * in every binding the material does not use. Binding = texture slot (UMBRA_TEX_*). */
#define UMBRA_SET_MATERIAL           1
#define UMBRA_TEX_BASE               0  /* base colour, sRGB (rgb x factor, a x alpha) */
#define UMBRA_TEX_METAL_ROUGH        1  /* linear: G roughness, B metallic */
#define UMBRA_TEX_NORMAL             2  /* linear tangent-space normal */
#define UMBRA_TEX_OCCLUSION          3  /* linear: R ambient occlusion */
#define UMBRA_TEX_EMISSIVE           4  /* sRGB */
/* The glTF PBR extensions' textures (material_ext.glsl), read only where the scene has that
 * lobe (UMBRA_SC_MATERIAL_EXT). The sRGB class for the colour ones and for those read in
 * alpha (sRGB leaves alpha linear), so an exporter's one image for colour and alpha (specular
 * colour + specular, sheen colour + sheen roughness) is one image. */
#define UMBRA_TEX_CLEARCOAT          5  /* linear: R clearcoat factor */
#define UMBRA_TEX_CLEARCOAT_ROUGHNESS 6 /* linear: G clearcoat roughness */
#define UMBRA_TEX_CLEARCOAT_NORMAL   7  /* linear tangent-space normal of the coat */
#define UMBRA_TEX_SHEEN_COLOR        8  /* sRGB: rgb sheen colour */
#define UMBRA_TEX_SHEEN_ROUGHNESS    9  /* A sheen roughness (sRGB class) */
#define UMBRA_TEX_SPECULAR           10 /* A specular factor (sRGB class) */
#define UMBRA_TEX_SPECULAR_COLOR     11 /* sRGB: rgb specular colour */
/* R: the see-through share of the coverage (umbra_material.ext.z): alpha x (1 - ext.z x R),
 * main pass and alpha-tested depth passes alike. */
#define UMBRA_TEX_TRANSMISSION       12 /* linear */
#define UMBRA_TEX_SLOTS              13
#define UMBRA_BINDING_BASE_TEXTURE       UMBRA_TEX_BASE
#define UMBRA_BINDING_METAL_ROUGH_TEXTURE UMBRA_TEX_METAL_ROUGH
#define UMBRA_BINDING_NORMAL_TEXTURE     UMBRA_TEX_NORMAL
#define UMBRA_BINDING_OCCLUSION_TEXTURE  UMBRA_TEX_OCCLUSION
#define UMBRA_BINDING_EMISSIVE_TEXTURE   UMBRA_TEX_EMISSIVE
/* umbra_material.tex.x: bit (1 << UMBRA_TEX_*) per texture the material samples; the same
 * bits, ORed over a scene, make UMBRA_SC_TEXTURES, and this one when a textured slot of a
 * drawn material reads the second uv set (the scene then has a uv1 vertex buffer; without it
 * the shaders never read location UV1). Vertex colours have no bit: every vertex has one
 * (white where the mesh has none, renderer/mesh.c) and the main pass always multiplies by it,
 * so a coloured mesh needs no pipeline variant of its own. */
#define UMBRA_TEXBIT_UV1             (1u << (UMBRA_TEX_SLOTS + 1))
/* umbra_material.tex.x, bit (1 << (UMBRA_TEX_UV1_SHIFT + UMBRA_TEX_*)): that slot samples
 * the second uv set (glTF TEXCOORD_1) instead of the first. */
#define UMBRA_TEX_UV1_SHIFT          16
/* Vertex input: binding 0 the interleaved vertices (locations 0..4: position, normal, uv,
 * colour, tangent), binding 1 the second uv set, a float2 per vertex at this location (the
 * vertices' own buffer bound there when the scene has no second uv set: never read then). */
#define UMBRA_LOCATION_UV1           5
#define UMBRA_VERTEX_BINDING_UV1     1
/* umbra_material.tex.y: alpha mode */
#define UMBRA_ALPHA_OPAQUE 0u
#define UMBRA_ALPHA_MASK   1u
#define UMBRA_ALPHA_BLEND  2u      /* dithered: ordered 4x4 threshold in screen / shadow-map space */

#define UMBRA_MAX_LIGHTS        64
#define UMBRA_MAX_SHADOW_VIEWS  256   /* directional 1..4 (cascades), spot 1, point 6 */
#define UMBRA_MAX_MATERIALS     4096
#define UMBRA_AOV_ATTACHMENTS   4     /* RGBA32F targets of one AOV pass */
/* AOV light packing (aov.frag writes it, renderer/record.c draws the passes, estimate.c counts
 * them, readback.c splits the planes): pass 0 holds (Z, N), (albedo, 1) and the visibility of
 * lights 0..7 in its targets 2 and 3; every further pass the visibility of 16 lights in its four
 * targets, four lights a target. "Target t of the whole readback" = pass * 4 + attachment. */
#define UMBRA_AOV_FIRST_PASS_LIGHTS 8u
#define UMBRA_AOV_PASS_LIGHTS       16u
/* The first light of AOV pass p (aov.frag's pc.info.z). */
#define UMBRA_AOV_PASS_FIRST_LIGHT(p) \
	((p) == 0u ? 0u : UMBRA_AOV_FIRST_PASS_LIGHTS + UMBRA_AOV_PASS_LIGHTS * ((p) - 1u))
/* The AOV passes that n shadowed lights need (at least 1: pass 0 carries Z, N, albedo). */
#define UMBRA_AOV_PASSES(n) \
	((n) <= UMBRA_AOV_FIRST_PASS_LIGHTS ? 1u \
	 : 1u + ((n) - UMBRA_AOV_FIRST_PASS_LIGHTS + UMBRA_AOV_PASS_LIGHTS - 1u) / UMBRA_AOV_PASS_LIGHTS)
/* Light i's visibility: target (over all passes) and component. */
#define UMBRA_AOV_LIGHT_TARGET(i) \
	((i) < UMBRA_AOV_FIRST_PASS_LIGHTS ? 2u + (i) / 4u \
	 : UMBRA_AOV_ATTACHMENTS + ((i) - UMBRA_AOV_FIRST_PASS_LIGHTS) / 4u)
#define UMBRA_AOV_LIGHT_COMPONENT(i) ((i) % 4u)

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
#define UMBRA_DEBUG_ENV_SHADOW 5   /* the environment's visibility (ibl.glsl env_visibility) */

/* umbra_frame.mode.x: tone map */
#define UMBRA_TONEMAP_NEUTRAL 0
#define UMBRA_TONEMAP_ACES    1
#define UMBRA_TONEMAP_NONE    2

/* umbra_push.info.y (main pass): per-draw flags */
#define UMBRA_DRAW_RECEIVE_SHADOWS 1u
#define UMBRA_DRAW_SHADOW_CATCHER  2u
#define UMBRA_DRAW_SPHERE          4u   /* the camera passes draw an analytic sphere's proxy (renderer/proxy.h) */

/* Specialization constant ids of mesh.frag (see renderer/pipelines.c rnd_main_key). */
#define UMBRA_SC_FILTERS     0
#define UMBRA_SC_DEBUG       1
#define UMBRA_SC_LINEAR      2
#define UMBRA_SC_TONEMAP     3
#define UMBRA_SC_CATCHER     4
#define UMBRA_SC_LIGHT_TYPES 5
#define UMBRA_SC_CASCADES    6
#define UMBRA_SC_TEXTURES    7    /* bits (1 << UMBRA_TEX_*) | UMBRA_TEXBIT_UV1 */
#define UMBRA_SC_MASKED      8    /* bit (1 << UMBRA_ALPHA_*) of the alpha modes in the scene */
#define UMBRA_SC_CONTACT     9    /* any light marches contact shadows (scene depth bound) */
#define UMBRA_SC_PCF_RADIUS  10   /* 2 when every PCF-filtered light has the default radius 1; 0: read per light */
#define UMBRA_SC_ENV         11   /* UMBRA_ENV_* bits: the environment map's light, shadows, background */
#define UMBRA_SC_MATERIAL_EXT 12  /* UMBRA_EXT_* bits of the drawn materials: the extension lobes compiled in */
#define UMBRA_SC_COUNT       13
/* Not in the key's sc[]: pipelines.c sets it from the pipeline's own sample count (the key
 * has that already, so it makes no variant of its own). */
#define UMBRA_SC_SAMPLES     13   /* rasterization samples: 1 or 4 */

/* umbra_material.ext.x and UMBRA_SC_MATERIAL_EXT: the glTF PBR extensions a material uses
 * (shaders/material_ext.glsl draws them; a scene without any compiles none of their code). */
#define UMBRA_EXT_CLEARCOAT 1u    /* KHR_materials_clearcoat: a second specular lobe over the base */
#define UMBRA_EXT_SHEEN     2u    /* KHR_materials_sheen: a Charlie sheen lobe over the base */
#define UMBRA_EXT_SPECULAR  4u    /* KHR_materials_specular / _ior: the dielectric F0, F90 and weight */

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
	U_MAT4 inv_view_proj;    /* clip -> world (the pixel-shading resolve: a sample's position) */
	U_VEC4 camera_pos;       /* xyz; w = 1 orthographic, 0 perspective */
	U_VEC4 camera_fwd;       /* xyz view direction (for orthographic V) */
	U_VEC4 background;       /* linear rgba */
	U_VEC4 clear;            /* the main pass's clear value: the background as the colour target holds it */
	U_VEC4 ambient_sky;      /* rgb already times intensity */
	U_VEC4 ambient_ground;
	U_VEC4 params;           /* x exposure multiplier, y near, z far, w the longest Poisson tap (PCSS) */
	U_UVEC4 mode;            /* x tonemap, y debug, z debug light, w light count */
	U_UVEC4 mode2;           /* x 1 = linear output (no tone map / sRGB), y transparent,
	                            z 1 = light culling off (UMBRA_LIGHT_CULL=0, tests) */
	U_VEC4 depth_lin;        /* proj[10], proj[14], proj[11], proj[15]: contact shadows turn the scene
	                            depth back into view depth (perspective and orthographic alike) */
	U_VEC4 target;           /* x, y view size in pixels; z world size of a pixel at view depth 1
	                            (perspective) or everywhere (orthographic); w 1 = orthographic */
	U_VEC4 poisson[16];      /* 32 Poisson-disk taps in the unit disk, two per vec4 */
	U_VEC4 filter_taps;      /* PCSS's filter reads tap i as (poisson[i] - xy) * z: centred, with a
	                            uniform disk's mean squared radius (renderer/frame.c); w unused */
	U_VEC4 env_filter_taps;  /* the same for the environment's filter, of the 16 odd taps (ibl.glsl) */
};

struct umbra_material {
	U_VEC4 base_color;       /* linear rgba */
	U_VEC4 emissive;         /* rgb (x KHR_materials_emissive_strength), a roughness */
	U_VEC4 params;           /* x metallic, y alpha cutoff, z normal scale, w occlusion strength */
	U_UVEC4 tex;             /* x texture bits (1 << UMBRA_TEX_*) and uv-set-1 bits
	                            (1 << (UMBRA_TEX_UV1_SHIFT + UMBRA_TEX_*)), y UMBRA_ALPHA_* */
	/* The extensions (read only where UMBRA_SC_MATERIAL_EXT has their bit): */
	U_VEC4 clearcoat;        /* x factor, y roughness, z normal scale, w the coat's F0 (from the ior) */
	U_VEC4 sheen;            /* rgb colour, w roughness */
	U_VEC4 specular;         /* rgb the dielectric F0 (from the ior) x specular colour, w specular factor */
	U_UVEC4 ext;             /* x UMBRA_EXT_* bits, y 1 = the specular-glossiness model (the
	                            diffuse x (1 - max(F0)), the ambient reflects F0), z the float bits of
	                            the see-through share (UMBRA_TEX_TRANSMISSION) */
	/* per texture slot, the uv transform (KHR_texture_transform) as two rows:
	 * uv' = (dot(uvx[2s].xy, uv) + uvx[2s].z, dot(uvx[2s+1].xy, uv) + uvx[2s+1].z) */
	U_VEC4 uvx[2 * UMBRA_TEX_SLOTS];
};

struct umbra_light {
	U_VEC4 color;            /* rgb * intensity; w type */
	U_VEC4 position;         /* xyz; w range (0 = unbounded) */
	U_VEC4 direction;        /* xyz normalised travel direction; w cos(outer) */
	U_VEC4 params;           /* x cos(inner), y size: tan(angular radius) or radius (m),
	                            z 1 = clipmap levels (else cascades), w max distance (0 = none) */
	U_UVEC4 shadow;          /* x first view, y view count (0 = unshadowed), z filter, w pcf radius (PCF);
	                            PCSS: w 1 = its views' depth bounds are written (UMBRA_BOUNDS_BLOCK) */
	U_VEC4 shadow_params;    /* x normal offset (texels), y max search radius (texels),
	                            z blend band (fraction), w fade start (view depth) */
	U_VEC4 splits;           /* directional cascades: far view depth of cascade 0..3 */
	U_VEC4 moment_params;    /* x EVSM exponent (0 = VSM), y light-bleed reduction, z min variance,
	                            w texels along the map's edge that read as lit (plan.c moment_edge) */
	U_VEC4 contact;          /* contact shadows: x ray length (world, 0 = from the map's texel), y steps,
	                            z thickness (view depth, world units; 0 = default), w 1 = on */
};

struct umbra_shadow_view {
	U_MAT4 view_proj;        /* world -> light clip (depth 0..1, near 0) */
	U_VEC4 params;           /* x world size of one texel (ortho) or at distance 1 (perspective),
	                            y 1 = perspective, z near, w far */
	U_VEC4 rect;             /* this view's tile in the shadow atlases: x, y, size, atlas size (texels) */
};

/* The environment of one view (renderer/env.c writes it, shaders/ibl.glsl reads it). Directions
 * are in the scene's frame; the map's textures in the map's own (rot turns one into the other). */
struct umbra_env {
	U_VEC4 sh[9];            /* rgb: irradiance / pi by spherical harmonics (order 2) of the map's
	                            direction, intensity applied: sum_i sh[i] Y_i(d_map) */
	U_VEC4 rot;              /* x cos, y sin of the rotation about +Y; z intensity; w the specular
	                            chain's last level (roughness 1) */
	U_VEC4 params;           /* x, y the map's width and height (texels); z the first light that is an
	                            environment direction (umbra_light: its shadow views), w those lights */
	U_VEC4 ground;           /* xyz the normal of a ground plane that hides every direction below it
	                            (those come after the mapped ones, with no map), w all directions */
	U_MAT4 inv_view_proj;    /* the camera's clip -> world (the background's rays) */
	U_VEC4 pass;             /* x the environment pass's view pixels per texel, a side (env_pass.c) */
	U_VEC4 dirs[UMBRA_MAX_ENV_DIRECTIONS];      /* xyz unit direction towards the sky, w its share of the
	                                               map's light (energy; the shares sum to 1) */
	U_VEC4 sizes[UMBRA_MAX_ENV_DIRECTIONS / 4]; /* sin of each direction's angular radius, four a vec4 */
};

/* One push-constant block for every pipeline (80 bytes). */
struct umbra_push {
	U_MAT4 view_proj;        /* shadow pass: light view-projection */
	U_UVEC4 info;            /* x material index, y UMBRA_DRAW_* flags, z AOV pass: first light */
};

/* The main pass's push constants (mesh.frag): the same 80 bytes, the draw's material head
 * (umbra_material's first four members) where the shadow passes have their view-projection
 * (mesh.vert takes the camera's from the frame block). lavapipe reads push constants once per
 * draw but gathers a storage-buffer record lane by lane, even at an index the whole draw
 * shares (thumb-512: ~10 % of the render's instructions). The uv transforms stay in the
 * materials buffer, read only by textured scenes. */
struct umbra_push_main {
	U_VEC4 base_color;
	U_VEC4 emissive;
	U_VEC4 params;
	U_UVEC4 tex;
	U_UVEC4 info;            /* as umbra_push.info */
};

#endif
