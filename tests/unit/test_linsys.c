/* tests/unit/test_linsys.c: the linear solves (src/solve/blocklu.c, src/solve/linsys.c)
 * against independent dense computations: random sparse matrices with a
 * hidden block triangular form (rows and columns shuffled), solved by the
 * dense-block LU and by KLU, checked against the residual of a dense
 * reference, their determinant's sign, and the condition numbers computed
 * from explicit inverses. Then every mechanism solved both ways. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "solve.h"
#include "helpers.h"
#include "mech.h"

enum { MAXN = 64 };

/* The measured figures, with MECH_HARD_VERBOSE set (as test_hard.c). */
static void note(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    note_tagged("linsys", fmt, ap);
    va_end(ap);
}

typedef struct sparse {
    int n;
    double a[MAXN * MAXN];     /* dense copy, row major */
    int Ap[MAXN + 1], Ai[MAXN * MAXN];
    double Ax[MAXN * MAXN];
    int R[MAXN + 1], nblocks;  /* the hidden blocks, before shuffling */
    int prow[MAXN], pcol[MAXN];  /* row i of a is row prow[i] of the block form */
} sparse;

static unsigned rng = 12345u;
static double uniform(void)  /* deterministic, in [-1, 1) */
{
    rng = rng * 1103515245u + 12345u;
    return ((rng >> 8) & 0xffffff) / (double)0x800000 - 1.0;
}

static void shuffle(int *p, int n)
{
    for (int i = 0; i < n; i++)
        p[i] = i;
    for (int i = n - 1; i > 0; i--) {
        int j = (int)((uniform() + 1.0) * 0.5 * (i + 1)) % (i + 1), t = p[i];
        p[i] = p[j], p[j] = t;
    }
}

/* Upper block triangular with the given block sizes, entries above the
 * blocks with probability 0.3, rows and columns shuffled, in CSC. */
static void make_matrix(sparse *s, const int *sizes, int nsizes)
{
    memset(s, 0, sizeof *s);
    int n = 0;
    for (int b = 0; b < nsizes; b++) {
        s->R[b] = n;
        n += sizes[b];
    }
    s->R[nsizes] = n;
    s->n = n;
    s->nblocks = nsizes;
    cr_assert_leq(n, MAXN);
    double form[MAXN * MAXN] = {0};
    for (int b = 0; b < nsizes; b++)
        for (int i = s->R[b]; i < s->R[b + 1]; i++) {
            for (int j = s->R[b]; j < s->R[b + 1]; j++)
                form[i * n + j] = uniform() + (i == j ? 0.5 : 0.0);
            for (int j = s->R[b + 1]; j < n; j++)
                if (uniform() < -0.4)
                    form[i * n + j] = 3.0 * uniform();
        }
    shuffle(s->prow, n);
    shuffle(s->pcol, n);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            s->a[i * n + j] = form[s->prow[i] * n + s->pcol[j]];
    int at = 0;
    for (int j = 0; j < n; j++) {
        s->Ap[j] = at;
        for (int i = 0; i < n; i++)
            if (s->a[i * n + j] != 0.0) {
                s->Ai[at] = i;
                s->Ax[at++] = s->a[i * n + j];
            }
    }
    s->Ap[n] = at;
}

/* Dense LU with partial pivoting of a copy (row major): solves b in place,
 * returns the determinant. */
static double dense_solve(const double *a0, int n, double *b)
{
    double a[MAXN * MAXN];
    memcpy(a, a0, sizeof(double) * (size_t)(n * n));
    double det = 1.0;
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(a[i * n + k]) > fabs(a[p * n + k]))
                p = i;
        if (p != k) {
            det = -det;
            for (int j = 0; j < n; j++) {
                double t = a[k * n + j];
                a[k * n + j] = a[p * n + j], a[p * n + j] = t;
            }
            if (b) {
                double t = b[k];
                b[k] = b[p], b[p] = t;
            }
        }
        det *= a[k * n + k];
        for (int i = k + 1; i < n; i++) {
            double l = a[i * n + k] / a[k * n + k];
            for (int j = k; j < n; j++)
                a[i * n + j] -= l * a[k * n + j];
            if (b)
                b[i] -= l * b[k];
        }
    }
    for (int k = n - 1; b && k >= 0; k--) {
        double t = b[k];
        for (int j = k + 1; j < n; j++)
            t -= a[k * n + j] * b[j];
        b[k] = t / a[k * n + k];
    }
    return det;
}

/* |A^-1|_1 of a dense row-major matrix, column by column. */
static double inverse_norm(const double *a, int n)
{
    double big = 0.0, e[MAXN];
    for (int j = 0; j < n; j++) {
        memset(e, 0, sizeof e);
        e[j] = 1.0;
        dense_solve(a, n, e);
        double s = 0.0;
        for (int i = 0; i < n; i++)
            s += fabs(e[i]);
        big = fmax(big, s);
    }
    return big;
}

static double column_norm(const sparse *s, int j)
{
    double t = 0.0;
    for (int i = 0; i < s->n; i++)
        t += fabs(s->a[i * s->n + j]);
    return t;
}

/* The blocks' reciprocal condition as blocklu defines it, from explicit
 * inverses of the hidden blocks: 1 / (|A(:,b)|_1 |A_bb^-1|_1), smallest. */
static double blocks_rcond(const sparse *s)
{
    int n = s->n, col_of[MAXN], row_of[MAXN];
    for (int i = 0; i < n; i++) {
        row_of[s->prow[i]] = i;
        col_of[s->pcol[i]] = i;
    }
    double worst = 1.0;
    for (int b = 0; b < s->nblocks; b++) {
        int k0 = s->R[b], k = s->R[b + 1] - k0;
        double blk[MAXN * MAXN], cn = 0.0;
        for (int i = 0; i < k; i++)
            for (int j = 0; j < k; j++)
                blk[i * k + j] = s->a[row_of[k0 + i] * n + col_of[k0 + j]];
        for (int j = 0; j < k; j++)
            cn = fmax(cn, column_norm(s, col_of[k0 + j]));
        worst = fmin(worst, 1.0 / (cn * inverse_norm(blk, k)));
    }
    return worst;
}

static double whole_rcond(const sparse *s)
{
    double an = 0.0;
    for (int j = 0; j < s->n; j++)
        an = fmax(an, column_norm(s, j));
    return 1.0 / (an * inverse_norm(s->a, s->n));
}

/* Hager's estimate of |A^-1|_1 with two iterations, as blocklu_rcond_whole
 * makes it, but from dense solves of A and A^T: x = 1/n, y = A^-1 x,
 * z = A^-T sign(y), then x = e_j at the first largest |z_j| and the larger
 * of the two |y|_1; a wrong transposed solve picks another vertex. */
static double hager_reference(const sparse *s)
{
    int n = s->n, j = 0;
    double at[MAXN * MAXN], y[MAXN], z[MAXN], est = 0.0;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < n; k++)
            at[k * n + i] = s->a[i * n + k];
    for (int i = 0; i < n; i++)
        y[i] = 1.0 / n;
    dense_solve(s->a, n, y);
    for (int i = 0; i < n; i++) {
        est += fabs(y[i]);
        z[i] = y[i] >= 0.0 ? 1.0 : -1.0;
    }
    dense_solve(at, n, z);
    for (int i = 0; i < n; i++)
        j = fabs(z[i]) > fabs(z[j]) ? i : j;
    memset(y, 0, sizeof y);
    y[j] = 1.0;
    dense_solve(s->a, n, y);
    double ny = 0.0;
    for (int i = 0; i < n; i++)
        ny += fabs(y[i]);
    return fmax(est, ny);
}

static void check_method(sparse *s, int method, const char *what)
{
    linsys_plan lp;
    linsys ls;
    cr_assert_eq(linsys_plan_init(&lp, s->n, s->Ap, s->Ai, method), 0, "%s: analysis", what);
    cr_assert_eq(linsys_init(&ls, &lp), 0, "%s: workspace", what);
    cr_assert_eq(linsys_factor(&ls, s->Ax), 0, "%s: factor", what);
    double x[MAXN], b[MAXN], ref[MAXN];
    for (int i = 0; i < s->n; i++)
        x[i] = b[i] = ref[i] = uniform();
    double det = dense_solve(s->a, s->n, ref);
    linsys_solve(&ls, x);
    double err = 0.0, big = 0.0;
    for (int i = 0; i < s->n; i++) {
        err = fmax(err, fabs(x[i] - ref[i]));
        big = fmax(big, fabs(ref[i]));
    }
    double rb, rw, exact_b = blocks_rcond(s), exact_w = whole_rcond(s);
    linsys_condition(&ls, s->Ax, &rb, &rw);
    note("%s: n = %d, %d blocks: |x - x_dense| %.2g (of %.2g); rcond blocks %.4g (exact "
         "%.4g), whole %.4g (exact %.4g)", what, s->n, s->nblocks, err, big, rb, exact_b, rw,
         exact_w);
    cr_assert_leq(err, 1e-12 * big / exact_w, "%s: solution off by %g", what, err);
    cr_assert_eq(linsys_det_sign(&ls), det > 0 ? 1 : -1, "%s: sign of det %g", what, det);
    /* Hager's estimates are lower bounds of the inverse's norm: rcond >= exact */
    cr_assert_geq(rw, exact_w * (1 - 1e-12), "%s: whole rcond %g below exact %g", what, rw,
                  exact_w);
    cr_assert_leq(rw, 10.0 * exact_w, "%s: whole rcond %g, exact %g", what, rw, exact_w);
    if (!lp.use_klu && lp.blu.nblocks > 1) {  /* the whole estimate: Hager's, step by step */
        double an = 0.0;
        for (int j = 0; j < s->n; j++)
            an = fmax(an, column_norm(s, j));
        double ref_w = 1.0 / (an * hager_reference(s));
        cr_assert(fabs(rw - ref_w) <= 1e-9 * ref_w, "%s: whole rcond %.17g, Hager from "
                  "dense solves %.17g", what, rw, ref_w);
    }
    if (!lp.use_klu) {
        int largest = 0;
        for (int k = 0; k < s->nblocks; k++)
            largest = s->R[k + 1] - s->R[k] > largest ? s->R[k + 1] - s->R[k] : largest;
        if (largest <= 8)  /* exact inverses */
            cr_assert(fabs(rb - exact_b) <= 1e-10 * exact_b, "%s: blocks rcond %.17g, exact "
                      "%.17g", what, rb, exact_b);
        else
            cr_assert(rb >= exact_b * (1 - 1e-12) && rb <= 10.0 * exact_b,
                      "%s: blocks rcond %g, exact %g", what, rb, exact_b);
        cr_assert_eq(lp.blu.nblocks, s->nblocks, "%s: %d blocks found, %d made", what,
                     lp.blu.nblocks, s->nblocks);
    }
    linsys_free(&ls);
    linsys_plan_free(&lp);
}

Test(linsys, random_block_triangular_matrices)
{
    static const int cases[][8] = {
        {1, 0}, {2, 0}, {1, 1, 2, 0}, {2, 2, 2, 2, 2, 0}, {3, 1, 5, 2, 0},
        {8, 2, 1, 0}, {12, 3, 0}, {16, 1, 2, 0}, {2, 6, 4, 7, 1, 1, 3, 0}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        int n = 0;
        while (cases[c][n])
            n++;
        for (int rep = 0; rep < 5; rep++) {
            sparse s;
            make_matrix(&s, cases[c], n);
            check_method(&s, MECH_LINEAR_AUTO, "dense blocks");
            check_method(&s, MECH_LINEAR_KLU, "KLU");
        }
    }
}

Test(linsys, large_block_goes_to_klu)
{
    static const int sizes[] = {2, BLOCKLU_MAX_BLOCK + 1, 3};
    sparse s;
    make_matrix(&s, sizes, 3);
    linsys_plan lp;
    cr_assert_eq(linsys_plan_init(&lp, s.n, s.Ap, s.Ai, MECH_LINEAR_AUTO), 0);
    cr_assert_eq(lp.use_klu, 1, "a %dx%d block is factored by KLU", BLOCKLU_MAX_BLOCK + 1,
                 BLOCKLU_MAX_BLOCK + 1);
    linsys_plan_free(&lp);
    check_method(&s, MECH_LINEAR_AUTO, "a large block");
    blocklu_plan bp;
    cr_assert_eq(blocklu_analyze(&bp, s.n, s.Ap, s.Ai, BLOCKLU_MAX_BLOCK), 2);
    blocklu_plan_free(&bp);
}

Test(linsys, singular_and_not_finite)
{
    static const int sizes[] = {2, 3, 1};
    sparse s;
    make_matrix(&s, sizes, 3);
    /* column 0 of the 3x3 block made a multiple of its column 1: a zero
       pivot, in that block */
    int n = s.n, col_of[MAXN], row_of[MAXN];
    for (int i = 0; i < n; i++) {
        row_of[s.prow[i]] = i;
        col_of[s.pcol[i]] = i;
    }
    int c0 = col_of[2], c1 = col_of[3];
    for (int r = 2; r < 5; r++)
        s.a[row_of[r] * n + c0] = 2.0 * s.a[row_of[r] * n + c1];
    for (int j = 0; j < n; j++)
        for (int p = s.Ap[j]; p < s.Ap[j + 1]; p++)
            s.Ax[p] = s.a[s.Ai[p] * n + j];
    blocklu_plan bp;
    blocklu b;
    cr_assert_eq(blocklu_analyze(&bp, n, s.Ap, s.Ai, BLOCKLU_MAX_BLOCK), 0);
    cr_assert_eq(blocklu_init(&b, &bp), 0);
    int rc = blocklu_factor(&b, s.Ax);
    double rb = rc == 0 ? blocklu_rcond(&b) : 0.0;
    note("singular 3x3 block: factor %d, singular column %d (made %d or %d), rcond %g", rc,
         b.singular_col, c0, c1, rb);
    cr_assert(rc < 0 || rb < 1e-14, "a singular block is found: factor %d, rcond %g", rc, rb);
    if (rc < 0) {
        int sc = b.singular_col;
        cr_assert(sc == c0 || sc == c1 || sc == col_of[4], "singular column %d", sc);
    }
    s.Ax[0] = NAN;
    cr_assert_lt(blocklu_factor(&b, s.Ax), 0, "a NaN entry is refused");
    blocklu_free(&b);
    blocklu_plan_free(&bp);
}

Test(linsys, structurally_singular)
{
    /* 3x3, column 2 empty */
    int Ap[] = {0, 2, 3, 3}, Ai[] = {0, 1, 2};
    blocklu_plan bp;
    cr_assert_eq(blocklu_analyze(&bp, 3, Ap, Ai, BLOCKLU_MAX_BLOCK), 1);
    blocklu_plan_free(&bp);
    linsys_plan lp;
    cr_assert_eq(linsys_plan_init(&lp, 3, Ap, Ai, MECH_LINEAR_AUTO), 1);
    linsys_plan_free(&lp);
}

/* Every mechanism gives the same table with dense blocks and with KLU (the
 * solution to about 1e-13 of each column's largest value). */
Test(linsys, mechanisms_dense_blocks_match_klu)
{
    static const char *const files[] = {
        "mechanisms/fourbar.yaml", "mechanisms/slider-crank.yaml", "mechanisms/stirling.yaml",
        "mechanisms/conveyor.yaml", "mechanisms/double-crank.yaml", "mechanisms/jansen.yaml",
        "mechanisms/quick-return.yaml", "mechanisms/watt-six-bar.yaml",
        "mechanisms/stephenson-six-bar.yaml", "mechanisms/offset-slider-crank.yaml"};
    for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
        mech_model *m = load_path(files[f]);
        mech_table t[2] = {{0}, {0}};
        for (int k = 0; k < 2; k++) {
            mech_solve_options o;
            mech_solve_options_default(&o);
            o.linear_solver = k ? MECH_LINEAR_KLU : MECH_LINEAR_AUTO;
            mech_diag d;
            mech_diag_init(&d);
            int rc = mech_solve(m, &o, &t[k], NULL, &d);
            cr_assert_eq(rc, MECH_OK, "%s", files[f]);
            mech_diag_free(&d);
        }
        cr_assert_eq(t[0].ncolumns, t[1].ncolumns);
        cr_assert_eq(t[0].nrows, t[1].nrows);
        double worst = 0.0;
        for (int c = 0; c < t[0].ncolumns; c++) {
            if (strstr(t[0].columns[c].name, "residual"))  /* rounding noise itself */
                continue;
            double big = 0.0, err = 0.0;
            for (int r = 0; r < t[0].nrows; r++) {
                big = fmax(big, fabs(mech_table_get(&t[1], r, c)));
                err = fmax(err, fabs(mech_table_get(&t[0], r, c) - mech_table_get(&t[1], r, c)));
            }
            if (big > 0.0)
                worst = fmax(worst, err / big);
            cr_assert_leq(err, 1e-12 * big + 1e-300, "%s: column %s differs by %g (of %g)",
                          files[f], t[0].columns[c].name, err, big);
        }
        note("%s: dense blocks and KLU agree to %.2g of each column's largest value", files[f],
             worst);
        mech_table_free(&t[0]);
        mech_table_free(&t[1]);
        mech_model_free(&m);
    }
}
