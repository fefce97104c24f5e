/* bench/bench_fit.c: `mech fit` against gradient-free minimisers on the same
 * objective, bounds and starts (docs/synthesis.md, "Against a gradient-free
 * method"; issue 31). The problems are docs/synthesis.md's worked example,
 * tests/fit/fourbar.yaml with r, l, b free (bounds 15:25, 50:70, 40:60 mm),
 * its targets the file's own solution (r 20, l 60, b 50 mm) at 12 crank
 * angles 0, 30, ..., 330 deg:
 *   path      P.x, P.y (path generation with prescribed timing)
 *   function  rocker.angle (function generation)
 * each from the start 10 % off (r 22, l 55, b 53 mm) and over the bounds.
 * The methods:
 *   lmder     mech fit's own local fit (fit_lm, src/study/fit_lm.c: MINPACK
 *             with the exact Jacobian), one start, then mech fit's 16 starts
 *             (the start, then the Halton points of the bounds) one after
 *             the other on one thread;
 *   BOBYQA    NLopt's local derivative-free method from the same start;
 *   CRS2-LM, ISRES, MLSL-LDS (+BOBYQA)  NLopt's global methods over the
 *             bounds, the start as their first point.
 * Every method evaluates fit_objective / fit_eval (src/study/fit.c): the
 * file loaded at p and the targets' rows solved; a "solve" is one such
 * evaluation (for lmder a Jacobian evaluation is one too: the same sweep
 * of the rows with the sensitivities). A point where the mechanism does not
 * assemble at every target gets the objective mech fit's penalty gives.
 * Printed: solves, CPU time (one thread), best objective, the largest error of the
 * recovered parameters, and the best objective reached within 50, 200,
 * 1000 and 5000 solves. Usage: bench-fit [tests/fit/fourbar.yaml] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <nlopt.h>

#include "mech.h"
#include "base.h"
#include "study.h"
#include "cli.h"

enum { NFREE = 3, NQ = 12, MAXCOLS = 2, NBUDGET = 4, BUDGET = 5000, STARTS = 16 };

static const long budgets[NBUDGET] = {50, 200, 1000, 5000};

/* CPU time of the process, s: one thread, and a shared machine's other
 * load left out */
static double cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct trace {
    double best[NBUDGET];  /* best objective within budgets[b] solves */
    double best_all;
    double p_best[NFREE];
} trace;

static void observe(void *ctx, long nsolves, double f)
{
    trace *t = ctx;
    for (int b = 0; b < NBUDGET; b++)
        if (nsolves <= budgets[b] && f < t->best[b])
            t->best[b] = f;
    if (f < t->best_all)
        t->best_all = f;
}

typedef struct bench {
    fit_problem fp;
    const char *names[NFREE];
    char unit[NFREE][32];
    mech_mark mark[NFREE];
    const char *cols[MAXCOLS];
    char col_unit[MAXCOLS][16];
    double q[NQ], target[NQ * MAXCOLS], r[NQ * MAXCOLS];
    double truth[NFREE], start[NFREE], lo[NFREE], hi[NFREE];
    double penalty;  /* the objective where the mechanism does not assemble */
    trace tr;
} bench;

static void trace_reset(bench *b)
{
    for (int k = 0; k < NBUDGET; k++)
        b->tr.best[k] = INFINITY;
    b->tr.best_all = INFINITY;
    b->fp.nsolves = 0;
}

/* The problem: the file, its targets from its own solution. */
static int setup(bench *b, const char *file, const char *const *cols, int ncols,
                 const double *lo, const double *hi)
{
    memset(b, 0, sizeof *b);
    static const char *const names[NFREE] = {"r", "l", "b"};
    for (int k = 0; k < NFREE; k++)
        b->names[k] = names[k];
    for (int j = 0; j < ncols; j++)
        b->cols[j] = cols[j];
    fit_problem *fp = &b->fp;
    fp->path = file;
    fp->nfree = NFREE;
    fp->names = b->names;
    fp->unit = b->unit;
    fp->mark = b->mark;
    fp->ncols = ncols;
    fp->cols = b->cols;
    fp->col_unit = b->col_unit;
    mech_diag d;
    mech_diag_init(&d);
    int rc = fit_prepare(fp, b->truth, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc != MECH_OK)
        return rc;
    for (int i = 0; i < NQ; i++)
        b->q[i] = i * 30.0 * 3.14159265358979323846 / 180.0;
    fp->nq = NQ;
    fp->q = b->q;
    fp->target = b->target;  /* zeros: the residuals are the solved values */
    mech_diag_init(&d);
    rc = fit_eval(fp, b->truth, b->r, NULL, &d);
    mech_diag_free(&d);
    if (rc != MECH_OK)
        return rc;
    memcpy(b->target, b->r, sizeof b->r);
    static const double start[NFREE] = {0.022, 0.055, 0.053};
    memcpy(b->lo, lo, sizeof b->lo);
    memcpy(b->hi, hi, sizeof b->hi);
    memcpy(b->start, start, sizeof start);
    /* mech fit's penalty: each residual 1000 times the start's rms (>= 1e-3) */
    double f0;
    mech_diag_init(&d);
    rc = fit_objective(fp, b->start, b->r, &f0, &d);
    mech_diag_free(&d);
    if (rc != MECH_OK)
        return rc;
    int m = NQ * ncols;
    double rms = sqrt(f0 / m), res = 1e3 * (rms > 1e-3 ? rms : 1e-3);
    b->penalty = m * res * res;
    fp->observe = observe;
    fp->observe_ctx = &b->tr;
    return MECH_OK;
}

/* The largest error of the parameters p against the truth, mm. */
static double param_error(const bench *b, const double *p)
{
    double e = 0.0;
    for (int k = 0; k < NFREE; k++)
        e = fmax(e, fabs(p[k] - b->truth[k]) * 1e3);
    return e;
}

static void row(const bench *b, const char *method, int starts, double seconds, const double *p)
{
    char cells[NBUDGET][16];
    for (int k = 0; k < NBUDGET; k++)
        if (b->fp.nsolves < budgets[k] && k > 0 && b->fp.nsolves < budgets[k - 1])
            snprintf(cells[k], sizeof cells[k], "%s", "\"");  /* finished before */
        else
            snprintf(cells[k], sizeof cells[k], "%.2g", b->tr.best[k]);
    printf("  %-22s %6d %7ld %9.3f %11.3g %11.3g  %9s %9s %9s %9s\n", method, starts,
           b->fp.nsolves, seconds, b->tr.best_all, param_error(b, p), cells[0], cells[1],
           cells[2], cells[3]);
}

/* ---- lmder: mech fit's local fit ------------------------------------- */

static double halton(long i, int base)
{
    double f = 1.0, r = 0.0;
    for (; i > 0; i /= base) {
        f /= base;
        r += f * (double)(i % base);
    }
    return r;
}

/* mech fit's starts: the start, then Halton point i of the bounds (bases
 * 2, 3, 5; src/cli/cmd_fit.c, start_point). */
static void start_point(const bench *b, long i, double *p)
{
    static const int primes[NFREE] = {2, 3, 5};
    for (int k = 0; k < NFREE; k++)
        p[k] = i == 0 ? b->start[k] : b->lo[k] + (b->hi[k] - b->lo[k]) * halton(i, primes[k]);
}

static void run_lmder(bench *b, int starts)
{
    trace_reset(b);
    double best[NFREE], best_f = INFINITY, t0 = cpu();
    memcpy(best, b->start, sizeof best);
    for (int i = 0; i < starts; i++) {
        double p[NFREE], f;
        int info;
        start_point(b, i, p);
        if (fit_lm(&b->fp, b->lo, b->hi, p, b->r, &f, &info) == MECH_OK && f < best_f) {
            best_f = f;
            memcpy(best, p, sizeof best);
        }
    }
    char name[32];
    snprintf(name, sizeof name, "lmder (mech fit)%s", starts > 1 ? " x16" : "");
    row(b, name, starts, cpu() - t0, best);
}

/* ---- NLopt ----------------------------------------------------------- */

static double nl_objective(unsigned n, const double *x, double *grad, void *data)
{
    (void)n;
    (void)grad;  /* derivative-free methods only */
    bench *b = data;
    double f;
    mech_diag d;
    mech_diag_init(&d);
    int rc = fit_objective(&b->fp, x, b->r, &f, &d);
    mech_diag_free(&d);
    return rc == MECH_OK ? f : b->penalty;
}

static void run_nlopt(bench *b, nlopt_algorithm alg, const char *name)
{
    trace_reset(b);
    nlopt_srand(1);
    nlopt_opt o = nlopt_create(alg, NFREE), local = NULL;
    nlopt_set_lower_bounds(o, b->lo);
    nlopt_set_upper_bounds(o, b->hi);
    nlopt_set_min_objective(o, nl_objective, b);
    nlopt_set_maxeval(o, BUDGET);
    nlopt_set_xtol_rel(o, 1e-14);
    if (alg == NLOPT_G_MLSL_LDS) {
        local = nlopt_create(NLOPT_LN_BOBYQA, NFREE);
        nlopt_set_xtol_rel(local, 1e-14);
        nlopt_set_local_optimizer(o, local);
    }
    double x[NFREE], f = INFINITY, t0 = cpu();
    memcpy(x, b->start, sizeof x);
    nlopt_result res = nlopt_optimize(o, x, &f);
    double secs = cpu() - t0;
    if (res < 0)
        fprintf(stderr, "bench-fit: %s: NLopt returned %d\n", name, (int)res);
    row(b, name, 1, secs, x);
    nlopt_destroy(local);
    nlopt_destroy(o);
}

static int one(const char *file, const char *title, const char *const *cols, int ncols,
               const double *lo, const double *hi)
{
    bench *b = calloc(1, sizeof *b);
    if (!b || setup(b, file, cols, ncols, lo, hi) != MECH_OK) {
        fprintf(stderr, "bench-fit: cannot set up the problem of %s\n", file);
        free(b);
        return 1;
    }
    printf("fit %s: %s, r l b free, bounds %g:%g %g:%g %g:%g mm, start 22 55 53 mm, 12 rows\n",
           file, title, lo[0] * 1e3, hi[0] * 1e3, lo[1] * 1e3, hi[1] * 1e3, lo[2] * 1e3,
           hi[2] * 1e3);
    printf("  %-22s %6s %7s %9s %11s %11s  %9s %9s %9s %9s\n", "method", "starts", "solves",
           "cpu [s]", "objective", "error [mm]", "F@50", "F@200", "F@1000", "F@5000");
    run_lmder(b, 1);
    run_lmder(b, STARTS);
    run_nlopt(b, NLOPT_LN_BOBYQA, "BOBYQA (local)");
    run_nlopt(b, NLOPT_GN_CRS2_LM, "CRS2-LM (global)");
    run_nlopt(b, NLOPT_GN_ISRES, "ISRES (global)");
    run_nlopt(b, NLOPT_G_MLSL_LDS, "MLSL-LDS+BOBYQA");
    free(b);
    return 0;
}

int main(int argc, char **argv)
{
    const char *file = argc > 1 ? argv[1] : "tests/fit/fourbar.yaml";
    static const char *const path[] = {"P.x", "P.y"}, *const function[] = {"rocker.angle"};
    int major, minor, bugfix;
    nlopt_version(&major, &minor, &bugfix);
    printf("fit against gradient-free methods (NLopt %d.%d.%d): objective sum r^2 (SI); F@N: "
           "the best objective within N solves (\": stopped before)\n", major, minor, bugfix);
    /* docs/synthesis.md's bounds, the answer at their centre; then bounds
     * with the answer off their centre (a method that samples the centre
     * first gains nothing) */
    static const double lo[NFREE] = {0.015, 0.050, 0.040}, hi[NFREE] = {0.025, 0.070, 0.060};
    static const double lo2[NFREE] = {0.016, 0.052, 0.038}, hi2[NFREE] = {0.028, 0.076, 0.058};
    int rc = one(file, "path (P.x, P.y)", path, 2, lo, hi);
    rc |= one(file, "path (P.x, P.y)", path, 2, lo2, hi2);
    rc |= one(file, "function (rocker.angle)", function, 1, lo, hi);
    rc |= one(file, "function (rocker.angle)", function, 1, lo2, hi2);
    return rc;
}
