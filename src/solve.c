/* src/solve.c: the numerical core (docs/solver.md).
 *
 * Set-up, once per mechanism: choose the unknowns the outputs need (the
 * blocks of the block triangular form that contain them, and every block
 * those depend on), compile an evaluator of just those rows, and analyse
 * the pattern of their Jacobian (linsys.c: dense blocks or KLU).
 * Per driver position: Newton with damping on the closure residual, one
 * factorisation per iteration; then dx/dq and d2x/dq2 by two solves with
 * the converged factors. Columns are
 * equilibrated before every factorisation, so the condition estimate measures the
 * geometry, not the units. */
#include <btf.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "solve.h"

enum { PHASE_POSITION, PHASE_VELOCITY, PHASE_ACCELERATION, NPHASES };

/* A Newton step longer than this (rad, or lref for slides) is shortened:
 * beyond it the linearisation says little. */
static const double MAX_STEP = 1.0;

/* ---- set-up ------------------------------------------------------------ */

/* The length scale of tolerances and slide columns: the largest distance
 * between two points of one link (or of the ground). A link with many
 * points (a ground with 10^4 pivots) uses its bounding box's diagonal
 * instead, at most sqrt(2) larger, to stay linear in the size. */
static double largest_length(const mech_model *m)
{
    double L = 0.0;
    for (int l = 0; l < m->nlinks; l++) {
        const mech_link *k = &m->links[l];
        if (k->npoints > 64) {
            double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
            for (int i = 0; i < k->npoints; i++) {
                x0 = fmin(x0, k->points[i].x);
                x1 = fmax(x1, k->points[i].x);
                y0 = fmin(y0, k->points[i].y);
                y1 = fmax(y1, k->points[i].y);
            }
            L = fmax(L, hypot(x1 - x0, y1 - y0));
            continue;
        }
        for (int i = 0; i < k->npoints; i++) {
            if (l == 0)
                L = fmax(L, hypot(k->points[i].x, k->points[i].y));
            for (int j = i + 1; j < k->npoints; j++)
                L = fmax(L, hypot(k->points[i].x - k->points[j].x, k->points[i].y - k->points[j].y));
        }
    }
    return L > 0.0 ? L : 1.0;
}

/* Unknowns some output (or a branch condition) depends on. */
static void needed_unknowns(solver *sv, unsigned char *need)
{
    const mech_model *m = sv->m;
    const mech_outputs *o = &m->outputs;
    if (sv->opt.all_blocks || o->forces) {
        memset(need, 1, (size_t)sv->n);
        for (int l = 1; l < m->nlinks; l++)
            sv->tree.active[l] = 1;
        return;
    }
    for (int i = 0; i < o->npoints; i++)
        kin_need_point(&sv->tree, o->points[i], need);
    for (int i = 0; i < o->nlinks; i++)
        kin_need_link(&sv->tree, o->links[i], need);
    for (int i = 0; i < o->nsliders; i++) {
        int var = sv->tree.slide_var[o->sliders[i]];
        if (var >= 0 && var < sv->n)
            need[var] = 1;
    }
    for (int b = 0; b < m->nbranches; b++)
        for (int k = 0; k < 3; k++)
            kin_need_point(&sv->tree, m->branches[b].point[k], need);
}

/* Short name of an unknown for messages. */
static const char *unknown_name(const solver *sv, int var) { return sv->sys->names[var]; }

static void log_blocks(const solver *sv, const int *P, const int *Q, const int *R,
                       const unsigned char *solve_block, const unsigned char *need)
{
    FILE *log = sv->opt.log;
    fprintf(log, "blocks: %d unknowns in %d blocks of the block triangular form; solving %d\n",
            sv->n, sv->nblocks, sv->nblocks_solved);
    for (int b = sv->nblocks - 1; b >= 0; b--) {  /* solution order: last block first */
        int wanted = 0;
        for (int k = R[b]; k < R[b + 1]; k++)
            wanted |= need[Q[k]];
        fprintf(log, "  block %d (%d equation%s, loops", sv->nblocks - b, R[b + 1] - R[b],
                R[b + 1] - R[b] == 1 ? "" : "s");
        int last = -1;
        for (int k = R[b]; k < R[b + 1]; k++)
            if (P[k] / 2 != last)
                fprintf(log, " %d", (last = P[k] / 2) + 1);
        fprintf(log, "):");
        for (int k = R[b]; k < R[b + 1]; k++)
            fprintf(log, " %s", unknown_name(sv, Q[k]));
        fprintf(log, " -- %s\n", !solve_block[b] ? "skipped, no output needs it"
                                 : wanted        ? "solved, outputs need it"
                                                 : "solved, a needed block depends on it");
    }
}

/* Row-wise pattern of the Jacobian: columns of row r are rc[rp[r] .. rp[r+1]-1]. */
static int transpose_pattern(const mech_system *s, int n, int **rp, int **rc)
{
    int nnz = s->Jp[n];
    *rp = xcalloc((size_t)n + 1, sizeof **rp);
    *rc = xcalloc((size_t)nnz + 1, sizeof **rc);
    int *fill = xcalloc((size_t)n + 1, sizeof *fill);
    if (!*rp || !*rc || !fill) {
        free(fill);
        return -1;
    }
    for (int p = 0; p < nnz; p++)
        (*rp)[s->Ji[p] + 1]++;
    for (int r = 0; r < n; r++)
        (*rp)[r + 1] += (*rp)[r];
    for (int c = 0; c < n; c++)
        for (int p = s->Jp[c]; p < s->Jp[c + 1]; p++)
            (*rc)[(*rp)[s->Ji[p]] + fill[s->Ji[p]]++] = c;
    free(fill);
    return 0;
}

/* Blocks to solve: those holding a needed unknown, then (the form is upper
 * block triangular, rows of block b only reach columns of blocks >= b)
 * every block reached from a block already chosen. */
static int choose_blocks(solver *sv, const unsigned char *need, unsigned char *row_on,
                         unsigned char *col_on)
{
    const mech_system *s = sv->sys;
    int n = sv->n, nmatch = 0;
    int *P = xcalloc((size_t)n, sizeof *P), *Q = xcalloc((size_t)n, sizeof *Q);
    int *R = xcalloc((size_t)n + 1, sizeof *R), *W = xcalloc(5 * (size_t)n, sizeof *W);
    int *blk = xcalloc((size_t)n, sizeof *blk);
    unsigned char *solve_block = xcalloc((size_t)n + 1, 1);
    int *rp = NULL, *rc = NULL, status = -1;
    if (!P || !Q || !R || !W || !blk || !solve_block)
        goto done;
    double work;
    sv->nblocks = btf_order(n, s->Jp, s->Ji, 0.0, &work, P, Q, R, &nmatch, W);
    if (nmatch < n) {
        status = 1;  /* structurally singular: caller reports */
        goto done;
    }
    for (int b = 0; b < sv->nblocks; b++)
        for (int k = R[b]; k < R[b + 1]; k++) {
            blk[Q[k]] = b;       /* block of each unknown */
        }
    for (int v = 0; v < n; v++)
        if (need[v])
            solve_block[blk[v]] = 1;
    /* rows in block order: propagate from low blocks to the higher ones they
       reach, through the row-wise pattern (the transpose), in O(nnz) */
    if (transpose_pattern(s, n, &rp, &rc) < 0)
        goto done;
    for (int b = 0; b < sv->nblocks; b++) {
        if (!solve_block[b])
            continue;
        for (int k = R[b]; k < R[b + 1]; k++) {
            row_on[P[k]] = 1;
            for (int p = rp[P[k]]; p < rp[P[k] + 1]; p++)
                solve_block[blk[rc[p]]] = 1;
        }
    }
    sv->nblocks_solved = 0;
    for (int b = 0; b < sv->nblocks; b++)
        if (solve_block[b]) {
            sv->nblocks_solved++;
            for (int k = R[b]; k < R[b + 1]; k++)
                col_on[Q[k]] = 1;
        }
    if (sv->opt.log)
        log_blocks(sv, P, Q, R, solve_block, need);
    status = 0;
done:
    free(rp);
    free(rc);
    free(P);
    free(Q);
    free(R);
    free(W);
    free(blk);
    free(solve_block);
    return status;
}

/* The matrix of the least-squares mode: [I J; J^T 0] of size nr + ns,
 * whose solution [r; dx] minimises |J dx - f| (Gauss-Newton). jpos[2k] and
 * jpos[2k+1] are where J entry k goes (in J and in J^T). */
static int augmented_pattern(solver *sv, const int *Jp, const int *Ji)
{
    int nr = sv->nr, ns = sv->ns, nnz = sv->nnzJ, N = nr + ns;
    int *rp = xcalloc((size_t)nr + 1, sizeof *rp), *fill = xcalloc((size_t)nr + 1, sizeof *fill);
    int *rk = xcalloc((size_t)nnz + 1, sizeof *rk);   /* J entries by row */
    int *colof = xcalloc((size_t)nnz + 1, sizeof *colof);
    sv->Ap = xcalloc((size_t)N + 1, sizeof *sv->Ap);
    sv->Ai = xcalloc((size_t)(nr + 2 * nnz) + 1, sizeof *sv->Ai);
    sv->Ax = xcalloc((size_t)(nr + 2 * nnz) + 1, sizeof *sv->Ax);
    sv->jpos = xcalloc(2 * (size_t)nnz + 1, sizeof *sv->jpos);
    int rc = -1;
    if (!rp || !fill || !rk || !colof || !sv->Ap || !sv->Ai || !sv->Ax || !sv->jpos)
        goto done;
    for (int c = 0; c < ns; c++)
        for (int k = Jp[c]; k < Jp[c + 1]; k++)
            colof[k] = c;
    for (int k = 0; k < nnz; k++)
        rp[Ji[k] + 1]++;
    for (int r = 0; r < nr; r++)
        rp[r + 1] += rp[r];
    for (int c = 0; c < ns; c++)
        for (int k = Jp[c]; k < Jp[c + 1]; k++)
            rk[rp[Ji[k]] + fill[Ji[k]]++] = k;
    int at = 0;
    for (int r = 0; r < nr; r++) {  /* columns of the residual block: I, then J^T */
        sv->Ap[r] = at;
        sv->Ai[at] = r;
        sv->Ax[at++] = 1.0;
        for (int p = rp[r]; p < rp[r + 1]; p++) {
            int k = rk[p];
            sv->jpos[2 * k + 1] = at;
            sv->Ai[at++] = nr + colof[k];
        }
    }
    for (int c = 0; c < ns; c++) {  /* columns of the unknowns: J */
        sv->Ap[nr + c] = at;
        for (int k = Jp[c]; k < Jp[c + 1]; k++) {
            sv->jpos[2 * k] = at;
            sv->Ai[at++] = Ji[k];
        }
    }
    sv->Ap[N] = at;
    sv->N = N;
    sv->nnz = at;
    rc = 0;
done:
    free(rp);
    free(fill);
    free(rk);
    free(colof);
    return rc;
}

/* Pattern of the solved rows and columns, and the tape computing them. */
static int compile_subset(solver *sv, const unsigned char *row_on, const unsigned char *col_on)
{
    const mech_system *s = sv->sys;
    int n = sv->n, rows = s->m, ns = 0, nr = 0;
    int *rowmap = xcalloc((size_t)rows + 1, sizeof *rowmap);
    sv->col = xcalloc((size_t)n + 1, sizeof *sv->col);
    sv->row = xcalloc((size_t)rows + 1, sizeof *sv->row);
    int *Jp = xcalloc((size_t)n + 1, sizeof *Jp);
    if (!rowmap || !sv->col || !sv->row || !Jp) {
        free(rowmap);
        free(Jp);
        return -1;
    }
    for (int r = 0; r < rows; r++) {
        rowmap[r] = row_on[r] ? nr : -1;
        if (row_on[r])
            sv->row[nr++] = r;
    }
    for (int c = 0; c < n; c++)
        if (col_on[c])
            sv->col[ns++] = c;
    sv->ns = ns;
    sv->nr = nr;
    int nnz = 0;
    for (int k = 0; k < ns; k++)
        for (int p = s->Jp[sv->col[k]]; p < s->Jp[sv->col[k] + 1]; p++)
            nnz += rowmap[s->Ji[p]] >= 0;
    sv->nnzJ = nnz;
    int *Ji = xcalloc((size_t)nnz + 1, sizeof *Ji);
    sv->Jv = xcalloc((size_t)nnz + 1, sizeof *sv->Jv);
    sv->proot = xcalloc((size_t)(nr + nnz) + 1, sizeof *sv->proot);
    sv->vroot = xcalloc((size_t)nr + 1, sizeof *sv->vroot);
    sv->aroot = xcalloc((size_t)nr + 1, sizeof *sv->aroot);
    if (!Ji || !sv->Jv || !sv->proot || !sv->vroot || !sv->aroot) {
        free(rowmap);
        free(Jp);
        free(Ji);
        return -1;
    }
    for (int i = 0; i < nr; i++) {
        sv->proot[i] = s->f[sv->row[i]];
        sv->vroot[i] = s->vel[sv->row[i]];
        sv->aroot[i] = s->acc[sv->row[i]];
    }
    int at = 0;
    for (int k = 0; k < ns; k++) {
        Jp[k] = at;
        for (int p = s->Jp[sv->col[k]]; p < s->Jp[sv->col[k] + 1]; p++)
            if (rowmap[s->Ji[p]] >= 0) {
                Ji[at] = rowmap[s->Ji[p]];
                sv->proot[nr + at++] = s->Jx[p];
            }
    }
    Jp[ns] = at;
    free(rowmap);
    int rc = 0;
    if (sv->aug) {
        rc = augmented_pattern(sv, Jp, Ji);
        free(Jp);
        free(Ji);
    } else {  /* square: J itself is factored */
        sv->Ap = Jp;
        sv->Ai = Ji;
        sv->Ax = xcalloc((size_t)nnz + 1, sizeof *sv->Ax);
        sv->N = ns;
        sv->nnz = nnz;
        rc = sv->Ax ? 0 : -1;
    }
    if (rc < 0)
        return -1;
    const ex *roots[NPHASES] = {sv->proot, sv->vroot, sv->aroot};
    int nroots[NPHASES] = {nr + nnz, nr, nr};
    /* dx/dq and d2x/dq2 feed the predictor even for positions only: all three
       phases (two solves with factors already there cost less than the
       Newton iteration a second-order predictor needs) */
    if (tape_compile(&sv->tp, &sv->sys->ex, SYS_NVARS(n), NPHASES, roots, nroots) < 0)
        return -1;
    /* what depends on the driver alone (its sines and cosines, the crank's
       terms) is computed once per position, not per Newton iteration */
    unsigned char *invariant = xcalloc((size_t)SYS_NVARS(n), 1);
    if (!invariant)
        return -1;
    invariant[SYS_VAR_Q(n)] = 1;
    tape_hoist(&sv->tp, PHASE_POSITION, invariant);
    free(invariant);
    sv->tape_q = NAN;
    return 0;
}

static int alloc_state(solver *sv)
{
    size_t n1 = (size_t)sv->n + 1, ns = (size_t)sv->ns + 1, nr = (size_t)sv->nr + 1;
    sv->pos = xcalloc(n1, sizeof *sv->pos);
    sv->vel = xcalloc(n1, sizeof *sv->vel);
    sv->acc = xcalloc(n1, sizeof *sv->acc);
    sv->x = xcalloc(ns, sizeof *sv->x);
    sv->xq = xcalloc(ns, sizeof *sv->xq);
    sv->xqq = xcalloc(ns, sizeof *sv->xqq);
    sv->f = xcalloc(nr, sizeof *sv->f);
    sv->dx = xcalloc(ns, sizeof *sv->dx);
    sv->xt = xcalloc(ns, sizeof *sv->xt);
    sv->ft = xcalloc(nr, sizeof *sv->ft);
    sv->rhs = xcalloc(nr + ns, sizeof *sv->rhs);
    sv->cscale = xcalloc(ns, sizeof *sv->cscale);
    if (!sv->pos || !sv->vel || !sv->acc || !sv->x || !sv->xq || !sv->xqq || !sv->f ||
        !sv->dx || !sv->xt || !sv->ft || !sv->rhs || !sv->cscale)
        return -1;
    return kin_state_init(&sv->ks, sv->m) == MECH_OK ? 0 : -1;
}

static int level_of(int want)
{
    if (want & MECH_WANT_ACCELERATION)
        return MECH_WANT_ALL;
    if (want & MECH_WANT_VELOCITY)
        return MECH_WANT_POSITION | MECH_WANT_VELOCITY;
    return MECH_WANT_POSITION;
}

int solver_init(solver *sv, const mech_model *m, const mech_solve_options *o, mech_diag *d)
{
    memset(sv, 0, sizeof *sv);
    sv->published = -1;
    sv->m = m;
    sv->opt = *o;
    sv->level = level_of(o->want ? o->want : MECH_WANT_ALL);
    int rc = mech_system_new(m, &sv->sys, d);
    if (rc != MECH_OK)
        return rc;
    sv->n = sv->sys->n;
    sv->lref = largest_length(m);
    if (!(sv->opt.tol > 0.0))
        sv->opt.tol = 1e-12;
    if (!(sv->opt.min_rcond > 0.0))
        sv->opt.min_rcond = 1e-6;
    sv->ftol = sv->opt.tol * sv->lref;
    if (kin_tree_build(&sv->tree, sv->sys) != MECH_OK)
        return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    int rows = sv->sys->m;
    unsigned char *need = xcalloc((size_t)sv->n + 1, 1), *row_on = xcalloc((size_t)rows + 1, 1),
                  *col_on = xcalloc((size_t)sv->n + 1, 1);
    rc = MECH_ENOMEM;
    sv->aug = rows > sv->n;
    if (need && row_on && col_on) {
        needed_unknowns(sv, need);
        int b = 0;
        if (sv->aug) {  /* redundant equations: no square block form; solve everything */
            memset(row_on, 1, (size_t)rows);
            memset(col_on, 1, (size_t)sv->n);
            for (int l = 1; l < m->nlinks; l++)
                sv->tree.active[l] = 1;
            sv->nblocks = sv->nblocks_solved = 1;
            if (sv->opt.log)
                fprintf(sv->opt.log, "blocks: %d equations for %d unknowns (redundant "
                        "constraints): all solved together, in the least-squares sense\n",
                        rows, sv->n);
        } else {
            b = choose_blocks(sv, need, row_on, col_on);
        }
        if (b > 0)
            rc = diag_error(d, m->file, m->driver.mark,
                            "the loop equations are structurally singular: some unknown "
                            "appears in no equation that could determine it (see 'mech equations')");
        else if (b == 0 && compile_subset(sv, row_on, col_on) == 0 && alloc_state(sv) == 0)
            rc = MECH_OK;
    }
    free(need);
    free(row_on);
    free(col_on);
    if (rc == MECH_ENOMEM)
        return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    if (rc != MECH_OK)
        return rc;
    if (sv->ns > 0 && linsys_init(&sv->ls, sv->N, sv->Ap, sv->Ai, sv->opt.linear_solver) != 0)
        return diag_error(d, m->file, (mech_mark){0, 0}, "cannot analyse the Jacobian "
                          "(out of memory)"), MECH_ENOMEM;
    if (sv->opt.log) {
        char method[96];
        fprintf(sv->opt.log, "linear solves: %s\n",
                sv->ns > 0 ? linsys_method_name(&sv->ls, method, sizeof method) : "none");
    }
    return MECH_OK;
}

void solver_free(solver *sv)
{
    linsys_free(&sv->ls);
    tape_free(&sv->tp);
    kin_state_free(&sv->ks);
    kin_tree_free(&sv->tree);
    mech_system_free(&sv->sys);
    void *blocks[] = {sv->col, sv->row, sv->Ap, sv->Ai, sv->Ax, sv->Jv, sv->jpos, sv->rhs,
                      sv->cscale, sv->proot,
                      sv->vroot, sv->aroot, sv->pos, sv->vel, sv->acc, sv->x, sv->xq,
                      sv->xqq, sv->f, sv->dx, sv->xt, sv->ft};
    for (size_t i = 0; i < sizeof blocks / sizeof blocks[0]; i++)
        free(blocks[i]);
    memset(sv, 0, sizeof *sv);
}

/* ---- one driver position ------------------------------------------------ */

/* (fmax is a library call at -O2, and would drop a NaN: here a NaN
 * entry makes the norm NaN.) */
double vec_norm_inf(const double *v, int n)
{
    double r = 0.0;
    for (int i = 0; i < n; i++) {
        double a = fabs(v[i]);
        r = a > r || a != a ? a : r;
    }
    return r;
}

/* Size of a change of the unknowns: angles in rad, slides in units of lref. */
double solver_step_size(const solver *sv, const double *dx)
{
    double r = 0.0;
    for (int i = 0; i < sv->ns; i++) {
        double v = fabs(dx[i]);
        if (sv->sys->unk_kind[sv->col[i]] == UNK_SLIDE)
            v /= sv->lref;
        r = v > r || v != v ? v : r;
    }
    return r;
}

/* f (and the raw Jacobian in Ax) at x, q; returns |f|inf. */
static double evaluate(solver *sv, const double *x, double q, double *f)
{
    tape *t = &sv->tp;
    if (!(q == sv->tape_q)) {
        tape_set_var(t, SYS_VAR_Q(sv->n), q);
        tape_run_invariant(t, PHASE_POSITION);
        sv->tape_q = q;
    }
    for (int i = 0; i < sv->ns; i++)
        tape_set_var(t, sv->col[i], x[i]);
    tape_run_variant(t, PHASE_POSITION);
    for (int i = 0; i < sv->nr; i++)
        f[i] = tape_value(t, sv->proot[i]);
    for (int k = 0; k < sv->nnzJ; k++)
        sv->Jv[k] = tape_value(t, sv->proot[sv->nr + k]);
    return vec_norm_inf(f, sv->nr);
}

/* Scale every column of J to unit largest entry (J C), remembering C, and
 * place the values in the factored matrix (J itself, or [I JC; (JC)^T 0]). */
static void equilibrate(solver *sv)
{
    const int *Jp = sv->aug ? sv->Ap + sv->nr : sv->Ap;  /* column starts of J's entries */
    int k = 0;
    for (int c = 0; c < sv->ns; c++) {
        int len = sv->aug ? Jp[c + 1] - Jp[c] : sv->Ap[c + 1] - sv->Ap[c];
        double big = 0.0;
        for (int p = 0; p < len; p++)
            big = fabs(sv->Jv[k + p]) > big ? fabs(sv->Jv[k + p]) : big;
        double cs = big > 0.0 && isfinite(big) ? 1.0 / big : 1.0;
        sv->cscale[c] = cs;
        for (int p = 0; p < len; p++, k++) {
            double v = sv->Jv[k] * cs;
            if (sv->aug) {
                sv->Ax[sv->jpos[2 * k]] = v;
                sv->Ax[sv->jpos[2 * k + 1]] = v;
            } else {
                sv->Ax[k] = v;
            }
        }
    }
}

/* Factor the Jacobian of the last evaluation, columns equilibrated. */
static int factor(solver *sv)
{
    equilibrate(sv);
    return linsys_factor(&sv->ls, sv->Ax);
}

/* Reciprocal 1-norm condition of the equilibrated Jacobian at the current
 * factors (docs/solver.md, section 4). */
static double condition(solver *sv)
{
    linsys_condition(&sv->ls, sv->Ax, &sv->rcond, &sv->rcond_whole);
    return sv->rcond;
}

/* dx from J dx = b (b has nr entries, dx ns): with the factors of J, or in
 * the least-squares sense through [I J; J^T 0] [r; y] = [b; 0]; the column
 * scaling is undone. */
static void linear_solve(solver *sv, const double *b, double *dx)
{
    double *w = sv->rhs;
    memcpy(w, b, (size_t)sv->nr * sizeof *w);
    for (int i = sv->nr; i < sv->N; i++)
        w[i] = 0.0;
    linsys_solve(&sv->ls, w);
    const double *y = sv->aug ? w + sv->nr : w;
    for (int i = 0; i < sv->ns; i++)
        dx[i] = y[i] * sv->cscale[i];
}

step_status solver_newton(solver *sv, double q)
{
    sv->generation++;  /* x changes: what was published is stale */
    int ns = sv->ns;
    sv->iters = 0;
    if (ns == 0) {
        sv->resid = 0.0;
        sv->rcond = 1.0;
        return STEP_OK;
    }
    double r = evaluate(sv, sv->x, q, sv->f), prev_step = INFINITY;
    int max_iter = sv->opt.max_iter > 0 ? sv->opt.max_iter : 50;
    /* Converged when the correction is below tol/100, or below its
       rounding floor, eps over the whole Jacobian's condition (from the
       previous position). The correction is applied to x (its error is then
       of the order of its square), but the factors, and so the rates, stay
       those of x before it: less than tol/100 away, which moves the rates
       by about that relative to the condition (docs/solver.md, section 2). */
    double xtol = 1e-2 * sv->opt.tol;
    for (int it = 0;; it++) {
        if (!isfinite(r))
            return STEP_NO_ASSEMBLY;
        if (factor(sv) < 0)
            return STEP_SINGULAR;
        if (!(sv->rcond > 0.0))  /* the first factorisation: a condition for the floor */
            condition(sv);
        if (it == 0)
            xtol = fmax(1e-2 * sv->opt.tol, DBL_EPSILON / fmax(sv->rcond_whole, 1e-300));
        linear_solve(sv, sv->f, sv->dx);
        double step = solver_step_size(sv, sv->dx);
        /* converged: residual small, and the step too, or no longer shrinking
           (the rounding floor of an ill-conditioned position) */
        if (r <= sv->ftol && (step <= xtol || step >= 0.9 * prev_step)) {
            sv->resid = r;
            sv->iters = it;
            if (step <= xtol)  /* a real (not noise) correction: take it */
                for (int i = 0; i < ns; i++)
                    sv->x[i] -= sv->dx[i];
            return condition(sv) < sv->opt.min_rcond ? STEP_SINGULAR : STEP_OK;
        }
        if (it == max_iter) {
            sv->resid = r;
            sv->iters = it;
            return STEP_NO_ASSEMBLY;
        }
        double lambda = step > MAX_STEP ? MAX_STEP / step : 1.0, rt;
        for (;;) {  /* damping: halve the step while the residual grows */
            for (int i = 0; i < ns; i++)
                sv->xt[i] = sv->x[i] - lambda * sv->dx[i];
            rt = evaluate(sv, sv->xt, q, sv->ft);
            if (rt <= r || rt <= sv->ftol || lambda < 1.0 / 1024)
                break;
            lambda *= 0.5;
        }
        memcpy(sv->x, sv->xt, (size_t)ns * sizeof *sv->x);
        memcpy(sv->f, sv->ft, (size_t)sv->nr * sizeof *sv->f);
        r = rt;
        prev_step = lambda == 1.0 ? step : INFINITY;
        sv->iters = it + 1;
    }
}

int solver_det_sign(solver *sv)
{
    /* the column scaling is positive: the sign is that of the factors */
    return sv->N == 0 ? 1 : linsys_det_sign(&sv->ls);
}

void solver_velocity_rhs(solver *sv, double *out)
{
    tape *t = &sv->tp;
    tape_set_var(t, SYS_VAR_QDOT(sv->n), 1.0);
    tape_run(t, PHASE_VELOCITY);
    for (int i = 0; i < sv->nr; i++)
        out[i] = tape_value(t, sv->vroot[i]);
}

void solver_rates(solver *sv)
{
    sv->generation++;
    if (sv->ns == 0)
        return;
    tape *t = &sv->tp;
    /* geometric rates (qdot = 1, qddot = 0); solver_publish scales them */
    solver_velocity_rhs(sv, sv->ft);
    linear_solve(sv, sv->ft, sv->xq);
    for (int i = 0; i < sv->ns; i++)
        tape_set_var(t, SYS_VAR_XDOT(sv->n, sv->col[i]), sv->xq[i]);
    tape_set_var(t, SYS_VAR_QDDOT(sv->n), 0.0);
    tape_run(t, PHASE_ACCELERATION);
    for (int i = 0; i < sv->nr; i++)
        sv->ft[i] = tape_value(t, sv->aroot[i]);
    linear_solve(sv, sv->ft, sv->xqq);
}

/* xdot = x_q qd and xddot = x_qq qd^2 + x_q qdd (the loop equations do not
 * depend on time explicitly). */
void solver_publish(solver *sv, double q, double qd, double qdd)
{
    /* the same state published again (the branch check, then the row) */
    if (sv->published == sv->generation && q == sv->pub_q && qd == sv->pub_qd &&
        qdd == sv->pub_qdd)
        return;
    sv->published = sv->generation;
    sv->pub_q = q, sv->pub_qd = qd, sv->pub_qdd = qdd;
    int n = sv->n;
    sv->pos[n] = q;
    sv->vel[n] = qd;
    sv->acc[n] = qdd;
    for (int i = 0; i < sv->ns; i++) {
        int c = sv->col[i];
        sv->pos[c] = sv->x[i];
        sv->vel[c] = sv->xq[i] * qd;
        sv->acc[c] = sv->xqq[i] * qd * qd + sv->xq[i] * qdd;
    }
    kin_update(&sv->tree, &sv->ks, sv->pos,
               sv->level & MECH_WANT_VELOCITY ? sv->vel : NULL,
               sv->level & MECH_WANT_ACCELERATION ? sv->acc : NULL);
}



