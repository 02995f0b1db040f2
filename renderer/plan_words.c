/*
 * renderer/plan_words.c — the shadow plan's decisions (plan.h, made in plan.c) in words, for the
 * render plan's `explain` (render_explain.c). Pure: static text.
 */
#include "plan.h"

/* What chose a light's map size, in words (the plan shows it). */
const char *rnd_size_rule_text(unsigned why)
{
	static const char *const text[RND_SIZE_RULE_COUNT] = {
		[RND_SIZE_ASKED] = "the light's shadow.resolution",
		[RND_SIZE_DEFAULT] = "a sun's default",
		[RND_SIZE_IMPORTANCE] = "the share of the view the light's reach covers",
		[RND_SIZE_HARD_EDGE] = "a hard light: its filter kernel within a pixel of the output",
		[RND_SIZE_CASTERS] = "the casters' box: texels finer than the default map's where the camera sees them close",
		[RND_SIZE_SEARCH] = "the casters' box: texels no finer than the PCSS blocker search reaches for their widest penumbra",
		[RND_SIZE_CAPPED] = "the server's largest shadow resolution",
		[RND_SIZE_ATLAS] = "the light's shadow.resolution, cut to what the atlas holds of its tiles alone",
	};
	return why < RND_SIZE_RULE_COUNT ? text[why] : "";
}

const char *rnd_light_plan_kind(const struct rnd_light *L, const struct rnd_light_plan *lp)
{
	if (L->shadow.dir_mode == RND_DIR_CASTERS) return "casters";
	if (L->type == RND_LIGHT_SPOT) return "spot";
	if (L->type == RND_LIGHT_POINT) return "cube";
	return lp->clipmap ? "clipmap" : lp->follows_camera ? "cascades" : "fit";
}
