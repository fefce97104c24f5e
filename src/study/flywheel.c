/* src/study/flywheel.c: flywheel sizing from the driver torque T(q) over one
 * cycle (docs/forces.md section 8), on the rows of a solved table:
 *   mean torque   Tm = integral T dq / (q_n - q_0)
 *   energy        E(q) = integral from q_0 to q of (T - Tm) dq
 *   fluctuation   dE = max E - min E (the largest energy fluctuation)
 *   inertia       I = dE / (Cs w^2), Cs the coefficient of speed
 *                 fluctuation (w_max - w_min) / w_mean, w the driver speed
 * Integrals by the trapezoidal rule on the rows (error O(h^2)). */
#include <math.h>
#include <string.h>

#include "study.h"

static const double TWO_PI = 6.28318530717958647692;
static const double DEG = 57.295779513082320877;

int flywheel_compute(const mech_table *t, const mech_model *m, double cs, flywheel_figures *f,
                     char *why, size_t size)
{
    memset(f, 0, sizeof *f);
    int cq = mech_table_column(t, "q"), ct = mech_table_column(t, "driver.torque");
    if (m->driver.kind == MECH_DRIVE_TIME)
        return snprintf(why, size, "the drivers are laws of time: a flywheel needs one crank "
                        "swept through its angle ('driver:')"), -1;
    if (m->driver.kind != MECH_DRIVE_ANGLE)
        return snprintf(why, size, "the driver is a slider: a flywheel needs a crank"), -1;
    if (cq < 0 || ct < 0)
        return snprintf(why, size, "no driver torque (the force analysis: --forces)"), -1;
    if (t->nrows < 2)
        return snprintf(why, size, "fewer than two rows solved"), -1;
    int n = t->nrows;
    double q0 = mech_table_get(t, 0, cq), work = 0.0;
    f->span = mech_table_get(t, n - 1, cq) - q0;
    for (int i = 1; i < n; i++)  /* integral of T dq */
        work += 0.5 * (mech_table_get(t, i, ct) + mech_table_get(t, i - 1, ct)) *
                (mech_table_get(t, i, cq) - mech_table_get(t, i - 1, cq));
    f->mean_torque = f->span != 0.0 ? work / f->span : 0.0;
    double e = 0.0, lo = 0.0, hi = 0.0;
    f->q_low = f->q_high = q0;
    for (int i = 1; i < n; i++) {  /* E(q_i), trapezoidal */
        double dq = mech_table_get(t, i, cq) - mech_table_get(t, i - 1, cq);
        e += (0.5 * (mech_table_get(t, i, ct) + mech_table_get(t, i - 1, ct)) - f->mean_torque) * dq;
        if (e < lo)
            lo = e, f->q_low = mech_table_get(t, i, cq);
        if (e > hi)
            hi = e, f->q_high = mech_table_get(t, i, cq);
    }
    f->fluctuation = hi - lo;
    f->speed = fabs(m->driver.speed);
    f->inertia = cs > 0.0 && f->speed > 0.0 ? f->fluctuation / (cs * f->speed * f->speed) : NAN;
    f->full_cycle = t->ngaps == 0 && fabs(fabs(f->span) - TWO_PI) <= 1e-9 * TWO_PI;
    return 0;
}

void flywheel_print(const flywheel_figures *f, double cs, FILE *out)
{
    fprintf(out, "  flywheel           mean driver torque %.6g N*m over %.6g deg%s\n",
            f->mean_torque, fabs(f->span) * DEG,
            f->full_cycle ? " (one turn)" : ": NOT one full turn without gaps, so these are not "
                                            "a cycle's figures (sweep 0 to 360 deg)");
    fprintf(out, "                     energy fluctuation %.6g J (energy lowest at q = %.6g deg, "
            "highest at %.6g deg)\n", f->fluctuation, f->q_low * DEG, f->q_high * DEG);
    if (cs > 0.0 && f->speed > 0.0)
        fprintf(out, "                     inertia %.6g kg*m^2 for a speed fluctuation of %g at "
                "%.6g rad/s\n", f->inertia, cs, f->speed);
    else if (cs > 0.0)
        fprintf(out, "                     no inertia: the driver speed is 0\n");
    else
        fprintf(out, "                     (--speed-fluctuation CS gives the flywheel inertia)\n");
}
