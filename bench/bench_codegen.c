/* bench/bench_codegen.c: the time per driver step of the solver `mech
 * codegen --prefix gen` wrote for one mechanism (bench/bench_codegen.sh
 * compiles the two together). It sweeps the file's driver range like
 * `mech solve` (gen_predict, then gen_solve: positions, velocities,
 * accelerations of the file's outputs) and prints
 *
 *   steps S us/step M (min N) iterations/step I
 *
 * the median and smallest of REPS sweeps. With --once [STEPS] it runs one
 * sweep only, of STEPS intervals over the file's range (default: the
 * file's), for callgrind: --toggle-collect=bench_sweep counts its
 * instructions. Exit 1 when a step does not solve. */
#define _POSIX_C_SOURCE 200809L  /* clock_gettime */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gen.h"

enum { REPS = 31 };

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* One sweep of the file's range from gen_init; the Newton iterations, or
 * -1 when a step fails. sink collects the outputs so nothing is optimised
 * away. */
__attribute__((noinline)) static long bench_sweep(gen_state *s, int steps, double *sink)
{
    long iters = 0;
    gen_init(s);
    for (int i = 0; i <= steps; i++) {
        double q = GEN_DRIVER_FROM + (GEN_DRIVER_TO - GEN_DRIVER_FROM) * i / steps;
        gen_predict(s, q);
        if (gen_solve(s, q, GEN_DRIVER_SPEED, GEN_DRIVER_ACCEL) != GEN_OK)
            return -1;
        iters += s->iterations;
        for (int c = 0; c < GEN_NOUT; c++)
            *sink += s->out[c];
    }
    return iters;
}

int main(int argc, char **argv)
{
    static gen_state s;
    double sink = 0.0, us[REPS];
    int once = argc > 1 && strcmp(argv[1], "--once") == 0, reps = once ? 1 : REPS;
    int steps = once && argc > 2 ? atoi(argv[2]) : GEN_DRIVER_STEPS;
    long iters = 0;
    if (steps < 1)
        steps = GEN_DRIVER_STEPS;
    for (int r = 0; r < reps; r++) {
        double t0 = now();
        iters = bench_sweep(&s, steps, &sink);
        us[r] = (now() - t0) / (steps + 1) * 1e6;
        if (iters < 0) {
            fprintf(stderr, "bench-codegen: a step did not solve\n");
            return 1;
        }
    }
    qsort(us, (size_t)reps, sizeof *us, cmp_double);
    printf("steps %d us/step %.4f (min %.4f) iterations/step %.3f\n", steps + 1,
           us[reps / 2], us[0], (double)iters / (steps + 1));
    return sink != sink;  /* the outputs are used: a NaN among them fails */
}
