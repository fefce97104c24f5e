/* src/forces/forces.c: joint reactions and the driver torque by Newton-Euler with
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
 *   P_driver + P_loads + P_gravity - P_friction = d/dt (kinetic energy).
 *
 * The plan describes the system once as data (forces_numbers: a column
 * per reaction, the links' masses, the loads, gears, friction and
 * drivers); the formulas that read it are src/runtime/rt_forces.h's, which the
 * generated code (`mech codegen`) carries and reads the same tables with. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"
#include "forces.h"
#include "equations.h"

enum { MAX_ENTRIES = 6 };  /* of a column: a force on two links */

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

static rt_point point_of(const mech_model *m, int l, int i)
{
    return (rt_point){l, {m->links[l].points[i].x, m->links[l].points[i].y}};
}

/* ---- the description: what enters each row and column ---------------- */

/* Column c: the reaction of its joint (Fx, Fy at the pin; N across, M or
 * the driver's force along a slider's guide: on the receiving link, its
 * opposite on the other), a gear pair's tooth force, or a turning driver's
 * torque on the driven link. */
static rt_fcol describe_column(const forces_plan *fp, int c)
{
    const mech_model *m = fp->m;
    rt_fcol d = {RT_COL_FORCE, {0, 0}, {0, {0.0, 0.0}}, RT_DIR_X, 0, 0.0, 0};
    if (fp->kind[c] == FC_CAM) {  /* pushes the follower off the cam */
        const mech_cam *cm = &m->cams->cam[fp->joint[c]];
        d.kind = RT_COL_CAM;
        d.gear = fp->joint[c];
        d.on[0] = cm->follower, d.on[1] = cm->cam;
        return d;
    }
    if (fp->kind[c] == FC_GEAR) {  /* on link[1], its opposite on link[0] */
        const mech_gear *gr = &m->gears[fp->joint[c]];
        d.kind = RT_COL_GEAR;
        d.gear = fp->joint[c];
        d.on[0] = gr->link[1], d.on[1] = gr->link[0];
        return d;
    }
    /* driver k's column: joint -1 - k */
    const mech_motion *dr = fp->joint[c] < 0 ? &m->drivers[-1 - fp->joint[c]] : NULL;
    mech_drive_kind dkind = dr ? dr->kind : MECH_DRIVE_SLIDER;
    int dindex = dr ? dr->index : -1;
    if (fp->joint[c] < 0 && dkind == MECH_DRIVE_ANGLE) {
        d.kind = RT_COL_MOMENT;
        d.on[0] = dindex;
        return d;
    }
    const mech_joint *jt = &m->joints[fp->joint[c] >= 0 ? fp->joint[c] : dindex];
    joint_links(jt, &d.on[0], &d.on[1]);
    if (fp->kind[c] == FC_MOMENT) {
        d.kind = RT_COL_MOMENT;
        return d;
    }
    d.at = point_of(m, jt->link[0], jt->point[0]);  /* the pin, or the sliding point */
    d.dir = fp->kind[c] == FC_FX ? RT_DIR_X : fp->kind[c] == FC_FY ? RT_DIR_Y
            : fp->kind[c] == FC_NORMAL ? RT_DIR_NORMAL : RT_DIR_ALONG;
    d.guide = jt->link[1];
    d.angle = jt->angle;
    return d;
}

/* The constant loads, then those that depend on the motion (their
 * registers in the model's program). */
static void describe_loads(const mech_model *m, rt_load *out)
{
    int n = 0;
    for (int i = 0; i < m->nloads; i++) {
        const mech_load *ld = &m->loads[i];
        rt_load d = {RT_LOAD_TORQUE, {ld->link, {0.0, 0.0}}, {ld->link, {0.0, 0.0}},
                     {ld->torque, 0.0}, {0, 0}};
        if (ld->kind == MECH_LOAD_FORCE) {
            d.kind = RT_LOAD_FORCE;
            d.at = point_of(m, ld->link, ld->point[0]);
            d.v[0] = ld->force[0], d.v[1] = ld->force[1];
        } else if (ld->kind == MECH_LOAD_DISTRIBUTED) {
            d.kind = RT_LOAD_SPREAD;
            d.at = point_of(m, ld->link, ld->point[0]);
            d.to = point_of(m, ld->link, ld->point[1]);
            d.v[0] = ld->intensity, d.v[1] = ld->direction;
        }
        out[n++] = d;
    }
    for (int i = 0; m->state_loads && i < m->state_loads->nloads; i++) {
        const sl_load *l = &m->state_loads->loads[i];
        rt_load d = {RT_LOAD_SL_FORCE, {l->link, {0.0, 0.0}}, {l->link, {0.0, 0.0}},
                     {0.0, 0.0}, {l->reg[0], l->reg[1]}};
        if (l->torque == 1) {
            d.kind = RT_LOAD_SL_TORQUE;
        } else if (l->torque == 2) {
            d.kind = RT_LOAD_SL_LINE;
            d.at = point_of(m, l->link, l->point);
            d.to = point_of(m, l->link2, l->point2);
        } else {
            d.at = point_of(m, l->link, l->point);
        }
        out[n++] = d;
    }
}

/* The joints with a friction coefficient. */
static int describe_friction(const forces_plan *fp, const kin_tree *tree, rt_friction *out)
{
    const mech_model *m = fp->m;
    int n = 0;
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (!(jt->friction > 0.0))
            continue;
        rt_friction d = {jt->kind == MECH_JOINT_SLIDER, 0, 0, fp->jcol[j], jt->friction,
                         jt->pin_radius, {0, {0.0, 0.0}}, jt->link[1], jt->angle, -1};
        joint_links(jt, &d.a, &d.b);
        if (d.slider) {
            d.at = point_of(m, jt->link[0], jt->point[0]);
            d.var = tree->slide_var[j];
        }
        out[n++] = d;
    }
    return n;
}

int forces_numbers(forces_numbers_t *fn, const forces_plan *fp, const mech_model *m,
                   const kin_tree *tree, double lref)
{
    memset(fn, 0, sizeof *fn);
    int nsl = m->state_loads ? m->state_loads->nloads : 0;
    fn->cols = xcalloc((size_t)fp->ncols + 1, sizeof *fn->cols);
    fn->body = xcalloc((size_t)m->nlinks + 1, sizeof *fn->body);
    fn->gears = xcalloc((size_t)m->ngears + 1, sizeof *fn->gears);
    fn->loads = xcalloc((size_t)(m->nloads + nsl) + 1, sizeof *fn->loads);
    fn->springs = xcalloc((size_t)m->nsprings + 1, sizeof *fn->springs);
    fn->fric = xcalloc((size_t)m->njoints + 1, sizeof *fn->fric);
    fn->drive = xcalloc((size_t)fp->ndrive + 1, sizeof *fn->drive);
    if (!fn->cols || !fn->body || !fn->gears || !fn->loads || !fn->springs || !fn->fric ||
        !fn->drive) {
        forces_numbers_free(fn);
        return -1;
    }
    forces_plan view = *fp;
    view.m = m;
    for (int c = 0; c < fp->ncols; c++)
        fn->cols[c] = describe_column(&view, c);
    for (int l = 0; l < m->nlinks; l++) {
        const mech_link *k = &m->links[l];
        fn->body[l] = (rt_body){k->has_mass, k->mass, k->inertia, {k->center[0], k->center[1]}};
    }
    for (int i = 0; i < m->ngears; i++)
        gears_rt(m, i, &fn->gears[i]);
    fn->nconst = m->nloads;
    fn->nloads = m->nloads + nsl;
    describe_loads(m, fn->loads);
    fn->nsprings = m->nsprings;
    for (int i = 0; i < m->nsprings; i++)
        springs_rt(m, i, &fn->springs[i]);
    fn->nfric = describe_friction(&view, tree, fn->fric);
    for (int k = 0; k < fp->ndrive && drivers_rows(m) > 0; k++) {
        const mech_motion *mo = &m->drivers[k];
        fn->drive[k] = mo->kind == MECH_DRIVE_ANGLE
                           ? (rt_drive){mo->index, -1} : (rt_drive){0, tree->slide_var[mo->index]};
    }
    fn->grav[0] = m->gravity[0], fn->grav[1] = m->gravity[1];
    fn->lref = lref;
    double qd = fabs(m->driver.speed);
    if (m->driver.kind == MECH_DRIVE_SLIDER)
        qd /= lref;
    fn->speed_eps = 1e-6 * (qd > 0.0 ? qd : 1.0);
    rt_power_scales(m->driver.kind == MECH_DRIVE_ANGLE, m->driver.speed, lref, &fn->linear,
                    &fn->turning);
    return 0;
}

void forces_numbers_free(forces_numbers_t *fn)
{
    void *blocks[] = {fn->cols, fn->body, fn->gears, fn->loads, fn->springs, fn->fric, fn->drive};
    free_all(blocks, COUNT_OF(blocks));
    memset(fn, 0, sizeof *fn);
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
    fp->ccol = fp->ncols;
    for (int i = 0; i < model_ncams(m); i++) {
        add_column(fp, FC_CAM, i);
        if (m->cams->cam[i].friction > 0.0)
            fp->has_friction = 1;
    }
    fp->ndrive = m->ndrivers;
    for (int k = 0; k < fp->ndrive; k++)
        add_column(fp, FC_DRIVE, -1 - k);
}

static int build_pattern(forces_plan *fp)
{
    int rows[MAX_ENTRIES], cap = 0;
    for (int c = 0; c < fp->ncols; c++)
        cap += rt_fcol_rows(&fp->num.cols[c], rows);
    fp->Ai = xcalloc((size_t)cap + 1, sizeof *fp->Ai);
    fp->slot = xcalloc((size_t)cap + 1, sizeof *fp->slot);
    if (!fp->Ai || !fp->slot)
        return -1;
    int at = 0;
    for (int c = 0; c < fp->ncols; c++) {
        fp->Ap[c] = at;
        int n = rt_fcol_rows(&fp->num.cols[c], rows);
        for (int k = 0; k < n; k++) {  /* rows are distinct: rank = place in row order */
            int rank = 0;
            for (int i = 0; i < n; i++)
                rank += rows[i] < rows[k];
            fp->Ai[at + rank] = rows[k];
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
    return diag_nomem(d, m->file, (mech_mark){0, 0});
}

int forces_plan_init(forces_plan *fp, const solver_plan *sp, int friction, mech_diag *d)
{
    const mech_model *m = sp->m;
    memset(fp, 0, sizeof *fp);
    fp->m = m;
    fp->nrows = 3 * (m->nlinks - 1);
    size_t nc = 2 * (size_t)m->njoints + (size_t)m->ngears + (size_t)model_ncams(m) + 1 +
                (size_t)m->ndrivers;
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
    if (forces_plan_numbers(fp, sp) < 0 || build_pattern(fp) < 0)
        return no_memory(m, d);
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

int forces_plan_numbers(forces_plan *fp, const solver_plan *sp)
{
    fp->m = sp->m;
    forces_numbers_free(&fp->num);
    return forces_numbers(&fp->num, fp, sp->m, &sp->tree, sp->lref);
}

void forces_plan_free(forces_plan *fp)
{
    linsys_plan_free(&fp->lp);
    forces_numbers_free(&fp->num);
    void *blocks[] = {fp->kind, fp->joint, fp->jcol, fp->Ap, fp->Ai, fp->slot};
    free_all(blocks, COUNT_OF(blocks));
    memset(fp, 0, sizeof *fp);
}

int forces_init(forces *fc, const forces_plan *fp)
{
    memset(fc, 0, sizeof *fc);
    fc->p = fp;
    size_t nr = (size_t)fp->nrows + 1, nc = (size_t)fp->ncols + 1;
    size_t nl2 = 2 * (size_t)fp->m->nlinks, depth = RT_ANDERSON_DEPTH;
    double **arrays[] = {&fc->Ax, &fc->cscale, &fc->b, &fc->y, &fc->y0, &fc->ynext,
                         &fc->aa_g, &fc->aa_r, &fc->aa_dg, &fc->aa_dr, &fc->fric,
                         &fc->g, &fc->vg, &fc->ag, &fc->spr, &fc->cam};
    size_t sizes[] = {(size_t)fp->nnz + 1, nc, nr + nc, nr + nc, nr + nc, nr + nc,
                      nr, nr, depth * nr, depth * nr, nr, nl2, nl2, nl2,
                      RT_SPRING_STATE * (size_t)fp->num.nsprings + 1,
                      4 * (size_t)model_ncams(fp->m) + 1};
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
                      fc->g, fc->vg, fc->ag, fc->aa_g, fc->aa_r, fc->aa_dg, fc->aa_dr, fc->spr,
                      fc->cam};
    free_all(blocks, COUNT_OF(blocks));
    free(fc->sl_reg);
    memset(fc, 0, sizeof *fc);
}

/* ---- one position ------------------------------------------------------ */

/* Inertia, gravity, the loads (constant, springs, those that depend on the
 * motion), in that order. */
static void known_loads(const forces *fc, const solver *sv, double *rhs)
{
    const forces_numbers_t *fn = &fc->p->num;
    const rt_frame *F = sv->ks.F;
    int nl = fc->p->m->nlinks;
    for (int l = 1; l < nl; l++)
        rt_body_load(&fn->body[l], &F[l], fc->ag + 2 * l, fn->grav, rhs + 3 * (l - 1));
    for (int i = 0; i < fn->nconst; i++)
        rt_load_apply(&fn->loads[i], F, fc->g, fc->sl_reg, rhs);
    for (int i = 0; i < fn->nsprings; i++)
        rt_spring_load(&fn->springs[i], fc->spr + RT_SPRING_STATE * i, fc->g, rhs);
    for (int i = fn->nconst; i < fn->nloads; i++)
        rt_load_apply(&fn->loads[i], F, fc->g, fc->sl_reg, rhs);
}

/* Each cam's contact at this position (docs/cams.md 6): the profile's
 * point and outward normal where the follower touches it (cam_geometry at
 * the cam's angle on its arm), turned into the ground frame by the cam's. */
static void cam_contacts(forces *fc, const solver *sv)
{
    const mech_model *m = fc->p->m;
    const rt_frame *F = sv->ks.F;
    for (int i = 0; i < model_ncams(m); i++) {
        const mech_cam *cm = &m->cams->cam[i];
        double x = cm->sense * (F[cm->cam].th - F[cm->arm].th - cm->start);
        cam_point g;
        cam_geometry(m, cm, x, &g);
        rt_point at = {cm->cam, {g.profile[0], g.profile[1]}};
        double c = cos(F[cm->cam].th), s = sin(F[cm->cam].th), *k = fc->cam + 4 * i;
        rt_point_motion(F, &at, k, NULL, NULL);
        k[2] = c * g.normal[0] - s * g.normal[1];
        k[3] = s * g.normal[0] + c * g.normal[1];
    }
}

/* Assemble the force matrix at the position (each column scaled to unit
 * largest entry) and factor it; -1 when singular. */
static int factor(forces *fc, const solver *sv)
{
    const forces_plan *fp = fc->p;
    double e[MAX_ENTRIES];
    cam_contacts(fc, sv);
    for (int c = 0; c < fp->ncols; c++) {
        int n = rt_fcol_entries(&fp->num.cols[c], fp->num.gears, fc->cam, sv->ks.F, fc->g, e);
        fc->cscale[c] = rt_scale_into(e, n, fc->Ax, fp->slot + fp->Ap[c]);
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

/* The rest of the solve (rt_forces_solve) on this state. */
typedef struct solve_ctx {
    forces *fc;
    const solver *sv;
} solve_ctx;

static void solve_rhs(forces *fc, const double *rhs, double *y)
{
    const forces_plan *fp = fc->p;
    memcpy(y, rhs, (size_t)fp->nrows * sizeof *y);
    linsys_solve(&fc->ls, y);
    for (int c = 0; c < fp->ncols; c++)
        y[c] *= fc->cscale[c];
}

static void ctx_solve(void *c, const double *rhs, double *y)
{
    solve_rhs(((solve_ctx *)c)->fc, rhs, y);
}

/* The velocity at the ground point p of the material of frame Fl. */
static void material_velocity(const rt_frame *Fl, const double p[2], double v[2])
{
    v[0] = Fl->vo[0] - Fl->om * (p[1] - Fl->o[1]);
    v[1] = Fl->vo[1] + Fl->om * (p[0] - Fl->o[0]);
}

/* Coulomb friction at each cam's contact (docs/cams.md 6): mu |F| along
 * the common tangent, against the follower's sliding on the cam there, on
 * the follower and its opposite on the cam; returns the power it takes. */
static double cam_friction(const forces *fc, const rt_frame *F, const double *y, double eps,
                           double *fric)
{
    const mech_model *m = fc->p->m;
    double power = 0.0;
    for (int i = 0; i < model_ncams(m); i++) {
        const mech_cam *cm = &m->cams->cam[i];
        if (!(cm->friction > 0.0))
            continue;
        const double *k = fc->cam + 4 * i;
        double p[2] = {k[0], k[1]}, t[2] = {-k[3], k[2]}, vf[2], vc[2];
        material_velocity(&F[cm->follower], p, vf);
        material_velocity(&F[cm->cam], p, vc);
        double slide = (vf[0] - vc[0]) * t[0] + (vf[1] - vc[1]) * t[1];
        double ff = cm->friction * fabs(y[fc->p->ccol + i]) * rt_smooth_sign(slide, eps);
        double on_f[2] = {-ff * t[0], -ff * t[1]}, on_c[2] = {ff * t[0], ff * t[1]};
        rt_load_force(fric, fc->g, cm->follower, p, on_f);
        rt_load_force(fric, fc->g, cm->cam, p, on_c);
        power += ff * slide;
    }
    return power;
}

static double ctx_friction(void *c, const double *y, double *fric)
{
    const solve_ctx *x = c;
    const forces_numbers_t *fn = &x->fc->p->num;
    double power = 0.0;
    memset(fric, 0, (size_t)x->fc->p->nrows * sizeof *fric);
    for (int k = 0; k < fn->nfric; k++)
        power += rt_friction_load(&fn->fric[k], x->sv->ks.F, x->fc->g, x->sv->vel, y,
                                  fn->speed_eps, fn->lref, fric);
    return power + cam_friction(x->fc, x->sv->ks.F, y, fn->speed_eps * fn->lref, fric);
}

static void ctx_separation(void *c, const double *y, double *rhs)
{
    const solve_ctx *x = c;
    const forces_plan *fp = x->fc->p;
    for (int i = 0; i < fp->m->ngears; i++)
        rt_gear_separation(&fp->num.gears[i], x->sv->ks.F, x->fc->g, y[fp->gcol + i], rhs);
}

static double ctx_drive_power(void *c, const double *y)
{
    const solve_ctx *x = c;
    const forces_plan *fp = x->fc->p;
    return rt_drive_power(fp->num.drive, fp->ndrive, drivers_rows(fp->m) > 0, x->sv->ks.F,
                          x->sv->vel, fp->m->driver.speed, y + fp->ncols - fp->ndrive);
}

static double ctx_power(void *c, double pd, double pfric)
{
    const solve_ctx *x = c;
    const forces *fc = x->fc;
    const forces_numbers_t *fn = &fc->p->num;
    const rt_frame *F = x->sv->ks.F;
    rt_power pw;
    rt_power_start(&pw, pd, pfric, fn->linear, fn->turning);
    for (int l = 1; l < fc->p->m->nlinks; l++)
        if (fn->body[l].has_mass)
            rt_power_body(&pw, &fn->body[l], &F[l], fc->vg + 2 * l, fc->ag + 2 * l, fn->grav);
    for (int i = 0; i < fn->nconst; i++)
        rt_power_load(&pw, &fn->loads[i], F, fc->sl_reg);
    for (int i = 0; i < fn->nsprings; i++)
        rt_power_spring(&pw, &fn->springs[i], fc->spr + RT_SPRING_STATE * i);
    for (int i = fn->nconst; i < fn->nloads; i++)
        rt_power_load(&pw, &fn->loads[i], F, fc->sl_reg);
    /* a cam's contact force, like a load, scales by its size times the speed:
       on a dwell every power vanishes while the driver's torque carries the
       rounding of forces of that size (the frictionless solve's, y0) */
    for (int i = 0; i < model_ncams(fc->p->m); i++)
        pw.scale += fabs(fc->y0[fc->p->ccol + i]) * fn->linear;
    return rt_power_end(&pw, pd, pfric);
}

static const rt_forces_ops solve_ops = {ctx_solve, ctx_friction, ctx_separation,
                                        ctx_drive_power, ctx_power};

int forces_solve(forces *fc, const solver *sv)
{
    const forces_plan *fp = fc->p;
    const forces_numbers_t *fn = &fp->num;
    for (int l = 0; l < fp->m->nlinks; l++)
        rt_centre(&fn->body[l], &sv->ks.F[l], fc->g + 2 * l, fc->vg + 2 * l, fc->ag + 2 * l);
    for (int i = 0; i < fn->nsprings; i++)  /* once: the loads and the power read them */
        rt_spring_eval(&fn->springs[i], sv->ks.F, fc->spr + RT_SPRING_STATE * i);
    state_loads_eval(fp->m->state_loads, sv, fc->sl_reg);
    known_loads(fc, sv, fc->b);
    if (factor(fc, sv) < 0)
        return -1;
    rt_forces_vec v = {fc->b, fc->y, fc->y0, fc->fric, fc->ynext, fc->aa_r, fc->aa_g,
                       fc->aa_dg, fc->aa_dr};
    solve_ctx ctx = {fc, sv};
    return rt_forces_solve(&solve_ops, &ctx, fp->nrows, fp->friction, fp->want_frictionless,
                           fp->m->ngears > 0, &v, &fc->out);
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
    *n = y[c];
    rt_slider_reaction(&sv->ks.F[jt->link[1]], jt->angle, y[c], fx, fy);
    if (jt->locked)
        *mo = y[c + 1];
}

double forces_gear(const forces *fc, int i, int with_friction)
{
    const forces_plan *fp = fc->p;
    return rt_tooth_force(&fp->num.gears[i], (with_friction ? fc->y : fc->y0)[fp->gcol + i]);
}

double forces_cam(const forces *fc, int i, int with_friction)
{
    return (with_friction ? fc->y : fc->y0)[fc->p->ccol + i];
}

double forces_drive_of(const forces *fc, int with_friction, int k)
{
    const forces_plan *fp = fc->p;
    return (with_friction ? fc->y : fc->y0)[fp->ncols - fp->ndrive + k];
}
