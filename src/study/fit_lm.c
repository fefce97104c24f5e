/* src/study/fit_lm.c: the local least-squares fits of mech fit and
 * mech_fit: MINPACK's lmder (Levenberg-Marquardt, Debian libcminpack) on
 * the problem fit.c defines, with the exact Jacobian, the bounds by a
 * change of variable and the constraints by a shifted penalty
 * (docs/synthesis.md sections 3 and 4); and the starts, run on worker
 * threads. libmech.so links MINPACK (shared); a static link pulls this
 * object, and needs -lcminpack, only when it calls mech_fit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cminpack.h>

#include "base.h"
#include "study.h"

typedef struct lm_ctx {
    fit_problem *fp;
    const double *lo, *hi;  /* [n] bounds, SI; an infinite one: no bound */
    double *p;              /* [n] the parameters at the point asked for */
    double *r, *jac;        /* [m], [m n] workspace of the Jacobian's call */
    double penalty;         /* each residual where the mechanism does not assemble */
    double worst;           /* the largest sum of squares evaluated (the penalty stays above) */
    int error;              /* MECH_ENOMEM met */
    int nt, nc;             /* target residuals, constraint values */
    double *shift, *wcon;   /* [nc] the constraints' shifts and weights */
} lm_ctx;

static int bounded(const lm_ctx *c, int k)
{
    return isfinite(c->lo[k]) && isfinite(c->hi[k]);
}

/* p = lo + (hi - lo) (1 + sin u) / 2 for a bounded parameter, else p = u. */
static void to_params(const lm_ctx *c, int n, const double *u, double *p)
{
    for (int k = 0; k < n; k++)
        p[k] = bounded(c, k) ? c->lo[k] + (c->hi[k] - c->lo[k]) * 0.5 * (1.0 + sin(u[k])) : u[k];
}

/* dp/du */
static double slope(const lm_ctx *c, int k, double u)
{
    return bounded(c, k) ? (c->hi[k] - c->lo[k]) * 0.5 * cos(u) : 1.0;
}

/* u of p: asin(2 (p - lo)/(hi - lo) - 1), clamped into the bounds. */
static void to_free(const lm_ctx *c, int n, const double *p, double *u)
{
    for (int k = 0; k < n; k++) {
        if (!bounded(c, k)) {
            u[k] = p[k];
            continue;
        }
        double s = 2.0 * (p[k] - c->lo[k]) / (c->hi[k] - c->lo[k]) - 1.0;
        u[k] = asin(s < -1.0 ? -1.0 : s > 1.0 ? 1.0 : s);
    }
}

static double sum_squares(const double *r, int m)
{
    double s = 0.0;
    for (int i = 0; i < m; i++)
        s += r[i] * r[i];
    return s;
}

/* MINPACK's callback: iflag 1 the residuals, 2 the Jacobian (by u). A
 * trial point where the mechanism does not assemble gets residuals so large
 * that lmder rejects the step and shortens it. */
static int lm_fcn(void *vp, int m, int n, const double *u, double *fvec, double *fjac, int ldfjac,
                  int iflag)
{
    lm_ctx *c = vp;
    mech_diag d;
    mech_diag_init(&d);
    to_params(c, n, u, c->p);
    int rc = MECH_OK;
    if (iflag == 1) {
        rc = fit_eval(c->fp, c->p, c->r, NULL, &d);
        if (rc == MECH_ESOLVE) {
            /* above every sum of squares seen: the constraints' penalties
             * may have raised it past the start's */
            double e = sqrt(10.0 * c->worst / m);
            for (int i = 0; i < m; i++)
                fvec[i] = c->penalty > e ? c->penalty : e;
            rc = MECH_OK;
        } else if (rc == MECH_OK) {
            memcpy(fvec, c->r, (size_t)c->nt * sizeof *fvec);
            for (int j = 0; j < c->nc; j++) {  /* w max(0, g + shift) */
                double g = c->r[c->nt + j] + c->shift[j];
                fvec[c->nt + j] = g > 0.0 ? c->wcon[j] * g : 0.0;
            }
            double ss = sum_squares(fvec, m);
            if (ss > c->worst)
                c->worst = ss;
        }
    } else if (iflag == 2) {
        rc = fit_eval(c->fp, c->p, c->r, c->jac, &d);
        for (int k = 0; rc == MECH_OK && k < n; k++) {
            double s = slope(c, k, u[k]);
            for (int i = 0; i < m; i++) {
                double x = c->jac[(size_t)k * m + i] * s;
                if (i >= c->nt)  /* a constraint's row: the penalty's derivative */
                    x = c->r[i] + c->shift[i - c->nt] > 0.0 ? c->wcon[i - c->nt] * x : 0.0;
                fjac[(size_t)k * (size_t)ldfjac + (size_t)i] = x;
            }
        }
    }
    mech_diag_free(&d);
    if (rc == MECH_ENOMEM)
        c->error = rc;
    return rc == MECH_OK ? 0 : -1;
}


int fit_lm(fit_problem *fp, const double *lo, const double *hi, double *p, double *r,
           double *objective, int *info)
{
    int n = fit_nvars(fp), m = fit_nres(fp), nt = fp->nq * fp->ncols, nc = fit_ncons(fp);
    size_t nn = (size_t)n, mm = (size_t)m;
    double *u = xcalloc(nn, sizeof *u), *fvec = xcalloc(mm, sizeof *fvec);
    double *fjac = xcalloc(mm * nn, sizeof *fjac), *diag = xcalloc(nn, sizeof *diag);
    double *qtf = xcalloc(nn, sizeof *qtf), *wa = xcalloc(3 * nn + mm, sizeof *wa);
    double *pw = xcalloc(nn, sizeof *pw), *jac = xcalloc(mm * nn, sizeof *jac);
    int *ipvt = xcalloc(nn, sizeof *ipvt);
    double *shift = xcalloc((size_t)nc + 1, sizeof *shift);
    double *wcon = xcalloc((size_t)nc + 1, sizeof *wcon);
    int rc = MECH_OK, nfev = 0, njev = 0;
    mech_diag d;
    mech_diag_init(&d);
    if (!u || !fvec || !fjac || !diag || !qtf || !wa || !pw || !jac || !ipvt || !shift || !wcon) {
        rc = MECH_ENOMEM;
        goto done;
    }
    /* the start must assemble at every target: else it is rejected */
    rc = fit_eval(fp, p, r, NULL, &d);
    if (rc != MECH_OK)
        goto done;
    lm_ctx c = {fp, lo, hi, pw, r, jac, 0.0, 0.0, MECH_OK, nt, nc, shift, wcon};
    double rms = sqrt(sum_squares(r, nt) / (nt ? nt : 1));
    c.penalty = 1e3 * (rms > 1e-3 ? rms : 1e-3);
    /* the constraints steer: each g <= 0 adds the residual w max(0, g + s),
     * a shifted quadratic penalty (the method of multipliers, Nocedal and
     * Wright, "Numerical Optimization", 2nd ed., 17.4): after each lmder
     * run the shift becomes max(0, s + g), which moves the minimum onto
     * the boundary g = 0 of an active constraint without the weight
     * growing. w: a violation of 1e-3 of the constraint's size weighs as
     * much as the start's residuals. */
    double f0 = sqrt(sum_squares(r, nt));
    for (int j = 0; j < nc; j++) {
        double size = j < fp->ncons && fp->con_scale[j] > 1e-300 ? fp->con_scale[j] : 1.0;
        wcon[j] = (f0 > 1e-6 ? f0 : 1e-6) / (1e-3 * size);
    }
    to_free(&c, n, p, u);
    /* one budget of evaluations for the start, whatever the rounds: with
     * free timing n is large (60 targets: 69 unknowns) and 30 rounds of
     * 200 (n + 1) each ran for hours */
    int budget = 200 * (n + 1), used = 0;
    for (int round = 0; round < (nc ? 30 : 1) && used < budget; round++) {
        /* tolerances: relative reduction of the sum of squares 1e-15,
         * relative step 1e-12 (lengths to about 1e-14 m on a 0.1 m
         * mechanism); gtol 0: the orthogonality test is left out (a
         * zero-residual problem ends by ftol or xtol). mode 1: MINPACK
         * scales by the Jacobian's columns. */
        *info = lmder(lm_fcn, &c, m, n, u, fvec, fjac, m, 1e-15, 1e-12, 0.0, budget - used, diag,
                      1, 100.0, 0, &nfev, &njev, ipvt, qtf, wa, wa + nn, wa + 2 * nn,
                      wa + 3 * nn);
        used += nfev;
        if (c.error != MECH_OK) {
            rc = c.error;
            goto done;
        }
        if (!nc)
            break;
        to_params(&c, n, u, p);
        if (fit_eval(fp, p, r, NULL, &d) != MECH_OK)
            break;
        /* on: until each constraint holds to 1/100 of the tolerance the
         * result is accepted at */
        int inside = 1;
        for (int j = 0; j < nc; j++)
            inside &= r[nt + j] <= 1e-2 * fit_con_tolerance(fp, j);
        if (inside)
            break;
        int moved = 0;
        for (int j = 0; j < nc; j++) {
            double s = shift[j] + r[nt + j];
            s = s > 0.0 ? s : 0.0;
            moved |= s != shift[j];
            shift[j] = s;
        }
        if (!moved)
            break;
    }
    to_params(&c, n, u, p);
    /* the result checked again: it assembles at every target, in bounds,
     * and meets every constraint (else it is rejected: info -2) */
    rc = fit_eval(fp, p, r, NULL, &d);
    if (rc == MECH_OK && fit_feasible(fp, r) != MECH_OK) {
        rc = MECH_ESOLVE;
        *info = -2;
    }
    if (rc == MECH_OK)
        *objective = sum_squares(r, nt);
done:
    mech_diag_free(&d);
    free(u);
    free(fvec);
    free(fjac);
    free(diag);
    free(qtf);
    free(wa);
    free(pw);
    free(jac);
    free(ipvt);
    free(shift);
    free(wcon);
    return rc;
}

/* ---- the starts ------------------------------------------------------ */

/* The radical inverse of i in base b: the Halton sequence's coordinate. */
static double halton(long i, int b)
{
    double f = 1.0, r = 0.0;
    for (; i > 0; i /= b) {
        f /= b;
        r += f * (double)(i % b);
    }
    return r;
}

static const int primes[FIT_MAX_FREE] = {2,  3,  5,  7,  11, 13, 17, 19, 23, 29, 31,
                                         37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79,
                                         83, 89, 97, 101, 103, 107, 109, 113, 127, 131};

typedef struct fit_runs {
    const fit_problem *fp;
    const double *lo, *hi, *p0;
    int whole_range;
    int n;                /* the starts */
    fit_start *st;
} fit_runs;

/* Tries for a start that assembles at every target (run_start). */
enum { START_TRIES = 64 };

/* Start i: the file's values (i = 0), else the Halton point i of the
 * bounds (an unbounded parameter keeps the file's value), with a seed
 * shifted in each coordinate by a random fraction, modulo 1 (a
 * Cranley-Patterson rotation: still spread evenly, another set for each
 * seed); with free timing the targets' driver positions. */
static void start_point(const fit_runs *runs, long i, double *p)
{
    const fit_problem *fp = runs->fp;
    for (int k = 0; k < fp->nfree; k++) {
        int b = isfinite(runs->lo[k]) && isfinite(runs->hi[k]);
        double u = halton(i, primes[k]);
        if (fp->seed)
            u = fmod(u + sweep_random_unit((uint64_t)fp->seed, 0, k), 1.0);
        p[k] = i == 0 || !b ? runs->p0[k] : runs->lo[k] + (runs->hi[k] - runs->lo[k]) * u;
    }
    for (int j = 0; fp->free_timing && j < fp->nq; j++)
        p[fp->nfree + j] = fp->q[j];
}

static void run_start(void *ctx, long i)
{
    fit_runs *runs = ctx;
    fit_start *st = &runs->st[i];
    fit_problem fp = *runs->fp;  /* this thread's: its own count of solves */
    fp.nsolves = 0;
    double *r = xcalloc((size_t)fit_nres(&fp), sizeof *r);
    /* a start must assemble at every target (fit_lm rejects it otherwise):
     * one that does not is replaced by the next point of this start's own
     * subsequence of the Halton points, i + n, i + 2n, ... (disjoint from
     * the other starts', whatever the threads), up to START_TRIES; each
     * try is a solve */
    start_point(runs, i, st->p);
    for (long k = 1; r && k < START_TRIES; k++) {
        mech_diag d;
        mech_diag_init(&d);
        int ok = fit_eval(&fp, st->p, r, NULL, &d) == MECH_OK;
        mech_diag_free(&d);
        if (ok)
            break;
        start_point(runs, i + k * runs->n, st->p);
    }
    st->objective = INFINITY;
    st->info = 0;
    st->rc = r ? fit_lm(&fp, runs->lo, runs->hi, st->p, r, &st->objective, &st->info)
               : MECH_ENOMEM;
    if (st->rc == MECH_OK && runs->whole_range) {
        mech_diag d;
        mech_diag_init(&d);
        st->rc = fit_check_range(&fp, st->p, &d);  /* a violated constraint: rejected */
        mech_diag_free(&d);
    }
    if (st->rc != MECH_OK)
        st->objective = INFINITY;
    st->solves = fp.nsolves;
    free(r);
}

static int by_objective(const void *a, const void *b)
{
    const fit_start *x = a, *y = b;
    return (x->objective > y->objective) - (x->objective < y->objective);
}

int fit_run_starts(const fit_problem *fp, const double *lo, const double *hi, const double *p0,
                   int whole_range, int n, int jobs, fit_start *st)
{
    if (fit_nvars(fp) > FIT_MAX_VARS || fp->nfree > FIT_MAX_FREE)
        return MECH_EINPUT;
    fit_runs runs = {fp, lo, hi, p0, whole_range, n, st};
    parallel_run(n, jobs > 0 ? jobs : parallel_default_jobs(), run_start, &runs);
    for (int i = 0; i < n; i++)
        if (st[i].rc != MECH_OK && st[i].rc != MECH_ESOLVE)
            return st[i].rc;
    qsort(st, (size_t)n, sizeof *st, by_objective);
    return MECH_OK;
}
