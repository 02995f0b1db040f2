/*
 * renderer/pipelines.c — shader modules (SPIR-V embedded at build time), the one descriptor
 * set layout and pipeline layout, the shadow sampler, and the graphics pipelines. The fixed
 * ones are created with the context; a main-pass variant (specialization constants of a
 * scene's lights and filters) is compiled here on its first use and kept by
 * pipeline_variants.c; the daemon's warm-up and the pipeline cache make that first use cheap.
 *
 * Pipelines use dynamic rendering (Vulkan 1.3): no render pass or framebuffer objects.
 * Variants: shadow depth-only [cull none/back]; main [output format][MSAA 1/4][cull none/back].
 */
#include <string.h>
#include "internal.h"
#include "mesh.h"
#include "shadow.vert.spv.h"
#include "mesh.vert.spv.h"
#include "mesh.frag.spv.h"
#include "aov.frag.spv.h"
#include "masked.vert.spv.h"
#include "masked.frag.spv.h"
#include "fullscreen.vert.spv.h"
#include "atlas.frag.spv.h"
#include "surface.frag.spv.h"
#include "vis.frag.spv.h"
#include "mesh_vis.frag.spv.h"
#include "surface_shade.frag.spv.h"
#include "vis_shade.frag.spv.h"
#include "resolve.frag.spv.h"
#include "env_background.frag.spv.h"
#include "env_vis.frag.spv.h"

enum rnd_result rnd_shader_module(struct rnd_context *ctx, const uint32_t *code, size_t size, const char *name,
                                  VkShaderModule *out, struct rnd_error *err)
{
	VkShaderModuleCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, .codeSize = size, .pCode = code};
	VkResult vr = vkCreateShaderModule(ctx->device, &ci, NULL, out);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkCreateShaderModule");
	RND_NAME(ctx, VK_OBJECT_TYPE_SHADER_MODULE, *out, "%s", name);
	return RND_OK;
}

const VkDescriptorType rnd_binding_type[UMBRA_BINDING_COUNT] = {
	[UMBRA_BINDING_FRAME] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
	[UMBRA_BINDING_MATERIALS] = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
	[UMBRA_BINDING_LIGHTS] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
	[UMBRA_BINDING_SHADOW_VIEWS] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
	[UMBRA_BINDING_SHADOW_MAP] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_MOMENTS] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_SCENE_DEPTH] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_DEPTH_BOUNDS] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_SURFACES] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_SURFACE_NORMALS] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_VISIBILITY] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_VISIBILITY_OUT] = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
	[UMBRA_BINDING_SURFACE_SHADING] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_SHADED] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_VIEW_DEPTH_MS] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_ENV] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
	[UMBRA_BINDING_ENV_SPECULAR] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_ENV_MAP] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_ENV_BRDF] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_ENV_SURFACES] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_ENV_NORMALS] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
	[UMBRA_BINDING_ENV_VIS] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
};

static enum rnd_result make_layouts(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_pipelines *p = &ctx->pipes;
	VkResult vr;
	VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
	VkDescriptorSetLayoutBinding b[UMBRA_BINDING_COUNT];
	for (uint32_t i = 0; i < UMBRA_BINDING_COUNT; i++)
		b[i] = (VkDescriptorSetLayoutBinding){i, rnd_binding_type[i], 1, stages, NULL};
	VkDescriptorSetLayoutCreateInfo dci = {
		.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, .bindingCount = UMBRA_BINDING_COUNT, .pBindings = b,
	};
	if ((vr = vkCreateDescriptorSetLayout(ctx->device, &dci, NULL, &p->set_layout)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreateDescriptorSetLayout");
	RND_NAME(ctx, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, p->set_layout, "umbra frame set layout");
	/* Set 1: the draw's material textures, one binding per slot (lavapipe has no dynamic
	 * indexing of sampler arrays, so a set per textured material). */
	VkDescriptorSetLayoutBinding tb[UMBRA_TEX_SLOTS];
	for (uint32_t i = 0; i < UMBRA_TEX_SLOTS; i++)
		tb[i] = (VkDescriptorSetLayoutBinding){i, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, NULL};
	VkDescriptorSetLayoutCreateInfo tci0 = {
		.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, .bindingCount = UMBRA_TEX_SLOTS, .pBindings = tb,
	};
	if ((vr = vkCreateDescriptorSetLayout(ctx->device, &tci0, NULL, &p->texture_layout)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreateDescriptorSetLayout (texture)");
	RND_NAME(ctx, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, p->texture_layout, "umbra texture set layout");
	VkDescriptorSetLayout sets[2] = {p->set_layout, p->texture_layout};
	VkPushConstantRange pcr = {stages, 0, sizeof(struct umbra_push)};
	VkPipelineLayoutCreateInfo lci = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, .setLayoutCount = 2, .pSetLayouts = sets,
		.pushConstantRangeCount = 1, .pPushConstantRanges = &pcr,
	};
	if ((vr = vkCreatePipelineLayout(ctx->device, &lci, NULL, &p->layout)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreatePipelineLayout");
	RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE_LAYOUT, p->layout, "umbra pipeline layout");
	/* Nearest + border white: lookups outside a shadow map read depth 1 (lit). Comparison is
	 * done in the shader (see mesh.frag). */
	VkSamplerCreateInfo sci = {
		.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO, .magFilter = VK_FILTER_NEAREST, .minFilter = VK_FILTER_NEAREST,
		.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
		.addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER, .addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
		.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, .borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE,
		.maxLod = 0.0f,
	};
	if ((vr = vkCreateSampler(ctx->device, &sci, NULL, &p->shadow_sampler)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreateSampler");
	RND_NAME(ctx, VK_OBJECT_TYPE_SAMPLER, p->shadow_sampler, "umbra shadow sampler");
	/* The depth atlas: its gathers stay inside their tile (shading.glsl gather_tile), so no
	 * border is ever read, and lavapipe's gather without one skips a compare and a blend per
	 * texel (thumb-512: ~2 % of the render's instructions). */
	sci.addressModeU = sci.addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
	if ((vr = vkCreateSampler(ctx->device, &sci, NULL, &p->atlas_sampler)) != VK_SUCCESS)
		return rnd_fail_vk(err, vr, "vkCreateSampler (atlas)");
	RND_NAME(ctx, VK_OBJECT_TYPE_SAMPLER, p->atlas_sampler, "umbra atlas sampler");
	/* Material textures: glTF sampler wrap and filter modes; every texture has its full mip
	 * chain (renderer/texture.c), and a minFilter without mipmaps reads level 0 only. */
	static const VkSamplerMipmapMode mipmode[3] = {VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST,
	                                               VK_SAMPLER_MIPMAP_MODE_NEAREST};
	static const VkSamplerAddressMode wrap[3] = {VK_SAMPLER_ADDRESS_MODE_REPEAT, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
	                                             VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT};
	for (uint32_t i = 0; i < RND_TEXTURE_SAMPLERS; i++) {
		VkSamplerCreateInfo tci = {
			.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
			.magFilter = (i & 2) ? VK_FILTER_NEAREST : VK_FILTER_LINEAR,
			.minFilter = (i & 1) ? VK_FILTER_NEAREST : VK_FILTER_LINEAR,
			.mipmapMode = mipmode[i / 36], .addressModeU = wrap[(i / 12) % 3], .addressModeV = wrap[(i / 4) % 3],
			.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT, .maxLod = i / 36 == RND_MIP_NONE ? 0.0f : VK_LOD_CLAMP_NONE,
		};
		if ((vr = vkCreateSampler(ctx->device, &tci, NULL, &p->texture_samplers[i])) != VK_SUCCESS)
			return rnd_fail_vk(err, vr, "vkCreateSampler (textures)");
		RND_NAME(ctx, VK_OBJECT_TYPE_SAMPLER, p->texture_samplers[i], "umbra texture sampler %u", i);
	}
	return RND_OK;
}

struct pipe_desc {
	VkShaderModule vs, fs;      /* fs may be 0: depth only */
	VkFormat color;             /* VK_FORMAT_UNDEFINED: no colour attachment */
	VkFormat depth;
	uint32_t samples;
	bool cull_back;
	bool shadow;                /* depth bias + clamp, LESS compare; else reversed-Z */
	bool after_prepass;         /* main pass: depth EQUAL, no depth writes */
	bool uv_only;               /* vertex input: position (0), uv (2), colour (3), uv1 (UMBRA_LOCATION_UV1) */
	bool dynamic_cull;          /* cull mode set per draw (vkCmdSetCullMode), cull_back ignored */
	uint32_t color_count;       /* colour attachments of format `color` (default 1 when color set) */
	VkFormat color_rest;        /* when set: the format of attachments 1.. */
	VkFormat color_last;        /* when set: the format of the last attachment */
	bool no_vertices;           /* fullscreen: no vertex input, no depth test */
	bool depth_less_ro;         /* fullscreen over a depth: test LESS (passes where it is above 0), no writes */
	bool depth_equal_ro;        /* fullscreen over a depth: test EQUAL (passes where it is still 0), no writes */
	const VkSpecializationInfo *spec;  /* fragment stage */
	VkPipelineLayout layout;    /* VK_NULL_HANDLE: the main passes' (ctx->pipes.layout) */
	const char *name;
};

/* The vertex layout (struct rnd_vertex; binding 1: the second uv set, umbra_shared.h); both
 * strides are dynamic (record.c). Alpha-tested depth passes read position, uvs and colour (its
 * alpha scales coverage); shadow passes the position only. */
static const VkVertexInputBindingDescription VERTEX_BINDINGS[2] = {
	{0, sizeof(struct rnd_vertex), VK_VERTEX_INPUT_RATE_VERTEX},
	{UMBRA_VERTEX_BINDING_UV1, 8, VK_VERTEX_INPUT_RATE_VERTEX},
};
static const VkVertexInputAttributeDescription VERTEX_ATTRIBUTES[6] = {
	{0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(struct rnd_vertex, pos)},
	{1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(struct rnd_vertex, nrm)},
	{2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(struct rnd_vertex, uv)},
	{3, 0, VK_FORMAT_R8G8B8A8_UNORM, offsetof(struct rnd_vertex, color)},
	{4, 0, VK_FORMAT_R8G8B8A8_SNORM, offsetof(struct rnd_vertex, tangent)},
	{UMBRA_LOCATION_UV1, UMBRA_VERTEX_BINDING_UV1, VK_FORMAT_R32G32_SFLOAT, 0},
};
static const VkVertexInputAttributeDescription VERTEX_ATTRIBUTES_UV[4] = {
	{0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(struct rnd_vertex, pos)},
	{2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(struct rnd_vertex, uv)},
	{3, 0, VK_FORMAT_R8G8B8A8_UNORM, offsetof(struct rnd_vertex, color)},
	{UMBRA_LOCATION_UV1, UMBRA_VERTEX_BINDING_UV1, VK_FORMAT_R32G32_SFLOAT, 0},
};

/* d's colour attachments: their formats and (no blending) write masks; returns how many. */
static uint32_t color_attachments(const struct pipe_desc *d, VkFormat formats[UMBRA_AOV_ATTACHMENTS],
                                  VkPipelineColorBlendAttachmentState cbas[UMBRA_AOV_ATTACHMENTS])
{
	uint32_t ncolor = d->color == VK_FORMAT_UNDEFINED ? 0 : d->color_count ? d->color_count : 1;
	for (uint32_t i = 0; i < UMBRA_AOV_ATTACHMENTS; i++) {
		formats[i] = i > 0 && d->color_rest ? d->color_rest : d->color;
		if (d->color_last && i + 1 == ncolor) formats[i] = d->color_last;
		cbas[i] = (VkPipelineColorBlendAttachmentState){.colorWriteMask = 0xf};
	}
	return ncolor;
}

static VkPipelineRasterizationStateCreateInfo rasterization_state(const struct rnd_context *ctx, const struct pipe_desc *d)
{
	VkPhysicalDeviceFeatures feats;
	vkGetPhysicalDeviceFeatures(ctx->phys, &feats);
	return (VkPipelineRasterizationStateCreateInfo){
		.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
		.depthClampEnable = d->shadow && feats.depthClamp,
		.polygonMode = VK_POLYGON_MODE_FILL,
		.cullMode = d->cull_back ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE,
		/* The projections flip Y into Vulkan's y-down framebuffer, so the picture is upright
		 * and glTF's counter-clockwise front faces stay counter-clockwise on screen. */
		.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
		.depthBiasEnable = d->shadow,
		.lineWidth = 1.0f,
	};
}

/* Shadow maps: LESS_OR_EQUAL; the main view: reversed-Z (GREATER_OR_EQUAL), EQUAL after its
 * pre-pass without writes; fullscreen passes test a depth only when asked. */
static VkPipelineDepthStencilStateCreateInfo depth_state(const struct pipe_desc *d)
{
	return (VkPipelineDepthStencilStateCreateInfo){
		.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
		.depthTestEnable = !d->no_vertices || d->depth_less_ro || d->depth_equal_ro,
		.depthWriteEnable = !d->after_prepass && !d->no_vertices,
		.depthCompareOp = d->shadow ? VK_COMPARE_OP_LESS_OR_EQUAL : d->depth_less_ro ? VK_COMPARE_OP_LESS
		                : d->depth_equal_ro ? VK_COMPARE_OP_EQUAL
		                : d->after_prepass ? VK_COMPARE_OP_EQUAL : VK_COMPARE_OP_GREATER_OR_EQUAL,
	};
}

/* The states d sets while recording; returns how many of dyn[5] it filled. */
static uint32_t dynamic_states(const struct pipe_desc *d, VkDynamicState dyn[5])
{
	uint32_t n = 0;
	dyn[n++] = VK_DYNAMIC_STATE_VIEWPORT;
	dyn[n++] = VK_DYNAMIC_STATE_SCISSOR;
	if (d->shadow) dyn[n++] = VK_DYNAMIC_STATE_DEPTH_BIAS;
	if (!d->no_vertices) dyn[n++] = VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE;
	if (d->dynamic_cull) dyn[n++] = VK_DYNAMIC_STATE_CULL_MODE;   /* core in Vulkan 1.3 */
	return n;
}

/* One graphics pipeline from d: one create-info per fixed-function state, in the order
 * Vulkan's struct takes them (the larger ones built by the helpers above). */
static enum rnd_result make_pipeline(struct rnd_context *ctx, const struct pipe_desc *d, VkPipeline *out,
                                     struct rnd_error *err)
{
	VkPipelineShaderStageCreateInfo stages[2] = {
		{.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_VERTEX_BIT, .module = d->vs, .pName = "main"},
		{.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_FRAGMENT_BIT, .module = d->fs, .pName = "main",
		 .pSpecializationInfo = d->spec},
	};
	VkFormat formats[UMBRA_AOV_ATTACHMENTS];
	VkPipelineColorBlendAttachmentState cbas[UMBRA_AOV_ATTACHMENTS];
	uint32_t ncolor = color_attachments(d, formats, cbas);
	VkPipelineVertexInputStateCreateInfo vi = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
		.pVertexBindingDescriptions = VERTEX_BINDINGS,
		.vertexBindingDescriptionCount = d->no_vertices ? 0 : 2,
		.vertexAttributeDescriptionCount = d->no_vertices ? 0 : d->uv_only ? 4 : d->shadow ? 1 : 6,
		.pVertexAttributeDescriptions = d->uv_only ? VERTEX_ATTRIBUTES_UV : VERTEX_ATTRIBUTES,
	};
	VkPipelineInputAssemblyStateCreateInfo ia = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO, .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST,
	};
	VkPipelineViewportStateCreateInfo vp = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO, .viewportCount = 1, .scissorCount = 1,
	};
	VkPipelineRasterizationStateCreateInfo rs = rasterization_state(ctx, d);
	VkPipelineMultisampleStateCreateInfo ms = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO, .rasterizationSamples = (VkSampleCountFlagBits)d->samples,
	};
	VkPipelineDepthStencilStateCreateInfo ds = depth_state(d);
	VkPipelineColorBlendStateCreateInfo cb = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
		.attachmentCount = ncolor, .pAttachments = cbas,
	};
	VkDynamicState dyn[5];
	VkPipelineDynamicStateCreateInfo dy = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO, .dynamicStateCount = dynamic_states(d, dyn), .pDynamicStates = dyn,
	};
	VkPipelineRenderingCreateInfo rci = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
		.colorAttachmentCount = ncolor, .pColorAttachmentFormats = formats,
		.depthAttachmentFormat = d->depth,
	};
	VkGraphicsPipelineCreateInfo ci = {
		.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, .pNext = &rci,
		.stageCount = d->fs ? 2 : 1, .pStages = stages,
		.pVertexInputState = &vi, .pInputAssemblyState = &ia, .pViewportState = &vp, .pRasterizationState = &rs,
		.pMultisampleState = &ms, .pDepthStencilState = &ds, .pColorBlendState = &cb, .pDynamicState = &dy,
		.layout = d->layout ? d->layout : ctx->pipes.layout,
	};
	VkResult vr = vkCreateGraphicsPipelines(ctx->device, ctx->pipeline_cache, 1, &ci, NULL, out);
	if (vr != VK_SUCCESS) {
		rnd_fail_vk(err, vr, "vkCreateGraphicsPipelines");
		snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg), " (%s)", d->name);
		return err->code;
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE, *out, "%s", d->name);
	return RND_OK;
}

enum rnd_result rnd_pipeline_fullscreen(struct rnd_context *ctx, VkShaderModule fs, VkFormat color, VkPipelineLayout layout,
                                        const VkSpecializationInfo *spec, const char *name, VkPipeline *out,
                                        struct rnd_error *err)
{
	struct pipe_desc d = {
		.vs = ctx->pipes.fullscreen_vs, .fs = fs, .color = color, .samples = 1, .no_vertices = true, .spec = spec,
		.layout = layout, .name = name,
	};
	return make_pipeline(ctx, &d, out, err);
}

/* The shader modules only rnd_pipelines_init()'s own pipelines use: destroyed once those exist
 * (a pipeline keeps what it needs of its modules). */
struct init_modules {
	VkShaderModule shadow_vs, masked_vs, masked_fs, surface_fs, surface_shade_fs;
};

static void init_modules_release(struct rnd_context *ctx, struct init_modules *m)
{
	if (m->surface_shade_fs) vkDestroyShaderModule(ctx->device, m->surface_shade_fs, NULL);
	if (m->surface_fs) vkDestroyShaderModule(ctx->device, m->surface_fs, NULL);
	if (m->masked_fs) vkDestroyShaderModule(ctx->device, m->masked_fs, NULL);
	if (m->masked_vs) vkDestroyShaderModule(ctx->device, m->masked_vs, NULL);
	if (m->shadow_vs) vkDestroyShaderModule(ctx->device, m->shadow_vs, NULL);
	*m = (struct init_modules){0};
}

/* Every module: those of the pipelines made at start (into m) and those the context keeps for
 * the variants (into ctx->pipes). On failure the caller releases both. */
static enum rnd_result make_modules(struct rnd_context *ctx, struct init_modules *m, struct rnd_error *err)
{
	struct rnd_pipelines *p = &ctx->pipes;
	enum rnd_result r;
	const struct { const uint32_t *code; size_t size; const char *name; VkShaderModule *out; } mods[] = {
#define MOD(spv, file, out) {spv, sizeof spv, file, out}
		MOD(spv_shadow_vert, "shadow.vert", &m->shadow_vs), MOD(spv_masked_vert, "masked.vert", &m->masked_vs),
		MOD(spv_masked_frag, "masked.frag", &m->masked_fs), MOD(spv_surface_frag, "surface.frag", &m->surface_fs),
		MOD(spv_surface_shade_frag, "surface_shade.frag", &m->surface_shade_fs),
		MOD(spv_mesh_vert, "mesh.vert", &p->mesh_vs), MOD(spv_mesh_frag, "mesh.frag", &p->mesh_fs),
		MOD(spv_aov_frag, "aov.frag", &p->aov_fs), MOD(spv_fullscreen_vert, "fullscreen.vert", &p->fullscreen_vs),
		MOD(spv_vis_frag, "vis.frag", &p->vis_fs), MOD(spv_mesh_vis_frag, "mesh_vis.frag", &p->mesh_vis_fs),
		MOD(spv_vis_shade_frag, "vis_shade.frag", &p->vis_shade_fs), MOD(spv_resolve_frag, "resolve.frag", &p->resolve_fs),
		MOD(spv_env_background_frag, "env_background.frag", &p->background_fs),
		MOD(spv_env_vis_frag, "env_vis.frag", &p->env_vis_fs),
#undef MOD
	};
	for (size_t i = 0; i < sizeof mods / sizeof mods[0]; i++)
		if ((r = rnd_shader_module(ctx, mods[i].code, mods[i].size, mods[i].name, mods[i].out, err)) != RND_OK) return r;
	return RND_OK;
}

/* The depth-only pipelines: shadow maps (alpha-tested and plain) and the main view's depth
 * pre-pass (alpha-tested and plain, 1 and 4 samples), each with and without back-face culling. */
static enum rnd_result make_depth_pipelines(struct rnd_context *ctx, const struct init_modules *mod, struct rnd_error *err)
{
	struct rnd_pipelines *p = &ctx->pipes;
	enum rnd_result r;
	/* Alpha-tested depth pipelines for alpha_mode MASK: shadow maps and the camera pre-pass. */
	for (int cull = 0; cull < 2; cull++) {
		struct pipe_desc d = {
			.vs = mod->masked_vs, .fs = mod->masked_fs, .color = VK_FORMAT_UNDEFINED, .depth = RND_SHADOW_FORMAT, .samples = 1,
			.cull_back = cull, .shadow = true, .uv_only = true, .name = "shadow depth (alpha mask)",
		};
		if ((r = make_pipeline(ctx, &d, &p->shadow_masked[cull], err)) != RND_OK) return r;
		for (int m = 0; m < 2; m++) {
			struct pipe_desc dp = {
				.vs = mod->masked_vs, .fs = mod->masked_fs, .color = VK_FORMAT_UNDEFINED, .depth = RND_DEPTH_FORMAT,
				.samples = m ? 4 : 1, .cull_back = cull, .uv_only = true, .name = "depth prepass (alpha mask)",
			};
			if ((r = make_pipeline(ctx, &dp, &p->prepass_masked[m][cull], err)) != RND_OK) return r;
		}
	}
	for (int cull = 0; cull < 2; cull++) {
		struct pipe_desc d = {
			.vs = mod->shadow_vs, .color = VK_FORMAT_UNDEFINED, .depth = RND_SHADOW_FORMAT, .samples = 1,
			.cull_back = cull, .shadow = true, .name = cull ? "shadow depth (cull back)" : "shadow depth",
		};
		if ((r = make_pipeline(ctx, &d, &p->shadow[cull], err)) != RND_OK) return r;
	}
	/* Depth pre-pass of the main view: the main pass then tests EQUAL, so every pixel is shaded
	 * by its visible surface only (lavapipe shades whole 4x4 blocks per triangle, and two-sided
	 * closed meshes would otherwise shade their hidden back halves too). */
	for (int m = 0; m < 2; m++) {
		for (int cull = 0; cull < 2; cull++) {
			char name[48];
			snprintf(name, sizeof name, "depth prepass msaa%d%s", m ? 4 : 1, cull ? " cull back" : "");
			struct pipe_desc d = {
				.vs = p->mesh_vs, .color = VK_FORMAT_UNDEFINED, .depth = RND_DEPTH_FORMAT, .samples = m ? 4 : 1,
				.cull_back = cull, .name = name,
			};
			if ((r = make_pipeline(ctx, &d, &p->prepass[m][cull], err)) != RND_OK) return r;
		}
	}
	return RND_OK;
}

/* The visibility pass's surfaces (renderer/visibility.c): what the main pass will shade at each
 * pixel centre, single-sample, the main pass's reversed-Z depth test; with and without the
 * shading attachment (pixel shading: deferred.c). */
static enum rnd_result make_surface_pipelines(struct rnd_context *ctx, const struct init_modules *mod, struct rnd_error *err)
{
	struct rnd_pipelines *p = &ctx->pipes;
	enum rnd_result r;
	for (int cull = 0; cull < 2; cull++) {
		struct pipe_desc d = {
			.vs = p->mesh_vs, .fs = mod->surface_fs, .color = RND_SURFACES_FORMAT, .color_count = 2,
			.color_rest = RND_SURFACE_NORMALS_FORMAT,
			.depth = RND_DEPTH_FORMAT, .samples = 1, .cull_back = cull, .name = cull ? "surfaces (cull back)" : "surfaces",
		};
		if ((r = make_pipeline(ctx, &d, &p->surfaces[cull], err)) != RND_OK) return r;
		d.fs = mod->surface_shade_fs;
		d.color_count = 3;
		d.color_last = RND_SURFACE_SHADING_FORMAT;
		d.name = cull ? "surfaces + shading (cull back)" : "surfaces + shading";
		if ((r = make_pipeline(ctx, &d, &p->surfaces_shade[cull], err)) != RND_OK) return r;
	}
	return RND_OK;
}

enum rnd_result rnd_pipelines_init(struct rnd_context *ctx, struct rnd_error *err)
{
	struct rnd_pipelines *p = &ctx->pipes;
	struct init_modules mod = {0};
	enum rnd_result r;
	pthread_mutex_init(&p->mu, NULL);
	pthread_cond_init(&p->compiled, NULL);
	if ((r = make_layouts(ctx, err)) != RND_OK || (r = make_modules(ctx, &mod, err)) != RND_OK ||
	    (r = make_depth_pipelines(ctx, &mod, err)) != RND_OK || (r = make_surface_pipelines(ctx, &mod, err)) != RND_OK) {
		init_modules_release(ctx, &mod);
		rnd_pipelines_release(ctx);
		return r;
	}
	init_modules_release(ctx, &mod);
	return RND_OK;
}

/* A fullscreen triangle's pipeline (fullscreen.vert, no vertices) with fragment shader fs:
 * no pre-pass, no culling. */
static void fullscreen(struct pipe_desc *d, const struct rnd_pipelines *p, VkShaderModule fs)
{
	d->vs = p->fullscreen_vs;
	d->fs = fs;
	d->no_vertices = true;
	d->after_prepass = false;
	d->cull_back = false;
	d->dynamic_cull = false;
}

/* What the passes other than the main one change in the main pass's description d. */
static void pass_desc(const struct rnd_context *ctx, const struct rnd_main_key *key, struct pipe_desc *d)
{
	const struct rnd_pipelines *p = &ctx->pipes;
	if (key->aov) {
		/* AOV pass: single-sample, its own depth test, four RGBA32F targets. */
		d->fs = p->aov_fs;
		d->color = VK_FORMAT_R32G32B32A32_SFLOAT;
		d->color_count = UMBRA_AOV_ATTACHMENTS;
		d->samples = 1;
		d->after_prepass = false;
	}
	if (key->vis_read) d->fs = p->mesh_vis_fs;
	if (key->vis_pass) {
		/* Visibility pass: a fullscreen triangle over the surfaces' depth, one sample, its
		 * results stored to an image (no colour attachment); with pixel shading (deferred.c)
		 * the colour shaded at each pixel centre into an image of the output's format. */
		fullscreen(d, p, key->vis_shade ? p->vis_shade_fs : p->vis_fs);
		d->color = key->vis_shade ? ctx->color_formats[key->format] : VK_FORMAT_UNDEFINED;
		d->samples = 1;
		d->depth_less_ro = true;
	}
	if (key->resolve) {
		/* Pixel shading's resolve: a fullscreen triangle into the single-sample target. */
		fullscreen(d, p, p->resolve_fs);
		d->spec = NULL;
		d->depth = VK_FORMAT_UNDEFINED;
		d->samples = 1;
	}
	if (key->background) {
		/* The environment behind the scene: a fullscreen triangle at depth 0 (the far plane of
		 * the reversed Z), kept where the depth is still 0: no geometry, sample by sample. */
		fullscreen(d, p, p->background_fs);
		d->depth_equal_ro = true;
	}
	if (key->env_pass) {
		/* The environment pass: a fullscreen triangle over its grid, one R16 target. */
		fullscreen(d, p, p->env_vis_fs);
		d->color = VK_FORMAT_R16_UNORM;
		d->depth = VK_FORMAT_UNDEFINED;
		d->samples = 1;
	}
}

/* Compiles main-pass variant key into *out (rnd_pipelines_main: pipeline_variants.c, which
 * keeps it); name: its debug name. */
enum rnd_result rnd_pipeline_variant_compile(struct rnd_context *ctx, const struct rnd_main_key *key, const char *name,
                                             VkPipeline *out, struct rnd_error *err)
{
	struct rnd_pipelines *p = &ctx->pipes;
	enum rnd_result r = RND_OK;
	/* the key's constants, then UMBRA_SC_SAMPLES: the samples this pipeline rasterises (d's,
	 * set below once the pass is known) */
	uint32_t values[UMBRA_SC_COUNT + 1];
	memcpy(values, key->sc, sizeof key->sc);
	VkSpecializationMapEntry entries[UMBRA_SC_COUNT + 1];
	for (uint32_t i = 0; i <= UMBRA_SC_COUNT; i++)
		entries[i] = (VkSpecializationMapEntry){i, (uint32_t)(i * sizeof(uint32_t)), sizeof(uint32_t)};
	VkSpecializationInfo spec = {UMBRA_SC_COUNT + 1, entries, sizeof values, values};
	struct pipe_desc d = {
		.vs = p->mesh_vs, .fs = p->mesh_fs, .color = ctx->color_formats[key->format], .depth = RND_DEPTH_FORMAT,
		.samples = key->samples, .cull_back = key->cull_back, .spec = &spec, .after_prepass = key->prepass, .name = name,
		.dynamic_cull = true,
	};
	VkShaderModule fs_fs = VK_NULL_HANDLE;
	if (key->atlas_view) {
		/* Debug view of the depth atlas: a fullscreen triangle. */
		if ((r = rnd_shader_module(ctx, spv_atlas_frag, sizeof spv_atlas_frag, "atlas.frag", &fs_fs, err)) != RND_OK)
			return r;
		fullscreen(&d, p, fs_fs);
		d.spec = NULL;
	}
	pass_desc(ctx, key, &d);
	values[UMBRA_SC_SAMPLES] = d.samples;
	r = make_pipeline(ctx, &d, out, err);
	if (fs_fs) vkDestroyShaderModule(ctx->device, fs_fs, NULL);
	return r;
}

void rnd_pipelines_release(struct rnd_context *ctx)
{
	struct rnd_pipelines *p = &ctx->pipes;
	if (!ctx->device) return;
	for (uint32_t i = 0; i < p->variant_count; i++) vkDestroyPipeline(ctx->device, p->variants[i].pipeline, NULL);
	for (uint32_t i = 0; i < p->retired_count; i++) vkDestroyPipeline(ctx->device, p->retired[i].pipeline, NULL);
	for (int c = 0; c < 2; c++) {
		if (p->shadow[c]) vkDestroyPipeline(ctx->device, p->shadow[c], NULL);
		if (p->shadow_masked[c]) vkDestroyPipeline(ctx->device, p->shadow_masked[c], NULL);
		for (int m = 0; m < 2; m++) {
			if (p->prepass[m][c]) vkDestroyPipeline(ctx->device, p->prepass[m][c], NULL);
			if (p->prepass_masked[m][c]) vkDestroyPipeline(ctx->device, p->prepass_masked[m][c], NULL);
		}
	}
	for (int c = 0; c < 2; c++) {
		if (p->surfaces[c]) vkDestroyPipeline(ctx->device, p->surfaces[c], NULL);
		if (p->surfaces_shade[c]) vkDestroyPipeline(ctx->device, p->surfaces_shade[c], NULL);
	}
	if (p->vis_shade_fs) vkDestroyShaderModule(ctx->device, p->vis_shade_fs, NULL);
	if (p->resolve_fs) vkDestroyShaderModule(ctx->device, p->resolve_fs, NULL);
	if (p->aov_fs) vkDestroyShaderModule(ctx->device, p->aov_fs, NULL);
	if (p->vis_fs) vkDestroyShaderModule(ctx->device, p->vis_fs, NULL);
	if (p->mesh_vis_fs) vkDestroyShaderModule(ctx->device, p->mesh_vis_fs, NULL);
	if (p->background_fs) vkDestroyShaderModule(ctx->device, p->background_fs, NULL);
	if (p->env_vis_fs) vkDestroyShaderModule(ctx->device, p->env_vis_fs, NULL);
	if (p->fullscreen_vs) vkDestroyShaderModule(ctx->device, p->fullscreen_vs, NULL);
	for (uint32_t i = 0; i < RND_TEXTURE_SAMPLERS; i++)
		if (p->texture_samplers[i]) vkDestroySampler(ctx->device, p->texture_samplers[i], NULL);
	if (p->mesh_fs) vkDestroyShaderModule(ctx->device, p->mesh_fs, NULL);
	if (p->mesh_vs) vkDestroyShaderModule(ctx->device, p->mesh_vs, NULL);
	if (p->shadow_sampler) vkDestroySampler(ctx->device, p->shadow_sampler, NULL);
	if (p->atlas_sampler) vkDestroySampler(ctx->device, p->atlas_sampler, NULL);
	if (p->layout) vkDestroyPipelineLayout(ctx->device, p->layout, NULL);
	if (p->set_layout) vkDestroyDescriptorSetLayout(ctx->device, p->set_layout, NULL);
	if (p->texture_layout) vkDestroyDescriptorSetLayout(ctx->device, p->texture_layout, NULL);
	pthread_mutex_destroy(&p->mu);
	memset(p, 0, sizeof *p);
}
