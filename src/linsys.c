/* src/linsys.c: dense blocks or KLU behind one interface (linsys.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "linsys.h"

static int klu_init(linsys *ls)
{
    klu_defaults(&ls->common);
    /* Rows are lengths or forces already, and callers equilibrate the
       columns; KLU's row scaling would blow a row that is small for a
       geometric reason (a dead centre) up to 1 and hide the singularity
       from the condition estimate. */
    ls->common.scale = 0;
    /* Diagonal preference only within a factor 10 of the largest pivot
       candidate (KLU's default 1e-3 allows growth of 1e3 per column). */
    ls->common.tol = 0.1;
    ls->seen = xcalloc((size_t)ls->n + 1, 1);
    if (!ls->seen)
        return -1;
    ls->sym = klu_analyze(ls->n, ls->Ap, ls->Ai, &ls->common);
    if (!ls->sym)
        return -1;
    ls->q_parity = permutation_parity(ls->sym->Q, ls->n, ls->seen);
    return 0;
}

int linsys_init(linsys *ls, int n, int *Ap, int *Ai, int method)
{
    memset(ls, 0, sizeof *ls);
    ls->n = n;
    ls->Ap = Ap;
    ls->Ai = Ai;
    if (method != MECH_LINEAR_KLU) {
        int rc = blocklu_analyze(&ls->blu, n, Ap, Ai, BLOCKLU_MAX_BLOCK);
        if (rc != 2)
            return rc;
        blocklu_free(&ls->blu);  /* a block too large for dense LU */
    }
    ls->use_klu = 1;
    return klu_init(ls);
}

void linsys_free(linsys *ls)
{
    if (ls->num)
        klu_free_numeric(&ls->num, &ls->common);
    if (ls->sym)
        klu_free_symbolic(&ls->sym, &ls->common);
    blocklu_free(&ls->blu);
    free(ls->seen);
    memset(ls, 0, sizeof *ls);
}

static int klu_fresh_factor(linsys *ls, double *Ax)
{
    if (ls->num)
        klu_free_numeric(&ls->num, &ls->common);
    ls->num = klu_factor(ls->Ap, ls->Ai, Ax, ls->sym, &ls->common);
    ls->factorizations++;
    if (!ls->num)
        return -1;
    klu_rcond(ls->sym, ls->num, &ls->common);
    ls->pivot_ratio_factor = ls->common.rcond;
    /* refactoring keeps this pivot order: its parity holds until the next */
    ls->perm_parity = permutation_parity(ls->num->Pnum, ls->n, ls->seen) ^ ls->q_parity;
    return 0;
}

/* Refactor with the old pivots while they hold; pivot afresh when the
 * pivot ratio (klu_rcond) has fallen below 1e-3 of its value at the last
 * full factorisation: pivots chosen for another position have degraded. */
static int klu_factor_values(linsys *ls, double *Ax)
{
    if (ls->num && klu_refactor(ls->Ap, ls->Ai, Ax, ls->sym, ls->num, &ls->common)) {
        ls->refactorizations++;
        klu_rcond(ls->sym, ls->num, &ls->common);
        if (ls->common.rcond >= 1e-3 * ls->pivot_ratio_factor)
            return 0;
    }
    return klu_fresh_factor(ls, Ax);
}

int linsys_factor(linsys *ls, double *Ax)
{
    ls->factored = 0;
    int nnz = ls->Ap[ls->n];
    for (int p = 0; p < nnz; p++)
        if (!isfinite(Ax[p]))
            return -1;
    int rc;
    if (ls->use_klu) {
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
    double rb = 0.0, rw = 0.0;
    if (ls->factored && !ls->use_klu) {
        rb = blocklu_rcond(&ls->blu);
        rw = ls->blu.nblocks == 1 || !rcond_whole ? rb : blocklu_rcond_whole(&ls->blu);
    } else if (ls->factored &&
               klu_condest(ls->Ap, Ax, ls->sym, ls->num, &ls->common) &&
               ls->common.condest > 0.0) {
        rb = rw = 1.0 / ls->common.condest;
    }
    *rcond_blocks = rb;
    if (rcond_whole)
        *rcond_whole = rw;
}

double linsys_pivot_ratio(linsys *ls)
{
    if (!ls->factored)
        return 0.0;
    if (!ls->use_klu)
        return blocklu_pivot_ratio(&ls->blu);
    klu_rcond(ls->sym, ls->num, &ls->common);
    return ls->common.rcond;
}

void linsys_solve(linsys *ls, double *x)
{
    if (ls->use_klu)
        klu_solve(ls->sym, ls->num, ls->n, 1, x, &ls->common);
    else
        blocklu_solve(&ls->blu, x);
}

int linsys_det_sign(const linsys *ls)
{
    if (!ls->factored || ls->n == 0)
        return ls->n == 0 ? 1 : 0;
    if (!ls->use_klu)
        return blocklu_det_sign(&ls->blu);
    /* L U = A(Pnum, Q) with unit-diagonal L */
    const double *ud = ls->num->Udiag;
    int neg = ls->perm_parity;
    for (int k = 0; k < ls->n; k++) {
        if (ud[k] == 0.0)
            return 0;
        neg ^= ud[k] < 0.0;
    }
    return neg ? -1 : 1;
}

int linsys_singular_col(const linsys *ls)
{
    int c = ls->use_klu ? ls->common.singular_col : ls->blu.singular_col;
    return c >= 0 && c < ls->n ? c : -1;
}

const char *linsys_method_name(const linsys *ls, char *buf, size_t size)
{
    if (ls->use_klu)
        snprintf(buf, size, "KLU");
    else
        snprintf(buf, size, "dense blocks (%d blocks, largest %dx%d)", ls->blu.nblocks,
                 ls->blu.largest, ls->blu.largest);
    return buf;
}
