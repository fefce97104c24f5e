/* src/runtime/rt_newton.h: Newton's method on the loop equations at one driver
 * position, with damping, the stop rule and its rounding floor
 * (docs/solver.md section 2). Part of the runtime that libmech (solve.c)
 * and the C that `mech codegen` writes share (docs/codegen.md): self-
 * contained, the C library only. The caller gives the residual, the
 * factorisation, the solve and the condition as functions of its own
 * (rt_newton_ops), its vectors and its tolerances. */
#ifndef MECH_RT_NEWTON_H
#define MECH_RT_NEWTON_H

#include <float.h>
#include <math.h>
#include <string.h>

#include "rt_blocklu.h"

/* What rt_newton returns. */
enum {
    RT_NEWTON_CONVERGED,   /* x solves f(x) = 0 */
    RT_NEWTON_DIVERGED,    /* no convergence in max_iter iterations, or a value not finite */
    RT_NEWTON_SINGULAR     /* a zero pivot, or converged where rcond < min_rcond */
};

/* A Newton step longer than this (rad, or units for slides) is shortened:
 * beyond it the linearisation says little. */
#define RT_NEWTON_MAX_STEP 1.0

/* |v|inf; a NaN entry makes it NaN (fmax would drop it). */
static inline double rt_norm_inf(const double *v, int n)
{
    double r = 0.0;
    for (int i = 0; i < n; i++) {
        double a = fabs(v[i]);
        r = a > r || a != a ? a : r;
    }
    return r;
}

/* Size of a change dx of the unknowns, max |dx_i| / unit_i: angles in rad
 * (unit 1: exact), slides in units of the largest length. */
static inline double rt_step_size(const double *dx, const double *unit, int n)
{
    double r = 0.0;
    for (int i = 0; i < n; i++) {
        double v = fabs(dx[i]) / unit[i];
        r = v > r || v != v ? v : r;
    }
    return r;
}

/* The caller's system, ctx its state. */
typedef struct rt_newton_ops {
    /* f = f(x) (nr values), the Jacobian kept for factor; returns |f|inf */
    double (*evaluate)(void *ctx, const double *x, double *f);
    /* factor the Jacobian of the last evaluation: 0, or -1 (a zero pivot,
       a value that is not finite) */
    int (*factor)(void *ctx);
    /* after each factorisation: the whole Jacobian's reciprocal condition
       Newton's rounding floor uses, the last position's (computed now when
       there is none) */
    double (*rcond_whole)(void *ctx);
    /* dx = J^-1 b (least squares: J^+ b) with the factors */
    void (*solve)(void *ctx, const double *b, double *dx);
    /* the condition at the converged position: the worst block's rcond */
    double (*rcond_at_solution)(void *ctx);
} rt_newton_ops;

/* The tolerances and sizes (fixed for a mechanism). */
typedef struct rt_newton_par {
    int nx, nr;          /* unknowns, residuals (nr > nx: least squares) */
    const double *unit;  /* [nx] rt_step_size's units */
    double tol;          /* converged when the step is below tol / 100 ... */
    double ftol;         /* ... and |f|inf <= ftol (m) */
    double min_rcond;    /* singular below this reciprocal condition */
    int max_iter;        /* iterations before giving up */
    int max_polish;      /* least squares: corrections at rounding level (0: square) */
} rt_newton_par;

/* The caller's vectors, read and written in place. */
typedef struct rt_newton_vec {
    double *x;           /* [nx] the guess in; the solution, or the last iterate, out */
    double *f, *ft;      /* [nr] f(x), f at the trial point */
    double *dx, *xt;     /* [nx] the correction, the trial point */
} rt_newton_vec;

/* Newton from v->x: converged when |f|inf <= ftol and the correction is
 * below tol/100, or below its rounding floor eps / rcond_whole, or no
 * longer shrinking (the floor of an ill-conditioned position); damped by
 * halving while the residual grows. The last correction below the bound
 * is applied (its error is then of the order of its square), but the
 * factors, and so the rates, stay those of x before it: less than tol/100
 * away. *residual (|f|inf, at convergence or at max_iter) and *iterations
 * as the solve went; returns RT_NEWTON_*. */
static inline int rt_newton(const rt_newton_ops *ops, void *ctx, const rt_newton_par *par,
                            const rt_newton_vec *v, double *residual, int *iterations)
{
    int nx = par->nx, polish = 0;
    *iterations = 0;
    double r = ops->evaluate(ctx, v->x, v->f), prev_step = HUGE_VAL, xtol = 1e-2 * par->tol;
    for (int it = 0;; it++) {
        if (!isfinite(r))
            return RT_NEWTON_DIVERGED;
        if (ops->factor(ctx) < 0)
            return RT_NEWTON_SINGULAR;
        double rw = ops->rcond_whole(ctx);
        if (it == 0)
            xtol = fmax(1e-2 * par->tol, DBL_EPSILON / fmax(rw, 1e-300));
        ops->solve(ctx, v->f, v->dx);
        double step = rt_step_size(v->dx, par->unit, nx);
        if (r <= par->ftol && (step <= xtol || step >= 0.9 * prev_step)) {
            /* least squares: the rates' solve amplifies what the last
               correction leaves in the factors (the augmented matrix's
               condition is about J's squared), so correct and refactor until
               the correction is at rounding */
            if (polish < par->max_polish && step <= xtol && step > 16 * DBL_EPSILON) {
                polish++;
                for (int i = 0; i < nx; i++)
                    v->x[i] -= v->dx[i];
                r = ops->evaluate(ctx, v->x, v->f);
                prev_step = step;
                *iterations = it + 1;
                continue;
            }
            *residual = r;
            *iterations = it;
            if (step <= xtol)  /* a real (not noise) correction: take it */
                for (int i = 0; i < nx; i++)
                    v->x[i] -= v->dx[i];
            return ops->rcond_at_solution(ctx) < par->min_rcond ? RT_NEWTON_SINGULAR
                                                                 : RT_NEWTON_CONVERGED;
        }
        if (it == par->max_iter) {
            *residual = r;
            *iterations = it;
            return RT_NEWTON_DIVERGED;
        }
        double lambda = step > RT_NEWTON_MAX_STEP ? RT_NEWTON_MAX_STEP / step : 1.0, rt;
        for (;;) {  /* damping: halve the step while the residual grows */
            for (int i = 0; i < nx; i++)
                v->xt[i] = v->x[i] - lambda * v->dx[i];
            rt = ops->evaluate(ctx, v->xt, v->ft);
            if (rt <= r || rt <= par->ftol || lambda < 1.0 / 1024)
                break;
            lambda *= 0.5;
        }
        memcpy(v->x, v->xt, (size_t)nx * sizeof *v->x);
        memcpy(v->f, v->ft, (size_t)par->nr * sizeof *v->f);
        r = rt;
        prev_step = lambda == 1.0 ? step : HUGE_VAL;
        *iterations = it + 1;
    }
}

#endif
