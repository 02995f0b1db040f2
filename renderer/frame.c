/*
 * renderer/frame.c — frame constants (see frame.h): what the shaders read of one view, packed
 * in the layouts of shaders/umbra_shared.h. Four regions of one host-visible buffer, each
 * aligned for uniform and storage use: the frame block, the materials (storage, as many as
 * the scene has), the lights and the shadow views (uniform blocks of their declared maximum
 * size). The mapped buffer keeps the previous render's bytes: every region is cleared first.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "contact.h"
#include "env.h"
#include "env_pass.h"
#include "frame.h"
#include "material.h"
#include "moments.h"
#include "record.h"

/* 32 Poisson-disk taps around the unit disk (PCSS blocker search and filtering; nine lie a
 * little outside it, the longest at 1.216: umbra_frame.params.w, how far the taps reach). The
 * even ones, the search's wide ring (shaders/shading.glsl pcss), come in ascending length: the
 * search takes only those that can reach a blocker (pcss_bounds' bound), a prefix
 * (tests/unit/test_plan_lights.c checks the order). The filter takes all 32. */
static const float POISSON[64] = {
	-0.146336f, -0.259194f, -0.920347f, -0.41142f, 0.0116886f, 0.326395f, -0.884518f, 0.568041f,
	0.0625935f, -0.50853f, -0.792474f, -0.779962f, 0.56859f, 0.11655f, -0.580859f, -0.208777f,
	-0.261147f, 0.588488f, -0.515427f, 0.0899991f, -0.614856f, 0.386578f, -0.420942f, 0.991272f,
	0.359172f, -0.633717f, -0.211219f, 0.114841f, 0.736442f, -0.189734f, -0.139439f, -0.888668f,
	-0.454634f, -0.707938f, 0.0380566f, 0.625477f, -0.53795f, 0.716666f, 0.125584f, 0.0469069f,
	-0.883908f, 0.217872f, 0.320597f, 0.291055f, -0.975402f, -0.0711386f, 0.435713f, -0.250832f,
	0.169469f, -0.997253f, 0.545763f, 0.730216f, 0.507797f, -0.916562f, 0.743156f, -0.505173f,
	0.865413f, -0.763726f, 0.843562f, 0.357036f, -0.811945f, 0.90521f, 0.872005f, 0.0483851f,
};

const float *rnd_frame_poisson(float *longest)
{
	float l = 0.0f;
	for (int i = 0; i < 32; i++) l = fmaxf(l, sqrtf(POISSON[2 * i] * POISSON[2 * i] + POISSON[2 * i + 1] * POISSON[2 * i + 1]));
	*longest = l;
	return POISSON;
}

/* The filter's 32 taps stand for a uniform disk of the penumbra's half-width: over a straight
 * edge, a light of uniform disk (sun) or sphere (spot, point) shape casts the penumbra of such a
 * disk, whose taps average at the centre with mean squared radius 1/2. The table's taps average
 * at (-0.061, -0.030) and spread wider (mean squared radius 0.663: 15 % in RMS radius, 3 to 28 %
 * in the 10-90 % width across an edge, by its direction), so every PCSS penumbra came out wider
 * than the light's and shifted by 6 % of its width. Issue 31: under a thin plate whose blocker
 * depth PCSS knows exactly, umbra's 10-90 % widths were 12.2-13.6 px where the traced reference
 * and Cycles (which agree within 0.5 %) have 11.6-11.7, and its edges stood 0.6 px off. The
 * filter reads the taps centred and scaled by 0.872 (the longest then 1.046, within
 * params.w's reach); the search keeps the table as it is. The environment's filter (ibl.glsl
 * env_pcss) reads the 16 odd taps the same way, with their own centre and scale. */
void rnd_frame_filter_taps(float out[3], int first, int step)
{
	double mx = 0.0, my = 0.0, r2 = 0.0;
	int n = 0;
	for (int i = first; i < 32; i += step, n++) {
		mx += POISSON[2 * i];
		my += POISSON[2 * i + 1];
	}
	mx /= n;
	my /= n;
	for (int i = first; i < 32; i += step) {
		double x = POISSON[2 * i] - mx, y = POISSON[2 * i + 1] - my;
		r2 += (x * x + y * y) / n;
	}
	out[0] = (float)mx;
	out[1] = (float)my;
	out[2] = (float)sqrt(0.5 / r2);
}

static VkDeviceSize align_up(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

/* Where each region starts in the slot's parameter buffer. */
struct params_layout {
	VkDeviceSize off_frame, off_mat, off_light, off_view, off_env, total;
	uint32_t nmat, nlight, nview;
};

static void params_layout(const struct rnd_context *ctx, const struct rnd_scene *sc, struct params_layout *lay)
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
	VkDeviceSize off_env = align_up(off_view + nview * sizeof(struct umbra_shadow_view), al);
	VkDeviceSize total = off_env + sizeof(struct umbra_env);
	*lay = (struct params_layout){off_frame, off_mat, off_light, off_view, off_env, total, nmat, nlight, nview};
}

static void write_frame(struct umbra_frame *f, const struct rnd_scene *sc, const struct rnd_camera_plan *cam,
                        float exposure, uint32_t shaded_lights)
{
	memcpy(f->view_proj, cam->view_proj, sizeof f->view_proj);
	memcpy(f->view, cam->view, sizeof f->view);
	memcpy(f->camera_pos, cam->pos, sizeof cam->pos);
	f->camera_pos[3] = cam->ortho ? 1.0f : 0.0f;
	memcpy(f->camera_fwd, cam->fwd, sizeof cam->fwd);
	memcpy(f->background, sc->environment.background, sizeof f->background);
	record_clear_color(sc, f->clear);
	if (!rnd_mat4_invert(f->inv_view_proj, cam->view_proj)) memset(f->inv_view_proj, 0, sizeof f->inv_view_proj);
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
	f->mode[3] = shaded_lights;
	f->mode2[0] = sc->output.pixels == RND_PIXELS_RGBA32F ? 1u : 0u;
	f->mode2[1] = sc->output.transparent ? 1u : 0u;
	/* UMBRA_LIGHT_CULL=0: every pixel shades every light, for the test that culling
	 * (shading.glsl light_all) leaves the image unchanged. */
	const char *cull = getenv("UMBRA_LIGHT_CULL");
	f->mode2[2] = cull && strcmp(cull, "0") == 0 ? 1u : 0u;
	memcpy(f->poisson, rnd_frame_poisson(&f->params[3]), sizeof f->poisson);
	rnd_frame_filter_taps(f->filter_taps, 0, 1);
	rnd_frame_filter_taps(f->env_filter_taps, 1, 2);   /* env_pcss's 16 odd taps (ibl.glsl) */
	f->depth_lin[0] = cam->proj[10];
	f->depth_lin[1] = cam->proj[14];
	f->depth_lin[2] = cam->proj[11];
	f->depth_lin[3] = cam->proj[15];
	f->target[0] = (float)sc->width;
	f->target[1] = (float)sc->height;
	/* proj[5] = -1/tan(fov/2) (perspective) or -2/height (orthographic): a pixel's world size. */
	f->target[2] = 2.0f / ((float)sc->height * fabsf(cam->proj[5]));
	f->target[3] = cam->ortho ? 1.0f : 0.0f;
}

static void write_materials(struct umbra_material *m, const struct rnd_scene *sc)
{
	for (uint32_t i = 0; i < sc->material_count || i == 0; i++) rnd_material_record(sc, i, &m[i]);
}

/* Light i of the scene with its shadow plan (views, filter, bias, moments, contact). */
static void write_light(const struct rnd_context *ctx, struct umbra_light *l, const struct rnd_scene *sc,
                        const struct rnd_shadow_plan *sp, uint32_t i)
{
	const struct rnd_light *in = &sc->lights[i];
	const struct rnd_light_plan *lp = &sp->lights[i];
	for (int k = 0; k < 3; k++) l->color[k] = in->color[k] * in->intensity;
	l->color[3] = (float)record_light_type(in->type);
	memcpy(l->position, in->position, sizeof in->position);
	l->position[3] = in->range;
	float d[3] = {0, -1, 0};
	if (in->type != RND_LIGHT_POINT) rnd_v3_normalize(d, in->direction);
	memcpy(l->direction, d, sizeof d);
	l->direction[3] = cosf(in->outer_angle);
	l->params[0] = cosf(in->inner_angle);
	l->params[1] = in->type == RND_LIGHT_DIRECTIONAL ? tanf(in->angular_diameter * 0.5f) : in->radius;
	l->shadow[0] = lp->first_view;
	l->shadow[1] = lp->view_count;
	l->shadow[2] = lp->filter;
	l->shadow[3] = lp->pcf_radius;
	/* PCSS: 1 = record.c drew the depth bounds with the maps. UMBRA_PCSS_BOUNDS=0 (read per
	 * render) leaves them unread, for the test that they change no byte (test_pcss_bounds). */
	const char *use = getenv("UMBRA_PCSS_BOUNDS");
	if (lp->filter == UMBRA_FILTER_PCSS)
		l->shadow[3] = lp->view_count && rnd_bounds_wanted(ctx, lp, (uint32_t)sp->views[lp->first_view].rect[2]) &&
		               !(use && strcmp(use, "0") == 0);
	l->shadow_params[0] = lp->bias_normal;
	l->shadow_params[1] = lp->search_texels;
	l->shadow_params[2] = in->shadow.blend;
	l->shadow_params[3] = lp->fade_start;
	l->params[2] = lp->clipmap ? 1.0f : 0.0f;
	l->params[3] = lp->max_distance;
	memcpy(l->splits, lp->splits, sizeof lp->splits);
	if (lp->moments) {
		float c = lp->evsm_exponent;
		l->moment_params[0] = lp->evsm ? c : 0.0f;
		l->moment_params[1] = fminf(fmaxf(in->shadow.vsm_light_bleed, 0.0f), 0.999f);
		/* Variance floor: a fraction of the warped depth's scale (EVSM) or of the
		 * depth range (VSM), so flat receivers do not self-shadow. */
		l->moment_params[2] = lp->evsm ? 1e-4f : 2e-6f;
		l->moment_params[3] = lp->moment_edge;
	}
	/* The mapped block keeps the previous render's values: off is written, not assumed. */
	memset(l->contact, 0, sizeof l->contact);
	if (rnd_contact_on(sc, sp, i)) rnd_contact_params(&in->shadow, l->contact);
}

/* w[0 .. n - 1]: bindings binding .. binding + n - 1 of set 0, images each of its own type. */
static uint32_t put_images(VkWriteDescriptorSet *w, VkDescriptorSet set, uint32_t binding, uint32_t n,
                           const VkDescriptorImageInfo *ii)
{
	for (uint32_t i = 0; i < n; i++)
		w[i] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = set, .dstBinding = binding + i,
			.descriptorCount = 1, .descriptorType = rnd_binding_type[binding + i], .pImageInfo = &ii[i],
		};
	return n;
}

/* Set 0's bindings of the passes beside the main one: the visibility pass's, the environment's
 * and pixel shading's (UMBRA_BINDING_SURFACES on). */
static void bind_passes(struct rnd_context *ctx, struct rnd_slot *s, const struct params_layout *lay,
                        const struct rnd_env_use *env, bool env_pass)
{
	VkWriteDescriptorSet w[UMBRA_BINDING_COUNT - UMBRA_BINDING_SURFACES];
	uint32_t n = 0;
	/* The visibility pass's images (visibility.c): only the pipelines of renders that use it
	 * declare them; other renders bind whatever images the slot has (render.c). */
	VkDescriptorImageInfo vi[4] = {
		{ctx->pipes.shadow_sampler, s->surfaces.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
		{ctx->pipes.shadow_sampler, s->normals.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
		{ctx->pipes.shadow_sampler, s->visibility.view, VK_IMAGE_LAYOUT_GENERAL},
		{VK_NULL_HANDLE, s->visibility.view, VK_IMAGE_LAYOUT_GENERAL},
	};
	n += put_images(w + n, s->set, UMBRA_BINDING_SURFACES, 4, vi);
	/* The environment: its block and images (the slot's white stand-ins without a map), the
	 * environment pass's images (stand-ins without the pass). */
	VkDescriptorBufferInfo ebi = {s->params.buf, lay->off_env, sizeof(struct umbra_env)};
	w[n++] = (VkWriteDescriptorSet){
		.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->set, .dstBinding = UMBRA_BINDING_ENV,
		.descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, .pBufferInfo = &ebi,
	};
	VkDescriptorImageInfo ei[6];
	rnd_env_images(ctx, env, s, ei);
	const struct rnd_image_res *pass[3] = {&s->env_surfaces, &s->env_normals, &s->env_vis};
	for (int i = 0; i < 3; i++)
		ei[3 + i] = env_pass ? (VkDescriptorImageInfo){ctx->pipes.shadow_sampler, pass[i]->view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}
		                     : (VkDescriptorImageInfo){ctx->pipes.texture_samplers[0], s->white.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
	n += put_images(w + n, s->set, UMBRA_BINDING_ENV_SPECULAR, 6, ei);
	/* Pixel shading's (deferred.c): its inputs, the shaded colours and the view's depth samples
	 * (integer and depth formats: the nearest sampler without a border; only texelFetch). */
	VkDescriptorImageInfo pi[3] = {
		{ctx->pipes.atlas_sampler, s->shading.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
		{ctx->pipes.atlas_sampler, s->shaded.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
		{ctx->pipes.atlas_sampler, s->depth.view, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL},
	};
	n += put_images(w + n, s->set, UMBRA_BINDING_SURFACE_SHADING, 3, pi);
	vkUpdateDescriptorSets(ctx->device, n, w, 0, NULL);
}

/* Set 0 of the draw pipelines: the four regions, the depth and moment atlases, the camera depth,
 * then the passes' bindings (bind_passes). */
static void bind_params(struct rnd_context *ctx, struct rnd_slot *s, const struct params_layout *lay, bool contact,
                        const struct rnd_env_use *env, bool env_pass)
{
	VkDescriptorBufferInfo bi[4] = {
		{s->params.buf, lay->off_frame, sizeof(struct umbra_frame)},
		{s->params.buf, lay->off_mat, lay->nmat * sizeof(struct umbra_material)},
		{s->params.buf, lay->off_light, lay->nlight * sizeof(struct umbra_light)},
		{s->params.buf, lay->off_view, lay->nview * sizeof(struct umbra_shadow_view)},
	};
	VkDescriptorImageInfo ii[4];
	ii[0] = (VkDescriptorImageInfo){ctx->pipes.atlas_sampler, ctx->atlas_depth.view, VK_IMAGE_LAYOUT_GENERAL};
	/* Without a moment atlas (no storage images) no light uses moments; the binding still
	 * needs an image. */
	ii[1] = ctx->atlas_moments.view
		? (VkDescriptorImageInfo){ctx->moments.sampler, ctx->atlas_moments.view, VK_IMAGE_LAYOUT_GENERAL}
		: (VkDescriptorImageInfo){ctx->pipes.shadow_sampler, ctx->atlas_depth.view, VK_IMAGE_LAYOUT_GENERAL};
	/* Contact shadows read the view's depth (drawn before the main pass); other renders bind
	 * the white texture, which their pipelines never read. */
	ii[2] = contact
		? (VkDescriptorImageInfo){ctx->pipes.shadow_sampler, s->scene_depth.view, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL}
		: (VkDescriptorImageInfo){ctx->pipes.texture_samplers[0], s->white.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
	/* Lights without depth bounds never read them (umbra_light.shadow.w). */
	ii[3] = ctx->atlas_bounds.view
		? (VkDescriptorImageInfo){ctx->pipes.shadow_sampler, ctx->atlas_bounds.view, VK_IMAGE_LAYOUT_GENERAL}
		: ii[0];
	VkWriteDescriptorSet w[UMBRA_BINDING_SURFACES];
	for (int i = 0; i < 4; i++) {
		w[i] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->set, .dstBinding = (uint32_t)i,
			.descriptorCount = 1, .descriptorType = rnd_binding_type[i], .pBufferInfo = &bi[i],
		};
	}
	put_images(w + UMBRA_BINDING_SHADOW_MAP, s->set, UMBRA_BINDING_SHADOW_MAP, 4, ii);
	vkUpdateDescriptorSets(ctx->device, UMBRA_BINDING_SURFACES, w, 0, NULL);
	bind_passes(ctx, s, lay, env, env_pass);
}

/* minmax.comp: the scratch map in, the depth bounds out. moments.frag: the depth atlas and the
 * blur temporary in (the moment atlas is its pass 1's attachment). */
static void bind_moments(struct rnd_context *ctx, struct rnd_slot *s)
{
	/* Bounds are drawn only for maps within maxStorageBufferRange bytes (rnd_bounds_wanted); a
	 * larger depth-only scratch is never read through this. */
	VkDeviceSize sb_range = s->scratch_buf.size < ctx->props.limits.maxStorageBufferRange
	                      ? s->scratch_buf.size : ctx->props.limits.maxStorageBufferRange;
	VkDescriptorBufferInfo sbi = {s->scratch_buf.buf, 0, sb_range};
	VkDescriptorImageInfo bi = {VK_NULL_HANDLE, ctx->atlas_bounds.view, VK_IMAGE_LAYOUT_GENERAL};
	VkDescriptorImageInfo fi[2] = {
		[UMBRA_MOMENTS_BINDING_DEPTH] = {ctx->moments.nearest, ctx->atlas_depth.view, VK_IMAGE_LAYOUT_GENERAL},
		[UMBRA_MOMENTS_BINDING_BLUR] = {ctx->moments.nearest, s->moments_tmp.view, VK_IMAGE_LAYOUT_GENERAL},
	};
	VkWriteDescriptorSet w[4];
	uint32_t n = 0;
	if (s->scratch_buf.buf)
		w[n++] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->moments_set,
			.dstBinding = UMBRA_MINMAX_BINDING_DEPTH, .descriptorCount = 1,
			.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, .pBufferInfo = &sbi,
		};
	if (ctx->atlas_bounds.view)
		w[n++] = (VkWriteDescriptorSet){
			.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->moments_set,
			.dstBinding = UMBRA_MINMAX_BINDING_BOUNDS, .descriptorCount = 1,
			.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, .pImageInfo = &bi,
		};
	/* The blur set only once the slot has a temporary: only renders with moment maps bind it. */
	if (s->blur_set && s->moments_tmp.view)
		for (uint32_t i = 0; i < 2; i++)
			w[n++] = (VkWriteDescriptorSet){
				.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = s->blur_set, .dstBinding = i,
				.descriptorCount = 1, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &fi[i],
			};
	vkUpdateDescriptorSets(ctx->device, n, w, 0, NULL);
}

enum rnd_result rnd_frame_write(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                const struct rnd_camera_plan *cam, const struct rnd_shadow_plan *sp,
                                float exposure, bool contact, const struct rnd_env_use *env, bool env_pass,
                                struct rnd_error *err)
{
	struct params_layout lay;
	params_layout(ctx, sc, &lay);
	enum rnd_result r = rnd_buffer_reserve(ctx, &s->params, lay.total,
	                                       VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
	                                       "slot params", err);
	if (r != RND_OK) return r;
	uint8_t *base = s->params.map;
	memset(base, 0, lay.total);
	s->params_used = lay.total;
	/* The environment's directions come after the scene's lights (render.c): lights, but not
	 * shaded as such (ibl.glsl reads their maps). */
	uint32_t env_lights = env ? env->mapped : 0, shaded = sc->light_count - env_lights;
	write_frame((struct umbra_frame *)(base + lay.off_frame), sc, cam, exposure, shaded);
	float inv_vp[16];
	if (!rnd_mat4_invert(inv_vp, cam->view_proj)) memset(inv_vp, 0, sizeof inv_vp);
	static const struct rnd_env_use none;
	rnd_env_write(env ? env : &none, &sc->environment, inv_vp, shaded, rnd_env_pass_scale(sc->width, sc->height),
	              (struct umbra_env *)(base + lay.off_env));
	write_materials((struct umbra_material *)(base + lay.off_mat), sc);
	struct umbra_light *l = (struct umbra_light *)(base + lay.off_light);
	for (uint32_t i = 0; i < sc->light_count; i++) write_light(ctx, &l[i], sc, sp, i);
	memcpy(base + lay.off_view, sp->views, sp->view_count * sizeof(struct umbra_shadow_view));
	bind_params(ctx, s, &lay, contact, env, env_pass);
	bind_moments(ctx, s);
	return RND_OK;
}
