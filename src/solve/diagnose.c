/* src/solve/diagnose.c: why a position or a sweep failed (diagnose.h): null
 * vectors of the Jacobian at a singular position, the rank of redundant
 * equations, and the assembly interval found by marching from row 0. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "solve.h"

static const double PI = 3.14159265358979323846;

static int is_angle_driver(const mech_model *m) { return m->driver.kind == MECH_DRIVE_ANGLE; }

/* The unit users read q in ("deg", "s" for laws of time, "mm") and the
   factor from SI to it. */
static const char *q_unit(const mech_model *m, double *scale)
{
    *scale = is_angle_driver(m) ? 180.0 / PI : m->driver.kind == MECH_DRIVE_TIME ? 1.0 : 1e3;
    return is_angle_driver(m) ? "deg" : m->driver.kind == MECH_DRIVE_TIME ? "s" : "mm";
}

/* "123.4 deg" or "0.1834 m": the driver position as users think of it. */
const char *diagnose_q_text(const mech_model *m, double q, char *buf, size_t size)
{
    if (is_angle_driver(m))
        snprintf(buf, size, "%.6g deg", q * 180.0 / PI);
    else if (m->driver.kind == MECH_DRIVE_TIME)
        snprintf(buf, size, "%.6g s", q);
    else
        snprintf(buf, size, "%.6g mm", q * 1e3);
    return buf;
}

const char *diagnose_q_interval(const mech_model *m, double a, double b, char *buf,
                                size_t size)
{
    double unit;
    const char *u = q_unit(m, &unit);
    double lo = fmin(a, b) * unit, hi = fmax(a, b) * unit, width = hi - lo;
    int dec = width > 0.0 ? (int)ceil(-log10(width)) + 1 : 6;
    dec = dec < 0 ? 0 : dec > 12 ? 12 : dec;
    snprintf(buf, size, "%.*f %s and %.*f %s", dec, lo, u, dec, hi, u);
    return buf;
}

const char *diagnose_driver_word(const mech_model *m)
{
    return is_angle_driver(m) ? "driver angle"
           : m->driver.kind == MECH_DRIVE_TIME ? "time" : "driver displacement";
}

/* The row that closes worst at the current iterate (a row of the system). */
int diagnose_worst_row(const solver *sv)
{
    int worst = 0;
    double big = -1.0;
    for (int i = 0; i < sv->p->nr; i++)
        if (fabs(sv->f[i]) > big) {
            big = fabs(sv->f[i]);
            worst = sv->p->row[i];
        }
    return worst;
}

/* Null vectors of the (equilibrated) Jacobian by dense LU with full
 * pivoting: which unknowns move freely, and which loop equations are
 * dependent, at a singular position. Small systems only; diagnostics. */
static int dense_null(const solver *sv, double *right, double *left)
{
    int n = sv->p->ns;
    if (n == 0 || n > 300 || sv->p->aug)  /* the least-squares matrix is not J */
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
            for (int p = sv->p->Ap[c]; p < sv->p->Ap[c + 1]; p++) {
                int r = sv->p->Ai[p];
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

/* Append the names of the unknowns (or the owners of the rows) with a large
 * null-vector component to buf. */
static void list_large(const solver *sv, const double *v, int rows, char *buf, size_t size)
{
    double big = vec_norm_inf(v, sv->p->ns);
    size_t at = strlen(buf);
    int count = 0, last_row = -1;
    char lb[256];
    for (int i = 0; i < sv->p->ns && at < size; i++) {
        if (!(fabs(v[i]) > 0.05 * big))
            continue;
        if (rows) {  /* the rows' owners: a loop once for its x and y rows */
            int r = sv->p->row[i];
            if (last_row >= 0 && rows_same_owner(sv->p->sys, r, last_row))
                continue;
            last_row = r;
            at += (size_t)snprintf(buf + at, size - at, "%s%s", count++ ? ", " : "",
                                   rows_owner(sv->p->sys, r, lb, sizeof lb));
        } else {  /* the unknown, and where it is: "th_crank (at 0 deg)" */
            int c = sv->p->col[i];
            int angle = sv->p->sys->unk_kind[c] == UNK_ANGLE;
            double val = angle ? remainder(sv->x[i], 2.0 * PI) * 180.0 / PI : sv->x[i] * 1e3;
            if (fabs(val) < 5e-4)  /* known to about sqrt(eps) at a singular position */
                val = 0.0;
            at += (size_t)snprintf(buf + at, size - at, "%s%s (at %.3f %s)", count++ ? ", " : "",
                                   sv->p->sys->names[c], val, angle ? "deg" : "mm");
        }
    }
}

/* Another pin of link li than joint j (revolute or slider point), or -1. */
static int other_pin(const mech_model *m, int li, int j)
{
    for (int k = 0; k < m->njoints; k++)
        for (int side = 0; side < 2 && k != j; side++)
            if (m->joints[k].link[side] == li)
                return m->links[li].points[m->joints[k].point[side]].id;
    return -1;
}

/* Which two moving links, pinned together, lie most nearly in line at the
 * position x (q): "coupler and rocker extended in line" (their pin between
 * their other pins) or "... folded in line"; "" when no pair is within
 * 1e-3 rad of it. Publishes x (diagnostics only). */
static void in_line_text(solver *sv, double q, const double *x, char *buf, size_t size)
{
    memcpy(sv->x, x, (size_t)sv->p->ns * sizeof *sv->x);
    sv->generation++;
    solver_publish(sv, q, 0.0, 0.0);
    diagnose_links_in_line(sv, 1.0 - 5e-7, buf, size);  /* cos of 1e-3 rad */
}

void diagnose_links_in_line(solver *sv, double cos_min, char *buf, size_t size)
{
    const mech_model *m = sv->p->m;
    kin_refresh_all(&sv->p->tree, &sv->ks);  /* kin_point on any link below */
    double best = cos_min;
    buf[0] = '\0';
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (jt->kind != MECH_JOINT_REVOLUTE || jt->link[0] == 0 || jt->link[1] == 0)
            continue;
        int pin = m->links[jt->link[0]].points[jt->point[0]].id;
        int q1 = other_pin(m, jt->link[0], j), q2 = other_pin(m, jt->link[1], j);
        if (q1 < 0 || q2 < 0 || q1 == pin || q2 == pin)
            continue;
        double p[2], a[2], b[2];
        kin_point(&sv->p->tree, &sv->ks, pin, p, NULL, NULL);
        kin_point(&sv->p->tree, &sv->ks, q1, a, NULL, NULL);
        kin_point(&sv->p->tree, &sv->ks, q2, b, NULL, NULL);
        double ux = a[0] - p[0], uy = a[1] - p[1], vx = b[0] - p[0], vy = b[1] - p[1];
        double nu = hypot(ux, uy), nv = hypot(vx, vy);
        double cs = nu > 0 && nv > 0 ? (ux * vx + uy * vy) / (nu * nv) : 0.0;
        if (fabs(cs) > best) {
            best = fabs(cs);
            snprintf(buf, size, "%s and %s %s in line", m->links[jt->link[0]].name,
                     m->links[jt->link[1]].name, cs < 0 ? "extended" : "folded");
        }
    }
}

/* At a singular position, is the driver's column -f_q in the range of J
 * (w . f_q = 0 for the left null vector w)? Then the solution curve goes on
 * through the position and another crosses it: a change point. Otherwise
 * the driver cannot move on: a dead point or limit position. */
static int is_change_point(solver *sv, const double *left)
{
    double *fq = xcalloc((size_t)sv->p->nr + 1, sizeof *fq);
    if (!fq)
        return 0;
    solver_velocity_rhs(sv, fq);
    double dot = 0.0, nw = 0.0, nf = 0.0;
    for (int i = 0; i < sv->p->nr; i++) {
        dot += left[i] * fq[i];
        nw += left[i] * left[i];
        nf += fq[i] * fq[i];
    }
    free(fq);
    return nw > 0.0 && nf > 0.0 && fabs(dot) <= 1e-3 * sqrt(nw * nf);
}

void diagnose_dependent_rows(const solver *sv, char *buf, size_t size)
{
    double *right = xcalloc((size_t)sv->p->ns + 1, sizeof *right);
    double *left = xcalloc((size_t)sv->p->nr + 1, sizeof *left);
    buf[0] = '\0';
    if (right && left && dense_null(sv, right, left) == 0)
        list_large(sv, left, 1, buf, size);
    free(right);
    free(left);
}

mech_fail_kind diagnose_singular(cont *c, double q)
{
    solver *sv = &c->sv;
    char qb[64], what[700] = "";
    double *right = xcalloc((size_t)sv->p->ns + 1, sizeof *right);
    double *left = xcalloc((size_t)sv->p->nr + 1, sizeof *left);
    char line[200] = "", kindb[512];
    c->fail_change_point = 0;
    if (right && left && dense_null(sv, right, left) == 0) {
        c->fail_change_point = is_change_point(sv, left);
        snprintf(what, sizeof what, ": the unknowns ");
        list_large(sv, right, 0, what, sizeof what);
        size_t at = strlen(what);
        snprintf(what + at, sizeof what - at, " are not determined by ");
        list_large(sv, left, 1, what, sizeof what);
    } else if (linsys_singular_col(&sv->ls) >= 0 && linsys_singular_col(&sv->ls) < sv->p->ns) {
        snprintf(what, sizeof what, ": the unknown %s is not determined",
                 sv->p->sys->names[sv->p->col[linsys_singular_col(&sv->ls)]]);
    }
    free(right);
    free(left);
    mech_fail_kind fk = c->fail_change_point ? MECH_FAIL_CHANGE_POINT : MECH_FAIL_DEAD_POINT;
    const char *kind = fail_words(fk);
    double *xs = xcalloc((size_t)sv->p->ns + 1, sizeof *xs);
    if (xs && !c->fail_change_point) {
        memcpy(xs, sv->x, (size_t)sv->p->ns * sizeof *xs);
        in_line_text(sv, q, xs, line, sizeof line);
        memcpy(sv->x, xs, (size_t)sv->p->ns * sizeof *xs);
    }
    free(xs);
    if (line[0]) {
        snprintf(kindb, sizeof kindb, "%s (%s%s)", kind, line,
                 c->m->driver.kind == MECH_DRIVE_SLIDER ? ": dead centre of the slider" : "");
        kind = kindb;
    }
    diag_fail(c->d, fk, c->m->file, c->m->driver.mark,
              "singular position at %s = %s (reciprocal condition %.2g, limit %.2g): %s%s; "
              "velocities there are not unique", diagnose_driver_word(c->m),
              diagnose_q_text(c->m, q, qb, sizeof qb), sv->rcond, sv->p->opt.min_rcond, kind, what);
    return fk;
}

/* Modified Gram-Schmidt over the rows of a (nr x ns, dense), in order,
 * keeping each reduced row as a combination cf (nr x nr) of the original
 * rows: a row left with less than 1e-8 of its length is implied by those
 * before it, and its combination is a left null vector w (w^T J = 0). For
 * each, named[] gets the equation with the largest |w| (on a tie, the later
 * one): an equation that takes part in the dependency. Returns the count. */
static int dependent_rows(int nr, int ns, double *a, double *cf, int *named)
{
    int count = 0;
    for (int i = 0; i < nr; i++) {
        double *ri = a + (size_t)i * ns, *ci = cf + (size_t)i * nr, len0 = 0.0, len = 0.0;
        ci[i] = 1.0;
        for (int col = 0; col < ns; col++)
            len0 += ri[col] * ri[col];
        for (int j = 0; j < i; j++) {
            double *rj = a + (size_t)j * ns, *cj = cf + (size_t)j * nr, dot = 0.0, nj = 0.0;
            for (int col = 0; col < ns; col++)
                dot += ri[col] * rj[col], nj += rj[col] * rj[col];
            if (!(nj > 0.0))
                continue;
            for (int col = 0; col < ns; col++)
                ri[col] -= dot / nj * rj[col];
            for (int k = 0; k <= j; k++)
                ci[k] -= dot / nj * cj[k];
        }
        for (int col = 0; col < ns; col++)
            len += ri[col] * ri[col];
        if (len > 1e-16 * len0)
            continue;
        for (int col = 0; col < ns; col++)
            ri[col] = 0.0;
        int best = i;
        for (int k = 0; k <= i; k++)
            if (fabs(ci[k]) >= (1.0 - 1e-9) * fabs(ci[best]))
                best = k;
        named[count++] = best;
    }
    return count;
}

/* With redundant constraints (more loop equations than unknowns), say which
 * equations are implied by the others at the first position, by the rows'
 * dependencies (dependent_rows). Small systems only (dense). */
void diagnose_redundant(cont *c, double q)
{
    solver *sv = &c->sv;
    int nr = sv->p->nr, ns = sv->p->ns;
    if (!sv->p->aug || nr > 400)
        return;
    double *a = xcalloc((size_t)nr * (size_t)ns + 1, sizeof *a);
    double *cf = xcalloc((size_t)nr * (size_t)nr + 1, sizeof *cf);
    int *named = xcalloc((size_t)nr + 1, sizeof *named);
    if (!a || !cf || !named) {
        free(a);
        free(cf);
        free(named);
        return;
    }
    for (int col = 0, k = 0; col < ns; col++)
        for (int p = sv->p->Ap[nr + col]; p < sv->p->Ap[nr + col + 1]; p++, k++)
            a[(size_t)sv->p->Ai[p] * ns + col] = sv->Jv[k];
    int count = dependent_rows(nr, ns, a, cf, named);
    char list[600] = "", lb[256], qb[64];
    size_t at = 0;
    for (int i = 0; i < count && at < sizeof list; i++) {
        int row = sv->p->row[named[i]];
        row_kind kind = sv->p->sys->rows[row].kind;
        const char *what = kind == ROW_LOOP_X ? "x equation" : kind == ROW_LOOP_Y ? "y equation"
                                                                                 : "row";
        at += (size_t)snprintf(list + at, sizeof list - at, "%s%s of %s", i ? ", " : "", what,
                               rows_owner(sv->p->sys, row, lb, sizeof lb));
    }
    free(a);
    free(cf);
    free(named);
    diag_add(c->d, MECH_SEV_WARNING, MECH_FAIL_REDUNDANT, c->m->file, c->m->driver.mark,
             "%s: at %s = %s the %d loop equations have rank %d; "
             "implied by the others: the %s; the mechanism moves because "
             "they are consistent, and it is solved in the least-squares sense (joint "
             "reactions are not unique)", fail_words(MECH_FAIL_REDUNDANT),
             diagnose_driver_word(c->m), diagnose_q_text(c->m, q, qb, sizeof qb), nr,
             nr - count, count ? list : "(none found)");
}

const char *diagnose_branch_text(const mech_model *m, const mech_branch *b, char *buf,
                                 size_t size)
{
    const char *const *pn = (const char *const *)m->point_names;
    if (b->kind == MECH_BRANCH_TURN)
        snprintf(buf, size, "%s-%s-%s turning %s", pn[b->point[0]], pn[b->point[1]],
                 pn[b->point[2]], b->sign > 0 ? "counter-clockwise" : "clockwise");
    else if (b->kind == MECH_BRANCH_X)
        snprintf(buf, size, "%s %s of %s", pn[b->point[0]], b->sign > 0 ? "right" : "left",
                 pn[b->point[1]]);
    else if (b->kind == MECH_BRANCH_Y)
        snprintf(buf, size, "%s %s %s", pn[b->point[0]], b->sign > 0 ? "above" : "below",
                 pn[b->point[1]]);
    else
        snprintf(buf, size, "slider %s %s", m->joints[b->slider].name,
                 b->sign > 0 ? "positive" : "negative");
    return buf;
}

/* The links (and sliders) whose unknowns are large in the right null
 * vector of J at the current x: those that cannot move the loop closer to
 * closing there ("coupler and rocker"); "" when unknown (a large system).
 * Returns how many. */
static int reach_links(const solver *sv, char *buf, size_t size)
{
    const mech_model *m = sv->p->m;
    const mech_system *sys = sv->p->sys;
    double *right = xcalloc((size_t)sv->p->ns + 1, sizeof *right);
    double *left = xcalloc((size_t)sv->p->nr + 1, sizeof *left);
    int count = 0, k = 0;
    size_t at = 0;
    buf[0] = '\0';
    if (right && left && dense_null(sv, right, left) == 0) {
        double big = vec_norm_inf(right, sv->p->ns);
        for (int i = 0; i < sv->p->ns; i++)
            count += fabs(right[i]) > 0.05 * big;
        for (int i = 0; i < sv->p->ns && at < size; i++) {
            if (!(fabs(right[i]) > 0.05 * big))
                continue;
            int var = sv->p->col[i], l = 0, j = 0;
            while (l < m->nlinks && sys->link_var[l] != var)
                l++;
            while (l == m->nlinks && j < m->njoints && sys->joint_var[j] != var)
                j++;
            const char *sep = k == 0 ? "" : k == count - 1 ? " and " : ", ";
            k++;
            at += (size_t)snprintf(buf + at, size - at, "%s%s%s", sep,
                                   l < m->nlinks ? "" : "slider ",
                                   l < m->nlinks ? m->links[l].name
                                   : j < m->njoints ? m->joints[j].name : sys->names[var]);
        }
    }
    free(right);
    free(left);
    return buf[0] ? count : 0;
}

/* No start closed the loops, and the first stopped where the Jacobian is
 * singular with the loops open: not a singular position but the nearest the
 * starts came to an assembly, where the links of the null vector are at the
 * limit of their reach (a crank longer than the coupler and rocker allow:
 * "coupler and rocker"). */
static mech_fail_kind cannot_reach(cont *c, double q, const start_failure *f)
{
    const mech_model *m = c->m;
    solver *sv = &c->sv;
    char qb[64], lb[256], links[300], where[360] = "";
    if (!f->best_is_last)
        cont_solve_at(c, q, c->xgap);  /* that start's state again */
    int n = reach_links(sv, links, sizeof links);
    if (n > 0)
        snprintf(where, sizeof where, ", where %s %s at the limit of %s reach", links,
                 n > 1 ? "are" : "is", n > 1 ? "their" : "its");
    diag_fail(c->d, MECH_FAIL_NO_ASSEMBLY, m->file, m->driver.mark,
              "%s at %s = %s: %s does not close (residual %.3g m at best, after Newton from "
              "the initial guesses%s%s); check the dimensions, or give `initial:` guesses near "
              "the intended assembly", fail_words(MECH_FAIL_NO_ASSEMBLY),
              diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb),
              rows_owner(sv->p->sys, diagnose_worst_row(sv), lb, sizeof lb),
              vec_norm_inf(sv->f, sv->p->nr), f->attempts > 1 ? " and other starts" : "", where);
    return MECH_FAIL_NO_ASSEMBLY;
}

mech_fail_kind diagnose_start(cont *c, double q, const start_failure *f)
{
    const mech_model *m = c->m;
    char qb[64], lb[256];
    if (f->branch >= 0) {
        const mech_branch *b = &m->branches[f->branch];
        char what[200];
        diag_fail(c->d, MECH_FAIL_BRANCH, m->file, b->mark,
                  "at %s = %s the mechanism assembles, but not with %s "
                  "(from the initial guesses%s); check the guesses or the branch",
                  diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb),
                  diagnose_branch_text(m, b, what, sizeof what),
                  f->attempts > 1 ? " and other starts" : "");
        return MECH_FAIL_BRANCH;
    }
    if (f->first == STEP_SINGULAR && !(f->best_resid <= c->sv.p->ftol))
        return cannot_reach(c, q, f);
    if (f->first == STEP_SINGULAR) {  /* a start converged where J is singular */
        if (!f->best_is_last)
            cont_solve_at(c, q, c->xgap);  /* that start's state again */
        return diagnose_singular(c, q);
    }
    diag_fail(c->d, MECH_FAIL_NO_ASSEMBLY, m->file, m->driver.mark,
              "%s at %s = %s: %s does not close (residual %.3g m after "
              "Newton from the initial guesses%s); check the dimensions, or give "
              "`initial:` guesses near the intended assembly", fail_words(MECH_FAIL_NO_ASSEMBLY),
              diagnose_driver_word(m), diagnose_q_text(m, q, qb, sizeof qb),
              rows_owner(c->sv.p->sys, f->row, lb, sizeof lb), f->resid,
              f->attempts > 1 ? " and other starts" : "");
    return MECH_FAIL_NO_ASSEMBLY;
}

/* ---- failures in the sweep -------------------------------------------- */

static double lower_limit(cont *c, double span, double hrow, int *found)
{
    cont_set_base(c, c->q0, c->x0, c->xq0, c->xqq0);
    return cont_march(c, hrow > 0 ? -1.0 : 1.0, fabs(hrow), span, found);
}

/* Look for another interval where a crank assembles, in the gap (hi, lo +
 * 2 pi) left by the one found: Newton from scattered starts every row
 * spacing; at the first success, march both ways to its limits. Small
 * systems only (it is a search). Returns 1 with the interval in lo2, hi2. */
static int other_interval(cont *c, double lo, double hi, double h, double *lo2, double *hi2)
{
    solver *sv = &c->sv;
    if (sv->p->ns > 50 || !(h > 0.0))
        return 0;
    unsigned rng = 12345u;
    for (double q = hi + h; q < lo + 2.0 * PI - 0.5 * h; q += h)
        for (int a = 1; a <= 8; a++) {
            cont_start_values(c, a, &rng);
            if (cont_try(c, q, 0) != STEP_OK)
                continue;
            /* save this point: both marches start from it */
            size_t bytes = (size_t)sv->p->ns * sizeof(double);
            memcpy(c->x0, sv->x, bytes);
            memcpy(c->xq0, sv->xq, bytes);
            memcpy(c->xqq0, sv->xqq, bytes);
            int f1, f2;
            cont_set_base(c, q, c->x0, c->xq0, c->xqq0);
            *hi2 = cont_march(c, 1.0, h, 2.0 * PI, &f1);
            cont_set_base(c, q, c->x0, c->xq0, c->xqq0);
            *lo2 = cont_march(c, -1.0, h, 2.0 * PI, &f2);
            return f1 && f2;
        }
    return 0;
}

/* At the singular position the sweep stopped at, can the driver not move
 * on (a limit position: the solution curve turns back, as against a change
 * point, where another crosses it)? 0 when unknown (a large system). */
static int at_limit(cont *c)
{
    solver *sv = &c->sv;
    double *right = xcalloc((size_t)sv->p->ns + 1, sizeof *right);
    double *left = xcalloc((size_t)sv->p->nr + 1, sizeof *left);
    int limit = right && left && dense_null(sv, right, left) == 0 && !is_change_point(sv, left);
    free(right);
    free(left);
    return limit;
}

/* "; at 109.4712206 deg, coupler and rocker extended in line" at the limit
 * the sweep reached (the base of the continuation), to the digits the
 * refinement (1e-9 of a row) reached; "" when no links are in line. */
static void limit_words(cont *c, double hrow, char *why, size_t size)
{
    const mech_model *m = c->m;
    char line[200];
    double upper = c->qc;
    why[0] = '\0';
    in_line_text(&c->sv, upper, c->xc, line, sizeof line);
    if (!line[0])
        return;
    double unit;
    const char *u = q_unit(m, &unit);
    double acc = fmax(1e-9 * fabs(hrow), 1e-11 * fmax(fabs(upper), fabs(hrow))) * unit;
    int dec = (int)floor(-log10(acc)) - 1;
    snprintf(why, size, "; at %.*f %s, %s%s", dec < 0 ? 0 : dec > 12 ? 12 : dec, upper * unit,
             u, line, m->driver.kind == MECH_DRIVE_SLIDER ? ": dead centre of the slider" : "");
}

/* The interval(s) where the mechanism assembles, from row 0 and the last
 * position reached: "from A to B[ and from C to D] (limit positions...)". */
static void assembly_range(cont *c, double q_row, double hrow, const char *why, char *buf,
                           size_t size)
{
    const mech_model *m = c->m;
    char qb[64], qc[64], qd[64], qe[64], more[200] = "";
    double upper = c->qc;
    c->searching = 1;
    double span = is_angle_driver(m) ? 2.0 * PI : fabs(q_row - c->q0) * 4.0 + c->sv.p->lref;
    int found;
    double lower = lower_limit(c, span, hrow, &found);
    double lo = fmin(lower, upper), hi = fmax(lower, upper), lo2, hi2;
    if (found && is_angle_driver(m) && other_interval(c, lo, hi, fabs(hrow), &lo2, &hi2))
        snprintf(more, sizeof more, " and from %s to %s", diagnose_q_text(m, lo2, qd, sizeof qd),
                 diagnose_q_text(m, hi2, qe, sizeof qe));
    snprintf(buf, size, "the mechanism assembles for %s from %s%s to %s%s (limit positions%s%s)",
             diagnose_driver_word(m), found || lo == lower ? "" : "at most ",
             diagnose_q_text(m, lo, qb, sizeof qb), diagnose_q_text(m, hi, qc, sizeof qc), more,
             found ? "" : "; the other side was not searched past one range", why);
}

mech_fail_kind diagnose_failure(cont *c, double q_row, double hrow)
{
    const mech_model *m = c->m;
    solver *sv = &c->sv;
    char qa[64], qb[64], lb[256], range[600];
    double upper = c->qc, fq = c->fail_q;
    step_status s = c->fail_status;
    int row = c->fail_row;
    double resid = c->fail_resid;
    const char *no_assembly = fail_words(MECH_FAIL_NO_ASSEMBLY);
    /* stuck at a limit short of the row: the row itself cannot assemble
       (a row on the limit itself is a singular position, below) */
    if (s == STEP_SINGULAR && fabs(q_row - fq) > 1e-6 * fabs(hrow) && at_limit(c)) {
        double rcond = sv->rcond;
        char why[300];
        c->fail_change_point = 0;  /* a limit (at_limit), not an earlier diagnosis's */
        limit_words(c, hrow, why, sizeof why);
        assembly_range(c, q_row, hrow, why, range, sizeof range);
        diag_fail(c->d, MECH_FAIL_NO_ASSEMBLY, m->file, m->driver.mark,
                  "%s at %s = %s: the sweep reached a limit position at %s "
                  "(reciprocal condition %.2g), past which %s does not close; %s", no_assembly,
                  diagnose_driver_word(m), diagnose_q_text(m, q_row, qa, sizeof qa),
                  diagnose_q_text(m, fq, qb, sizeof qb), rcond,
                  rows_owner(sv->p->sys, row, lb, sizeof lb), range);
        return MECH_FAIL_NO_ASSEMBLY;
    }
    if (s == STEP_SINGULAR)
        return diagnose_singular(c, fq);
    if (s == STEP_NO_ASSEMBLY) {
        char why[300];
        limit_words(c, hrow, why, sizeof why);
        assembly_range(c, q_row, hrow, why, range, sizeof range);
        diag_fail(c->d, MECH_FAIL_NO_ASSEMBLY, m->file, m->driver.mark,
                  "%s at %s = %s: %s does not close (residual %.3g m); %s", no_assembly,
                  diagnose_driver_word(m), diagnose_q_text(m, q_row, qa, sizeof qa),
                  rows_owner(sv->p->sys, row, lb, sizeof lb), resid, range);
        return MECH_FAIL_NO_ASSEMBLY;
    }
    if (s == STEP_JUMP) {
        diag_fail(c->d, MECH_FAIL_JUMP, m->file, m->driver.mark,
                  "at %s = %s %s (to another assembly branch, or through a "
                  "branch point) although the step was refined to %.3g of the row spacing; "
                  "the sweep stops here rather than switch branches silently",
                  diagnose_driver_word(m), diagnose_q_text(m, fq, qa, sizeof qa),
                  fail_words(MECH_FAIL_JUMP), fabs(fq - upper) / fmax(fabs(hrow), 1e-300));
        return MECH_FAIL_JUMP;
    }
    if (s == STEP_BRANCH) {
        diag_fail(c->d, MECH_FAIL_BRANCH, m->file, m->driver.mark,
                  "at %s = %s the mechanism %s (a change point, where the branches cross); the "
                  "sweep stops on the declared branch at %s", diagnose_driver_word(m),
                  diagnose_q_text(m, fq, qa, sizeof qa), fail_words(MECH_FAIL_BRANCH),
                  diagnose_q_text(m, upper, qb, sizeof qb));
        return MECH_FAIL_BRANCH;
    }
    diag_nomem(c->d, m->file, (mech_mark){0, 0});
    return MECH_FAIL_NOMEM;
}
