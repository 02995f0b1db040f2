/*
 * renderer/submit.c — submits that can stop (see submit.h): the deadline check, the fault
 * switch, submit + sliced fence wait, band sizing, and the order of one view's submits.
 */
#include <math.h>
#include <string.h>
#include <time.h>
#include "deferred.h"
#include "visibility.h"
#include "env_pass.h"
#include "submit.h"
#include "contact.h"

/* A fence is waited on in slices this long; between slices a long wait is logged. */
#define WAIT_SLICE_NS (1000ull * 1000 * 1000)

static uint64_t now_ns(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (uint64_t)t.tv_sec * 1000000000ull + (uint64_t)t.tv_nsec;
}

void rnd_pacer_init(struct rnd_pacer *p, const struct rnd_scene *sc)
{
	memset(p, 0, sizeof *p);
	p->sc = sc;
	p->shadow_scale = 1.0;
	if (sc->deadline_ns) {
		uint64_t now = now_ns();
		double left = sc->deadline_ns > now ? (double)(sc->deadline_ns - now) / 1e6 : 0.0;
		/* An eighth of the time left, at most a second: a render that yields to the requests
		 * behind it (at half their deadline) stops within a slice, with room for theirs. */
		p->slice_ms = fmin(1000.0, fmax(50.0, left / 8));
	} else if (sc->cancel) {
		p->slice_ms = 1000.0;
	}
}

enum rnd_result rnd_pacer_check(const struct rnd_pacer *p, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	if (sc->deadline_ns) {
		uint64_t now = now_ns();
		if (now >= sc->deadline_ns)
			return rnd_fail(err, RND_ERR_TIMEOUT, "stopped %.0f ms past its deadline after %u submits",
			                (double)(now - sc->deadline_ns) / 1e6, p->submits);
	}
	if (sc->cancel && sc->cancel(sc->cancel_user))
		return rnd_fail(err, RND_ERR_TIMEOUT, "cancelled after %u submits", p->submits);
	return RND_OK;
}

enum rnd_result rnd_pacer_hopeless(const struct rnd_pacer *p, uint32_t rows_left, struct rnd_error *err)
{
	const struct rnd_scene *sc = p->sc;
	if (!sc->deadline_ns || !p->measured || !p->rows[1]) return RND_OK;
	/* The rows left at the last band's measured cost: a low bound (the rows below are rarely
	 * cheaper than the sky above), so a render stopped here would not have made it. */
	double left_ms = (double)rows_left * p->ms[1] / p->rows[1];
	uint64_t now = now_ns();
	double time_ms = sc->deadline_ns > now ? (double)(sc->deadline_ns - now) / 1e6 : 0;
	if (left_ms <= time_ms) return RND_OK;
	return rnd_fail(err, RND_ERR_TIMEOUT, "stopped after %u submits: its %u rows left need ~%.0f ms at the rate measured, "
	                "%.0f ms before its deadline", p->submits, rows_left, left_ms, time_ms);
}

uint32_t rnd_pacer_band_rows(const struct rnd_pacer *p, uint32_t left, uint32_t min_rows, double est_row_ms,
                             double est_fixed_ms)
{
	double slice = p->slice_ms > 0 ? p->slice_ms : 1000.0;
	double per_row = est_row_ms, fixed = est_fixed_ms, cap = INFINITY;
	if (p->measured >= 1) {
		double r1 = p->rows[1], t1 = p->ms[1];
		per_row = t1 / r1;
		fixed = 0;
		if (p->measured >= 2) {
			double r0 = p->rows[0], t0 = p->ms[0];
			/* Two bands of clearly different height separate the per-band work (vertices,
			 * repeated in every band) from the per-row work. */
			if (fabs(r1 - r0) >= 0.25 * fmax(r0, r1)) {
				double k = (t1 - t0) / (r1 - r0), v = t1 - r1 * k;
				if (k > 0 && v >= 0) { per_row = k; fixed = v; }
			}
		}
		cap = 2 * r1;   /* rows differ (sky above, objects below): grow at most 2x per band */
	}
	/* Cheap rows (background) say little about the rows below them: never plan with less than
	 * the estimate per row. With a quarter of it, 16 soft spot lights at 2048^2 measured the sky
	 * and then ran one 3 s band with a request waiting behind it (the daemon yields between
	 * submits, at half the waiter's deadline: it answered 504 where it had time for 200). */
	if (per_row < est_row_ms) per_row = est_row_ms;
	if (per_row <= 0) per_row = 1e-6;
	/* Vertex-bound: more bands only repeat the fixed part; let a band's rows cost at least
	 * three times it instead of shrinking without end. */
	double rows = fixed < 0.75 * slice ? (slice - fixed) / per_row : 3 * fixed / per_row;
	if (p->measured == 0 && rows < min_rows) rows = min_rows;
	if (rows > cap) rows = cap;
	if (rows < min_rows) rows = min_rows;
	if (rows >= left || left - rows < min_rows) return left;   /* no sliver at the bottom */
	return (uint32_t)rows;
}

/* Submits the slot's command buffer and waits for it. Nothing stays in flight after a failed
 * vkQueueSubmit (the spec leaves resources untouched then), so only a failed wait sets
 * *gpu_busy. */
static enum rnd_result submit_wait(struct rnd_context *ctx, struct rnd_slot *s, bool *gpu_busy, struct rnd_error *err)
{
	VkResult vr = VK_SUCCESS;
	int fault = __atomic_load_n(&ctx->fault_kind, __ATOMIC_RELAXED);
	if (fault && __atomic_sub_fetch(&ctx->fault_countdown, 1, __ATOMIC_RELAXED) == 0 &&
	    __atomic_exchange_n(&ctx->fault_kind, RND_FAULT_NONE, __ATOMIC_RELAXED) == fault) {
		vr = fault == RND_FAULT_DEVICE_LOST ? VK_ERROR_DEVICE_LOST : VK_ERROR_OUT_OF_DEVICE_MEMORY;
		rnd_log(ctx, 1, "injected fault: queue submit returns %s", rnd_vk_str(vr));
		return rnd_fail_vk(err, vr, "vkQueueSubmit (injected fault)");
	}
	VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &s->cmd};
	pthread_mutex_lock(&ctx->queue_mu);
	vr = vkQueueSubmit(ctx->queue, 1, &si, s->fence);
	pthread_mutex_unlock(&ctx->queue_mu);
	if (vr != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkQueueSubmit");
	/* No fixed timeout: a render slower than any bound is slow, not lost (a lost device
	 * answers VK_ERROR_DEVICE_LOST itself). The deadline is checked between submits. */
	for (uint32_t slices = 1;; slices++) {
		vr = vkWaitForFences(ctx->device, 1, &s->fence, VK_TRUE, WAIT_SLICE_NS);
		if (vr != VK_TIMEOUT) break;
		if (slices == 10 || slices % 60 == 0)
			rnd_log(ctx, 1, "slot %u: one submit has run for %u s (slow, not lost; waiting on)", s->index, slices);
	}
	if (vr != VK_SUCCESS) {
		/* The commands may still run: their resources stay held, and the context is failed
		 * so that it is recreated (which waits for the device first). */
		*gpu_busy = true;
		enum rnd_result r = rnd_fail_vk(err, vr, "vkWaitForFences");
		if (r != RND_ERR_DEVICE_LOST) {
			err->code = RND_ERR_DEVICE_LOST;
			r = RND_ERR_DEVICE_LOST;
		}
		return r;
	}
	vkResetFences(ctx->device, 1, &s->fence);
	return RND_OK;
}

/* ---- one command buffer at a time ---- */

struct cmd_state {
	bool open;
	bool prologue;      /* this command buffer holds the textures' upload and the white clear */
	uint32_t ts;        /* next RND_TS_* to write */
};

static enum rnd_result cmd_open(struct rnd_slot *s, struct rnd_pacer *p, struct cmd_state *st, struct rnd_error *err)
{
	VkResult vr;
	if (st->open) return RND_OK;
	if ((vr = vkResetCommandBuffer(s->cmd, 0)) != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkResetCommandBuffer");
	VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
	                               .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
	if ((vr = vkBeginCommandBuffer(s->cmd, &bi)) != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkBeginCommandBuffer");
	st->open = true;
	st->ts = 0;
	st->prologue = false;
	if (s->queries) {
		vkCmdResetQueryPool(s->cmd, s->queries, 0, RND_TS_COUNT);
		vkCmdWriteTimestamp2(s->cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, s->queries, RND_TS_START);
	}
	st->ts = RND_TS_START + 1;
	if (p->prologue) {
		record_textures(s, p->tex, p->ntex);
		if (p->env) rnd_env_record(p->ctx, s->cmd, p->env);
		p->prologue = false;
		st->prologue = true;
	}
	return RND_OK;
}

/* Writes the timestamps up to idx: a phase this submit lacks gets zero length. */
static void cmd_mark(struct rnd_slot *s, struct cmd_state *st, uint32_t idx)
{
	for (; st->ts <= idx; st->ts++)
		if (s->queries) vkCmdWriteTimestamp2(s->cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, s->queries, st->ts);
}

/* Ends, checks the deadline, submits and waits; adds the GPU time per stage. *wall_ms: the
 * submit's wall time. */
static enum rnd_result cmd_flush(struct rnd_context *ctx, struct rnd_slot *s, struct rnd_pacer *p,
                                 struct cmd_state *st, struct rnd_timings *tm, double *wall_ms, bool *gpu_busy,
                                 struct rnd_error *err)
{
	VkResult vr;
	enum rnd_result r;
	cmd_mark(s, st, RND_TS_COPY_END);
	st->open = false;
	if ((vr = vkEndCommandBuffer(s->cmd)) != VK_SUCCESS) return rnd_fail_vk(err, vr, "vkEndCommandBuffer");
	if ((r = rnd_pacer_check(p, err)) != RND_OK) return r;
	double t0 = rnd_now_ms();
	if ((r = submit_wait(ctx, s, gpu_busy, err)) != RND_OK) return r;
	double t1 = rnd_now_ms();
	p->submits++;
	if (st->prologue) s->white_ready = true;   /* its clear (recorded while false) has run */
	*wall_ms = t1 - t0;
	uint64_t ts[RND_TS_COUNT];
	if (s->queries && vkGetQueryPoolResults(ctx->device, s->queries, 0, RND_TS_COUNT, sizeof ts, ts, sizeof ts[0],
	                                        VK_QUERY_RESULT_64_BIT) == VK_SUCCESS) {
		double k = ctx->timestamp_period / 1e6;
		tm->shadow_ms += (double)(ts[RND_TS_SHADOW_END] - ts[RND_TS_START]) * k;
		tm->main_ms += (double)(ts[RND_TS_MAIN_END] - ts[RND_TS_SHADOW_END]) * k;
		tm->visibility_ms += (double)(ts[RND_TS_VIS_END] - ts[RND_TS_SHADOW_END]) * k;
		tm->readback_ms += (double)(ts[RND_TS_COPY_END] - ts[RND_TS_MAIN_END]) * k;
	} else {
		tm->main_ms += t1 - t0;
	}
	return RND_OK;
}

/* ---- one view ---- */

/* The blur temporary's contents never carry over: take it from UNDEFINED each time. */
static void moments_tmp_undefined(struct rnd_slot *s)
{
	if (s->moments_tmp.img)
		record_image_barrier(s->cmd, s->moments_tmp.img, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
		                     VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
		                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
		                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
}

/* One map estimated past half a slice, in parts of its casters' triangles, a submit each (the
 * deadline checked between): the first part sized by the estimate (est ms for the whole map, as
 * the cost model says, times the pacer's scale), the next ones by the measured time per triangle
 * (grown at most 2x a part, as the bands). Each part's wall time feeds the scale of the groups
 * after it, as a whole group's does (rnd_pacer_shadow_part_measured). */
static enum rnd_result submit_shadow_parts(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                           uint32_t v, double est, uint64_t total, struct rnd_pacer *p,
                                           struct cmd_state *st, struct rnd_timings *tm, bool *gpu_busy,
                                           struct rnd_error *err)
{
	enum rnd_result r;
	double target = p->slice_ms / 2;
	uint32_t fixed = rv->sc->shadow_part_triangles;
	double per = fixed ? fixed : fmax(1.0, floor((double)total * target / (p->shadow_scale * est)));
	for (uint64_t lo = 0; lo < total;) {
		uint64_t hi = lo + (uint64_t)per < total ? lo + (uint64_t)per : total;
		if ((r = cmd_open(s, p, st, err)) != RND_OK) return r;
		if (lo == 0) moments_tmp_undefined(s);
		record_shadow_part(ctx, s, rv, v, lo, hi, total);
		cmd_mark(s, st, RND_TS_SHADOW_END);
		double wall;
		if ((r = cmd_flush(ctx, s, p, st, tm, &wall, gpu_busy, err)) != RND_OK) return r;
		rnd_pacer_shadow_part_measured(p, st->prologue, est, hi - lo, total, wall);
		double rate = wall / (double)(hi - lo);   /* ms per triangle, measured */
		double next = rate > 0 ? target / rate : 2 * per;
		if (!fixed) per = fmax(1.0, fmin(next, 2 * per));
		lo = hi;
		p->shadow_parts++;
		p->shadow_submits++;
	}
	return RND_OK;
}

/* What a group of shadow views may be estimated at: half a slice, in estimates scaled by what
 * the last group or map part measured; until one was measured, an eighth. The estimate is the cost model's
 * for an idle machine, and a group runs whole before the deadline is checked: 32 spot maps
 * estimated at 0.4 s together went in one submit that took 11 s on a machine at load 15 (the
 * request behind it, answered at the deadline's half, missed its own). A small first group
 * costs one submit more where the estimate was right. */
static double shadow_budget(const struct rnd_pacer *p)
{
	return p->shadow_measured ? p->slice_ms / 2 : p->slice_ms / 8;
}

void rnd_pacer_shadow_measured(struct rnd_pacer *p, bool prologue, double est, double wall)
{
	if (prologue || !(est > 0)) return;
	p->shadow_scale = fmax(1.0, wall / est);
	p->shadow_measured = true;
}

void rnd_pacer_shadow_part_measured(struct rnd_pacer *p, bool prologue, double est, uint64_t part, uint64_t total,
                                    double wall)
{
	if (total) rnd_pacer_shadow_measured(p, prologue, est * (double)part / (double)total, wall);
}

static enum rnd_result submit_shadows(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                      struct rnd_pacer *p, struct cmd_state *st, struct rnd_timings *tm,
                                      bool *gpu_busy, struct rnd_error *err)
{
	enum rnd_result r;
	const struct rnd_shadow_plan *sp = rv->sp;
	bool paced = p->slice_ms > 0;
	const double *est = rv->map_ms;
	const uint64_t *tris = rv->map_tris;
	uint32_t v = 0;
	while (v < sp->view_count) {
		if (sp->view_skip[v]) { v++; continue; }
		uint32_t fixed = rv->sc->shadow_part_triangles;
		double k = p->shadow_scale;
		if (fixed ? tris[v] > fixed : paced && k * est[v] > p->slice_ms / 2 && tris[v] > 1) {
			if ((r = submit_shadow_parts(ctx, s, rv, v, est[v], tris[v], p, st, tm, gpu_busy, err)) != RND_OK)
				return r;
			v++;
			continue;
		}
		uint32_t end = v + 1;
		double sum = est[v];
		while (end < sp->view_count) {
			if (paced && k * (sum + est[end]) > shadow_budget(p)) break;
			sum += est[end];
			end++;
		}
		if ((r = cmd_open(s, p, st, err)) != RND_OK) return r;
		moments_tmp_undefined(s);
		record_shadows(ctx, s, rv, v, end);
		cmd_mark(s, st, RND_TS_SHADOW_END);
		double wall;
		if (paced) {
			if ((r = cmd_flush(ctx, s, p, st, tm, &wall, gpu_busy, err)) != RND_OK) return r;
			p->shadow_submits++;
			rnd_pacer_shadow_measured(p, st->prologue, sum, wall);
		}
		v = end;
	}
	return RND_OK;
}

enum rnd_result rnd_submit_view(struct rnd_context *ctx, struct rnd_slot *s, const struct record_view *rv,
                                struct rnd_pacer *p, struct rnd_timings *tm, bool *gpu_busy, struct rnd_error *err)
{
	enum rnd_result r;
	struct cmd_state st = {0};
	const struct rnd_scene *sc = rv->sc;
	if ((r = submit_shadows(ctx, s, rv, p, &st, tm, gpu_busy, err)) != RND_OK) goto fail;
	/* Contact shadows march against the whole view's depth: drawn once, before any band; so is
	 * the environment pass. */
	if (rv->contact) {
		if ((r = cmd_open(s, p, &st, err)) != RND_OK) goto fail;
		record_scene_depth(ctx, s, rv);
	}
	if (rv->env_pass && !rv->env_pass_reused) {
		if ((r = cmd_open(s, p, &st, err)) != RND_OK) goto fail;
		if ((r = record_env_pass(ctx, s, rv, err)) != RND_OK) goto fail;
	}

	bool split = p->slice_ms > 0 || sc->band_rows;
	double est_row = rv->row_ms, est_fixed = rv->band_ms;
	/* Down to single rows: with many soft-shadowed lights and AOVs one row of a large image
	 * can take a second on lavapipe. */
	uint32_t min_rows = 1;
	for (uint32_t y = 0; y < sc->height;) {
		uint32_t left = sc->height - y;
		uint32_t rows = !split ? left : sc->band_rows ? sc->band_rows : rnd_pacer_band_rows(p, left, min_rows, est_row, est_fixed);
		if (rows > left) rows = left;
		struct record_view band = *rv;
		band.band_y = y;
		band.band_h = rows;
		if ((r = cmd_open(s, p, &st, err)) != RND_OK) goto fail;
		cmd_mark(s, &st, RND_TS_SHADOW_END);
		if (rv->vis && (r = record_visibility(ctx, s, &band, err)) != RND_OK) goto fail;
		cmd_mark(s, &st, RND_TS_VIS_END);
		r = rv->deferred ? record_deferred_main(ctx, s, &band, err) : record_main(ctx, s, &band, err);
		if (r != RND_OK) goto fail;
		if (rv->aov_passes && (r = record_aov(ctx, s, &band, err)) != RND_OK) goto fail;
		cmd_mark(s, &st, RND_TS_MAIN_END);
		record_readback(s, &band);
		double wall;
		if ((r = cmd_flush(ctx, s, p, &st, tm, &wall, gpu_busy, err)) != RND_OK) return r;
		p->rows[0] = p->rows[1]; p->ms[0] = p->ms[1];
		p->rows[1] = rows; p->ms[1] = wall;
		p->measured++;
		y += rows;
		if (y < sc->height && (r = rnd_pacer_hopeless(p, sc->height - y, err)) != RND_OK) return r;
	}
	return RND_OK;
fail:
	if (st.open) vkEndCommandBuffer(s->cmd);
	return r;
}

void rnd_context_inject_fault(struct rnd_context *ctx, enum rnd_fault kind, uint32_t nth_submit)
{
	__atomic_store_n(&ctx->fault_kind, RND_FAULT_NONE, __ATOMIC_SEQ_CST);
	__atomic_store_n(&ctx->fault_countdown, nth_submit ? nth_submit : 1, __ATOMIC_SEQ_CST);
	__atomic_store_n(&ctx->fault_kind, (int)kind, __ATOMIC_SEQ_CST);
}
