/* src/equations/gears.c: gear pairs and racks (gears.h). The rolling condition of a
 * pair at its pitch point, relative to the arm both pivots are fixed in,
 * is one linear row in the link angles: its derivatives, the velocity and
 * acceleration rows, follow symbolically like those of the loops. */
#include <math.h>
#include <stdio.h>

#include "equations.h"

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

void gears_rt(const mech_model *m, int i, rt_gear *out)
{
    const mech_gear *g = &m->gears[i];
    const mech_link *arm = &m->links[g->arm];
    const mech_point *a = &arm->points[g->arm_pivot[0]];
    const mech_point *b = g->kind == MECH_GEAR_PAIR ? &arm->points[g->arm_pivot[1]] : a;
    int pair = g->kind == MECH_GEAR_PAIR, rack = g->kind == MECH_GEAR_RACK;
    *out = (rt_gear){rack, {g->arm, {a->x, a->y}}, {g->arm, {b->x, b->y}},
                     pair && g->internal && g->radius[0] < g->radius[1],  /* a inside the ring b */
                     rack ? m->joints[g->rack].link[1] : 0, rack ? m->joints[g->rack].angle : 0.0,
                     (double)g->side, g->radius[0],
                     /* b is pushed away from a's teeth: along n, unless a is the ring */
                     pair && g->internal && g->radius[0] > g->radius[1] ? -1.0 : 1.0,
                     tan(g->pressure_angle), cos(g->pressure_angle), {g->link[1], g->link[0]}};
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
