/* src/blocklu.h: LU factors of a square sparse matrix whose block
 * triangular form has only small diagonal blocks (docs/solver.md, section
 * "Linear solves"). Each diagonal block is stored dense and factored with
 * partial pivoting; the entries above the blocks stay sparse. Analysis
 * (blocklu_plan) and the factors (blocklu) are apart, like KLU's symbolic
 * and numeric objects; factor, solve and the condition estimate allocate
 * nothing. */
#ifndef MECH_BLOCKLU_H
#define MECH_BLOCKLU_H

/* Largest diagonal block factored dense: beyond it KLU is used (linsys.c). */
enum { BLOCKLU_MAX_BLOCK = 16 };

/* The analysis of a pattern: immutable once made, shared by every blocklu
 * factoring values of that pattern (one per thread). */
typedef struct blocklu_plan {
    int n, nblocks, largest;   /* order, number of blocks, largest block */
    int *P, *Q;                /* [n] A(P,Q) is upper block triangular (btf_order) */
    int *R;                    /* [nblocks+1] first row/column of each block */
    int *at;                   /* [nblocks] start of each block's dense storage in v */
    int nnz;
    int *where;                /* [nnz] slot in v of each entry of A (CSC order) */
    int nv;                    /* values: the dense blocks (ndense), then one slot per entry
                                  above the blocks */
    int *op, *oi;              /* [n+1], [above]: entries above the blocks, by permuted
                                  column: their permuted rows; values v[ndense + p] */
    int *oj;                   /* [above] the permuted column of each (a block's entries
                                  are op[R[k]] .. op[R[k+1]]-1: one loop for them) */
    int ndense;
    int dense_full;            /* every slot of the dense blocks is an entry of A (no
                                  structural zero to clear before factoring) */
    int pq_parity;             /* parity of P and Q together */
} blocklu_plan;

/* Factors of one matrix with an analysed pattern (per thread). */
typedef struct blocklu {
    const blocklu_plan *plan;  /* borrowed */
    double *v;                 /* [nv] block k x k column major, then the entries above */
    int *piv;                  /* [n] row swapped into each position within its block */
    double *anorm;             /* [nblocks] 1-norm of each block's columns (with the
                                  entries above the block) before factoring */
    double *colnorm;           /* [n] 1-norm of each column of A */
    double *w;                 /* [4 n + 3 largest] solve and estimator work */
    int swap_parity;           /* parity of the row swaps of the last factorisation */
    int singular_col;          /* column of A with a zero pivot, or -1 */
} blocklu;

/* Block triangular form of the pattern (Ap, Ai: CSC, n columns). Returns 0,
 * 1 when the pattern is structurally singular, 2 when some diagonal block is
 * larger than max_block (at most BLOCKLU_MAX_BLOCK), -1 when out of memory. */
int blocklu_analyze(blocklu_plan *b, int n, const int *Ap, const int *Ai, int max_block);
void blocklu_plan_free(blocklu_plan *b);
/* Workspace and factors for values of the plan's pattern; -1 when out of memory. */
int blocklu_init(blocklu *b, const blocklu_plan *plan);
void blocklu_free(blocklu *b);

/* Factor the values Ax (the analysed pattern). Returns 0, or -1 for a zero
 * pivot or a value that is not finite (b->singular_col says where). */
int blocklu_factor(blocklu *b, const double *Ax);
/* x := A^-1 x with the last factors. */
void blocklu_solve(blocklu *b, double *x);
/* Smallest reciprocal 1-norm condition of the diagonal blocks, each block's
 * inverse measured against its whole columns: 1 / (|A(:,b)|_1 |A_bb^-1|_1).
 * The inverse's norm is exact for blocks up to 8x8 (column by column),
 * Hager's estimate for larger ones. */
double blocklu_rcond(blocklu *b);
/* Reciprocal 1-norm condition of the whole A (Hager's estimate with whole
 * solves): with many blocks in a chain it can be far smaller than the
 * blocks', since errors pass from block to block. */
double blocklu_rcond_whole(blocklu *b);
/* Smallest |pivot| / largest column 1-norm of its block, over the blocks
 * (cheap: no solves; tiny at an exactly singular matrix). */
double blocklu_pivot_ratio(const blocklu *b);
/* Sign of det A: +1, -1, 0. */
int blocklu_det_sign(const blocklu *b);

#endif
