/* src/sweep.c: the analysed system (mech_analysis) and the driver sweep
 * (mech_solve), a thin client of the stages below it:
 *
 *   mech_analysis_new   solver plan (solve.c), force plan (forces.c) and
 *                       column layout (columns.c): built once, read only;
 *   mech_analysis_solve per call, a continuation state (continuation.c)
 *                       walks the driver positions; each row is solved,
 *                       its forces computed and the row filled through the
 *                       layout; a failure is explained by diagnose.c.
 *
 * A driver value goes: the options' or the file's range (sweep_values)
 * -> cont_start / cont_advance (predict, Newton, checks) -> solver_publish
 * (rates, link frames) -> forces_solve -> columns_fill. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "columns.h"
#include "diagnose.h"
#include "variant_regs.h"

struct mech_analysis {
    const mech_model *m;       /* borrowed: must outlive the analysis */
    mech_solve_options opt;    /* opt.outputs points to outputs */
    mech_outputs outputs;      /* what is output (a copy: options' or the file's) */
    solver_plan sp;
    int want_forces;           /* joint reactions wanted */
    forces_plan fp;            /* when want_forces */
    column_layout cols;
    double *values;            /* [nvalues] driver positions of the sweep */
    int nvalues;
    double setup_seconds;
};

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void mech_solve_options_default(mech_solve_options *o)
{
    memset(o, 0, sizeof *o);
    o->tol = 1e-12;
    o->max_iter = 50;
    o->min_rcond = 1e-6;
    o->want = MECH_WANT_ALL;
}

/* ---- the analysed system ------------------------------------------------- */

static int no_memory(const mech_model *m, mech_diag *d)
{
    return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
}

/* Driver positions of the sweep: the file's, or the options' range. */
static double *sweep_values(const mech_model *m, const mech_solve_options *o, int *count)
{
    if (!o->has_range) {
        double *v = xcalloc((size_t)m->driver.nvalues + 1, sizeof *v);
        if (v)
            memcpy(v, m->driver.values, (size_t)m->driver.nvalues * sizeof *v);
        *count = m->driver.nvalues;
        return v;
    }
    int steps = o->steps > 0 ? o->steps : 1;
    double *v = xcalloc((size_t)steps + 1, sizeof *v);
    for (int i = 0; v && i <= steps; i++)
        v[i] = i == steps ? o->to : o->from + (o->to - o->from) * i / steps;
    *count = steps + 1;
    return v;
}

/* The result table is kept in memory: refuse (clearly) one above 2 GiB
 * rather than let an overcommitted allocation kill the run part-way. */
static int too_large(const mech_analysis *a, int nrows, mech_diag *d)
{
    double bytes = (double)a->cols.ncols * nrows * sizeof(double);
    if (bytes <= 2147483648.0)
        return 0;
    diag_error(d, a->m->file, a->m->driver.mark,
               "the results would take %.3g GB in memory (%d rows of %d columns): ask for "
               "fewer steps (--steps) or fewer outputs (--outputs)", bytes / 1e9, nrows,
               a->cols.ncols);
    return 1;
}

/* Which friction columns: 0 none, 1 with friction, 2 with and without. */
static int friction_columns(const mech_analysis *a)
{
    if (!a->want_forces || !a->fp.has_friction || a->opt.friction == MECH_FRICTION_OFF)
        return 0;
    return a->opt.friction == MECH_FRICTION_BOTH ? 2 : 1;
}

static int copy_outputs(mech_outputs *to, const mech_outputs *from)
{
    *to = *from;
    to->points = xcalloc((size_t)from->npoints + 1, sizeof *to->points);
    to->links = xcalloc((size_t)from->nlinks + 1, sizeof *to->links);
    to->sliders = xcalloc((size_t)from->nsliders + 1, sizeof *to->sliders);
    if (!to->points || !to->links || !to->sliders) {
        mech_outputs_free(to);
        return -1;
    }
    if (from->npoints)  /* an empty list may be NULL: memcpy from NULL is undefined */
        memcpy(to->points, from->points, (size_t)from->npoints * sizeof *to->points);
    if (from->nlinks)
        memcpy(to->links, from->links, (size_t)from->nlinks * sizeof *to->links);
    if (from->nsliders)
        memcpy(to->sliders, from->sliders, (size_t)from->nsliders * sizeof *to->sliders);
    return 0;
}

static int build_plans(mech_analysis *a, mech_system *sys, mech_diag *d)
{
    const mech_model *m = a->m;
    int rc = solver_plan_init_with(&a->sp, m, &a->opt, sys, d);
    if (rc == MECH_OK && a->want_forces)
        rc = forces_plan_init(&a->fp, &a->sp, a->opt.friction, d);
    if (rc == MECH_OK && a->want_forces && a->opt.log) {
        char method[96];
        fprintf(a->opt.log, "force system: %d reactions; linear solves: %s\n", a->fp.ncols,
                linsys_method_name(&a->fp.lp, method, sizeof method));
    }
    if (rc != MECH_OK)
        return rc;
    /* the sweep needs only the compiled plan; a sweep's shared analysis
       (SYS_REGISTERS) keeps the set-up data: its variants look up their
       coefficients' registers through it (variant_regs.c) */
    if (a->sp.sys && a->sp.sys->mode != SYS_REGISTERS)
        solver_plan_compact(&a->sp);
    column_request rq = {&a->outputs, a->sp.level, a->want_forces, friction_columns(a),
                         a->opt.diagnostics};
    if (columns_build(&a->cols, m, &rq) != MECH_OK)
        return no_memory(m, d);
    if (!(a->values = sweep_values(m, &a->opt, &a->nvalues)))
        return no_memory(m, d);
    return too_large(a, a->nvalues, d) ? MECH_EINPUT : MECH_OK;
}

int mech_analysis_new(const mech_model *m, const mech_solve_options *o, mech_analysis **out,
                      mech_diag *d)
{
    return analysis_new_with(m, o, NULL, out, d);
}

int analysis_new_with(const mech_model *m, const mech_solve_options *o, mech_system *sys,
                      mech_analysis **out, mech_diag *d)
{
    *out = NULL;
    if (!m->has_driver) {
        mech_system_free(&sys);
        return diag_error(d, m->file, (mech_mark){0, 0}, "the mechanism has no driver");
    }
    double t0 = now_seconds();
    mech_analysis *a = xcalloc(1, sizeof *a);
    if (!a) {
        mech_system_free(&sys);
        return no_memory(m, d);
    }
    a->m = m;
    a->opt = *o;
    if (copy_outputs(&a->outputs, o->outputs ? o->outputs : &m->outputs) != 0) {
        free(a);
        mech_system_free(&sys);
        return no_memory(m, d);
    }
    a->opt.outputs = &a->outputs;
    a->want_forces = o->forces > 0 || (o->forces == 0 && a->outputs.forces);
    if (a->want_forces) {  /* reactions need every link's acceleration */
        a->opt.all_blocks = 1;
        a->opt.want = MECH_WANT_ALL;
    }
    int rc = build_plans(a, sys, d);
    if (rc != MECH_OK) {
        mech_analysis_free(&a);
        return rc;
    }
    a->setup_seconds = now_seconds() - t0;
    *out = a;
    return MECH_OK;
}

void mech_analysis_free(mech_analysis **pa)
{
    mech_analysis *a = pa ? *pa : NULL;
    if (!a)
        return;
    columns_free(&a->cols);
    mech_outputs_free(&a->outputs);
    forces_plan_free(&a->fp);
    solver_plan_free(&a->sp);
    free(a->values);
    free(a);
    *pa = NULL;
}

/* ---- a variant's view of an analysis (variant_regs.h) --------------------- */

/* What a view owns beside its copy of the analysis: the numbers the plans
 * took from the model (the tape's register image with the coefficients,
 * the slide step units, the link frames' attachment points). */
typedef struct analysis_view {
    mech_analysis a;           /* first: the view is used as an analysis */
    mech_system sys;           /* the system's fields, its model the variant's */
    int *const_reg;            /* the tape's constant list: the base's, then the */
    double *const_val;         /* coefficients' registers set by analysis_view_set */
    int nbase, ncap;           /* the base's constants; room in the lists */
} analysis_view;

mech_analysis *analysis_view_new(const mech_analysis *base, const mech_model *mv)
{
    analysis_view *v = xcalloc(1, sizeof *v);
    if (!v)
        return NULL;
    mech_analysis *a = &v->a;
    *a = *base;
    v->sys = *base->sp.sys;
    v->sys.model = mv;
    a->m = mv;
    solver_plan *sp = &a->sp;
    sp->m = mv;
    sp->sys = &v->sys;
    sp->lref = solver_largest_length(mv);
    sp->ftol = sp->opt.tol * sp->lref;
    /* the registers a state starts from (tape_registers_new): the base's
       constants and, appended by analysis_view_set, the coefficients */
    v->nbase = base->sp.tp.nconst;
    v->ncap = v->nbase + v->sys.nvars + 1;
    v->const_reg = xcalloc((size_t)v->ncap, sizeof *v->const_reg);
    v->const_val = xcalloc((size_t)v->ncap, sizeof *v->const_val);
    sp->unit = xcalloc((size_t)sp->ns + 1, sizeof *sp->unit);
    int ok = v->const_reg && v->const_val && sp->unit &&
             kin_tree_build(&sp->tree, &v->sys) == MECH_OK;
    if (!ok) {  /* what is not the view's own is the base's: not freed */
        free(v->const_reg);
        free(v->const_val);
        free(sp->unit);
        free(v);
        return NULL;
    }
    if (v->nbase > 0) {
        memcpy(v->const_reg, base->sp.tp.const_reg, (size_t)v->nbase * sizeof *v->const_reg);
        memcpy(v->const_val, base->sp.tp.const_val, (size_t)v->nbase * sizeof *v->const_val);
    }
    sp->tp.const_reg = v->const_reg;
    sp->tp.const_val = v->const_val;
    sp->tp.nconst = v->nbase;
    memcpy(sp->tree.active, base->sp.tree.active, (size_t)mv->nlinks);
    kin_tree_finish(&sp->tree);  /* the links whose cos and sin are kept, as the base's */
    for (int i = 0; i < sp->ns; i++)  /* as root_registers (solve.c) */
        sp->unit[i] = v->sys.unk_kind[sp->col[i]] == UNK_SLIDE ? sp->lref : 1.0;
    if (a->want_forces) {
        a->fp.m = mv;  /* as forces_plan_init */
        double qd = fabs(mv->driver.speed);
        if (mv->driver.kind == MECH_DRIVE_SLIDER)
            qd /= sp->lref;
        a->fp.speed_eps = 1e-6 * (qd > 0.0 ? qd : 1.0);
    }
    return a;
}

void analysis_view_set(mech_analysis *view, int var, double value)
{
    analysis_view *v = (analysis_view *)view;
    tape *tp = &view->sp.tp;
    int r = tp->var_reg[var], k = v->nbase;
    if (r < 0)
        return;  /* a coefficient the compiled phases do not read */
    while (k < tp->nconst && v->const_reg[k] != r)
        k++;
    if (k == tp->nconst) {
        if (k >= v->ncap)
            return;  /* not reached: a register per variable at most */
        tp->nconst++;
        v->const_reg[k] = r;
    }
    v->const_val[k] = value;
}

void analysis_view_free(mech_analysis **pv)
{
    if (!pv || !*pv)
        return;
    analysis_view *v = (analysis_view *)*pv;
    free(v->const_reg);
    free(v->const_val);
    free(v->a.sp.unit);
    kin_tree_free(&v->a.sp.tree);
    free(v);
    *pv = NULL;
}

const mech_system *analysis_system(const mech_analysis *a) { return a->sp.sys; }

int mech_analysis_columns(const mech_analysis *a) { return a->cols.ncols; }

int mech_analysis_header(const mech_analysis *a, mech_table *out)
{
    return columns_make_table(&a->cols, out, 0);
}

/* ---- one sweep -------------------------------------------------------------- */

/* One call's state: the continuation, the forces, and where rows go. */
typedef struct run {
    const mech_analysis *a;
    cont c;
    forces fc;
    mech_diag *d;
    mech_solve_stats *st;
    mech_table *t;             /* rows are appended here */
    int refined_notes;         /* refinements reported so far */
} run;

static int solve_forces(run *r, double q)
{
    const mech_model *m = r->a->m;
    char qb[64], joints[400];
    int rc = forces_solve(&r->fc, &r->c.sv);
    if (rc == -1) {
        forces_singular_joints(&r->fc, joints, sizeof joints);
        return diag_error(r->d, m->file, m->driver.mark,
                          "the force system is singular at %s = %s (reciprocal condition %.2g): "
                          "redundant constraints make the reactions of %s not unique",
                          diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb),
                          r->fc.rcond, joints[0] ? joints : "some joints"), MECH_ESOLVE;
    }
    if (rc == -2)
        return diag_error(r->d, m->file, m->driver.mark,
                          "joint friction does not converge at %s = %s (fixed-point iteration, "
                          "%d steps): the friction coefficients may make the mechanism "
                          "self-locking there", diagnose_driver_word(m),
                          diagnose_q_text(m, q, qb, sizeof qb), 100), MECH_ESOLVE;
    double worst = fmax(fabs(r->fc.residual), fabs(r->fc.residual0));
    if (worst > r->st->worst_power_residual)
        r->st->worst_power_residual = worst;
    if (r->fc.iterations > r->st->max_friction_iterations)
        r->st->max_friction_iterations = r->fc.iterations;
    return MECH_OK;
}

static void note_refined(run *r, double q)
{
    const mech_model *m = r->a->m;
    if (r->c.row_substeps == 0 || r->refined_notes++ >= 5)
        return;
    char qb[64];
    diag_note(r->d, m->file, m->driver.mark,
              "the step to %s = %s was refined into %d steps (reciprocal condition "
              "there %.2g): a difficult position, near a singular one or a fast change",
              diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb),
              r->c.row_substeps + 1, r->c.sv.rcond);
}

/* A value that is not a finite number is never passed off as a result:
 * an error naming the column and the driver position (extreme data, such
 * as a driver speed of 1e160 rad/s, overflow the rates). */
static int check_finite(run *r, double q, const double *out)
{
    const column_layout *cl = &r->a->cols;
    /* x - x is NaN for an infinite or NaN x, else 0: four independent sums */
    double z[4] = {0.0, 0.0, 0.0, 0.0};
    int k = 0;
    for (; k + 4 <= cl->ncols; k += 4)
        for (int i = 0; i < 4; i++)
            z[i] += out[k + i] - out[k + i];
    for (; k < cl->ncols; k++)
        z[0] += out[k] - out[k];
    if (z[0] + z[1] + z[2] + z[3] == 0.0)
        return MECH_OK;
    int c = 0;
    while (c < cl->ncols && isfinite(out[c]))
        c++;
    if (c == cl->ncols)
        return MECH_OK;
    const mech_model *m = r->a->m;
    char qb[64];
    return diag_error(r->d, m->file, m->driver.mark,
                      "at %s = %s the column %s is %s, not a finite number: the data overflow "
                      "double precision (check the driver's speed and acceleration, the "
                      "masses and loads, and their units)",
                      diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb),
                      cl->cols[c].name, isnan(out[c]) ? "NaN" : out[c] > 0 ? "+inf" : "-inf"),
           MECH_ESOLVE;
}

/* fill_row's status when the force analysis fails: the sweep stops there. */
enum { ROW_STOP = 1 };

/* Publish the reached row at q, its forces, append it to the table:
 * MECH_OK, or ROW_STOP (the force analysis failed, reported). */
static int fill_row(run *r, double q)
{
    cont *c = &r->c;
    double *out = r->t->values + (size_t)r->t->nrows * (size_t)r->t->ncolumns;
    note_refined(r, q);
    solver_publish(&c->sv, q, c->qd, c->qdd);
    if (r->a->want_forces && solve_forces(r, q) != MECH_OK)
        return ROW_STOP;
    row_sources rs = {&c->sv, r->a->want_forces ? &r->fc : NULL, c->row_iters, c->row_substeps};
    columns_fill(&r->a->cols, &rs, out);
    if (check_finite(r, q, out) != MECH_OK)
        return ROW_STOP;
    r->t->nrows++;
    r->st->iterations += c->row_iters;
    if (c->row_iters > r->st->max_iterations)
        r->st->max_iterations = c->row_iters;
    return MECH_OK;
}

/* With opt.limit_rows, a row at the limit q (solution near x) when the
 * position is not singular there. */
static int limit_row(run *r, double q, const double *x)
{
    cont *c = &r->c;
    if (!r->a->opt.limit_rows)
        return MECH_OK;
    c->row_iters = 0;
    c->row_substeps = 0;
    return cont_solve_at(c, q, x) == STEP_OK ? fill_row(r, q) : MECH_OK;
}

static mech_gap_kind gap_kind(const cont *c, step_status s)
{
    switch (s) {
    case STEP_SINGULAR:
        return c->fail_change_point ? MECH_GAP_CHANGE_POINT : MECH_GAP_DEAD_POINT;
    case STEP_BRANCH:
        return MECH_GAP_BRANCH;
    case STEP_JUMP:
        return MECH_GAP_JUMP;
    default:
        return MECH_GAP_NO_ASSEMBLY;
    }
}

/* The continuation failed before q[row]: why (diagnosed from the state of
 * the failure), then the limit it reached refined to 1e-12 of the row
 * spacing from the position kept before the diagnosis, kept for restarts,
 * and its row. */
static int failed_row(run *r, const double *q, int row, mech_gap *g)
{
    cont *c = &r->c;
    size_t bytes = (size_t)c->sv.p->ns * sizeof(double);
    double hrow = q[row] - q[row - 1], fq = c->fail_q, qbase = c->qc;
    step_status s = c->fail_status;
    memcpy(c->xgap, c->xc, bytes);
    memcpy(c->xqgap, c->xqc, bytes);
    memcpy(c->xqqgap, c->xqqc, bytes);
    diagnose_failure(c, q[row], hrow);
    *g = (mech_gap){gap_kind(c, s), row, row, qbase, qbase, 1, 0};
    cont_set_base(c, qbase, c->xgap, c->xqgap, c->xqqgap);
    c->searching = 1;
    cont_advance(c, fq, 1e-12 * fmax(fabs(hrow), 1e-12));
    g->from = c->qc;
    memcpy(c->xgap, c->xc, bytes);
    return limit_row(r, g->from, c->xgap);
}

/* After a gap, the row at q[row]: re-assembly, the limit behind it (and its
 * row), then the row itself. MECH_ESOLVE when it does not assemble. */
static int restart_row(run *r, const double *q, int row, mech_gap *g)
{
    cont *c = &r->c;
    if (cont_restart(c, q[row]) != MECH_OK)
        return MECH_ESOLVE;
    int found = 0, rc = MECH_OK;
    g->to = q[row];
    if (row > 0) {
        double h = 1e-12 * fmax(fabs(q[row] - q[row - 1]), 1e-12);
        g->to = cont_limit_behind(c, q[row - 1], h, &found);
        if (found)
            rc = limit_row(r, g->to, c->xc);
        cont_back_to_start(c);
    }
    g->to_limit = found;
    c->row_iters = 0;  /* the search is not the row's work */
    c->row_substeps = 0;
    return rc != MECH_OK ? rc : fill_row(r, q[row]);
}

/* Row `row`: reach it (row 0 from the guesses, after a gap by a restart,
 * else by continuation) and append it. MECH_ESOLVE when it cannot be
 * reached (*g then describes the gap it opens), else fill_row's status. */
static int solve_row(run *r, const double *q, int row, mech_gap *g, int in_gap)
{
    cont *c = &r->c;
    c->row_iters = 0;
    c->row_substeps = 0;
    if (in_gap)
        return restart_row(r, q, row, g);
    if (row == 0) {
        if (cont_start(c, q[0]) != MECH_OK) {
            unsigned rng = 0;
            cont_start_values(c, 0, &rng);
            memcpy(c->xgap, c->sv.x, (size_t)c->sv.p->ns * sizeof *c->xgap);
            *g = (mech_gap){gap_kind(c, c->fail_status), 0, 0, q[0], q[0], 0, 0};
            return MECH_ESOLVE;
        }
    } else if (cont_advance(c, q[row], 1e-9 * fmax(fabs(q[row] - q[row - 1]), 1e-12)) !=
               STEP_OK) {
        int rc = failed_row(r, q, row, g);
        return rc != MECH_OK ? rc : MECH_ESOLVE;
    }
    return fill_row(r, q[row]);
}

/* Append *g to the table's gaps (allocated only when a gap closes). */
static int add_gap(mech_table *t, const mech_gap *g)
{
    mech_gap *more = realloc(t->gaps, (size_t)(t->ngaps + 1) * sizeof *more);
    if (!more)
        return -1;
    t->gaps = more;
    t->gaps[t->ngaps++] = *g;
    return 0;
}

/* Every requested row that can be reached; the others as gaps. A failure
 * of the forces stops the sweep (its status returned). */
static int sweep_rows(run *r, const double *q, int nq)
{
    int status = MECH_OK, in_gap = 0;
    mech_gap g = {0};
    const mech_solve_options *o = &r->a->opt;
    for (int row = 0; row < nq; row++) {
        if (o->progress && row > 0 && (row & 4095) == 0)
            o->progress(o->progress_ctx, row, nq);
        int rc = solve_row(r, q, row, &g, in_gap);
        if (rc == MECH_OK) {
            if (in_gap && add_gap(r->t, &g) != 0)
                return no_memory(r->a->m, r->d);
            in_gap = 0;
            continue;
        }
        if (rc != MECH_ESOLVE)
            return rc == ROW_STOP ? MECH_ESOLVE : rc;
        status = MECH_ESOLVE;
        g.last_row = row;
        in_gap = 1;
    }
    if (o->progress)
        o->progress(o->progress_ctx, nq, nq);
    if (in_gap) {
        g.to = q[nq - 1];
        g.to_limit = 0;
        if (add_gap(r->t, &g) != 0)
            return no_memory(r->a->m, r->d);
    }
    return status;
}

static void finish_stats(run *r, int rows, double t0)
{
    mech_solve_stats *st = r->st;
    const solver_plan *sp = &r->a->sp;
    st->steps = rows;
    st->seconds = now_seconds() - t0;
    st->setup_seconds = r->a->setup_seconds;
    st->factorizations = r->c.sv.ls.factorizations;
    st->refactorizations = r->c.sv.ls.refactorizations;
    st->nunknowns = sp->n;
    st->nsolved = sp->ns;
    st->nblocks = sp->nblocks;
    st->nblocks_solved = sp->nblocks_solved;
}

static int run_init(run *r, const mech_analysis *a, mech_diag *d)
{
    if (cont_init(&r->c, &a->sp, d, r->st) != 0)
        return no_memory(a->m, d);
    if (a->want_forces && forces_init(&r->fc, &a->fp) != 0)
        return no_memory(a->m, d);
    return MECH_OK;
}

int mech_analysis_solve(const mech_analysis *a, const double *q, int nq, mech_table *out,
                        mech_solve_stats *stats, mech_diag *d)
{
    mech_solve_stats local;
    run r;
    memset(&r, 0, sizeof r);
    memset(out, 0, sizeof *out);
    r.a = a;
    r.d = d;
    r.st = stats ? stats : &local;
    memset(r.st, 0, sizeof *r.st);
    r.st->min_rcond = INFINITY;
    if (!q) {
        q = a->values;
        nq = a->nvalues;
    }
    int rc = too_large(a, nq, d) ? MECH_EINPUT : run_init(&r, a, d);
    /* with limit rows, at most one more per requested row and one more */
    int capacity = a->opt.limit_rows ? 2 * nq + 1 : nq;
    if (rc == MECH_OK && columns_make_table(&a->cols, out, capacity) != MECH_OK)
        rc = no_memory(a->m, d);
    double t0 = now_seconds();
    out->nrequested = nq;
    r.t = out;
    if (rc == MECH_OK)
        rc = sweep_rows(&r, q, nq);
    finish_stats(&r, out->nrows, t0);
    forces_free(&r.fc);
    cont_free(&r.c);
    return rc;
}

int mech_solve(const mech_model *m, const mech_solve_options *o, mech_table *out,
               mech_solve_stats *stats, mech_diag *d)
{
    mech_analysis *a = NULL;
    memset(out, 0, sizeof *out);
    int rc = mech_analysis_new(m, o, &a, d);
    if (rc == MECH_OK)
        rc = mech_analysis_solve(a, NULL, 0, out, stats, d);
    else if (stats)
        memset(stats, 0, sizeof *stats);
    mech_analysis_free(&a);
    return rc;
}
