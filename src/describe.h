/* src/describe.h: a checked model's summary as labelled lines: what `mech
 * check` prints ("  LABEL      TEXT") and `mech report` shows in its
 * structure table, from one function so that the two always agree. */
#ifndef MECH_DESCRIBE_H
#define MECH_DESCRIBE_H

#include "internal.h"

typedef void (*describe_emit)(void *ctx, const char *label, const char *text);

/* emit(ctx, label, text) for each line, in order: links, joints, unknowns,
 * loops, mobility, the driver (or the sweep of time and one line per law),
 * outputs, then one line per spring, load that depends on the motion and
 * gear pair. */
void model_describe(const mech_model *m, const mech_summary *s, describe_emit emit, void *ctx);

#endif
