/* src/blocklu.c: dense LU of the small diagonal blocks of a block
 * triangular form (blocklu.h, docs/solver.md "Linear solves").
 *
 * Planar mechanisms give Jacobians whose block triangular form has blocks
 * of one or two loops (1x1 to 8x8). At that size KLU's per-call overhead
 * (its own block loop, pivot bookkeeping, a general sparse kernel) costs
 * more than the arithmetic; a dense kernel per block is several times
 * faster and still exploits the sparsity that matters, the triangular
 * coupling between blocks, which stays sparse. */
#include <btf.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blocklu.h"
#include "internal.h"

/* Exact inverse norm up to this block size; Hager's estimate above. */
enum { EXACT_NORM_MAX = 8, HAGER_ITERATIONS = 5, WHOLE_HAGER_ITERATIONS = 2 };

void blocklu_plan_free(blocklu_plan *b)
{
    void *blocks[] = {b->P, b->Q, b->R, b->at, b->where, b->op, b->oi, b->oj};
    free_all(blocks, COUNT_OF(blocks));
    memset(b, 0, sizeof *b);
}

int blocklu_init(blocklu *b, const blocklu_plan *plan)
{
    memset(b, 0, sizeof *b);
    int n = plan->n, nb = plan->nblocks;
    b->plan = plan;
    b->singular_col = -1;
    b->v = xcalloc((size_t)plan->nv + 1, sizeof *b->v);
    b->piv = xcalloc((size_t)n + 1, sizeof *b->piv);
    b->anorm = xcalloc((size_t)nb + 1, sizeof *b->anorm);
    b->colnorm = xcalloc((size_t)n + 1, sizeof *b->colnorm);
    b->w = xcalloc(4 * (size_t)n + 3 * (size_t)plan->largest + 1, sizeof *b->w);
    if (!b->v || !b->piv || !b->anorm || !b->colnorm || !b->w) {
        blocklu_free(b);
        return -1;
    }
    return 0;
}

void blocklu_free(blocklu *b)
{
    void *blocks[] = {b->v, b->piv, b->anorm, b->colnorm, b->w};
    free_all(blocks, COUNT_OF(blocks));
    memset(b, 0, sizeof *b);
}

/* Where each entry of A goes: its block's dense storage, or the list of
 * entries above the blocks (CSC by permuted column). */
static int place_entries(blocklu_plan *b, const int *Ap, const int *Ai, const int *pinv,
                         const int *blk)
{
    int n = b->n, nnz = Ap[n], above = 0;
    for (int k = 0; k < n; k++) {  /* permuted column k is column Q[k] of A */
        int c = b->Q[k];
        for (int p = Ap[c]; p < Ap[c + 1]; p++)
            above += blk[pinv[Ai[p]]] != blk[k];
    }
    b->op = xcalloc((size_t)n + 1, sizeof *b->op);
    b->oi = xcalloc((size_t)above + 1, sizeof *b->oi);
    b->oj = xcalloc((size_t)above + 1, sizeof *b->oj);
    b->where = xcalloc((size_t)nnz + 1, sizeof *b->where);
    b->nv = b->ndense + above;
    if (!b->op || !b->oi || !b->oj || !b->where)
        return -1;
    int e = 0;
    for (int k = 0; k < n; k++) {
        int c = b->Q[k], bk = blk[k], k0 = b->R[bk], size = b->R[bk + 1] - k0;
        b->op[k] = e;
        for (int p = Ap[c]; p < Ap[c + 1]; p++) {
            int i = pinv[Ai[p]];
            if (blk[i] == bk) {
                b->where[p] = b->at[bk] + (i - k0) + (k - k0) * size;
            } else {
                b->oi[e] = i;
                b->oj[e] = k;
                b->where[p] = b->ndense + e++;
            }
        }
    }
    b->op[n] = e;
    b->nnz = nnz;
    unsigned char *hit = xcalloc((size_t)b->ndense + 1, 1);  /* slots covered */
    if (!hit)
        return -1;
    int covered = 0;
    for (int p = 0; p < nnz; p++)
        if (b->where[p] < b->ndense && !hit[b->where[p]]) {
            hit[b->where[p]] = 1;
            covered++;
        }
    free(hit);
    b->dense_full = covered == b->ndense;
    return 0;
}

int blocklu_analyze(blocklu_plan *b, int n, const int *Ap, const int *Ai, int max_block)
{
    if (max_block > BLOCKLU_MAX_BLOCK)  /* block_factor_general's row list holds that many */
        max_block = BLOCKLU_MAX_BLOCK;
    memset(b, 0, sizeof *b);
    b->n = n;
    b->P = xcalloc((size_t)n + 1, sizeof *b->P);
    b->Q = xcalloc((size_t)n + 1, sizeof *b->Q);
    b->R = xcalloc((size_t)n + 2, sizeof *b->R);
    int *work = xcalloc(5 * (size_t)n + 1, sizeof *work);
    int *pinv = xcalloc((size_t)n + 1, sizeof *pinv), *blk = xcalloc((size_t)n + 1, sizeof *blk);
    int rc = -1;
    if (!b->P || !b->Q || !b->R || !work || !pinv || !blk)
        goto done;
    double maxwork_done;
    int nmatch = 0;
    /* btf_order takes non-const arrays but does not modify them */
    b->nblocks = btf_order(n, (int *)Ap, (int *)Ai, 0.0, &maxwork_done, b->P, b->Q, b->R,
                           &nmatch, work);
    if (nmatch < n) {
        rc = 1;
        goto done;
    }
    b->at = xcalloc((size_t)b->nblocks + 1, sizeof *b->at);
    if (!b->at)
        goto done;
    for (int k = 0; k < b->nblocks; k++) {
        int size = b->R[k + 1] - b->R[k];
        if (size > max_block) {  /* before size * size can overflow */
            b->largest = size;
            rc = 2;
            goto done;
        }
        if (size > b->largest)
            b->largest = size;
        b->at[k] = b->ndense;
        b->ndense += size * size;
        for (int i = b->R[k]; i < b->R[k + 1]; i++)
            blk[i] = k;
    }
    for (int k = 0; k < n; k++)
        pinv[b->P[k]] = k;
    if (place_entries(b, Ap, Ai, pinv, blk) < 0)
        goto done;
    unsigned char *seen = (unsigned char *)work;  /* 5n ints: room for n bytes */
    b->pq_parity = permutation_parity(b->P, n, seen) ^ permutation_parity(b->Q, n, seen);
    rc = 0;
done:
    free(work);
    free(pinv);
    free(blk);
    return rc;
}

/* ---- one dense block, k x k column major ----------------------------- */

/* LU with partial pivoting in place: P a = L U, unit L below the diagonal.
 * Returns the local column of a zero pivot, or -1. A zero multiplier's
 * update (x - 0 t) is skipped: the same values, but for the sign of a zero. */
static int block_factor_general(double *a, int k, int *piv, int *swaps)
{
    int rows[BLOCKLU_MAX_BLOCK];
    for (int j = 0; j < k; j++) {
        int p = j;
        double best = fabs(a[j + j * k]);
        for (int i = j + 1; i < k; i++)
            if (fabs(a[i + j * k]) > best) {  /* the first of equal magnitudes, as before */
                best = fabs(a[i + j * k]);
                p = i;
            }
        piv[j] = p;
        if (!(a[p + j * k] != 0.0))
            return j;
        if (p != j) {
            *swaps ^= 1;
            for (int c = 0; c < k; c++) {
                double t = a[j + c * k];
                a[j + c * k] = a[p + c * k];
                a[p + c * k] = t;
            }
        }
        double inv = 1.0 / a[j + j * k];
        int nl = 0;  /* the rows with a nonzero multiplier: force blocks are sparse */
        for (int i = j + 1; i < k; i++)
            if (a[i + j * k] != 0.0) {
                a[i + j * k] *= inv;
                rows[nl++] = i;
            }
        for (int c = j + 1; c < k && nl > 0; c++) {
            double t = a[j + c * k];
            if (t != 0.0)
                for (int q = 0; q < nl; q++)
                    a[rows[q] + c * k] -= a[rows[q] + j * k] * t;
        }
    }
    return -1;
}

static inline int block_factor(double *a, int k, int *piv, int *swaps)
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
    return block_factor_general(a, k, piv, swaps);
}

/* y := (P^T L U)^-1 y */
static void block_solve_general(const double *a, int k, const int *piv, double *y)
{
    for (int j = 0; j < k; j++) {
        double t = y[piv[j]];
        y[piv[j]] = y[j];
        y[j] = t;
    }
    for (int j = 0; j < k; j++)
        for (int i = j + 1; i < k; i++)
            y[i] -= a[i + j * k] * y[j];
    for (int j = k - 1; j >= 0; j--) {
        y[j] /= a[j + j * k];
        for (int i = 0; i < j; i++)
            y[i] -= a[i + j * k] * y[j];
    }
}

/* Blocks of one and two equations (most of them: one loop's two unknowns)
 * unrolled; the loops' overhead is most of the work at this size. */
static inline void block_solve(const double *a, int k, const int *piv, double *y)
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
    } else {
        block_solve_general(a, k, piv, y);
    }
}

/* y := (P^T L U)^-T y = P^T L^-T U^-T y */
static void block_solve_transposed_general(const double *a, int k, const int *piv, double *y)
{
    for (int j = 0; j < k; j++) {
        double s = y[j];
        for (int i = 0; i < j; i++)
            s -= a[i + j * k] * y[i];
        y[j] = s / a[j + j * k];
    }
    for (int j = k - 1; j >= 0; j--) {
        double s = y[j];
        for (int i = j + 1; i < k; i++)
            s -= a[i + j * k] * y[i];
        y[j] = s;
    }
    for (int j = k - 1; j >= 0; j--) {
        double t = y[piv[j]];
        y[piv[j]] = y[j];
        y[j] = t;
    }
}

/* ... a 2 x 2 block unrolled (the same operations in the same order) */
static inline void block_solve_transposed(const double *a, int k, const int *piv, double *y)
{
    if (k != 2) {
        block_solve_transposed_general(a, k, piv, y);
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

static double norm1(const double *y, int k)
{
    double s = 0.0;
    for (int i = 0; i < k; i++)
        s += fabs(y[i]);
    return s;
}

/* |B^-1|_1 exactly: the largest column sum of the inverse. */
static double inverse_norm_exact(const double *a, int k, const int *piv, double *y)
{
    double big = 0.0;
    for (int j = 0; j < k; j++) {
        memset(y, 0, (size_t)k * sizeof *y);
        y[j] = 1.0;
        block_solve(a, k, piv, y);
        double ny = norm1(y, k);
        big = ny > big ? ny : big;
    }
    return big;
}

/* |B^-1|_1 of a 1x1 or 2x2 block from its factors: with P B = [a b; c d]
 * = [u11 u12; l u11, l u12 + u22], |B^-1|_1 = |(P B)^-1|_1 (a row
 * permutation of B permutes the columns of its inverse) = max(|d| + |c|,
 * |b| + |a|) / |u11 u22|. */
static double inverse_norm_small(const double *f, int k)
{
    if (k == 1)
        return 1.0 / fabs(f[0]);
    double a = f[0], b = f[2], c = f[1] * f[0], d = f[1] * f[2] + f[3];
    double cols = fabs(d) + fabs(c) > fabs(b) + fabs(a) ? fabs(d) + fabs(c) : fabs(b) + fabs(a);
    return cols / fabs(f[0] * f[3]);
}

/* Hager's estimate of |A^-1|_1 for an n x n A given by its solves (a lower
 * bound, usually exact): climb the convex function |A^-1 x|_1 over the unit
 * 1-ball from its centre, moving to the vertex its gradient points to,
 * until that stops increasing it, for at most `iterations` solves. w: 3n. */
typedef struct solves {
    void (*solve)(void *ctx, double *y);            /* y := A^-1 y */
    void (*solve_transposed)(void *ctx, double *y); /* y := A^-T y */
    void *ctx;
} solves;

static double inverse_norm_hager(const solves *s, int n, int iterations, double *w)
{
    double *x = w, *y = w + n, *z = w + 2 * n, est = 0.0;
    for (int i = 0; i < n; i++)
        x[i] = 1.0 / n;
    for (int it = 0; it < iterations; it++) {
        memcpy(y, x, (size_t)n * sizeof *y);
        s->solve(s->ctx, y);
        double ny = norm1(y, n);
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

/* One block's factors, for inverse_norm_hager. */
typedef struct block_ref {
    const double *a;
    int k;
    const int *piv;
} block_ref;

static void block_ref_solve(void *c, double *y)
{
    const block_ref *r = c;
    block_solve(r->a, r->k, r->piv, y);
}

static void block_ref_solve_transposed(void *c, double *y)
{
    const block_ref *r = c;
    block_solve_transposed(r->a, r->k, r->piv, y);
}

/* ---- the whole matrix -------------------------------------------------- */

/* The 1-norm of each column of A (colnorm), and of the block columns of A
 * (anorm: a block's columns with the entries above the block). A block's
 * reciprocal condition is measured against its whole columns: after the
 * columns are equilibrated a 1x1 block is always 1 on its own, yet near
 * zero next to the entries above it at a singular position. */
static void column_norms(blocklu *b)
{
    const blocklu_plan *pl = b->plan;
    const double *above = b->v + pl->ndense;
    for (int k = 0; k < pl->nblocks; k++) {
        int k0 = pl->R[k], size = pl->R[k + 1] - k0;
        const double *a = b->v + pl->at[k];
        double big = 0.0;
        for (int j = 0; j < size; j++) {
            double sum = 0.0;
            for (int i = 0; i < size; i++)
                sum += fabs(a[i + j * size]);
            for (int p = pl->op[k0 + j]; p < pl->op[k0 + j + 1]; p++)
                sum += fabs(above[p]);
            b->colnorm[k0 + j] = sum;
            big = sum > big ? sum : big;
        }
        b->anorm[k] = big;
    }
}

int blocklu_factor(blocklu *b, const double *Ax)
{
    const blocklu_plan *pl = b->plan;
    if (!pl->dense_full)  /* the structural zeros inside the blocks */
        memset(b->v, 0, (size_t)pl->ndense * sizeof *b->v);
    b->singular_col = -1;
    for (int p = 0; p < pl->nnz; p++) {
        if (!isfinite(Ax[p]))
            return -1;
        b->v[pl->where[p]] = Ax[p];
    }
    column_norms(b);
    b->swap_parity = 0;
    for (int k = 0; k < pl->nblocks; k++) {
        int k0 = pl->R[k], size = pl->R[k + 1] - k0;
        double *a = b->v + pl->at[k];
        int zero = block_factor(a, size, b->piv + k0, &b->swap_parity);
        if (zero >= 0) {
            b->singular_col = pl->Q[k0 + zero];
            return -1;
        }
    }
    return 0;
}

/* Backward over the blocks (the form is upper block triangular): solve the
 * block, then move its columns' entries above it to the right-hand side. */
void blocklu_solve(blocklu *b, double *x)
{
    const blocklu_plan *pl = b->plan;
    double *y = b->w;
    const double *above = b->v + pl->ndense;
    for (int k = 0; k < pl->n; k++)
        y[k] = x[pl->P[k]];
    if (pl->nblocks == 1)  /* one loop or one coupled group: nothing above it */
        block_solve(b->v, pl->n, b->piv, y);
    for (int k = pl->nblocks - 1; k >= 0 && pl->nblocks > 1; k--) {
        int k0 = pl->R[k], size = pl->R[k + 1] - k0;
        block_solve(b->v + pl->at[k], size, b->piv + k0, y + k0);
        for (int p = pl->op[k0]; p < pl->op[k0 + size]; p++)  /* by column, then row */
            y[pl->oi[p]] -= above[p] * y[pl->oj[p]];
    }
    for (int k = 0; k < pl->n; k++)
        x[pl->Q[k]] = y[k];
}

/* x := A^-T x: forward over the blocks (A^T is lower block triangular). */
static void solve_transposed(blocklu *b, double *x)
{
    const blocklu_plan *pl = b->plan;
    double *y = b->w;
    const double *above = b->v + pl->ndense;
    for (int k = 0; k < pl->n; k++)
        y[k] = x[pl->Q[k]];
    for (int k = 0; k < pl->nblocks; k++) {
        int k0 = pl->R[k], size = pl->R[k + 1] - k0;
        for (int p = pl->op[k0]; p < pl->op[k0 + size]; p++)  /* by column, then row */
            y[pl->oj[p]] -= above[p] * y[pl->oi[p]];
        block_solve_transposed(b->v + pl->at[k], size, b->piv + k0, y + k0);
    }
    for (int k = 0; k < pl->n; k++)
        x[pl->P[k]] = y[k];
}

static double whole_norm1(const blocklu *b)
{
    const blocklu_plan *pl = b->plan;
    double big = 0.0;
    for (int j = 0; j < pl->n; j++)
        big = fmax(big, b->colnorm[j]);
    return big;
}

static void whole_solve(void *c, double *y) { blocklu_solve(c, y); }
static void whole_solve_transposed(void *c, double *y) { solve_transposed(c, y); }

double blocklu_rcond_whole(blocklu *b)
{
    const blocklu_plan *pl = b->plan;
    /* two iterations: the estimate only sets the rounding floor of Newton's
       step, where a lower bound of the inverse's norm errs on the safe side
       (a smaller floor, at worst one more iteration) */
    solves s = {whole_solve, whole_solve_transposed, b};
    double est = inverse_norm_hager(&s, pl->n, WHOLE_HAGER_ITERATIONS, b->w + pl->n);
    double anorm = whole_norm1(b), r = anorm > 0.0 && est > 0.0 ? 1.0 / (anorm * est) : 0.0;
    return r >= 0.0 ? r : 0.0;
}

double blocklu_rcond(blocklu *b)
{
    const blocklu_plan *pl = b->plan;
    double worst = 1.0;
    double *w = b->w + 4 * pl->n;
    for (int k = 0; k < pl->nblocks; k++) {
        int k0 = pl->R[k], size = pl->R[k + 1] - k0;
        const double *a = b->v + pl->at[k];
        block_ref ref = {a, size, b->piv + k0};
        solves sv = {block_ref_solve, block_ref_solve_transposed, &ref};
        double inv = size <= 2              ? inverse_norm_small(a, size)
                     : size <= EXACT_NORM_MAX ? inverse_norm_exact(a, size, b->piv + k0, w)
                                              : inverse_norm_hager(&sv, size, HAGER_ITERATIONS, w);
        double r = b->anorm[k] > 0.0 && inv > 0.0 ? 1.0 / (b->anorm[k] * inv) : 0.0;
        if (!(r >= 0.0))  /* NaN: an overflowed inverse, singular */
            r = 0.0;
        worst = fmin(worst, r);
    }
    return worst;
}

double blocklu_pivot_ratio(const blocklu *b)
{
    const blocklu_plan *pl = b->plan;
    double worst = 1.0;
    for (int k = 0; k < pl->nblocks; k++) {
        int k0 = pl->R[k], size = pl->R[k + 1] - k0;
        const double *a = b->v + pl->at[k];
        for (int j = 0; j < size; j++) {
            double r = b->anorm[k] > 0.0 ? fabs(a[j + j * size]) / b->anorm[k] : 0.0;
            worst = r < worst ? r : worst;
        }
    }
    return worst;
}

int blocklu_det_sign(const blocklu *b)
{
    const blocklu_plan *pl = b->plan;
    int neg = pl->pq_parity ^ b->swap_parity;
    for (int k = 0; k < pl->nblocks; k++) {
        int k0 = pl->R[k], size = pl->R[k + 1] - k0;
        const double *a = b->v + pl->at[k];
        for (int j = 0; j < size; j++) {
            double d = a[j + j * size];
            if (d == 0.0)
                return 0;
            neg ^= d < 0.0;
        }
    }
    return neg ? -1 : 1;
}
