/* src/solve/linsys.c: dense blocks or KLU behind one interface (linsys.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "solve.h"

static int klu_plan(linsys_plan *lp)
{
    klu_defaults(&lp->common);
    /* Rows are lengths or forces already, and callers equilibrate the
       columns; KLU's row scaling would blow a row that is small for a
       geometric reason (a dead centre) up to 1 and hide the singularity
       from the condition estimate. */
    lp->common.scale = 0;
    /* Diagonal preference only within a factor 10 of the largest pivot
       candidate (KLU's default 1e-3 allows growth of 1e3 per column). */
    lp->common.tol = 0.1;
    unsigned char *seen = xcalloc((size_t)lp->n + 1, 1);
    if (!seen)
        return -1;
    lp->sym = klu_analyze(lp->n, lp->Ap, lp->Ai, &lp->common);
    if (lp->sym)
        lp->q_parity = permutation_parity(lp->sym->Q, lp->n, seen);
    free(seen);
    return lp->sym ? 0 : -1;
}

int linsys_plan_init(linsys_plan *lp, int n, int *Ap, int *Ai, int method)
{
    memset(lp, 0, sizeof *lp);
    lp->n = n;
    lp->Ap = Ap;
    lp->Ai = Ai;
    if (method != MECH_LINEAR_KLU) {
        int rc = blocklu_analyze(&lp->blu, n, Ap, Ai, BLOCKLU_MAX_BLOCK);
        if (rc != 2)
            return rc;
        blocklu_plan_free(&lp->blu);  /* a block too large for dense LU */
    }
    lp->use_klu = 1;
    return klu_plan(lp);
}

void linsys_plan_free(linsys_plan *lp)
{
    if (lp->sym)
        klu_free_symbolic(&lp->sym, &lp->common);
    blocklu_plan_free(&lp->blu);
    memset(lp, 0, sizeof *lp);
}

int linsys_init(linsys *ls, const linsys_plan *lp)
{
    memset(ls, 0, sizeof *ls);
    ls->plan = lp;
    ls->common = lp->common;
    if (!lp->use_klu)
        return blocklu_init(&ls->blu, &lp->blu);
    ls->seen = xcalloc((size_t)lp->n + 1, 1);
    return ls->seen ? 0 : -1;
}

void linsys_free(linsys *ls)
{
    if (ls->num)
        klu_free_numeric(&ls->num, &ls->common);
    blocklu_free(&ls->blu);
    free(ls->seen);
    memset(ls, 0, sizeof *ls);
}

static int klu_fresh_factor(linsys *ls, double *Ax)
{
    const linsys_plan *lp = ls->plan;
    if (ls->num)
        klu_free_numeric(&ls->num, &ls->common);
    ls->num = klu_factor(lp->Ap, lp->Ai, Ax, lp->sym, &ls->common);
    ls->factorizations++;
    if (!ls->num)
        return -1;
    klu_rcond(lp->sym, ls->num, &ls->common);
    ls->pivot_ratio_factor = ls->common.rcond;
    /* refactoring keeps this pivot order: its parity holds until the next */
    ls->perm_parity = permutation_parity(ls->num->Pnum, lp->n, ls->seen) ^ lp->q_parity;
    return 0;
}

/* Refactor with the old pivots while they hold; pivot afresh when the
 * pivot ratio (klu_rcond) has fallen below 1e-3 of its value at the last
 * full factorisation: pivots chosen for another position have degraded. */
static int klu_factor_values(linsys *ls, double *Ax)
{
    const linsys_plan *lp = ls->plan;
    if (ls->num && klu_refactor(lp->Ap, lp->Ai, Ax, lp->sym, ls->num, &ls->common)) {
        ls->refactorizations++;
        klu_rcond(lp->sym, ls->num, &ls->common);
        if (ls->common.rcond >= 1e-3 * ls->pivot_ratio_factor)
            return 0;
    }
    return klu_fresh_factor(ls, Ax);
}

int linsys_factor(linsys *ls, double *Ax)
{
    const linsys_plan *lp = ls->plan;
    ls->factored = 0;
    int rc;
    if (lp->use_klu) {
        int nnz = lp->Ap[lp->n];  /* (blocklu_factor checks its own) */
        for (int p = 0; p < nnz; p++)
            if (!isfinite(Ax[p]))
                return -1;
        rc = klu_factor_values(ls, Ax);
    } else {
        ls->factorizations++;
        rc = blocklu_factor(&ls->blu, Ax);
    }
    ls->factored = rc == 0;
    return rc;
}

/* klu_condest is Hager's method with KLU's factors, of the whole matrix.
 * klu_rcond's pivot ratio is not a condition estimate: pivoting that
 * prefers the diagonal can make it 1e-6 at a perfectly regular position. */
void linsys_condition(linsys *ls, double *Ax, double *rcond_blocks, double *rcond_whole)
{
    const linsys_plan *lp = ls->plan;
    double rb = 0.0, rw = 0.0;
    if (ls->factored && !lp->use_klu) {
        rb = blocklu_rcond(&ls->blu);
        rw = lp->blu.nblocks == 1 || !rcond_whole ? rb : blocklu_rcond_whole(&ls->blu);
    } else if (ls->factored &&
               klu_condest(lp->Ap, Ax, lp->sym, ls->num, &ls->common) &&
               ls->common.condest > 0.0) {
        rb = rw = 1.0 / ls->common.condest;
    }
    *rcond_blocks = rb;
    if (rcond_whole)
        *rcond_whole = rw;
}

int linsys_condition_bounds(linsys *ls, double *rcond_blocks, double *rcond_whole)
{
    if (!ls->factored || ls->plan->use_klu)
        return -1;
    return blocklu_rcond_bounds(&ls->blu, rcond_blocks, rcond_whole);
}

double linsys_pivot_ratio(linsys *ls)
{
    if (!ls->factored)
        return 0.0;
    if (!ls->plan->use_klu)
        return blocklu_pivot_ratio(&ls->blu);
    klu_rcond(ls->plan->sym, ls->num, &ls->common);
    return ls->common.rcond;
}

void linsys_solve(linsys *ls, double *x)
{
    const linsys_plan *lp = ls->plan;
    if (lp->use_klu)
        klu_solve(lp->sym, ls->num, lp->n, 1, x, &ls->common);
    else
        blocklu_solve(&ls->blu, x);
}

int linsys_det_sign(const linsys *ls)
{
    int n = ls->plan ? ls->plan->n : 0;
    if (!ls->factored || n == 0)
        return n == 0 ? 1 : 0;
    if (!ls->plan->use_klu)
        return blocklu_det_sign(&ls->blu);
    /* L U = A(Pnum, Q) with unit-diagonal L */
    const double *ud = ls->num->Udiag;
    int neg = ls->perm_parity;
    for (int k = 0; k < n; k++) {
        if (ud[k] == 0.0)
            return 0;
        neg ^= ud[k] < 0.0;
    }
    return neg ? -1 : 1;
}

int linsys_singular_col(const linsys *ls)
{
    if (!ls->plan)
        return -1;
    int c = ls->plan->use_klu ? ls->common.singular_col : ls->blu.singular_col;
    return c >= 0 && c < ls->plan->n ? c : -1;
}

const char *linsys_method_name(const linsys_plan *lp, char *buf, size_t size)
{
    if (lp->use_klu)
        snprintf(buf, size, "KLU");
    else
        snprintf(buf, size, "dense blocks (%d blocks, largest %dx%d)", lp->blu.nblocks,
                 lp->blu.largest, lp->blu.largest);
    return buf;
}
