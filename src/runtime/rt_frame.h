/* src/runtime/rt_frame.h: link frames and the motion of their points (the
 * kinematics of docs/architecture.md, "Vector-loop formulation"). Part of
 * the runtime that libmech (kinematics.c) and the C that `mech codegen`
 * writes share (docs/codegen.md): self-contained, the C library only.
 *
 * A point r (link frame) of link l is at
 *   p = o + R(th) r,  v = v_o + w x (R r),  a = a_o + al x (R r) - w^2 R r;
 * a slider's mover point M = T + s u (T the guide's point, u the guide
 * direction) moves with
 *   v_M = v_T + s' u + s w_g u_perp,
 *   a_M = a_T + s'' u + (2 s' w_g + s al_g) u_perp - s w_g^2 u. */
#ifndef MECH_RT_FRAME_H
#define MECH_RT_FRAME_H

#include <math.h>

#include "rt_base.h"

/* One link's frame at a position, with its rates. */
typedef struct rt_frame {
    double th, om, al;         /* angle, angular velocity, angular acceleration */
    double c, s;               /* cos th, sin th */
    double o[2], vo[2], ao[2]; /* origin and its rates */
} rt_frame;

/* The ground's frame: angle 0 at the origin, at rest. */
static inline void rt_frame_rest(rt_frame *F)
{
    F->th = F->om = F->al = 0.0;
    F->c = 1.0;
    F->s = 0.0;
    F->o[0] = F->o[1] = F->vo[0] = F->vo[1] = F->ao[0] = F->ao[1] = 0.0;
}

/* Point (r0, r1) of F's link: its position p, velocity v and acceleration
 * a (v, a may be NULL: not wanted). */
RT_INLINE void rt_on_link(const rt_frame *F, double r0, double r1, double *p, double *v,
                          double *a)
{
    double rx = F->c * r0 - F->s * r1, ry = F->s * r0 + F->c * r1;  /* R r */
    double w = F->om, al = F->al;
    p[0] = F->o[0] + rx;
    p[1] = F->o[1] + ry;
    if (v) {
        v[0] = F->vo[0] - w * ry;
        v[1] = F->vo[1] + w * rx;
    }
    if (a) {
        a[0] = F->ao[0] - al * ry - w * w * rx;
        a[1] = F->ao[1] + al * rx - w * w * ry;
    }
}

/* Place F (its angle and rates set) so that its point (r0, r1) is at p,
 * moving with v and a. */
RT_INLINE void rt_place_at(rt_frame *F, double r0, double r1, const double *p, const double *v,
                           const double *a)
{
    double rx = F->c * r0 - F->s * r1, ry = F->s * r0 + F->c * r1;
    double w = F->om, al = F->al;
    F->o[0] = p[0] - rx;
    F->o[1] = p[1] - ry;
    F->vo[0] = v[0] + w * ry;
    F->vo[1] = v[1] - w * rx;
    F->ao[0] = a[0] + al * ry + w * w * rx;
    F->ao[1] = a[1] - al * rx + w * w * ry;
}

/* The direction u of a guide at `angle` in the frame G. */
RT_INLINE void rt_guide_dir(const rt_frame *G, double angle, double u[2])
{
    double ang = G->th + angle;
    u[0] = cos(ang);
    u[1] = sin(ang);
}

/* A slider's offset d[0] = s u of its mover point from the guide's point,
 * and its rates d[1], d[2], for the guide G with direction (ux, uy) and the
 * slide s, s', s''. */
RT_INLINE void rt_slide_offset(const rt_frame *G, double ux, double uy, double s, double sd,
                               double sdd, double d[3][2])
{
    double w = G->om, al = G->al;  /* u_perp = (-uy, ux) */
    d[0][0] = s * ux;
    d[0][1] = s * uy;
    double tang = sd, norm = s * w;  /* along u, along u_perp */
    d[1][0] = tang * ux - norm * uy;
    d[1][1] = tang * uy + norm * ux;
    double ta = sdd - s * w * w, na = 2.0 * sd * w + s * al;
    d[2][0] = ta * ux - na * uy;
    d[2][1] = ta * uy + na * ux;
}

/* Place L from its parent P across their joint: its point (rp0, rp1) in
 * P, plus sign d for a slider (the mover's offset from the guide's point,
 * rt_slide_offset; d NULL for a revolute), is L's point (rl0, rl1). */
RT_INLINE void rt_place_across(rt_frame *L, const rt_frame *P, double rp0, double rp1,
                               double rl0, double rl1, const double (*d)[2], double sign)
{
    double p[2], v[2], a[2];
    rt_on_link(P, rp0, rp1, p, v, a);
    if (d)
        for (int k = 0; k < 2; k++) {
            p[k] += sign * d[0][k];
            v[k] += sign * d[1][k];
            a[k] += sign * d[2][k];
        }
    rt_place_at(L, rl0, rl1, p, v, a);
}

#endif
