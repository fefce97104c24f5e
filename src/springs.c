/* src/springs.c: linear and torsional springs and viscous dampers
 * (docs/forces.md section 7). Each is evaluated from the published motion
 * of the solver (link frames, their rates): no allocation, no state.
 *
 * Linear, ends P (link a) and Q (link b), L = |Q - P|, u = (Q - P) / L:
 *   force F = preload + k (L - L0) + c dL/dt, dL/dt = u . (vQ - vP),
 *   tension positive: F u acts on a at P, -F u on b at Q.
 * Torsional at a pin, receiving link a, other link b, phi = th_a - th_b:
 *   torque T = preload + k (phi - phi0) + c dphi/dt; -T on a, +T on b.
 * Either way the power delivered to the links is -F dL/dt (-T dphi/dt). */
#include <math.h>
#include <stdio.h>

#include "springs.h"

static const double PI = 3.14159265358979323846;

void springs_point_motion(const solver *sv, int l, int i, double p[2], double v[2])
{
    const mech_point *pt = &sv->p->m->links[l].points[i];
    double r[2] = {pt->x, pt->y};
    kin_on_link(&sv->ks, l, r, p, v, NULL);
}

void springs_line(const solver *sv, const int link[2], const int point[2], double p[2][2],
                  double v[2][2], double u[2], double *length, double *rate)
{
    springs_point_motion(sv, link[0], point[0], p[0], v[0]);
    springs_point_motion(sv, link[1], point[1], p[1], v[1]);
    double d[2] = {p[1][0] - p[0][0], p[1][1] - p[0][1]};
    *length = hypot(d[0], d[1]);
    /* coincident ends: no direction; the force is then taken along x */
    u[0] = *length > 0.0 ? d[0] / *length : 1.0;
    u[1] = *length > 0.0 ? d[1] / *length : 0.0;
    *rate = u[0] * (v[1][0] - v[0][0]) + u[1] * (v[1][1] - v[0][1]);
}

void springs_eval(const mech_spring *s, const solver *sv, spring_state *st)
{
    if (s->kind == MECH_SPRING_TORSION) {
        /* the deflection taken in (-pi, pi]: link angles carry whole turns */
        double dev = remainder(sv->ks.th[s->link[0]] - sv->ks.th[s->link[1]] - s->free, 2 * PI);
        st->length = s->free + dev;
        st->rate = sv->ks.om[s->link[0]] - sv->ks.om[s->link[1]];
        st->force = s->preload + s->stiffness * dev + s->damping * st->rate;
        return;
    }
    springs_line(sv, s->link, s->point, st->p, st->v, st->u, &st->length, &st->rate);
    st->force = s->preload + s->stiffness * (st->length - s->free) + s->damping * st->rate;
}

void springs_add_known_load(double *rhs, const double *g, int l, const double *p,
                            const double *f, double t)
{
    if (l == 0)
        return;
    double r[2] = {p[0] - g[2 * l], p[1] - g[2 * l + 1]};
    double *row = rhs + 3 * (l - 1);
    row[0] -= f[0];
    row[1] -= f[1];
    row[2] -= r[0] * f[1] - r[1] * f[0] + t;
}

void springs_add_loads(const mech_model *m, const solver *sv, const double *g, double *rhs)
{
    static const double none[2] = {0.0, 0.0};
    for (int i = 0; i < m->nsprings; i++) {
        const mech_spring *s = &m->springs[i];
        spring_state st;
        springs_eval(s, sv, &st);
        if (s->kind == MECH_SPRING_TORSION) {
            springs_add_known_load(rhs, g, s->link[0], none, none, -st.force);
            springs_add_known_load(rhs, g, s->link[1], none, none, st.force);
            continue;
        }
        double f[2] = {st.force * st.u[0], st.force * st.u[1]};  /* on end 0, toward end 1 */
        double fb[2] = {-f[0], -f[1]};
        springs_add_known_load(rhs, g, s->link[0], st.p[0], f, 0.0);
        springs_add_known_load(rhs, g, s->link[1], st.p[1], fb, 0.0);
    }
}

/* The scale a spring adds to the power balance is its force times the
 * mechanism's speed (driver speed, times the largest length for a crank),
 * not just its own power: where the mechanism stands still at a dead point
 * every power vanishes while the driver torque still carries the rounding
 * of forces of that size (a dead centre of the example: 3e-8 relative to the
 * vanishing powers alone, 1e-16 to this). */
void springs_power_scales(const mech_model *m, const solver *sv, double *linear,
                          double *turning)
{
    double lref = sv->p->lref, speed = fabs(m->driver.speed);
    int angle = m->driver.kind == MECH_DRIVE_ANGLE;
    *linear = angle ? speed * lref : speed;
    *turning = angle ? speed : speed / lref;
}

double springs_power(const mech_model *m, const solver *sv, double *scale)
{
    double total = 0.0, linear, turning;
    springs_power_scales(m, sv, &linear, &turning);
    for (int i = 0; i < m->nsprings; i++) {
        const mech_spring *s = &m->springs[i];
        spring_state st;
        springs_eval(s, sv, &st);
        total -= st.force * st.rate;
        *scale += fabs(st.force * st.rate) +
                  fabs(st.force) * (s->kind == MECH_SPRING_TORSION ? turning : linear);
    }
    return total;
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
