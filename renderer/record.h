/*
 * renderer/record.h — recording one view's commands into a slot's command buffer: texture
 * uploads, shadow passes, the camera's depth pre-pass + main pass, the AOV passes, and the
 * copies into the readback buffer. Called by submit.c only; nothing here submits or waits.
 */
#ifndef UMBRA_RENDERER_RECORD_H
#define UMBRA_RENDERER_RECORD_H

#include "draw.h"
#include "plan.h"
#include "slot.h"

struct rnd_env_use;

/* Draws what the camera passes draw of d (cam_first_index, cam_index_count). */
static inline void record_draw_camera(VkCommandBuffer cmd, const struct draw *d)
{
	vkCmdDrawIndexed(cmd, d->cam_index_count, 1, d->cam_first_index, 0, 0);
}

/* Everything the recorders need to know about this view. */
struct record_view {
	const struct rnd_scene *sc;
	const struct rnd_camera_plan *cam;
	const struct rnd_shadow_plan *sp;
	const struct draw *draws;
	uint32_t ndraw;
	uint32_t aov_passes;           /* 0 = no AOVs */
	VkDeviceSize color_offset;     /* where this view's pixels go in the readback buffer */
	VkDeviceSize aov_offset;       /* where its first AOV attachment goes */
	VkDeviceSize aov_stride;       /* bytes between AOV attachments' regions */
	uint32_t sheet_width;          /* pixels per readback row */
	uint32_t pixel_bytes;          /* of one colour pixel in the readback buffer */
	/* The rows of this view that one submit draws (render area + scissor; the viewport stays
	 * the whole view, so a band's pixels are exactly those of the unsplit pass). */
	uint32_t band_y, band_h;       /* band_h 0 = every row */
	bool contact;                  /* draw the view's depth for contact shadows first (contact.c) */
	bool vis;                      /* shadows from the visibility pass (visibility.c), drawn per band */
	/* The plan's estimates (cost.c): each shadow view's milliseconds and casters' triangles,
	 * the main pass's per row and per band. */
	const double *map_ms;
	const uint64_t *map_tris;
	double row_ms, band_ms;
	/* What the recorders drew, counted as they record (struct rnd_timings; NULL: not counted):
	 * the camera's triangles in the main pass (pixel shading's: its depth pass) of the view's
	 * first band, the casters' triangles of every shadow map drawn. */
	uint64_t *drawn_camera, *drawn_shadow;
	bool deferred;                 /* with vis: shaded once per pixel centre (deferred.c) */
	/* Every light the shadow passes draw for: the scene's, then the environment's directions
	 * (render.c, env_shadow.h); NULL: the scene's. */
	const struct rnd_light *shadow_lights;
	const struct rnd_env_use *env;  /* the view's environment (NULL: none) */
	bool env_pass;                 /* its shadows from the environment pass (env_pass.c), drawn once */
	bool env_pass_reused;          /* that pass's images as the slot holds them (env_pass.h): not drawn */
};

/* The rows of the view that this submit draws (band_y, band_h). */
VkRect2D record_band_area(const struct record_view *rv);
void record_image_barrier(VkCommandBuffer cmd, VkImage img, VkImageAspectFlags aspect, uint32_t layers,
                          VkImageLayout from, VkImageLayout to, VkPipelineStageFlags2 src_stage,
                          VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access);
/* A colour target written whole by a fullscreen pass: img made a colour attachment, its old
 * contents dropped, after its previous use at src_stage; the attachment (not cleared, stored). */
VkRenderingAttachmentInfo record_color_overwrite(VkCommandBuffer cmd, const struct rnd_image_res *img,
                                                 VkPipelineStageFlags2 src_stage);
/* Depth-only passes (shadow maps, the camera depth of contact shadows): img made a depth
 * attachment after its previous use (src_stage, src_access), then rendering begun into its
 * view over (0, 0, w, h), cleared to 1, with that viewport and scissor. */
void record_begin_depth(VkCommandBuffer cmd, VkImage img, VkImageView view, uint32_t w, uint32_t h,
                        VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access);
/* The rendering begun by record_begin_depth (view already a depth attachment): cleared to 1, or
 * with load what an earlier submit drew kept (a shadow map in parts, record_shadow.c). */
void record_depth_rendering(VkCommandBuffer cmd, VkImageView view, uint32_t w, uint32_t h, bool load);
/* Binds the slot's vertex and index buffers and its set 0 (frame constants, atlases). */
void record_bind_geometry(struct rnd_context *ctx, struct rnd_slot *s);
/* The band's camera draws, inside a rendering the caller began: record_bind_geometry, then each
 * draw with pipes[its cull_back], bound when it changes. push: each draw's material and flags as
 * push constants (the surfaces passes' shaders read them); count: its camera triangles added to
 * rv->drawn_camera (by the one pass per view that stands for the main pass). */
void record_camera_draws(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                         const VkPipeline pipes[2], bool push, bool count);
/* A colour attachment just written (COLOR_ATTACHMENT_OPTIMAL), made readable by the next
 * pass's fragment shaders (SHADER_READ_ONLY_OPTIMAL). */
void record_color_to_sampled(VkCommandBuffer cmd, VkImage img);
/* One draw with the shadow (depth-only) pipelines, culling back faces when cull is set; masked
 * draws get their material index in push->info.x and their texture set. *bound is the
 * pipeline bound last (VK_NULL_HANDLE at the start of a pass). */
void record_depth_draw(struct rnd_context *ctx, struct rnd_slot *s, const struct draw *d, int cull,
                       struct umbra_push *push, VkPipeline *bound);
/* Copies the staged texels (slot->staging, tightly packed in texture order) into the slot's
 * texture images and leaves them ready for sampling (upload.c). */
void record_textures(struct rnd_slot *s, const struct rnd_texture *const *tex, uint32_t n);
/* Shadow views first..end-1 of v->sp (skipped ones left out), each drawn into the slot's
 * scratch map and copied into its atlas tile. */
void record_shadows(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *v, uint32_t first,
                    uint32_t end);
/* One map in parts, each its own submit (record_shadow.c): triangles [lo, hi) of the `total`
 * that shadow view v draws (those of the draws record_shadow_draws says it draws); the part from 0 begins the map, the one
 * reaching total copies it into its tile. Between parts the slot's scratch depth image holds
 * the map so far: nothing else may draw into it. */
void record_shadow_part(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *v, uint32_t view,
                        uint64_t lo, uint64_t hi, uint64_t total);
/* Whether shadow view v draws draw i (a caster inside its frustum) and, if so, with back faces
 * culled (*cull). */
bool record_shadow_draws(const struct record_view *rv, uint32_t v, uint32_t i, int *cull);
/* The specialization key of the view's main pass (see mesh.frag) over its first ndraw draws. */
void record_main_key(const struct record_view *rv, uint32_t ndraw, struct rnd_main_key *k);
enum rnd_result record_main(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *v,
                            struct rnd_error *err);
enum rnd_result record_aov(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *v,
                           struct rnd_error *err);
/* Copies the band's resolved colour into the readback buffer, then makes it host-visible
 * (readback.c). */
void record_readback(struct rnd_slot *s, const struct record_view *v);

/* The public enums as the shaders spell them (umbra_shared.h); the uniforms (frame.c) and
 * the specialization key (record.c) both use these, so they cannot drift apart. */
uint32_t record_light_type(enum rnd_light_type t);
/* The background as the main pass's colour target holds it (its clear value): the requested
 * colour itself, sRGB-encoded for display outputs, not tone mapped (a caller asking for white
 * gets 255); (0,0,0,0) for a transparent output. */
void record_clear_color(const struct rnd_scene *sc, float out[4]);
uint32_t record_tonemap(enum rnd_tonemap t);
uint32_t record_debug(enum rnd_debug d);


#endif
