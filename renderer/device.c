/*
 * renderer/device.c — the Vulkan context: instance, validation messenger, physical device
 * choice, logical device and queue, pipeline cache file. Owns the lifetime of everything else
 * in the context (pipelines.c, slot.c are initialised and released from here).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "deferred.h"
#include "internal.h"
#include "env.h"
#include "moments.h"
#include "shadow_cache.h"

const char *rnd_vk_str(VkResult r)
{
	switch (r) {
#define C(x) case x: return #x;
	C(VK_SUCCESS) C(VK_NOT_READY) C(VK_TIMEOUT) C(VK_INCOMPLETE)
	C(VK_ERROR_OUT_OF_HOST_MEMORY) C(VK_ERROR_OUT_OF_DEVICE_MEMORY) C(VK_ERROR_INITIALIZATION_FAILED)
	C(VK_ERROR_DEVICE_LOST) C(VK_ERROR_MEMORY_MAP_FAILED) C(VK_ERROR_LAYER_NOT_PRESENT)
	C(VK_ERROR_EXTENSION_NOT_PRESENT) C(VK_ERROR_FEATURE_NOT_PRESENT) C(VK_ERROR_INCOMPATIBLE_DRIVER)
	C(VK_ERROR_TOO_MANY_OBJECTS) C(VK_ERROR_FORMAT_NOT_SUPPORTED) C(VK_ERROR_FRAGMENTED_POOL)
	C(VK_ERROR_OUT_OF_POOL_MEMORY) C(VK_ERROR_UNKNOWN)
#undef C
	default: return "VkResult(?)";
	}
}

static void vfail(struct rnd_error *err, enum rnd_result code, enum rnd_error_at at, uint32_t index, const char *fmt,
                  va_list ap)
{
	vsnprintf(err->msg, sizeof err->msg, fmt, ap);
	err->code = code;
	err->vk_result = 0;
	err->at = at;
	err->at_index = index;
}

enum rnd_result rnd_fail(struct rnd_error *err, enum rnd_result code, const char *fmt, ...)
{
	if (err) {
		va_list ap;
		va_start(ap, fmt);
		vfail(err, code, RND_AT_NONE, 0, fmt, ap);
		va_end(ap);
	}
	return code;
}

enum rnd_result rnd_fail_at(struct rnd_error *err, enum rnd_result code, enum rnd_error_at at, uint32_t index,
                            const char *fmt, ...)
{
	if (err) {
		va_list ap;
		va_start(ap, fmt);
		vfail(err, code, at, index, fmt, ap);
		va_end(ap);
	}
	return code;
}

enum rnd_result rnd_fail_vk(struct rnd_error *err, VkResult vr, const char *what)
{
	enum rnd_result code = RND_ERR_VULKAN;
	if (vr == VK_ERROR_DEVICE_LOST) code = RND_ERR_DEVICE_LOST;
	else if (vr == VK_ERROR_OUT_OF_HOST_MEMORY || vr == VK_ERROR_OUT_OF_DEVICE_MEMORY) code = RND_ERR_OOM;
	rnd_fail(err, code, "%s: %s", what, rnd_vk_str(vr));
	if (err) err->vk_result = (int)vr;
	return code;
}

const char *rnd_result_str(enum rnd_result r);

double rnd_now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

void rnd_log(const struct rnd_context *ctx, int level, const char *fmt, ...)
{
	char buf[1024];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
	if (ctx && ctx->desc.log) ctx->desc.log(ctx->desc.log_user, level, buf);
	else if (level <= 1) fprintf(stderr, "umbra: %s\n", buf);
}

void rnd_name(const struct rnd_context *ctx, VkObjectType type, uint64_t handle, const char *fmt, ...)
{
	PFN_vkSetDebugUtilsObjectNameEXT set_name = ctx->set_object_name;
	if (!set_name || !handle) return;
	char name[128];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(name, sizeof name, fmt, ap);
	va_end(ap);
	VkDebugUtilsObjectNameInfoEXT info = {
		.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT,
		.objectType = type, .objectHandle = handle, .pObjectName = name,
	};
	set_name(ctx->device, &info);
}

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT sev,
	VkDebugUtilsMessageTypeFlagsEXT type, const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
	struct rnd_context *ctx = user;
	/* The shadow atlases stay in GENERAL layout on purpose: concurrent renders sample some
	 * tiles while another render copies a new map into another tile, and one image has one
	 * layout. The layer's performance hint that a copy into GENERAL would be faster in
	 * TRANSFER_DST_OPTIMAL (UNASSIGNED-CoreValidation-DrawState-InvalidImageLayout) is
	 * expected there, and only there. The atlas is known by its name or by its handle: with
	 * two renders recording at once the layer has printed it nameless ("VkImage 0x...[]"). */
	if ((type & VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT) && data->messageIdNumber == 0x4dae5635 &&
	    data->pMessage && strstr(data->pMessage, "GENERAL")) {
		char atlas[48];
		snprintf(atlas, sizeof atlas, "VkImage 0x%llx[", (unsigned long long)(uintptr_t)ctx->atlas_depth.img);
		if (strstr(data->pMessage, "[shadow depth atlas]") || (ctx->atlas_depth.img && strstr(data->pMessage, atlas)))
			return VK_FALSE;
	}
	if (sev >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
		__atomic_add_fetch(&ctx->validation_count, 1, __ATOMIC_RELAXED);
		rnd_log(ctx, 0, "vulkan validation: %s", data->pMessage ? data->pMessage : "(no message)");
	}
	return VK_FALSE;
}

static bool has_layer(const char *name)
{
	uint32_t n = 0;
	vkEnumerateInstanceLayerProperties(&n, NULL);
	VkLayerProperties *p = calloc(n ? n : 1, sizeof *p);
	if (!p) return false;
	vkEnumerateInstanceLayerProperties(&n, p);
	bool found = false;
	for (uint32_t i = 0; i < n && !found; i++) found = !strcmp(p[i].layerName, name);
	free(p);
	return found;
}

static bool has_instance_ext(const char *name)
{
	uint32_t n = 0;
	vkEnumerateInstanceExtensionProperties(NULL, &n, NULL);
	VkExtensionProperties *p = calloc(n ? n : 1, sizeof *p);
	if (!p) return false;
	vkEnumerateInstanceExtensionProperties(NULL, &n, p);
	bool found = false;
	for (uint32_t i = 0; i < n && !found; i++) found = !strcmp(p[i].extensionName, name);
	free(p);
	return found;
}

static enum rnd_result create_instance(struct rnd_context *ctx, struct rnd_error *err)
{
	const char *layers[1];
	uint32_t nlayers = 0;
	const char *exts[2];
	uint32_t nexts = 0;
	if (ctx->desc.validation) {
		if (!has_layer("VK_LAYER_KHRONOS_validation"))
			return rnd_fail(err, RND_ERR_NO_DEVICE, "validation requested but VK_LAYER_KHRONOS_validation is not installed (apt-get install vulkan-validationlayers)");
		layers[nlayers++] = "VK_LAYER_KHRONOS_validation";
	}
	ctx->has_debug_utils = has_instance_ext(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
	if (ctx->has_debug_utils) exts[nexts++] = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;

	VkApplicationInfo app = {
		.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
		.pApplicationName = "umbra", .applicationVersion = 1,
		.pEngineName = "umbra", .engineVersion = 1,
		.apiVersion = VK_API_VERSION_1_3,
	};
	VkDebugUtilsMessengerCreateInfoEXT dbg = {
		.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
		.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
		.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
		               VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT,
		.pfnUserCallback = on_validation, .pUserData = ctx,
	};
	VkInstanceCreateInfo ci = {
		.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
		/* Also catches messages from vkCreateInstance/vkDestroyInstance themselves. */
		.pNext = (ctx->desc.validation && ctx->has_debug_utils) ? &dbg : NULL,
		.pApplicationInfo = &app,
		.enabledLayerCount = nlayers, .ppEnabledLayerNames = layers,
		.enabledExtensionCount = nexts, .ppEnabledExtensionNames = exts,
	};
	VkResult vr = vkCreateInstance(&ci, NULL, &ctx->instance);
	if (vr != VK_SUCCESS) {
		enum rnd_result r = rnd_fail_vk(err, vr, "vkCreateInstance (is a Vulkan driver installed? mesa-vulkan-drivers)");
		if (r == RND_ERR_VULKAN) err->code = r = RND_ERR_NO_DEVICE;
		return r;
	}
	if (ctx->desc.validation && ctx->has_debug_utils) {
		PFN_vkCreateDebugUtilsMessengerEXT create = (PFN_vkCreateDebugUtilsMessengerEXT)
			vkGetInstanceProcAddr(ctx->instance, "vkCreateDebugUtilsMessengerEXT");
		if (create && create(ctx->instance, &dbg, NULL, &ctx->messenger) != VK_SUCCESS)
			ctx->messenger = VK_NULL_HANDLE;
	}
	return RND_OK;
}

static void destroy_instance(struct rnd_context *ctx)
{
	if (ctx->messenger) {
		PFN_vkDestroyDebugUtilsMessengerEXT destroy = (PFN_vkDestroyDebugUtilsMessengerEXT)
			vkGetInstanceProcAddr(ctx->instance, "vkDestroyDebugUtilsMessengerEXT");
		if (destroy) destroy(ctx->instance, ctx->messenger, NULL);
	}
	if (ctx->instance) vkDestroyInstance(ctx->instance, NULL);
}

/* Score: a name match wins; else discrete > integrated > virtual > CPU. */
static int device_score(const VkPhysicalDeviceProperties *p, const char *want)
{
	if (p->apiVersion < VK_API_VERSION_1_3) return -1;
	if (want && *want) return strstr(p->deviceName, want) ? 100 : -1;
	switch (p->deviceType) {
	case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 50;
	case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 40;
	case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 30;
	case VK_PHYSICAL_DEVICE_TYPE_CPU: return 10;
	default: return 5;
	}
}

static enum rnd_result pick_device(struct rnd_context *ctx, struct rnd_error *err)
{
	const char *want = ctx->desc.device_name;
	if (!want) want = getenv("UMBRA_DEVICE");
	uint32_t n = 0;
	VkResult vr = vkEnumeratePhysicalDevices(ctx->instance, &n, NULL);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkEnumeratePhysicalDevices");
	if (n == 0) return rnd_fail(err, RND_ERR_NO_DEVICE, "no Vulkan device found (install mesa-vulkan-drivers for lavapipe)");
	VkPhysicalDevice devs[16];
	if (n > 16) n = 16;
	vkEnumeratePhysicalDevices(ctx->instance, &n, devs);
	int best = -1;
	char names[512] = "";
	for (uint32_t i = 0; i < n; i++) {
		VkPhysicalDeviceProperties p;
		vkGetPhysicalDeviceProperties(devs[i], &p);
		size_t l = strlen(names);
		snprintf(names + l, sizeof names - l, "%s'%s'", l ? ", " : "", p.deviceName);
		int s = device_score(&p, want);
		if (s > best) { best = s; ctx->phys = devs[i]; ctx->props = p; }
	}
	if (best < 0)
		return rnd_fail(err, RND_ERR_NO_DEVICE, "no Vulkan 1.3 device%s%s%s (found %s)",
		                want && *want ? " named like '" : "", want && *want ? want : "", want && *want ? "'" : "", names);
	vkGetPhysicalDeviceMemoryProperties(ctx->phys, &ctx->mem_props);
	/* The largest single allocation and buffer: renders that would need more are refused
	 * up front (estimate.c) rather than failing as out-of-memory. */
	VkPhysicalDeviceMaintenance4Properties m4 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_PROPERTIES};
	VkPhysicalDeviceMaintenance3Properties m3 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES,
	                                             .pNext = &m4};
	VkPhysicalDeviceProperties2 lim2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &m3};
	vkGetPhysicalDeviceProperties2(ctx->phys, &lim2);
	ctx->max_allocation = m3.maxMemoryAllocationSize;
	if (m4.maxBufferSize && m4.maxBufferSize < ctx->max_allocation) ctx->max_allocation = m4.maxBufferSize;
	/* Textures per scene. A draw binds one material's set (UMBRA_TEX_SLOTS images) beside set
	 * 0's two samplers, so the device's per-stage bound limits a material, not a scene: a
	 * scene's distinct textures are bounded by memory (the estimate and admission count
	 * their texels) and by the descriptor sets each slot preallocates for them, which
	 * RND_MAX_TEXTURES_CEILING keeps to a few MB. A main-pass draw binds UMBRA_TEX_SLOTS (13,
	 * the glTF PBR extensions' textures among them) beside set 0's up to 7 samplers: more than
	 * the 16 per stage Vulkan guarantees, fewer than any desktop driver or lavapipe offers
	 * (lavapipe and NVIDIA: 10^6), so a device under that says so here rather than failing
	 * in a pipeline layout. */
	uint32_t stage_samplers = UMBRA_TEX_SLOTS + 7;
	if (ctx->props.limits.maxPerStageDescriptorSamplers < stage_samplers ||
	    ctx->props.limits.maxPerStageDescriptorSampledImages < stage_samplers)
		return rnd_fail(err, RND_ERR_NO_DEVICE, "device '%s' binds %u samplers per shader stage; umbra's main pass needs %u",
		                ctx->props.deviceName, ctx->props.limits.maxPerStageDescriptorSamplers, stage_samplers);
	ctx->device_max_textures = RND_MAX_TEXTURES_CEILING;

	VkPhysicalDeviceDriverProperties drv = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
	VkPhysicalDeviceProperties2 p2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &drv};
	vkGetPhysicalDeviceProperties2(ctx->phys, &p2);
	snprintf(ctx->driver_name, sizeof ctx->driver_name, "%s", drv.driverName);
	snprintf(ctx->driver_info, sizeof ctx->driver_info, "%s", drv.driverInfo);

	uint32_t nq = 0;
	vkGetPhysicalDeviceQueueFamilyProperties(ctx->phys, &nq, NULL);
	VkQueueFamilyProperties qf[16];
	if (nq > 16) nq = 16;
	vkGetPhysicalDeviceQueueFamilyProperties(ctx->phys, &nq, qf);
	for (uint32_t i = 0; i < nq; i++) {
		if (qf[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
			ctx->queue_family = i;
			ctx->timestamps = qf[i].timestampValidBits > 0 && ctx->props.limits.timestampPeriod > 0;
			ctx->timestamp_period = ctx->props.limits.timestampPeriod;
			return RND_OK;
		}
	}
	return rnd_fail(err, RND_ERR_NO_DEVICE, "device '%s' has no graphics queue", ctx->props.deviceName);
}

/* The shaders take subgroupOr in fragment shaders (shading.glsl light_all: the lights any pixel
 * of a block reaches). Vulkan 1.1 promises subgroups in compute shaders only; every desktop
 * driver and lavapipe have them in fragment shaders too. */
static bool fragment_subgroups(const struct rnd_context *ctx)
{
	VkPhysicalDeviceSubgroupProperties sp = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
	VkPhysicalDeviceProperties2 p2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &sp};
	vkGetPhysicalDeviceProperties2(ctx->phys, &p2);
	return (sp.supportedStages & VK_SHADER_STAGE_FRAGMENT_BIT) &&
	       (sp.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT);
}

static enum rnd_result create_device(struct rnd_context *ctx, struct rnd_error *err)
{
	if (!fragment_subgroups(ctx))
		return rnd_fail(err, RND_ERR_NO_DEVICE, "device '%s' has no subgroup arithmetic in fragment shaders",
		                ctx->props.deviceName);
	VkPhysicalDeviceFeatures have;
	vkGetPhysicalDeviceFeatures(ctx->phys, &have);
	VkPhysicalDeviceVulkan13Features f13 = {
		.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
		.dynamicRendering = VK_TRUE, .synchronization2 = VK_TRUE,
		/* SPIR-V for Vulkan 1.3 gives a compute shader's spec-constant workgroup size as
		 * LocalSizeId, which needs maintenance4 (a feature every 1.3 device has). */
		.maintenance4 = VK_TRUE,
	};
	VkPhysicalDeviceFeatures2 f2 = {
		.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &f13,
		/* depthClamp: casters in front of a cascade's near plane still cast ("pancaking"). */
		.features = {.depthClamp = have.depthClamp, .depthBiasClamp = have.depthBiasClamp,
		             .shaderImageGatherExtended = have.shaderImageGatherExtended,
		             /* the visibility pass stores r16 from a fragment shader */
		             .fragmentStoresAndAtomics = have.fragmentStoresAndAtomics,
		             .shaderStorageImageExtendedFormats = have.shaderStorageImageExtendedFormats},
	};
	float prio = 1.0f;
	VkDeviceQueueCreateInfo qci = {
		.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
		.queueFamilyIndex = ctx->queue_family, .queueCount = 1, .pQueuePriorities = &prio,
	};
	VkDeviceCreateInfo ci = {
		.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, .pNext = &f2,
		.queueCreateInfoCount = 1, .pQueueCreateInfos = &qci,
	};
	VkResult vr = vkCreateDevice(ctx->phys, &ci, NULL, &ctx->device);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkCreateDevice");
	vkGetDeviceQueue(ctx->device, ctx->queue_family, 0, &ctx->queue);
	if (ctx->has_debug_utils)
		ctx->set_object_name = (PFN_vkSetDebugUtilsObjectNameEXT)vkGetDeviceProcAddr(ctx->device, "vkSetDebugUtilsObjectNameEXT");
	RND_NAME(ctx, VK_OBJECT_TYPE_DEVICE, ctx->device, "umbra device");
	RND_NAME(ctx, VK_OBJECT_TYPE_QUEUE, ctx->queue, "umbra graphics queue");

	VkFormatProperties fp;
	vkGetPhysicalDeviceFormatProperties(ctx->phys, RND_SHADOW_FORMAT, &fp);
	if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) ||
	    !(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT)) {
		vkDestroyDevice(ctx->device, NULL);
		ctx->device = VK_NULL_HANDLE;
		return rnd_fail(err, RND_ERR_NO_DEVICE, "device '%s' cannot render and sample D32_SFLOAT shadow maps", ctx->props.deviceName);
	}
	vkGetPhysicalDeviceFormatProperties(ctx->phys, RND_VISIBILITY_FORMAT, &fp);
	VkFormatFeatureFlags vis_need = VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
	/* the surfaces pass renders normals to 16-bit snorm, a colour-attachment format Vulkan does
	 * not require (lavapipe and the desktop GPUs have it) */
	VkFormatProperties np;
	vkGetPhysicalDeviceFormatProperties(ctx->phys, RND_SURFACE_NORMALS_FORMAT, &np);
	VkFormatFeatureFlags surf_need = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
	ctx->visibility_pass = have.fragmentStoresAndAtomics && have.shaderStorageImageExtendedFormats &&
	                       (fp.optimalTilingFeatures & vis_need) == vis_need &&
	                       (np.optimalTilingFeatures & surf_need) == surf_need;
	ctx->pixel_shading = rnd_deferred_supported(ctx);
	ctx->color_formats[RND_PIXELS_RGBA8] = VK_FORMAT_R8G8B8A8_UNORM;
	ctx->color_formats[RND_PIXELS_RGBA16] = VK_FORMAT_R16G16B16A16_UNORM;
	ctx->color_formats[RND_PIXELS_RGBA32F] = VK_FORMAT_R32G32B32A32_SFLOAT;
	return RND_OK;
}

/* The cache file starts with the VkPipelineCacheHeaderVersionOne; the driver rejects data from
 * another device or driver version itself, so a stale file only costs a recompile. */
static void create_pipeline_cache(struct rnd_context *ctx)
{
	void *data = NULL;
	size_t size = 0;
	if (ctx->cache_path[0]) {
		FILE *f = fopen(ctx->cache_path, "rb");
		if (f) {
			if (fseek(f, 0, SEEK_END) == 0) {
				long n = ftell(f);
				if (n > 0 && n < (64l << 20) && fseek(f, 0, SEEK_SET) == 0 && (data = malloc((size_t)n))) {
					size = fread(data, 1, (size_t)n, f);
				}
			}
			fclose(f);
		}
	}
	VkPipelineCacheCreateInfo ci = {
		.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO, .initialDataSize = size, .pInitialData = data,
	};
	if (vkCreatePipelineCache(ctx->device, &ci, NULL, &ctx->pipeline_cache) != VK_SUCCESS) {
		ci.initialDataSize = 0; ci.pInitialData = NULL;
		if (vkCreatePipelineCache(ctx->device, &ci, NULL, &ctx->pipeline_cache) != VK_SUCCESS)
			ctx->pipeline_cache = VK_NULL_HANDLE;
	}
	RND_NAME(ctx, VK_OBJECT_TYPE_PIPELINE_CACHE, ctx->pipeline_cache, "umbra pipeline cache");
	free(data);
}

enum rnd_result rnd_context_save_cache(struct rnd_context *ctx, struct rnd_error *err)
{
	if (!ctx->cache_path[0] || !ctx->pipeline_cache) return RND_OK;
	size_t size = 0;
	VkResult vr = vkGetPipelineCacheData(ctx->device, ctx->pipeline_cache, &size, NULL);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkGetPipelineCacheData");
	void *data = malloc(size ? size : 1);
	if (!data) return rnd_fail(err, RND_ERR_OOM, "pipeline cache: out of memory (%zu bytes)", size);
	vr = vkGetPipelineCacheData(ctx->device, ctx->pipeline_cache, &size, data);
	if (vr != VK_SUCCESS) { free(data); return rnd_fail_vk(err, vr, "vkGetPipelineCacheData"); }
	char tmp[4200];
	snprintf(tmp, sizeof tmp, "%s.tmp.%ld", ctx->cache_path, (long)getpid());
	FILE *f = fopen(tmp, "wb");
	if (!f) { free(data); return rnd_fail(err, RND_ERR_IO, "cannot write pipeline cache '%s': %s", tmp, strerror(errno)); }
	size_t w = fwrite(data, 1, size, f);
	int cl = fclose(f);
	free(data);
	if (w != size || cl != 0 || rename(tmp, ctx->cache_path) != 0) {
		int e = errno;
		unlink(tmp);
		return rnd_fail(err, RND_ERR_IO, "cannot write pipeline cache '%s': %s", ctx->cache_path, strerror(e));
	}
	return RND_OK;
}

enum rnd_result rnd_context_create(const struct rnd_context_desc *desc, struct rnd_context **out, struct rnd_error *err)
{
	enum rnd_result r;
	struct rnd_error scratch_err;
	if (!err) err = &scratch_err;   /* failure paths below always fill it */
	*out = NULL;
	memset(err, 0, sizeof *err);
	struct rnd_context *ctx = calloc(1, sizeof *ctx);
	if (!ctx) return rnd_fail(err, RND_ERR_OOM, "out of memory for the context");
	if (desc) ctx->desc = *desc;
	if (!ctx->desc.slots) ctx->desc.slots = 1;
	if (!ctx->desc.max_width) ctx->desc.max_width = RND_MAX_DIMENSION;
	if (!ctx->desc.max_height) ctx->desc.max_height = RND_MAX_DIMENSION;
	if (!ctx->desc.atlas_size) ctx->desc.atlas_size = 4096;
	if (ctx->desc.pipeline_cache_path) snprintf(ctx->cache_path, sizeof ctx->cache_path, "%s", ctx->desc.pipeline_cache_path);
	ctx->desc.pipeline_cache_path = ctx->cache_path;
	ctx->desc.device_name = NULL; /* not kept: the caller's string may go away */
	pthread_mutex_init(&ctx->queue_mu, NULL);
	pthread_mutex_init(&ctx->slot_mu, NULL);
	pthread_cond_init(&ctx->slot_cv, NULL);

	struct rnd_context_desc d = desc ? *desc : (struct rnd_context_desc){0};
	ctx->desc.device_name = d.device_name; /* used by pick_device only, during create */
	if ((r = create_instance(ctx, err)) != RND_OK) goto fail_instance;
	if ((r = pick_device(ctx, err)) != RND_OK) goto fail_device;
	ctx->desc.device_name = NULL;
	ctx->max_textures = d.max_textures ? d.max_textures : RND_DEFAULT_MAX_TEXTURES;
	if (ctx->max_textures > ctx->device_max_textures) ctx->max_textures = ctx->device_max_textures;
	if ((r = create_device(ctx, err)) != RND_OK) goto fail_device;
	create_pipeline_cache(ctx);
	if ((r = rnd_pipelines_init(ctx, err)) != RND_OK) goto fail_pipelines;
	if ((r = rnd_moments_init(ctx, err)) != RND_OK) goto fail_moments;
	if ((r = rnd_slots_init(ctx, err)) != RND_OK) goto fail_slots;
	if ((r = rnd_cache_init(ctx, err)) != RND_OK) goto fail_cache;
	if ((r = rnd_env_init(ctx, err)) != RND_OK) goto fail_env;
	rnd_log(ctx, 2, "device '%s' (%s %s)", ctx->props.deviceName, ctx->driver_name, ctx->driver_info);
	*out = ctx;
	return RND_OK;

fail_env:
	rnd_cache_release_all(ctx);
fail_cache:
	rnd_slots_release(ctx);
fail_slots:
	rnd_moments_release(ctx);
fail_moments:
	rnd_pipelines_release(ctx);
fail_pipelines:
	if (ctx->pipeline_cache) vkDestroyPipelineCache(ctx->device, ctx->pipeline_cache, NULL);
	vkDestroyDevice(ctx->device, NULL);
fail_device:
	destroy_instance(ctx);
fail_instance:
	pthread_cond_destroy(&ctx->slot_cv);
	pthread_mutex_destroy(&ctx->slot_mu);
	pthread_mutex_destroy(&ctx->queue_mu);
	free(ctx);
	return r;
}

void rnd_context_destroy(struct rnd_context *ctx)
{
	if (!ctx) return;
	if (ctx->device) vkDeviceWaitIdle(ctx->device); /* once, at shutdown: nothing may be in flight */
	rnd_env_release_all(ctx);
	rnd_cache_release_all(ctx);
	rnd_slots_release(ctx);
	rnd_moments_release(ctx);
	rnd_pipelines_release(ctx);
	if (ctx->pipeline_cache) vkDestroyPipelineCache(ctx->device, ctx->pipeline_cache, NULL);
	if (ctx->device) vkDestroyDevice(ctx->device, NULL);
	destroy_instance(ctx);
	pthread_cond_destroy(&ctx->slot_cv);
	pthread_mutex_destroy(&ctx->slot_mu);
	pthread_mutex_destroy(&ctx->queue_mu);
	free(ctx);
}

void rnd_context_info(const struct rnd_context *ctx, struct rnd_info *info)
{
	memset(info, 0, sizeof *info);
	snprintf(info->device_name, sizeof info->device_name, "%s", ctx->props.deviceName);
	snprintf(info->driver_name, sizeof info->driver_name, "%s", ctx->driver_name);
	snprintf(info->driver_info, sizeof info->driver_info, "%s", ctx->driver_info);
	info->api_version = ctx->props.apiVersion;
	info->is_cpu = ctx->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
	info->max_allocation = ctx->max_allocation;
	info->max_textures = ctx->max_textures;
	info->device_max_textures = ctx->device_max_textures;
	info->max_image_dimension = ctx->props.limits.maxImageDimension2D;
	info->max_shadow_resolution = ctx->props.limits.maxImageDimension2D < 8192 ? ctx->props.limits.maxImageDimension2D : 8192;
	info->moments_fp32_filterable = ctx->moments.fp32;
}

uint32_t rnd_context_validation_messages(const struct rnd_context *ctx)
{
	return ctx ? (uint32_t)__atomic_load_n(&ctx->validation_count, __ATOMIC_RELAXED) : 0;
}
