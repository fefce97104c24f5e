/* src/runtime/rt_law.h: a law of time's value and first three derivatives,
 * and the motion programs' laws (docs/motion-programs.md). Part of the
 * runtime that libmech (law_eval.c, programs.c) and the C that `mech
 * codegen` writes share (docs/codegen.md): the same operations in the same
 * order, so a law the generated code evaluates is the interpreter's bit
 * for bit. Self-contained, the C library only.
 *
 * A law is a list of nodes, operands first. Each node's value and its
 * first three derivatives in t are propagated forward; a function g of one
 * argument a goes through Faa di Bruno's formula with g, g', g'', g''' at
 * a's value:
 *     f' = g' a',  f'' = g' a'' + g'' a'^2,  f''' = g' a''' + 3 g'' a' a'' + g''' a'^3. */
#ifndef MECH_RT_LAW_H
#define MECH_RT_LAW_H

#include <complex.h>
#include <math.h>
#include <string.h>

/* RT_LAWFN: the runtime's law functions (each translation unit uses some) */
#if defined(__GNUC__)
#define RT_LAWFN static __attribute__((unused))
#else
#define RT_LAWFN static
#endif

/* ORDER LAW: src/load/load.h's law_op in the same order */
enum {
    RT_LAW_CONST, RT_LAW_T, RT_LAW_ADD, RT_LAW_MUL, RT_LAW_NEG, RT_LAW_SIN, RT_LAW_COS,
    RT_LAW_DIV, RT_LAW_EXP, RT_LAW_LOG, RT_LAW_SQRT, RT_LAW_TAN, RT_LAW_TANH, RT_LAW_ATAN2,
    RT_LAW_ABS, RT_LAW_MIN, RT_LAW_MAX, RT_LAW_STEP, RT_LAW_SIGN, RT_LAW_PROGRAM
};
/* a program segment's law (shape) */
enum {
    RT_SHAPE_NONE, RT_SHAPE_CYCLOIDAL, RT_SHAPE_HARMONIC, RT_SHAPE_345, RT_SHAPE_4567,
    RT_SHAPE_MODTRAP, RT_SHAPE_MODSINE, RT_SHAPE_USER, RT_SHAPE_CUBIC
};
enum { RT_LAW_USER_MAX = 256 };  /* operations of a segment's own law f(u) */

typedef struct rt_law_node {
    int op;      /* RT_LAW_* */
    int a, b;    /* operands, -1 unused; RT_LAW_PROGRAM: b is the program */
    double k;    /* RT_LAW_CONST: the value */
} rt_law_node;

struct rt_program;
typedef struct rt_law {
    const rt_law_node *nodes;  /* [n] */
    int n, root;
    const struct rt_program *const *progs;  /* RT_LAW_PROGRAM's programs */
} rt_law;

typedef struct rt_piece {  /* f'' = c0 + c1 sin(w u + phi) from u0 */
    double u0, f0, f1, c0, c1, w, phi;
} rt_piece;

typedef struct rt_segment {
    int kind;          /* libmech's prog_kind */
    int shape;         /* RT_SHAPE_* */
    double x0, span;   /* where it starts in the period, its span (SI of x) */
    double s0, lift;   /* s at its start; the signed lift */
    rt_piece piece[5]; /* the modified trapezoid and sine */
    int npieces;
    rt_law user;       /* RT_SHAPE_USER: f(u) */
    void *user_law;    /* libmech: the struct mech_law it was parsed into (owned) */
    int line, col;     /* libmech: where the file gives it */
} rt_segment;

typedef struct rt_program {
    const rt_segment *seg;  /* [n] */
    int n;
    double start, period, net;
} rt_program;

/* f[0..3] of g(a) from g[0..3] at a's value and a's derivatives a[0..3] */
RT_LAWFN void rt_law_chain(const double g[4], const double a[4], double f[4])
{
    f[0] = g[0];
    f[1] = g[1] * a[1];
    f[2] = g[1] * a[2] + g[2] * a[1] * a[1];
    f[3] = g[1] * a[3] + 3.0 * g[2] * a[1] * a[2] + g[3] * a[1] * a[1] * a[1];
}

RT_LAWFN void rt_law_product(const double a[4], const double b[4], double f[4])
{
    f[0] = a[0] * b[0];
    f[1] = a[1] * b[0] + a[0] * b[1];
    f[2] = a[2] * b[0] + 2.0 * a[1] * b[1] + a[0] * b[2];
    f[3] = a[3] * b[0] + 3.0 * (a[2] * b[1] + a[1] * b[2]) + a[0] * b[3];
}

/* g, g', g'', g''' of the elementary function of op at x (RT_LAW_DIV: 1/x);
 * NaN where it is not defined */
RT_LAWFN void rt_law_elementary(int op, double x, double g[4])
{
    switch (op) {
    case RT_LAW_SIN: {
        double s = sin(x), c = cos(x);
        g[0] = s, g[1] = c, g[2] = -s, g[3] = -c;
        break;
    }
    case RT_LAW_COS: {
        double s = sin(x), c = cos(x);
        g[0] = c, g[1] = -s, g[2] = -c, g[3] = s;
        break;
    }
    case RT_LAW_TAN: {  /* v' = 1 + v^2 */
        double v = tan(x), w = 1.0 + v * v;
        g[0] = v, g[1] = w, g[2] = 2.0 * v * w, g[3] = 2.0 * w * (1.0 + 3.0 * v * v);
        break;
    }
    case RT_LAW_TANH: {  /* v' = 1 - v^2 */
        double v = tanh(x), w = 1.0 - v * v;
        g[0] = v, g[1] = w, g[2] = -2.0 * v * w, g[3] = -2.0 * w * (1.0 - 3.0 * v * v);
        break;
    }
    case RT_LAW_EXP:
        g[0] = g[1] = g[2] = g[3] = exp(x);
        break;
    case RT_LAW_LOG:
        g[0] = x > 0 ? log(x) : NAN;
        g[1] = 1.0 / x, g[2] = -g[1] * g[1], g[3] = 2.0 * g[1] * g[1] * g[1];
        if (!(x > 0))
            g[1] = g[2] = g[3] = NAN;
        break;
    case RT_LAW_SQRT: {  /* at 0 the rate is infinite: NaN */
        double r = x >= 0 ? sqrt(x) : NAN;
        g[0] = r;
        g[1] = r > 0 ? 0.5 / r : NAN;
        g[2] = r > 0 ? -0.5 * g[1] / x : NAN;
        g[3] = r > 0 ? -1.5 * g[2] / x : NAN;
        break;
    }
    default: {  /* 1 / x */
        double i = 1.0 / x;
        if (x == 0.0)
            i = NAN;
        g[0] = i, g[1] = -i * i, g[2] = 2.0 * i * i * i, g[3] = -6.0 * i * i * i * i;
        break;
    }
    }
}

/* atan2(y, x) = arg z, z = x + i y: its derivatives are Im of those of log z */
RT_LAWFN void rt_law_atan2(const double y[4], const double x[4], double f[4])
{
    double complex z = x[0] + I * y[0], z1 = x[1] + I * y[1], z2 = x[2] + I * y[2],
                   z3 = x[3] + I * y[3];
    f[0] = atan2(y[0], x[0]);
    if (z == 0) {
        f[1] = f[2] = f[3] = NAN;
        return;
    }
    double complex w = z1 / z;
    f[1] = cimag(w);
    f[2] = cimag(z2 / z - w * w);
    f[3] = cimag(z3 / z - 3.0 * w * z2 / z + 2.0 * w * w * w);
}

/* abs, step, sign: at a zero of the argument the derivatives exist only
 * while it stays on one side */
RT_LAWFN void rt_law_piecewise(int op, const double a[4], double f[4])
{
    if (op == RT_LAW_ABS) {
        double s = a[0] > 0 ? 1.0 : a[0] < 0 ? -1.0 : 0.0;
        if (s != 0) {
            for (int k = 0; k < 4; k++)
                f[k] = s * a[k];
            return;
        }
        f[0] = 0.0;  /* |a| near a zero of a: a'' t^2 / 2 when a' = 0 */
        f[1] = a[1] == 0 ? 0.0 : NAN;
        f[2] = a[1] == 0 ? fabs(a[2]) : NAN;
        f[3] = a[1] == 0 && a[2] != 0 ? copysign(1.0, a[2]) * a[3]
               : a[1] == 0 && a[3] == 0 ? 0.0 : NAN;
        return;
    }
    f[0] = op == RT_LAW_STEP ? (a[0] > 0 ? 1.0 : 0.0) : (a[0] > 0 ? 1.0 : a[0] < 0 ? -1.0 : 0.0);
    int flat = a[0] != 0 || (a[1] == 0 && a[2] == 0 && a[3] == 0);
    f[1] = f[2] = f[3] = flat ? 0.0 : NAN;  /* it jumps here */
}

/* min (want < 0) or max of two: the branch below (above); where they meet
 * with different rates, a corner: no derivative */
RT_LAWFN void rt_law_extremum(int want, const double a[4], const double b[4], double f[4])
{
    int k = 0;
    while (k < 4 && a[k] == b[k])
        k++;
    const double *pick = k == 4 || (a[k] - b[k]) * want > 0 ? a : b;
    memcpy(f, pick, 4 * sizeof *f);
    if (k == 1)
        f[1] = f[2] = f[3] = NAN;
    else if (k == 3)  /* they cross at the third order */
        f[3] = NAN;
}

/* ---- the programs' laws, normalised: f(0) = 0, f(1) = 1, u in [0, 1] ---- */

RT_LAWFN void rt_piece_at(const rt_piece *p, double u, double f[4])
{
    double h = u - p->u0, wu = p->w * u + p->phi, w0 = p->w * p->u0 + p->phi;
    double k = p->c1 / p->w;
    f[3] = p->c1 * p->w * cos(wu);
    f[2] = p->c0 + p->c1 * sin(wu);
    f[1] = p->f1 + p->c0 * h - k * (cos(wu) - cos(w0));
    f[0] = p->f0 + p->f1 * h + 0.5 * p->c0 * h * h - k * ((sin(wu) - sin(w0)) / p->w - cos(w0) * h);
}

RT_LAWFN double rt_law_eval3(const rt_law *l, double t, double *buf, double d[3]);

RT_LAWFN void rt_shape_eval(const rt_segment *sg, double u, double f[4])
{
    const double PI = 3.14159265358979323846;
    double c, s, u2 = u * u;
    switch (sg->shape) {
    case RT_SHAPE_CYCLOIDAL:  /* u - sin(2 pi u) / (2 pi) */
        c = cos(2 * PI * u), s = sin(2 * PI * u);
        f[0] = u - s / (2 * PI), f[1] = 1 - c, f[2] = 2 * PI * s, f[3] = 4 * PI * PI * c;
        break;
    case RT_SHAPE_HARMONIC:  /* (1 - cos(pi u)) / 2 */
        c = cos(PI * u), s = sin(PI * u);
        f[0] = 0.5 * (1 - c), f[1] = 0.5 * PI * s, f[2] = 0.5 * PI * PI * c;
        f[3] = -0.5 * PI * PI * PI * s;
        break;
    case RT_SHAPE_345:  /* 10 u^3 - 15 u^4 + 6 u^5 */
        f[0] = u2 * u * (10 + u * (-15 + 6 * u));
        f[1] = u2 * (30 + u * (-60 + 30 * u));
        f[2] = u * (60 + u * (-180 + 120 * u));
        f[3] = 60 + u * (-360 + 360 * u);
        break;
    case RT_SHAPE_4567:  /* 35 u^4 - 84 u^5 + 70 u^6 - 20 u^7 */
        f[0] = u2 * u2 * (35 + u * (-84 + u * (70 - 20 * u)));
        f[1] = u2 * u * (140 + u * (-420 + u * (420 - 140 * u)));
        f[2] = u2 * (420 + u * (-1680 + u * (2100 - 840 * u)));
        f[3] = u * (840 + u * (-5040 + u * (8400 - 4200 * u)));
        break;
    case RT_SHAPE_MODTRAP:
    case RT_SHAPE_MODSINE: {
        int j = sg->npieces - 1;
        while (j > 0 && u < sg->piece[j].u0)
            j--;
        rt_piece_at(&sg->piece[j], u, f);
        break;
    }
    case RT_SHAPE_CUBIC: {  /* a spline's piece (a cam's profile points): piece[0] holds
                               f = f1 u + c0 u^2 / 2 + c1 u^3 / 6 */
        const rt_piece *p = &sg->piece[0];
        f[3] = p->c1;
        f[2] = p->c0 + p->c1 * u;
        f[1] = p->f1 + u * (p->c0 + 0.5 * p->c1 * u);
        f[0] = u * (p->f1 + u * (0.5 * p->c0 + p->c1 * u / 6.0));
        break;
    }
    case RT_SHAPE_USER: {
        double buf[4 * RT_LAW_USER_MAX], d[3];
        f[0] = rt_law_eval3(&sg->user, u, buf, d);
        f[1] = d[0], f[2] = d[1], f[3] = d[2];
        break;
    }
    default: f[0] = f[1] = f[2] = f[3] = 0.0; break;  /* a dwell */
    }
}

/* s(x) and its derivatives d[0..3] in x: the segment of x in its period */
RT_LAWFN void rt_program_eval(const rt_program *p, double x, double d[4])
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
    const rt_segment *sg = &p->seg[lo];
    double u = (xl - sg->x0) / sg->span, f[4];
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    rt_shape_eval(sg, u, f);
    double b = sg->span;
    d[0] = p->start + k * p->net + sg->s0 + sg->lift * f[0];
    d[1] = sg->lift * f[1] / b;
    d[2] = sg->lift * f[2] / (b * b);
    d[3] = sg->lift * f[3] / (b * b * b);
}

/* The law's value at t and d[0..2] its first three derivatives (d may be
 * NULL), each node into buf[4 * n] */
RT_LAWFN double rt_law_eval3(const rt_law *l, double t, double *buf, double d[3])
{
    for (int i = 0; i < l->n; i++) {
        const rt_law_node *nd = &l->nodes[i];
        double *f = buf + 4 * i, g[4];
        const double *a = nd->a >= 0 ? buf + 4 * nd->a : NULL;
        const double *b = nd->b >= 0 ? buf + 4 * nd->b : NULL;
        switch (nd->op) {
        case RT_LAW_CONST: f[0] = nd->k, f[1] = f[2] = f[3] = 0.0; break;
        case RT_LAW_T: f[0] = t, f[1] = 1.0, f[2] = f[3] = 0.0; break;
        case RT_LAW_ADD:
            for (int k = 0; k < 4; k++)
                f[k] = a[k] + b[k];
            break;
        case RT_LAW_NEG:
            for (int k = 0; k < 4; k++)
                f[k] = -a[k];
            break;
        case RT_LAW_MUL: rt_law_product(a, b, f); break;
        case RT_LAW_DIV: {
            double inv[4];
            rt_law_elementary(RT_LAW_DIV, b[0], g);
            rt_law_chain(g, b, inv);
            rt_law_product(a, inv, f);
            break;
        }
        case RT_LAW_ATAN2: rt_law_atan2(a, b, f); break;
        case RT_LAW_ABS: case RT_LAW_STEP: case RT_LAW_SIGN: rt_law_piecewise(nd->op, a, f); break;
        case RT_LAW_MIN: case RT_LAW_MAX:
            rt_law_extremum(nd->op == RT_LAW_MIN ? -1 : 1, a, b, f);
            break;
        case RT_LAW_PROGRAM:
            rt_program_eval(l->progs[nd->b], a[0], g);
            rt_law_chain(g, a, f);
            break;
        default:  /* sin cos tan tanh exp log sqrt */
            rt_law_elementary(nd->op, a[0], g);
            rt_law_chain(g, a, f);
            break;
        }
    }
    const double *r = l->root >= 0 && l->root < l->n ? buf + 4 * l->root : NULL;
    if (d) {
        d[0] = r ? r[1] : NAN;
        d[1] = r ? r[2] : NAN;
        d[2] = r ? r[3] : NAN;
    }
    return r ? r[0] : NAN;
}

/* The law's order-th derivative at t (0: its value; 1, 2, 3), buf[4 * n]:
 * what the DAG's call of an opaque law asks (libmech's tape and the
 * generated code alike) */
RT_LAWFN double rt_law_call(const rt_law *l, int order, double t, double *buf)
{
    double d[3], r = rt_law_eval3(l, t, buf, d);
    if (order == 0)
        return r;
    if (isnan(r))
        return NAN;
    return order <= 3 ? d[order - 1] : NAN;
}

#endif
