/*
 * renderer/upload.h — tessellation into the slot's buffers (see upload.c), called by render.c
 * once per render, as its plan says, before anything is recorded.
 *
 * Threading: the slot is the caller's; its vertex and index buffers are grown (after their last
 * fence: nothing of the slot is in flight while it is held) and written through their mapping.
 */
#ifndef UMBRA_RENDERER_UPLOAD_H
#define UMBRA_RENDERER_UPLOAD_H

#include "render_plan.h"
#include "submit.h"

/* Tessellates every object (at the plan's level of detail, renderer/lod.h) into the slot's
 * buffers where the plan's draws say, and the camera's proxy of a sphere where the plan has
 * one (renderer/proxy.h). Checks the pacer's deadline as it goes: a scene of millions of
 * triangles takes seconds. */
enum rnd_result rnd_upload_scene(struct rnd_context *ctx, struct rnd_slot *s, const struct rnd_plan *plan,
                                 const struct rnd_pacer *pacer, struct rnd_error *err);

#endif
