/*
 * server/explain_text.h — the render plan as a short text table (umbra-render --explain on a
 * terminal). Writes to f; allocates nothing it keeps.
 */
#ifndef UMBRA_SERVER_EXPLAIN_TEXT_H
#define UMBRA_SERVER_EXPLAIN_TEXT_H

#include <stdio.h>
#include "umbra/rnd.h"

void srv_explain_text(FILE *f, const struct rnd_plan *plan);

#endif
