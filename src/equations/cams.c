/* src/equations/cams.c: cam-follower pairs (equations.h, docs/cams.md). The
 * follower's coordinate is the program's lift at the cam's angle on the
 * arm: one row whose lift is an opaque call of that angle (law_expr), so
 * the Jacobian's entry, the velocity and the acceleration rows follow by
 * the chain rule with the program's exact derivatives. */
#include <math.h>
#include <stdio.h>

#include "equations.h"

static const double PI = 3.14159265358979323846;

ex cams_row(mech_system *s, int i)
{
    const mech_cam *cm = &s->model->cams->cam[i];
    expr_ctx *c = &s->ex;
    const ex *th = s->link_angle;
    ex rel = expr_add(c, th[cm->cam], expr_neg(c, th[cm->arm]));  /* the cam on its arm */
    ex x = expr_mul(c, expr_const(c, (double)cm->sense),
                    expr_add(c, rel, expr_const(c, -cm->start)));
    ex lift = law_expr(cm->program, c, x);
    ex coord = cm->motion == CAM_TRANSLATING
                   ? s->slide[cm->slider]
                   : expr_add(c, th[cm->follower], expr_neg(c, th[cm->arm]));
    ex row = expr_add(c, coord, expr_const(c, -cm->c0));
    return expr_add(c, row, expr_mul(c, expr_const(c, -(double)cm->rise), lift));
}

void cams_design(const mech_model *m, int i, char *buf, size_t size)
{
    const mech_cam *c = &m->cams->cam[i];
    double deg = 180.0 / PI;
    size_t at = 0;
    if (c->contact != CAM_FLAT_FACED)
        at += (size_t)snprintf(buf, size, "%s: pressure angle at most %.4g deg (at %.4g deg), ",
                               c->name, c->pressure_max * deg, c->pressure_at * deg);
    else
        at += (size_t)snprintf(buf, size, "%s: face from %.6g to %.6g mm %s (width at least "
                               "%.6g mm), ", c->name, c->face_lo * 1e3, c->face_hi * 1e3,
                               c->motion == CAM_TRANSLATING ? "of the follower's line"
                               : "along it from its first point",
                               (c->face_hi - c->face_lo) * 1e3);
    if (at < size && c->contact != CAM_FLAT_FACED && isfinite(c->rho_pitch_min))
        at += (size_t)snprintf(buf + at, size - at, "pitch curve radius at least %.6g mm (at "
                               "%.4g deg), ", c->rho_pitch_min * 1e3, c->rho_pitch_at * deg);
    if (at < size)
        snprintf(buf + at, size - at, "profile radius at least %.6g mm (at %.4g deg)",
                 c->rho_profile_min * 1e3, c->rho_profile_at * deg);
}

void cams_describe(const mech_model *m, int i, char *buf, size_t size)
{
    static const char *const contact[] = {"roller", "knife-edge", "flat-faced"};
    const mech_cam *c = &m->cams->cam[i];
    const struct mech_program *p = c->program->progs[0];
    double deg = 180.0 / PI;
    char base[96];
    if (c->motion == CAM_TRANSLATING)
        snprintf(base, sizeof base, "slider '%s' at %.6g mm + s, offset %+.6g mm",
                 m->joints[c->slider].name, c->c0 * 1e3, c->offset * 1e3);
    else
        snprintf(base, sizeof base, "'%s' at %.6g deg %c s", m->links[c->follower].name,
                 c->c0 * deg, c->rise > 0 ? '+' : '-');
    char roller[48] = "", law[64];
    if (c->points)
        snprintf(law, sizeof law, "profile of %d points (the lift at every %.6g deg)",
                 c->npoints, p->period / p->n * deg);
    else
        snprintf(law, sizeof law, "program of %d segments over %.6g deg", p->n, p->period * deg);
    if (c->roller > 0)
        snprintf(roller, sizeof roller, ", roller %.6g mm", c->roller * 1e3);
    snprintf(buf, size, "%s: cam '%s' on '%s' turning %s, %s follower %s, base radius %.6g mm"
             "%s, %s", c->name, m->links[c->cam].name,
             m->links[c->arm].name, c->sense > 0 ? "ccw" : "cw", contact[c->contact], base,
             c->base * 1e3, roller, law);
}
