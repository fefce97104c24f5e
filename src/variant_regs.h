/* src/variant_regs.h: one analysis per sweep (variant_regs.c): the system
 * of the sweep's base model analysed once with the lengths and angles that
 * the varied parameters move as register leaves (SYS_REGISTERS), and each
 * variant solved through a view of that analysis with its own numbers. */
#ifndef MECH_VARIANT_REGS_H
#define MECH_VARIANT_REGS_H

#include "system.h"

/* sweep.c: an analysis built on a system made beforehand (owned by the
 * analysis from here on, also on failure; NULL: built as mech_analysis_new). */
int analysis_new_with(const mech_model *m, const mech_solve_options *o, mech_system *sys,
                      mech_analysis **out, mech_diag *d);
/* A view of `base` for model mv (the same structure, other numbers): the
 * plans are base's, shared and read only; the numbers the plans took from
 * the model (length scale, slide units, link frames' attachment points,
 * the friction's speed scale) are mv's, and the register image is a copy
 * that analysis_view_set changes. NULL when out of memory. Solve it with
 * mech_analysis_solve; free it with analysis_view_free (not
 * mech_analysis_free). */
mech_analysis *analysis_view_new(const mech_analysis *base, const mech_model *mv);
void analysis_view_set(mech_analysis *view, int var, double value);
void analysis_view_free(mech_analysis **view);
const mech_system *analysis_system(const mech_analysis *a);

/* The analysed base of a sweep, shared read only by the variants. */
typedef struct variant_base variant_base;

/* The base: model `base` (checked; owned from here on, also on failure),
 * the parameters names[0..nnames-1] that the variants change, forces as
 * mech_solve_options.forces. MECH_OK, or why not (the variants are then
 * analysed one by one). */
int vbase_new(mech_model *base, const char *const *names, int nnames, int forces,
              variant_base **out, mech_diag *d);
void vbase_free(variant_base **b);

enum { VBASE_REANALYSE = -1000 };
/* Solve the variant model mv (loaded and checked) through the base's
 * analysis into *t; VBASE_REANALYSE (nothing in t or d) when mv's
 * structure or a number the analysis folded differs from the base's, or
 * a length the base has as a leaf is exactly 0 (docs/batch.md, "One
 * analysis per sweep"); else mech_analysis_solve's status. Thread safe. */
int vbase_solve(const variant_base *b, const mech_model *mv, mech_table *t, mech_diag *d);
const mech_model *vbase_model(const variant_base *b);

#endif
