/*
 * renderer/readback.h — the render's output: the sheet its views are laid out on, the layout of
 * the readback buffer (colour, then the AOV attachments of every pass), and the copy out of that
 * buffer into the caller's rnd_image (see readback.c).
 *
 * Threading: pure sizes, and a copy from a slot the caller holds whose submits have completed.
 */
#ifndef UMBRA_RENDERER_READBACK_H
#define UMBRA_RENDERER_READBACK_H

#include "slot.h"

/* The views' sheet and where everything lies in the slot's readback buffer. */
struct rnd_sheet {
	uint32_t views, cols, rows;
	uint64_t width, height;       /* pixels of the whole sheet */
	size_t px;                    /* bytes of one colour pixel */
	uint32_t passes;              /* AOV passes (0 = no AOVs) */
	VkDeviceSize color_bytes;     /* the colour sheet, at offset 0 */
	VkDeviceSize att_bytes;       /* one RGBA32F AOV attachment of the sheet, after the colour */
	VkDeviceSize readback_bytes;  /* all of it */
};

/* The sheet of scene sc (which passed validation). Pure. */
void rnd_sheet_init(struct rnd_sheet *sh, const struct rnd_scene *sc);
/* Copies the colour sheet (straight alpha for transparent 8/16-bit outputs) and the AOV planes
 * out of the slot's readback buffer into *out. On failure *out is left empty. */
enum rnd_result rnd_readback_image(const struct rnd_slot *s, const struct rnd_scene *sc, const struct rnd_sheet *sh,
                                   struct rnd_image *out, struct rnd_error *err);

#endif
