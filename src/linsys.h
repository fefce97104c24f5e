/* src/linsys.h: the linear solves of a Newton or force system (docs/solver.md
 * "Linear solves"). One square sparse pattern is analysed once; each step
 * factors new values, estimates the condition and solves. When every
 * diagonal block of the block triangular form is small (planar mechanisms:
 * one or two loops per block) the blocks are factored dense (blocklu.c);
 * otherwise, or when asked, by SuiteSparse KLU. As in KLU, the analysis
 * (linsys_plan, shared) and the factors (linsys, per thread) are apart. */
#ifndef MECH_LINSYS_H
#define MECH_LINSYS_H

#include <klu.h>

#include "blocklu.h"
#include "mech.h"

/* The analysis of one pattern (immutable once made; threads share it). */
typedef struct linsys_plan {
    int n;
    int *Ap, *Ai;              /* the pattern (not owned) */
    int use_klu;               /* 0: dense blocks, 1: KLU */
    blocklu_plan blu;
    klu_common common;         /* the settings every factorisation copies */
    klu_symbolic *sym;         /* read only after klu_analyze */
    int q_parity;              /* parity of KLU's fixed column order */
} linsys_plan;

/* Factors of values of a plan's pattern: one per thread. */
typedef struct linsys {
    const linsys_plan *plan;   /* borrowed */
    blocklu blu;
    klu_common common;         /* KLU writes its status here: one per thread */
    klu_numeric *num;
    int factored;              /* the last factorisation succeeded */
    double pivot_ratio_factor; /* klu_rcond at the last full klu_factor */
    int perm_parity;           /* of the row and column orders of KLU's factors */
    unsigned char *seen;       /* [n] permutation parity work */
    int factorizations;        /* full factorisations (every dense-block one) */
    int refactorizations;      /* klu_refactor with the previous pivot order */
} linsys;

/* Analyse the n x n pattern (CSC; kept by reference). method is
 * MECH_LINEAR_AUTO or MECH_LINEAR_KLU. Returns 0, 1 when the pattern is
 * structurally singular, -1 when out of memory or KLU fails. */
int linsys_plan_init(linsys_plan *lp, int n, int *Ap, int *Ai, int method);
void linsys_plan_free(linsys_plan *lp);
/* Factors and workspace for the plan's pattern: 0, or -1 out of memory. */
int linsys_init(linsys *ls, const linsys_plan *lp);
void linsys_free(linsys *ls);

/* Factor the values Ax. Returns 0, or -1 when singular or not finite. */
int linsys_factor(linsys *ls, double *Ax);
/* Reciprocal 1-norm condition with the current factors (0 when not
 * factored): of the worst diagonal block against its whole columns
 * (blocklu_rcond; KLU: of the whole matrix), and of the whole matrix. They
 * differ when errors pass along a chain of blocks: the first says whether
 * the position is singular, the second how far rounding reaches (NULL:
 * not wanted, saves whole solves). */
void linsys_condition(linsys *ls, double *Ax, double *rcond_blocks, double *rcond_whole);
/* Smallest pivot against the largest column (dense blocks: per block, of
 * the block's columns; KLU: klu_rcond). Not a condition estimate, but tiny
 * (about eps) at an exactly singular matrix; 0 when not factored. */
double linsys_pivot_ratio(linsys *ls);
/* x := A^-1 x with the current factors. */
void linsys_solve(linsys *ls, double *x);
/* Sign of det A with the current factors (+1, -1; 0 singular). */
int linsys_det_sign(const linsys *ls);
/* After a failed factorisation: a column with a zero pivot, or -1. */
int linsys_singular_col(const linsys *ls);
/* "dense blocks (largest 2x2)" or "KLU". */
const char *linsys_method_name(const linsys_plan *lp, char *buf, size_t size);

#endif
