/* src/load/law_eval.c: a law's value and its first three derivatives
 * (forward differentiation of the tree, exact: no difference quotient),
 * where it is not defined and why, and the law as an opaque function of
 * the DAG (docs/motion-programs.md, "Laws of time").
 *
 * Every function of one argument g(a) goes through Faa di Bruno's formula
 * with g and its derivatives at the argument's value:
 *     f' = g' a',  f'' = g' a'' + g'' a'^2,  f''' = g' a''' + 3 g'' a' a'' + g''' a'^3,
 * so a new function is its four values g, g', g'', g''' and nothing else. */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "load.h"

/* f[0..3] of g(a) from g[0..3] at a's value and a's derivatives a[0..3] */
static void chain(const double g[4], const double a[4], double f[4])
{
    f[0] = g[0];
    f[1] = g[1] * a[1];
    f[2] = g[1] * a[2] + g[2] * a[1] * a[1];
    f[3] = g[1] * a[3] + 3.0 * g[2] * a[1] * a[2] + g[3] * a[1] * a[1] * a[1];
}

static void product(const double a[4], const double b[4], double f[4])
{
    f[0] = a[0] * b[0];
    f[1] = a[1] * b[0] + a[0] * b[1];
    f[2] = a[2] * b[0] + 2.0 * a[1] * b[1] + a[0] * b[2];
    f[3] = a[3] * b[0] + 3.0 * (a[2] * b[1] + a[1] * b[2]) + a[0] * b[3];
}

/* g, g', g'', g''' of the elementary function of op at x */
static void elementary(law_op op, double x, double g[4])
{
    switch (op) {
    case LAW_SIN: {
        double s = sin(x), c = cos(x);
        g[0] = s, g[1] = c, g[2] = -s, g[3] = -c;
        break;
    }
    case LAW_COS: {
        double s = sin(x), c = cos(x);
        g[0] = c, g[1] = -s, g[2] = -c, g[3] = s;
        break;
    }
    case LAW_TAN: {  /* v' = 1 + v^2 */
        double v = tan(x), w = 1.0 + v * v;
        g[0] = v, g[1] = w, g[2] = 2.0 * v * w, g[3] = 2.0 * w * (1.0 + 3.0 * v * v);
        break;
    }
    case LAW_TANH: {  /* v' = 1 - v^2 */
        double v = tanh(x), w = 1.0 - v * v;
        g[0] = v, g[1] = w, g[2] = -2.0 * v * w, g[3] = -2.0 * w * (1.0 - 3.0 * v * v);
        break;
    }
    case LAW_EXP:
        g[0] = g[1] = g[2] = g[3] = exp(x);
        break;
    case LAW_LOG:  /* NaN at x <= 0: not defined there */
        g[0] = x > 0 ? log(x) : NAN;
        g[1] = 1.0 / x, g[2] = -g[1] * g[1], g[3] = 2.0 * g[1] * g[1] * g[1];
        if (!(x > 0))
            g[1] = g[2] = g[3] = NAN;
        break;
    case LAW_SQRT: {  /* at 0 the rate is infinite: NaN */
        double r = x >= 0 ? sqrt(x) : NAN;
        g[0] = r;
        g[1] = r > 0 ? 0.5 / r : NAN;
        g[2] = r > 0 ? -0.5 * g[1] / x : NAN;
        g[3] = r > 0 ? -1.5 * g[2] / x : NAN;
        break;
    }
    default: {  /* 1 / x (LAW_DIV's divisor) */
        double i = 1.0 / x;
        if (x == 0.0)
            i = NAN;
        g[0] = i, g[1] = -i * i, g[2] = 2.0 * i * i * i, g[3] = -6.0 * i * i * i * i;
        break;
    }
    }
}

/* atan2(y, x) = arg z, z = x + i y: its derivatives are Im of those of log z */
static void atan2_of(const double y[4], const double x[4], double f[4])
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

/* abs, step, sign: piecewise; at a zero of the argument the derivatives
 * exist only while it stays on one side */
static void piecewise(law_op op, const double a[4], double f[4])
{
    if (op == LAW_ABS) {
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
    f[0] = op == LAW_STEP ? (a[0] > 0 ? 1.0 : 0.0) : (a[0] > 0 ? 1.0 : a[0] < 0 ? -1.0 : 0.0);
    int flat = a[0] != 0 || (a[1] == 0 && a[2] == 0 && a[3] == 0);
    f[1] = f[2] = f[3] = flat ? 0.0 : NAN;  /* it jumps here */
}

/* min (want < 0) or max of two: the branch below (above); where they meet
 * with different rates, a corner: no derivative */
static void extremum(int want, const double a[4], const double b[4], double f[4])
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

static void program_of(const struct mech_law *l, const law_node *nd, const double a[4],
                       double f[4])
{
    double g[4];
    program_eval(l->progs[nd->b], a[0], g);
    chain(g, a, f);
}

double law_eval3(const struct mech_law *l, double t, double *buf, double d[3])
{
    for (int i = 0; i < l->n; i++) {
        const law_node *nd = &l->nodes[i];
        double *f = buf + 4 * i, g[4];
        const double *a = nd->a >= 0 ? buf + 4 * nd->a : NULL;
        const double *b = nd->b >= 0 ? buf + 4 * nd->b : NULL;
        switch (nd->op) {
        case LAW_CONST: f[0] = nd->k, f[1] = f[2] = f[3] = 0.0; break;
        case LAW_T: f[0] = t, f[1] = 1.0, f[2] = f[3] = 0.0; break;
        case LAW_ADD:
            for (int k = 0; k < 4; k++)
                f[k] = a[k] + b[k];
            break;
        case LAW_NEG:
            for (int k = 0; k < 4; k++)
                f[k] = -a[k];
            break;
        case LAW_MUL: product(a, b, f); break;
        case LAW_DIV: {
            double inv[4];
            elementary(LAW_DIV, b[0], g);
            chain(g, b, inv);
            product(a, inv, f);
            break;
        }
        case LAW_ATAN2: atan2_of(a, b, f); break;
        case LAW_ABS: case LAW_STEP: case LAW_SIGN: piecewise(nd->op, a, f); break;
        case LAW_MIN: case LAW_MAX: extremum(nd->op == LAW_MIN ? -1 : 1, a, b, f); break;
        case LAW_PROGRAM: program_of(l, nd, a, f); break;
        default:  /* sin cos tan tanh exp log sqrt */
            elementary(nd->op, a[0], g);
            chain(g, a, f);
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

double law_eval(const struct mech_law *l, double t, double *dt, double *dtt)
{
    double buf[4 * LAW_MAX_NODES], d[3];  /* no allocation: called at every step */
    double r = law_eval3(l, t, buf, d);
    if (dt)
        *dt = isnan(r) ? NAN : d[0];
    if (dtt)
        *dtt = isnan(r) ? NAN : d[1];
    return r;
}

double law_fn_eval(const void *data, int order, double t)
{
    double d[3], r = law_eval(data, t, &d[0], &d[1]);
    if (order == 0)
        return r;
    if (order <= 2)
        return d[order - 1];
    double buf[4 * LAW_MAX_NODES];
    law_eval3(data, t, buf, d);
    return order == 3 ? d[2] : NAN;  /* the DAG never goes past the acceleration's rate */
}

int law_is_opaque(const struct mech_law *l)
{
    for (int i = 0; i < l->n; i++)
        if (l->nodes[i].op > LAW_COS)
            return 1;
    return 0;
}

static const char *op_name(law_op op)
{
    static const char *const names[] = {
        [LAW_DIV] = "a division", [LAW_EXP] = "exp", [LAW_LOG] = "log", [LAW_SQRT] = "sqrt",
        [LAW_TAN] = "tan", [LAW_TANH] = "tanh", [LAW_ATAN2] = "atan2", [LAW_ABS] = "abs",
        [LAW_MIN] = "min", [LAW_MAX] = "max", [LAW_STEP] = "step", [LAW_SIGN] = "sign",
        [LAW_PROGRAM] = "the motion program", [LAW_SIN] = "sin", [LAW_COS] = "cos",
        [LAW_MUL] = "a product", [LAW_ADD] = "a sum"};
    return op < (int)(sizeof names / sizeof names[0]) && names[op] ? names[op] : "an operation";
}

/* why node nd (its operands finite) is not: its value (order 0) or a rate */
static void describe(const law_node *nd, const double *buf, int order, char *why, size_t size)
{
    const double *a = nd->a >= 0 ? buf + 4 * nd->a : NULL;
    const double *b = nd->b >= 0 ? buf + 4 * nd->b : NULL;
    double x = a ? a[0] : 0.0;
    const char *rate = order == 1 ? "its rate" : "its second derivative";
    switch (nd->op) {
    case LAW_DIV: snprintf(why, size, "division by zero (the divisor is %g)", b ? b[0] : 0.0); break;
    case LAW_LOG: snprintf(why, size, "log of %g (log needs a positive number)", x); break;
    case LAW_SQRT:
        snprintf(why, size, x < 0 ? "sqrt of a negative number (%g)"
                                  : "sqrt at %g, where %s is infinite", x, rate);
        break;
    case LAW_ATAN2: snprintf(why, size, "atan2(0, 0): no angle"); break;
    case LAW_ABS: case LAW_STEP: case LAW_SIGN: case LAW_MIN: case LAW_MAX:
        snprintf(why, size, "%s switches here (its argument crosses %s): %s does not exist",
                 op_name(nd->op), nd->op == LAW_MIN || nd->op == LAW_MAX ? "the other" : "0",
                 rate);
        break;
    default:
        snprintf(why, size, "%s of %g is not a finite number%s", op_name(nd->op), x,
                 order ? " in its derivatives" : "");
        break;
    }
}

int law_defined(const struct mech_law *l, double t, char *why, size_t size)
{
    double buf[4 * LAW_MAX_NODES];
    law_eval3(l, t, buf, NULL);
    for (int i = 0; i < l->n; i++)
        for (int k = 0; k < 3; k++)
            if (!isfinite(buf[4 * i + k])) {
                describe(&l->nodes[i], buf, k, why, size);
                return 0;
            }
    return 1;
}
