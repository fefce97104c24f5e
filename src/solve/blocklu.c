/* src/solve/blocklu.c: dense LU of the small diagonal blocks of a block
 * triangular form (blocklu.h, docs/solver.md "Linear solves").
 *
 * Planar mechanisms give Jacobians whose block triangular form has blocks
 * of one or two loops (1x1 to 8x8). At that size KLU's per-call overhead
 * (its own block loop, pivot bookkeeping, a general sparse kernel) costs
 * more than the arithmetic; a dense kernel per block is several times
 * faster and still exploits the sparsity that matters, the triangular
 * coupling between blocks, which stays sparse. */
#include <btf.h>
#include <stdlib.h>
#include <string.h>

#include "solve.h"
#include "base.h"

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
    if (max_block > BLOCKLU_MAX_BLOCK)  /* rt_block_factor's row list holds that many */
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
    b->rb = (rt_blocks){n, b->nblocks, b->ndense, b->nnz, b->dense_full, b->pq_parity,
                        b->P, b->Q, b->R, b->at, b->where, b->op, b->oi, b->oj};
    b->one_2x2 = n == 2 && b->nblocks == 1 && b->nnz == 4 && b->dense_full;
    rc = 0;
done:
    free(work);
    free(pinv);
    free(blk);
    return rc;
}

/* One dense 2 x 2 block with nothing above it (a single loop's two
 * unknowns: a four-bar, a slider-crank) is the commonest system: the
 * functions below pass it to the runtime's loops as a table whose sizes are
 * constants in the call, which the compiler unrolls as it does for the
 * generated code's tables (the loops' overhead is most of the work at this
 * size). The same operations in the same order: the same values. */
static const int one_R[2] = {0, 2}, one_at[1] = {0}, one_op[3] = {0, 0, 0};

#define ONE_2X2(rb)                                                                           \
    ((rt_blocks){2, 1, 4, 4, 1, (rb)->pq_parity, (rb)->P, (rb)->Q, one_R, one_at, (rb)->where, \
                 one_op, (rb)->oi, (rb)->oj})

RT_INLINE int factor_with(blocklu *b, const rt_blocks *rb, const double *Ax)
{
    b->singular_col = -1;
    if (rt_blocks_place(rb, Ax, b->v) < 0)
        return -1;
    rt_blocks_column_norms(rb, b->v, b->colnorm, b->anorm);
    int zero = rt_blocks_factor_placed(rb, b->v, b->piv, &b->swap_parity);
    if (zero >= 0) {
        b->singular_col = rb->Q[zero];
        return -1;
    }
    return 0;
}

int blocklu_factor(blocklu *b, const double *Ax)
{
    const rt_blocks *rb = &b->plan->rb;
    if (b->plan->one_2x2) {
        const rt_blocks one = ONE_2X2(rb);
        return factor_with(b, &one, Ax);
    }
    return factor_with(b, rb, Ax);
}

void blocklu_solve(blocklu *b, double *x)
{
    const rt_blocks *rb = &b->plan->rb;
    if (b->plan->one_2x2) {
        const rt_blocks one = ONE_2X2(rb);
        rt_blocks_solve(&one, b->v, b->piv, b->w, x);
        return;
    }
    rt_blocks_solve(rb, b->v, b->piv, b->w, x);
}

double blocklu_rcond_whole(blocklu *b)
{
    return rt_blocks_rcond_whole(&b->plan->rb, b->v, b->piv, b->colnorm, b->w);
}

int blocklu_rcond_bounds(blocklu *b, double *rcond, double *rcond_whole)
{
    const rt_blocks *rb = &b->plan->rb;
    if (b->plan->one_2x2) {
        const rt_blocks one = ONE_2X2(rb);
        return rt_blocks_rcond_bounds(&one, b->v, b->piv, b->anorm, b->w, rcond, rcond_whole);
    }
    return rt_blocks_rcond_bounds(rb, b->v, b->piv, b->anorm, b->w, rcond, rcond_whole);
}

double blocklu_rcond(blocklu *b)
{
    return rt_blocks_rcond(&b->plan->rb, b->v, b->piv, b->anorm, b->w + 4 * b->plan->n);
}

double blocklu_pivot_ratio(const blocklu *b)
{
    return rt_blocks_pivot_ratio(&b->plan->rb, b->v, b->anorm);
}

int blocklu_det_sign(const blocklu *b)
{
    return rt_blocks_det_sign(&b->plan->rb, b->v, b->swap_parity);
}
