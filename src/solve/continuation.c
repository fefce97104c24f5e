/* src/solve/continuation.c: from one driver position to the next
 * (continuation.h, docs/solver.md): row 0 from the guesses, then predict,
 * correct by Newton, check, accept or halve the step. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "solve.h"
#include "load.h"

static const double PI = 3.14159265358979323846;

/* The largest move of the unknowns (rad, or lref for slides) a step may
 * predict: over a longer one the Taylor prediction says little, and Newton
 * from it may land on another assembly without either check (correction
 * against the move, det J's sign) noticing, when two loops jump at once. */
static const double MAX_PREDICTED_MOVE = 0.25;

/* Scattered starts tried for the unknowns without a guess at row 0. */
enum { START_ATTEMPTS = 48 };

/* The file's guess for each unknown (NAN: none), gathered once: looking
 * the guesses up per unknown would cost O(unknowns x guesses). */
static int gather_guesses(cont *c)
{
    const solver_plan *sp = c->sv.p;
    const mech_model *m = c->m;
    c->guess = xcalloc((size_t)sp->n + 1, sizeof *c->guess);
    if (!c->guess)
        return -1;
    for (int i = 0; i < sp->n; i++)
        c->guess[i] = NAN;
    for (int g = 0; g < m->nguesses; g++) {
        const mech_guess *gs = &m->guesses[g];
        int var = gs->is_slider ? sp->sys->joint_var[gs->index] : sp->sys->link_var[gs->index];
        if (var >= 0 && var < sp->n)
            c->guess[var] = gs->value;
    }
    return 0;
}

int cont_init(cont *c, const solver_plan *sp, mech_diag *d, mech_solve_stats *st)
{
    memset(c, 0, sizeof *c);
    c->m = sp->m;
    c->d = d;
    c->st = st;
    c->qd = sp->m->driver.speed;
    c->qdd = sp->m->driver.accel;
    if (solver_init(&c->sv, sp) != 0)
        return -1;
    size_t ns = (size_t)sp->ns + 1;
    double **arrays[] = {&c->xc, &c->xqc, &c->xqqc, &c->xqq_prev, &c->xpred,
                         &c->x0, &c->xq0, &c->xqq0, &c->xgap, &c->xqgap, &c->xqqgap};
    if (xcalloc_doubles(arrays, NULL, ns, COUNT_OF(arrays)) < 0)
        return -1;
    return gather_guesses(c);
}

void cont_free(cont *c)
{
    void *blocks[] = {c->xc, c->xqc, c->xqqc, c->xqq_prev, c->xpred, c->x0,
                      c->xq0, c->xqq0, c->guess, c->xgap, c->xqgap, c->xqqgap, c->xdrawn};
    free_all(blocks, COUNT_OF(blocks));
    solver_free(&c->sv);
    memset(c, 0, sizeof *c);
}


/* Taylor: x + h x_q + h^2/2 x_qq + h^3/6 x_qqq, with x_qqq from the last two
 * x_qq (x_q and x_qq are solved at every position, whatever the output
 * level: solver_rates). The cubic term makes
 * the error of a 1-degree step about 1e-8 instead of 1e-6, so that one
 * Newton correction reaches rounding and the second iteration only
 * confirms it: two evaluations and factorisations per step instead of three
 * (docs/solver.md, section 4). */
static void predict(cont *c, double qn)
{
    solver *sv = &c->sv;
    double h = qn - c->qc, dq = c->qc - c->q_prev;
    int prev = c->have_prev && dq != 0.0;
    for (int i = 0; i < sv->p->ns; i++) {
        double xqqq = prev ? (c->xqqc[i] - c->xqq_prev[i]) / dq : 0.0;
        c->xpred[i] = c->xc[i] + h * (c->xqc[i] + h * (0.5 * c->xqqc[i] + h * xqqq / 6.0));
    }
    memcpy(sv->x, c->xpred, (size_t)sv->p->ns * sizeof *sv->x);
}

/* The signed quantity of branch condition b at the published position. */
static double branch_value(cont *c, const mech_branch *b)
{
    if (b->kind == MECH_BRANCH_SLIDER) {
        int var = c->sv.p->tree.slide_var[b->slider];
        return var >= 0 ? c->sv.pos[var] : 0.0;
    }
    double p[3][2];
    for (int k = 0; k < 3; k++)
        kin_point(&c->sv.p->tree, &c->sv.ks, b->point[k], p[k], NULL, NULL);
    if (b->kind == MECH_BRANCH_X)
        return p[0][0] - p[1][0];
    if (b->kind == MECH_BRANCH_Y)
        return p[0][1] - p[1][1];
    return (p[1][0] - p[0][0]) * (p[2][1] - p[1][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[1][0]);
}

int cont_branches_hold(cont *c, int *which, int continuing)
{
    const mech_model *m = c->m;
    for (int b = 0; b < m->nbranches; b++) {
        if (continuing && m->branches[b].first_only)
            continue;
        if (branch_value(c, &m->branches[b]) * m->branches[b].sign <= 0.0) {
            *which = b;
            return 0;
        }
    }
    return 1;
}

/* det J changed sign between the base and qn: a singular position was
 * crossed (a change point); the sweep may have passed to another assembly. */
static void note_crossing(cont *c, double qn)
{
    int sign = c->try_sign;  /* of the step being accepted (cont_try) */
    if (sign != 0 && c->det_sign != 0 && sign != c->det_sign && !c->searching &&
        c->crossings++ < 10) {
        char qab[128], loops[400], where[420] = "";
        diagnose_dependent_rows(&c->sv, loops, sizeof loops);  /* J nearly singular here */
        if (loops[0])
            snprintf(where, sizeof where, " of %s", loops);
        diag_add(c->d, MECH_SEV_WARNING, MECH_FAIL_CHANGE_POINT, c->m->file,
                 c->m->driver.mark, "between %s = %s the Jacobian's determinant changes sign: "
                 "the sweep passed a change point%s, where assembly branches cross, and may "
                 "continue on the other assembly; declare `branch:` to keep one",
                 diagnose_driver_word(c->m),
                 diagnose_q_interval(c->m, c->qc, qn, qab, sizeof qab), where);
    }
    if (sign != 0)
        c->det_sign = sign;
}

/* Keep the converged x at qn as the new base of the continuation. */
static void accept(cont *c, double qn)
{
    solver *sv = &c->sv;
    note_crossing(c, qn);
    size_t bytes = (size_t)sv->p->ns * sizeof(double);
    memcpy(c->xqq_prev, c->xqqc, bytes);
    c->q_prev = c->qc;
    c->have_prev = 1;
    c->qc = qn;
    memcpy(c->xc, sv->x, bytes);
    memcpy(c->xqc, sv->xq, bytes);
    memcpy(c->xqqc, sv->xqq, bytes);
}

static void note_stats(cont *c, double q)
{
    solver *sv = &c->sv;
    mech_solve_stats *st = c->st;
    if (sv->resid > st->worst_residual)
        st->worst_residual = sv->resid;
    /* a bound at or above the smallest so far cannot lower it */
    if (sv->rcond < st->min_rcond && solver_rcond(sv) < st->min_rcond) {
        st->min_rcond = sv->rcond;
        st->worst_rcond_q = q;
    }
}

/* Newton at qn from sv->x, then the checks that make a step acceptable. */
step_status cont_try(cont *c, double qn, int continuing)
{
    solver *sv = &c->sv;
    step_status s = solver_newton(sv, qn);
    c->row_iters += sv->iters;
    if (s != STEP_OK)
        return s;
    if (continuing) {
        /* correction against predicted move: large means another solution */
        for (int i = 0; i < sv->p->ns; i++)
            sv->dx[i] = sv->x[i] - c->xpred[i];
        double corr = solver_step_size(sv->p, sv->dx);
        if (corr > 0.5 * c->pred_move + 0.05)
            return STEP_JUMP;
        /* det J changed sign: a singular position was crossed, or Newton
           fell onto another assembly that the test above let pass (a long
           step, whose prediction means little). Shorten the step: a change
           point is still crossed at a short one, a jump is not. */
        c->try_sign = solver_det_sign(sv);
        if (c->try_sign != 0 && c->det_sign != 0 && c->try_sign != c->det_sign &&
            fabs(qn - c->qc) > c->hcross)
            return STEP_JUMP;
    } else {
        c->try_sign = solver_det_sign(sv);
    }
    solver_rates(sv);
    int b;
    if (c->m->nbranches) {  /* the branch test needs the point positions */
        solver_publish(sv, qn, c->qd, c->qdd);  /* the row's own, unless rejected */
        if (!cont_branches_hold(c, &b, continuing))
            return STEP_BRANCH;
    }
    return STEP_OK;
}

/* From the base c->qc to q by continuation, halving rejected steps. */
/* How far the prediction moves the unknowns from the base (angles in rad,
 * slides in lref). */
static double predicted_move(cont *c)
{
    solver *sv = &c->sv;
    for (int i = 0; i < sv->p->ns; i++)
        sv->dx[i] = c->xpred[i] - c->xc[i];
    return solver_step_size(sv->p, sv->dx);
}

step_status cont_advance(cont *c, double q, double hmin)
{
    double h = q - c->qc;
    step_status s = STEP_OK;
    c->fail_status = STEP_OK;
    c->hcross = 1e6 * hmin;  /* 1e-3 of the row spacing */
    while (c->qc != q) {
        double remaining = q - c->qc;
        double qn = fabs(remaining) <= fabs(h) * (1.0 + 1e-12) ? q : c->qc + h;
        predict(c, qn);
        c->pred_move = predicted_move(c);
        if (fabs(h) > c->hcross && c->pred_move > MAX_PREDICTED_MOVE) {
            h *= 0.5;  /* beyond the predictor's reach: shorten before solving */
            continue;
        }
        s = cont_try(c, qn, 1);
        if (s == STEP_OK) {
            note_stats(c, qn);
            accept(c, qn);
            if (c->qc != q)
                c->row_substeps++;
            if (fabs(2.0 * h) <= fabs(q - c->qc))
                h *= 2.0;  /* recover the step after a difficulty */
            continue;
        }
        if (c->fail_status == STEP_OK) {
            c->fail_resid = vec_norm_inf(c->sv.f, c->sv.p->nr);
            c->fail_row = diagnose_worst_row(&c->sv);
        }
        c->fail_q = qn;
        c->fail_status = s;
        if (fabs(h) <= hmin)
            return s;
        h *= 0.5;
    }
    return STEP_OK;
}

/* ---- row 0 --------------------------------------------------------------- */

static unsigned next_random(unsigned *state)
{
    *state = *state * 1664525u + 1013904223u;
    return *state >> 8;
}

/* Starting values: the file's guesses; the others 0 on the first attempt,
 * scattered over a turn (angles) or +-2 lref (slides) later. */
void cont_start_values(cont *c, int attempt, unsigned *rng)
{
    solver *sv = &c->sv;
    const solver_plan *sp = sv->p;
    for (int i = 0; i < sp->ns; i++) {
        int var = sp->col[i];
        double u = attempt ? (double)(next_random(rng) & 0xffff) / 65536.0 - 0.5 : 0.0;
        sv->x[i] = sp->sys->unk_kind[var] == UNK_ANGLE ? 2.0 * PI * u : 4.0 * sp->lref * u;
        if (!isnan(c->guess[var]))
            sv->x[i] = c->guess[var];
    }
}

static int has_unguessed(const cont *c)
{
    for (int i = 0; i < c->sv.p->ns; i++)
        if (isnan(c->guess[c->sv.p->col[i]]))
            return 1;
    return 0;
}

/* What failed start attempt a tells the diagnosis (start_failure): the
 * first as it is; the one whose loops came closest to closing, its x kept
 * in c->xgap (scratch until a gap is opened). */
static void note_attempt(cont *c, start_failure *f, int a, step_status s)
{
    solver *sv = &c->sv;
    double resid = vec_norm_inf(sv->f, sv->p->nr);  /* at x: also where Newton stopped */
    if (a == 0) {
        f->first = s;
        f->resid = s == STEP_SINGULAR ? resid : sv->resid;
        f->row = diagnose_worst_row(sv);
    }
    f->best_is_last = 0;
    if (a == 0 || resid < f->best_resid) {
        f->best_resid = resid;
        f->best_is_last = 1;
        memcpy(c->xgap, sv->x, (size_t)sv->p->ns * sizeof *sv->x);
    }
}

/* The continuation's status for the kind row 0's failure was reported as
 * (the gap's kind, sweep.c). */
static step_status status_of_kind(mech_fail_kind k)
{
    return k == MECH_FAIL_DEAD_POINT || k == MECH_FAIL_CHANGE_POINT ? STEP_SINGULAR
           : k == MECH_FAIL_BRANCH ? STEP_BRANCH : STEP_NO_ASSEMBLY;
}

/* Row 0 also fixes the base of the continuation and row 0's copy (for the
 * assembly search after a failure). */
static int cont_start_at(cont *c, double q);
static void set_start(cont *c, double q);

/* Row 0 of a drawn file: assembled at the drawing's driver value, where its
 * guesses hold, then continued to q (docs/format.md 5.4). */
int cont_start(cont *c, double q)
{
    double q0 = c->m->start_q;
    if (!c->m->has_start || q0 == q)
        return cont_start_at(c, q);
    if (cont_start_at(c, q0) != MECH_OK)
        return MECH_ESOLVE;
    if (!c->xdrawn)
        c->xdrawn = xcalloc((size_t)c->sv.p->ns + 1, sizeof *c->xdrawn);
    if (c->xdrawn)  /* the drawing's assembly, for the check against its guesses */
        memcpy(c->xdrawn, c->sv.x, (size_t)c->sv.p->ns * sizeof *c->xdrawn);
    c->det_sign = solver_det_sign(&c->sv);
    if (cont_advance(c, q, 1e-9 * fabs(q - q0)) != STEP_OK) {
        c->fail_kind = c->fail_status == STEP_SINGULAR ? MECH_FAIL_DEAD_POINT
                       : c->fail_status == STEP_BRANCH ? MECH_FAIL_BRANCH
                                                       : MECH_FAIL_NO_ASSEMBLY;
        c->fail_status = status_of_kind(c->fail_kind);
        int angle = c->m->driver.kind == MECH_DRIVE_ANGLE;
        double k = angle ? 180.0 / PI : 1e3;
        const char *u = angle ? "deg" : "mm";
        diag_fail(c->d, c->fail_kind, c->m->file, c->m->driver.mark, "the drawn assembly, "
                  "followed from the drawing's driver value %.6g %s towards the sweep's first "
                  "value %.6g %s, stops at %.6g %s", q0 * k, u, q * k, u, c->qc * k, u);
        return MECH_ESOLVE;
    }
    c->det_sign = 0;
    c->row_substeps = 0;  /* the way from the drawing is no refinement of row 0 */
    set_start(c, q);
    return MECH_OK;
}

static int cont_start_at(cont *c, double q)
{
    solver *sv = &c->sv;
    unsigned rng = 20261121u;
    /* drivers as laws of time: the driven unknowns start at their laws */
    drivers_guess(c->m, sv->p->sys->link_var, sv->p->sys->joint_var, q, c->guess);
    start_failure f = {.branch = -1};
    f.attempts = has_unguessed(c) ? START_ATTEMPTS : 1;
    step_status s = STEP_NO_ASSEMBLY;
    for (int a = 0; a < f.attempts; a++) {
        cont_start_values(c, a, &rng);
        s = cont_try(c, q, 0);
        if (s == STEP_OK)
            break;
        note_attempt(c, &f, a, s);
        if (s == STEP_BRANCH)
            cont_branches_hold(c, &f.branch, 0);
    }
    if (s != STEP_OK) {
        c->fail_kind = diagnose_start(c, q, &f);
        c->fail_status = status_of_kind(c->fail_kind);
        return MECH_ESOLVE;
    }
    note_stats(c, q);
    c->qc = q;
    accept(c, q);
    c->have_prev = 0;
    diagnose_redundant(c, q);
    c->q0 = q;
    size_t bytes = (size_t)sv->p->ns * sizeof(double);
    memcpy(c->x0, c->xc, bytes);
    memcpy(c->xq0, c->xqc, bytes);
    memcpy(c->xqq0, c->xqqc, bytes);
    return MECH_OK;
}

/* Keep the solved row at q as the base and as row 0's copy. */
static void set_start(cont *c, double q)
{
    solver *sv = &c->sv;
    note_stats(c, q);
    c->qc = q;
    c->det_sign = 0;  /* another interval may have the other sign */
    accept(c, q);
    c->have_prev = 0;
    c->q0 = q;
    size_t bytes = (size_t)sv->p->ns * sizeof(double);
    memcpy(c->x0, c->xc, bytes);
    memcpy(c->xq0, c->xqc, bytes);
    memcpy(c->xqq0, c->xqqc, bytes);
}

/* Scattered starting values for every unknown, guessed or not. */
static void scatter_all(cont *c, unsigned *rng)
{
    const solver_plan *sp = c->sv.p;
    for (int i = 0; i < sp->ns; i++) {
        double u = (double)(next_random(rng) & 0xffff) / 65536.0 - 0.5;
        c->sv.x[i] = sp->sys->unk_kind[sp->col[i]] == UNK_ANGLE ? 2.0 * PI * u : 4.0 * sp->lref * u;
    }
}

/* Scattered starts tried at each row of a gap. */
enum { RESTART_ATTEMPTS = 16 };

int cont_restart(cont *c, double q)
{
    solver *sv = &c->sv;
    const solver_plan *sp = sv->p;
    unsigned rng = 20261125u;
    int attempts = sp->ns <= 50 ? RESTART_ATTEMPTS : 2;
    for (int a = 0; a < attempts; a++) {
        if (a == 0)
            memcpy(sv->x, c->xgap, (size_t)sp->ns * sizeof *sv->x);
        else if (a == 1)
            cont_start_values(c, 0, &rng);
        else
            scatter_all(c, &rng);
        if (cont_try(c, q, 0) != STEP_OK)
            continue;
        for (int i = 0; i < sp->ns; i++)  /* angles continuous across the gap */
            if (sp->sys->unk_kind[sp->col[i]] == UNK_ANGLE)
                sv->x[i] -= 2.0 * PI * nearbyint((sv->x[i] - c->xgap[i]) / (2.0 * PI));
        c->searching = 0;
        set_start(c, q);
        return MECH_OK;
    }
    return MECH_ESOLVE;
}

double cont_limit_behind(cont *c, double qback, double hmin, int *found)
{
    int searching = c->searching;
    c->searching = 1;
    *found = cont_advance(c, qback, hmin) != STEP_OK;
    c->searching = searching;
    return c->qc;
}

step_status cont_solve_at(cont *c, double q, const double *x)
{
    memcpy(c->sv.x, x, (size_t)c->sv.p->ns * sizeof *c->sv.x);
    return cont_try(c, q, 0);
}

void cont_back_to_start(cont *c)
{
    solver *sv = &c->sv;
    if (cont_solve_at(c, c->q0, c->x0) != STEP_OK)  /* from its own solution: one iteration */
        memcpy(sv->x, c->x0, (size_t)sv->p->ns * sizeof *sv->x);
    cont_set_base(c, c->q0, c->x0, c->xq0, c->xqq0);
    c->det_sign = solver_det_sign(sv);
}

/* Make (q, x, x_q, x_qq) the base of the continuation. */
void cont_set_base(cont *c, double q, const double *x, const double *xq, const double *xqq)
{
    size_t bytes = (size_t)c->sv.p->ns * sizeof(double);
    memcpy(c->xc, x, bytes);
    memcpy(c->xqc, xq, bytes);
    memcpy(c->xqqc, xqq, bytes);
    c->qc = q;
    c->have_prev = 0;
}

/* From the base, march in direction dir by steps h until assembly fails or
 * `span` is covered; returns the last position reached (a limit when
 * *found). */
double cont_march(cont *c, double dir, double h, double span, int *found)
{
    double q0 = c->qc;
    *found = 0;
    for (double q = q0; fabs(q - q0) < span;) {
        q += dir * h;
        if (cont_advance(c, q, 1e-9 * fmax(h, 1e-12)) != STEP_OK) {
            *found = c->fail_status == STEP_NO_ASSEMBLY || c->fail_status == STEP_SINGULAR;
            return c->qc;
        }
    }
    return c->qc;
}

