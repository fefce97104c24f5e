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
 * sine, Norton, Cam Design and Manufacturing Handbook, ch. 3). */
static void piece_at(const prog_piece *p, double u, double f[4])
{
    double h = u - p->u0, wu = p->w * u + p->phi, w0 = p->w * p->u0 + p->phi;
    double k = p->c1 / p->w;
    f[3] = p->c1 * p->w * cos(wu);
    f[2] = p->c0 + p->c1 * sin(wu);
    f[1] = p->f1 + p->c0 * h - k * (cos(wu) - cos(w0));
    f[0] = p->f0 + p->f1 * h + 0.5 * p->c0 * h * h - k * ((sin(wu) - sin(w0)) / p->w - cos(w0) * h);
}

void prog_shape_init(prog_segment *sg)
{
    static const prog_piece trap[5] = {
        {0.0, 0, 0, 0, 1, 4 * PI, 0},     {0.125, 0, 0, 1, 0, 1, 0},
        {0.375, 0, 0, 0, -1, 4 * PI, 0},  {0.625, 0, 0, -1, 0, 1, 0},
        {0.875, 0, 0, 0, 1, 4 * PI, 0}};
    static const prog_piece msin[3] = {
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
            piece_at(&sg->piece[j - 1], sg->piece[j].u0, f);
        sg->piece[j].f0 = f[0];
        sg->piece[j].f1 = f[1];
    }
    if (sg->npieces == 0)
        return;
    piece_at(&sg->piece[sg->npieces - 1], 1.0, f);
    double scale = 1.0 / f[0];
    for (int j = 0; j < sg->npieces; j++) {
        prog_piece *p = &sg->piece[j];
        p->f0 *= scale, p->f1 *= scale, p->c0 *= scale, p->c1 *= scale;
    }
}

static void pieces_eval(const prog_segment *sg, double u, double f[4])
{
    int j = sg->npieces - 1;
    while (j > 0 && u < sg->piece[j].u0)
        j--;
    piece_at(&sg->piece[j], u, f);
}


void prog_shape_eval(const prog_segment *sg, double u, double f[4])
{
    double c, s, u2 = u * u;
    switch (sg->shape) {
    case SHAPE_CYCLOIDAL:  /* u - sin(2 pi u) / (2 pi) */
        c = cos(2 * PI * u), s = sin(2 * PI * u);
        f[0] = u - s / (2 * PI), f[1] = 1 - c, f[2] = 2 * PI * s, f[3] = 4 * PI * PI * c;
        break;
    case SHAPE_HARMONIC:  /* (1 - cos(pi u)) / 2 */
        c = cos(PI * u), s = sin(PI * u);
        f[0] = 0.5 * (1 - c), f[1] = 0.5 * PI * s, f[2] = 0.5 * PI * PI * c;
        f[3] = -0.5 * PI * PI * PI * s;
        break;
    case SHAPE_345:  /* 10 u^3 - 15 u^4 + 6 u^5 */
        f[0] = u2 * u * (10 + u * (-15 + 6 * u));
        f[1] = u2 * (30 + u * (-60 + 30 * u));
        f[2] = u * (60 + u * (-180 + 120 * u));
        f[3] = 60 + u * (-360 + 360 * u);
        break;
    case SHAPE_4567:  /* 35 u^4 - 84 u^5 + 70 u^6 - 20 u^7 */
        f[0] = u2 * u2 * (35 + u * (-84 + u * (70 - 20 * u)));
        f[1] = u2 * u * (140 + u * (-420 + u * (420 - 140 * u)));
        f[2] = u2 * (420 + u * (-1680 + u * (2100 - 840 * u)));
        f[3] = u * (840 + u * (-5040 + u * (8400 - 4200 * u)));
        break;
    case SHAPE_MODTRAP:
    case SHAPE_MODSINE: pieces_eval(sg, u, f); break;
    case SHAPE_USER: {
        double buf[4 * PROG_USER_MAX_NODES], d[3];
        f[0] = law_eval3(sg->user, u, buf, d);
        f[1] = d[0], f[2] = d[1], f[3] = d[2];
        break;
    }
    default: f[0] = f[1] = f[2] = f[3] = 0.0; break;  /* a dwell */
    }
}

void program_eval(const mech_program *p, double x, double d[4])
{
    double k = floor(x / p->period), xl = x - k * p->period;
    if (xl >= p->period)  /* rounding at a period's end */
        xl -= p->period, k += 1;
    if (xl < 0)
        xl = 0;
    int lo = 0, hi = p->n - 1;
    while (lo < hi) {  /* the last segment starting at or before xl */
        int mid = (lo + hi + 1) / 2;
        if (p->seg[mid].x0 <= xl)
            lo = mid;
        else
            hi = mid - 1;
    }
    const prog_segment *sg = &p->seg[lo];
    double u = (xl - sg->x0) / sg->span, f[4];
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    prog_shape_eval(sg, u, f);
    double b = sg->span;
    d[0] = p->start + k * p->net + sg->s0 + sg->lift * f[0];
    d[1] = sg->lift * f[1] / b;
    d[2] = sg->lift * f[2] / (b * b);
    d[3] = sg->lift * f[3] / (b * b * b);
}

void program_free(mech_program *p)
{
    if (!p)
        return;
    for (int i = 0; i < p->n; i++)
        law_free(p->seg[i].user);
    free(p->seg);
    free(p);
}
