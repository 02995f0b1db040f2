/*
 * renderer/frame.h — the frame constants of one view (see frame.c): the umbra_frame block, the
 * materials, the lights and the shadow views packed into the slot's parameter buffer, and the
 * slot's descriptor sets pointed at them (set 0 of the draw pipelines, minmax.comp's and moments.frag's sets).
 *
 * Called by render.c once per view, after the shadow plan has its atlas tiles and before the
 * view is recorded. Threading: the slot is the caller's; nothing else is written.
 */
#ifndef UMBRA_RENDERER_FRAME_H
#define UMBRA_RENDERER_FRAME_H

#include "plan.h"
#include "slot.h"

struct rnd_env_use;

/* Fills the uniform/storage regions (growing the slot's parameter buffer when needed) and
 * points the slot's descriptor sets at them. contact: the view draws its camera depth
 * (slot->scene_depth, bound for contact shadows). The slot's visibility-pass images are bound
 * too (visibility.c): the caller makes sure they exist. */
/* sc: the scene with the environment's directions after its own lights (render.c); env: what
 * the render holds of its environment (NULL: none), for the umbra_env block and its images;
 * env_pass: the environment pass's images are bound (else the slot's white stand-ins). */
enum rnd_result rnd_frame_write(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_scene *sc,
                                const struct rnd_camera_plan *cam, const struct rnd_shadow_plan *sp,
                                float exposure, bool contact, const struct rnd_env_use *env, bool env_pass,
                                struct rnd_error *err);

/* The 32 Poisson-disk taps of the frame block (x, y pairs; PCSS's search and filter), and the
 * longest tap's length (umbra_frame.params.w). Tests check the order the search relies on. */
const float *rnd_frame_poisson(float *longest);

/* How PCSS's filter reads those taps, (tap - centre) * scale: out[0], out[1] the mean of taps
 * first, first + step, ..., out[2] the scale that gives them a uniform disk's mean squared
 * radius, 1/2 (umbra_frame.filter_taps: all 32; env_filter_taps: the 16 odd ones). */
void rnd_frame_filter_taps(float out[3], int first, int step);

#endif
