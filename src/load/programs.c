/* src/load/programs.c: motion programs (docs/motion-programs.md): the
 * standard laws of a rise or return, normalised (f(0) = 0, f(1) = 1, u in
 * [0, 1]) with their exact derivatives f', f'', f''' in u, and a
 * program's displacement s(x) and its derivatives in its variable x. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

static const double PI = 3.14159265358979323846;

static const struct {
    const char *name;
    prog_shape shape;
} shape_names[] = {
    {"cycloidal", SHAPE_CYCLOIDAL},     {"harmonic", SHAPE_HARMONIC},
    {"simple-harmonic", SHAPE_HARMONIC}, {"3-4-5", SHAPE_345},
    {"4-5-6-7", SHAPE_4567},            {"modified-trapezoid", SHAPE_MODTRAP},
    {"modified-sine", SHAPE_MODSINE},
    /* the same with spaces, as books write them */
    {"simple harmonic", SHAPE_HARMONIC}, {"modified trapezoid", SHAPE_MODTRAP},
    {"modified sine", SHAPE_MODSINE},
};

prog_shape prog_shape_by_name(const char *name)
{
    for (size_t i = 0; i < sizeof shape_names / sizeof shape_names[0]; i++)
        if (strcmp(name, shape_names[i].name) == 0)
            return shape_names[i].shape;
    return SHAPE_NONE;
}

const char *prog_shape_name(prog_shape s)
{
    if (s == SHAPE_USER)
        return "user law";
    for (size_t i = 0; i < sizeof shape_names / sizeof shape_names[0]; i++)
        if (shape_names[i].shape == s)
            return shape_names[i].name;
    return "dwell";
}

/* ---- the piecewise laws: f'' = c0 + c1 sin(w u + phi) on each piece ----
 * Integrated in closed form from f(0) = f'(0) = 0 with a peak of 1, then
 * scaled so that f(1) = 1: the peak acceleration is then the law's
 * coefficient (4.8881 for the modified trapezoid, 5.5280 for the modified
 * sine, Norton, Cam Design and Manufacturing Handbook, ch. 3). The pieces
 * are evaluated by rt_law.h's rt_piece_at. */
void prog_shape_init(prog_segment *sg)
{
    static const rt_piece trap[5] = {
        {0.0, 0, 0, 0, 1, 4 * PI, 0},     {0.125, 0, 0, 1, 0, 1, 0},
        {0.375, 0, 0, 0, -1, 4 * PI, 0},  {0.625, 0, 0, -1, 0, 1, 0},
        {0.875, 0, 0, 0, 1, 4 * PI, 0}};
    static const rt_piece msin[3] = {
        {0.0, 0, 0, 0, 1, 4 * PI, 0}, {0.125, 0, 0, 0, 1, 4 * PI / 3, PI / 3},
        {0.875, 0, 0, 0, 1, 4 * PI, 0}};
    sg->npieces = 0;
    if (sg->shape == SHAPE_MODTRAP)
        memcpy(sg->piece, trap, sizeof trap), sg->npieces = 5;
    else if (sg->shape == SHAPE_MODSINE)
        memcpy(sg->piece, msin, sizeof msin), sg->npieces = 3;
    double f[4] = {0, 0, 0, 0};
    for (int j = 0; j < sg->npieces; j++) {  /* each piece starts where the last ends */
        if (j > 0)
            rt_piece_at(&sg->piece[j - 1], sg->piece[j].u0, f);
        sg->piece[j].f0 = f[0];
        sg->piece[j].f1 = f[1];
    }
    if (sg->npieces == 0)
        return;
    rt_piece_at(&sg->piece[sg->npieces - 1], 1.0, f);
    double scale = 1.0 / f[0];
    for (int j = 0; j < sg->npieces; j++) {
        rt_piece *p = &sg->piece[j];
        p->f0 *= scale, p->f1 *= scale, p->c0 *= scale, p->c1 *= scale;
    }
}

void prog_shape_eval(const prog_segment *sg, double u, double f[4]) { rt_shape_eval(sg, u, f); }

void program_eval(const mech_program *p, double x, double d[4]) { rt_program_eval(&p->rt, x, d); }

void program_free(mech_program *p)
{
    if (!p)
        return;
    for (int i = 0; i < p->n; i++)
        law_free(p->seg[i].user_law);
    free(p->seg);
    free(p);
}
