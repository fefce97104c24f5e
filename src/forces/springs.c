/* src/forces/springs.c: linear and torsional springs and viscous dampers
 * (docs/forces.md section 7): each as the force system reads it
 * (rt_forces.h, rt_spring: its formulas, its loads and its power), and in
 * words.
 *
 * Linear, ends P (link a) and Q (link b), L = |Q - P|, u = (Q - P) / L:
 *   force F = preload + k (L - L0) + c dL/dt, dL/dt = u . (vQ - vP),
 *   tension positive: F u acts on a at P, -F u on b at Q.
 * Torsional at a pin, receiving link a, other link b, phi = th_a - th_b:
 *   torque T = preload + k (phi - phi0) + c dphi/dt; -T on a, +T on b.
 * Either way the power delivered to the links is -F dL/dt (-T dphi/dt). */
#include <math.h>
#include <stdio.h>

#include "forces.h"

static const double PI = 3.14159265358979323846;

void springs_rt(const mech_model *m, int i, rt_spring *out)
{
    const mech_spring *s = &m->springs[i];
    int tor = s->kind == MECH_SPRING_TORSION;
    rt_spring d = {tor, {{s->link[0], {0.0, 0.0}}, {s->link[1], {0.0, 0.0}}}, s->free,
                   s->stiffness, s->preload, s->damping};
    for (int k = 0; k < 2 && !tor; k++) {
        const mech_point *pt = &m->links[s->link[k]].points[s->point[k]];
        d.end[k].r[0] = pt->x, d.end[k].r[1] = pt->y;
    }
    *out = d;
}

void springs_eval(const mech_model *m, int i, const solver *sv, spring_state *st)
{
    rt_spring d;
    double v[RT_SPRING_STATE];
    springs_rt(m, i, &d);
    rt_spring_eval(&d, sv->ks.F, v);
    st->length = v[0];
    st->rate = v[1];
    st->force = v[2];
}

void springs_describe(const mech_model *m, int i, char *buf, size_t size)
{
    const mech_spring *s = &m->springs[i];
    int tor = s->kind == MECH_SPRING_TORSION;
    size_t at;
    if (tor)
        at = (size_t)snprintf(buf, size, "%s: torsional at %s (%s, %s)", s->name,
                              m->joints[s->joint].name, m->links[s->link[0]].name,
                              m->links[s->link[1]].name);
    else
        at = (size_t)snprintf(buf, size, "%s: linear %s-%s (%s, %s)", s->name,
                              m->links[s->link[0]].points[s->point[0]].name,
                              m->links[s->link[1]].points[s->point[1]].name,
                              m->links[s->link[0]].name, m->links[s->link[1]].name);
    if (at < size && s->stiffness > 0)
        at += (size_t)snprintf(buf + at, size - at, ", stiffness %g %s, free %s %g %s",
                               s->stiffness, tor ? "N*m/rad" : "N/m", tor ? "angle" : "length",
                               tor ? s->free * 180.0 / PI : s->free, tor ? "deg" : "m");
    if (at < size && s->preload != 0)
        at += (size_t)snprintf(buf + at, size - at, ", preload %g %s", s->preload,
                               tor ? "N*m" : "N");
    if (at < size && s->damping > 0)
        snprintf(buf + at, size - at, ", damping %g %s", s->damping, tor ? "N*m*s/rad" : "N*s/m");
}
