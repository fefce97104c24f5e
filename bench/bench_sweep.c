/* bench/bench_sweep.c: what a variant of `mech sweep` costs beyond its crank
 * sweep, for the conveyor with l1 varied (CPU time of one thread; not a
 * test). Four ways, each over the same variants:
 *   sweep only  mech_analysis_solve of each variant's analysis, built
 *               beforehand and not timed (the crank sweeps themselves);
 *   read each   mech_load_file_with + mech_check + mech_solve per variant (the
 *               file read and its YAML parsed each time);
 *   parsed once sweep_variant_solve with MECH_SWEEP_REANALYSE set (the YAML
 *               parsed once, each variant loaded, checked, analysed, solved);
 *   one analysis sweep_variant_solve (variant_regs.c: each variant loaded,
 *               checked and solved through the sweep's one analysis).
 * The four are interleaved and each timed as the best of 3 rounds (the
 * machine is shared). Usage: bench-sweep [FILE [PARAM [FROM_MM TO_MM]]] */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "mech.h"
#include "study.h"

enum { NVAR = 200, ROUNDS = 3, WAYS = 4 };

static double cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void texts(double from, double to, char text[NVAR][32])
{
    for (int i = 0; i < NVAR; i++)
        snprintf(text[i], 32, "%.10g mm", from + (to - from) * i / (NVAR - 1));
}

static int old_way(const char *file, const mech_override *ov, mech_table *t, mech_diag *d)
{
    mech_model *m = NULL;
    mech_summary s;
    int rc = mech_load_file_with(file, ov, 1, &m, d);
    if (rc == MECH_OK)
        rc = mech_check(m, &s, d);
    if (rc == MECH_OK) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        rc = mech_solve(m, &o, t, NULL, d);
    }
    mech_model_free(&m);
    return rc;
}

int main(int argc, char **argv)
{
    const char *file = argc > 1 ? argv[1] : "mechanisms/conveyor.yaml";
    const char *param = argc > 2 ? argv[2] : "l1";
    double from = argc > 4 ? atof(argv[3]) : 55, to = argc > 4 ? atof(argv[4]) : 65;
    static char text[NVAR][32];
    texts(from, to, text);
    mech_diag d;
    mech_diag_init(&d);
    static mech_model *m[NVAR];
    static mech_analysis *a[NVAR];
    mech_solve_options o;
    mech_solve_options_default(&o);
    for (int i = 0; i < NVAR; i++) {
        mech_override ov = {param, text[i]};
        if (mech_load_file_with(file, &ov, 1, &m[i], &d) != MECH_OK ||
            mech_analysis_new(m[i], &o, &a[i], &d) != MECH_OK) {
            mech_diag_print(&d, stderr);
            return 1;
        }
    }
    sweep_shared *sh = sweep_shared_new(file, 0);  /* the sweep's parsed file and one analysis */
    double t[WAYS] = {1e300, 1e300, 1e300, 1e300};
    int failed = 0;
    for (int round = 0; round < WAYS * ROUNDS; round++) {  /* interleaved; best of ROUNDS */
        int way = round % WAYS;
        if (way == 2)
            setenv("MECH_SWEEP_REANALYSE", "1", 1);
        else
            unsetenv("MECH_SWEEP_REANALYSE");
        double t0 = cpu();
        for (int i = 0; i < NVAR; i++) {
            mech_override ov = {param, text[i]};
            mech_table tab = {0};
            int rc = way == 0 ? mech_analysis_solve(a[i], NULL, 0, &tab, NULL, &d)
                     : way == 1 ? old_way(file, &ov, &tab, &d)
                                : sweep_variant_solve(sh, &ov, 1, &tab, NULL, &d);
            failed += rc != MECH_OK;
            mech_table_free(&tab);
        }
        double per = (cpu() - t0) / NVAR;
        t[way] = per < t[way] ? per : t[way];
    }
    printf("sweep variants: %s, %s from %g to %g mm, %d variants, one thread, CPU time "
           "(best of %d)\n", file, param, from, to, NVAR, ROUNDS);
    printf("%-34s %10s %14s %12s\n", "", "us/variant", "variants/CPU-s", "beyond sweep");
    static const char *const what[] = {"crank sweep only (analysed before)",
                                       "file read, load, check, analyse", "YAML parsed once, analysed each",
                                       "one analysis per sweep"};
    for (int way = 0; way < WAYS; way++)
        printf("%-34s %10.1f %14.1f %11.1f%%\n", what[way], t[way] * 1e6, 1 / t[way],
               100 * (t[way] - t[0]) / t[0]);
    long shared, alone;
    sweep_variant_counts(sh, &shared, &alone);
    sweep_shared_free(&sh);
    printf("(sweep_variant_solve: %ld variant runs through the one analysis, %ld analysed alone)\n",
           shared, alone);
    if (failed)
        printf("(%d variant runs failed)\n", failed);
    for (int i = 0; i < NVAR; i++) {
        mech_analysis_free(&a[i]);
        mech_model_free(&m[i]);
    }
    mech_diag_free(&d);
    return failed != 0;
}
