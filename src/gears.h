/* src/gears.h: gear pairs and racks (higher pairs): their constraint rows
 * after the loop rows of the residual, the geometry of the tooth force for
 * the kinetostatics, and their description for mech check
 * (docs/format.md section "Gears", docs/forces.md section 9). */
#ifndef MECH_GEARS_H
#define MECH_GEARS_H

#include "solve.h"

/* The constraint row of gear pair i (an expression in the link angles and
 * slider displacements of s; its place among the rows: rows.h), metres:
 *   PAIR: r_a (th_a - th_arm - o_a) + sign r_b (th_b - th_arm - o_b)
 *         (sign +1 external, -1 internal)
 *   RACK: s - o_s - side r (th_p - th_arm - o_p) */
ex gears_row(mech_system *s, int i);

/* The tooth force of gear pair i at the published position of sv: its
 * pitch point p, the common tangent t there (n rotated +90 deg, n the unit
 * from link[0]'s centre through p) and the unit r that pushes link[1] away
 * from link[0]'s teeth (along n or against it). The force on link[1] is
 * F t + |F| tan(pressure angle) r (the line of action of the flank that
 * carries it), its opposite on link[0]; F is the force system's unknown.
 * sv NULL (the pattern is being built): any point and directions. */
void gears_contact(const mech_model *m, const solver *sv, int i, double *p, double *t,
                   double *r);

/* Gear pair i in words, as mech check shows it. */
void gears_describe(const mech_model *m, int i, char *buf, size_t size);

#endif
