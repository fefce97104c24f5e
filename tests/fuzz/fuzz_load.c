/* tests/fuzz/fuzz_load.c: libFuzzer target for the loader and what follows
 * it on a file that loads: the structure check, the equation system (loops.c,
 * system.c, expr.c, tape.c) and its printing, and, for small mechanisms, a
 * short solve.
 *
 * Built and run by tests/fuzz/run.sh (clang -fsanitize=fuzzer,address,undefined).
 * Every allocation is freed: LeakSanitizer reports any leak as a crash. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "mech.h"

enum {
    SOLVE_MAX_VALUES = 50,    /* driver positions: keeps one input well under a second */
    SOLVE_MAX_UNKNOWNS = 60,
};

/* Solve a small mechanism with every output, forces included, so that
 * solve.c, sweep.c, kinematics.c and forces.c see fuzzed models too. */
static void try_solve(const mech_model *m, const mech_system *s)
{
    if (m->driver.nvalues > SOLVE_MAX_VALUES || mech_system_size(s) > SOLVE_MAX_UNKNOWNS)
        return;
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.max_iter = 20;
    o.forces = 1;
    o.friction = MECH_FRICTION_BOTH;
    o.diagnostics = 1;
    mech_table t = {0};
    mech_diag d;
    mech_diag_init(&d);
    mech_solve(m, &o, &t, NULL, &d);
    mech_table_free(&t);
    mech_diag_free(&d);
}

/* `mech equations` in both formats (names of any length and characters
 * reach print.c's escaping), to a sink. */
static void print_equations(const mech_system *s)
{
    static FILE *sink;
    if (!sink)
        sink = fopen("/dev/null", "w");
    if (!sink)
        return;
    mech_system_print(s, MECH_FORMAT_TEXT, sink);
    mech_system_print(s, MECH_FORMAT_LATEX, sink);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    if (mech_load_string((const char *)data, size, "fuzz.yaml", &m, &d) == MECH_OK) {
        mech_summary sum;
        if (mech_check(m, &sum, &d) == MECH_OK) {
            mech_system *s = NULL;
            if (mech_system_new(m, &s, &d) == MECH_OK) {
                print_equations(s);
                try_solve(m, s);
            }
            mech_system_free(&s);
        }
    }
    mech_model_free(&m);
    mech_diag_free(&d);
    return 0;
}
