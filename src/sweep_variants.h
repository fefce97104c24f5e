/* src/sweep_variants.h: one variant of `mech sweep` (sweep_variants.c). */
#ifndef MECH_SWEEP_VARIANTS_H
#define MECH_SWEEP_VARIANTS_H

#include "mech.h"

/* Load `file` with the parameter replacements ov[0..nov-1], check it and
 * solve its sweep (options: the defaults, forces as mech_solve_options.
 * forces) into *t; the status and messages are those of mech_load_file_with,
 * mech_check and mech_solve. With `model` non-NULL the variant's model
 * (NULL when it could not be loaded) is handed over in *model, for the
 * metrics that need it (flywheel:CS, the driver's speed); the caller frees
 * it. Thread safe: the parsed file is shared. */
int sweep_variant_solve(const char *file, const mech_override *ov, int nov, int forces,
                        mech_table *t, mech_model **model, mech_diag *d);

/* How many variants were solved through the sweep's one analysis and how
 * many were analysed on their own (re-analysed), since the process began. */
void sweep_variant_counts(long *shared, long *alone);

#endif
