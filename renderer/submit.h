/*
 * renderer/submit.h — one view's work as submits that can stop (render.c calls it per view).
 *
 * With a deadline or a cancel callback in the scene, the work of a view is cut into several
 * submits, each waited on before the next is recorded: shadow views in groups of about half
 * a slice by estimate (an eighth until a group was measured, then scaled by what it measured), then the main (+ AOV) pass in horizontal bands (render area + scissor)
 * whose height comes from the measured time of the bands before. Between submits the deadline
 * and the callback are checked; past them the view stops with RND_ERR_TIMEOUT. Without
 * either, a view is one submit (the normal path costs nothing extra).
 *
 * A fence is waited on in slices with no limit: a slow submit is slow, never "lost". Only a
 * VkResult from the driver (VK_ERROR_DEVICE_LOST, or any other failed wait: the GPU state is
 * then unknown) fails the context. The test-only fault switch (rnd_context_inject_fault) acts
 * at the queue submit.
 *
 * Threading: a pacer belongs to one render; the slot is the caller's.
 */
#ifndef UMBRA_RENDERER_SUBMIT_H
#define UMBRA_RENDERER_SUBMIT_H

#include "env.h"
#include "record.h"

struct rnd_pacer {
	const struct rnd_scene *sc;
	double slice_ms;            /* target wall time of one submit; 0 = as few submits as possible */
	uint32_t submits;           /* submitted by this render so far */
	uint32_t shadow_parts;      /* of them, parts of shadow maps (submit.c) */
	uint32_t shadow_submits;    /* of them, those of shadow maps alone (whole or in parts; paced only) */
	/* Shadow groups: measured wall time over the estimate of the last group or map part
	 * measured (at least 1), and whether one was (submit.c: the first group is kept small
	 * until then). */
	double shadow_scale;
	bool shadow_measured;
	const struct rnd_texture *const *tex; /* staged textures, recorded into the first submit */
	uint32_t ntex;
	bool prologue;              /* textures (and the slot's white texture) not yet recorded */
	struct rnd_context *ctx;    /* for the environment's build, recorded with the prologue */
	const struct rnd_env_use *env; /* env.h: what the render builds of its environment (NULL: nothing) */
	/* The last two bands: rows and wall milliseconds (the next band's height comes from them). */
	uint32_t rows[2];
	double ms[2];
	uint32_t measured;
};

/* After a whole group of shadow maps, estimated est ms by the cost model and measured wall ms:
 * the scale of the groups after it (wall / est, never below 1: never plan with less than the
 * estimate, as the bands) and shadow_measured (the first group is kept small until then). A
 * submit that also carried the prologue (textures, environment: prologue true) says nothing of
 * the maps' and does not count. */
void rnd_pacer_shadow_measured(struct rnd_pacer *p, bool prologue, double est, double wall);
/* The same after one part of a map drawn in parts: part of its total caster triangles, the
 * map estimated est ms whole; the part's share of the estimate is measured against wall. */
void rnd_pacer_shadow_part_measured(struct rnd_pacer *p, bool prologue, double est, uint64_t part, uint64_t total,
                                    double wall);

/* Sets the slice from the deadline left (a quarter of it, 50..1000 ms) or 0 without one. */
void rnd_pacer_init(struct rnd_pacer *p, const struct rnd_scene *sc);
/* RND_ERR_TIMEOUT when the rows_left of the main pass cannot be drawn before the deadline at
 * the last band's measured cost: stopped now, not at the deadline (the worker goes to the
 * requests behind it a whole render's time earlier; under load, when the machine is slowest). */
enum rnd_result rnd_pacer_hopeless(const struct rnd_pacer *p, uint32_t rows_left, struct rnd_error *err);
/* RND_ERR_TIMEOUT (message says how far past) when the deadline has passed or cancel says so. */
enum rnd_result rnd_pacer_check(const struct rnd_pacer *p, struct rnd_error *err);
/* Height of the next band: from the estimate before any band ran, else from the last two
 * bands (time = fixed + rows * per_row); at least min_rows, at most left. Pure. */
uint32_t rnd_pacer_band_rows(const struct rnd_pacer *p, uint32_t left, uint32_t min_rows, double est_row_ms,
                             double est_fixed_ms);

/* Records and submits view rv (its shadow views, then its main pass in bands). On failure
 * *gpu_busy is set when commands may still run on the GPU (a failed fence wait): the caller
 * must then keep what they use (the context is failed). */
enum rnd_result rnd_submit_view(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                struct rnd_pacer *p, struct rnd_timings *tm, bool *gpu_busy, struct rnd_error *err);

#endif
