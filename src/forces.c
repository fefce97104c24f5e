/* src/forces.c: joint reactions and the driver torque by Newton-Euler with
 * D'Alembert inertia loads (docs/forces.md).
 *
 * Rows: for each moving link l, forces in x and y and the moment about its
 * centre of mass G. Columns: Fx, Fy of each revolute joint; the normal force
 * N (and, for a locked slider, the couple M) of each slider; the tangential
 * tooth force of each gear pair (its separating part follows from it:
 * gear_separation, docs/forces.md section 9); the driver's torque or force. A joint's reaction acts on its receiving link (the later
 * one in the file for a revolute, the sliding link for a slider) and its
 * opposite on the other link.
 *
 * Friction: Coulomb moments mu r |F| in revolutes and forces mu |N| in
 * sliders, opposing the relative motion, found by fixed-point iteration on
 * the reaction magnitudes, starting from the frictionless solution. The
 * sign of the relative speed is smoothed, v / sqrt(v^2 + eps^2), with eps a
 * millionth of the driver speed, so that the friction load is continuous
 * where the relative motion reverses.
 *
 * Power balance (independent of the force solution except for the driver):
 *   P_driver + P_loads + P_gravity - P_friction = d/dt (kinetic energy). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "drivers.h"
#include "forces.h"
#include "gears.h"
#include "springs.h"
#include "state_loads.h"

enum { MAX_ENTRIES = 6, FRICTION_MAX_ITER = 100, ANDERSON_DEPTH = 3 };
static const double FRICTION_TOL = 1e-12;

/* ---- geometry of one step -------------------------------------------- */

static int moving_row(int link) { return 3 * (link - 1); }  /* -3 .. for ground: unused */

/* Receiving link (a) and the other (b) of joint j. */
static void joint_links(const mech_joint *jt, int *a, int *b)
{
    if (jt->kind == MECH_JOINT_SLIDER) {
        *a = jt->link[0];
        *b = jt->link[1];
    } else {
        *a = jt->link[0] > jt->link[1] ? jt->link[0] : jt->link[1];
        *b = jt->link[0] > jt->link[1] ? jt->link[1] : jt->link[0];
    }
}

static void point_motion(const solver *sv, int l, int i, double *p, double *v, double *a)
{
    const mech_point *pt = &sv->p->m->links[l].points[i];
    double r[2] = {pt->x, pt->y};
    kin_on_link(&sv->ks, l, r, p, v, a);
}

/* Centres of mass of every link (the frame origin for a link without mass)
 * with their rates, once per step: every column, load and power term of a
 * link needs them. */
static void update_centres(forces *fc, const solver *sv)
{
    const mech_model *m = fc->p->m;
    for (int l = 0; l < m->nlinks; l++) {
        const mech_link *k = &m->links[l];
        double r[2] = {k->has_mass ? k->center[0] : 0.0, k->has_mass ? k->center[1] : 0.0};
        kin_on_link(&sv->ks, l, r, fc->g + 2 * l, fc->vg + 2 * l, fc->ag + 2 * l);
    }
}

/* Contact point of joint j: the pin, or the sliding point. */
static void contact(const solver *sv, const mech_joint *jt, double *p, double *v)
{
    double a[2];
    point_motion(sv, jt->link[0], jt->point[0], p, v, a);
}

/* The contact point alone (no rates): what a column's entries need. */
static void contact_point(const solver *sv, const mech_joint *jt, double *p)
{
    const mech_point *pt = &sv->p->m->links[jt->link[0]].points[jt->point[0]];
    double r[2] = {pt->x, pt->y};
    kin_on_link(&sv->ks, jt->link[0], r, p, NULL, NULL);
}

/* Guide direction u of a slider. */
static void guide_dir(const solver *sv, const mech_joint *jt, double *u)
{
    double ang = sv->ks.th[jt->link[1]] + jt->angle;
    u[0] = cos(ang);
    u[1] = sin(ang);
}

static double cross(const double *r, const double *f) { return r[0] * f[1] - r[1] * f[0]; }

/* ---- the columns ---------------------------------------------------- */

typedef struct entry {
    int row;
    double val;
} entry;

static int push_force(entry *e, int n, const double *centres, int l, const double *p,
                      const double *f, double sign)
{
    if (l == 0)
        return n;
    static const double origin[2] = {0.0, 0.0};  /* building the pattern: no centres */
    const double *g = centres ? centres + 2 * l : origin;
    double r[2] = {p[0] - g[0], p[1] - g[1]};
    int row = moving_row(l);
    e[n++] = (entry){row, sign * f[0]};
    e[n++] = (entry){row + 1, sign * f[1]};
    e[n++] = (entry){row + 2, sign * cross(r, f)};
    return n;
}

static int push_moment(entry *e, int n, int l, double sign)
{
    if (l != 0)
        e[n++] = (entry){moving_row(l) + 2, sign};
    return n;
}

/* Contact point p and direction dir of the force of column c on joint jt
 * at the published position of sv; with no position (sv NULL, the pattern
 * is being built) any point and direction do: only the rows matter. */
static void column_geometry(const solver *sv, const mech_joint *jt, fc_kind kind, double *p,
                            double *dir)
{
    double u[2] = {1.0, 0.0};
    p[0] = p[1] = 0.0;
    if (sv)
        contact_point(sv, jt, p);
    if (sv && (kind == FC_NORMAL || kind == FC_DRIVE))
        guide_dir(sv, jt, u);
    switch (kind) {
    case FC_FX: dir[0] = 1.0; dir[1] = 0.0; break;
    case FC_FY: dir[0] = 0.0; dir[1] = 1.0; break;
    case FC_NORMAL: dir[0] = -u[1]; dir[1] = u[0]; break;
    case FC_DRIVE: dir[0] = u[0]; dir[1] = u[1]; break;
    case FC_MOMENT: case FC_GEAR: dir[0] = dir[1] = 0.0; break;
    }
}

/* Entries of column c, in the order they are made (the plan's slot puts
 * them in row order: build_pattern sorts once): at the published position
 * of sv with the centres of mass g, or (sv NULL) just their rows. */
static int column_entries(const forces_plan *fp, const solver *sv, const double *g, int c,
                          entry *e)
{
    const mech_model *m = fp->m;
    int n = 0;
    if (fp->kind[c] == FC_GEAR) {  /* the tooth force: on link[1], its opposite on link[0] */
        const mech_gear *gr = &m->gears[fp->joint[c]];
        double p[2], t[2], r[2];  /* the unknown: its component along the tangent t */
        gears_contact(m, sv, fp->joint[c], p, t, r);
        n = push_force(e, n, g, gr->link[1], p, t, 1.0);
        return push_force(e, n, g, gr->link[0], p, t, -1.0);
    }
    /* driver k's column: joint -1 - k */
    const mech_motion *dr = fp->joint[c] < 0 ? &m->drivers[-1 - fp->joint[c]] : NULL;
    mech_drive_kind dkind = dr ? dr->kind : MECH_DRIVE_SLIDER;
    int dindex = dr ? dr->index : -1;
    if (fp->joint[c] < 0 && dkind == MECH_DRIVE_ANGLE) {
        n = push_moment(e, n, dindex, 1.0);
    } else {
        const mech_joint *jt = &m->joints[fp->joint[c] >= 0 ? fp->joint[c] : dindex];
        int a, b;
        joint_links(jt, &a, &b);
        double p[2], dir[2];
        column_geometry(sv, jt, fp->kind[c], p, dir);
        if (fp->kind[c] == FC_MOMENT) {
            n = push_moment(e, n, a, 1.0);
            n = push_moment(e, n, b, -1.0);
        } else {
            n = push_force(e, n, g, a, p, dir, 1.0);
            n = push_force(e, n, g, b, p, dir, -1.0);
        }
    }
    return n;
}

static int add_column(forces_plan *fp, fc_kind kind, int joint)
{
    fp->kind[fp->ncols] = kind;
    fp->joint[fp->ncols] = joint;
    return fp->ncols++;
}

static void make_columns(forces_plan *fp)
{
    const mech_model *m = fp->m;
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        fp->jcol[j] = fp->ncols;
        if (jt->kind == MECH_JOINT_REVOLUTE) {
            add_column(fp, FC_FX, j);
            add_column(fp, FC_FY, j);
        } else {
            add_column(fp, FC_NORMAL, j);
            if (jt->locked)
                add_column(fp, FC_MOMENT, j);
        }
        if (jt->friction > 0.0)
            fp->has_friction = 1;
    }
    fp->gcol = fp->ncols;
    for (int g = 0; g < m->ngears; g++)
        add_column(fp, FC_GEAR, g);
    fp->ndrive = m->ndrivers;
    for (int k = 0; k < fp->ndrive; k++)
        add_column(fp, FC_DRIVE, -1 - k);
}

static int build_pattern(forces_plan *fp)
{
    entry e[MAX_ENTRIES];
    int cap = 0;
    for (int c = 0; c < fp->ncols; c++)
        cap += column_entries(fp, NULL, NULL, c, e);
    fp->Ai = xcalloc((size_t)cap + 1, sizeof *fp->Ai);
    fp->slot = xcalloc((size_t)cap + 1, sizeof *fp->slot);
    if (!fp->Ai || !fp->slot)
        return -1;
    int at = 0;
    for (int c = 0; c < fp->ncols; c++) {
        fp->Ap[c] = at;
        int n = column_entries(fp, NULL, NULL, c, e);
        for (int k = 0; k < n; k++) {  /* rows are distinct: rank = place in row order */
            int rank = 0;
            for (int i = 0; i < n; i++)
                rank += e[i].row < e[k].row;
            fp->Ai[at + rank] = e[k].row;
            fp->slot[at + k] = at + rank;
        }
        at += n;
    }
    fp->Ap[fp->ncols] = at;
    fp->nnz = at;
    return 0;
}

/* 1 when nothing in m can load a joint: no moving link has a mass or an
 * inertia and there are no loads (gravity acts on masses only). */
static int nothing_loads(const mech_model *m)
{
    if (m->nloads > 0 || m->nsprings > 0 || m->state_loads)
        return 0;
    for (int i = 1; i < m->nlinks; i++)
        if (m->links[i].mass != 0.0 || m->links[i].inertia != 0.0)
            return 0;
    return 1;
}

static int no_memory(const mech_model *m, mech_diag *d)
{
    return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
}

int forces_plan_init(forces_plan *fp, const solver_plan *sp, int friction, mech_diag *d)
{
    const mech_model *m = sp->m;
    memset(fp, 0, sizeof *fp);
    fp->m = m;
    fp->nrows = 3 * (m->nlinks - 1);
    size_t nc = 2 * (size_t)m->njoints + (size_t)m->ngears + 1 + (size_t)m->ndrivers;
    fp->kind = xcalloc(nc, sizeof *fp->kind);
    fp->joint = xcalloc(nc, sizeof *fp->joint);
    fp->jcol = xcalloc((size_t)m->njoints + 1, sizeof *fp->jcol);
    fp->Ap = xcalloc(nc + 1, sizeof *fp->Ap);
    if (!fp->kind || !fp->joint || !fp->jcol || !fp->Ap)
        return no_memory(m, d);
    make_columns(fp);
    fp->friction = friction != MECH_FRICTION_OFF && fp->has_friction;
    fp->want_frictionless = friction == MECH_FRICTION_BOTH;
    if (fp->ncols != fp->nrows)
        return diag_error(d, m->file, m->driver.mark,
                          "the force analysis has %d unknown reactions for %d equilibrium "
                          "equations: the mechanism is %s", fp->ncols, fp->nrows,
                          fp->ncols > fp->nrows ? "over-constrained (reactions not unique)"
                                                : "under-constrained"), MECH_EINPUT;
    if (build_pattern(fp) < 0)
        return no_memory(m, d);
    double qd = fabs(m->driver.speed);
    if (m->driver.kind == MECH_DRIVE_SLIDER)
        qd /= sp->lref;
    fp->speed_eps = 1e-6 * (qd > 0.0 ? qd : 1.0);
    int rc = linsys_plan_init(&fp->lp, fp->ncols, fp->Ap, fp->Ai, sp->opt.linear_solver);
    if (rc < 0)
        return no_memory(m, d);
    if (rc > 0)
        return diag_error(d, m->file, m->driver.mark,
                          "the force analysis is structurally singular: some reaction appears in "
                          "no equilibrium equation that could determine it"), MECH_EINPUT;
    if (nothing_loads(m))  /* the zeros are right, but likely not what was meant */
        diag_note(d, m->file, m->driver.mark,
                  "no link has a mass and there are no loads: every joint reaction and the "
                  "driver %s are zero (give links a 'mass' or add 'loads')",
                  m->driver.kind == MECH_DRIVE_ANGLE ? "torque" : "force");
    return MECH_OK;
}

void forces_plan_free(forces_plan *fp)
{
    linsys_plan_free(&fp->lp);
    void *blocks[] = {fp->kind, fp->joint, fp->jcol, fp->Ap, fp->Ai, fp->slot};
    free_all(blocks, COUNT_OF(blocks));
    memset(fp, 0, sizeof *fp);
}

int forces_init(forces *fc, const forces_plan *fp)
{
    memset(fc, 0, sizeof *fc);
    fc->p = fp;
    size_t nr = (size_t)fp->nrows + 1, nc = (size_t)fp->ncols + 1;
    size_t nl2 = 2 * (size_t)fp->m->nlinks, depth = ANDERSON_DEPTH;
    double **arrays[] = {&fc->Ax, &fc->cscale, &fc->b, &fc->y, &fc->y0, &fc->ynext,
                         &fc->aa_g, &fc->aa_r, &fc->aa_dg, &fc->aa_dr, &fc->fric,
                         &fc->g, &fc->vg, &fc->ag};
    size_t sizes[] = {(size_t)fp->nnz + 1, nc, nr + nc, nr + nc, nr + nc, nr + nc,
                      nr, nr, depth * nr, depth * nr, nr, nl2, nl2, nl2};
    if (xcalloc_doubles(arrays, sizes, 0, COUNT_OF(arrays)) < 0)
        return -1;
    if (fp->m->state_loads && !(fc->sl_reg = state_loads_registers(fp->m->state_loads)))
        return -1;
    return linsys_init(&fc->ls, &fp->lp);
}

void forces_free(forces *fc)
{
    linsys_free(&fc->ls);
    void *blocks[] = {fc->Ax, fc->b, fc->y, fc->y0, fc->ynext, fc->fric, fc->cscale,
                      fc->g, fc->vg, fc->ag, fc->aa_g, fc->aa_r, fc->aa_dg, fc->aa_dr};
    free_all(blocks, COUNT_OF(blocks));
    free(fc->sl_reg);
    memset(fc, 0, sizeof *fc);
}

/* ---- the right-hand side --------------------------------------------- */

/* An external force f at point p of link l: moves to the right-hand side. */
static void load_force(double *rhs, const forces *fc, int l, const double *p, const double *f)
{
    if (l == 0)
        return;
    const double *g = fc->g + 2 * l;
    double r[2] = {p[0] - g[0], p[1] - g[1]};
    int row = moving_row(l);
    rhs[row] -= f[0];
    rhs[row + 1] -= f[1];
    rhs[row + 2] -= cross(r, f);
}

static void load_moment(double *rhs, int l, double t)
{
    if (l != 0)
        rhs[moving_row(l) + 2] -= t;
}

/* Resultant of a load and its point of application (and that point's
 * velocity, for the power balance). Uniform distributed loads act at the
 * middle of their segment. */
static void load_resultant(const solver *sv, const mech_load *ld, double *f, double *p, double *v)
{
    double a[2];
    if (ld->kind == MECH_LOAD_FORCE) {
        f[0] = ld->force[0];
        f[1] = ld->force[1];
        point_motion(sv, ld->link, ld->point[0], p, v, a);
        return;
    }
    double p0[2], p1[2], v0[2], v1[2];
    point_motion(sv, ld->link, ld->point[0], p0, v0, a);
    point_motion(sv, ld->link, ld->point[1], p1, v1, a);
    double w = ld->intensity * hypot(p1[0] - p0[0], p1[1] - p0[1]);
    f[0] = w * cos(ld->direction);
    f[1] = w * sin(ld->direction);
    for (int k = 0; k < 2; k++) {
        p[k] = 0.5 * (p0[k] + p1[k]);
        v[k] = 0.5 * (v0[k] + v1[k]);
    }
}

/* Inertia, gravity and external loads. */
static void known_loads(const forces *fc, const solver *sv, double *rhs)
{
    const forces_plan *fp = fc->p;
    const mech_model *m = fp->m;
    for (int l = 1; l < m->nlinks; l++) {
        const mech_link *k = &m->links[l];
        int row = moving_row(l);
        if (!k->has_mass) {
            rhs[row] = rhs[row + 1] = rhs[row + 2] = 0.0;
            continue;
        }
        const double *ag = fc->ag + 2 * l;
        rhs[row] = k->mass * (ag[0] - m->gravity[0]);
        rhs[row + 1] = k->mass * (ag[1] - m->gravity[1]);
        rhs[row + 2] = k->inertia * sv->ks.al[l];
    }
    for (int i = 0; i < m->nloads; i++) {
        const mech_load *ld = &m->loads[i];
        if (ld->kind == MECH_LOAD_TORQUE) {
            load_moment(rhs, ld->link, ld->torque);
            continue;
        }
        double f[2], p[2], v[2];
        load_resultant(sv, ld, f, p, v);
        load_force(rhs, fc, ld->link, p, f);
    }
    springs_add_loads(m, sv, fc->g, rhs);
    state_loads_add(m->state_loads, sv, fc->sl_reg, fc->g, rhs);
}

/* The separating part of each tooth force, |F| tan(pressure angle) for the
 * tangential force F of reactions y (gears.h): a known load given y. It
 * lies along the line of centres, so it changes no F, only the pivots'
 * reactions: one more solve finds them. */
static void gear_separation(const forces *fc, const solver *sv, const double *y, double *rhs)
{
    const mech_model *m = fc->p->m;
    for (int i = 0; i < m->ngears; i++) {
        const mech_gear *gr = &m->gears[i];
        double p[2], t[2], r[2];
        gears_contact(m, sv, i, p, t, r);
        double k = fabs(y[fc->p->gcol + i]) * tan(gr->pressure_angle);
        double fb[2] = {k * r[0], k * r[1]}, fa[2] = {-fb[0], -fb[1]};
        load_force(rhs, fc, gr->link[1], p, fb);
        load_force(rhs, fc, gr->link[0], p, fa);
    }
}

/* ---- friction ---------------------------------------------------------- */

static double smooth_sign(double v, double eps) { return v / sqrt(v * v + eps * eps); }

/* Relative speed of joint j: angular (revolute, receiving minus other link)
 * or sliding (slider, along the guide). */
static double relative_speed(const forces *fc, const solver *sv, int j)
{
    const forces_plan *fp = fc->p;
    const mech_joint *jt = &fp->m->joints[j];
    if (jt->kind == MECH_JOINT_SLIDER) {
        int var = sv->p->tree.slide_var[j];
        return var >= 0 ? sv->vel[var] : 0.0;
    }
    int a, b;
    joint_links(jt, &a, &b);
    return sv->ks.om[a] - sv->ks.om[b];
}

/* Friction loads for reactions y (into fc->fric) and the power they
 * dissipate. */
static double friction_loads(forces *fc, const solver *sv, const double *y)
{
    const forces_plan *fp = fc->p;
    const mech_model *m = fp->m;
    double power = 0.0;
    memset(fc->fric, 0, (size_t)fp->nrows * sizeof *fc->fric);
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (!(jt->friction > 0.0))
            continue;
        int a, b, c = fp->jcol[j];
        joint_links(jt, &a, &b);
        double rel = relative_speed(fc, sv, j);
        if (jt->kind == MECH_JOINT_REVOLUTE) {
            double eps = fp->speed_eps;
            double mf = jt->friction * jt->pin_radius * sqrt(y[c] * y[c] + y[c + 1] * y[c + 1]) *
                        smooth_sign(rel, eps);
            load_moment(fc->fric, a, -mf);
            load_moment(fc->fric, b, mf);
            power += mf * rel;
        } else {
            double eps = fp->speed_eps * sv->p->lref, u[2], p[2], v[2];
            double ff = jt->friction * fabs(y[c]) * smooth_sign(rel, eps);
            guide_dir(sv, jt, u);
            contact(sv, jt, p, v);
            double fa[2] = {-ff * u[0], -ff * u[1]}, fb[2] = {ff * u[0], ff * u[1]};
            load_force(fc->fric, fc, a, p, fa);
            load_force(fc->fric, fc, b, p, fb);
            power += ff * rel;
        }
    }
    return power;
}

/* ---- solving ------------------------------------------------------------ */

static int factor(forces *fc, const solver *sv)
{
    const forces_plan *fp = fc->p;
    entry e[MAX_ENTRIES];
    for (int c = 0; c < fp->ncols; c++) {
        int n = column_entries(fp, sv, fc->g, c, e), at = fp->Ap[c];
        double big = 0.0;
        for (int k = 0; k < n; k++)  /* (fmax is a library call at -O2) */
            big = fabs(e[k].val) > big ? fabs(e[k].val) : big;
        fc->cscale[c] = big > 0.0 ? 1.0 / big : 1.0;
        for (int k = 0; k < n; k++)
            fc->Ax[fp->slot[at + k]] = e[k].val * fc->cscale[c];
    }
    if (linsys_factor(&fc->ls, fc->Ax) < 0) {
        fc->rcond = 0.0;
        return -1;
    }
    /* The force matrix is the transpose of the joints' constraint Jacobian
       (link coordinates): singular exactly where the loop equations are
       (their condition is checked at every step against min_rcond, far
       above 1e-13) or, with redundant constraints, everywhere. So the full
       estimate runs at the first step, and later only when the pivots hint
       at a singular matrix (as klu_rcond does for KLU). */
    if (!fc->condition_known || linsys_pivot_ratio(&fc->ls) < 1e-10) {
        linsys_condition(&fc->ls, fc->Ax, &fc->rcond, NULL);
        fc->condition_known = 1;
    }
    return fc->rcond < 1e-13 ? -1 : 0;
}

static void solve_rhs(forces *fc, const double *rhs, double *y)
{
    const forces_plan *fp = fc->p;
    memcpy(y, rhs, (size_t)fp->nrows * sizeof *y);
    linsys_solve(&fc->ls, y);
    for (int c = 0; c < fp->ncols; c++)
        y[c] *= fc->cscale[c];
}

/* The drivers' power for the reactions y: the sum over the drivers of each
 * load times the rate of its coordinate (for the sweep's own, q's speed). */
static double drive_power(const forces *fc, const solver *sv, const double *y)
{
    const forces_plan *fp = fc->p;
    const mech_model *m = fp->m;
    int first = fp->ncols - fp->ndrive;
    double p = 0.0;
    for (int k = 0; k < fp->ndrive; k++) {
        const mech_motion *mo = &m->drivers[k];
        int var = mo->kind == MECH_DRIVE_SLIDER ? sv->p->tree.slide_var[mo->index] : -1;
        double rate = mo->kind == MECH_DRIVE_ANGLE ? sv->ks.om[mo->index]
                      : var >= 0 ? sv->vel[var] : 0.0;
        p += y[first + k] * rate;
    }
    return p;
}

/* P_driver + P_loads + P_gravity - P_friction - dT/dt, relative to the
 * largest of those terms. */
static double power_residual(const forces *fc, const solver *sv, double pd, double pfric)
{
    const forces_plan *fp = fc->p;
    const mech_model *m = fp->m;
    double kin = 0.0, ext = 0.0, scale = fabs(pd) + fabs(pfric);
    for (int l = 1; l < m->nlinks; l++) {
        const mech_link *k = &m->links[l];
        if (!k->has_mass)
            continue;
        const double *vg = fc->vg + 2 * l, *ag = fc->ag + 2 * l;
        double dk = k->mass * (vg[0] * ag[0] + vg[1] * ag[1]) + k->inertia * sv->ks.om[l] * sv->ks.al[l];
        double pg = k->mass * (m->gravity[0] * vg[0] + m->gravity[1] * vg[1]);
        kin += dk;
        ext += pg;
        scale += fabs(k->mass * vg[0] * ag[0]) + fabs(k->mass * vg[1] * ag[1]) +
                 fabs(k->inertia * sv->ks.om[l] * sv->ks.al[l]) + fabs(pg);
    }
    for (int i = 0; i < m->nloads; i++) {
        const mech_load *ld = &m->loads[i];
        double pw;
        if (ld->kind == MECH_LOAD_TORQUE) {
            pw = ld->torque * sv->ks.om[ld->link];
        } else {
            double f[2], p[2], v[2];
            load_resultant(sv, ld, f, p, v);
            pw = f[0] * v[0] + f[1] * v[1];
        }
        ext += pw;
        scale += fabs(pw);
    }
    ext += springs_power(m, sv, &scale);
    ext += state_loads_power(m->state_loads, sv, fc->sl_reg, &scale);
    double r = pd + ext - pfric - kin;
    return scale > 0.0 ? r / scale : 0.0;
}

/* gamma minimising |r - sum_k gamma_k dr_k| over the `depth` newest
 * differences (normal equations, Gaussian elimination with pivoting);
 * returns how many weights are used (0: a plain step, when the
 * differences are nearly dependent). */
static int anderson_weights(const double *dr, int n, int depth, int newest, const double *r,
                            double *gamma)
{
    double a[ANDERSON_DEPTH][ANDERSON_DEPTH + 1];
    for (int k = 0; k < depth; k++) {
        const double *dk = dr + ((newest - k + ANDERSON_DEPTH) % ANDERSON_DEPTH) * n;
        for (int l = 0; l <= k; l++) {
            const double *dl = dr + ((newest - l + ANDERSON_DEPTH) % ANDERSON_DEPTH) * n;
            double s = 0.0;
            for (int i = 0; i < n; i++)
                s += dk[i] * dl[i];
            a[k][l] = a[l][k] = s;
        }
        double s = 0.0;
        for (int i = 0; i < n; i++)
            s += dk[i] * r[i];
        a[k][depth] = s;
    }
    double scale = 0.0;
    for (int k = 0; k < depth; k++)
        scale = a[k][k] > scale ? a[k][k] : scale;
    for (int k = 0; k < depth; k++) {
        int p = k;
        for (int i = k + 1; i < depth; i++)
            if (fabs(a[i][k]) > fabs(a[p][k]))
                p = i;
        if (!(fabs(a[p][k]) > 1e-12 * scale))
            return 0;
        for (int j = 0; j <= depth; j++) {
            double t = a[k][j];
            a[k][j] = a[p][j], a[p][j] = t;
        }
        for (int i = k + 1; i < depth; i++) {
            double l = a[i][k] / a[k][k];
            for (int j = k; j <= depth; j++)
                a[i][j] -= l * a[k][j];
        }
    }
    for (int k = depth - 1; k >= 0; k--) {
        double s = a[k][depth];
        for (int j = k + 1; j < depth; j++)
            s -= a[k][j] * gamma[j];
        gamma[k] = s / a[k][k];
    }
    return depth;
}

/* The reactions with friction: y = G(y) = A^-1 (b + friction loads of y),
 * from the frictionless y, by Anderson acceleration of the fixed point
 * (Walker and Ni, SIAM J. Numer. Anal. 49, 2011): the next iterate combines
 * the last ANDERSON_DEPTH images G(y) with the weights that minimise the
 * combined residual G(y) - y in least squares. Each iteration costs one
 * solve, like the plain iteration, but the conveyor needs 4-5 instead of
 * 6-9. A step whose residual grows restarts the history (plain iteration).
 * Converged when |G(y) - y| <= 1e-12 |G(y)|; y = G(y) then. */
static void friction_fixed_point(forces *fc, const solver *sv)
{
    const forces_plan *fp = fc->p;
    int n = fp->nrows, depth = 0, newest = 0;
    double *g = fc->ynext, *r = fc->aa_r, *dg = fc->aa_dg, *dr = fc->aa_dr;
    double prev_res = INFINITY;
    for (int it = 1;; it++) {
        friction_loads(fc, sv, fc->y);
        for (int i = 0; i < n; i++)
            fc->fric[i] += fc->b[i];
        gear_separation(fc, sv, fc->y, fc->fric);
        solve_rhs(fc, fc->fric, g);
        double res = 0.0, big = 0.0;
        for (int i = 0; i < n; i++) {
            double ri = g[i] - fc->y[i];
            res = fabs(ri) > res ? fabs(ri) : res;
            big = fabs(g[i]) > big ? fabs(g[i]) : big;
        }
        fc->iterations = it;
        if (res <= FRICTION_TOL * big || !isfinite(res)) {
            memcpy(fc->y, g, (size_t)n * sizeof *fc->y);
            fc->friction_power = friction_loads(fc, sv, fc->y);
            if (!isfinite(res))
                fc->iterations = -1;
            return;
        }
        if (it == FRICTION_MAX_ITER) {
            fc->iterations = -1;
            return;
        }
        if (!(res < prev_res))
            depth = 0;  /* not contracting: restart the history (a plain step) */
        prev_res = res;
        /* differences to the previous image and residual (slot newest) */
        if (it > 1) {
            newest = (newest + 1) % ANDERSON_DEPTH;
            for (int i = 0; i < n; i++) {
                double ri = g[i] - fc->y[i];
                dg[newest * n + i] = g[i] - fc->aa_g[i];
                dr[newest * n + i] = ri - r[i];
            }
            depth = depth < ANDERSON_DEPTH ? depth + 1 : ANDERSON_DEPTH;
        }
        for (int i = 0; i < n; i++) {
            r[i] = g[i] - fc->y[i];
            fc->aa_g[i] = g[i];
        }
        double gamma[ANDERSON_DEPTH];
        int used = anderson_weights(dr, n, depth, newest, r, gamma);
        memcpy(fc->y, g, (size_t)n * sizeof *fc->y);
        for (int k = 0; k < used; k++) {
            const double *dgk = dg + ((newest - k + ANDERSON_DEPTH) % ANDERSON_DEPTH) * n;
            for (int i = 0; i < n; i++)
                fc->y[i] -= gamma[k] * dgk[i];
        }
    }
}

int forces_solve(forces *fc, const solver *sv)
{
    const forces_plan *fp = fc->p;
    int n = fp->nrows;
    update_centres(fc, sv);
    state_loads_eval(fp->m->state_loads, sv, fc->sl_reg);
    known_loads(fc, sv, fc->b);
    if (factor(fc, sv) < 0)
        return -1;
    /* the frictionless reactions: the answer without friction, asked for
       beside it, or the friction iteration's start at the first step; later
       steps start from the last step's reactions (one solve fewer, and
       closer) */
    fc->residual0 = 0.0;
    if (!fp->friction || fp->want_frictionless || !fc->have_previous) {
        solve_rhs(fc, fc->b, fc->y0);
        if (fp->m->ngears) {  /* the teeth's separating forces, from their tangential ones */
            memcpy(fc->fric, fc->b, (size_t)n * sizeof *fc->fric);
            gear_separation(fc, sv, fc->y0, fc->fric);
            solve_rhs(fc, fc->fric, fc->y0);
        }
        fc->residual0 = power_residual(fc, sv, drive_power(fc, sv, fc->y0), 0.0);
        memcpy(fc->y, fc->y0, (size_t)n * sizeof *fc->y);
    }
    fc->have_previous = 1;
    fc->iterations = 0;
    fc->friction_power = 0.0;
    if (fp->friction)
        friction_fixed_point(fc, sv);
    fc->drive_power = drive_power(fc, sv, fc->y);
    fc->residual = power_residual(fc, sv, fc->drive_power, fc->friction_power);
    return fc->iterations < 0 ? -2 : 0;
}

/* Where column c is marked in forces_singular_joints: its joint, its driver
 * k (njoints + k), or its gear pair (njoints + ndrivers + the pair). */
static int singular_slot(const forces_plan *fp, int c)
{
    if (fp->kind[c] == FC_GEAR)
        return fp->m->njoints + fp->m->ndrivers + fp->joint[c];
    return fp->joint[c] >= 0 ? fp->joint[c] : fp->m->njoints - 1 - fp->joint[c];
}

/* Slot j of forces_singular_joints in words: the joint's name, "the driver"
 * (the only one) or "driver crank", "gear pair g12". */
static const char *slot_name(const mech_model *m, int j, char *buf, size_t size)
{
    int first_gear = m->njoints + m->ndrivers;
    if (j < m->njoints)
        return m->joints[j].name;
    if (j < first_gear && m->ndrivers == 1)
        return "the driver";
    if (j < first_gear)
        snprintf(buf, size, "driver %s", drivers_name(m, j - m->njoints));
    else
        snprintf(buf, size, "gear pair %s", m->gears[j - first_gear].name);
    return buf;
}

/* The joints whose reactions are not determined at a singular position:
 * large components of A^-1 b (inverse iteration) lie along the null space;
 * when the factorisation itself failed, KLU's first singular column. */
void forces_singular_joints(forces *fc, char *buf, size_t size)
{
    const forces_plan *fp = fc->p;
    const mech_model *m = fp->m;
    size_t at = 0;
    buf[0] = '\0';
    int ncols = fp->ncols, count = 0, nslots = m->njoints + m->ndrivers + m->ngears;
    char name[160];
    unsigned char *mark = xcalloc((size_t)nslots + 1, 1);
    if (!mark)
        return;
    if (fc->ls.factored) {
        for (int r = 0; r < fp->nrows; r++)
            fc->ynext[r] = 1.0 + 0.1 * r;  /* a generic right-hand side */
        solve_rhs(fc, fc->ynext, fc->ynext);
        double big = vec_norm_inf(fc->ynext, ncols);
        for (int c = 0; c < ncols; c++)
            if (isfinite(big) && fabs(fc->ynext[c]) > 0.1 * big)
                mark[singular_slot(fp, c)] = 1;
    } else if (linsys_singular_col(&fc->ls) >= 0) {
        mark[singular_slot(fp, linsys_singular_col(&fc->ls))] = 1;
    }
    for (int j = 0; j < nslots && at < size; j++)
        if (mark[j])
            at += (size_t)snprintf(buf + at, size - at, "%s%s", count++ ? ", " : "",
                                   slot_name(m, j, name, sizeof name));
    free(mark);
}

void forces_joint(const forces *fc, const solver *sv, int j, int with_friction, double *fx,
                  double *fy, double *n, double *mo)
{
    const forces_plan *fp = fc->p;
    const double *y = with_friction ? fc->y : fc->y0;
    const mech_joint *jt = &fp->m->joints[j];
    int c = fp->jcol[j];
    *n = *mo = 0.0;
    if (jt->kind == MECH_JOINT_REVOLUTE) {
        *fx = y[c];
        *fy = y[c + 1];
        return;
    }
    double u[2];
    guide_dir(sv, jt, u);
    *n = y[c];
    *fx = -u[1] * y[c];
    *fy = u[0] * y[c];
    if (jt->locked)
        *mo = y[c + 1];
}

double forces_gear(const forces *fc, int i, int with_friction)
{
    const forces_plan *fp = fc->p;
    return (with_friction ? fc->y : fc->y0)[fp->gcol + i] / cos(fp->m->gears[i].pressure_angle);
}

double forces_drive_of(const forces *fc, int with_friction, int k)
{
    const forces_plan *fp = fc->p;
    return (with_friction ? fc->y : fc->y0)[fp->ncols - fp->ndrive + k];
}
