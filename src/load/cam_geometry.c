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

void cam_geometry(const mech_model *m, const mech_cam *c, double x, cam_point *g)
{
    double s[4], q[3][2], mv[2], jq[2], jq1[2], w[2], w1[2], jw[2], w2[2], n[2];
    program_eval(c->program->progs[0], x, s);
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
    double pitch[2], contact[2];
    g->x = x;
    g->s[0] = s[0], g->s[1] = s[1], g->s[2] = s[2];
    g->rho_pitch = -sg * len * len * len / cross(w, w2);
    g->face = 0.0;
    if (c->contact == CAM_FLAT_FACED) {  /* the face normal to the line, touching where */
        double u[2] = {mv[0], mv[1]}, un[2];  /* the face's point moves with it (envelope) */
        perp(u, un);
        double along = c->base + s[0], side = -sg * s[1];
        for (int i = 0; i < 2; i++)
            contact[i] = along * u[i] + side * un[i];
        g->face = side - c->offset;
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
    g->pitch[0] = oc->x + pitch[0], g->pitch[1] = oc->y + pitch[1];
    g->profile[0] += oc->x, g->profile[1] += oc->y;
}
