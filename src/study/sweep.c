/* src/study/sweep.c: the analysed system (mech_analysis) and the driver sweep
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

#include "base.h"
#include "study.h"
#include "solve.h"

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

/* A free driver (docs/dynamics.md) at rest: its stand-in law for the sweep
 * is a constant, so the assembly checks would call the still outputs a
 * degenerate assembly. */
static int still_free_driver(const mech_model *m)
{
    for (int i = 0; m->free_drivers && i < m->free_drivers->n; i++)
        if (m->free_drivers->d[i].speed == 0.0)
            return 1;
    return 0;
}

/* ---- the analysed system ------------------------------------------------- */

static int no_memory(const mech_model *m, mech_diag *d)
{
    return diag_nomem(d, m->file, (mech_mark){0, 0});
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
    to->cams = xcalloc((size_t)from->ncams + 1, sizeof *to->cams);
    if (!to->points || !to->links || !to->sliders || !to->cams) {
        mech_outputs_free(to);
        return -1;
    }
    if (from->ncams)
        memcpy(to->cams, from->cams, (size_t)from->ncams * sizeof *to->cams);
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
    /* the sweep needs only the compiled plan; a sweep's shared analysis (a
       system with leaves) is kept whole: it lives as long as the sweep */
    if (a->sp.sys && a->sp.nleaf == 0)
        solver_plan_compact(&a->sp);
    column_request rq = {&a->outputs, a->sp.level, a->want_forces, friction_columns(a),
                         a->opt.diagnostics};
    if (columns_build(&a->cols, m, &rq) != MECH_OK)
        return no_memory(m, d);
    if (!(a->values = sweep_values(m, &a->opt, &a->nvalues)))
        return no_memory(m, d);
    return too_large(a, a->nvalues, d) ? MECH_EINPUT : MECH_OK;
}

/* The public entries' analysis: m and out required, o read by its size
 * (NULL: the defaults), d a real diag. */
static int analysis_new_checked(const char *func, const mech_model *m,
                                const mech_solve_options *o, mech_analysis **out, mech_diag *d)
{
    mech_solve_options full;
    if (out)
        *out = NULL;
    int rc = !m || !out ? api_null(d, func, m ? "out" : "m") : api_options(o, &full, func, d);
    return rc == MECH_OK ? analysis_new_with(m, &full, NULL, out, d) : rc;
}

int mech_analysis_new(const mech_model *m, const mech_solve_options *o, mech_analysis **out,
                      mech_diag *d)
{
    mech_diag own, *dd = api_diag(d, &own);
    int rc = analysis_new_checked("mech_analysis_new", m, o, out, dd);
    api_diag_end(d, &own);
    return rc;
}

int analysis_new_with(const mech_model *m, const mech_solve_options *o, mech_system *sys,
                      mech_analysis **out, mech_diag *d)
{
    *out = NULL;
    if (!m->has_driver) {
        mech_system_free(&sys);
        return diag_error(d, m->file, (mech_mark){0, 0}, "the mechanism has no driver");
    }
    double t0 = clock_seconds();
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
    a->setup_seconds = clock_seconds() - t0;
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

/* ---- the numbers, and a variant's view of an analysis (variant_regs.h) ---- */

/* Every number the plans take from a model, from m: the solver plan's and
 * the force plan's (the column layout holds none). The plans' set-up
 * computes them through the same per-plan functions. 0, or -1 out of
 * memory. */
static int analysis_numbers(mech_analysis *a, const mech_model *m)
{
    a->m = m;
    solver_plan_numbers(&a->sp, m);
    return a->want_forces ? forces_plan_numbers(&a->fp, &a->sp) : 0;
}

/* A view is a copy of the analysis: the structure is the base's, shared and
 * read only; the numbers are the view's own, from the variant's model. */
mech_analysis *analysis_view_new(const mech_analysis *base, const mech_model *mv)
{
    mech_analysis *a = xcalloc(1, sizeof *a);
    if (!a)
        return NULL;
    *a = *base;
    memset(&a->fp.num, 0, sizeof a->fp.num);  /* the base's: the view computes its own */
    if (solver_numbers_alloc(&a->sp) < 0 || analysis_numbers(a, mv) < 0) {
        analysis_view_free(&a);  /* what is not the view's own is the base's */
        return NULL;
    }
    return a;
}

void analysis_view_free(mech_analysis **pv)
{
    if (!pv || !*pv)
        return;
    if ((*pv)->want_forces)
        forces_numbers_free(&(*pv)->fp.num);
    solver_numbers_free(&(*pv)->sp);
    free(*pv);
    *pv = NULL;
}

const mech_system *analysis_system(const mech_analysis *a) { return a->sp.sys; }

const solver_plan *analysis_solver_plan(const mech_analysis *a) { return &a->sp; }

const forces_plan *analysis_forces_plan(const mech_analysis *a)
{
    return a->want_forces ? &a->fp : NULL;
}

const double *analysis_positions(const mech_analysis *a, int *n)
{
    *n = a->nvalues;
    return a->values;
}

int mech_analysis_columns(const mech_analysis *a) { return a ? a->cols.ncols : 0; }

int mech_analysis_header(const mech_analysis *a, mech_table *out)
{
    return a && out ? columns_make_table(&a->cols, out, 0) : MECH_EINPUT;
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
    int lift_off;              /* a cam's lift-off reported (the first only) */
    assembly_samples smp;      /* positions kept for the assembly's checks (assembly.c) */
} run;

/* The requested row at q failed with kind k: the solve's failure is the
 * gravest found (mech_solve_stats.failure), at the first row that had it. */
static void note_failure(run *r, mech_fail_kind k, double q)
{
    mech_fail_kind now = r->st->failure;
    r->st->failure = fail_graver(now, k);
    if (r->st->failure != now)
        r->st->failure_q = q;
}

/* The force analysis failed at q (forces_solve's rc -1 or -2): why, and
 * its kind; MECH_ESOLVE. Kept out of solve_forces, which runs every row. */
static int forces_failed(run *r, double q, int rc)
{
    const mech_model *m = r->a->m;
    char qb[64], joints[400];
    mech_fail_kind k = rc == -1 ? MECH_FAIL_REDUNDANT : MECH_FAIL_NOT_CONVERGED;
    note_failure(r, k, q);
    if (rc == -1) {
        forces_singular_joints(&r->fc, joints, sizeof joints);
        return diag_fail(r->d, k, m->file, m->driver.mark,
                         "the force system is singular at %s = %s (reciprocal condition %.2g): "
                         "%s make the reactions of %s not unique",
                         diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb),
                         r->fc.rcond, fail_words(k), joints[0] ? joints : "some joints");
    }
    return diag_fail(r->d, k, m->file, m->driver.mark,
                     "joint friction %s at %s = %s (fixed-point iteration, "
                     "%d steps): the friction coefficients may make the mechanism "
                     "self-locking there", fail_words(k), diagnose_driver_word(m),
                     diagnose_q_text(m, q, qb, sizeof qb), 100);
}

/* A cam's contact cannot pull (docs/cams.md 6): the first row where one
 * would is a warning naming the cam and the driver's position. */
static void check_lift_off(run *r, double q)
{
    const mech_model *m = r->a->m;
    for (int i = 0; i < model_ncams(m) && !r->lift_off; i++) {
        double f = forces_cam(&r->fc, i, 1);
        if (f >= 0.0)
            continue;
        char qb[64];
        r->lift_off = 1;
        diag_warning(r->d, m->file, m->cams->cam[i].mark, "cam '%s': the follower lifts off "
                     "at %s = %s: the contact would have to pull (%.6g N); a follower spring "
                     "with more preload or stiffness, or a lower speed, keeps it on the cam "
                     "(the rows there are not a motion that can happen)", m->cams->cam[i].name,
                     diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb), f);
    }
}

static int solve_forces(run *r, double q)
{
    int rc = forces_solve(&r->fc, &r->c.sv);
    if (rc < 0)
        return forces_failed(r, q, rc);
    check_lift_off(r, q);
    double worst = fmax(fabs(r->fc.out.residual), fabs(r->fc.out.residual0));
    if (worst > r->st->worst_power_residual)
        r->st->worst_power_residual = worst;
    if (r->fc.out.iterations > r->st->max_friction_iterations)
        r->st->max_friction_iterations = r->fc.out.iterations;
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
              r->c.row_substeps + 1, solver_rcond(&r->c.sv));
}

/* A value that is not a finite number is never passed off as a result:
 * an error naming the column and the driver position (extreme data, such
 * as a driver speed of 1e160 rad/s, overflow the rates). `mech solve
 * --jit` checks the generated code's rows with it too. */
int analysis_check_finite(const mech_analysis *a, double q, const double *out, mech_diag *d)
{
    const column_layout *cl = &a->cols;
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
    const mech_model *m = a->m;
    char qb[64];
    return diag_fail(d, MECH_FAIL_NON_FINITE, m->file, m->driver.mark,
                     "at %s = %s the column %s is %s, %s: the data overflow "
                     "double precision (check the driver's speed and acceleration, the "
                     "masses and loads, and their units)",
                     diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb),
                     cl->cols[c].name, isnan(out[c]) ? "NaN" : out[c] > 0 ? "+inf" : "-inf",
                     fail_words(MECH_FAIL_NON_FINITE));
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
    if (r->a->opt.diagnostics)
        solver_rcond(&c->sv);  /* the rcond column: exact */
    row_sources rs = {&c->sv, r->a->want_forces ? &r->fc : NULL, c->row_iters, c->row_substeps};
    columns_fill(&r->a->cols, &rs, out);
    if (analysis_check_finite(r->a, q, out, r->d) != MECH_OK) {
        note_failure(r, MECH_FAIL_NON_FINITE, q);
        return ROW_STOP;
    }
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
    note_failure(r, diagnose_failure(c, q[row], hrow), q[row]);
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
            note_failure(r, c->fail_kind, q[0]);
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

/* A law of time not defined at q (a log of a negative number, a division
 * by zero, a corner of abs): an error at the driver, naming the time and
 * why, not NaN rows (docs/motion-programs.md). */
static int undefined_law(run *r, double q)
{
    const mech_model *m = r->a->m;
    char why[160];
    int k = drivers_undefined(m, q, why, sizeof why);
    if (k < 0)
        return MECH_OK;
    return diag_error(r->d, m->file, m->drivers[k].mark, "driver '%s': its law is not defined "
                      "at t = %.10g s: %s", drivers_name(m, k), q, why);
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
        if (undefined_law(r, q[row]) != MECH_OK)
            return MECH_EINPUT;
        int rc = solve_row(r, q, row, &g, in_gap);
        if (rc == MECH_OK && row >= r->smp.next_row)
            assembly_take(&r->smp, row, q[row], r->c.sv.x);
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
    st->seconds = clock_seconds() - t0;
    st->setup_seconds = r->a->setup_seconds;
    st->factorizations = r->c.sv.ls.factorizations;
    st->refactorizations = r->c.sv.ls.refactorizations;
    st->nunknowns = sp->n;
    st->nsolved = sp->ns;
    st->nblocks = sp->nblocks;
    st->nblocks_solved = sp->nblocks_solved;
}

static int run_init(run *r, const mech_analysis *a, int nq, mech_diag *d)
{
    if (cont_init(&r->c, &a->sp, d, r->st) != 0)
        return no_memory(a->m, d);
    if (assembly_samples_init(&r->smp, a->sp.ns, nq) != 0)
        return no_memory(a->m, d);
    if (a->want_forces && forces_init(&r->fc, &a->fp) != 0)
        return no_memory(a->m, d);
    return MECH_OK;
}

static int analysis_solve(const mech_analysis *a, const double *q, int nq, mech_table *out,
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
    r.st->failure_q = NAN;
    if (!q) {
        q = a->values;
        nq = a->nvalues;
    }
    int rc = too_large(a, nq, d) ? MECH_EINPUT : run_init(&r, a, nq, d);
    /* with limit rows, at most one more per requested row and one more */
    int capacity = a->opt.limit_rows ? 2 * nq + 1 : nq;
    if (rc == MECH_OK && columns_make_table(&a->cols, out, capacity) != MECH_OK)
        rc = no_memory(a->m, d);
    double t0 = clock_seconds();
    out->nrequested = nq;
    r.t = out;
    if (rc == MECH_OK)
        rc = sweep_rows(&r, q, nq);
    if (r.smp.n > 0 && !still_free_driver(a->m)) {
        r.smp.x_guessed = r.c.xdrawn;  /* a drawn file's guesses hold at its drawing */
        assembly_check(&r.c.sv, &r.smp, d);
    }
    if (rc != MECH_OK && r.st->failure == MECH_FAIL_NONE)  /* not at a row: too large, memory */
        r.st->failure = fail_of_status(rc);
    finish_stats(&r, out->nrows, t0);
    forces_free(&r.fc);
    cont_free(&r.c);
    assembly_samples_free(&r.smp);
    return rc;
}

int analysis_assembly_check(const mech_analysis *a, assembly_samples *smp, mech_diag *d)
{
    if (smp->n == 0 || still_free_driver(a->m))
        return 0;
    solver sv;
    int rc = solver_init(&sv, &a->sp);
    if (rc == 0)
        assembly_check(&sv, smp, d);
    solver_free(&sv);
    return rc == 0 ? 0 : -1;
}

/* The public sweeps: out may be NULL (the rows are not kept), stats and d
 * too (mech.h, "NULL arguments"). */
int mech_analysis_solve(const mech_analysis *a, const double *q, int nq, mech_table *out,
                        mech_solve_stats *stats, mech_diag *d)
{
    mech_table unused;
    mech_table *t = out ? out : &unused;
    mech_diag own, *dd = api_diag(d, &own);
    int rc;
    memset(t, 0, sizeof *t);
    if (!a)
        rc = api_null(dd, "mech_analysis_solve", "a");
    else if (q && nq < 0)
        rc = diag_error(dd, "mech_analysis_solve", (mech_mark){0, 0},
                        "nq is %d: the number of driver positions in q", nq);
    else
        rc = analysis_solve(a, q, nq, t, stats, dd);
    if (!out)
        mech_table_free(&unused);
    api_diag_end(d, &own);
    return rc;
}

int mech_solve(const mech_model *m, const mech_solve_options *o, mech_table *out,
               mech_solve_stats *stats, mech_diag *d)
{
    mech_analysis *a = NULL;
    mech_table unused;
    mech_table *t = out ? out : &unused;
    mech_diag own, *dd = api_diag(d, &own);
    memset(t, 0, sizeof *t);
    int rc = analysis_new_checked("mech_solve", m, o, &a, dd);
    if (rc == MECH_OK)
        rc = analysis_solve(a, NULL, 0, t, stats, dd);
    else if (stats)
        *stats = (mech_solve_stats){.failure = fail_of_status(rc), .failure_q = NAN};
    mech_analysis_free(&a);
    if (!out)
        mech_table_free(&unused);
    api_diag_end(d, &own);
    return rc;
}
