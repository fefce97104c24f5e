/* src/runtime/rt_forces.h: the kinetostatics (docs/forces.md): what enters each
 * row and column of the force system, the known loads, the friction loads,
 * the power balance and the solve with the friction iteration. Part of the
 * runtime that libmech (forces.c) and the C that `mech codegen` writes
 * share (docs/codegen.md): self-contained, the C library only.
 *
 * The system is described once, as data (forces_plan in forces.c builds
 * the tables): a column per reaction (rt_fcol), the links' masses
 * (rt_body), the loads (rt_load: constant, springs, loads that depend on
 * the motion), the gear pairs (rt_gear), the joints with friction
 * (rt_friction) and the drivers (rt_drive). libmech loops over the tables;
 * the generated code holds them as constants and calls the same functions
 * for each entry in turn.
 *
 * Rows: three per moving link l >= 1, forces in x and y and the moment
 * about its centre of mass g[2 l], g[2 l + 1]: rows 3 (l - 1) .. +2. Link 0
 * is the ground: nothing on it enters the system. */
#ifndef MECH_RT_FORCES_H
#define MECH_RT_FORCES_H

#include <math.h>
#include <string.h>

#include "rt_base.h"
#include "rt_frame.h"

/* A point of a link, in the link's frame. */
typedef struct rt_point {
    int link;
    double r[2];
} rt_point;

static inline void rt_point_motion(const rt_frame *F, const rt_point *pt, double *p, double *v,
                                   double *a)
{
    rt_on_link(&F[pt->link], pt->r[0], pt->r[1], p, v, a);
}

/* ---- loads moved to the right-hand side ------------------------------- */

/* A known force f at p on link l: -f on its rows, and its moment about the
 * centre, r x f, and with t (not NULL) a moment *t too, r x f + *t (its own
 * rounding: springs and the loads that depend on the motion). */
RT_INLINE void rt_load_rows(double *rhs, const double *g, int l, const double *p, const double *f,
                            const double *t)
{
    if (l == 0)
        return;
    double r[2] = {p[0] - g[2 * l], p[1] - g[2 * l + 1]};
    double *row = rhs + 3 * (l - 1);
    row[0] -= f[0];
    row[1] -= f[1];
    row[2] -= t ? r[0] * f[1] - r[1] * f[0] + *t : r[0] * f[1] - r[1] * f[0];
}

RT_INLINE void rt_load_force(double *rhs, const double *g, int l, const double *p, const double *f)
{
    rt_load_rows(rhs, g, l, p, f, NULL);
}

RT_INLINE void rt_add_load(double *rhs, const double *g, int l, const double *p, const double *f,
                           double t)
{
    rt_load_rows(rhs, g, l, p, f, &t);
}

RT_INLINE void rt_load_moment(double *rhs, int l, double t)
{
    if (l != 0)
        rhs[3 * (l - 1) + 2] -= t;
}

/* ---- the links' masses ------------------------------------------------ */

typedef struct rt_body {
    int has_mass;
    double mass, inertia;  /* kg, kg m^2 about the centre */
    double centre[2];      /* link frame */
} rt_body;

/* The centre of mass of a link (the frame origin for a link without mass)
 * and its rates. */
RT_INLINE void rt_centre(const rt_body *b, const rt_frame *Fl, double *g, double *vg, double *ag)
{
    double r0 = b->has_mass ? b->centre[0] : 0.0, r1 = b->has_mass ? b->centre[1] : 0.0;
    rt_on_link(Fl, r0, r1, g, vg, ag);
}

/* D'Alembert's inertia load and gravity grav on the rows of moving link l
 * (centre acceleration ag[2 l], [2 l + 1]), set (not added): the first
 * entries of the right-hand side. */
RT_INLINE void rt_body_load(const rt_body *b, const rt_frame *Fl, const double *ag,
                            const double *grav, double *row)
{
    if (!b->has_mass) {
        row[0] = row[1] = row[2] = 0.0;
        return;
    }
    row[0] = b->mass * (ag[0] - grav[0]);
    row[1] = b->mass * (ag[1] - grav[1]);
    row[2] = b->inertia * Fl->al;
}

/* ---- gear pairs (docs/forces.md section 9) ----------------------------- */

typedef struct rt_gear {
    int rack;          /* 1: a pinion on a rack, 0: a pair of gears */
    rt_point a, b;     /* the pivots on the arm (b: a pair's second gear) */
    int inside;        /* a pair whose first gear runs inside the ring b */
    int guide;         /* rack: the guide's link, its angle, the pinion's side */
    double angle, side;
    double radius;     /* the first gear's pitch radius */
    double sep;        /* the second gear is pushed along sep n */
    double tan_pa;     /* tan and cos of the pressure angle (the interpreter's libm) */
    double cos_pa;
    int on[2];         /* the tooth force acts on on[0], its opposite on on[1] */
} rt_gear;

/* Pitch point p, common tangent t (the tooth force's direction on on[0])
 * and separating direction r of the pair at the frames F. */
RT_INLINE void rt_gear_contact(const rt_gear *gr, const rt_frame *F, double p[2], double t[2],
                               double r[2])
{
    double a[2], n[2];  /* a's centre; n: unit from a's centre through the pitch point */
    rt_point_motion(F, &gr->a, a, NULL, NULL);
    if (gr->rack) {
        /* the rack's line is r from the centre, to the right of the guide's
           direction u when side > 0: n = -side (-u_y, u_x) */
        double u[2];
        rt_guide_dir(&F[gr->guide], gr->angle, u);
        n[0] = gr->side * u[1];
        n[1] = -gr->side * u[0];
    } else {
        double b[2];
        rt_point_motion(F, &gr->b, b, NULL, NULL);
        double d = hypot(b[0] - a[0], b[1] - a[1]);
        n[0] = (b[0] - a[0]) / d;
        n[1] = (b[1] - a[1]) / d;
        if (gr->inside) {
            n[0] = -n[0];
            n[1] = -n[1];
        }
    }
    p[0] = a[0] + gr->radius * n[0];
    p[1] = a[1] + gr->radius * n[1];
    t[0] = -n[1];
    t[1] = n[0];
    r[0] = gr->sep * n[0];
    r[1] = gr->sep * n[1];
}

/* The separating part |F| tan(pressure angle) of the tooth force F (its
 * tangential component y) along r, a known load added to rhs. */
RT_INLINE void rt_gear_separation(const rt_gear *gr, const rt_frame *F, const double *g, double y,
                                  double *rhs)
{
    double p[2], t[2], r[2];
    rt_gear_contact(gr, F, p, t, r);
    double k = fabs(y) * gr->tan_pa;
    double fb[2] = {k * r[0], k * r[1]}, fa[2] = {-fb[0], -fb[1]};
    rt_load_force(rhs, g, gr->on[0], p, fb);
    rt_load_force(rhs, g, gr->on[1], p, fa);
}

/* The tooth force along the line of action, of its tangential part y. */
static inline double rt_tooth_force(const rt_gear *gr, double y) { return y / gr->cos_pa; }

/* A slider's reaction in the ground frame: its normal force n across the
 * guide at `angle` in the frame G. */
RT_INLINE void rt_slider_reaction(const rt_frame *G, double angle, double n, double *fx,
                                  double *fy)
{
    double u[2];
    rt_guide_dir(G, angle, u);
    *fx = -u[1] * n;
    *fy = u[0] * n;
}

/* ---- the columns: one per unknown reaction ---------------------------- */

enum {
    RT_COL_FORCE,   /* a force along a direction at a point of a joint */
    RT_COL_MOMENT,  /* a couple (a locked slider's, a turning driver's) */
    RT_COL_GEAR,    /* the tooth force of a gear pair, along its tangent */
    RT_COL_CAM      /* a cam's contact force along the common normal, at the contact:
                       the caller's table of each cam's contact point and unit normal
                       at this position (x, y, nx, ny in the ground frame) */
};
enum { RT_DIR_X, RT_DIR_Y, RT_DIR_NORMAL, RT_DIR_ALONG };  /* a force column's direction */

typedef struct rt_fcol {
    int kind;          /* RT_COL_* */
    int on[2];         /* the links it acts on: + on on[0], - on on[1] (0: the ground) */
    rt_point at;       /* FORCE: where it acts */
    int dir;           /* FORCE: x, y, or across or along the guide */
    int guide;         /* NORMAL, ALONG: the guide's link and angle */
    double angle;
    int gear;          /* GEAR: its pair in the rt_gear table; CAM: its pair in the
                          contacts' table */
} rt_fcol;

/* The rows of column c's entries, in the order rt_fcol_entries makes
 * them; how many. */
static inline int rt_fcol_rows(const rt_fcol *c, int *rows)
{
    int n = 0;
    for (int k = 0; k < 2; k++) {
        int l = c->on[k];
        if (l == 0)
            continue;
        if (c->kind == RT_COL_MOMENT) {
            rows[n++] = 3 * (l - 1) + 2;
            continue;
        }
        for (int i = 0; i < 3; i++)
            rows[n++] = 3 * (l - 1) + i;
    }
    return n;
}

/* The entries e[] of column c at the frames F, centres g: a unit force
 * (its x and y and its moment about the centre) or couple on on[0], and
 * its opposite on on[1]; how many. */
RT_INLINE int rt_fcol_entries(const rt_fcol *c, const rt_gear *gears, const double *cams,
                              const rt_frame *F, const double *g, double *e)
{
    int n = 0;
    double p[2], d[2];
    if (c->kind == RT_COL_MOMENT) {
        for (int k = 0; k < 2; k++)
            if (c->on[k] != 0)
                e[n++] = k ? -1.0 : 1.0;
        return n;
    }
    if (c->kind == RT_COL_GEAR) {
        double r[2];
        rt_gear_contact(&gears[c->gear], F, p, d, r);
    } else if (c->kind == RT_COL_CAM) {
        const double *k = cams + 4 * c->gear;
        p[0] = k[0], p[1] = k[1], d[0] = k[2], d[1] = k[3];
    } else {
        rt_point_motion(F, &c->at, p, NULL, NULL);
        double u[2] = {1.0, 0.0};
        if (c->dir == RT_DIR_NORMAL || c->dir == RT_DIR_ALONG)
            rt_guide_dir(&F[c->guide], c->angle, u);
        d[0] = c->dir == RT_DIR_X ? 1.0 : c->dir == RT_DIR_Y ? 0.0
               : c->dir == RT_DIR_NORMAL ? -u[1] : u[0];
        d[1] = c->dir == RT_DIR_X ? 0.0 : c->dir == RT_DIR_Y ? 1.0
               : c->dir == RT_DIR_NORMAL ? u[0] : u[1];
    }
    for (int k = 0; k < 2; k++) {
        int l = c->on[k];
        if (l == 0)
            continue;
        double sign = k ? -1.0 : 1.0, r[2] = {p[0] - g[2 * l], p[1] - g[2 * l + 1]};
        e[n++] = sign * d[0];
        e[n++] = sign * d[1];
        e[n++] = sign * (r[0] * d[1] - r[1] * d[0]);
    }
    return n;
}

/* ---- springs and the loads along a line (docs/forces.md section 7) ----- */

/* The line from point a to point b: its ends p[2][2] and their velocities
 * v, the unit vector u from a to b (along x when they coincide), the length
 * and its rate. */
RT_INLINE void rt_line(const rt_frame *F, const rt_point *a, const rt_point *b, double p[2][2],
                       double v[2][2], double u[2], double *length, double *rate)
{
    rt_point_motion(F, a, p[0], v[0], NULL);
    rt_point_motion(F, b, p[1], v[1], NULL);
    double d[2] = {p[1][0] - p[0][0], p[1][1] - p[0][1]};
    *length = hypot(d[0], d[1]);
    u[0] = *length > 0.0 ? d[0] / *length : 1.0;
    u[1] = *length > 0.0 ? d[1] / *length : 0.0;
    *rate = u[0] * (v[1][0] - v[0][0]) + u[1] * (v[1][1] - v[0][1]);
}

typedef struct rt_spring {
    int torsion;       /* 1: at a pin, between the angles of end[0].link and end[1].link */
    rt_point end[2];   /* linear: its ends */
    double rest;       /* the length (m) or angle (rad) where it pulls with its preload */
    double stiffness, preload, damping;
} rt_spring;

/* What a spring is at a position, in st[RT_SPRING_STATE]: length or angle,
 * rate, force or torque (tension positive), u[2], the ends' positions. */
enum { RT_SPRING_STATE = 9 };

RT_INLINE void rt_spring_eval(const rt_spring *sp, const rt_frame *F, double *st)
{
    if (sp->torsion) {
        /* the deflection taken in (-pi, pi]: link angles carry whole turns */
        const rt_frame *A = &F[sp->end[0].link], *B = &F[sp->end[1].link];
        double dev = remainder(A->th - B->th - sp->rest, 2.0 * 3.14159265358979323846);
        st[0] = sp->rest + dev;
        st[1] = A->om - B->om;
        st[2] = sp->preload + sp->stiffness * dev + sp->damping * st[1];
        return;
    }
    double p[2][2], v[2][2];
    rt_line(F, &sp->end[0], &sp->end[1], p, v, st + 3, &st[0], &st[1]);
    st[2] = sp->preload + sp->stiffness * (st[0] - sp->rest) + sp->damping * st[1];
    st[5] = p[0][0], st[6] = p[0][1], st[7] = p[1][0], st[8] = p[1][1];
}

/* A spring's loads (state st) on the right-hand side: tension F u on the
 * first end, -F u on the second; a torsional one -T on the first link, T
 * on the second. */
RT_INLINE void rt_spring_load(const rt_spring *sp, const double *st, const double *g, double *rhs)
{
    static const double none[2] = {0.0, 0.0};
    if (sp->torsion) {
        rt_add_load(rhs, g, sp->end[0].link, none, none, -st[2]);
        rt_add_load(rhs, g, sp->end[1].link, none, none, st[2]);
        return;
    }
    double f[2] = {st[2] * st[3], st[2] * st[4]}, fb[2] = {-f[0], -f[1]};
    rt_add_load(rhs, g, sp->end[0].link, st + 5, f, 0.0);
    rt_add_load(rhs, g, sp->end[1].link, st + 7, fb, 0.0);
}

/* ---- loads: constant, and those that depend on the motion ------------- */

enum {
    RT_LOAD_TORQUE,    /* v[0] on at.link */
    RT_LOAD_FORCE,     /* (v[0], v[1]) at `at` */
    RT_LOAD_SPREAD,    /* v[0] per length along at .. to, at angle v[1], at the middle */
    RT_LOAD_SL_FORCE,  /* (reg[0], reg[1]) at `at` (registers of the loads' program) */
    RT_LOAD_SL_TORQUE, /* reg[0] on at.link */
    RT_LOAD_SL_LINE    /* reg[0] along the line at .. to, tension positive */
};

typedef struct rt_load {
    int kind;          /* RT_LOAD_* */
    rt_point at, to;
    double v[2];
    int reg[2];
} rt_load;

/* A constant load's resultant f at p (moving with v): a spread load acts
 * at the middle of its segment. */
RT_INLINE void rt_load_resultant(const rt_load *ld, const rt_frame *F, double *f, double *p,
                                 double *v)
{
    double a[2];
    if (ld->kind == RT_LOAD_FORCE) {
        f[0] = ld->v[0];
        f[1] = ld->v[1];
        rt_point_motion(F, &ld->at, p, v, a);
        return;
    }
    double p0[2], p1[2], v0[2], v1[2];
    rt_point_motion(F, &ld->at, p0, v0, a);
    rt_point_motion(F, &ld->to, p1, v1, a);
    double w = ld->v[0] * hypot(p1[0] - p0[0], p1[1] - p0[1]);
    f[0] = w * cos(ld->v[1]);
    f[1] = w * sin(ld->v[1]);
    for (int k = 0; k < 2; k++) {
        p[k] = 0.5 * (p0[k] + p1[k]);
        v[k] = 0.5 * (v0[k] + v1[k]);
    }
}

/* Load ld on the right-hand side (reg: the registers of the loads that
 * depend on the motion). */
RT_INLINE void rt_load_apply(const rt_load *ld, const rt_frame *F, const double *g,
                             const double *reg, double *rhs)
{
    static const double none[2] = {0.0, 0.0};
    double f[2], p[2], v[2];
    switch (ld->kind) {
    case RT_LOAD_TORQUE:
        rt_load_moment(rhs, ld->at.link, ld->v[0]);
        return;
    case RT_LOAD_FORCE:
    case RT_LOAD_SPREAD:
        rt_load_resultant(ld, F, f, p, v);
        rt_load_force(rhs, g, ld->at.link, p, f);
        return;
    case RT_LOAD_SL_TORQUE:
        rt_add_load(rhs, g, ld->at.link, none, none, reg[ld->reg[0]]);
        return;
    case RT_LOAD_SL_LINE: {
        double pe[2][2], ve[2][2], u[2], len, rate, t = reg[ld->reg[0]];
        rt_line(F, &ld->at, &ld->to, pe, ve, u, &len, &rate);
        double fa[2] = {t * u[0], t * u[1]}, fb[2] = {-fa[0], -fa[1]};
        rt_add_load(rhs, g, ld->at.link, pe[0], fa, 0.0);
        rt_add_load(rhs, g, ld->to.link, pe[1], fb, 0.0);
        return;
    }
    default:  /* RT_LOAD_SL_FORCE */
        f[0] = reg[ld->reg[0]];
        f[1] = reg[ld->reg[1]];
        rt_point_motion(F, &ld->at, p, v, NULL);
        rt_add_load(rhs, g, ld->at.link, p, f, 0.0);
    }
}

/* ---- the power balance (docs/forces.md section 5) ---------------------- */

/* P_driver + P_loads + P_gravity - P_friction - dT/dt relative to the sum
 * of the terms' magnitudes, summed in this order: rt_power_start, the
 * bodies, the loads (the constant ones into ext, the springs' and then the
 * loads' that depend on the motion into totals of their own), rt_power_end.
 * A load's scale is its size times the mechanism's speed (a force times
 * `linear`, a torque times `turning`), not just its power: at a dead point
 * every power vanishes while the driver's load still carries the rounding
 * of forces of that size. */
typedef struct rt_power {
    double kin, ext, scale;
    double springs, sloads;  /* the springs' power, the motion-dependent loads' */
    double linear, turning;
} rt_power;

/* The speeds that turn a load's size into a power scale, for a driver
 * (turning: angle 1) at `speed` and the largest length lref. */
static inline void rt_power_scales(int turning_driver, double speed, double lref, double *linear,
                                   double *turning)
{
    double v = fabs(speed);
    *linear = turning_driver ? v * lref : v;
    *turning = turning_driver ? v : v / lref;
}

RT_INLINE void rt_power_start(rt_power *pw, double pd, double pfric, double linear,
                              double turning)
{
    pw->kin = pw->ext = pw->springs = pw->sloads = 0.0;
    pw->scale = fabs(pd) + fabs(pfric);
    pw->linear = linear;
    pw->turning = turning;
}

/* A link with mass: dT/dt and gravity's power (vg, ag: its centre's rates). */
RT_INLINE void rt_power_body(rt_power *pw, const rt_body *b, const rt_frame *Fl, const double *vg,
                             const double *ag, const double *grav)
{
    double dk = b->mass * (vg[0] * ag[0] + vg[1] * ag[1]) + b->inertia * Fl->om * Fl->al;
    double pg = b->mass * (grav[0] * vg[0] + grav[1] * vg[1]);
    pw->kin += dk;
    pw->ext += pg;
    pw->scale += fabs(b->mass * vg[0] * ag[0]) + fabs(b->mass * vg[1] * ag[1]) +
                 fabs(b->inertia * Fl->om * Fl->al) + fabs(pg);
}

RT_INLINE void rt_power_load(rt_power *pw, const rt_load *ld, const rt_frame *F,
                             const double *reg)
{
    double p, f[2], q[2], v[2];
    switch (ld->kind) {
    case RT_LOAD_TORQUE:
        p = ld->v[0] * F[ld->at.link].om;
        pw->ext += p;
        pw->scale += fabs(p);
        return;
    case RT_LOAD_FORCE:
    case RT_LOAD_SPREAD:
        rt_load_resultant(ld, F, f, q, v);
        p = f[0] * v[0] + f[1] * v[1];
        pw->ext += p;
        pw->scale += fabs(p);
        return;
    case RT_LOAD_SL_TORQUE: {
        double t = reg[ld->reg[0]];
        p = t * F[ld->at.link].om;
        pw->scale += fabs(t) * pw->turning;
        break;
    }
    case RT_LOAD_SL_LINE: {
        double pe[2][2], ve[2][2], u[2], len, rate, t = reg[ld->reg[0]];
        rt_line(F, &ld->at, &ld->to, pe, ve, u, &len, &rate);
        p = -t * rate;
        pw->scale += fabs(t) * pw->linear;
        break;
    }
    default:  /* RT_LOAD_SL_FORCE */
        f[0] = reg[ld->reg[0]];
        f[1] = reg[ld->reg[1]];
        rt_point_motion(F, &ld->at, q, v, NULL);
        p = f[0] * v[0] + f[1] * v[1];
        pw->scale += hypot(f[0], f[1]) * pw->linear;
    }
    pw->sloads += p;
    pw->scale += fabs(p);
}

/* A spring (state st): -F dL/dt. */
RT_INLINE void rt_power_spring(rt_power *pw, const rt_spring *sp, const double *st)
{
    pw->springs -= st[2] * st[1];
    pw->scale += fabs(st[2] * st[1]) + fabs(st[2]) * (sp->torsion ? pw->turning : pw->linear);
}

RT_INLINE double rt_power_end(rt_power *pw, double pd, double pfric)
{
    pw->ext += pw->springs;
    pw->ext += pw->sloads;
    double r = pd + pw->ext - pfric - pw->kin;
    return pw->scale > 0.0 ? r / pw->scale : 0.0;
}

/* ---- the drivers' loads ---------------------------------------------- */

/* A driver's coordinate: a link's angle (link > 0), or a slide whose rate
 * is vel[var] (var -1: none, 0). */
typedef struct rt_drive {
    int link, var;
} rt_drive;

/* The drivers' power for their loads y[0 .. n-1]: the driver's load times
 * `speed` (one driver, the sweep variable), or (laws of time) the sum of
 * each load times the rate of its coordinate. */
RT_INLINE double rt_drive_power(const rt_drive *d, int n, int laws, const rt_frame *F,
                                const double *vel, double speed, const double *y)
{
    if (!laws)
        return y[0] * speed;
    double p = 0.0;
    for (int k = 0; k < n; k++) {
        double rate = d[k].link > 0 ? F[d[k].link].om : d[k].var >= 0 ? vel[d[k].var] : 0.0;
        p += y[k] * rate;
    }
    return p;
}

/* ---- joint friction (docs/forces.md section 4) ------------------------- */

typedef struct rt_friction {
    int slider;        /* 0: a pin, 1: a slider */
    int a, b;          /* the receiving link, the other */
    int col;           /* the joint's first reaction column */
    double mu, radius; /* the coefficient; a pin's radius */
    rt_point at;       /* slider: the contact point */
    int guide;         /* slider: the guide's link and angle */
    double angle;
    int var;           /* slider: its rate vel[var] (-1: none, 0) */
} rt_friction;

/* v / sqrt(v^2 + eps^2): the sign of v, continuous where v reverses. */
static inline double rt_smooth_sign(double v, double eps) { return v / sqrt(v * v + eps * eps); }

/* The Coulomb loads of joint fr for the reactions y, added to fric: a
 * moment mu r |F| in a pin, a force mu |N| in a slider (eps times lref),
 * against the relative motion; returns the power they take. */
RT_INLINE double rt_friction_load(const rt_friction *fr, const rt_frame *F, const double *g,
                                  const double *vel, const double *y, double eps, double lref,
                                  double *fric)
{
    const double *yc = y + fr->col;
    if (!fr->slider) {
        double rel = F[fr->a].om - F[fr->b].om;
        double mf = fr->mu * fr->radius * sqrt(yc[0] * yc[0] + yc[1] * yc[1]) *
                    rt_smooth_sign(rel, eps);
        rt_load_moment(fric, fr->a, -mf);
        rt_load_moment(fric, fr->b, mf);
        return mf * rel;
    }
    double rel = fr->var >= 0 ? vel[fr->var] : 0.0;
    double ff = fr->mu * fabs(yc[0]) * rt_smooth_sign(rel, eps * lref);
    double u[2], p[2];
    rt_guide_dir(&F[fr->guide], fr->angle, u);
    rt_point_motion(F, &fr->at, p, NULL, NULL);
    double fa[2] = {-ff * u[0], -ff * u[1]}, fb[2] = {ff * u[0], ff * u[1]};
    rt_load_force(fric, g, fr->a, p, fa);
    rt_load_force(fric, g, fr->b, p, fb);
    return ff * rel;
}

/* ---- the program of the loads that depend on the motion --------------- */

/* Its operations (state_loads.h: SLOP_*). */
enum {
    RT_SL_ADD, RT_SL_SUB, RT_SL_MUL, RT_SL_DIV, RT_SL_NEG, RT_SL_POWI, RT_SL_SIN, RT_SL_COS,
    RT_SL_TAN, RT_SL_ATAN2, RT_SL_SQRT, RT_SL_ABS, RT_SL_MIN, RT_SL_MAX, RT_SL_EXP, RT_SL_LOG,
    RT_SL_TANH, RT_SL_STEP, RT_SL_SIGN, RT_SL_SMOOTHSIGN, RT_SL_COUNT
};

/* One operation: op(a, b), k the exponent of RT_SL_POWI. */
RT_INLINE double rt_sl_apply(int op, double a, double b, int k)
{
    switch (op) {
    case RT_SL_ADD: return a + b;
    case RT_SL_SUB: return a - b;
    case RT_SL_MUL: return a * b;
    case RT_SL_DIV: return a / b;
    case RT_SL_NEG: return -a;
    case RT_SL_POWI: {
        double r = 1.0, x = k < 0 ? 1.0 / a : a;
        for (int e = k < 0 ? -k : k; e > 0; e--)
            r *= x;
        return r;
    }
    case RT_SL_SIN: return sin(a);
    case RT_SL_COS: return cos(a);
    case RT_SL_TAN: return tan(a);
    case RT_SL_ATAN2: return atan2(a, b);
    case RT_SL_SQRT: return sqrt(a);
    case RT_SL_ABS: return fabs(a);
    case RT_SL_MIN: return a < b ? a : b;
    case RT_SL_MAX: return a > b ? a : b;
    case RT_SL_EXP: return exp(a);
    case RT_SL_LOG: return log(a);
    case RT_SL_TANH: return tanh(a);
    case RT_SL_STEP: return a > 0.0 ? 1.0 : 0.0;
    case RT_SL_SIGN: return a > 0.0 ? 1.0 : a < 0.0 ? -1.0 : 0.0;
    case RT_SL_SMOOTHSIGN: return a / sqrt(a * a + b * b);
    default: return 0.0;
    }
}

/* ---- the solve -------------------------------------------------------- */

enum { RT_FRICTION_MAX_ITER = 100, RT_ANDERSON_DEPTH = 3 };
#define RT_FRICTION_TOL 1e-12

/* gamma minimising |r - sum_k gamma_k dr_k| over the `depth` newest
 * differences (a ring of RT_ANDERSON_DEPTH vectors of n; normal equations,
 * Gaussian elimination with pivoting); how many weights are used (0: a
 * plain step, when the differences are nearly dependent). */
static inline int rt_anderson_weights(const double *dr, int n, int depth, int newest,
                                      const double *r, double *gamma)
{
    double a[RT_ANDERSON_DEPTH][RT_ANDERSON_DEPTH + 1];
    for (int k = 0; k < depth; k++) {
        const double *dk = dr + ((newest - k + RT_ANDERSON_DEPTH) % RT_ANDERSON_DEPTH) * n;
        for (int l = 0; l <= k; l++) {
            const double *dl = dr + ((newest - l + RT_ANDERSON_DEPTH) % RT_ANDERSON_DEPTH) * n;
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

/* The caller's force system, ctx its state. */
typedef struct rt_forces_ops {
    /* y = A^-1 rhs with the factors, the column scaling undone */
    void (*solve)(void *ctx, const double *rhs, double *y);
    /* the friction loads of the reactions y into fric (set), their power */
    double (*friction)(void *ctx, const double *y, double *fric);
    /* the gears' separating loads for the reactions y, added to rhs */
    void (*separation)(void *ctx, const double *y, double *rhs);
    /* the drivers' power for the reactions y */
    double (*drive_power)(void *ctx, const double *y);
    /* the power balance for the drivers' power pd and friction's pfric */
    double (*power)(void *ctx, double pd, double pfric);
} rt_forces_ops;

/* The caller's vectors of n (the reactions; dg, dr: RT_ANDERSON_DEPTH n). */
typedef struct rt_forces_vec {
    double *b;         /* the known loads' right-hand side */
    double *y, *y0;    /* the reactions with friction, without */
    double *fric;      /* work: friction loads (and a right-hand side) */
    double *g;         /* work: the image G(y) */
    double *r, *ag;    /* Anderson: the last residual and image */
    double *dg, *dr;   /* their last differences (a ring) */
} rt_forces_vec;

/* What a solve gives besides the reactions. */
typedef struct rt_forces_out {
    int have_previous; /* in: y holds the last position's reactions; out: 1 */
    int iterations;    /* friction fixed-point iterations (-1: no convergence) */
    double residual0;  /* the power balance without friction (0: not solved) */
    double residual;   /* ... with it */
    double friction_power, drive_power;
} rt_forces_out;

/* The reactions with friction: y = G(y) = A^-1 (b + friction loads of y),
 * from y, by Anderson acceleration of the fixed point (Walker and Ni, SIAM
 * J. Numer. Anal. 49, 2011): the next iterate combines the last
 * RT_ANDERSON_DEPTH images G(y) with the weights that minimise the combined
 * residual G(y) - y in least squares. Each iteration costs one solve, like
 * the plain iteration, but the conveyor needs 4-5 instead of 6-9. A step
 * whose residual grows restarts the history (plain iteration). Converged
 * when |G(y) - y| <= 1e-12 |G(y)|; y = G(y) then. */
static inline void rt_friction_fixed_point(const rt_forces_ops *ops, void *ctx, int n,
                                           const rt_forces_vec *v, rt_forces_out *out)
{
    int depth = 0, newest = 0;
    double *g = v->g, *r = v->r, *dg = v->dg, *dr = v->dr, prev_res = HUGE_VAL;
    for (int it = 1;; it++) {
        ops->friction(ctx, v->y, v->fric);
        for (int i = 0; i < n; i++)
            v->fric[i] += v->b[i];
        ops->separation(ctx, v->y, v->fric);
        ops->solve(ctx, v->fric, g);
        double res = 0.0, big = 0.0;
        for (int i = 0; i < n; i++) {
            double ri = g[i] - v->y[i];
            res = fabs(ri) > res ? fabs(ri) : res;
            big = fabs(g[i]) > big ? fabs(g[i]) : big;
        }
        out->iterations = it;
        if (res <= RT_FRICTION_TOL * big || !isfinite(res)) {
            memcpy(v->y, g, (size_t)n * sizeof *v->y);
            out->friction_power = ops->friction(ctx, v->y, v->fric);
            if (!isfinite(res))
                out->iterations = -1;
            return;
        }
        if (it == RT_FRICTION_MAX_ITER) {
            out->iterations = -1;
            return;
        }
        if (!(res < prev_res))
            depth = 0;  /* not contracting: restart the history (a plain step) */
        prev_res = res;
        if (it > 1) {  /* differences to the previous image and residual (slot newest) */
            newest = (newest + 1) % RT_ANDERSON_DEPTH;
            for (int i = 0; i < n; i++) {
                double ri = g[i] - v->y[i];
                dg[newest * n + i] = g[i] - v->ag[i];
                dr[newest * n + i] = ri - r[i];
            }
            depth = depth < RT_ANDERSON_DEPTH ? depth + 1 : RT_ANDERSON_DEPTH;
        }
        for (int i = 0; i < n; i++) {
            r[i] = g[i] - v->y[i];
            v->ag[i] = g[i];
        }
        double gamma[RT_ANDERSON_DEPTH];
        int used = rt_anderson_weights(dr, n, depth, newest, r, gamma);
        memcpy(v->y, g, (size_t)n * sizeof *v->y);
        for (int k = 0; k < used; k++) {
            const double *dgk = dg + ((newest - k + RT_ANDERSON_DEPTH) % RT_ANDERSON_DEPTH) * n;
            for (int i = 0; i < n; i++)
                v->y[i] -= gamma[k] * dgk[i];
        }
    }
}

/* With the force matrix factored and the known loads in v->b: the
 * reactions, friction and the power balance (docs/forces.md section 3).
 * The frictionless reactions y0 are the answer without friction, asked for
 * beside it (frictionless), or the friction iteration's start at the first
 * position; later positions start from the last one's reactions (one solve
 * fewer, and closer). Gear pairs: their separating forces follow from the
 * tangential ones, one solve more. Returns 0, or -2 when the friction
 * iteration does not converge. */
static inline int rt_forces_solve(const rt_forces_ops *ops, void *ctx, int n, int friction,
                                  int frictionless, int gears, const rt_forces_vec *v,
                                  rt_forces_out *out)
{
    out->residual0 = 0.0;
    if (!friction || frictionless || !out->have_previous) {
        ops->solve(ctx, v->b, v->y0);
        if (gears) {
            memcpy(v->fric, v->b, (size_t)n * sizeof *v->fric);
            ops->separation(ctx, v->y0, v->fric);
            ops->solve(ctx, v->fric, v->y0);
        }
        out->residual0 = ops->power(ctx, ops->drive_power(ctx, v->y0), 0.0);
        memcpy(v->y, v->y0, (size_t)n * sizeof *v->y);
    }
    out->have_previous = 1;
    out->iterations = 0;
    out->friction_power = 0.0;
    if (friction)
        rt_friction_fixed_point(ops, ctx, n, v, out);
    out->drive_power = ops->drive_power(ctx, v->y);
    out->residual = ops->power(ctx, out->drive_power, out->friction_power);
    return out->iterations < 0 ? -2 : 0;
}

#endif
