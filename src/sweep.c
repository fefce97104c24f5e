/* src/sweep.c: mech_solve, the driver sweep (docs/solver.md).
 *
 * Row 0 is found by Newton from the file's guesses (then from scattered
 * starts for the unknowns without a guess) on the declared branch. Each
 * later row is reached by continuation: predict x(q + h) from x, dx/dq and
 * d2x/dq2, correct by Newton, and accept only when the correction is small
 * next to the predicted move (else the solution may have jumped to another
 * assembly) and the declared branch still holds. A rejected step is halved,
 * down to a tiny fraction of the row spacing; failing there locates an
 * assembly limit, a singular position or a branch point, which the error
 * message names with the driver position and the loops or unknowns. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "forces.h"
#include "solve.h"

static const double PI = 3.14159265358979323846;

/* Scattered starts tried for the unknowns without a guess at row 0. */
enum { START_ATTEMPTS = 48 };

typedef struct sweep {
    solver sv;
    forces fc;
    int want_forces;           /* joint reactions wanted */
    int friction_mode;         /* MECH_FRICTION_* */
    mech_table *out;
    mech_solve_stats *st;
    mech_diag *d;
    const mech_model *m;
    double qd, qdd;            /* driver speed and acceleration */
    /* the last accepted position and its rates (the continuation's base) */
    double qc;
    double *xc, *xqc, *xqqc;   /* [ns] */
    double *xqq_prev;          /* [ns] d2x/dq2 there: the predictor's third derivative */
    double q_prev;
    int have_prev;
    double *xpred;             /* [ns] */
    /* row 0, kept to look for the assembly range after a failure */
    double q0, *x0, *xq0, *xqq0;
    double *guess;             /* [n] the file's guess of each unknown, NAN if none */
    int row_iters;             /* Newton iterations spent on the current row */
    int row_substeps;          /* extra continuation steps the row needed (refinement) */
    int refined_notes;         /* refinements reported so far */
    int det_sign;              /* sign of det J at the base (0: unknown) */
    int crossings;             /* sign changes reported */
    int searching;             /* looking for assembly limits: no crossing reports */
    double fail_q;             /* where the last rejected attempt was */
    step_status fail_status;
    double fail_resid;         /* residual and worst loop of the first rejected attempt */
    int fail_loop;
} sweep;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- messages ------------------------------------------------------------ */

static int is_angle_driver(const mech_model *m) { return m->driver.kind == MECH_DRIVE_ANGLE; }

/* "123.4 deg" or "0.1834 m": the driver position as users think of it. */
static const char *q_text(const mech_model *m, double q, char *buf, size_t size)
{
    if (is_angle_driver(m))
        snprintf(buf, size, "%.6g deg", q * 180.0 / PI);
    else
        snprintf(buf, size, "%.6g mm", q * 1e3);
    return buf;
}

static const char *driver_word(const mech_model *m)
{
    return is_angle_driver(m) ? "driver angle" : "driver displacement";
}

/* "loop 2 (A-B-C-D-A)" */
static const char *loop_label(const solver *sv, int k, char *buf, size_t size)
{
    const mech_model *m = sv->m;
    const loop_set *ls = &sv->sys->loops;
    size_t at = (size_t)snprintf(buf, size, "loop %d (", k + 1);
    if (ls->from_file && k < m->nloops) {
        for (int i = 0; i < m->loops[k].npoints && at < size; i++)
            at += (size_t)snprintf(buf + at, size - at, "%s%s", i ? "-" : "",
                                   m->point_names[m->loops[k].points[i]]);
    } else {
        const char *first = NULL;  /* the point each term starts from */
        for (int t = ls->start[k]; t < ls->start[k + 1] && at < size; t++) {
            const loop_term *lt = &ls->terms[t];
            const char *p;
            if (lt->kind == TERM_BODY) {
                p = m->links[lt->link].points[lt->p0].name;
            } else {
                const mech_joint *j = &m->joints[lt->joint];
                int side = lt->sign > 0 ? 1 : 0;  /* + runs guide point -> mover */
                p = m->links[j->link[side]].points[j->point[side]].name;
            }
            first = first ? first : p;
            at += (size_t)snprintf(buf + at, size - at, "%s-", p);
        }
        if (at < size)
            at += (size_t)snprintf(buf + at, size - at, "%s", first ? first : "?");
    }
    if (at < size)
        snprintf(buf + at, size - at, ")");
    return buf;
}

/* The loop that closes worst at the current iterate. */
static int worst_loop(const solver *sv)
{
    int worst = 0;
    double big = -1.0;
    for (int i = 0; i < sv->nr; i++)
        if (fabs(sv->f[i]) > big) {
            big = fabs(sv->f[i]);
            worst = sv->row[i] / 2;
        }
    return worst;
}

/* Null vectors of the (equilibrated) Jacobian by dense LU with full
 * pivoting: which unknowns move freely, and which loop equations are
 * dependent, at a singular position. Small systems only; diagnostics. */
static int dense_null(const solver *sv, double *right, double *left)
{
    int n = sv->ns;
    if (n == 0 || n > 300 || sv->aug)  /* the least-squares matrix is not J */
        return -1;
    double *a = xcalloc((size_t)n * (size_t)n, sizeof *a);
    int *pr = xcalloc((size_t)n, sizeof *pr), *pc = xcalloc((size_t)n, sizeof *pc);
    if (!a || !pr || !pc) {
        free(a);
        free(pr);
        free(pc);
        return -1;
    }
    for (int pass = 0; pass < 2; pass++) {  /* 0: J, 1: J^T */
        double *out = pass == 0 ? right : left;
        for (int c = 0; c < n; c++)
            for (int p = sv->Ap[c]; p < sv->Ap[c + 1]; p++) {
                int r = sv->Ai[p];
                if (pass == 0)
                    a[r * n + c] = sv->Ax[p];
                else
                    a[c * n + r] = sv->Ax[p];
            }
        for (int i = 0; i < n; i++)
            pr[i] = pc[i] = i;
        for (int k = 0; k < n; k++) {
            int bi = k, bj = k;
            for (int i = k; i < n; i++)
                for (int j = k; j < n; j++)
                    if (fabs(a[pr[i] * n + pc[j]]) > fabs(a[pr[bi] * n + pc[bj]]))
                        bi = i, bj = j;
            int t = pr[k]; pr[k] = pr[bi]; pr[bi] = t;
            t = pc[k]; pc[k] = pc[bj]; pc[bj] = t;
            double piv = a[pr[k] * n + pc[k]];
            if (piv == 0.0)
                continue;
            for (int i = k + 1; i < n; i++) {
                double l = a[pr[i] * n + pc[k]] / piv;
                for (int j = k; j < n; j++)
                    a[pr[i] * n + pc[j]] -= l * a[pr[k] * n + pc[j]];
            }
        }
        /* U z = 0 with z_last = 1, back substitution, then undo the column order */
        double *z = out;
        for (int i = 0; i < n; i++)
            z[i] = 0.0;
        z[pc[n - 1]] = 1.0;
        for (int k = n - 2; k >= 0; k--) {
            double s = 0.0;
            for (int j = k + 1; j < n; j++)
                s += a[pr[k] * n + pc[j]] * z[pc[j]];
            double piv = a[pr[k] * n + pc[k]];
            z[pc[k]] = piv != 0.0 ? -s / piv : 0.0;
        }
        memset(a, 0, (size_t)n * (size_t)n * sizeof *a);
    }
    free(a);
    free(pr);
    free(pc);
    return 0;
}

/* Append the names of the unknowns (or loops) with a large null-vector
 * component to buf. */
static void list_large(const solver *sv, const double *v, int loops, char *buf, size_t size)
{
    double big = vec_norm_inf(v, sv->ns);
    size_t at = strlen(buf);
    int count = 0, last_loop = -1;
    char lb[256];
    for (int i = 0; i < sv->ns && at < size; i++) {
        if (!(fabs(v[i]) > 0.05 * big))
            continue;
        if (loops) {
            int k = sv->row[i] / 2;
            if (k == last_loop)
                continue;
            last_loop = k;
            at += (size_t)snprintf(buf + at, size - at, "%s%s", count++ ? ", " : "",
                                   loop_label(sv, k, lb, sizeof lb));
        } else {  /* the unknown, and where it is: "th_crank (at 0 deg)" */
            int c = sv->col[i];
            int angle = sv->sys->unk_kind[c] == UNK_ANGLE;
            double val = angle ? remainder(sv->x[i], 2.0 * PI) * 180.0 / PI : sv->x[i] * 1e3;
            if (fabs(val) < 5e-4)  /* known to about sqrt(eps) at a singular position */
                val = 0.0;
            at += (size_t)snprintf(buf + at, size - at, "%s%s (at %.3f %s)", count++ ? ", " : "",
                                   sv->sys->names[c], val, angle ? "deg" : "mm");
        }
    }
}

/* At a singular position, is the driver's column -f_q in the range of J
 * (w . f_q = 0 for the left null vector w)? Then the solution curve goes on
 * through the position and another crosses it: a change point. Otherwise
 * the driver cannot move on: a dead point or limit position. */
static int is_change_point(solver *sv, const double *left)
{
    double *fq = xcalloc((size_t)sv->nr + 1, sizeof *fq);
    if (!fq)
        return 0;
    solver_velocity_rhs(sv, fq);
    double dot = 0.0, nw = 0.0, nf = 0.0;
    for (int i = 0; i < sv->nr; i++) {
        dot += left[i] * fq[i];
        nw += left[i] * left[i];
        nf += fq[i] * fq[i];
    }
    free(fq);
    return nw > 0.0 && nf > 0.0 && fabs(dot) <= 1e-3 * sqrt(nw * nf);
}

static void report_singular(sweep *w, double q)
{
    solver *sv = &w->sv;
    char qb[64], what[700] = "";
    const char *kind = "a dead point, toggle or limit position";
    double *right = xcalloc((size_t)sv->ns + 1, sizeof *right);
    double *left = xcalloc((size_t)sv->nr + 1, sizeof *left);
    if (right && left && dense_null(sv, right, left) == 0) {
        if (is_change_point(sv, left))
            kind = "a change point, where two assembly branches cross";
        snprintf(what, sizeof what, ": the unknowns ");
        list_large(sv, right, 0, what, sizeof what);
        size_t at = strlen(what);
        snprintf(what + at, sizeof what - at, " are not determined by ");
        list_large(sv, left, 1, what, sizeof what);
    } else if (linsys_singular_col(&sv->ls) >= 0 && linsys_singular_col(&sv->ls) < sv->ns) {
        snprintf(what, sizeof what, ": the unknown %s is not determined",
                 sv->sys->names[sv->col[linsys_singular_col(&sv->ls)]]);
    }
    free(right);
    free(left);
    diag_error(w->d, w->m->file, w->m->driver.mark,
               "singular position at %s = %s (reciprocal condition %.2g, limit %.2g): %s%s; "
               "velocities there are not unique", driver_word(w->m),
               q_text(w->m, q, qb, sizeof qb), sv->rcond, sv->opt.min_rcond, kind, what);
}

/* With redundant constraints (more loop equations than unknowns), say which
 * equations are implied by the others at the first position: modified
 * Gram-Schmidt over the rows of J, in order; a row left with less than 1e-8
 * of its length is redundant. Small systems only (dense). */
static void report_redundant(sweep *w, double q)
{
    solver *sv = &w->sv;
    int nr = sv->nr, ns = sv->ns;
    if (!sv->aug || nr > 400)
        return;
    double *a = xcalloc((size_t)nr * (size_t)ns + 1, sizeof *a);
    if (!a)
        return;
    for (int c = 0, k = 0; c < ns; c++)
        for (int p = sv->Ap[nr + c]; p < sv->Ap[nr + c + 1]; p++, k++)
            a[(size_t)sv->Ai[p] * ns + c] = sv->Jv[k];
    char list[600] = "", lb[256], qb[64];
    size_t at = 0;
    int count = 0;
    for (int i = 0; i < nr; i++) {
        double *ri = a + (size_t)i * ns, len0 = 0.0, len = 0.0;
        for (int c = 0; c < ns; c++)
            len0 += ri[c] * ri[c];
        for (int j = 0; j < i; j++) {
            double *rj = a + (size_t)j * ns, dot = 0.0, nj = 0.0;
            for (int c = 0; c < ns; c++)
                dot += ri[c] * rj[c], nj += rj[c] * rj[c];
            if (nj > 0.0)
                for (int c = 0; c < ns; c++)
                    ri[c] -= dot / nj * rj[c];
        }
        for (int c = 0; c < ns; c++)
            len += ri[c] * ri[c];
        if (len <= 1e-16 * len0) {
            for (int c = 0; c < ns; c++)
                ri[c] = 0.0;
            if (at < sizeof list)
                at += (size_t)snprintf(list + at, sizeof list - at, "%s%s equation of %s",
                                       count++ ? ", " : "", sv->row[i] % 2 ? "y" : "x",
                                       loop_label(sv, sv->row[i] / 2, lb, sizeof lb));
        }
    }
    free(a);
    diag_warning(w->d, w->m->file, w->m->driver.mark,
                 "redundant constraints: at %s = %s the %d loop equations have rank %d; "
                 "implied by the others: the %s; the mechanism moves because "
                 "they are consistent, and it is solved in the least-squares sense (joint "
                 "reactions are not unique)", driver_word(w->m),
                 q_text(w->m, q, qb, sizeof qb), nr, nr - count, count ? list : "(none found)");
}

/* ---- continuation ----------------------------------------------------- */

/* Taylor: x + h x_q + h^2/2 x_qq + h^3/6 x_qqq, with x_qqq from the last two
 * x_qq (x_q and x_qq are solved at every position, whatever the output
 * level: solver_rates). The cubic term makes
 * the error of a 1-degree step about 1e-8 instead of 1e-6, so that one
 * Newton correction reaches rounding and the second iteration only
 * confirms it: two evaluations and factorisations per step instead of three
 * (docs/solver.md, section 4). */
static void predict(sweep *w, double qn)
{
    solver *sv = &w->sv;
    double h = qn - w->qc, dq = w->qc - w->q_prev;
    int prev = w->have_prev && dq != 0.0;
    for (int i = 0; i < sv->ns; i++) {
        double xqqq = prev ? (w->xqqc[i] - w->xqq_prev[i]) / dq : 0.0;
        w->xpred[i] = w->xc[i] + h * (w->xqc[i] + h * (0.5 * w->xqqc[i] + h * xqqq / 6.0));
    }
    memcpy(sv->x, w->xpred, (size_t)sv->ns * sizeof *sv->x);
}

/* Every declared branch condition holds at the published position. */
static int branches_hold(sweep *w, int *which)
{
    const mech_model *m = w->m;
    for (int b = 0; b < m->nbranches; b++) {
        double p[3][2];
        for (int k = 0; k < 3; k++)
            kin_point(&w->sv.tree, &w->sv.ks, m->branches[b].point[k], p[k], NULL, NULL);
        double cross = (p[1][0] - p[0][0]) * (p[2][1] - p[1][1]) -
                       (p[1][1] - p[0][1]) * (p[2][0] - p[1][0]);
        if (cross * m->branches[b].sign <= 0.0) {
            *which = b;
            return 0;
        }
    }
    return 1;
}

/* det J changed sign between the base and qn: a singular position was
 * crossed (a change point); the sweep may have passed to another assembly. */
static void note_crossing(sweep *w, double qn)
{
    int sign = solver_det_sign(&w->sv);
    if (sign != 0 && w->det_sign != 0 && sign != w->det_sign && !w->searching &&
        w->crossings++ < 10) {
        char qa[64], qb[64];
        diag_warning(w->d, w->m->file, w->m->driver.mark,
                     "between %s = %s and %s the Jacobian's determinant changes sign: the "
                     "sweep passed a change point, where assembly branches cross, and may "
                     "continue on the other assembly; declare `branch:` to keep one",
                     driver_word(w->m), q_text(w->m, fmin(w->qc, qn), qa, sizeof qa),
                     q_text(w->m, fmax(w->qc, qn), qb, sizeof qb));
    }
    if (sign != 0)
        w->det_sign = sign;
}

/* Keep the converged x at qn as the new base of the continuation. */
static void accept(sweep *w, double qn)
{
    solver *sv = &w->sv;
    note_crossing(w, qn);
    size_t bytes = (size_t)sv->ns * sizeof(double);
    memcpy(w->xqq_prev, w->xqqc, bytes);
    w->q_prev = w->qc;
    w->have_prev = 1;
    w->qc = qn;
    memcpy(w->xc, sv->x, bytes);
    memcpy(w->xqc, sv->xq, bytes);
    memcpy(w->xqqc, sv->xqq, bytes);
}

static void note_stats(sweep *w, double q)
{
    solver *sv = &w->sv;
    mech_solve_stats *st = w->st;
    if (sv->resid > st->worst_residual)
        st->worst_residual = sv->resid;
    if (sv->rcond < st->min_rcond) {
        st->min_rcond = sv->rcond;
        st->worst_rcond_q = q;
    }
}

/* Newton at qn from sv->x, then the checks that make a step acceptable. */
static step_status try_position(sweep *w, double qn, int continuing)
{
    solver *sv = &w->sv;
    step_status s = solver_newton(sv, qn);
    w->row_iters += sv->iters;
    if (s != STEP_OK)
        return s;
    if (continuing) {
        /* correction against predicted move: large means another solution */
        for (int i = 0; i < sv->ns; i++)
            sv->dx[i] = sv->x[i] - w->xpred[i];
        double corr = solver_step_size(sv, sv->dx);
        for (int i = 0; i < sv->ns; i++)
            sv->dx[i] = w->xpred[i] - w->xc[i];
        if (corr > 0.5 * solver_step_size(sv, sv->dx) + 0.05)
            return STEP_JUMP;
    }
    solver_rates(sv);
    int b;
    if (w->m->nbranches) {  /* the branch test needs the point positions */
        solver_publish(sv, qn, w->qd, w->qdd);  /* the row's own, unless rejected */
        if (!branches_hold(w, &b))
            return STEP_BRANCH;
    }
    return STEP_OK;
}

/* From the base w->qc to q by continuation, halving rejected steps. */
static step_status advance(sweep *w, double q, double hmin)
{
    double h = q - w->qc;
    step_status s = STEP_OK;
    w->fail_status = STEP_OK;
    while (w->qc != q) {
        double remaining = q - w->qc;
        double qn = fabs(remaining) <= fabs(h) * (1.0 + 1e-12) ? q : w->qc + h;
        predict(w, qn);
        s = try_position(w, qn, 1);
        if (s == STEP_OK) {
            note_stats(w, qn);
            accept(w, qn);
            if (w->qc != q)
                w->row_substeps++;
            if (fabs(2.0 * h) <= fabs(q - w->qc))
                h *= 2.0;  /* recover the step after a difficulty */
            continue;
        }
        if (w->fail_status == STEP_OK) {
            w->fail_resid = vec_norm_inf(w->sv.f, w->sv.nr);
            w->fail_loop = worst_loop(&w->sv);
        }
        w->fail_q = qn;
        w->fail_status = s;
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

/* The file's guess for each unknown (NAN: none), gathered once: looking
 * the guesses up per unknown would cost O(unknowns x guesses). */
static int gather_guesses(sweep *w)
{
    solver *sv = &w->sv;
    const mech_model *m = w->m;
    w->guess = xcalloc((size_t)sv->n + 1, sizeof *w->guess);
    if (!w->guess)
        return -1;
    for (int i = 0; i < sv->n; i++)
        w->guess[i] = NAN;
    for (int g = 0; g < m->nguesses; g++) {
        const mech_guess *gs = &m->guesses[g];
        int var = gs->is_slider ? sv->sys->joint_var[gs->index] : sv->sys->link_var[gs->index];
        if (var >= 0 && var < sv->n)
            w->guess[var] = gs->value;
    }
    return 0;
}

/* Starting values: the file's guesses; the others 0 on the first attempt,
 * scattered over a turn (angles) or +-2 lref (slides) later. */
static void start_values(sweep *w, int attempt, unsigned *rng)
{
    solver *sv = &w->sv;
    for (int i = 0; i < sv->ns; i++) {
        int c = sv->col[i];
        double u = attempt ? (double)(next_random(rng) & 0xffff) / 65536.0 - 0.5 : 0.0;
        sv->x[i] = sv->sys->unk_kind[c] == UNK_ANGLE ? 2.0 * PI * u : 4.0 * sv->lref * u;
        if (!isnan(w->guess[c]))
            sv->x[i] = w->guess[c];
    }
}

static int has_unguessed(const sweep *w)
{
    for (int i = 0; i < w->sv.ns; i++)
        if (isnan(w->guess[w->sv.col[i]]))
            return 1;
    return 0;
}

static int start(sweep *w, double q)
{
    solver *sv = &w->sv;
    const mech_model *m = w->m;
    unsigned rng = 20261121u;
    int attempts = has_unguessed(w) ? START_ATTEMPTS : 1, branch = -1;
    step_status s = STEP_NO_ASSEMBLY, first = STEP_OK;
    double first_resid = 0.0;
    int first_loop = 0;
    for (int a = 0; a < attempts; a++) {
        start_values(w, a, &rng);
        s = try_position(w, q, 0);
        if (a == 0) {
            first = s;
            first_resid = sv->resid;
            first_loop = worst_loop(sv);
        }
        if (s == STEP_OK)
            break;
        if (s == STEP_BRANCH)
            branches_hold(w, &branch);
    }
    char qb[64], lb[256];
    if (s == STEP_OK) {
        note_stats(w, q);
        w->qc = q;
        accept(w, q);
        w->have_prev = 0;
        report_redundant(w, q);
        return MECH_OK;
    }
    if (branch >= 0) {
        const mech_branch *b = &m->branches[branch];
        return diag_error(w->d, m->file, b->mark,
                          "at %s = %s the mechanism assembles, but not with %s-%s-%s turning %s "
                          "(from the initial guesses%s); check the guesses or the branch",
                          driver_word(m), q_text(m, q, qb, sizeof qb), m->point_names[b->point[0]],
                          m->point_names[b->point[1]], m->point_names[b->point[2]],
                          b->sign > 0 ? "counter-clockwise" : "clockwise",
                          attempts > 1 ? " and other starts" : ""), MECH_ESOLVE;
    }
    if (first == STEP_SINGULAR) {
        report_singular(w, q);
        return MECH_ESOLVE;
    }
    return diag_error(w->d, m->file, m->driver.mark,
                      "cannot assemble at %s = %s: %s does not close (residual %.3g m after "
                      "Newton from the initial guesses%s); check the dimensions, or give "
                      "`initial:` guesses near the intended assembly",
                      driver_word(m), q_text(m, q, qb, sizeof qb),
                      loop_label(sv, first_loop, lb, sizeof lb), first_resid,
                      attempts > 1 ? " and other starts" : ""), MECH_ESOLVE;
}

/* ---- failures in the sweep -------------------------------------------- */

/* March from row 0 away from the sweep direction to find where assembly
 * stops on that side; returns that limit (or the end of the search). */
/* From the base, march in direction dir by steps h until assembly fails or
 * `span` is covered; returns the last position reached (a limit when
 * *found). */
static double march(sweep *w, double dir, double h, double span, int *found)
{
    double q0 = w->qc;
    *found = 0;
    for (double q = q0; fabs(q - q0) < span;) {
        q += dir * h;
        if (advance(w, q, 1e-9 * fmax(h, 1e-12)) != STEP_OK) {
            *found = w->fail_status == STEP_NO_ASSEMBLY || w->fail_status == STEP_SINGULAR;
            return w->qc;
        }
    }
    return w->qc;
}

/* Make (q, x, x_q, x_qq) the base of the continuation. */
static void set_base(sweep *w, double q, const double *x, const double *xq, const double *xqq)
{
    size_t bytes = (size_t)w->sv.ns * sizeof(double);
    memcpy(w->xc, x, bytes);
    memcpy(w->xqc, xq, bytes);
    memcpy(w->xqqc, xqq, bytes);
    w->qc = q;
    w->have_prev = 0;
}

static double lower_limit(sweep *w, double span, double hrow, int *found)
{
    set_base(w, w->q0, w->x0, w->xq0, w->xqq0);
    return march(w, hrow > 0 ? -1.0 : 1.0, fabs(hrow), span, found);
}

/* Look for another interval where a crank assembles, in the gap (hi, lo +
 * 2 pi) left by the one found: Newton from scattered starts every row
 * spacing; at the first success, march both ways to its limits. Small
 * systems only (it is a search). Returns 1 with the interval in lo2, hi2. */
static int other_interval(sweep *w, double lo, double hi, double h, double *lo2, double *hi2)
{
    solver *sv = &w->sv;
    if (sv->ns > 50 || !(h > 0.0))
        return 0;
    unsigned rng = 12345u;
    for (double q = hi + h; q < lo + 2.0 * PI - 0.5 * h; q += h)
        for (int a = 1; a <= 8; a++) {
            start_values(w, a, &rng);
            if (try_position(w, q, 0) != STEP_OK)
                continue;
            /* save this point: both marches start from it */
            size_t bytes = (size_t)sv->ns * sizeof(double);
            memcpy(w->x0, sv->x, bytes);
            memcpy(w->xq0, sv->xq, bytes);
            memcpy(w->xqq0, sv->xqq, bytes);
            int f1, f2;
            set_base(w, q, w->x0, w->xq0, w->xqq0);
            *hi2 = march(w, 1.0, h, 2.0 * PI, &f1);
            set_base(w, q, w->x0, w->xq0, w->xqq0);
            *lo2 = march(w, -1.0, h, 2.0 * PI, &f2);
            return f1 && f2;
        }
    return 0;
}

static void report_failure(sweep *w, double q_row, double hrow)
{
    const mech_model *m = w->m;
    solver *sv = &w->sv;
    char qa[64], qb[64], qc[64], lb[256];
    double upper = w->qc, fq = w->fail_q;
    step_status s = w->fail_status;
    int loop = w->fail_loop;
    double resid = w->fail_resid;
    if (s == STEP_SINGULAR) {
        report_singular(w, fq);
        return;
    }
    if (s == STEP_NO_ASSEMBLY) {
        w->searching = 1;
        double span = is_angle_driver(m) ? 2.0 * PI : fabs(q_row - w->q0) * 4.0 + sv->lref;
        int found;
        double lower = lower_limit(w, span, hrow, &found);
        double lo = fmin(lower, upper), hi = fmax(lower, upper), lo2, hi2;
        char more[200] = "", qd[64], qe[64];
        if (found && is_angle_driver(m) && other_interval(w, lo, hi, fabs(hrow), &lo2, &hi2))
            snprintf(more, sizeof more, " and from %s to %s", q_text(m, lo2, qd, sizeof qd),
                     q_text(m, hi2, qe, sizeof qe));
        diag_error(w->d, m->file, m->driver.mark,
                   "cannot assemble at %s = %s: %s does not close (residual %.3g m); the "
                   "mechanism assembles for %s from %s%s to %s%s (limit positions%s)",
                   driver_word(m), q_text(m, q_row, qa, sizeof qa),
                   loop_label(sv, loop, lb, sizeof lb), resid, driver_word(m),
                   found || lo == lower ? "" : "at most ", q_text(m, lo, qb, sizeof qb),
                   q_text(m, hi, qc, sizeof qc), more,
                   found ? "" : "; the other side was not searched past one range");
        return;
    }
    if (s == STEP_JUMP)
        diag_error(w->d, m->file, m->driver.mark,
                   "at %s = %s the solution jumps (to another assembly branch, or through a "
                   "branch point) although the step was refined to %.3g of the row spacing; "
                   "the sweep stops here rather than switch branches silently",
                   driver_word(m), q_text(m, fq, qa, sizeof qa),
                   fabs(fq - upper) / fmax(fabs(hrow), 1e-300));
    else if (s == STEP_BRANCH)
        diag_error(w->d, m->file, m->driver.mark,
                   "at %s = %s the mechanism leaves the declared assembly branch (a change "
                   "point, where the branches cross); the sweep stops on the declared branch "
                   "at %s",
                   driver_word(m), q_text(m, fq, qa, sizeof qa), q_text(m, upper, qb, sizeof qb));
    else
        diag_error(w->d, m->file, (mech_mark){0, 0}, "out of memory");
}

/* ---- the output table ------------------------------------------------ */

static int add_column(mech_table *t, const char *name, const char *suffix, const char *unit)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s%s", name, suffix);
    mech_column *c = &t->columns[t->ncolumns];
    c->name = xstrdup(buf);
    c->unit = xstrdup(unit);
    if (!c->name || !c->unit) {
        free(c->name);
        free(c->unit);
        return -1;
    }
    t->ncolumns++;
    return 0;
}

/* Column base name of joint j: its name, or name(link,link) when several
 * joints share the name (three links on one pin). */
static const char *joint_label(const mech_model *m, int j, char *buf, size_t size)
{
    const mech_joint *jt = &m->joints[j];
    int shared = 0;
    for (int k = 0; k < m->njoints; k++)
        shared |= k != j && strcmp(m->joints[k].name, jt->name) == 0;
    if (!shared)
        return jt->name;
    snprintf(buf, size, "%s(%s,%s)", jt->name, m->links[jt->link[0]].name,
             m->links[jt->link[1]].name);
    return buf;
}

/* Reaction columns of every joint, the driver, and the power balance;
 * `suffix` tells the frictionless set apart when both are written. */
static int force_columns(mech_table *t, const mech_model *m, const char *suffix)
{
    char name[200], buf[160];
    int rc = 0;
    for (int j = 0; j < m->njoints; j++) {
        const char *base = joint_label(m, j, buf, sizeof buf);
        const char *parts[] = {".Fx", ".Fy", m->joints[j].kind == MECH_JOINT_SLIDER ? ".N" : ".F"};
        for (int k = 0; k < 3; k++) {
            snprintf(name, sizeof name, "%s%s", base, parts[k]);
            rc |= add_column(t, name, suffix, "N");
        }
        if (m->joints[j].kind == MECH_JOINT_SLIDER && m->joints[j].locked) {
            snprintf(name, sizeof name, "%s.M", base);
            rc |= add_column(t, name, suffix, "N*m");
        }
    }
    if (m->driver.kind == MECH_DRIVE_ANGLE)
        rc |= add_column(t, "driver.torque", suffix, "N*m");
    else
        rc |= add_column(t, "driver.force", suffix, "N");
    rc |= add_column(t, "power.residual", suffix, "-");
    return rc;
}

static int make_columns(mech_table *t, const mech_model *m, int level, int diagnostics,
                        int with_forces, int friction)
{
    const mech_outputs *o = &m->outputs;
    int vel = level & MECH_WANT_VELOCITY, acc = level & MECH_WANT_ACCELERATION;
    int max = 1 + 6 * o->npoints + 3 * o->nlinks + 3 * o->nsliders + 4 +
              (with_forces ? 2 * (4 * m->njoints + 2) + 2 : 0);
    t->columns = xcalloc((size_t)max, sizeof *t->columns);
    if (!t->columns)
        return -1;
    int rc = add_column(t, "q", "", is_angle_driver(m) ? "rad" : "m");
    for (int i = 0; i < o->npoints; i++) {
        const char *p = m->point_names[o->points[i]];
        rc |= add_column(t, p, ".x", "m") | add_column(t, p, ".y", "m");
        if (vel)
            rc |= add_column(t, p, ".vx", "m/s") | add_column(t, p, ".vy", "m/s");
        if (acc)
            rc |= add_column(t, p, ".ax", "m/s^2") | add_column(t, p, ".ay", "m/s^2");
    }
    for (int i = 0; i < o->nlinks; i++) {
        const char *l = m->links[o->links[i]].name;
        rc |= add_column(t, l, ".angle", "rad");
        if (vel)
            rc |= add_column(t, l, ".omega", "rad/s");
        if (acc)
            rc |= add_column(t, l, ".alpha", "rad/s^2");
    }
    for (int i = 0; i < o->nsliders; i++) {
        const char *s = m->joints[o->sliders[i]].name;
        rc |= add_column(t, s, ".s", "m");
        if (vel)
            rc |= add_column(t, s, ".v", "m/s");
        if (acc)
            rc |= add_column(t, s, ".a", "m/s^2");
    }
    if (with_forces) {
        rc |= force_columns(t, m, "");
        if (friction >= 1)
            rc |= add_column(t, "friction.power", "", "W") |
                  add_column(t, "friction.iterations", "", "-");
        if (friction == 2)
            rc |= force_columns(t, m, ".nofriction");
    }
    if (diagnostics)
        rc |= add_column(t, "iterations", "", "-") | add_column(t, "residual", "", "m") |
              add_column(t, "rcond", "", "-") | add_column(t, "substeps", "", "-");
    return rc ? -1 : 0;
}

static double var_or_zero(const double *v, int var) { return var >= 0 ? v[var] : 0.0; }

static double *fill_forces(sweep *w, double *out, int with_friction)
{
    const mech_model *m = w->m;
    for (int j = 0; j < m->njoints; j++) {
        double fx, fy, n, mo;
        forces_joint(&w->fc, &w->sv, j, with_friction, &fx, &fy, &n, &mo);
        *out++ = fx;
        *out++ = fy;
        *out++ = m->joints[j].kind == MECH_JOINT_SLIDER ? n : hypot(fx, fy);
        if (m->joints[j].kind == MECH_JOINT_SLIDER && m->joints[j].locked)
            *out++ = mo;
    }
    *out++ = forces_drive(&w->fc, with_friction);
    *out++ = with_friction ? w->fc.residual : w->fc.residual0;
    return out;
}

static void fill_row(sweep *w, int row)
{
    solver *sv = &w->sv;
    const mech_model *m = w->m;
    const mech_outputs *o = &m->outputs;
    int vel = sv->level & MECH_WANT_VELOCITY, acc = sv->level & MECH_WANT_ACCELERATION;
    double *out = w->out->values + (size_t)row * (size_t)w->out->ncolumns;
    *out++ = sv->pos[sv->n];
    for (int i = 0; i < o->npoints; i++) {
        double p[2], v[2], a[2];
        kin_point(&sv->tree, &sv->ks, o->points[i], p, v, a);
        *out++ = p[0];
        *out++ = p[1];
        if (vel) {
            *out++ = v[0];
            *out++ = v[1];
        }
        if (acc) {
            *out++ = a[0];
            *out++ = a[1];
        }
    }
    for (int i = 0; i < o->nlinks; i++) {
        int l = o->links[i];
        *out++ = sv->ks.th[l];
        if (vel)
            *out++ = sv->ks.om[l];
        if (acc)
            *out++ = sv->ks.al[l];
    }
    for (int i = 0; i < o->nsliders; i++) {
        int var = sv->tree.slide_var[o->sliders[i]];
        *out++ = var_or_zero(sv->pos, var);
        if (vel)
            *out++ = var_or_zero(sv->vel, var);
        if (acc)
            *out++ = var_or_zero(sv->acc, var);
    }
    if (w->want_forces) {
        out = fill_forces(w, out, w->friction_mode != MECH_FRICTION_OFF);
        if (w->fc.friction) {
            *out++ = w->fc.friction_power;
            *out++ = w->fc.iterations;
        }
        if (w->friction_mode == MECH_FRICTION_BOTH && w->fc.has_friction)
            out = fill_forces(w, out, 0);
    }
    if (sv->opt.diagnostics) {
        *out++ = w->row_iters;
        *out++ = sv->resid;
        *out++ = sv->rcond;
        *out++ = w->row_substeps;
    }
}

/* ---- forces --------------------------------------------------------------- */

static int solve_forces(sweep *w, double q)
{
    char qb[64], joints[400];
    int r = forces_solve(&w->fc, &w->sv);
    if (r == -1) {
        forces_singular_joints(&w->fc, joints, sizeof joints);
        return diag_error(w->d, w->m->file, w->m->driver.mark,
                          "the force system is singular at %s = %s (reciprocal condition %.2g): "
                          "redundant constraints make the reactions of %s not unique",
                          driver_word(w->m), q_text(w->m, q, qb, sizeof qb), w->fc.rcond,
                          joints[0] ? joints : "some joints"),
               MECH_ESOLVE;
    }
    if (r == -2)
        return diag_error(w->d, w->m->file, w->m->driver.mark,
                          "joint friction does not converge at %s = %s (fixed-point iteration, "
                          "%d steps): the friction coefficients may make the mechanism "
                          "self-locking there", driver_word(w->m), q_text(w->m, q, qb, sizeof qb),
                          100), MECH_ESOLVE;
    double worst = fmax(fabs(w->fc.residual), fabs(w->fc.residual0));
    if (worst > w->st->worst_power_residual)
        w->st->worst_power_residual = worst;
    if (w->fc.iterations > w->st->max_friction_iterations)
        w->st->max_friction_iterations = w->fc.iterations;
    return MECH_OK;
}

/* ---- mech_solve ------------------------------------------------------- */

void mech_solve_options_default(mech_solve_options *o)
{
    memset(o, 0, sizeof *o);
    o->tol = 1e-12;
    o->max_iter = 50;
    o->min_rcond = 1e-6;
    o->want = MECH_WANT_ALL;
}

static int alloc_sweep(sweep *w)
{
    size_t ns = (size_t)w->sv.ns + 1;
    double **arrays[] = {&w->xc, &w->xqc, &w->xqqc, &w->xqq_prev, &w->xpred,
                         &w->x0, &w->xq0, &w->xqq0};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
        if (!(*arrays[i] = xcalloc(ns, sizeof(double))))
            return -1;
    return gather_guesses(w);
}

static void free_sweep(sweep *w)
{
    double *arrays[] = {w->xc, w->xqc, w->xqqc, w->xqq_prev, w->xpred, w->x0,
                        w->xq0, w->xqq0,
                        w->guess};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
        free(arrays[i]);
    solver_free(&w->sv);
}

/* Which friction columns: 0 none, 1 with friction, 2 with and without. */
static int friction_columns(const sweep *w)
{
    if (!w->fc.has_friction || w->friction_mode == MECH_FRICTION_OFF)
        return 0;
    return w->friction_mode == MECH_FRICTION_BOTH ? 2 : 1;
}

/* The result table is kept in memory: refuse (clearly) one above 2 GiB
 * rather than let an overcommitted allocation kill the run part-way. */
static int too_large(sweep *w, int nvalues)
{
    const mech_outputs *o = &w->m->outputs;
    double cols = 1 + 6.0 * o->npoints + 3.0 * o->nlinks + 3.0 * o->nsliders + 4 +
                  (w->want_forces ? 8.0 * w->m->njoints + 6 : 0);
    double bytes = cols * nvalues * sizeof(double);
    if (bytes <= 2147483648.0)
        return 0;
    diag_error(w->d, w->m->file, w->m->driver.mark,
               "the results would take %.3g GB in memory (%d rows of %.0f columns): ask for "
               "fewer steps (--steps) or fewer outputs (--outputs)", bytes / 1e9, nvalues, cols);
    return 1;
}

/* Driver positions of the sweep: the file's, or the options' range. */
static double *sweep_values(const mech_model *m, const mech_solve_options *o, int *count)
{
    if (!o->has_range) {
        double *v = xcalloc((size_t)m->driver.nvalues, sizeof *v);
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

static void finish_stats(sweep *w, int rows, double t0)
{
    mech_solve_stats *st = w->st;
    st->steps = rows;
    st->seconds = now_seconds() - t0;  /* t0: after the set-up */
    st->factorizations = w->sv.ls.factorizations;
    st->refactorizations = w->sv.ls.refactorizations;
    st->nunknowns = w->sv.n;
    st->nsolved = w->sv.ns;
    st->nblocks = w->sv.nblocks;
    st->nblocks_solved = w->sv.nblocks_solved;
}

int mech_solve(const mech_model *m, const mech_solve_options *o, mech_table *out,
               mech_solve_stats *stats, mech_diag *d)
{
    mech_solve_stats local;
    sweep w;
    memset(&w, 0, sizeof w);
    memset(out, 0, sizeof *out);
    w.st = stats ? stats : &local;
    memset(w.st, 0, sizeof *w.st);
    w.st->min_rcond = INFINITY;
    w.out = out;
    w.d = d;
    w.m = m;
    if (!m->has_driver)
        return diag_error(d, m->file, (mech_mark){0, 0}, "the mechanism has no driver");
    double t0 = now_seconds();
    mech_solve_options opt = *o;
    w.want_forces = o->forces || m->outputs.forces;
    w.friction_mode = o->friction;
    if (w.want_forces) {  /* reactions need every link's acceleration */
        opt.all_blocks = 1;
        opt.want = MECH_WANT_ALL;
    }
    o = &opt;
    int rc = solver_init(&w.sv, m, o, d), nvalues = 0;
    if (rc == MECH_OK && w.want_forces)
        rc = forces_init(&w.fc, &w.sv, w.friction_mode != MECH_FRICTION_OFF, d);
    if (rc == MECH_OK && w.want_forces)
        w.fc.want_frictionless = w.friction_mode == MECH_FRICTION_BOTH;
    if (rc == MECH_OK && w.want_forces && o->log) {
        char method[96];
        fprintf(o->log, "force system: %d reactions; linear solves: %s\n", w.fc.ncols,
                linsys_method_name(&w.fc.ls, method, sizeof method));
    }
    w.st->setup_seconds = now_seconds() - t0;
    double *values = NULL;
    if (rc == MECH_OK) {
        rc = MECH_ENOMEM;
        values = sweep_values(m, o, &nvalues);
        if (values && too_large(&w, nvalues))
            rc = MECH_EINPUT;
        else if (values && alloc_sweep(&w) == 0 &&
                 make_columns(out, m, w.sv.level, o->diagnostics, w.want_forces,
                              friction_columns(&w)) == 0 &&
                 (out->values = xcalloc((size_t)nvalues * (size_t)out->ncolumns + 1,
                                        sizeof(double))))
            rc = MECH_OK;
        else if (rc == MECH_ENOMEM)
            diag_error(d, m->file, (mech_mark){0, 0}, "out of memory");
    }
    w.qd = m->driver.speed;
    t0 = now_seconds();
    w.qdd = m->driver.accel;
    int row = 0;
    for (; rc == MECH_OK && row < nvalues; row++) {
        double q = values[row];
        w.row_iters = 0;
        w.row_substeps = 0;
        if (row == 0) {
            rc = start(&w, q);
            w.q0 = q;
            size_t bytes = (size_t)w.sv.ns * sizeof(double);
            memcpy(w.x0, w.xc, bytes);
            memcpy(w.xq0, w.xqc, bytes);
            memcpy(w.xqq0, w.xqqc, bytes);
        } else {
            double hrow = q - values[row - 1];
            double hmin = 1e-9 * fmax(fabs(hrow), 1e-12);
            if (advance(&w, q, hmin) != STEP_OK) {
                report_failure(&w, q, hrow);
                rc = MECH_ESOLVE;
            }
        }
        if (rc != MECH_OK)
            break;
        if (w.row_substeps > 0 && w.refined_notes++ < 5) {
            char qb[64];
            diag_note(d, m->file, m->driver.mark,
                      "the step to %s = %s was refined into %d steps (reciprocal condition "
                      "there %.2g): a difficult position, near a singular one or a fast change",
                      driver_word(m), q_text(m, q, qb, sizeof qb), w.row_substeps + 1,
                      w.sv.rcond);
        }
        solver_publish(&w.sv, q, w.qd, w.qdd);
        if (w.want_forces && (rc = solve_forces(&w, q)) != MECH_OK)
            break;
        fill_row(&w, row);
        w.st->iterations += w.row_iters;
        if (w.row_iters > w.st->max_iterations)
            w.st->max_iterations = w.row_iters;
    }
    out->nrows = row;
    finish_stats(&w, row, t0);
    free(values);
    forces_free(&w.fc);
    free_sweep(&w);
    return rc;
}
