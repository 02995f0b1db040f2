/*
 * renderer/render.c — rnd_render(): one scene, start to finish, on one render slot.
 *
 *   validate -> tessellate straight into the slot's mapped vertex/index buffers (upload)
 *   -> plan camera and shadow views -> write uniforms -> per view, submit.c records and
 *   submits the shadow passes and the main pass (MSAA + resolve) with its copy into the
 *   readback buffer, in several submits when the scene has a deadline -> copy pixels out.
 *
 * Every submit is waited on before the next, so nothing of this render is in flight when
 * rnd_render() returns (unless a fence wait itself failed: the context is then failed) and
 * the slot's resources may be reused or grown by the next render.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "contact.h"
#include "estimate.h"
#include "lod.h"
#include "material.h"
#include "mesh.h"
#include "plan.h"
#include "moments.h"
#include "record.h"
#include "shadow_cache.h"
#include "submit.h"

static double now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static enum rnd_result validate(const struct rnd_context *ctx, const struct rnd_scene *sc, struct rnd_error *err)
{
	if (sc->width < 1 || sc->height < 1 || sc->width > ctx->desc.max_width || sc->height > ctx->desc.max_height ||
	    sc->width > ctx->props.limits.maxImageDimension2D || sc->height > ctx->props.limits.maxImageDimension2D)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_SIZE, 0, "image %ux%u is outside 1..%u x 1..%u", sc->width, sc->height,
		                ctx->desc.max_width, ctx->desc.max_height);
	if (sc->output.msaa != 1 && sc->output.msaa != 4)
		return rnd_fail(err, RND_ERR_INVALID, "msaa %u: must be 1 or 4", sc->output.msaa);
	if ((unsigned)sc->output.pixels >= RND_COLOR_FORMAT_COUNT)
		return rnd_fail(err, RND_ERR_INVALID, "unknown pixel format %d", (int)sc->output.pixels);
	if (sc->material_count > UMBRA_MAX_MATERIALS)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_MATERIALS, 0, "%u materials: at most %d", sc->material_count,
		                   UMBRA_MAX_MATERIALS);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (sc->objects[i].material >= sc->material_count && sc->material_count > 0)
			return rnd_fail(err, RND_ERR_INVALID, "object %u: material %u does not exist", i, sc->objects[i].material);
	if (sc->output.debug == RND_DEBUG_SHADOW && sc->output.debug_light >= sc->light_count && sc->light_count > 0)
		return rnd_fail(err, RND_ERR_INVALID, "debug_light %u names no light", sc->output.debug_light);
	if (sc->output.aovs && sc->output.pixels != RND_PIXELS_RGBA32F)
		return rnd_fail(err, RND_ERR_INVALID, "AOVs need the linear RGBA32F output (EXR)");
	uint32_t planes = rnd_aov_planes(sc);
	if (planes > RND_MAX_AOV_PLANES)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_AOVS, 0, "%u AOV planes: at most %d (shadow AOVs of at most %d lights)",
		                   planes, RND_MAX_AOV_PLANES, RND_MAX_AOV_PLANES - 7);
	if (sc->view_count && !sc->views) return rnd_fail(err, RND_ERR_INVALID, "view_count %u with no views", sc->view_count);
	if (sc->view_count > RND_MAX_VIEWS) return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_VIEWS, 0, "%u views: at most %u", sc->view_count, RND_MAX_VIEWS);
	return RND_OK;
}

/* 32 Poisson-disk taps in the unit disk (PCSS blocker search and filtering). */
static const float POISSON[64] = {
	-0.975402f, -0.0711386f, -0.920347f, -0.41142f, -0.883908f, 0.217872f, -0.884518f, 0.568041f,
	-0.811945f, 0.90521f, -0.792474f, -0.779962f, -0.614856f, 0.386578f, -0.580859f, -0.208777f,
	-0.53795f, 0.716666f, -0.515427f, 0.0899991f, -0.454634f, -0.707938f, -0.420942f, 0.991272f,
	-0.261147f, 0.588488f, -0.211219f, 0.114841f, -0.146336f, -0.259194f, -0.139439f, -0.888668f,
	0.0116886f, 0.326395f, 0.0380566f, 0.625477f, 0.0625935f, -0.50853f, 0.125584f, 0.0469069f,
	0.169469f, -0.997253f, 0.320597f, 0.291055f, 0.359172f, -0.633717f, 0.435713f, -0.250832f,
	0.507797f, -0.916562f, 0.545763f, 0.730216f, 0.56859f, 0.11655f, 0.743156f, -0.505173f,
	0.736442f, -0.189734f, 0.843562f, 0.357036f, 0.865413f, -0.763726f, 0.872005f, 0.0483851f,
};

static VkDeviceSize align_up(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

/* Fills the uniform/storage regions and points the slot's descriptor set at them. */
static enum rnd_result write_params(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                    const struct rnd_camera_plan *cam, const struct rnd_shadow_plan *sp,
                                    float exposure, bool contact, struct rnd_error *err)
{
	VkDeviceSize al = ctx->props.limits.minStorageBufferOffsetAlignment;
	if (ctx->props.limits.minUniformBufferOffsetAlignment > al) al = ctx->props.limits.minUniformBufferOffsetAlignment;
	uint32_t nmat = sc->material_count ? sc->material_count : 1;
	/* Lights and views are uniform blocks of their declared (maximum) size. */
	uint32_t nlight = UMBRA_MAX_LIGHTS;
	uint32_t nview = UMBRA_MAX_SHADOW_VIEWS;
	VkDeviceSize off_frame = 0;
	VkDeviceSize off_mat = align_up(sizeof(struct umbra_frame), al);
	VkDeviceSize off_light = align_up(off_mat + nmat * sizeof(struct umbra_material), al);
	VkDeviceSize off_view = align_up(off_light + nlight * sizeof(struct umbra_light), al);
	VkDeviceSize total = off_view + nview * sizeof(struct umbra_shadow_view);
	enum rnd_result r = rnd_buffer_reserve(ctx, &s->params, total,
	                                       VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
	                                       "slot params", err);
	if (r != RND_OK) return r;
	uint8_t *base = s->params.map;
	memset(base, 0, total);

	struct umbra_frame *f = (struct umbra_frame *)(base + off_frame);
	memcpy(f->view_proj, cam->view_proj, sizeof f->view_proj);
	memcpy(f->view, cam->view, sizeof f->view);
	memcpy(f->camera_pos, cam->pos, sizeof cam->pos);
	f->camera_pos[3] = cam->ortho ? 1.0f : 0.0f;
	memcpy(f->camera_fwd, cam->fwd, sizeof cam->fwd);
	memcpy(f->background, sc->environment.background, sizeof f->background);
	for (int k = 0; k < 3; k++) {
		f->ambient_sky[k] = sc->environment.ambient_sky[k] * sc->environment.ambient_intensity;
		f->ambient_ground[k] = sc->environment.ambient_ground[k] * sc->environment.ambient_intensity;
	}
	f->params[0] = exp2f(exposure);
	f->params[1] = cam->znear;
	f->params[2] = cam->zfar;
	f->mode[0] = record_tonemap(sc->output.tonemap);
	f->mode[1] = record_debug(sc->output.debug);
	f->mode[2] = sc->output.debug_light;
	f->mode[3] = sc->light_count;
	f->mode2[0] = sc->output.pixels == RND_PIXELS_RGBA32F ? 1u : 0u;
	f->mode2[1] = sc->output.transparent ? 1u : 0u;
	/* UMBRA_LIGHT_CULL=0: every pixel shades every light, for the test that culling
	 * (shading.glsl light_all) leaves the image unchanged. */
	const char *cull = getenv("UMBRA_LIGHT_CULL");
	f->mode2[2] = cull && strcmp(cull, "0") == 0 ? 1u : 0u;
	memcpy(f->poisson, POISSON, sizeof f->poisson);
	f->depth_lin[0] = cam->proj[10];
	f->depth_lin[1] = cam->proj[14];
	f->depth_lin[2] = cam->proj[11];
	f->depth_lin[3] = cam->proj[15];
	f->target[0] = (float)sc->width;
	f->target[1] = (float)sc->height;
	/* proj[5] = -1/tan(fov/2) (perspective) or -2/height (orthographic): a pixel's world size. */
	f->target[2] = 2.0f / ((float)sc->height * fabsf(cam->proj[5]));
	f->target[3] = cam->ortho ? 1.0f : 0.0f;

	struct umbra_material *m = (struct umbra_material *)(base + off_mat);
	if (!sc->material_count) {
		struct rnd_material d;
		rnd_material_defaults(&d);
		memcpy(m[0].base_color, d.base_color, sizeof d.base_color);
		m[0].emissive[3] = d.roughness;
	}
	for (uint32_t i = 0; i < sc->material_count; i++) rnd_material_write(&sc->materials[i], &m[i]);

	struct umbra_light *l = (struct umbra_light *)(base + off_light);
	for (uint32_t i = 0; i < sc->light_count; i++) {
		const struct rnd_light *in = &sc->lights[i];
		const struct rnd_light_plan *lp = &sp->lights[i];
		for (int k = 0; k < 3; k++) l[i].color[k] = in->color[k] * in->intensity;
		l[i].color[3] = (float)record_light_type(in->type);
		memcpy(l[i].position, in->position, sizeof in->position);
		l[i].position[3] = in->range;
		float d[3] = {0, -1, 0};
		if (in->type != RND_LIGHT_POINT) rnd_v3_normalize(d, in->direction);
		memcpy(l[i].direction, d, sizeof d);
		l[i].direction[3] = cosf(in->outer_angle);
		l[i].params[0] = cosf(in->inner_angle);
		l[i].params[1] = in->type == RND_LIGHT_DIRECTIONAL ? tanf(in->angular_diameter * 0.5f) : in->radius;
		l[i].shadow[0] = lp->first_view;
		l[i].shadow[1] = lp->view_count;
		l[i].shadow[2] = lp->filter;
		l[i].shadow[3] = lp->pcf_radius;
		l[i].shadow_params[0] = lp->bias_normal;
		l[i].shadow_params[1] = lp->search_texels;
		l[i].shadow_params[2] = in->shadow.blend;
		l[i].shadow_params[3] = lp->fade_start;
		l[i].params[2] = lp->clipmap ? 1.0f : 0.0f;
		l[i].params[3] = lp->max_distance;
		memcpy(l[i].splits, lp->splits, sizeof lp->splits);
		if (lp->moments) {
			float c = lp->evsm_exponent;
			l[i].moment_params[0] = lp->evsm ? c : 0.0f;
			l[i].moment_params[1] = fminf(fmaxf(in->shadow.vsm_light_bleed, 0.0f), 0.999f);
			/* Variance floor: a fraction of the warped depth's scale (EVSM) or of the
			 * depth range (VSM), so flat receivers do not self-shadow. */
			l[i].moment_params[2] = lp->evsm ? 1e-4f : 2e-6f;
		}
		/* The mapped block keeps the previous render's values: off is written, not assumed. */
		memset(l[i].contact, 0, sizeof l[i].contact);
		if (rnd_contact_on(sc, sp, i)) rnd_contact_params(&in->shadow, l[i].contact);
	}
	memcpy(base + off_view, sp->views, sp->view_count * sizeof(struct umbra_shadow_view));

	VkDescriptorBufferInfo bi[4] = {
		{s->params.buf, off_frame, sizeof(struct umbra_frame)},
		{s->params.buf, off_mat, nmat * sizeof(struct umbra_material)},
		{s->params.buf, off_light, nlight * sizeof(struct umbra_light)},
		{s->params.buf, off_view, nview * sizeof(struct umbra_shadow_view)},
	};
	VkDescriptorImageInfo ii = {ctx->pipes.shadow_sampler, ctx->atlas_depth.view, VK_IMAGE_LAYOUT_GENERAL};
	/* Without a moment atlas (no storage images) no light uses moments; the binding still
	 * needs an image. */
	VkDescriptorImageInfo mi = ctx->atlas_moments.view
		? (VkDescriptorImageInfo){ctx->moments.sampler, ctx->atlas_moments.view, VK_IMAGE_LAYOUT_GENERAL}
		: (VkDescriptorImageInfo){ctx->pipes.shadow_sampler, ctx->atlas_depth.view, VK_IMAGE_LAYOUT_GENERAL};
	/* Contact shadows read the view's depth (drawn before the main pass); other renders bind
	 * the white texture, which their pipelines never read. */
	VkDescriptorImageInfo di = contact
		? (VkDescriptorImageInfo){ctx->pipes.shadow_sampler, s->scene_depth.view, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL}
		: (VkDescriptorImageInfo){ctx->pipes.texture_samplers[0], s->white.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
	VkWriteDescriptorSet w[7];
	w[5] = (VkWriteDescriptorSet){
		.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->set, .dstBinding = UMBRA_BINDING_MOMENTS,
		.descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &mi,
	};
	w[6] = (VkWriteDescriptorSet){
		.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->set, .dstBinding = UMBRA_BINDING_SCENE_DEPTH,
		.descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &di,
	};
	for (int i = 0; i < 5; i++) {
		w[i] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->set, .dstBinding = (uint32_t)i,
			.descriptorCount = 1,
			.descriptorType = rnd_binding_type[i],
			.pBufferInfo = i < 4 ? &bi[i] : NULL, .pImageInfo = i == 4 ? &ii : NULL,
		};
	}
	vkUpdateDescriptorSets(ctx->device, 7, w, 0, NULL);
	/* moments.comp: the scratch map in, the blur temporary, the moment atlas out. */
	/* Moment maps read at most maxStorageBufferRange bytes of it (their resolution is capped to
	 * fit: rnd_moments_max_res); a larger depth-only scratch is never read through this. */
	VkDeviceSize sb_range = s->scratch_buf.size < ctx->props.limits.maxStorageBufferRange
	                      ? s->scratch_buf.size : ctx->props.limits.maxStorageBufferRange;
	VkDescriptorBufferInfo sbi = {s->scratch_buf.buf, 0, sb_range};
	VkDescriptorImageInfo ci[3] = {
		{VK_NULL_HANDLE, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED},
		{VK_NULL_HANDLE, s->moments_tmp.view, VK_IMAGE_LAYOUT_GENERAL},
		{VK_NULL_HANDLE, ctx->atlas_moments.view, VK_IMAGE_LAYOUT_GENERAL},
	};
	VkWriteDescriptorSet cw[3];
	uint32_t ncw = 0;
	if (s->scratch_buf.buf)
		cw[ncw++] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->moments_set,
			.dstBinding = UMBRA_MOMENTS_BINDING_DEPTH, .descriptorCount = 1,
			.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, .pBufferInfo = &sbi,
		};
	for (uint32_t i = 1; i < 3; i++) {
		if (!ci[i].imageView) continue;
		cw[ncw++] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->moments_set, .dstBinding = i,
			.descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, .pImageInfo = &ci[i],
		};
	}
	vkUpdateDescriptorSets(ctx->device, ncw, cw, 0, NULL);
	return RND_OK;
}


/* Tessellates every object into the slot's buffers; fills draws and the scene bounds. */
static enum rnd_result upload(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                              const struct rnd_pacer *pacer, const uint32_t *lod, struct draw *draws,
                              struct rnd_aabb *bounds, struct rnd_error *err)
{
	uint64_t nv = 0, ni = 0;
	for (uint32_t i = 0; i < sc->object_count; i++) {
		uint32_t v, x;
		struct rnd_object o = sc->objects[i];
		rnd_lod_apply(&o, lod[i]); /* renderer/lod.h: no finer than the output can show */
		rnd_mesh_counts(&o, &v, &x);
		nv += v; ni += x;
	}
	if (nv > UINT32_MAX || ni > UINT32_MAX)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_OBJECTS, 0, "scene too large: %llu vertices, %llu indices",
		                (unsigned long long)nv, (unsigned long long)ni);
	enum rnd_result r;
	VkDeviceSize vbytes = (nv ? nv : 1) * sizeof(struct rnd_vertex), ibytes = (ni ? ni : 1) * sizeof(uint32_t);
	if ((r = rnd_buffer_reserve(ctx, &s->vertices, vbytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "slot vertices", err)) != RND_OK)
		return r;
	if ((r = rnd_buffer_reserve(ctx, &s->indices, ibytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, "slot indices", err)) != RND_OK)
		return r;
	struct rnd_vertex *vtx = s->vertices.map;
	uint32_t *idx = s->indices.map;
	uint32_t vbase = 0, ibase = 0;
	rnd_aabb_empty(bounds);
	for (uint32_t i = 0; i < sc->object_count; i++) {
		struct rnd_object lo = sc->objects[i];
		rnd_lod_apply(&lo, lod[i]);
		const struct rnd_object *o = &lo;
		struct draw *d = &draws[i];
		uint32_t v, x;
		rnd_mesh_counts(o, &v, &x);
		/* Tessellating millions of triangles takes seconds: the deadline holds here too. */
		if (((i & 15) == 0 || x > (1u << 20)) && (r = rnd_pacer_check(pacer, err)) != RND_OK) return r;
		rnd_aabb_empty(&d->bounds);
		if ((r = rnd_mesh_write(o, vtx + vbase, idx + ibase, vbase, &d->bounds, err)) != RND_OK) {
			char m[sizeof err->msg];
			snprintf(m, sizeof m, "%s", err->msg);
			return rnd_fail(err, r, "object %u: %s", i, m);
		}
		d->first_index = ibase;
		d->index_count = x;
		d->first_vertex = vbase;
		d->vertex_count = v;
		d->material = sc->material_count ? o->material : 0;
		bool catcher = sc->material_count && sc->materials[o->material].shadow_catcher;
		d->flags = (o->receive_shadows ? UMBRA_DRAW_RECEIVE_SHADOWS : 0) | (catcher ? UMBRA_DRAW_SHADOW_CATCHER : 0);
		/* A shadow catcher receives shadows and casts none (contract §7). */
		d->cast = o->cast_shadows && !catcher;
		/* MASK and dithered BLEND both take the alpha-tested depth passes. */
		d->masked = sc->material_count && sc->materials[o->material].alpha_mode != RND_ALPHA_OPAQUE;
		d->texture_set = 0; /* set by rnd_material_textures() */
		d->single_sided = !o->double_sided;
		d->closed = o->shape == RND_SHAPE_SPHERE || o->shape == RND_SHAPE_BOX || o->shape == RND_SHAPE_CYLINDER ||
		            (o->shape == RND_SHAPE_MESH && o->closed);
		d->cull_back = d->single_sided;
		rnd_aabb_union(bounds, &d->bounds);
		vbase += v; ibase += x;
	}
	return RND_OK;
}

/* Number of AOV passes the scene's AOVs need (see aov.frag). */
/* Turns the AOV attachments in the readback buffer (RGBA32F, sheet-sized each) into named
 * float planes. */
static enum rnd_result split_aovs(const struct rnd_scene *sc, const float *rb, size_t att_floats, uint32_t npix,
                                  struct rnd_image *out, struct rnd_error *err)
{
	uint32_t aovs = sc->output.aovs;
	struct { char name[24]; uint32_t att, comp; } plan[RND_MAX_AOV_PLANES];
	uint32_t n = 0;
	if (aovs & RND_AOV_SHADOW) {
		for (uint32_t i = 0; i < sc->light_count; i++) {
			uint32_t att = i < 8 ? 2 + i / 4 : 4 + (i - 8) / 4, comp = i % 4;
			snprintf(plan[n].name, sizeof plan[n].name, "shadow.%u", i);
			plan[n].att = att; plan[n].comp = comp; n++;
		}
	}
	if (aovs & RND_AOV_DEPTH) { snprintf(plan[n].name, 24, "Z"); plan[n].att = 0; plan[n].comp = 0; n++; }
	if (aovs & RND_AOV_NORMAL) {
		const char *nm[3] = {"N.X", "N.Y", "N.Z"};
		for (int k = 0; k < 3; k++) { snprintf(plan[n].name, 24, "%s", nm[k]); plan[n].att = 0; plan[n].comp = 1 + k; n++; }
	}
	if (aovs & RND_AOV_ALBEDO) {
		const char *nm[3] = {"albedo.R", "albedo.G", "albedo.B"};
		for (int k = 0; k < 3; k++) { snprintf(plan[n].name, 24, "%s", nm[k]); plan[n].att = 1; plan[n].comp = k; n++; }
	}
	for (uint32_t p = 0; p < n; p++) {
		float *plane = malloc((size_t)npix * sizeof(float));
		if (!plane) return rnd_fail(err, RND_ERR_OOM, "out of memory for AOV '%s'", plan[p].name);
		const float *src = rb + plan[p].att * att_floats + plan[p].comp;
		for (uint32_t i = 0; i < npix; i++) plane[i] = src[(size_t)i * 4];
		out->aov[p] = plane;
		memcpy(out->aov_names[p], plan[p].name, sizeof out->aov_names[p]);
		out->aov_count = p + 1;
	}
	return RND_OK;
}

/* 8/16-bit outputs with transparency: straight alpha (PNG's convention) from the premultiplied
 * resolve. RGBA32F (EXR) stays premultiplied, as EXR expects. */
static void unpremultiply(void *pixels, uint64_t n, enum rnd_pixel_format f)
{
	if (f == RND_PIXELS_RGBA8) {
		uint8_t *p = pixels;
		for (uint64_t i = 0; i < n; i++, p += 4) {
			unsigned a = p[3];
			if (a == 0 || a == 255) continue;
			for (int k = 0; k < 3; k++) {
				unsigned v = (p[k] * 255u + a / 2) / a;
				p[k] = (uint8_t)(v > 255 ? 255 : v);
			}
		}
	} else if (f == RND_PIXELS_RGBA16) {
		uint16_t *p = pixels;
		for (uint64_t i = 0; i < n; i++, p += 4) {
			uint32_t a = p[3];
			if (a == 0 || a == 65535) continue;
			for (int k = 0; k < 3; k++) {
				uint32_t v = (p[k] * 65535u + a / 2) / a;
				p[k] = (uint16_t)(v > 65535 ? 65535 : v);
			}
		}
	}
}

enum rnd_result rnd_render(struct rnd_context *ctx, const struct rnd_scene *sc, struct rnd_image *out,
                           struct rnd_timings *timings, struct rnd_error *err)
{
	enum rnd_result r;
	struct rnd_timings tm = {0};
	struct rnd_error scratch_err;
	if (!err) err = &scratch_err;   /* failure paths below always fill it */
	memset(out, 0, sizeof *out);
	memset(err, 0, sizeof *err);
	if (__atomic_load_n(&ctx->failed, __ATOMIC_RELAXED))
		return rnd_fail(err, RND_ERR_DEVICE_LOST, "the Vulkan device was lost earlier; the context must be recreated");
	if ((r = validate(ctx, sc, err)) != RND_OK) return r;

	uint32_t nviews = sc->view_count ? sc->view_count : 1;
	uint32_t cols, rows;
	rnd_sheet_layout(nviews, &cols, &rows);
	uint64_t sheet_w = (uint64_t)cols * sc->width, sheet_h = (uint64_t)rows * sc->height;
	if (sheet_w > RND_MAX_SHEET_SIDE || sheet_h > RND_MAX_SHEET_SIDE || sheet_w * sheet_h > RND_MAX_SHEET_PIXELS)
		return rnd_fail_at(err, RND_ERR_LIMIT, RND_AT_VIEWS, 0, "a sheet of %u views is %llux%llu pixels: too large", nviews,
		                (unsigned long long)sheet_w, (unsigned long long)sheet_h);
	struct rnd_estimate est;
	if ((r = rnd_render_estimate(ctx, sc, &est, err)) != RND_OK) return r;

	struct rnd_cache_grant grants[UMBRA_MAX_LIGHTS];
	uint32_t grant_light[UMBRA_MAX_LIGHTS], req_tiles[UMBRA_MAX_LIGHTS];
	uint32_t ngrant = 0;
	bool granted = false;
	bool gpu_busy = false;        /* a submit did not finish: keep its resources alive */
	uint8_t cascades[UMBRA_MAX_LIGHTS] = {0};

	/* Per-request memory: one block for the draw list, the shadow plan, the level of detail of
	 * each object and the texture list. */
	size_t draws_bytes = (sc->object_count ? sc->object_count : 1) * sizeof(struct draw);
	size_t lod_bytes = (sc->object_count ? sc->object_count : 1) * sizeof(uint32_t);
	size_t tex_off = (draws_bytes + sizeof(struct rnd_shadow_plan) + lod_bytes + 15) & ~(size_t)15;
	void *arena = malloc(tex_off + ctx->max_textures * sizeof(void *));
	if (!arena) return rnd_fail(err, RND_ERR_OOM, "out of memory for %u objects", sc->object_count);
	struct draw *draws = arena;
	struct rnd_shadow_plan *sp = (struct rnd_shadow_plan *)((char *)arena + draws_bytes);
	uint32_t *lod = (uint32_t *)((char *)sp + sizeof *sp);
	rnd_lod_choose(sc, nviews, sp, lod);

	struct rnd_slot *s = rnd_slot_acquire(ctx);
	double t0 = now_ms();
	struct rnd_pacer pacer;
	rnd_pacer_init(&pacer, sc);
	if ((r = rnd_pacer_check(&pacer, err)) != RND_OK) goto done;
	struct rnd_aabb bounds;
	struct rnd_camera_plan cam;
	const struct rnd_texture **tex = (const struct rnd_texture **)((char *)arena + tex_off);
	uint32_t ntex = 0;
	if ((r = upload(ctx, s, sc, &pacer, lod, draws, &bounds, err)) != RND_OK) goto done;
	/* Auto-framing `fit: objects` leaves out planes and shadow catchers (the ground). */
	struct rnd_aabb obj_bounds;
	rnd_aabb_empty(&obj_bounds);
	for (uint32_t i = 0; i < sc->object_count; i++)
		if (rnd_object_frames(&sc->objects[i], sc->material_count ? sc->materials : NULL))
			rnd_aabb_union(&obj_bounds, &draws[i].bounds);
	if (rnd_aabb_is_empty(&obj_bounds)) obj_bounds = bounds;
	if ((r = rnd_material_textures(ctx, s, sc, draws, tex, &ntex, err)) != RND_OK) goto done;
	tm.upload_ms = now_ms() - t0;
	pacer.tex = tex;
	pacer.ntex = ntex;
	pacer.prologue = true;

	VkFormat fmt = ctx->color_formats[sc->output.pixels];
	if ((r = rnd_slot_targets(ctx, s, fmt, sc->width, sc->height, sc->output.msaa, err)) != RND_OK) goto done;
	uint32_t passes = rnd_aov_passes(sc);
	if (passes && (r = rnd_slot_aov(ctx, s, sc->width, sc->height, err)) != RND_OK) goto done;
	size_t px = (size_t)rnd_pixel_bytes(sc->output.pixels);
	VkDeviceSize color_bytes = sheet_w * sheet_h * px;
	VkDeviceSize att_bytes = sheet_w * sheet_h * 16;
	VkDeviceSize rb = color_bytes + (VkDeviceSize)passes * UMBRA_AOV_ATTACHMENTS * att_bytes;
	if ((r = rnd_buffer_reserve(ctx, &s->readback, rb, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "slot readback", err)) != RND_OK)
		goto done;
	if (nviews > 1) memset(s->readback.map, 0, rb); /* unused cells of the sheet (colour and AOVs) */

	/* A plane with every other object on its lit side shadows nothing: out of the shadow pass. */
	for (uint32_t i = 0; i < sc->object_count && sc->object_count <= 256; i++) {
		if (!draws[i].cast || sc->objects[i].shape != RND_SHAPE_PLANE) continue;
		bool casts = false;
		for (uint32_t j = 0; j < sc->object_count && !casts; j++)
			casts = j != i && rnd_plane_may_shadow(sc, &sc->objects[i], &draws[j].bounds);
		draws[i].cast = casts;
	}

	/* What every spot/point key starts from: the casters' world-space geometry, their
	 * culling and alpha masks (with texture content), and the scene bounds (far planes). */
	uint64_t geo = rnd_hash(0x756d627261ull, &bounds, sizeof bounds);
	for (uint32_t i = 0; i < sc->object_count; i++) {
		const struct draw *d = &draws[i];
		if (!d->cast || !d->index_count) continue;
		uint32_t flags[3] = {d->single_sided, d->closed, d->masked};
		geo = rnd_hash(geo, flags, sizeof flags);
		geo = rnd_hash(geo, (const struct rnd_vertex *)s->vertices.map + d->first_vertex,
		               (size_t)d->vertex_count * sizeof(struct rnd_vertex));
		geo = rnd_hash(geo, (const uint32_t *)s->indices.map + d->first_index, (size_t)d->index_count * 4);
		if (d->masked) {
			const struct rnd_material *m = &sc->materials[sc->objects[i].material];
			geo = rnd_hash(geo, &m->alpha_cutoff, sizeof m->alpha_cutoff);
			geo = rnd_hash(geo, &m->alpha_mode, sizeof m->alpha_mode);
			geo = rnd_hash(geo, &m->sampling[RND_TEX_BASE], sizeof m->sampling[RND_TEX_BASE]);
			geo = rnd_hash(geo, m->base_color, sizeof m->base_color);
			if (m->base_color_texture)
				geo = rnd_hash(geo, m->base_color_texture->rgba,
				               (size_t)m->base_color_texture->width * m->base_color_texture->height * 4);
		}
	}

	for (uint32_t v = 0; v < nviews; v++) {
		const struct rnd_camera *camera = sc->view_count ? &sc->views[v] : &sc->camera;
		if ((r = rnd_camera_plan(camera, sc->width, sc->height, camera->fit == RND_FIT_OBJECTS ? &obj_bounds : &bounds,
		                         &cam, err)) != RND_OK)
			goto done;
		if (camera->fit == RND_FIT_OBJECTS) {
			/* Framed on the objects, but near/far must still hold the whole scene. */
			struct rnd_camera c2 = *camera;
			memcpy(c2.position, cam.pos, sizeof cam.pos);
			for (int k = 0; k < 3; k++) c2.target[k] = cam.pos[k] + cam.fwd[k];
			c2.fit = RND_FIT_NONE;
			if ((r = rnd_camera_plan(&c2, sc->width, sc->height, &bounds, &cam, err)) != RND_OK) goto done;
		}
		for (uint32_t i = 0; i < sc->object_count; i++)
			draws[i].cull_back = draws[i].single_sided ||
			                     (draws[i].closed && record_camera_outside(&cam, &draws[i].bounds));
		if ((r = rnd_shadow_plan_with(sc, &bounds, &cam, v ? cascades : NULL, sp, err)) != RND_OK) goto done;
		if (v == 0)
			for (uint32_t i = 0; i < sc->light_count && i < UMBRA_MAX_LIGHTS; i++)
				cascades[i] = sc->lights[i].type == RND_LIGHT_DIRECTIONAL && sp->lights[i].view_count > 1 &&
				              !sp->lights[i].clipmap;
		bool any_moments = false;
		for (uint32_t i = 0; i < sc->light_count; i++)
			if (sp->lights[i].moments && sp->lights[i].view_count) any_moments = true;
		if (any_moments && !ctx->atlas_moments.img) {
			r = rnd_fail(err, RND_ERR_INVALID, "shadow filters vsm/evsm need storage images this device lacks");
			goto done;
		}
		for (uint32_t i = 0; i < sc->light_count; i++) {
			struct rnd_light_plan *lp = &sp->lights[i];
			/* exp(2cd) must stay finite in the precision asked for (fp16 storage limits c). */
			float cmax = rnd_moments_max_exponent(lp->fp16 ? VK_FORMAT_R16G16_SFLOAT : ctx->atlas_moments.format);
			if (lp->evsm) lp->evsm_exponent = lp->evsm_exponent > 0 ? fminf(lp->evsm_exponent, cmax) : cmax;
		}

		/* Tiles: granted once per request. Spot and point maps are keyed for reuse by later
		 * requests; directional maps are transient. Later views re-render only the maps that
		 * follow the camera (cascades, clipmap levels) into the same tiles. */
		if (!granted) {
			struct rnd_cache_request req[UMBRA_MAX_LIGHTS];
			for (uint32_t i = 0; i < sc->light_count; i++) {
				const struct rnd_light_plan *lp = &sp->lights[i];
				if (!lp->view_count) continue;
				uint64_t key = 0;
				if (sc->lights[i].type != RND_LIGHT_DIRECTIONAL) {
					float k[8] = {lp->bias_constant, lp->bias_slope, (float)lp->resolution, (float)lp->filter,
					              lp->moments ? (lp->evsm ? lp->evsm_exponent : -1.0f) : 0.0f,
					              lp->moments ? sc->lights[i].shadow.vsm_blur : 0.0f, (float)sc->lights[i].type, 0};
					key = rnd_hash(geo, k, sizeof k);
					key = rnd_hash(key, &sp->views[lp->first_view], lp->view_count * sizeof(struct umbra_shadow_view));
					if (!key) key = 1;
				}
				grant_light[ngrant] = i;
				req_tiles[ngrant] = lp->view_count;
				/* Moment maps are read as a storage buffer: at most the device's range. */
				uint32_t res = lp->resolution, mmax = rnd_moments_max_res(ctx);
				if (lp->moments && res > mmax) res = mmax;
				req[ngrant++] = (struct rnd_cache_request){key, lp->view_count, res};
			}
			/* Waiting for atlas room counts against the render's deadline like its submits. */
			double wait_until = sc->deadline_ns ? (double)sc->deadline_ns * 1e-9 : 0.0;
			if ((r = rnd_cache_acquire(ctx, req, ngrant, wait_until, grants, err)) != RND_OK) { ngrant = 0; goto done; }
			granted = true;
		}
		uint32_t max_moment_res = 0;
		for (uint32_t k = 0; k < ngrant; k++) {
			const struct rnd_light_plan *lp = &sp->lights[grant_light[k]];
			if (lp->view_count != req_tiles[k]) {
				r = rnd_fail(err, RND_ERR_INVALID, "light %u: view %u needs %u shadow tiles, view 0 had %u",
				             grant_light[k], v, lp->view_count, req_tiles[k]);
				goto done;
			}
			bool follows_camera = sc->lights[grant_light[k]].type == RND_LIGHT_DIRECTIONAL && lp->view_count > 1;
			bool skip = grants[k].hit || (v > 0 && !follows_camera);
			for (uint32_t t = 0; t < lp->view_count; t++) {
				float *rect = sp->views[lp->first_view + t].rect;
				rect[0] = (float)grants[k].tile[t].x;
				rect[1] = (float)grants[k].tile[t].y;
				rect[2] = (float)grants[k].res;
				rect[3] = (float)ctx->desc.atlas_size;
				sp->view_skip[lp->first_view + t] = skip;
				if (skip) tm.shadow_maps_reused++;
				else tm.shadow_maps_rendered++;
			}
			if (lp->moments && !skip && grants[k].res > max_moment_res) max_moment_res = grants[k].res;
		}
		if (max_moment_res && (r = rnd_slot_moments_tmp(ctx, s, max_moment_res, err)) != RND_OK) goto done;
		uint32_t max_res = 64;
		for (uint32_t k = 0; k < ngrant; k++)
			if (grants[k].res > max_res) max_res = grants[k].res;
		if ((r = rnd_slot_shadow_scratch(ctx, s, max_res, err)) != RND_OK) goto done;
		bool contact = rnd_contact_any(sc, sp);
		if (contact && (r = rnd_slot_scene_depth(ctx, s, sc->width, sc->height, err)) != RND_OK) goto done;
		if ((r = write_params(ctx, s, sc, &cam, sp, camera->exposure, contact, err)) != RND_OK) goto done;

		uint32_t col = v % cols, row = v / cols;
		VkDeviceSize cell = ((VkDeviceSize)row * sc->height * sheet_w + (VkDeviceSize)col * sc->width);
		struct record_view rv = {
			.sc = sc, .cam = &cam, .sp = sp, .draws = draws, .ndraw = sc->object_count, .aov_passes = passes,
			.color_offset = cell * px, .aov_offset = color_bytes + cell * 16, .aov_stride = att_bytes,
			.sheet_width = (uint32_t)sheet_w, .pixel_bytes = (uint32_t)px, .contact = contact,
		};
		if ((r = rnd_submit_view(ctx, s, &rv, &pacer, &tm, &gpu_busy, err)) != RND_OK) goto done;
	}

	double t_copy = now_ms();
	out->pixels = malloc(color_bytes);
	if (!out->pixels) { r = rnd_fail(err, RND_ERR_OOM, "out of memory for a %llux%llu image",
	                                 (unsigned long long)sheet_w, (unsigned long long)sheet_h); goto done; }
	memcpy(out->pixels, s->readback.map, color_bytes);
	if (sc->output.transparent && sc->output.debug == RND_DEBUG_NONE) unpremultiply(out->pixels, sheet_w * sheet_h, sc->output.pixels);
	out->width = (uint32_t)sheet_w;
	out->height = (uint32_t)sheet_h;
	out->format = sc->output.pixels;
	out->stride = sheet_w * px;
	out->view_count = nviews;
	out->view_columns = cols;
	out->view_width = sc->width;
	out->view_height = sc->height;
	if (passes && (r = split_aovs(sc, (const float *)((const uint8_t *)s->readback.map + color_bytes), att_bytes / 4,
	                              (uint32_t)(sheet_w * sheet_h), out, err)) != RND_OK) {
		rnd_image_release(out);
		goto done;
	}
	tm.readback_ms += now_ms() - t_copy;
	r = RND_OK;
	goto done;

done:
	if (r == RND_ERR_DEVICE_LOST) {
		__atomic_store_n(&ctx->failed, 1, __ATOMIC_RELAXED);
		rnd_cache_wake(ctx);   /* renders waiting for atlas room: they would wait for ever */
		rnd_log(ctx, 0, "device lost: %s", err->msg);
	}
	/* Everything this render submitted has completed (each submit is waited on; a failed
	 * vkQueueSubmit leaves nothing in flight, a deadline stops between submits) — unless a
	 * fence wait failed: then the GPU may still use the tiles and textures, and they stay held
	 * (the context is failed and must be recreated, which waits for the device first). Any
	 * other failure, out of memory included, gives its tiles back to the atlas here. */
	if (!gpu_busy) {
		if (granted) rnd_cache_release(ctx, grants, ngrant, r == RND_OK);
		rnd_slot_drop_textures(ctx, s);
		rnd_slot_trim(ctx, s);
	}
	rnd_slot_release(ctx, s);
	free(arena);
	if (timings) *timings = tm;
	return r;
}
