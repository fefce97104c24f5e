/* src/cli/cmd_fit_lm.c: one local least-squares fit of mech fit: MINPACK's
 * lmder (Levenberg-Marquardt, Debian libcminpack) on the problem fit.c
 * defines, with the exact Jacobian and the bounds by a change of variable
 * (docs/synthesis.md, "Bounds"). Linked into the mech binary and the unit
 * tests only: libmech does not depend on MINPACK. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cminpack.h>

#include "cli.h"
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
    for (int round = 0; round < (nc ? 30 : 1); round++) {
        /* tolerances: relative reduction of the sum of squares 1e-15,
         * relative step 1e-12 (lengths to about 1e-14 m on a 0.1 m
         * mechanism); gtol 0: the orthogonality test is left out (a
         * zero-residual problem ends by ftol or xtol). mode 1: MINPACK
         * scales by the Jacobian's columns. */
        *info = lmder(lm_fcn, &c, m, n, u, fvec, fjac, m, 1e-15, 1e-12, 0.0, 200 * (n + 1), diag,
                      1, 100.0, 0, &nfev, &njev, ipvt, qtf, wa, wa + nn, wa + 2 * nn,
                      wa + 3 * nn);
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
