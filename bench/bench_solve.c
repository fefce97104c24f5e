/* bench/bench_solve.c: time per driver step of mech_solve for each file at
 * four levels (positions; + velocities; + accelerations; + forces, with the
 * file's friction; the first three with the file's `outputs: forces` off,
 * which would otherwise force every level to compute everything), with the Newton
 * iterations per step and the worst closure residual that time bought.
 * Median, min and max over repeated sweeps; set-up excluded. Not a test. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "mech.h"

enum { REPS = 21 };

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void bench_level(const mech_model *m, const char *file, const char *label, int want,
                        int forces)
{
    double us[REPS];
    mech_solve_stats st = {0};
    for (int r = 0; r < REPS; r++) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.want = want;
        o.forces = forces ? 1 : -1; /* the kinematic levels without the file's forces */
        mech_table t = {0};
        mech_diag d;
        mech_diag_init(&d);
        if (mech_solve(m, &o, &t, &st, &d) != MECH_OK) {
            mech_diag_print(&d, stderr);
            mech_diag_free(&d);
            mech_table_free(&t);
            return;
        }
        mech_diag_free(&d);
        mech_table_free(&t);
        us[r] = st.seconds / st.steps * 1e6;
    }
    qsort(us, REPS, sizeof us[0], cmp);
    printf("%-24s %-6s %5d %4d/%-4d %9.3f %9.3f %9.3f %8.2f %5d %10.2e %9.3g\n", file,
           label, st.steps, st.nsolved, st.nunknowns, us[REPS / 2], us[0], us[REPS - 1],
           (double)st.iterations / st.steps, st.max_iterations, st.worst_residual, st.min_rcond);
}

/* Half a second of untimed sweeps of the first file: on this virtual
 * machine the first file timed after start-up measured up to 2x slower
 * than the same file timed again (the host ramps the CPU up). */
static void warm_up(const char *file)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    mech_summary s;
    if (mech_load_file(file, &m, &d) == MECH_OK && mech_check(m, &s, &d) == MECH_OK) {
        double t0 = bench_now();
        while (bench_now() - t0 < 0.5) {
            mech_solve_options o;
            mech_solve_options_default(&o);
            mech_table t = {0};
            mech_diag_free(&d);
            mech_diag_init(&d);
            mech_solve(m, &o, &t, NULL, &d);
            mech_table_free(&t);
        }
    }
    mech_diag_free(&d);
    mech_model_free(&m);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        warm_up(argv[1]);
    printf("time per driver step of mech_solve (median/min/max of %d sweeps, set-up excluded)\n", REPS);
    printf("%-24s %-6s %5s %9s %9s %9s %9s %8s %5s %10s %9s\n", "mechanism", "level", "steps",
           "solved", "med us", "min us", "max us", "it/step", "maxit", "worst res", "min rcond");
    for (int a = 1; a < argc; a++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_summary s;
        if (mech_load_file(argv[a], &m, &d) != MECH_OK || mech_check(m, &s, &d) != MECH_OK) {
            mech_diag_print(&d, stderr);
            mech_diag_free(&d);
            mech_model_free(&m);
            continue;
        }
        mech_diag_free(&d);
        const char *base = strrchr(argv[a], '/') ? strrchr(argv[a], '/') + 1 : argv[a];
        bench_level(m, base, "pos", MECH_WANT_POSITION, 0);
        bench_level(m, base, "vel", MECH_WANT_POSITION | MECH_WANT_VELOCITY, 0);
        bench_level(m, base, "acc", MECH_WANT_ALL, 0);
        bench_level(m, base, "forces", MECH_WANT_ALL, 1);
        mech_model_free(&m);
    }
    return 0;
}
