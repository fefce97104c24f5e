/* src/runtime/rt_blocklu.h: dense LU of the diagonal blocks of a block triangular
 * form, the entries above the blocks kept sparse: factor, solve, the
 * condition and the sign of the determinant (docs/solver.md "Linear
 * solves"). Part of the runtime that libmech (blocklu.c) and the C that
 * `mech codegen` writes share: the generator carries this file's text
 * (docs/codegen.md), so it is self-contained, the C library only, its data
 * in an rt_blocks table and the caller's arrays, nothing reserved here.
 *
 * A's block triangular form is A(P, Q) = [B_1 X ...; 0 B_2 ...; ...]: block
 * k is rows and columns R[k] .. R[k+1]-1 of the permuted matrix, stored
 * dense (k x k, column major) at v[at[k]]; the entries above the blocks
 * follow the blocks in v (v[ndense + p]), by permuted column (op[c] ..
 * op[c+1]-1), each with its permuted row oi[p] and column oj[p]. */
#ifndef MECH_RT_BLOCKLU_H
#define MECH_RT_BLOCKLU_H

#include <math.h>
#include <string.h>

#include "rt_base.h"

/* Largest diagonal block factored dense (the row list of rt_block_factor). */
enum { RT_MAX_BLOCK = 16 };

/* The block triangular form of an n x n pattern of nnz entries (CSC). */
typedef struct rt_blocks {
    int n, nblocks, ndense, nnz;
    int dense_full;   /* every dense slot is an entry of A (nothing to clear) */
    int pq_parity;    /* parity of P and Q together */
    const int *P, *Q; /* [n] A(P, Q) is upper block triangular */
    const int *R;     /* [nblocks + 1] first row and column of each block */
    const int *at;    /* [nblocks] start of each block in v */
    const int *where; /* [nnz] slot in v of each entry of A (CSC order) */
    const int *op;    /* [n + 1] entries above the blocks by permuted column */
    const int *oi;    /* [above] their permuted rows */
    const int *oj;    /* [above] their permuted columns */
} rt_blocks;

/* The scale of a column of values v[n]: 1 / max |v_i|, 1 for a column of
 * zeros or one that is not finite (equilibration: J C, each column of
 * largest entry 1, so that the condition measures the geometry, not the
 * units). */
RT_INLINE double rt_column_scale(const double *v, int n)
{
    double big = 0.0;
    for (int i = 0; i < n; i++)  /* (fmax is a library call at -O2) */
        big = fabs(v[i]) > big ? fabs(v[i]) : big;
    return big > 0.0 && isfinite(big) ? 1.0 / big : 1.0;
}

/* e[n] scaled by rt_column_scale(e, n) into out[dst[k]] (a column's
 * entries into their slots); the scale. */
RT_INLINE double rt_scale_into(const double *e, int n, double *out, const int *dst)
{
    double cs = rt_column_scale(e, n);
    for (int k = 0; k < n; k++)
        out[dst[k]] = e[k] * cs;
    return cs;
}

/* ---- one dense block, k x k column major ------------------------------- */

/* a = L U with partial pivoting in place (P a = L U, unit L below the
 * diagonal), piv[j]: the row swapped with row j, *swaps toggled at each
 * swap. Returns the local column of a zero pivot, or -1. A zero
 * multiplier's update (x - 0 t) is skipped: the same values but for the
 * sign of a zero, and force blocks are sparse. */
RT_INLINE int rt_block_factor_loops(double *a, int k, int *piv, int *swaps)
{
    /* only rows[0..nl) is read (GCC's unrolled update computes addresses
       from every entry up to k, whose unused terms cancel: valgrind reports
       those unset entries as used, tests/valgrind.supp; setting them cost
       the conveyor's compiled forces 355 instructions per step) */
    int rows[RT_MAX_BLOCK];
    RT_UNROLL for (int j = 0; j < k; j++) {
        int p = j;
        double best = fabs(a[j + j * k]);
        RT_UNROLL for (int i = j + 1; i < k; i++)
            if (fabs(a[i + j * k]) > best) {  /* the first of equal magnitudes */
                best = fabs(a[i + j * k]);
                p = i;
            }
        piv[j] = p;
        if (!(a[p + j * k] != 0.0))
            return j;
        if (p != j) {
            *swaps ^= 1;
            RT_UNROLL for (int c = 0; c < k; c++) {
                double t = a[j + c * k];
                a[j + c * k] = a[p + c * k];
                a[p + c * k] = t;
            }
        }
        double inv = 1.0 / a[j + j * k];
        int nl = 0;  /* the rows with a nonzero multiplier */
        RT_UNROLL for (int i = j + 1; i < k; i++)
            if (a[i + j * k] != 0.0) {
                a[i + j * k] *= inv;
                rows[nl++] = i;
            }
        for (int c = j + 1; c < k && nl > 0; c++) {
            double t = a[j + c * k];
            if (t != 0.0)
                RT_UNROLL for (int q = 0; q < nl; q++)
                    a[rows[q] + c * k] -= a[rows[q] + j * k] * t;
        }
    }
    return -1;
}

/* ... out of line for libmech (its sizes vary), and for 3 x 3 and 4 x 4
 * blocks with the size a constant, which the compiler unrolls: the same
 * operations in the same order, with less of the loops' overhead */
RT_KERNEL int rt_block_factor_general(double *a, int k, int *piv, int *swaps)
{
    return rt_block_factor_loops(a, k, piv, swaps);
}

RT_KERNEL int rt_block_factor_3(double *a, int *piv, int *swaps)
{
    return rt_block_factor_loops(a, 3, piv, swaps);
}

RT_KERNEL int rt_block_factor_4(double *a, int *piv, int *swaps)
{
    return rt_block_factor_loops(a, 4, piv, swaps);
}

/* ... blocks of one and two equations (most of them: one loop's two
 * unknowns) unrolled: the loops' overhead is most of the work at this size */
RT_INLINE int rt_block_factor(double *a, int k, int *piv, int *swaps)
{
    if (k == 1) {
        piv[0] = 0;
        return a[0] != 0.0 ? -1 : 0;
    }
    if (k == 2) {
        piv[0] = fabs(a[1]) > fabs(a[0]);
        piv[1] = 1;
        if (piv[0]) {
            double t = a[0];
            a[0] = a[1], a[1] = t;
            t = a[2];
            a[2] = a[3], a[3] = t;
            *swaps ^= 1;
        }
        if (!(a[0] != 0.0))
            return 0;
        a[1] /= a[0];
        a[3] -= a[1] * a[2];
        return a[3] != 0.0 ? -1 : 1;
    }
    if (k == 3)
        return rt_block_factor_3(a, piv, swaps);
    if (k == 4)
        return rt_block_factor_4(a, piv, swaps);
    return rt_block_factor_general(a, k, piv, swaps);
}

/* y := (P^T L U)^-1 y with rt_block_factor's factors. */
RT_INLINE void rt_block_solve_loops(const double *a, int k, const int *piv, double *y)
{
    RT_UNROLL for (int j = 0; j < k; j++) {  /* y = P y */
        double t = y[piv[j]];
        y[piv[j]] = y[j];
        y[j] = t;
    }
    RT_UNROLL for (int j = 0; j < k; j++)  /* y = L \ y */
        RT_UNROLL for (int i = j + 1; i < k; i++)
            y[i] -= a[i + j * k] * y[j];
    RT_UNROLL for (int j = k - 1; j >= 0; j--) {  /* y = U \ y */
        y[j] /= a[j + j * k];
        RT_UNROLL for (int i = 0; i < j; i++)
            y[i] -= a[i + j * k] * y[j];
    }
}

RT_KERNEL void rt_block_solve_general(const double *a, int k, const int *piv, double *y)
{
    rt_block_solve_loops(a, k, piv, y);
}

RT_KERNEL void rt_block_solve_3(const double *a, const int *piv, double *y)
{
    rt_block_solve_loops(a, 3, piv, y);
}

RT_KERNEL void rt_block_solve_4(const double *a, const int *piv, double *y)
{
    rt_block_solve_loops(a, 4, piv, y);
}

RT_INLINE void rt_block_solve(const double *a, int k, const int *piv, double *y)
{
    if (k == 1) {
        y[0] /= a[0];
    } else if (k == 2) {
        if (piv[0]) {
            double t = y[0];
            y[0] = y[1];
            y[1] = t;
        }
        double y1 = (y[1] - a[1] * y[0]) / a[3];
        y[0] = (y[0] - a[2] * y1) / a[0];
        y[1] = y1;
    } else if (k == 3) {
        rt_block_solve_3(a, piv, y);
    } else if (k == 4) {
        rt_block_solve_4(a, piv, y);
    } else {
        rt_block_solve_general(a, k, piv, y);
    }
}

/* y := (P^T L U)^-T y = P^T L^-T U^-T y. */
RT_KERNEL void rt_block_solve_transposed_general(const double *a, int k, const int *piv, double *y)
{
    RT_UNROLL for (int j = 0; j < k; j++) {  /* y = U^-T y */
        double s = y[j];
        RT_UNROLL for (int i = 0; i < j; i++)
            s -= a[i + j * k] * y[i];
        y[j] = s / a[j + j * k];
    }
    RT_UNROLL for (int j = k - 1; j >= 0; j--) {  /* y = L^-T y */
        double s = y[j];
        RT_UNROLL for (int i = j + 1; i < k; i++)
            s -= a[i + j * k] * y[i];
        y[j] = s;
    }
    RT_UNROLL for (int j = k - 1; j >= 0; j--) {  /* y = P^T y */
        double t = y[piv[j]];
        y[piv[j]] = y[j];
        y[j] = t;
    }
}

/* ... a 2 x 2 block unrolled (the same operations in the same order) */
RT_INLINE void rt_block_solve_transposed(const double *a, int k, const int *piv, double *y)
{
    if (k != 2) {
        rt_block_solve_transposed_general(a, k, piv, y);
        return;
    }
    y[0] = y[0] / a[0];
    y[1] = (y[1] - a[2] * y[0]) / a[3];
    y[0] = y[0] - a[1] * y[1];
    if (piv[0]) {  /* piv[1] is 1: no swap */
        double t = y[0];
        y[0] = y[1];
        y[1] = t;
    }
}

/* |y|_1 */
static inline double rt_norm1(const double *y, int k)
{
    double s = 0.0;
    for (int i = 0; i < k; i++)
        s += fabs(y[i]);
    return s;
}

/* |B^-1|_1 of a 1x1 or 2x2 block from its factors: with P B = [a b; c d]
 * = [u11 u12; l u11, l u12 + u22], |B^-1|_1 = |(P B)^-1|_1 (a row
 * permutation of B permutes the columns of its inverse) = max(|d| + |c|,
 * |b| + |a|) / |u11 u22|. */
static inline double rt_block_inverse_norm_small(const double *f, int k)
{
    if (k == 1)
        return 1.0 / fabs(f[0]);
    double a = f[0], b = f[2], c = f[1] * f[0], d = f[1] * f[2] + f[3];
    double cols = fabs(d) + fabs(c) > fabs(b) + fabs(a) ? fabs(d) + fabs(c) : fabs(b) + fabs(a);
    return cols / fabs(f[0] * f[3]);
}

/* |B^-1|_1 exactly: the largest column sum of the inverse, column by
 * column. y: k of work. */
static inline double rt_block_inverse_norm_exact(const double *a, int k, const int *piv, double *y)
{
    double big = 0.0;
    for (int j = 0; j < k; j++) {
        memset(y, 0, (size_t)k * sizeof *y);
        y[j] = 1.0;
        rt_block_solve(a, k, piv, y);
        double ny = rt_norm1(y, k);
        big = ny > big ? ny : big;
    }
    return big;
}

/* An n x n matrix given by its solves, for rt_inverse_norm_hager. */
typedef struct rt_solves {
    void (*solve)(void *ctx, double *y);            /* y := A^-1 y */
    void (*solve_transposed)(void *ctx, double *y); /* y := A^-T y */
    void *ctx;
} rt_solves;

/* Hager's estimate of |A^-1|_1 (a lower bound, usually exact): climb the
 * convex function |A^-1 x|_1 over the unit 1-ball from its centre, moving
 * to the vertex its gradient points to, until that stops increasing it,
 * for at most `iterations` solves. w: 3 n of work. */
static inline double rt_inverse_norm_hager(const rt_solves *s, int n, int iterations, double *w)
{
    double *x = w, *y = w + n, *z = w + 2 * n, est = 0.0;
    for (int i = 0; i < n; i++)
        x[i] = 1.0 / n;
    for (int it = 0; it < iterations; it++) {
        memcpy(y, x, (size_t)n * sizeof *y);
        s->solve(s->ctx, y);
        double ny = rt_norm1(y, n);
        if (it > 0 && ny <= est)
            break;
        est = ny;
        if (it == iterations - 1)
            break;
        for (int i = 0; i < n; i++)
            z[i] = y[i] >= 0.0 ? 1.0 : -1.0;
        s->solve_transposed(s->ctx, z);
        int j = 0;
        double ztx = 0.0;
        for (int i = 0; i < n; i++) {
            ztx += z[i] * x[i];
            if (fabs(z[i]) > fabs(z[j]))
                j = i;
        }
        if (it > 0 && fabs(z[j]) <= ztx)
            break;
        memset(x, 0, (size_t)n * sizeof *x);
        x[j] = 1.0;
    }
    return est;
}

/* One block's factors, for rt_inverse_norm_hager. */
typedef struct rt_block_ref {
    const double *a;
    int k;
    const int *piv;
} rt_block_ref;

static inline void rt_block_ref_solve(void *c, double *y)
{
    const rt_block_ref *r = (const rt_block_ref *)c;
    rt_block_solve(r->a, r->k, r->piv, y);
}

static inline void rt_block_ref_solve_transposed(void *c, double *y)
{
    const rt_block_ref *r = (const rt_block_ref *)c;
    rt_block_solve_transposed(r->a, r->k, r->piv, y);
}

/* Exact inverse norm up to this block size; Hager's estimate above. */
enum { RT_EXACT_NORM_MAX = 8, RT_HAGER_ITERATIONS = 5, RT_WHOLE_HAGER_ITERATIONS = 2 };

/* |B^-1|_1 of a factored block: closed form up to 2 x 2, column by column
 * up to 8 x 8, Hager's estimate beyond. w: 3 k of work. */
static inline double rt_block_inverse_norm(const double *a, int k, const int *piv, double *w)
{
    if (k <= 2)
        return rt_block_inverse_norm_small(a, k);
    if (k <= RT_EXACT_NORM_MAX)
        return rt_block_inverse_norm_exact(a, k, piv, w);
    rt_block_ref ref = {a, k, piv};
    rt_solves sv = {rt_block_ref_solve, rt_block_ref_solve_transposed, &ref};
    return rt_inverse_norm_hager(&sv, k, RT_HAGER_ITERATIONS, w);
}

/* ---- the whole matrix -------------------------------------------------- */

/* v = A's values Ax (CSC, the analysed pattern) in their slots; -1 when one
 * is not finite. */
RT_INLINE int rt_blocks_place(const rt_blocks *b, const double *Ax, double *v)
{
    if (!b->dense_full)  /* the structural zeros inside the blocks */
        memset(v, 0, (size_t)b->ndense * sizeof *v);
    RT_UNROLL for (int p = 0; p < b->nnz; p++) {
        if (!isfinite(Ax[p]))
            return -1;
        v[b->where[p]] = Ax[p];
    }
    return 0;
}

/* The 1-norm of each column of A (colnorm[n]) and of each block's columns
 * with the entries above the block (anorm[nblocks]): a block's reciprocal
 * condition is measured against its whole columns (after equilibration a
 * 1 x 1 block is 1 on its own, yet near zero next to the entries above it
 * at a singular position). */
RT_INLINE void rt_blocks_column_norms(const rt_blocks *b, const double *v, double *colnorm,
                                      double *anorm)
{
    const double *above = v + b->ndense;
    RT_UNROLL for (int k = 0; k < b->nblocks; k++) {
        int k0 = b->R[k], size = b->R[k + 1] - k0;
        const double *a = v + b->at[k];
        double big = 0.0;
        RT_UNROLL for (int j = 0; j < size; j++) {
            double sum = 0.0;
            RT_UNROLL for (int i = 0; i < size; i++)
                sum += fabs(a[i + j * size]);
            RT_UNROLL for (int p = b->op[k0 + j]; p < b->op[k0 + j + 1]; p++)
                sum += fabs(above[p]);
            colnorm[k0 + j] = sum;
            big = sum > big ? sum : big;
        }
        anorm[k] = big;
    }
}

/* Factor the blocks of the placed values v in place (piv[n], *swaps: the
 * parity of the row swaps). Returns the permuted column of a zero pivot, or
 * -1. */
RT_INLINE int rt_blocks_factor_placed(const rt_blocks *b, double *v, int *piv, int *swaps)
{
    *swaps = 0;
    RT_UNROLL for (int k = 0; k < b->nblocks; k++) {
        int k0 = b->R[k];
        int zero = rt_block_factor(v + b->at[k], b->R[k + 1] - k0, piv + k0, swaps);
        if (zero >= 0)
            return k0 + zero;
    }
    return -1;
}

/* x := A^-1 x: backward over the blocks (the form is upper block
 * triangular), solve the block, then move its columns' entries above it to
 * the right-hand side. w: n of work. */
RT_INLINE void rt_blocks_solve(const rt_blocks *b, const double *v, const int *piv, double *w,
                               double *x)
{
    const double *above = v + b->ndense;
    RT_UNROLL for (int k = 0; k < b->n; k++)
        w[k] = x[b->P[k]];
    if (b->nblocks == 1)  /* one loop or one coupled group: nothing above it */
        rt_block_solve(v, b->n, piv, w);
    else
        RT_UNROLL for (int k = b->nblocks - 1; k >= 0; k--) {
            int k0 = b->R[k], size = b->R[k + 1] - k0;
            rt_block_solve(v + b->at[k], size, piv + k0, w + k0);
            RT_UNROLL for (int p = b->op[k0]; p < b->op[k0 + size]; p++)  /* by column, then row */
                w[b->oi[p]] -= above[p] * w[b->oj[p]];
        }
    RT_UNROLL for (int k = 0; k < b->n; k++)
        x[b->Q[k]] = w[k];
}

/* x := A^-T x: forward over the blocks (A^T is lower block triangular). */
RT_INLINE void rt_blocks_solve_transposed(const rt_blocks *b, const double *v, const int *piv,
                                          double *w, double *x)
{
    const double *above = v + b->ndense;
    RT_UNROLL for (int k = 0; k < b->n; k++)
        w[k] = x[b->Q[k]];
    RT_UNROLL for (int k = 0; k < b->nblocks; k++) {
        int k0 = b->R[k], size = b->R[k + 1] - k0;
        RT_UNROLL for (int p = b->op[k0]; p < b->op[k0 + size]; p++)  /* by column, then row */
            w[b->oj[p]] -= above[p] * w[b->oi[p]];
        rt_block_solve_transposed(v + b->at[k], size, piv + k0, w + k0);
    }
    RT_UNROLL for (int k = 0; k < b->n; k++)
        x[b->P[k]] = w[k];
}

/* Smallest reciprocal 1-norm condition of the blocks, each measured
 * against its whole columns: 1 / (|A(:, B)|_1 |B^-1|_1). w: 3 largest. */
static inline double rt_blocks_rcond(const rt_blocks *b, const double *v, const int *piv,
                                     const double *anorm, double *w)
{
    double worst = 1.0;
    for (int k = 0; k < b->nblocks; k++) {
        int k0 = b->R[k];
        double inv = rt_block_inverse_norm(v + b->at[k], b->R[k + 1] - k0, piv + k0, w);
        double r = anorm[k] > 0.0 && inv > 0.0 ? 1.0 / (anorm[k] * inv) : 0.0;
        if (!(r >= 0.0))  /* NaN: an overflowed inverse, singular */
            r = 0.0;
        worst = fmin(worst, r);
    }
    return worst;
}

/* The factors of the whole matrix, for rt_inverse_norm_hager. */
typedef struct rt_blocks_ref {
    const rt_blocks *b;
    const double *v;
    const int *piv;
    double *w;
} rt_blocks_ref;

static inline void rt_blocks_ref_solve(void *c, double *y)
{
    const rt_blocks_ref *r = (const rt_blocks_ref *)c;
    rt_blocks_solve(r->b, r->v, r->piv, r->w, y);
}

static inline void rt_blocks_ref_solve_transposed(void *c, double *y)
{
    const rt_blocks_ref *r = (const rt_blocks_ref *)c;
    rt_blocks_solve_transposed(r->b, r->v, r->piv, r->w, y);
}

/* Reciprocal 1-norm condition of the whole A, Hager's estimate with two
 * iterations (it sets only the rounding floor of Newton's step, where a
 * lower bound of the inverse's norm errs on the safe side): with many
 * blocks in a chain it can be far smaller than the blocks'. w: 4 n. */
static inline double rt_blocks_rcond_whole(const rt_blocks *b, const double *v, const int *piv,
                                           const double *colnorm, double *w)
{
    rt_blocks_ref ref = {b, v, piv, w};
    rt_solves s = {rt_blocks_ref_solve, rt_blocks_ref_solve_transposed, &ref};
    double est = rt_inverse_norm_hager(&s, b->n, RT_WHOLE_HAGER_ITERATIONS, w + b->n);
    double anorm = 0.0;
    for (int j = 0; j < b->n; j++)
        anorm = fmax(anorm, colnorm[j]);
    double r = anorm > 0.0 && est > 0.0 ? 1.0 / (anorm * est) : 0.0;
    return r >= 0.0 ? r : 0.0;
}

/* Smallest |pivot| / the 1-norm of its block's columns (cheap: no solves;
 * tiny at an exactly singular matrix). */
static inline double rt_blocks_pivot_ratio(const rt_blocks *b, const double *v,
                                           const double *anorm)
{
    double worst = 1.0;
    for (int k = 0; k < b->nblocks; k++) {
        int size = b->R[k + 1] - b->R[k];
        const double *a = v + b->at[k];
        for (int j = 0; j < size; j++) {
            double r = anorm[k] > 0.0 ? fabs(a[j + j * size]) / anorm[k] : 0.0;
            worst = r < worst ? r : worst;
        }
    }
    return worst;
}

/* Sign of det A (+1, -1, 0) from the factors: the permutations' parity,
 * the row swaps', the pivots' signs. */
static inline int rt_blocks_det_sign(const rt_blocks *b, const double *v, int swap_parity)
{
    int neg = b->pq_parity ^ swap_parity;
    RT_UNROLL for (int k = 0; k < b->nblocks; k++) {
        int size = b->R[k + 1] - b->R[k];
        const double *a = v + b->at[k];
        RT_UNROLL for (int j = 0; j < size; j++) {
            double d = a[j + j * size];
            if (d == 0.0)
                return 0;
            neg ^= d < 0.0;
        }
    }
    return neg ? -1 : 1;
}

/* ---- upper bounds of the inverse's norm (no solves of A) ---------------- */

/* y := G^T y, G = M(U)^-1 M(L)^-1 P >= |B^-1| entrywise for one block B =
 * P^T L U (rt_block_factor's factors), M the comparison matrix (|t_jj| on
 * the diagonal, -|t_ij| off it): rt_block_solve_transposed on M(U), M(L),
 * with y >= 0 (sums of positive terms, no cancellation); without the
 * permutation P^T when perm is 0 (a block alone: only the largest entry is
 * wanted). */
RT_INLINE void rt_block_bound_transposed(const double *a, int n, const int *piv, double *y,
                                         int perm)
{
    for (int j = 0; j < n; j++) {
        double t = y[j];
        for (int i = 0; i < j; i++)
            t += fabs(a[i + j * n]) * y[i];
        y[j] = t / fabs(a[j + j * n]);
    }
    for (int j = n - 1; j >= 0; j--) {
        double t = y[j];
        for (int i = j + 1; i < n; i++)
            t += fabs(a[i + j * n]) * y[i];
        y[j] = t;
    }
    for (int j = n - 1; j >= 0 && perm; j--) {
        double t = y[piv[j]];
        y[piv[j]] = y[j];
        y[j] = t;
    }
}

/* An upper bound of |B^-1|_1 for block k (k >= 0), or of |A^-1|_1 for the
 * whole A (k = -1): the largest entry of 1^T Y, Y >= |A^-1| entrywise the
 * inverse of the block triangular comparison matrix (the blocks' G^-1 on
 * its diagonal, -|a_ij| above): rt_blocks_solve_transposed with G and
 * |a_ij|. y: n of work. */
static inline double rt_blocks_inverse_bound(const rt_blocks *b, const double *v, const int *piv,
                                             int k, double *y)
{
    const double *above = v + b->ndense;
    double big = 0.0;
    int k0 = k < 0 ? 0 : k, k1 = k < 0 ? b->nblocks : k + 1;
    for (int i = b->R[k0]; i < b->R[k1]; i++)
        y[i] = 1.0;
    for (int c = k0; c < k1; c++) {
        int lo = b->R[c], n = b->R[c + 1] - lo;
        for (int p = b->op[lo]; p < b->op[lo + n] && k < 0; p++)  /* by column, then row */
            y[b->oj[p]] += fabs(above[p]) * y[b->oi[p]];
        rt_block_bound_transposed(v + b->at[c], n, piv + lo, y + lo, k < 0);
    }
    for (int i = b->R[k0]; i < b->R[k1]; i++)
        big = y[i] > big ? y[i] : big;
    return big;
}

/* Lower bounds of rt_blocks_rcond and rt_blocks_rcond_whole without their
 * solves: each block's rcond exactly (closed forms) up to 2 x 2, 1 / (anorm
 * (1 + 1e-6) bound) beyond, and the whole matrix's likewise (when there
 * are several blocks; else the worst block's). Returns 1 when a bound was
 * used, 0 when both are the exact values. w: n of work.
 *
 * Why they are lower bounds of the values those compute, roundings
 * included: the inverse's columns that rt_block_inverse_norm computes and
 * Hager's vectors (A^-1 x, |x|_1 = 1) are computed by triangular and block
 * back substitutions, which are backward stable: exact solves with every
 * factor entry and entry above the blocks perturbed by at most 3 n eps
 * relatively, so their entries are at most those of Y |x|
 * (rt_blocks_inverse_bound) times (1 + 3 n eps)^(2 n) (every path through
 * the comparison inverses has at most 2 n factors); the bound's own
 * rounding (sums of positive terms) is as small; both below 1 + 1e-6 for
 * n <= 20000, and the rest are the same monotone roundings (anorm * inv,
 * 1 / (...), fmin). */
static inline int rt_blocks_rcond_bounds(const rt_blocks *b, const double *v, const int *piv,
                                         const double *anorm, double *w, double *rcond,
                                         double *rcond_whole)
{
    double worst = 1.0, anorm_all = 0.0;
    int bounded = 0;
    for (int k = 0; k < b->nblocks; k++) {
        int n = b->R[k + 1] - b->R[k];
        double inv = n <= 2 ? rt_block_inverse_norm_small(v + b->at[k], n)
                            : (1.0 + 1e-6) * rt_blocks_inverse_bound(b, v, piv, k, w);
        double r = anorm[k] > 0.0 && inv > 0.0 ? 1.0 / (anorm[k] * inv) : 0.0;
        if (!(r >= 0.0))
            r = 0.0;
        worst = fmin(worst, r);
        anorm_all = fmax(anorm_all, anorm[k]);
        bounded |= n > 2;
    }
    *rcond = *rcond_whole = worst;
    if (b->nblocks > 1) {
        double est = (1.0 + 1e-6) * rt_blocks_inverse_bound(b, v, piv, -1, w);
        *rcond_whole = anorm_all > 0.0 && est > 0.0 ? 1.0 / (anorm_all * est) : 0.0;
        bounded = 1;
    }
    return bounded;
}

#endif
