/*
 * renderer/readback.h — the render's output: the copy out of the readback buffer (laid out as
 * the plan's sheet says, estimate.h: colour, then the AOV attachments of every pass) into the
 * caller's rnd_image (see readback.c).
 *
 * Threading: a copy from a slot the caller holds whose submits have completed.
 */
#ifndef UMBRA_RENDERER_READBACK_H
#define UMBRA_RENDERER_READBACK_H

#include "estimate.h"
#include "slot.h"

/* Copies the colour sheet (straight alpha for transparent 8/16-bit outputs) and the AOV planes
 * out of the slot's readback buffer into *out. On failure *out is left empty. */
enum rnd_result rnd_readback_image(const struct rnd_slot *s, const struct rnd_scene *sc, const struct rnd_sheet *sh,
                                   struct rnd_image *out, struct rnd_error *err);

#endif
