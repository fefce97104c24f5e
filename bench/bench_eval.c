/* bench/bench_eval.c: cost of one evaluation of f and the Jacobian through
 * the compiled tape (the inner loop of every Newton iteration), and of the
 * velocity and acceleration right-hand sides. Prints a table; not a test. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "equations.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    printf("%-28s %5s %5s %6s %12s %12s %12s %12s\n", "mechanism", "n", "nnz", "instr",
           "f+J ns(med)", "min", "max", "vel+acc ns");
    for (int a = 1; a < argc; a++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_system *s = NULL;
        if (mech_load_file(argv[a], &m, &d) != MECH_OK || mech_system_new(m, &s, &d) != MECH_OK) {
            mech_diag_print(&d, stderr);
            mech_diag_free(&d);
            mech_model_free(&m);
            continue;
        }
        mech_diag_free(&d);
        int n = s->n;
        double *x = calloc((size_t)n, sizeof *x), *f = calloc((size_t)n, sizeof *f);
        double *J = calloc((size_t)s->nnz + 1, sizeof *J), *r = calloc((size_t)n, sizeof *r);
        enum { REPS = 15, CALLS = 200000 };
        double t[REPS], tr = 0, sink = 0;
        for (int k = 0; k < REPS; k++) {
            double t0 = now();
            for (int i = 0; i < CALLS; i++) {
                x[i % n] += 1e-9;  /* a changing state, as in Newton */
                sys_eval_position(s, x, 0.3, f, J);
                sink += f[0];
            }
            t[k] = (now() - t0) / CALLS * 1e9;
        }
        double t0 = now();
        for (int i = 0; i < CALLS; i++) {
            sys_eval_velocity_rhs(s, 1.0, r);
            sys_eval_accel_rhs(s, x, 1.0, 0.0, r);
            sink += r[0];
        }
        tr = (now() - t0) / CALLS * 1e9;
        qsort(t, REPS, sizeof t[0], cmp);
        printf("%-28s %5d %5d %6d %12.1f %12.1f %12.1f %12.1f%s\n", argv[a], n, s->nnz,
               s->tp.nins, t[REPS / 2], t[0], t[REPS - 1], tr, sink == 12345.678 ? " " : "");
        free(x);
        free(f);
        free(J);
        free(r);
        mech_system_free(&s);
        mech_model_free(&m);
    }
    return 0;
}
