/* src/diagnose.h: why a position or a sweep failed, in a user's words:
 * assembly limits, singular positions (dead points, change points),
 * redundant constraints, branch jumps; each message names the driver
 * position and the rows' owners (rows.h) or the unknowns involved. */
#ifndef MECH_DIAGNOSE_H
#define MECH_DIAGNOSE_H

#include "continuation.h"

/* "123.4 deg" or "0.1834 mm": the driver position as users think of it. */
const char *diagnose_q_text(const mech_model *m, double q, char *buf, size_t size);
/* "179.9995 deg and 180.0005 deg": two positions with the digits that
 * tell them apart. */
const char *diagnose_q_interval(const mech_model *m, double a, double b, char *buf,
                                size_t size);
/* "driver angle" or "driver displacement". */
const char *diagnose_driver_word(const mech_model *m);
/* "A-B-C turning clockwise", "D right of C", "B above O", "slider s positive". */
const char *diagnose_branch_text(const mech_model *m, const mech_branch *b, char *buf,
                                 size_t size);
/* The row (of the system: rows.h names it) that closes worst at the
 * current iterate. */
int diagnose_worst_row(const solver *sv);

/* Row 0 could not be found at q: first is the status of the first attempt
 * (with its residual and worst row), branch the violated branch condition
 * (-1 none), attempts how many starts were tried. */
void diagnose_start(cont *c, double q, step_status first, double resid, int row, int branch,
                    int attempts);
/* The owners of the rows that depend at the current (nearly singular)
 * factors, e.g. "loop 1 (A-B-C-D-A), gear pair 'g'"; "" when unknown (a
 * large system). */
void diagnose_dependent_rows(const solver *sv, char *buf, size_t size);
/* A singular position at q: which unknowns are free, which rows depend. */
void diagnose_singular(cont *c, double q);
/* Redundant constraints at row 0: which equations the others imply. */
void diagnose_redundant(cont *c, double q);
/* The sweep could not reach the row at q_row (row spacing hrow): the
 * assembly interval(s), the singular position, or the branch jump. */
void diagnose_failure(cont *c, double q_row, double hrow);

#endif
