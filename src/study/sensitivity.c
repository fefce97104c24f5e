/* src/study/sensitivity.c: d(output)/d(parameter) along a solved sweep, from the
 * implicit-function theorem, exact to rounding (mech_sensitivity).
 *
 * The loop equations are written with the points' coordinates C as
 * leaves (system_coef.c, SYS_LEAF_CARTESIAN); the model's parameter
 * expressions give dC/dp (param_expr.c, no file read). With T the time derivative (x -> x', q -> q', x' -> x'',
 * q' -> q'') and P the derivative by p (x -> X, x' -> V, x'' -> A, C ->
 * dC/dp; q does not depend on p), f = 0, T f = 0 and T T f = 0 hold for
 * every p, so
 *   J X = -P0(f),   J V = -P1(T f),   J A = -P2(T T f)
 * where J = df/dx (= d(T f)/dx' = d(T T f)/dx'') and Pk leaves out the
 * unknown term (P0 without X, P1 without V, P2 without A). Every output (a
 * point's position built along the spanning tree, a link angle, a slider)
 * e gives P(e), P(T e), P(T T e). All of it symbolic, compiled to one tape
 * of four phases (J and P0 f; P1; P2; the outputs), run per row and
 * parameter with a dense LU of J. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"
#include "study.h"

enum { PH_J, PH_V, PH_A, PH_OUT, NPH };

/* ---- the symbolic part ------------------------------------------------ */

/* sum over the variables v of e with tan[v] >= 0 of de/dv * (variable tan[v]) */
static ex directional(expr_ctx *c, ex e, const int *tan, int *vars, int maxv)
{
    int nv = expr_vars(c, e, vars, maxv);
    ex sum = c->zero;
    for (int k = 0; k < nv && k < maxv; k++) {
        int v = vars[k], t = tan[v];
        if (t >= 0)
            sum = expr_add(c, sum, expr_mul(c, expr_diff(c, e, v), expr_var(c, t)));
    }
    return sum;
}

/* Tangent maps over all variables: time, and P without or with each unknown level. */
static int make_maps(sens_plan *sp)
{
    int n = sp->n, nv = sp->nvars;
    for (int k = 0; k < NMAPS; k++) {
        sp->map[k] = xcalloc((size_t)nv, sizeof *sp->map[k]);
        if (!sp->map[k])
            return -1;
        for (int v = 0; v < nv; v++)
            sp->map[k][v] = -1;
    }
    for (int i = 0; i < n; i++) {
        sp->map[MAP_T][i] = SYS_VAR_XDOT(n, i);
        sp->map[MAP_T][SYS_VAR_XDOT(n, i)] = sp->v_xdd + i;
        for (int k = MAP_P1; k <= MAP_P; k++)
            sp->map[k][i] = sp->v_X + i;
        sp->map[MAP_P2][SYS_VAR_XDOT(n, i)] = sp->v_V + i;
        sp->map[MAP_P][SYS_VAR_XDOT(n, i)] = sp->v_V + i;
        sp->map[MAP_P][sp->v_xdd + i] = sp->v_A + i;
    }
    sp->map[MAP_T][SYS_VAR_Q(n)] = SYS_VAR_QDOT(n);
    sp->map[MAP_T][SYS_VAR_QDOT(n)] = SYS_VAR_QDDOT(n);
    for (int g = 0; g < 2 * sp->npoints; g++)
        for (int k = MAP_P0; k <= MAP_P; k++)
            sp->map[k][SYS_NVARS(n) + g] = sp->v_D + g;
    return 0;
}

/* Point i of link l in the ground frame: o_l + R(theta_l) C_i. */
static void on_link(sens_plan *sp, int l, int i, ex *x, ex *y)
{
    mech_system *s = sp->sys;
    expr_ctx *c = &s->ex;
    int g = s->point_base[l] + i;
    ex cx = expr_var(c, SYS_COORD(s->n, g)), cy = expr_var(c, SYS_COORD(s->n, g) + 1);
    ex th = s->link_angle[l], co = expr_cos(c, th), si = expr_sin(c, th);
    *x = expr_add(c, sp->ox[l], expr_sub(c, expr_mul(c, cx, co), expr_mul(c, cy, si)));
    *y = expr_add(c, sp->oy[l], expr_add(c, expr_mul(c, cx, si), expr_mul(c, cy, co)));
}

/* The frame origin of link l, placed from its parent along the spanning
 * tree as kinematics.c places it (parents first: sp->frames in BFS order). */
static void place(sens_plan *sp, int l)
{
    mech_system *s = sp->sys;
    const mech_model *m = s->model;
    expr_ctx *c = &s->ex;
    int j = s->span.parent_joint[l], pl = s->span.parent_link[l];
    const mech_joint *jt = &m->joints[j];
    int mine = jt->kind == MECH_JOINT_REVOLUTE ? loops_attach(jt, l)
                                               : jt->point[l == jt->link[0] ? 0 : 1];
    int theirs = jt->kind == MECH_JOINT_REVOLUTE ? loops_attach(jt, pl)
                                                 : jt->point[l == jt->link[0] ? 1 : 0];
    ex px, py;
    on_link(sp, pl, theirs, &px, &py);
    if (jt->kind != MECH_JOINT_REVOLUTE) {  /* mover = guide point + s u, u at theta_g + angle */
        ex a = expr_add(c, s->link_angle[jt->link[1]], expr_const(c, jt->angle));
        ex dx = expr_mul(c, s->slide[j], expr_cos(c, a)), dy = expr_mul(c, s->slide[j], expr_sin(c, a));
        if (l != jt->link[0]) {
            dx = expr_neg(c, dx);
            dy = expr_neg(c, dy);
        }
        px = expr_add(c, px, dx);
        py = expr_add(c, py, dy);
    }
    sp->ox[l] = sp->oy[l] = c->zero;  /* on_link of l itself at the origin, then subtract */
    ex rx, ry;
    on_link(sp, l, mine, &rx, &ry);
    sp->ox[l] = expr_sub(c, px, rx);
    sp->oy[l] = expr_sub(c, py, ry);
}

static int build_frames(sens_plan *sp)
{
    mech_system *s = sp->sys;
    int nl = s->model->nlinks;
    sp->ox = xcalloc((size_t)nl, sizeof *sp->ox);
    sp->oy = xcalloc((size_t)nl, sizeof *sp->oy);
    if (!sp->ox || !sp->oy)
        return -1;
    for (int l = 0; l < nl; l++)
        sp->ox[l] = sp->oy[l] = s->ex.zero;
    for (int k = 0; k < s->span.norder; k++)
        place(sp, s->span.order[k]);
    return s->ex.failed ? -1 : 0;
}

/* The link nearest the ground that carries point name id, and its index there. */
static int carrier(const mech_system *s, int id, int *index)
{
    const mech_model *m = s->model;
    int best = -1;
    for (int l = 0; l < m->nlinks; l++)
        for (int i = 0; i < m->links[l].npoints; i++)
            if (m->links[l].points[i].id == id && s->span.depth[l] >= 0 &&
                (best < 0 || s->span.depth[l] < s->span.depth[best])) {
                best = l;
                *index = i;
            }
    return best;
}

int sens_output_expr(sens_plan *sp, int kind, int obj, int comp, ex *e)
{
    mech_system *s = sp->sys;
    if (kind == SENS_LINK) {
        *e = s->link_angle[obj];
        return 0;
    }
    if (kind == SENS_SLIDER) {
        *e = s->slide[obj];
        return *e < 0 ? -1 : 0;
    }
    int i = 0, l = carrier(s, obj, &i);
    if (l < 0)
        return -1;
    ex x, y;
    on_link(sp, l, i, &x, &y);
    *e = comp ? y : x;
    return 0;
}

/* e, T e, T T e -> P e, P T e, P T T e: three roots of the output phase. */
int sens_add_output(sens_plan *sp, ex e, int *first_root)
{
    expr_ctx *c = &sp->sys->ex;
    if (sp->nout + 3 > sp->capout) {
        int cap = 2 * sp->capout + 24;
        ex *more = xrealloc_array(sp->out, (size_t)cap, sizeof *more);
        if (!more)
            return -1;
        sp->out = more;
        sp->capout = cap;
    }
    *first_root = sp->nout;
    for (int level = 0; level < 3; level++) {
        sp->out[sp->nout++] = directional(c, e, sp->map[MAP_P], sp->vars, sp->nvars);
        e = directional(c, e, sp->map[MAP_T], sp->vars, sp->nvars);
    }
    return c->failed ? -1 : 0;
}

/* The equations' rows: P0 f, P1 T f, P2 T T f. */
static int build_rows(sens_plan *sp)
{
    mech_system *s = sp->sys;
    expr_ctx *c = &s->ex;
    int rows = s->m;
    for (int k = 0; k < 3; k++)
        if (!(sp->g[k] = xcalloc((size_t)rows + 1, sizeof *sp->g[k])))
            return -1;
    for (int r = 0; r < rows; r++) {
        ex v = directional(c, s->f[r], sp->map[MAP_T], sp->vars, sp->nvars);
        ex a = directional(c, v, sp->map[MAP_T], sp->vars, sp->nvars);
        sp->g[0][r] = directional(c, s->f[r], sp->map[MAP_P0], sp->vars, sp->nvars);
        sp->g[1][r] = directional(c, v, sp->map[MAP_P1], sp->vars, sp->nvars);
        sp->g[2][r] = directional(c, a, sp->map[MAP_P2], sp->vars, sp->nvars);
    }
    return c->failed ? -1 : 0;
}

/* ---- plan ---------------------------------------------------------------- */

void sens_plan_free(sens_plan *sp)
{
    if (!sp)
        return;
    tape_free(&sp->tp);
    for (int k = 0; k < NMAPS; k++)
        free(sp->map[k]);
    for (int k = 0; k < 3; k++)
        free(sp->g[k]);
    free(sp->ox);
    free(sp->oy);
    free(sp->out);
    free(sp->vars);
    free(sp->reg);
    free(sp->lu);
    free(sp->piv);
    free(sp->rhs);
    mech_system_free(&sp->sys);
    memset(sp, 0, sizeof *sp);
}

/* The derivatives carried into the equations are the points' (dC/dp). A
 * parameter that also moves a slider's angle, or a gear pair's radii or
 * phase (the model's parameter expressions say), would be differentiated
 * without that term: refused. */
static int refuse_unsupported(const mech_model *m, int p, mech_diag *d)
{
    if (model_ncams(m) > 0)  /* the cams' numbers and programs are folded (docs/cams.md) */
        return diag_error(d, m->file, m->cams->cam[0].mark, "parameter '%s': sensitivities of "
                          "a mechanism with a cam pair ('%s') are not computed yet",
                          m->params[p].name, m->cams->cam[0].name);
    const param_exprs *pe = m->pexpr;
    double *dv = pe ? xcalloc((size_t)pe->n + 1, sizeof *dv) : NULL;
    if (!pe)
        return MECH_OK;
    if (!dv)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    pexpr_derivatives(pe, p, dv);
    int rc = MECH_OK;
    for (int j = 0; j < m->njoints && rc == MECH_OK; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER &&
            pexpr_deriv_of(dv, pexpr_get(pe, PXN_SLIDER_ANGLE, j)) != 0.0)
            rc = diag_error(d, m->file, m->joints[j].mark, "parameter '%s' sets the angle of "
                            "slider '%s': sensitivities through a slider's angle are not "
                            "computed", m->params[p].name, m->joints[j].name);
    for (int g = 0; g < m->ngears && rc == MECH_OK; g++)  /* gears.c's rows */
        for (int k = 0; k < 4 && rc == MECH_OK; k++)
            if (pexpr_deriv_of(dv, pexpr_get(pe, PXN_GEAR, 4 * g + k)) != 0.0)
                rc = diag_error(d, m->file, m->gears[g].mark, "parameter '%s' sets the radii or "
                                "the phase of gear pair '%s': sensitivities through a gear pair "
                                "are not computed", m->params[p].name, m->gears[g].name);
    free(dv);
    return rc;
}

int sens_plan_new(sens_plan *sp, const mech_model *m, const int *which, int nwhich,
                  mech_diag *d)
{
    memset(sp, 0, sizeof *sp);
    int rc = MECH_OK;
    for (int k = 0; k < nwhich && rc == MECH_OK; k++)
        rc = refuse_unsupported(m, which[k], d);
    if (rc != MECH_OK)
        return rc;
    sys_leaves coordinates = {SYS_LEAF_CARTESIAN, which, nwhich};
    if ((rc = sys_new_with(m, &coordinates, &sp->sys, d)) != MECH_OK) {
        sens_plan_free(sp);
        return rc;
    }
    mech_system *s = sp->sys;
    if (s->m != s->n) {
        rc = diag_error(d, m->file, (mech_mark){0, 0}, "sensitivities need as many loop "
                        "equations as unknowns (%d equations, %d unknowns: redundant "
                        "constraints)", s->m, s->n);
        sens_plan_free(sp);
        return rc;
    }
    sp->n = s->n;
    sp->npoints = s->point_base[m->nlinks];
    sp->v_xdd = s->nvars;
    sp->v_D = sp->v_xdd + sp->n;
    sp->v_X = sp->v_D + 2 * sp->npoints;
    sp->v_V = sp->v_X + sp->n;
    sp->v_A = sp->v_V + sp->n;
    sp->nvars = sp->v_A + sp->n;
    sp->vars = xcalloc((size_t)sp->nvars, sizeof *sp->vars);
    sp->lu = xcalloc((size_t)sp->n * (size_t)sp->n + 1, sizeof *sp->lu);
    sp->piv = xcalloc((size_t)sp->n + 1, sizeof *sp->piv);
    sp->rhs = xcalloc((size_t)sp->n + 1, sizeof *sp->rhs);
    if (!sp->vars || !sp->lu || !sp->piv || !sp->rhs || make_maps(sp) < 0 ||
        build_rows(sp) < 0 || build_frames(sp) < 0) {
        sens_plan_free(sp);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    return MECH_OK;
}

int sens_plan_compile(sens_plan *sp, mech_diag *d)
{
    mech_system *s = sp->sys;
    int rows = s->m;
    ex *ph0 = xcalloc((size_t)(s->nnz + rows) + 1, sizeof *ph0);
    if (!ph0)
        return diag_nomem(d, s->model->file, (mech_mark){0, 0});
    memcpy(ph0, s->Jx, (size_t)s->nnz * sizeof *ph0);
    memcpy(ph0 + s->nnz, sp->g[0], (size_t)rows * sizeof *ph0);
    const ex *roots[NPH] = {ph0, sp->g[1], sp->g[2], sp->out};
    int nroots[NPH] = {s->nnz + rows, rows, rows, sp->nout};
    int rc = tape_compile(&sp->tp, &s->ex, sp->nvars, NPH, roots, nroots);
    free(ph0);
    if (rc == 0 && !(sp->reg = tape_registers_new(&sp->tp)))
        rc = -1;
    if (rc != 0)
        return diag_nomem(d, s->model->file, (mech_mark){0, 0});
    return MECH_OK;
}

/* ---- numbers ------------------------------------------------------------- */

/* Dense LU with partial pivoting of J (from the phase-0 registers) into
 * sp->lu; 0, or -1 when J is singular. */
static int factor(sens_plan *sp)
{
    mech_system *s = sp->sys;
    int n = sp->n;
    double *a = sp->lu;
    memset(a, 0, (size_t)n * (size_t)n * sizeof *a);
    for (int j = 0; j < n; j++)
        for (int k = s->Jp[j]; k < s->Jp[j + 1]; k++)
            a[s->Ji[k] * n + j] = tape_value(&sp->tp, sp->reg, s->Jx[k]);
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(a[i * n + k]) > fabs(a[p * n + k]))
                p = i;
        sp->piv[k] = p;
        if (a[p * n + k] == 0.0)
            return -1;
        if (p != k)
            for (int j = 0; j < n; j++) {
                double t = a[k * n + j];
                a[k * n + j] = a[p * n + j];
                a[p * n + j] = t;
            }
        for (int i = k + 1; i < n; i++) {
            double l = a[i * n + k] /= a[k * n + k];
            for (int j = k + 1; j < n; j++)
                a[i * n + j] -= l * a[k * n + j];
        }
    }
    return 0;
}

/* b := J^-1 b (after factor). */
static void lu_solve(const sens_plan *sp, double *b)
{
    int n = sp->n;
    const double *a = sp->lu;
    for (int k = 0; k < n; k++) {
        double t = b[k];
        b[k] = b[sp->piv[k]];
        b[sp->piv[k]] = t;
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < i; j++)
            b[i] -= a[i * n + j] * b[j];
    for (int i = n - 1; i >= 0; i--) {
        for (int j = i + 1; j < n; j++)
            b[i] -= a[i * n + j] * b[j];
        b[i] /= a[i * n + i];
    }
}

/* One level: rhs = -g[level] (just computed), solve, set the unknown's tangent. */
static void solve_level(sens_plan *sp, int level, int base)
{
    for (int r = 0; r < sp->n; r++)
        sp->rhs[r] = -tape_value(&sp->tp, sp->reg, sp->g[level][r]);
    lu_solve(sp, sp->rhs);
    for (int i = 0; i < sp->n; i++)
        tape_set_var(&sp->tp, sp->reg, base + i, sp->rhs[i]);
}

int sens_row(sens_plan *sp, const double *state, int param, double *out)
{
    const tape *t = &sp->tp;
    int n = sp->n;
    for (int v = 0; v < SYS_NVARS(n); v++)  /* x, q, x', q', q'' */
        tape_set_var(t, sp->reg, v, state[v]);
    for (int i = 0; i < n; i++)
        tape_set_var(t, sp->reg, sp->v_xdd + i, state[SYS_NVARS(n) + i]);
    const mech_model *m = sp->sys->model;
    for (int l = 0, g = 0; l < m->nlinks; l++)
        for (int i = 0; i < m->links[l].npoints; i++, g++) {
            tape_set_var(t, sp->reg, SYS_COORD(n, g), m->links[l].points[i].x);
            tape_set_var(t, sp->reg, SYS_COORD(n, g) + 1, m->links[l].points[i].y);
        }
    for (int g = 0; g < 2 * sp->npoints; g++)
        tape_set_var(t, sp->reg, sp->v_D + g, sp->sys->dxy[param][g]);
    tape_run(t, sp->reg, PH_J);
    if (factor(sp) < 0)
        return -1;
    solve_level(sp, 0, sp->v_X);
    tape_run(t, sp->reg, PH_V);
    solve_level(sp, 1, sp->v_V);
    tape_run(t, sp->reg, PH_A);
    solve_level(sp, 2, sp->v_A);
    tape_run(t, sp->reg, PH_OUT);
    for (int k = 0; k < sp->nout; k++)
        out[k] = tape_value(t, sp->reg, sp->out[k]);
    return 0;
}
