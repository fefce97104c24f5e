/* tests/unit/test_fit.c: mech fit's problem (src/study/fit.c) and its local
 * solver (src/study/fit_lm.c) against independent truths, on
 * tests/fit/fourbar.yaml. (1) The Jacobian fit_eval gives (from the
 * sensitivities) against central differences of the residuals themselves
 * (each a whole solve with the parameter replaced), relative step 1e-5:
 * the difference's truncation error is about h^2 |y'''| and its rounding
 * Newton's 1e-12 of 70 mm over 2 h, both below 1e-6 of the column's
 * scale; agreement asked to 1e-5 of the largest derivative of the column.
 * (2) Recovery: targets solved at known parameters, the fit from 10 %
 * off (bounded and unbounded) must give them back to 1e-9 relative.
 * (3) fit_objective and the observer (bench/bench_fit.c's objective and
 * trace) against fit_eval's residuals; fit_sweep (mech fit --plot) over
 * the file's range, whole and with gaps.
 * (4) The constraints' rows (docs/synthesis.md 4: expressions differentiated
 * on their recorded trees, the transmission from the sensitivities)
 * against central differences. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "helpers.h"
#include "base.h"
#include "study.h"

#define NQ 8
#define NC 3
#define NF 4

static const char *const names[NF] = {"r", "l", "b", "phi"};
static const char *const cols[NC] = {"P.x", "P.y", "rocker.angle"};
static char units[NF][32];
static mech_mark marks[NF];
static char col_units[NC][16];
static double qs[NQ], targets[NQ * NC];

/* The problem on the fixture, targets 0 (the residuals are then the solved
 * values themselves), p0 the file's values. */
static fit_problem problem_of(const char *path, double *p0, int timing)
{
    fit_problem fp = {0};
    fp.free_timing = timing;
    fp.path = path;
    fp.nfree = NF;
    fp.names = (const char **)names;
    fp.unit = units;
    fp.mark = marks;
    fp.nq = NQ;
    for (int i = 0; i < NQ; i++)
        qs[i] = i * 45.0 * 3.14159265358979323846 / 180.0;
    fp.q = qs;
    fp.ncols = NC;
    fp.cols = (const char **)cols;
    fp.col_unit = col_units;
    memset(targets, 0, sizeof targets);
    fp.target = targets;
    mech_diag d;
    mech_diag_init(&d);
    int rc = fit_prepare(&fp, p0, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK, "fit_prepare");
    return fp;
}

static fit_problem problem(double *p0, int timing)
{
    return problem_of("tests/fit/fourbar.yaml", p0, timing);
}

Test(fit, jacobian_against_central_differences)
{
    double p0[NF], r[NQ * NC], jac[NQ * NC * NF], rp[NQ * NC], rm[NQ * NC];
    fit_problem fp = problem(p0, 0);
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(fit_eval(&fp, p0, r, jac, &d), MECH_OK);
    for (int k = 0; k < NF; k++) {
        double p[NF];
        memcpy(p, p0, sizeof p);
        double h = 1e-5 * fabs(p0[k]);
        p[k] = p0[k] + h;
        cr_assert_eq(fit_eval(&fp, p, rp, NULL, &d), MECH_OK);
        p[k] = p0[k] - h;
        cr_assert_eq(fit_eval(&fp, p, rm, NULL, &d), MECH_OK);
        for (int j = 0; j < NC; j++) {
            double scale = 0.0;
            for (int i = 0; i < NQ; i++)
                scale = fmax(scale, fabs(jac[k * NQ * NC + i * NC + j]));
            for (int i = 0; i < NQ; i++) {
                double exact = jac[k * NQ * NC + i * NC + j];
                double fd = (rp[i * NC + j] - rm[i * NC + j]) / (2.0 * h);
                cr_expect(fabs(exact - fd) <= 1e-5 * scale + 1e-12,
                          "d(%s)/d(%s) at q = %g deg: exact %.12g, central difference %.12g",
                          cols[j], names[k], qs[i] * 180 / 3.14159265358979323846, exact, fd);
            }
        }
    }
    cr_expect_eq(fp.nsolves, 1 + 2 * NF);
    mech_diag_free(&d);
    fit_problem_free(&fp);
}

static void recover(int bounded)
{
    double p0[NF], truth[NF], r[NQ * NC];
    fit_problem fp = problem(p0, 0);
    mech_diag d;
    mech_diag_init(&d);
    memcpy(truth, p0, sizeof truth);
    cr_assert_eq(fit_eval(&fp, truth, targets, NULL, &d), MECH_OK);  /* y(truth) */
    double lo[NF], hi[NF], p[NF];
    for (int k = 0; k < NF; k++) {
        lo[k] = bounded ? 0.7 * truth[k] : -INFINITY;
        hi[k] = bounded ? 1.2 * truth[k] : INFINITY;
        p[k] = truth[k] * (k % 2 ? 0.9 : 1.1);
    }
    double obj = -1.0;
    int info = 0;
    cr_assert_eq(fit_lm(&fp, lo, hi, p, r, &obj, &info), MECH_OK);
    for (int k = 0; k < NF; k++)
        cr_expect(fabs(p[k] - truth[k]) <= 1e-9 * fabs(truth[k]), "%s: %.15g, expected %.15g",
                  names[k], p[k], truth[k]);
    cr_expect(obj >= 0.0 && obj < 1e-24, "objective %g", obj);
    cr_expect(info >= 1 && info <= 4, "lmder's info %d: converged", info);
    mech_diag_free(&d);
    fit_problem_free(&fp);
}

Test(fit, recovery_unbounded) { recover(0); }
Test(fit, recovery_bounded) { recover(1); }

/* Free timing: dr/dq_i (from the rates: dy/dq = (dy/dt) / (dq/dt)) against
 * central differences, relative step 1e-6 of a radian, on each row; the
 * other rows' residuals do not move (checked: 0 in the Jacobian). */
Test(fit, timing_jacobian_against_central_differences)
{
    enum { NV = NF + NQ };
    double p[NV], r[NQ * NC], jac[NQ * NC * NV], rp[NQ * NC], rm[NQ * NC];
    fit_problem fp = problem(p, 1);
    cr_assert_eq(fit_nvars(&fp), NV);
    for (int i = 0; i < NQ; i++)
        p[NF + i] = qs[i] + 0.1;  /* off the file's rows */
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(fit_eval(&fp, p, r, jac, &d), MECH_OK);
    for (int i = 0; i < NQ; i++) {
        double pp[NV], h = 1e-6;
        memcpy(pp, p, sizeof pp);
        pp[NF + i] = p[NF + i] + h;
        cr_assert_eq(fit_eval(&fp, pp, rp, NULL, &d), MECH_OK);
        pp[NF + i] = p[NF + i] - h;
        cr_assert_eq(fit_eval(&fp, pp, rm, NULL, &d), MECH_OK);
        for (int row = 0; row < NQ * NC; row++) {
            double exact = jac[(NF + i) * NQ * NC + row];
            double fd = (rp[row] - rm[row]) / (2.0 * h);
            cr_expect(fabs(exact - fd) <= 1e-6 * (fabs(exact) + 0.01),
                      "d(row %d)/d(q_%d): exact %.12g, central difference %.12g", row, i, exact,
                      fd);
            if (row / NC != i)
                cr_expect_eq(exact, 0.0);
        }
    }
    mech_diag_free(&d);
    fit_problem_free(&fp);
}

/* The observer sees every evaluation that assembles, with the count of
 * solves and the objective fit_objective returns (the one bench/bench_fit.c
 * gives NLopt): the same number as the sum of the squares of fit_eval's
 * residuals. */
typedef struct seen {
    long n, last_solve;
    double last;
} seen;

static void observe(void *ctx, long nsolves, double f)
{
    seen *s = ctx;
    s->n++;
    s->last_solve = nsolves;
    s->last = f;
}

Test(fit, objective_and_observer)
{
    double p0[NF], r[NQ * NC], f = -1.0;
    fit_problem fp = problem(p0, 0);
    seen s = {0, 0, 0.0};
    fp.observe = observe;
    fp.observe_ctx = &s;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(fit_objective(&fp, p0, r, &f, &d), MECH_OK);
    double sum = 0.0;
    for (int i = 0; i < NQ * NC; i++)
        sum += r[i] * r[i];
    cr_expect(sum > 0.0 && f == sum, "objective %.17g, sum of squares %.17g", f, sum);
    cr_expect_eq(s.n, 1);
    cr_expect_eq(s.last_solve, fp.nsolves);
    cr_expect(s.last == f);
    /* a point where the mechanism does not assemble: ESOLVE, infinite,
     * counted as a solve, not observed */
    double far[NF];
    memcpy(far, p0, sizeof far);
    far[0] = 0.2;  /* a crank of 200 mm on a 70 mm ground */
    long before = fp.nsolves;
    cr_expect_eq(fit_objective(&fp, far, r, &f, &d), MECH_ESOLVE);
    cr_expect(isinf(f));
    cr_expect_eq(fp.nsolves, before + 1);
    cr_expect_eq(s.n, 1);
    mech_diag_free(&d);
    fit_problem_free(&fp);
}

/* fit_sweep: the file's own range (0 to 360 deg in 36 steps) at p, with
 * the target columns; not a counted solve; a crank that cannot turn fully
 * gives ESOLVE with the rows solved and the gaps. */
Test(fit, sweep_over_the_file_range)
{
    double p0[NF];
    fit_problem fp = problem(p0, 0);
    mech_table t = {0};
    mech_diag d;
    mech_diag_init(&d);
    long before = fp.nsolves;
    cr_assert_eq(fit_sweep(&fp, p0, &t, &d), MECH_OK);
    cr_expect_eq(fp.nsolves, before);
    cr_expect_eq(t.nrows, 37);
    for (int j = 0; j < NC; j++)
        cr_expect(mech_table_column(&t, cols[j]) > 0, "column %s", cols[j]);
    mech_table_free(&t);
    double p[NF];
    memcpy(p, p0, sizeof p);
    p[0] = 0.045;  /* r 45 mm: s + l = 45 + 70 > 60 + 50, not a Grashof crank */
    cr_expect_eq(fit_sweep(&fp, p, &t, &d), MECH_ESOLVE);
    cr_expect(t.nrows > 0 && t.nrows < 37 && t.ngaps > 0, "%d rows, %d gaps", t.nrows, t.ngaps);
    mech_table_free(&t);
    mech_diag_free(&d);
    fit_problem_free(&fp);
}

/* The constraint rows of the Jacobian: the fixture with a fit: section of
 * two expressions (a ratio, and a nonlinear one of three parameters) and a
 * transmission between coupler and rocker, with and without free timing. */
static void constraint_rows(int timing)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/mech-test-fitc-%d-%d.yaml", (int)getpid(), timing);
    FILE *in = fopen("tests/fit/fourbar.yaml", "r"), *out = fopen(path, "w");
    cr_assert(in && out);
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        fwrite(buf, 1, n, out);
    fputs("fit:\n  constraints:\n    - \"l / r >= 3.2\"\n"
          "    - \"sqrt(r^2 + b^2) * sin(phi + 10 deg) <= l - 5 mm\"\n"
          "  transmission: {links: [coupler, rocker], min: 30 deg}\n", out);
    fclose(in);
    fclose(out);
    enum { NV = NF + NQ, NR = NQ * NC + 2 + NQ };
    double p[NV], r[NR], jac[NR * NV], rp[NR], rm[NR];
    fit_problem fp = problem_of(path, p, timing);
    int nv = fit_nvars(&fp);
    cr_assert_eq(fit_nres(&fp), NR);
    cr_assert_eq(fp.ncons, 2);
    for (int i = 0; timing && i < NQ; i++)
        p[NF + i] = qs[i] + 0.1;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(fit_eval(&fp, p, r, jac, &d), MECH_OK);
    cr_expect(fabs(r[NQ * NC] - (3.2 - p[1] / p[0])) <= 1e-15, "g of l / r >= 3.2: %.17g",
              r[NQ * NC]);
    for (int k = 0; k < nv; k++) {
        double pp[NV], h = k < NF ? 1e-5 * fabs(p[k]) : 1e-6;
        memcpy(pp, p, sizeof pp);
        pp[k] = p[k] + h;
        cr_assert_eq(fit_eval(&fp, pp, rp, NULL, &d), MECH_OK);
        pp[k] = p[k] - h;
        cr_assert_eq(fit_eval(&fp, pp, rm, NULL, &d), MECH_OK);
        for (int row = NQ * NC; row < NR; row++) {
            double exact = jac[k * NR + row], fd = (rp[row] - rm[row]) / (2.0 * h);
            cr_expect(fabs(exact - fd) <= 1e-6 * (fabs(exact) + 0.01 * (k < NF ? 1.0 / p[k] : 1.0)),
                      "d(constraint row %d)/d(%d): exact %.12g, central difference %.12g",
                      row - NQ * NC, k, exact, fd);
        }
    }
    mech_diag_free(&d);
    fit_problem_free(&fp);
    remove(path);
}

Test(fit, constraint_jacobian_against_central_differences) { constraint_rows(0); }
Test(fit, constraint_timing_jacobian_against_central_differences) { constraint_rows(1); }
