/* src/flywheel.h: flywheel sizing from the driver torque over one cycle
 * (docs/forces.md section 8): the mean torque, the largest fluctuation of
 * the energy, and the inertia that keeps the speed within a coefficient of
 * speed fluctuation. Used by mech solve --stats and mech sweep --metric. */
#ifndef MECH_FLYWHEEL_H
#define MECH_FLYWHEEL_H

#include "internal.h"

typedef struct flywheel_figures {
    double mean_torque;  /* N*m: integral of T dq over the rows, / (q_last - q_first) */
    double fluctuation;  /* J: max - min of E(q) = integral of (T - mean) dq */
    double q_low, q_high;/* rad: where E is lowest and highest */
    double span;         /* rad: q_last - q_first */
    double speed;        /* rad/s: the driver's speed (its magnitude) */
    double inertia;      /* kg*m^2: fluctuation / (cs speed^2); NAN without cs or speed */
    int full_cycle;      /* 1: the rows cover one turn exactly, without gaps */
} flywheel_figures;

/* The figures of a solved table with a driver.torque column, crank driver
 * of model m; cs the coefficient of speed fluctuation (0: no inertia).
 * Trapezoidal rule on the rows. Returns 0, or -1 with the reason in why
 * (no torque column, a slider driver, fewer than two rows). */
int flywheel_compute(const mech_table *t, const mech_model *m, double cs, flywheel_figures *f,
                     char *why, size_t size);

/* Print the figures (mech solve --stats), with a note when the rows are
 * not one full turn. */
void flywheel_print(const flywheel_figures *f, double cs, FILE *out);

#endif
