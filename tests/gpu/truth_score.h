/* tests/gpu — score.py's metrics of a shadow view against a stored visibility reference
 * (truth_score.c). */
#ifndef UMBRA_TRUTH_SCORE_H
#define UMBRA_TRUTH_SCORE_H

#include <stdbool.h>
#include "umbra/rnd.h"

struct truth_score {
	double rmse, iou, disagree_core, hf_cand, hf_truth;
	double missing_contact;   /* truth-shadowed px within 8 px of a geometry edge left lit */
	double false_core;        /* truth-lit px away from shadow edges made shadowed */
	long valid, shadow;
};

/* Over the valid pixels (mask less geometry edges): rmse, IoU of the shadowed regions
 * (visibility < 0.5), disagree_core / false_core away from shadow edges (2-px band),
 * missing_contact within 8 px of a geometry edge, and the penumbrae's high-frequency energy. */
void truth_score(const float *truth, const float *cand, const float *mask, const float *edge, int w, int h,
                 struct truth_score *s);
/* Replaces the first `from` in doc by `to` (a new string; NULL when absent or out of memory). */
char *truth_replaced(const char *doc, const char *from, const char *to);
/* Renders doc (a debug "shadow" view) and scores its visibility; keeps the image in *img. */
bool truth_render_scored(const char *doc, const float *truth, const float *mask, const float *edge, int w, int h,
                         struct rnd_image *img, struct truth_score *s);

#endif
