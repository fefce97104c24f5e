/* src/load/param_expr.c: the model's parameter expressions (param_expr.h): the
 * trees the loader records over parameter leaves, their values and their
 * exact derivatives by a parameter.
 *
 * The derivative rules are forward mode (Griewank and Walther, "Evaluating
 * Derivatives", 2nd ed., SIAM 2008, chapter 3), one rule per operation, in
 * one place (px_deriv): used node after node for d/dp, and when a node
 * would have no parameter below it, to keep only the sign of its zero
 * derivative instead of the node. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

param_exprs *pexpr_new(void) { return xcalloc(1, sizeof(param_exprs)); }

void pexpr_free(param_exprs *pe)
{
    if (!pe)
        return;
    for (int l = 0; l < pe->npoint_links; l++)
        free(pe->point[l]);
    free(pe->point);
    free(pe->npoint);
    free(pe->node);
    free(pe->def);
    for (int k = 0; k < PXN_KINDS; k++)
        free(pe->table[k]);
    free(pe);
}

/* Operands each operation reads (a, then b, then c). */
static int arity(px_op op)
{
    switch (op) {
    case PX_CONST:
    case PX_PARAM:
        return 0;
    case PX_NEG:
    case PX_SCALE:
    case PX_POWI:
    case PX_SQRT:
    case PX_SIN:
    case PX_COS:
    case PX_TAN:
        return 1;
    case PX_POLAR_X:
    case PX_POLAR_Y:
        return 3;
    default:
        return 2;
    }
}

/* The derivative of node n (value n->value) from its operands' values va,
 * vb, vc and derivatives da, db, dc: the rules the quantity expressions
 * were differentiated by when each load carried one (forward mode). */
static double px_deriv(const px_node *n, double va, double vb, double vc, double da, double db,
                       double dc)
{
    switch (n->op) {
    case PX_CONST:
        return n->a ? -0.0 : 0.0;
    case PX_PARAM:
        return 0.0;  /* pexpr_derivatives: 1 for the parameter, else its definition's */
    case PX_NEG:
        return -da;
    case PX_SCALE:
        return da * n->k;
    case PX_ADD:
        return da + db;
    case PX_SUB:
        return da - db;
    case PX_MUL:
        return da * vb + va * db;
    case PX_DIV:  /* (a/b)' without b^2 underflowing */
        return da / vb - (va / vb) * (db / vb);
    case PX_POWI:
        return n->k == 0 ? 0.0 : n->k * pow(va, n->k - 1) * da;
    case PX_SQRT:
        return n->value > 0 ? da / (2.0 * n->value) : 0.0;
    case PX_SIN:
        return da * cos(va);
    case PX_COS:
        return da * -sin(va);
    case PX_TAN:
        return da * (1.0 + n->value * n->value);
    case PX_ATAN2: {  /* d atan2(y, x) = (x dy - y dx) / (x^2 + y^2) */
        double r2 = va * va + vb * vb;
        return r2 > 0 ? (vb * da - va * db) / r2 : 0.0;
    }
    case PX_HYPOT:
        return n->value > 0 ? (va * da + vb * db) / n->value : 0.0;
    case PX_POLAR_X:
        return da + db * cos(vc) - vb * sin(vc) * dc;
    case PX_POLAR_Y:
        return da + db * sin(vc) + vb * cos(vc) * dc;
    }
    return 0.0;
}

/* The value of op on operand values (pexpr_eval): as the loader computed it. */
static double px_value(const px_node *n, double a, double b, double c)
{
    switch (n->op) {
    case PX_CONST:
        return n->k;
    case PX_PARAM:
        return n->value;  /* pexpr_eval: the parameter's given value */
    case PX_NEG:
        return -a;
    case PX_SCALE:
        return a * n->k;
    case PX_ADD:
        return a + b;
    case PX_SUB:
        return a - b;
    case PX_MUL:
        return a * b;
    case PX_DIV:
        return a / b;
    case PX_POWI:
        return pow(a, n->k);
    case PX_SQRT:
        return sqrt(a);
    case PX_SIN:
        return sin(a);
    case PX_COS:
        return cos(a);
    case PX_TAN:
        return tan(a);
    case PX_ATAN2:
        return atan2(a, b);
    case PX_HYPOT:
        return hypot(a, b);
    case PX_POLAR_X:
        return a + b * cos(c);
    case PX_POLAR_Y:
        return a + b * sin(c);
    }
    return 0.0;
}

/* A node appended (its index), or -1 when out of memory. */
static int append(param_exprs *pe, px_node nd)
{
    if (pe->n == pe->cap) {
        int cap = pe->cap ? 2 * pe->cap : 64;
        px_node *more = xrealloc_array(pe->node, (size_t)cap, sizeof *more);
        if (!more) {
            pe->failed = 1;
            return -1;
        }
        pe->node = more;
        pe->cap = cap;
    }
    pe->node[pe->n] = nd;
    return pe->n++;
}

/* The node of operand q: itself, or a constant made for a fixed number. */
static int operand_node(param_exprs *pe, pxq q)
{
    if (q.h >= 0)
        return q.h;
    return append(pe, (px_node){PX_CONST, q.h == PX_FIXED_NEG, -1, -1, q.v, q.v});
}

static double fixed_deriv(int h) { return h == PX_FIXED_NEG ? -0.0 : 0.0; }

pxq pexpr_make(param_exprs *pe, px_op op, double k, pxq a, pxq b, pxq c, double value)
{
    pxq q[3] = {a, b, c};
    int na = arity(op), moving = 0;
    for (int i = 0; i < na; i++)
        moving |= q[i].h >= 0;
    px_node nd = {op, -1, -1, -1, k, value};
    if (!moving || pe->failed) {  /* no parameter below: only the sign of d/dp = 0 */
        double d = px_deriv(&nd, a.v, b.v, c.v, fixed_deriv(a.h), fixed_deriv(b.h),
                            fixed_deriv(c.h));
        return (pxq){value, signbit(d) && d == 0.0 ? PX_FIXED_NEG : PX_FIXED};
    }
    int *slot[3] = {&nd.a, &nd.b, &nd.c};
    for (int i = 0; i < na; i++)
        if ((*slot[i] = operand_node(pe, q[i])) < 0)
            return pxq_fixed(value);
    int h = append(pe, nd);
    return (pxq){value, h < 0 ? PX_FIXED : h};
}

pxq pexpr_param(param_exprs *pe, int k, double value)
{
    int h = append(pe, (px_node){PX_PARAM, k, -1, -1, 0.0, value});
    return (pxq){value, h < 0 ? PX_FIXED : h};
}

/* Room for entry i of a table of handles (new entries PX_FIXED); 0, or -1. */
static int grow(param_exprs *pe, int **table, int *count, int i)
{
    if (i < *count)
        return 0;
    int n = *count ? 2 * *count : 8;
    while (n <= i)
        n *= 2;
    int *more = xrealloc_array(*table, (size_t)n, sizeof *more);
    if (!more) {
        pe->failed = 1;
        return -1;
    }
    for (int k = *count; k < n; k++)
        more[k] = PX_FIXED;
    *table = more;
    *count = n;
    return 0;
}

void pexpr_set_param(param_exprs *pe, int k, int h)
{
    if (grow(pe, &pe->def, &pe->nparams, k) == 0)
        pe->def[k] = h;
}

void pexpr_set_point(param_exprs *pe, int link, int index, int h_x, int h_y)
{
    if (link >= pe->npoint_links) {
        int n = pe->npoint_links ? 2 * pe->npoint_links : 8;
        while (n <= link)
            n *= 2;
        int **more = xrealloc_array(pe->point, (size_t)n, sizeof *more);
        int *counts = more ? xrealloc_array(pe->npoint, (size_t)n, sizeof *counts) : NULL;
        if (more)
            pe->point = more;
        if (!counts) {
            pe->failed = 1;
            return;
        }
        pe->npoint = counts;
        for (int l = pe->npoint_links; l < n; l++) {
            pe->point[l] = NULL;
            pe->npoint[l] = 0;
        }
        pe->npoint_links = n;
    }
    if (grow(pe, &pe->point[link], &pe->npoint[link], 2 * index + 1) == 0) {
        pe->point[link][2 * index] = h_x;
        pe->point[link][2 * index + 1] = h_y;
    }
}

void pexpr_set(param_exprs *pe, pxn_kind kind, int index, int h)
{
    if (grow(pe, &pe->table[kind], &pe->ntable[kind], index) == 0)
        pe->table[kind][index] = h;
}

/* ---- reading ------------------------------------------------------------ */

int pexpr_point(const param_exprs *pe, int link, int index, int comp)
{
    if (!pe || link >= pe->npoint_links || 2 * index + comp >= pe->npoint[link])
        return PX_FIXED;
    return pe->point[link][2 * index + comp];
}

int pexpr_get(const param_exprs *pe, pxn_kind kind, int index)
{
    return pe && index < pe->ntable[kind] ? pe->table[kind][index] : PX_FIXED;
}

void pexpr_derivatives(const param_exprs *pe, int p, double *d)
{
    for (int i = 0; i < pe->n; i++) {
        const px_node *nd = &pe->node[i];
        if (nd->op == PX_PARAM) {
            int def = nd->a < pe->nparams ? pe->def[nd->a] : PX_FIXED;
            d[i] = nd->a == p ? 1.0 : pexpr_deriv_of(d, def);
            continue;
        }
        double va = 0.0, vb = 0.0, vc = 0.0, da = 0.0, db = 0.0, dc = 0.0;
        if (nd->a >= 0 && nd->op != PX_CONST)
            va = pe->node[nd->a].value, da = d[nd->a];
        if (nd->b >= 0)
            vb = pe->node[nd->b].value, db = d[nd->b];
        if (nd->c >= 0)
            vc = pe->node[nd->c].value, dc = d[nd->c];
        d[i] = px_deriv(nd, va, vb, vc, da, db, dc);
    }
}

void pexpr_eval(const param_exprs *pe, const double *pv, double *out)
{
    for (int i = 0; i < pe->n; i++) {
        const px_node *nd = &pe->node[i];
        if (nd->op == PX_PARAM) {
            out[i] = pv[nd->a];
            continue;
        }
        double a = nd->a >= 0 && nd->op != PX_CONST ? out[nd->a] : 0.0;
        double b = nd->b >= 0 ? out[nd->b] : 0.0, c = nd->c >= 0 ? out[nd->c] : 0.0;
        out[i] = px_value(nd, a, b, c);
    }
}

int pexpr_point_gradient(const mech_model *m, int p, double *out)
{
    const param_exprs *pe = m->pexpr;
    double *d = xcalloc(pe ? (size_t)pe->n + 1 : 1, sizeof *d);
    if (!d)
        return -1;
    if (pe)
        pexpr_derivatives(pe, p, d);
    for (int l = 0, g = 0; l < m->nlinks; l++)
        for (int i = 0; i < m->links[l].npoints; i++, g++)
            for (int c = 0; c < 2; c++)
                out[2 * g + c] = pexpr_deriv_of(d, pexpr_point(pe, l, i, c));
    free(d);
    return 0;
}
