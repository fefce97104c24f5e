/* src/gears.c: gear pairs and racks (gears.h). The rolling condition of a
 * pair at its pitch point, relative to the arm both pivots are fixed in,
 * is one linear row in the link angles: its derivatives, the velocity and
 * acceleration rows, follow symbolically like those of the loops. */
#include <math.h>
#include <stdio.h>

#include "gears.h"
#include "springs.h"

static const double PI = 3.14159265358979323846;

/* k x, dropped when k is 0 (an arm on the ground has no angle term). */
static ex term(expr_ctx *c, double k, ex x)
{
    return k == 0.0 ? c->zero : expr_mul(c, expr_const(c, k), x);
}

/* The row in expanded form, sum of k_i x_i + constant: the driver's term
 * is then a product of its own, computed once per driver position (the
 * tape's hoisted part), and `mech equations` prints each angle once. */
ex gears_row(mech_system *s, int i)
{
    const mech_model *m = s->model;
    expr_ctx *c = &s->ex;
    const mech_gear *g = &m->gears[i];
    const ex *th = s->link_angle;
    double ra = g->radius[0];
    ex sum;
    if (g->kind == MECH_GEAR_RACK) {
        /* s - s0 - side r (th_p - th_arm - o_p) */
        double k = g->side * ra;
        sum = expr_add(c, s->slide[g->rack], term(c, -k, th[g->link[0]]));
        sum = expr_add(c, sum, term(c, k, th[g->arm]));
        return expr_add(c, sum, expr_const(c, k * g->offset[0] - g->offset[1]));
    }
    /* r_a (th_a - th_arm - o_a) + sign r_b (th_b - th_arm - o_b) */
    double rb = (g->internal ? -1.0 : 1.0) * g->radius[1];
    sum = expr_add(c, term(c, ra, th[g->link[0]]), term(c, rb, th[g->link[1]]));
    sum = expr_add(c, sum, term(c, -(ra + rb), th[g->arm]));
    return expr_add(c, sum, expr_const(c, -(ra * g->offset[0] + rb * g->offset[1])));
}

void gears_contact(const mech_model *m, const solver *sv, int i, double *p, double *t,
                   double *r)
{
    const mech_gear *g = &m->gears[i];
    p[0] = p[1] = 0.0;
    t[0] = 1.0;
    t[1] = r[0] = r[1] = 0.0;
    if (!sv)
        return;
    double a[2], n[2];  /* a's centre; n: unit from a's centre through the pitch point */
    springs_point_motion(sv, g->arm, g->arm_pivot[0], a, NULL);
    if (g->kind == MECH_GEAR_RACK) {
        /* the rack's line is r from the centre, to the right of the guide's
           direction u when side > 0: n = -side (-u_y, u_x) */
        const mech_joint *jt = &m->joints[g->rack];
        double ang = sv->ks.th[jt->link[1]] + jt->angle;
        n[0] = g->side * sin(ang);
        n[1] = -g->side * cos(ang);
    } else {
        double b[2];
        springs_point_motion(sv, g->arm, g->arm_pivot[1], b, NULL);
        double d = hypot(b[0] - a[0], b[1] - a[1]);
        n[0] = (b[0] - a[0]) / d;
        n[1] = (b[1] - a[1]) / d;
        if (g->internal && g->radius[0] < g->radius[1]) {  /* a inside the ring b */
            n[0] = -n[0];
            n[1] = -n[1];
        }
    }
    p[0] = a[0] + g->radius[0] * n[0];
    p[1] = a[1] + g->radius[0] * n[1];
    t[0] = -n[1];
    t[1] = n[0];
    /* b is pushed away from a's teeth: along n, unless a is the ring */
    double sep = g->kind == MECH_GEAR_PAIR && g->internal && g->radius[0] > g->radius[1]
                     ? -1.0 : 1.0;
    r[0] = sep * n[0];
    r[1] = sep * n[1];
}

void gears_describe(const mech_model *m, int i, char *buf, size_t size)
{
    const mech_gear *g = &m->gears[i];
    double deg = 180.0 / PI;
    if (g->kind == MECH_GEAR_RACK) {
        snprintf(buf, size, "%s: pinion '%s' (r %.6g mm) on rack '%s' (link '%s', guide '%s'), "
                 "s = %+.6g mm/rad * th, pressure angle %.6g deg", g->name,
                 m->links[g->link[0]].name, g->radius[0] * 1e3, m->joints[g->rack].name,
                 m->links[g->link[1]].name, m->links[g->arm].name,
                 g->side * g->radius[0] * 1e3, g->pressure_angle * deg);
        return;
    }
    char teeth[64] = "";
    if (g->teeth[0])
        snprintf(teeth, sizeof teeth, ", z %d:%d", g->teeth[0], g->teeth[1]);
    snprintf(buf, size, "%s: '%s' with '%s', %s on '%s', r %.6g:%.6g mm%s, ratio %+.6g, "
             "pressure angle %.6g deg", g->name, m->links[g->link[0]].name,
             m->links[g->link[1]].name, g->internal ? "internal" : "external",
             m->links[g->arm].name, g->radius[0] * 1e3, g->radius[1] * 1e3, teeth,
             (g->internal ? 1.0 : -1.0) * g->radius[0] / g->radius[1], g->pressure_angle * deg);
}
