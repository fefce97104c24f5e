/* src/load/cam_geometry.c: a cam's profile and design quantities from its
 * follower's program (docs/cams.md, section 3): by kinematic inversion, the
 * follower's contact element seen from the cam. In the arm's frame, with
 * the cam's centre O as origin, the follower's trace point is q(x) (the
 * roller's centre, the knife's tip, the flat face's foot on its line); the
 * cam has turned by th(x) = start + sense x on the arm, so in the cam's
 * frame the pitch curve is P(x) = Rot(-th) q(x) and
 *     P'  = Rot(-th) w,                 w  = q' - sense J q,
 *     P'' = Rot(-th) (w' - sense J w),  w' = q'' - sense J q',
 * J the rotation by +90 deg. A rise is traced clockwise in the cam's frame
 * when the cam turns counterclockwise (sense +1), so the outward normal is
 * N = sense J w / |w| and the radius of curvature, positive where the curve
 * is convex, rho = -sense |w|^3 / (w x (w' - sense J w)). */
#include <math.h>

#include "load.h"

/* J v: v turned by +90 deg */
static void perp(const double v[2], double out[2])
{
    double x = v[0];
    out[0] = -v[1];
    out[1] = x;
}

static double cross(const double a[2], const double b[2]) { return a[0] * b[1] - a[1] * b[0]; }

static void rotate(double a, const double v[2], double out[2])
{
    double c = cos(a), s = sin(a), x = v[0];
    out[0] = c * x - s * v[1];
    out[1] = s * x + c * v[1];
}

/* The trace point q and its derivatives in x, in the arm's frame from O,
 * and the unit m along which it moves as the lift grows. */
static void trace_point(const mech_model *m, const mech_cam *c, const double s[3], double q[3][2],
                        double mv[2])
{
    if (c->motion == CAM_TRANSLATING) {
        double a = m->joints[c->slider].angle, u[2] = {cos(a), sin(a)}, n[2];
        perp(u, n);
        double d0 = c->contact == CAM_FLAT_FACED
                        ? c->base
                        : sqrt((c->base + c->roller) * (c->base + c->roller) - c->offset * c->offset);
        for (int i = 0; i < 2; i++) {
            q[0][i] = c->offset * n[i] + (d0 + s[0]) * u[i];
            q[1][i] = s[1] * u[i];
            q[2][i] = s[2] * u[i];
            mv[i] = u[i];
        }
        return;
    }
    const mech_point *pf = &m->links[c->follower].points[c->follower_pivot[0]];
    const mech_point *pa = &m->links[c->arm].points[c->follower_pivot[1]];
    const mech_point *r = &m->links[c->follower].points[c->at];
    const mech_point *o = &m->links[c->arm].points[c->cam_pivot[1]];
    double v0[2] = {r->x - pf->x, r->y - pf->y}, v[2], jv[2];
    double k = c->rise, ds = k * s[1];
    rotate(c->c0 + k * s[0], v0, v);
    perp(v, jv);
    double len = hypot(v[0], v[1]);
    for (int i = 0; i < 2; i++) {
        q[0][i] = (i ? pa->y - o->y : pa->x - o->x) + v[i];
        q[1][i] = ds * jv[i];
        q[2][i] = k * s[2] * jv[i] - ds * ds * v[i];
        mv[i] = k * jv[i] / len;
    }
}

double cam_face(const mech_model *m, const mech_cam *c, double w[2])
{
    const mech_link *fl = &m->links[c->follower];
    const mech_point *pf = &fl->points[c->follower_pivot[0]];
    const mech_point *a = &fl->points[c->face[0]], *b = &fl->points[c->face[1]];
    double wl = hypot(b->x - a->x, b->y - a->y);
    w[0] = (b->x - a->x) / wl, w[1] = (b->y - a->y) / wl;
    return (a->x - pf->x) * -w[1] + (a->y - pf->y) * w[0];
}

/* An oscillating flat face (section 3 of docs/cams.md): the face's line
 * p . nu = d in the arm's frame from O, nu = R(psi) J w, d = (P - O) . nu
 * + k; seen from the cam, a line whose normal turns at phi' = rise s' -
 * sense, so the contact (its envelope) is h n + (h' / phi') J n with h =
 * |d| and n = sign(d) nu, and the profile's radius h + (h'' phi' - h'
 * phi'') / phi'^3. */
static void oscillating_face(const mech_model *m, const mech_cam *c, const double s[3],
                             double x, cam_point *g)
{
    const mech_link *fl = &m->links[c->follower];
    const mech_point *pf = &fl->points[c->follower_pivot[0]];
    const mech_point *pa = &m->links[c->arm].points[c->follower_pivot[1]];
    const mech_point *o = &m->links[c->arm].points[c->cam_pivot[1]];
    const mech_point *a = &fl->points[c->face[0]];
    double w0[2], w[2], nu[2], jnu[2], dv[2] = {pa->x - o->x, pa->y - o->y};
    double k = cam_face(m, c, w0);
    double r = c->rise, psi = c->c0 + r * s[0], p1 = r * s[1], p2 = r * s[2];
    rotate(psi, w0, w);
    perp(w, nu);
    perp(nu, jnu);  /* = -w */
    double d = dv[0] * nu[0] + dv[1] * nu[1] + k;
    double dw = dv[0] * w[0] + dv[1] * w[1];        /* (P - O) . w */
    double sg = d < 0.0 ? -1.0 : 1.0, h = sg * d;
    double h1 = sg * -dw * p1;                      /* dd/dpsi = -(P - O) . w */
    double h2 = sg * (-d + k) * p1 * p1 - sg * dw * p2;  /* d2: -(P - O) . nu psi'^2 - ... */
    double f1 = p1 - c->sense, f2 = p2;             /* the normal's turning rate in the cam */
    double n[2] = {sg * nu[0], sg * nu[1]}, jn[2];
    perp(n, jn);
    double contact[2], th = c->start + c->sense * x;
    for (int i = 0; i < 2; i++)
        contact[i] = h * n[i] + h1 / f1 * jn[i];
    g->rho_pitch = NAN;
    g->rho_profile = h + (h2 * f1 - h1 * f2) / (f1 * f1 * f1);
    /* the contact along the face from A (where the follower's point A is) */
    double ax = pa->x - o->x, ay = pa->y - o->y, av[2] = {a->x - pf->x, a->y - pf->y}, ar[2];
    rotate(psi, av, ar);
    g->face = (contact[0] - ax - ar[0]) * w[0] + (contact[1] - ay - ar[1]) * w[1];
    /* the pressure angle: from the motion of the follower's point at the
       contact (about the pivot, as the lift grows) to the normal */
    double rel[2] = {contact[0] - ax, contact[1] - ay}, mv[2];
    perp(rel, mv);
    double ml = hypot(mv[0], mv[1]);
    mv[0] *= r / ml, mv[1] *= r / ml;
    g->pressure = atan2(cross(mv, n), mv[0] * n[0] + mv[1] * n[1]);
    double foot[2] = {d * nu[0], d * nu[1]}, pitch[2];
    rotate(-th, foot, pitch);
    rotate(-th, contact, g->profile);
    rotate(-th, n, g->normal);
    (void)jnu;
    const mech_point *oc = &m->links[c->cam].points[c->cam_pivot[0]];
    g->pitch[0] = oc->x + pitch[0], g->pitch[1] = oc->y + pitch[1];
    g->profile[0] += oc->x, g->profile[1] += oc->y;
}

void cam_geometry(const mech_model *m, const mech_cam *c, double x, cam_point *g)
{
    double s[4], q[3][2], mv[2], jq[2], jq1[2], w[2], w1[2], jw[2], w2[2], n[2];
    program_eval(c->program->progs[0], x, s);
    g->x = x;
    g->s[0] = s[0], g->s[1] = s[1], g->s[2] = s[2], g->s[3] = s[3];
    if (c->motion == CAM_OSCILLATING && c->contact == CAM_FLAT_FACED)
        return oscillating_face(m, c, s, x, g);
    trace_point(m, c, s, q, mv);
    double sg = c->sense;
    perp(q[0], jq);
    perp(q[1], jq1);
    for (int i = 0; i < 2; i++) {
        w[i] = q[1][i] - sg * jq[i];
        w1[i] = q[2][i] - sg * jq1[i];
    }
    perp(w, jw);
    for (int i = 0; i < 2; i++)
        w2[i] = w1[i] - sg * jw[i];
    double len = hypot(w[0], w[1]);
    for (int i = 0; i < 2; i++)
        n[i] = sg * jw[i] / len;  /* the outward normal, in the arm's frame */
    double th = c->start + sg * x;
    const mech_point *oc = &m->links[c->cam].points[c->cam_pivot[0]];
    double pitch[2], contact[2], normal[2] = {n[0], n[1]};
    g->rho_pitch = -sg * len * len * len / cross(w, w2);
    g->face = 0.0;
    if (c->contact == CAM_FLAT_FACED) {  /* the face normal to the line, touching where */
        double u[2] = {mv[0], mv[1]}, un[2];  /* the face's point moves with it (envelope) */
        perp(u, un);
        double along = c->base + s[0], side = -sg * s[1];
        for (int i = 0; i < 2; i++)
            contact[i] = along * u[i] + side * un[i];
        g->face = side - c->offset;
        normal[0] = u[0], normal[1] = u[1];
        g->pressure = 0.0;
        g->rho_profile = c->base + s[0] + s[2];
    } else {
        for (int i = 0; i < 2; i++)
            contact[i] = q[0][i] - c->roller * n[i];
        g->pressure = atan2(cross(mv, n), mv[0] * n[0] + mv[1] * n[1]);
        g->rho_profile = g->rho_pitch - c->roller;
    }
    rotate(-th, q[0], pitch);
    rotate(-th, contact, g->profile);
    rotate(-th, normal, g->normal);
    g->pitch[0] = oc->x + pitch[0], g->pitch[1] = oc->y + pitch[1];
    g->profile[0] += oc->x, g->profile[1] += oc->y;
}
