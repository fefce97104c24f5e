/* src/load/law_eval.c: a law's value and its first three derivatives
 * (forward differentiation of the tree, exact, no difference quotient:
 * src/runtime/rt_law.h, which the generated code shares), where it is not
 * defined and why, and the law as an opaque function of the DAG
 * (docs/motion-programs.md, "Laws of time"). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "load.h"

/* the rt view of a law (rt_law.h evaluates it) */
static rt_law view(const struct mech_law *l)
{
    return (rt_law){l->nodes, l->n, l->root, (const rt_program *const *)l->rtprogs};
}

double law_eval3(const struct mech_law *l, double t, double *buf, double d[3])
{
    rt_law v = view(l);
    return rt_law_eval3(&v, t, buf, d);
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
    double buf[4 * LAW_MAX_NODES];  /* no allocation: called at every step */
    rt_law v = view(data);
    return rt_law_call(&v, order, t, buf);
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
