/* bench/bench_alloc.c: does the per-step loop allocate? A counting
 * allocator (malloc and friends interposed in this program, forwarding to
 * glibc's __libc_* functions) counts the calls made by mech_solve for the
 * same mechanism at 36 and at 3600 driver steps: the set-up allocates the
 * same either way, so any difference is allocation per step. Not a test. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mech.h"

void *__libc_malloc(size_t);
void *__libc_calloc(size_t, size_t);
void *__libc_realloc(void *, size_t);
void __libc_free(void *);

static long calls;  /* malloc, calloc and realloc calls while counting */
static int counting;

void *malloc(size_t n)
{
    calls += counting;
    return __libc_malloc(n);
}
void *calloc(size_t n, size_t s)
{
    calls += counting;
    return __libc_calloc(n, s);
}
void *realloc(void *p, size_t n)
{
    calls += counting;
    return __libc_realloc(p, n);
}
void free(void *p) { __libc_free(p); }

static long count_solve(const mech_model *m, int steps, int forces, int *factorizations)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.has_range = 1;
    o.from = m->driver.values[0];
    o.to = m->driver.values[m->driver.nvalues - 1];
    o.steps = steps;
    o.forces = forces;
    mech_table t = {0};
    mech_diag d;
    mech_diag_init(&d);
    calls = 0;
    counting = 1;
    mech_solve_stats st;
    int rc = mech_solve(m, &o, &t, &st, &d);
    counting = 0;
    *factorizations = st.factorizations;
    mech_table_free(&t);
    mech_diag_free(&d);
    return rc == MECH_OK ? calls : -1;
}

int main(int argc, char **argv)
{
    printf("allocations made by mech_solve (set-up included) at 36 and 3600 steps\n");
    printf("(factorisations: dense blocks factor in place at every Newton iteration; with KLU\n"
           "a fresh klu_factor, when the old pivots degrade, allocates its factors)\n");
    printf("%-26s %-7s %10s %10s %12s %s\n", "mechanism", "level", "36 steps", "3600 steps",
           "factorisations", "allocation per step");
    int bad = 0;
    for (int a = 1; a < argc; a++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_summary s;
        if (mech_load_file(argv[a], &m, &d) != MECH_OK || mech_check(m, &s, &d) != MECH_OK) {
            mech_diag_free(&d);
            mech_model_free(&m);
            continue;
        }
        mech_diag_free(&d);
        const char *base = strrchr(argv[a], '/') ? strrchr(argv[a], '/') + 1 : argv[a];
        for (int forces = 0; forces <= 1; forces++) {
            int f1, f2;
            long c1 = count_solve(m, 36, forces, &f1), c2 = count_solve(m, 3600, forces, &f2);
            /* dense blocks allocate nothing per factorisation; an extra
               klu_factor allocates its Numeric: 16 blocks at most */
            int per = c1 < 0 || c2 < 0 || c2 - c1 > 16L * (f2 - f1);
            bad |= per;
            printf("%-26s %-7s %10ld %10ld %5d -> %-4d %s\n", base, forces ? "forces" : "kinem.",
                   c1, c2, f1, f2, c1 < 0 || c2 < 0 ? "(solve failed)" : per ? "YES" : "none");
        }
        mech_model_free(&m);
    }
    return bad;
}
