/* src/solve/solve.c: the numerical core (docs/solver.md).
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
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"
#include "rt_newton.h"
#include "solve.h"

enum { PHASE_POSITION, PHASE_VELOCITY, PHASE_ACCELERATION, NPHASES };

/* ---- set-up ------------------------------------------------------------ */

/* The length scale of tolerances and slide columns: the largest distance
 * between two points of one link (or of the ground). A link with many
 * points (a ground with 10^4 pivots) uses its bounding box's diagonal
 * instead, at most sqrt(2) larger, to stay linear in the size. */
double solver_largest_length(const mech_model *m)
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
static void needed_unknowns(solver_plan *sp, unsigned char *need)
{
    const mech_model *m = sp->m;
    const mech_outputs *o = sp->opt.outputs ? sp->opt.outputs : &m->outputs;
    if (sp->opt.all_blocks) {
        memset(need, 1, (size_t)sp->n);
        for (int l = 1; l < m->nlinks; l++)
            sp->tree.active[l] = 1;
        return;
    }
    for (int i = 0; i < o->npoints; i++)
        kin_need_point(&sp->tree, o->points[i], need);
    for (int i = 0; i < o->nlinks; i++)
        kin_need_link(&sp->tree, o->links[i], need);
    for (int i = 0; i < o->nsliders; i++) {
        int var = sp->tree.slide_var[o->sliders[i]];
        if (var >= 0 && var < sp->n)
            need[var] = 1;
    }
    for (int k = 0; k < m->ndrivers; k++) {  /* their columns are always output */
        const mech_motion *mo = &m->drivers[k];
        int var = mo->kind == MECH_DRIVE_SLIDER ? sp->tree.slide_var[mo->index] : -1;
        if (mo->kind == MECH_DRIVE_ANGLE)
            kin_need_link(&sp->tree, mo->index, need);
        else if (var >= 0 && var < sp->n)
            need[var] = 1;
    }
    for (int b = 0; b < m->nbranches; b++) {
        const mech_branch *br = &m->branches[b];
        int var = br->kind == MECH_BRANCH_SLIDER ? sp->tree.slide_var[br->slider] : -1;
        if (var >= 0 && var < sp->n)
            need[var] = 1;
        for (int k = 0; k < 3 && br->kind != MECH_BRANCH_SLIDER; k++)
            kin_need_point(&sp->tree, br->point[k], need);
    }
}

/* Short name of an unknown for messages. */
static const char *unknown_name(const solver_plan *sp, int var) { return sp->sys->names[var]; }

static void log_blocks(const solver_plan *sp, const int *P, const int *Q, const int *R,
                       const unsigned char *solve_block, const unsigned char *need)
{
    FILE *log = sp->opt.log;
    fprintf(log, "blocks: %d unknowns in %d blocks of the block triangular form; solving %d\n",
            sp->n, sp->nblocks, sp->nblocks_solved);
    for (int b = sp->nblocks - 1; b >= 0; b--) {  /* solution order: last block first */
        int wanted = 0;
        for (int k = R[b]; k < R[b + 1]; k++)
            wanted |= need[Q[k]];
        fprintf(log, "  block %d (%d equation%s, loops", sp->nblocks - b, R[b + 1] - R[b],
                R[b + 1] - R[b] == 1 ? "" : "s");
        int last = -1;
        for (int k = R[b]; k < R[b + 1]; k++)
            if (P[k] / 2 != last)
                fprintf(log, " %d", (last = P[k] / 2) + 1);
        fprintf(log, "):");
        for (int k = R[b]; k < R[b + 1]; k++)
            fprintf(log, " %s", unknown_name(sp, Q[k]));
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
static int choose_blocks(solver_plan *sp, const unsigned char *need, unsigned char *row_on,
                         unsigned char *col_on)
{
    const mech_system *s = sp->sys;
    int n = sp->n, nmatch = 0;
    int *P = xcalloc((size_t)n, sizeof *P), *Q = xcalloc((size_t)n, sizeof *Q);
    int *R = xcalloc((size_t)n + 1, sizeof *R), *W = xcalloc(5 * (size_t)n, sizeof *W);
    int *blk = xcalloc((size_t)n, sizeof *blk);
    unsigned char *solve_block = xcalloc((size_t)n + 1, 1);
    int *rp = NULL, *rc = NULL, status = -1;
    if (!P || !Q || !R || !W || !blk || !solve_block)
        goto done;
    double work;
    sp->nblocks = btf_order(n, s->Jp, s->Ji, 0.0, &work, P, Q, R, &nmatch, W);
    if (nmatch < n) {
        status = 1;  /* structurally singular: caller reports */
        goto done;
    }
    for (int b = 0; b < sp->nblocks; b++)
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
    for (int b = 0; b < sp->nblocks; b++) {
        if (!solve_block[b])
            continue;
        for (int k = R[b]; k < R[b + 1]; k++) {
            row_on[P[k]] = 1;
            for (int p = rp[P[k]]; p < rp[P[k] + 1]; p++)
                solve_block[blk[rc[p]]] = 1;
        }
    }
    sp->nblocks_solved = 0;
    for (int b = 0; b < sp->nblocks; b++)
        if (solve_block[b]) {
            sp->nblocks_solved++;
            for (int k = R[b]; k < R[b + 1]; k++)
                col_on[Q[k]] = 1;
        }
    if (sp->opt.log)
        log_blocks(sp, P, Q, R, solve_block, need);
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
static int augmented_pattern(solver_plan *sp, const int *Jp, const int *Ji)
{
    int nr = sp->nr, ns = sp->ns, nnz = sp->nnzJ, N = nr + ns;
    int *rp = xcalloc((size_t)nr + 1, sizeof *rp), *fill = xcalloc((size_t)nr + 1, sizeof *fill);
    int *rk = xcalloc((size_t)nnz + 1, sizeof *rk);   /* J entries by row */
    int *colof = xcalloc((size_t)nnz + 1, sizeof *colof);
    sp->Ap = xcalloc((size_t)N + 1, sizeof *sp->Ap);
    sp->Ai = xcalloc((size_t)(nr + 2 * nnz) + 1, sizeof *sp->Ai);
    sp->Ax0 = xcalloc((size_t)(nr + 2 * nnz) + 1, sizeof *sp->Ax0);
    sp->jpos = xcalloc(2 * (size_t)nnz + 1, sizeof *sp->jpos);
    int rc = -1;
    if (!rp || !fill || !rk || !colof || !sp->Ap || !sp->Ai || !sp->Ax0 || !sp->jpos)
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
        sp->Ap[r] = at;
        sp->Ai[at] = r;
        sp->Ax0[at++] = 1.0;
        for (int p = rp[r]; p < rp[r + 1]; p++) {
            int k = rk[p];
            sp->jpos[2 * k + 1] = at;
            sp->Ai[at++] = nr + colof[k];
        }
    }
    for (int c = 0; c < ns; c++) {  /* columns of the unknowns: J */
        sp->Ap[nr + c] = at;
        for (int k = Jp[c]; k < Jp[c + 1]; k++) {
            sp->jpos[2 * k] = at;
            sp->Ai[at++] = Ji[k];
        }
    }
    sp->Ap[N] = at;
    sp->N = N;
    sp->nnz = at;
    rc = 0;
done:
    free(rp);
    free(fill);
    free(rk);
    free(colof);
    return rc;
}

/* Where the tape computes cos and sin of a link's angle itself (a body
 * vector along the link's x axis), the link frame takes them from its
 * registers (solver_publish) instead of calling sincos again: the same
 * function of the same argument, so the same values. */
static int frame_registers(solver_plan *sp)
{
    const tape *t = &sp->tp;
    const expr_ctx *c = &sp->sys->ex;
    int nlinks = sp->sys->model->nlinks;
    sp->csreg = xcalloc(4 * (size_t)nlinks + 1, sizeof *sp->csreg);
    if (!sp->csreg)
        return -1;
    sp->ncs = 0;
    for (int l = 0; l < nlinks; l++) {
        int var = sp->tree.angle_var[l], *r = sp->csreg + 4 * sp->ncs;
        ex v = var >= 0 ? expr_find(c, EX_VAR, var, -1, -1, 0.0) : -1;
        ex cs = v >= 0 ? expr_find(c, EX_COS, -1, v, -1, 0.0) : -1;
        ex sn = v >= 0 ? expr_find(c, EX_SIN, -1, v, -1, 0.0) : -1;
        r[0] = l;
        r[1] = var >= 0 && var < t->nvars ? t->var_reg[var] : -1;
        r[2] = cs >= 0 && (size_t)cs < t->nnodes ? t->node_reg[cs] : -1;
        r[3] = sn >= 0 && (size_t)sn < t->nnodes ? t->node_reg[sn] : -1;
        if (v >= 0 && r[1] >= 0 && r[2] >= 0 && r[3] >= 0)
            sp->ncs++;
    }
    return 0;
}

/* Of frame_registers' list, the frames kin_update computes cos and sin of
 * (kin_tree_finish has chosen them). */
static void frame_registers_used(solver_plan *sp)
{
    int k = 0;
    for (int i = 0; sp->csreg && i < sp->ncs; i++)
        if (sp->tree.keep_cs[sp->csreg[4 * i]])
            memmove(sp->csreg + 4 * k++, sp->csreg + 4 * i, 4 * sizeof *sp->csreg);
    sp->ncs = k;
}

/* Where the per-step code reads and writes the tape's registers, looked up
 * once here instead of through the node and variable maps at every step. */
static int root_registers(solver_plan *sp)
{
    const tape *t = &sp->tp;
    int nr = sp->nr, ns = sp->ns, n = sp->n;
    sp->preg = xcalloc((size_t)(nr + sp->nnzJ) + 1, sizeof *sp->preg);
    sp->vreg = xcalloc((size_t)nr + 1, sizeof *sp->vreg);
    sp->areg = xcalloc((size_t)nr + 1, sizeof *sp->areg);
    sp->xreg = xcalloc((size_t)ns + 1, sizeof *sp->xreg);
    sp->xdreg = xcalloc((size_t)ns + 1, sizeof *sp->xdreg);
    if (!sp->preg || !sp->vreg || !sp->areg || !sp->xreg || !sp->xdreg)
        return -1;
    for (int i = 0; i < nr + sp->nnzJ; i++)
        sp->preg[i] = t->node_reg[sp->proot[i]];
    for (int i = 0; i < nr; i++) {
        sp->vreg[i] = t->node_reg[sp->vroot[i]];
        sp->areg[i] = t->node_reg[sp->aroot[i]];
    }
    for (int i = 0; i < ns; i++) {
        sp->xreg[i] = t->var_reg[sp->col[i]];
        sp->xdreg[i] = t->var_reg[SYS_VAR_XDOT(n, sp->col[i])];
    }
    return frame_registers(sp);
}

/* ---- the numbers ---------------------------------------------------------- */

int solver_numbers_alloc(solver_plan *sp)
{
    sp->nleaf = sp->sys->nvars - SYS_NVARS(sp->n);
    sp->unit = xcalloc((size_t)sp->ns + 1, sizeof *sp->unit);
    sp->leaf = sp->nleaf ? xcalloc((size_t)sp->nleaf, sizeof *sp->leaf) : NULL;
    sp->tree.attach = xcalloc(4 * (size_t)sp->sys->model->nlinks + 1, sizeof *sp->tree.attach);
    return sp->unit && (sp->leaf || !sp->nleaf) && sp->tree.attach ? 0 : -1;
}

void solver_numbers_free(solver_plan *sp)
{
    free(sp->unit);
    free(sp->leaf);
    free(sp->tree.attach);
    sp->unit = sp->leaf = sp->tree.attach = NULL;
}

void solver_plan_numbers(solver_plan *sp, const mech_model *m)
{
    sp->m = m;
    sp->lref = solver_largest_length(m);
    sp->ftol = sp->opt.tol * sp->lref;
    for (int i = 0; i < sp->ns; i++)  /* step sizes: angles in rad, slides in lref */
        sp->unit[i] = sp->sys->unk_kind[sp->col[i]] == UNK_SLIDE ? sp->lref : 1.0;
    for (int k = 0; k < sp->nleaf; k++)
        sp->leaf[k] = sys_leaf_value(sp->sys, m, SYS_NVARS(sp->n) + k);
    kin_tree_numbers(&sp->tree, m);
}

/* The tape of the solved rows: the residuals and Jacobian entries, then the
 * velocity and acceleration right-hand sides, with the part that depends
 * on the driver alone hoisted. */
static int compile_tape(solver_plan *sp)
{
    int n = sp->n, nr = sp->nr;
    const ex *roots[NPHASES] = {sp->proot, sp->vroot, sp->aroot};
    int nroots[NPHASES] = {nr + sp->nnzJ, nr, nr};
    /* dx/dq and d2x/dq2 feed the predictor even for positions only: all three
       phases (two solves with factors already there cost less than the
       Newton iteration a second-order predictor needs) */
    int nv = sp->sys->nvars;  /* SYS_NVARS(n), and a polar system's leaves */
    if (tape_compile(&sp->tp, &sp->sys->ex, nv, NPHASES, roots, nroots) < 0)
        return -1;
    /* what depends on the driver alone (its sines and cosines, the crank's
       terms) is computed once per position, not per Newton iteration */
    unsigned char *invariant = xcalloc((size_t)nv, 1);
    if (!invariant)
        return -1;
    invariant[SYS_VAR_Q(n)] = 1;
    memset(invariant + SYS_NVARS(n), 1, (size_t)(nv - SYS_NVARS(n)));  /* fixed per sweep */
    tape_hoist(&sp->tp, PHASE_POSITION, invariant);
    free(invariant);
    if (tape_fuse(&sp->tp, roots, nroots) < 0)
        return -1;
    return root_registers(sp);
}

/* The solved rows (row) and columns (col); rowmap[r]: solved index of
 * equation r, or -1. */
static int choose_subset(solver_plan *sp, const unsigned char *row_on,
                         const unsigned char *col_on, int *rowmap)
{
    int n = sp->n, rows = sp->sys->m;
    sp->col = xcalloc((size_t)n + 1, sizeof *sp->col);
    sp->row = xcalloc((size_t)rows + 1, sizeof *sp->row);
    if (!sp->col || !sp->row)
        return -1;
    for (int r = 0; r < rows; r++) {
        rowmap[r] = row_on[r] ? sp->nr : -1;
        if (row_on[r])
            sp->row[sp->nr++] = r;
    }
    for (int c = 0; c < n; c++)
        if (col_on[c])
            sp->col[sp->ns++] = c;
    return 0;
}

/* The Jacobian of the solved subset (CSC: Jp, Ji) and the roots of the
 * three phases (residuals then Jacobian entries; rate right-hand sides). */
static int subset_jacobian(solver_plan *sp, const int *rowmap, int *Jp, int **Ji)
{
    const mech_system *s = sp->sys;
    int ns = sp->ns, nr = sp->nr, nnz = 0;
    for (int k = 0; k < ns; k++)
        for (int p = s->Jp[sp->col[k]]; p < s->Jp[sp->col[k] + 1]; p++)
            nnz += rowmap[s->Ji[p]] >= 0;
    sp->nnzJ = nnz;
    *Ji = xcalloc((size_t)nnz + 1, sizeof **Ji);
    sp->proot = xcalloc((size_t)(nr + nnz) + 1, sizeof *sp->proot);
    sp->vroot = xcalloc((size_t)nr + 1, sizeof *sp->vroot);
    sp->aroot = xcalloc((size_t)nr + 1, sizeof *sp->aroot);
    if (!*Ji || !sp->proot || !sp->vroot || !sp->aroot)
        return -1;
    for (int i = 0; i < nr; i++) {
        sp->proot[i] = s->f[sp->row[i]];
        sp->vroot[i] = s->vel[sp->row[i]];
        sp->aroot[i] = s->acc[sp->row[i]];
    }
    int at = 0;
    for (int k = 0; k < ns; k++) {
        Jp[k] = at;
        for (int p = s->Jp[sp->col[k]]; p < s->Jp[sp->col[k] + 1]; p++)
            if (rowmap[s->Ji[p]] >= 0) {
                (*Ji)[at] = rowmap[s->Ji[p]];
                sp->proot[nr + at++] = s->Jx[p];
            }
    }
    Jp[ns] = at;
    return 0;
}

/* Pattern of the solved rows and columns, and the tape computing them. */
static int compile_subset(solver_plan *sp, const unsigned char *row_on, const unsigned char *col_on)
{
    int *rowmap = xcalloc((size_t)sp->sys->m + 1, sizeof *rowmap);
    int *Jp = xcalloc((size_t)sp->n + 1, sizeof *Jp), *Ji = NULL;
    int rc = rowmap && Jp && choose_subset(sp, row_on, col_on, rowmap) == 0 &&
                     subset_jacobian(sp, rowmap, Jp, &Ji) == 0 ? 0 : -1;
    free(rowmap);
    if (rc == 0 && sp->aug) {
        rc = augmented_pattern(sp, Jp, Ji);
    } else if (rc == 0) {  /* square: J itself is factored */
        sp->Ap = Jp;
        sp->Ai = Ji;
        Jp = Ji = NULL;
        sp->Ax0 = xcalloc((size_t)sp->nnzJ + 1, sizeof *sp->Ax0);
        sp->N = sp->ns;
        sp->nnz = sp->nnzJ;
        rc = sp->Ax0 ? 0 : -1;
    }
    free(Jp);
    free(Ji);
    return rc == 0 ? compile_tape(sp) : -1;
}

static int level_of(int want)
{
    if (want & MECH_WANT_ACCELERATION)
        return MECH_WANT_ALL;
    if (want & MECH_WANT_VELOCITY)
        return MECH_WANT_POSITION | MECH_WANT_VELOCITY;
    return MECH_WANT_POSITION;
}

int solver_plan_init(solver_plan *sp, const mech_model *m, const mech_solve_options *o,
                     mech_diag *d)
{
    return solver_plan_init_with(sp, m, o, NULL, d);
}

int solver_plan_init_with(solver_plan *sp, const mech_model *m, const mech_solve_options *o,
                          mech_system *sys, mech_diag *d)
{
    memset(sp, 0, sizeof *sp);
    sp->m = m;
    sp->opt = *o;
    sp->level = level_of(o->want ? o->want : MECH_WANT_ALL);
    sp->sys = sys;
    int rc = sys ? MECH_OK : mech_system_new(m, &sp->sys, d);
    if (rc != MECH_OK)
        return rc;
    sp->n = sp->sys->n;
    if (!(sp->opt.tol > 0.0))
        sp->opt.tol = 1e-12;
    if (!(sp->opt.min_rcond > 0.0))
        sp->opt.min_rcond = 1e-6;
    const char *rc_env = getenv("MECH_RCOND");
    sp->exact_rcond = rc_env && strcmp(rc_env, "exact") == 0;
    if (kin_tree_build(&sp->tree, sp->sys) != MECH_OK)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    int rows = sp->sys->m;
    unsigned char *need = xcalloc((size_t)sp->n + 1, 1), *row_on = xcalloc((size_t)rows + 1, 1),
                  *col_on = xcalloc((size_t)sp->n + 1, 1);
    rc = MECH_ENOMEM;
    sp->aug = rows > sp->n;
    if (need && row_on && col_on) {
        needed_unknowns(sp, need);
        int b = 0;
        if (sp->aug) {  /* redundant equations: no square block form; solve everything */
            memset(row_on, 1, (size_t)rows);
            memset(col_on, 1, (size_t)sp->n);
            for (int l = 1; l < m->nlinks; l++)
                sp->tree.active[l] = 1;
            sp->nblocks = sp->nblocks_solved = 1;
            if (sp->opt.log)
                fprintf(sp->opt.log, "blocks: %d equations for %d unknowns (redundant "
                        "constraints): all solved together, in the least-squares sense\n",
                        rows, sp->n);
        } else {
            b = choose_blocks(sp, need, row_on, col_on);
        }
        /* with drivers' rows: name the conflicting drivers, the free unknowns */
        if (b > 0 && sp->sys->nrows_of[ROW_DRIVER] > 0)
            rc = drivers_report_structure(sp->sys, d);
        else if (b > 0)
            rc = diag_error(d, m->file, m->driver.mark,
                            "the loop equations are structurally singular: some unknown "
                            "appears in no equation that could determine it (see 'mech equations')");
        else if (b == 0 && compile_subset(sp, row_on, col_on) == 0)
            rc = MECH_OK;
    }
    free(need);
    free(row_on);
    free(col_on);
    kin_tree_finish(&sp->tree);  /* the active links are chosen */
    frame_registers_used(sp);
    if (rc == MECH_OK && solver_numbers_alloc(sp) < 0)
        rc = MECH_ENOMEM;
    if (rc == MECH_OK)
        solver_plan_numbers(sp, m);
    if (rc == MECH_ENOMEM)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    if (rc != MECH_OK)
        return rc;
    if (sp->ns > 0 && linsys_plan_init(&sp->lp, sp->N, sp->Ap, sp->Ai, sp->opt.linear_solver) != 0)
        return diag_fail(d, MECH_FAIL_NOMEM, m->file, (mech_mark){0, 0}, "cannot analyse the "
                         "Jacobian (%s)", fail_words(MECH_FAIL_NOMEM));
    if (sp->opt.log) {
        char method[96];
        fprintf(sp->opt.log, "linear solves: %s\n",
                sp->ns > 0 ? linsys_method_name(&sp->lp, method, sizeof method) : "none");
    }
    return MECH_OK;
}

void solver_plan_free(solver_plan *sp)
{
    linsys_plan_free(&sp->lp);
    tape_free(&sp->tp);
    solver_numbers_free(sp);
    kin_tree_free(&sp->tree);
    mech_system_free(&sp->sys);
    void *blocks[] = {sp->col, sp->row, sp->Ap, sp->Ai, sp->Ax0, sp->jpos, sp->proot,
                      sp->vroot, sp->aroot, sp->preg, sp->vreg, sp->areg, sp->xreg,
                      sp->xdreg, sp->csreg};
    free_all(blocks, COUNT_OF(blocks));
    memset(sp, 0, sizeof *sp);
}

/* ---- the numeric state ------------------------------------------------- */

int solver_init(solver *sv, const solver_plan *sp)
{
    memset(sv, 0, sizeof *sv);
    sv->p = sp;
    sv->rcond_exact = 1;  /* nothing bounded yet */
    sv->published = -1;
    sv->tape_q = NAN;
    size_t n1 = (size_t)sp->n + 1, ns = (size_t)sp->ns + 1, nr = (size_t)sp->nr + 1;
    double **arrays[] = {&sv->pos, &sv->vel, &sv->acc, &sv->x, &sv->xq, &sv->xqq, &sv->f,
                         &sv->ft, &sv->dx, &sv->xt, &sv->rhs, &sv->cscale, &sv->Jv, &sv->Ax};
    size_t sizes[] = {n1, n1, n1, ns, ns, ns, nr, nr, ns, ns, nr + ns, ns,
                      (size_t)sp->nnzJ + 1, (size_t)sp->nnz + 1};
    if (xcalloc_doubles(arrays, sizes, 0, COUNT_OF(arrays)) < 0)
        return -1;
    if (sp->Ax0)  /* NULL once compacted when square: zeros, as calloc left them */
        memcpy(sv->Ax, sp->Ax0, (size_t)sp->nnz * sizeof *sv->Ax);
    if (!(sv->reg = tape_registers_new(&sp->tp)))
        return -1;
    for (int k = 0; k < sp->nleaf; k++)  /* the leaves' values: the plan's numbers */
        tape_set_var(&sp->tp, sv->reg, SYS_NVARS(sp->n) + k, sp->leaf[k]);
    if (sp->ns > 0 && linsys_init(&sv->ls, &sp->lp) != 0)
        return -1;
    return kin_state_init(&sv->ks, sp->m) == MECH_OK ? 0 : -1;
}

void solver_free(solver *sv)
{
    linsys_free(&sv->ls);
    kin_state_free(&sv->ks);
    void *blocks[] = {sv->reg, sv->pos, sv->vel, sv->acc, sv->x, sv->xq, sv->xqq, sv->f,
                      sv->ft, sv->dx, sv->xt, sv->rhs, sv->cscale, sv->Jv, sv->Ax};
    free_all(blocks, COUNT_OF(blocks));
    memset(sv, 0, sizeof *sv);
}

/* ---- one driver position ------------------------------------------------ */

double vec_norm_inf(const double *v, int n) { return rt_norm_inf(v, n); }

double solver_step_size(const solver_plan *sp, const double *dx)
{
    return rt_step_size(dx, sp->unit, sp->ns);
}

/* f (and the raw Jacobian in Ax) at x, q; returns |f|inf. */
static double evaluate(solver *sv, const double *x, double q, double *f)
{
    const solver_plan *sp = sv->p;
    const tape *t = &sp->tp;
    double *reg = sv->reg;
    if (!(q == sv->tape_q)) {
        tape_set_var(t, reg, SYS_VAR_Q(sp->n), q);
        tape_run_invariant(t, reg, PHASE_POSITION);
        sv->tape_q = q;
    }
    for (int i = 0; i < sp->ns; i++)
        if (sp->xreg[i] >= 0)
            reg[sp->xreg[i]] = x[i];
    tape_run_variant(t, reg, PHASE_POSITION);
    for (int i = 0; i < sp->nr; i++)
        f[i] = reg[sp->preg[i]];
    for (int k = 0; k < sp->nnzJ; k++)
        sv->Jv[k] = reg[sp->preg[sp->nr + k]];
    return vec_norm_inf(f, sp->nr);
}

/* Scale every column of J to unit largest entry (J C), remembering C, and
 * place the values in the factored matrix (J itself, or [I JC; (JC)^T 0]). */
RT_INLINE void equilibrate(solver *sv)
{
    const solver_plan *sp = sv->p;
    const int *Jp = sp->aug ? sp->Ap + sp->nr : sp->Ap;  /* column starts of J's entries */
    int k = 0;
    for (int c = 0; c < sp->ns; c++) {
        int len = sp->aug ? Jp[c + 1] - Jp[c] : sp->Ap[c + 1] - sp->Ap[c];
        double cs = rt_column_scale(sv->Jv + k, len);
        sv->cscale[c] = cs;
        for (int p = 0; p < len; p++, k++) {
            double v = sv->Jv[k] * cs;
            if (sp->aug) {
                sv->Ax[sp->jpos[2 * k]] = v;
                sv->Ax[sp->jpos[2 * k + 1]] = v;
            } else {
                sv->Ax[k] = v;
            }
        }
    }
}

/* Factor the Jacobian of the last evaluation, columns equilibrated. */
static int factor(solver *sv)
{
    sv->factorisations++;
    equilibrate(sv);
    return linsys_factor(&sv->ls, sv->Ax);
}

/* Reciprocal 1-norm condition of the equilibrated Jacobian at the current
 * factors (docs/solver.md, section 4). */
static double condition(solver *sv)
{
    linsys_condition(&sv->ls, sv->Ax, &sv->rcond, &sv->rcond_whole);
    sv->rcond_exact = 1;
    return sv->rcond;
}

/* The condition at a converged position, for Newton's status (singular
 * below min_rcond) and the next position's rounding floor (xtol =
 * max(1e-2 tol, eps / rcond_whole)): lower bounds of both without solves
 * when they already give the exact values' status and floor (the bounds
 * are at most the exact values, roundings included: rt_blocklu.h,
 * rt_blocks_rcond_bounds; docs/codegen.md, "The condition at a solution",
 * as the generated code does), else the exact values. Least squares and
 * KLU: the exact values. */
static double condition_at_solution(solver *sv)
{
    const solver_plan *sp = sv->p;
    double worst, whole, floor_at = DBL_EPSILON / (1e-2 * sp->opt.tol);
    /* where the last position needed the exact values (a long chain's
       whole-matrix condition is below floor_at all along), the bounds
       would be computed for nothing */
    int worth = sv->rcond_whole >= floor_at && sv->rcond >= sp->opt.min_rcond;
    int bounded = sp->aug || sp->exact_rcond || !worth ? -1
                  : linsys_condition_bounds(&sv->ls, &worst, &whole);
    if (bounded == 0 || (bounded == 1 && worst >= sp->opt.min_rcond && whole > 0.0 &&
                         DBL_EPSILON / fmax(whole, 1e-300) <= 1e-2 * sp->opt.tol)) {
        sv->rcond = worst;  /* bounded 0: one block of at most 2 x 2, its exact values */
        sv->rcond_whole = whole;
        sv->rcond_exact = !bounded;
        sv->rcond_factorisation = sv->factorisations;
        return worst;
    }
    return condition(sv);
}

double solver_rcond(solver *sv)
{
    if (!sv->rcond_exact && sv->rcond_factorisation == sv->factorisations)
        condition(sv);
    return sv->rcond;
}

/* dx from J dx = b (b has nr entries, dx ns): with the factors of J, or in
 * the least-squares sense through [I J; J^T 0] [r; y] = [b; 0]; the column
 * scaling is undone. */
static void linear_solve(solver *sv, const double *b, double *dx)
{
    const solver_plan *sp = sv->p;
    double *w = sv->rhs;
    memcpy(w, b, (size_t)sp->nr * sizeof *w);
    for (int i = sp->nr; i < sp->N; i++)
        w[i] = 0.0;
    linsys_solve(&sv->ls, w);
    const double *y = sp->aug ? w + sp->nr : w;
    for (int i = 0; i < sp->ns; i++)
        dx[i] = y[i] * sv->cscale[i];
}

/* ---- Newton (rt_newton.h) on the state of one position ----------------- */

typedef struct newton_ctx {
    solver *sv;
    double q;
    const double *shift;  /* [nr] f(x, q) = shift is solved (NULL: 0) */
} newton_ctx;

static double newton_evaluate(void *c, const double *x, double *f)
{
    newton_ctx *n = c;
    double r = evaluate(n->sv, x, n->q, f);
    if (!n->shift)
        return r;
    for (int i = 0; i < n->sv->p->nr; i++)
        f[i] -= n->shift[i];
    return vec_norm_inf(f, n->sv->p->nr);
}

static int newton_factor(void *c) { return factor(((newton_ctx *)c)->sv); }

/* The last position's condition: Newton's rounding floor (computed at the
 * first factorisation of all). */
static double newton_rcond_whole(void *c)
{
    solver *sv = ((newton_ctx *)c)->sv;
    if (!(sv->rcond > 0.0))
        condition(sv);
    return sv->rcond_whole;
}

static void newton_solve(void *c, const double *b, double *dx)
{
    linear_solve(((newton_ctx *)c)->sv, b, dx);
}

static double newton_rcond_at_solution(void *c)
{
    return condition_at_solution(((newton_ctx *)c)->sv);
}

static const rt_newton_ops newton_ops = {newton_evaluate, newton_factor, newton_rcond_whole,
                                         newton_solve, newton_rcond_at_solution};

step_status solver_newton(solver *sv, double q) { return solver_newton_shifted(sv, q, NULL); }

step_status solver_newton_shifted(solver *sv, double q, const double *shift)
{
    const solver_plan *sp = sv->p;
    sv->generation++;  /* x changes: what was published is stale */
    sv->iters = 0;
    if (sp->ns == 0) {
        sv->resid = 0.0;
        sv->rcond = 1.0;
        return STEP_OK;
    }
    /* least squares: up to 3 corrections at rounding level (rt_newton) */
    rt_newton_par par = {sp->ns, sp->nr, sp->unit, sp->opt.tol, sp->ftol, sp->opt.min_rcond,
                         sp->opt.max_iter > 0 ? sp->opt.max_iter : 50, sp->aug ? 3 : 0};
    rt_newton_vec v = {sv->x, sv->f, sv->ft, sv->dx, sv->xt};
    newton_ctx ctx = {sv, q, shift};
    int st = rt_newton(&newton_ops, &ctx, &par, &v, &sv->resid, &sv->iters);
    return st == RT_NEWTON_CONVERGED ? STEP_OK
           : st == RT_NEWTON_SINGULAR ? STEP_SINGULAR : STEP_NO_ASSEMBLY;
}

int solver_det_sign(solver *sv)
{
    const solver_plan *sp = sv->p;
    /* the column scaling is positive: the sign is that of the factors */
    return sp->N == 0 ? 1 : linsys_det_sign(&sv->ls);
}

void solver_velocity_rhs(solver *sv, double *out)
{
    const solver_plan *sp = sv->p;
    const tape *t = &sp->tp;
    double *reg = sv->reg;
    tape_set_var(t, reg, SYS_VAR_QDOT(sp->n), 1.0);
    tape_run(t, reg, PHASE_VELOCITY);
    for (int i = 0; i < sp->nr; i++)
        out[i] = reg[sp->vreg[i]];
}

void solver_rates(solver *sv)
{
    const solver_plan *sp = sv->p;
    sv->generation++;
    if (sp->ns == 0)
        return;
    const tape *t = &sp->tp;
    double *reg = sv->reg;
    /* geometric rates (qdot = 1, qddot = 0); solver_publish scales them */
    solver_velocity_rhs(sv, sv->ft);
    linear_solve(sv, sv->ft, sv->xq);
    for (int i = 0; i < sp->ns; i++)
        if (sp->xdreg[i] >= 0)
            reg[sp->xdreg[i]] = sv->xq[i];
    tape_set_var(t, reg, SYS_VAR_QDDOT(sp->n), 0.0);
    tape_run(t, reg, PHASE_ACCELERATION);
    for (int i = 0; i < sp->nr; i++)
        sv->ft[i] = reg[sp->areg[i]];
    linear_solve(sv, sv->ft, sv->xqq);
}

void solver_rates_shifted(solver *sv, const double *vshift, const double *ashift)
{
    const solver_plan *sp = sv->p;
    sv->generation++;
    if (sp->ns == 0)
        return;
    const tape *t = &sp->tp;
    double *reg = sv->reg;
    solver_velocity_rhs(sv, sv->ft);  /* -f_q for qdot = 1 */
    for (int i = 0; vshift && i < sp->nr; i++)
        sv->ft[i] += vshift[i];
    linear_solve(sv, sv->ft, sv->xq);
    for (int i = 0; i < sp->ns; i++)
        if (sp->xdreg[i] >= 0)
            reg[sp->xdreg[i]] = sv->xq[i];
    tape_set_var(t, reg, SYS_VAR_QDDOT(sp->n), 0.0);
    tape_run(t, reg, PHASE_ACCELERATION);
    for (int i = 0; i < sp->nr; i++)
        sv->ft[i] = reg[sp->areg[i]] + (ashift ? ashift[i] : 0.0);
    linear_solve(sv, sv->ft, sv->xqq);
}

void solver_accel_shifted(solver *sv, const double *ashift)
{
    const solver_plan *sp = sv->p;
    sv->generation++;
    if (sp->ns == 0)
        return;
    /* the acceleration phase's registers still hold this position's terms */
    for (int i = 0; i < sp->nr; i++)
        sv->ft[i] = sv->reg[sp->areg[i]] + (ashift ? ashift[i] : 0.0);
    linear_solve(sv, sv->ft, sv->xqq);
}

/* xdot = x_q qd and xddot = x_qq qd^2 + x_q qdd (the loop equations do not
 * depend on time explicitly). */
/* cos and sin of the link angles that the tape's registers hold for the
 * angle being published (the last position evaluation's: its variable's
 * register holds the same double), given to the frames. */
static void offer_frames(solver *sv)
{
    const solver_plan *sp = sv->p;
    for (int i = 0; i < sp->ncs; i++) {
        const int *r = sp->csreg + 4 * i;
        uint64_t a, b;  /* the same bits (not ==: -0 and 0 have other sines) */
        memcpy(&a, &sv->pos[sp->tree.angle_var[r[0]]], sizeof a);
        memcpy(&b, &sv->reg[r[1]], sizeof b);
        if (a == b)
            kin_offer_cs(&sv->ks, r[0], sv->reg[r[1]], sv->reg[r[2]], sv->reg[r[3]]);
    }
}

void solver_publish(solver *sv, double q, double qd, double qdd)
{
    const solver_plan *sp = sv->p;
    /* the same state published again (the branch check, then the row) */
    if (sv->published == sv->generation && q == sv->pub_q && qd == sv->pub_qd &&
        qdd == sv->pub_qdd)
        return;
    sv->published = sv->generation;
    sv->pub_q = q, sv->pub_qd = qd, sv->pub_qdd = qdd;
    int n = sp->n;
    sv->pos[n] = q;
    sv->vel[n] = qd;
    sv->acc[n] = qdd;
    for (int i = 0; i < sp->ns; i++) {
        int c = sp->col[i];
        sv->pos[c] = sv->x[i];
        sv->vel[c] = sv->xq[i] * qd;
        sv->acc[c] = sv->xqq[i] * qd * qd + sv->xq[i] * qdd;
    }
    offer_frames(sv);
    kin_update(&sp->tree, &sv->ks, sv->pos,
               sp->level & MECH_WANT_VELOCITY ? sv->vel : NULL,
               sp->level & MECH_WANT_ACCELERATION ? sv->acc : NULL);
}



