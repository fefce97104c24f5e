/* src/symbolic/expr.c: hash-consed expression DAG. Constructors simplify exactly
 * (x + 0, 0 * x, 1 * x, --x, folding of constants: the folded value is the
 * one the evaluator would compute, so nothing changes numerically). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "symbolic.h"
#include "base.h"

static size_t hash_node(expr_op op, int var, ex a, ex b, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    uint64_t h = 0x9e3779b97f4a7c15u * ((uint64_t)op + 1);
    h ^= (uint64_t)(uint32_t)var * 0xff51afd7ed558ccdu;
    h = (h ^ (uint64_t)(uint32_t)a) * 0xc4ceb9fe1a85ec53u;
    h = (h ^ (uint64_t)(uint32_t)b) * 0x9e3779b97f4a7c15u;
    h ^= bits * 0xff51afd7ed558ccdu;
    return (size_t)(h ^ (h >> 29));
}

static int same_node(const expr_node *n, expr_op op, int var, ex a, ex b, double v)
{
    return n->op == op && n->var == var && n->a == a && n->b == b &&
           memcmp(&n->value, &v, sizeof v) == 0;  /* -0.0 and 0.0 stay distinct */
}

static int grow_table(expr_ctx *c)
{
    size_t cap = c->tcap ? 2 * c->tcap : 1024;
    int *t = xrealloc_array(NULL, cap, sizeof *t);
    if (!t)
        return -1;
    for (size_t i = 0; i < cap; i++)
        t[i] = -1;
    for (size_t k = 0; k < c->count; k++) {
        const expr_node *n = &c->nodes[k];
        size_t i = hash_node(n->op, n->var, n->a, n->b, n->value) & (cap - 1);
        while (t[i] >= 0)
            i = (i + 1) & (cap - 1);
        t[i] = (int)k;
    }
    free(c->table);
    c->table = t;
    c->tcap = cap;
    return 0;
}

/* Node (op, var, a, b, v) found in the hash table (c->tcap > 0), or -1
 * with *slot the empty slot where it would go. */
static inline ex probe(const expr_ctx *c, expr_op op, int var, ex a, ex b, double v,
                       size_t *slot)
{
    size_t i = hash_node(op, var, a, b, v) & (c->tcap - 1);
    for (; c->table[i] >= 0; i = (i + 1) & (c->tcap - 1))
        if (same_node(&c->nodes[c->table[i]], op, var, a, b, v))
            return c->table[i];
    *slot = i;
    return -1;
}

/* The node (op, var, a, b, v) if the DAG holds it, else -1 (nothing made). */
ex expr_find(const expr_ctx *c, expr_op op, int var, ex a, ex b, double v)
{
    size_t slot;
    return c->failed || c->tcap == 0 ? -1 : probe(c, op, var, a, b, v, &slot);
}

/* The unique node (op, var, a, b, v): found, or made. */
static ex intern(expr_ctx *c, expr_op op, int var, ex a, ex b, double v)
{
    if (c->failed)
        return 0;
    if (2 * (c->count + 1) > c->tcap && grow_table(c) < 0)
        goto oom;
    size_t i;
    ex found = probe(c, op, var, a, b, v, &i);
    if (found >= 0)
        return found;
    if (c->count == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 1024;
        expr_node *n = cap > INT32_MAX ? NULL : xrealloc_array(c->nodes, cap, sizeof *n);
        if (!n)
            goto oom;
        c->nodes = n;
        c->cap = cap;
    }
    expr_node *n = &c->nodes[c->count];
    *n = (expr_node){op, var, a, b, v, -1, 0};
    c->table[i] = (int)c->count;
    return (ex)c->count++;
oom:
    c->failed = 1;
    return 0;
}

int expr_init(expr_ctx *c)
{
    memset(c, 0, sizeof *c);
    c->zero = expr_const(c, 0.0);
    c->one = expr_const(c, 1.0);
    return c->failed ? -1 : 0;
}

void expr_free(expr_ctx *c)
{
    free(c->fns);
    free(c->nodes);
    free(c->table);
    memset(c, 0, sizeof *c);
}

ex expr_const(expr_ctx *c, double v)
{
    return intern(c, EX_CONST, -1, -1, -1, v == 0.0 ? 0.0 : v);  /* -0 -> 0 */
}

/* sin and cos of a constant angle. The double nearest a multiple of pi/2
 * (as "90 deg" becomes) stands for that multiple: its sine and cosine are
 * exactly 0 or +-1, not 6e-17, so a vertical guide has no spurious term. */
static double quadrant_exact(double v, int want_sin)
{
    const double half_pi = 1.57079632679489661923;
    double r = v / half_pi, k = nearbyint(r);
    if (fabs(r - k) > 4e-16 * fmax(1.0, fabs(k)) || fabs(k) > 1e6)
        return want_sin ? sin(v) : cos(v);
    long q = ((long)k % 4 + 4) % 4;  /* quadrant */
    static const double s[4] = {0, 1, 0, -1}, co[4] = {1, 0, -1, 0};
    return want_sin ? s[q] : co[q];
}
ex expr_var(expr_ctx *c, int var) { return intern(c, EX_VAR, var, -1, -1, 0.0); }

static int is_const(const expr_ctx *c, ex e) { return c->nodes[e].op == EX_CONST; }
static double cval(const expr_ctx *c, ex e) { return c->nodes[e].value; }

ex expr_neg(expr_ctx *c, ex a)
{
    if (is_const(c, a))
        return expr_const(c, -cval(c, a));
    if (c->nodes[a].op == EX_NEG)
        return c->nodes[a].a;
    if (c->nodes[a].op == EX_MUL && is_const(c, c->nodes[a].a)) {  /* -(k x) = (-k) x, exact */
        double k = cval(c, c->nodes[a].a);
        ex x = c->nodes[a].b;
        return expr_mul(c, expr_const(c, -k), x);
    }
    return intern(c, EX_NEG, -1, a, -1, 0.0);
}

ex expr_add(expr_ctx *c, ex a, ex b)
{
    if (is_const(c, a) && is_const(c, b))
        return expr_const(c, cval(c, a) + cval(c, b));
    if (expr_is_const(c, a, 0.0))
        return b;
    if (expr_is_const(c, b, 0.0))
        return a;
    if ((c->nodes[b].op == EX_NEG && c->nodes[b].a == a) ||
        (c->nodes[a].op == EX_NEG && c->nodes[a].a == b))
        return c->zero;  /* x - x */
    if (c->nodes[a].op == EX_NEG && c->nodes[b].op == EX_NEG) {
        ex x = c->nodes[a].a, y = c->nodes[b].a;
        return expr_neg(c, expr_add(c, x, y));
    }
    return intern(c, EX_ADD, -1, a, b, 0.0);
}

ex expr_sub(expr_ctx *c, ex a, ex b) { return expr_add(c, a, expr_neg(c, b)); }

ex expr_mul(expr_ctx *c, ex a, ex b)
{
    if (is_const(c, b) && !is_const(c, a)) {  /* constant factor first */
        ex t = a;
        a = b;
        b = t;
    }
    if (is_const(c, a)) {
        double v = cval(c, a);
        if (is_const(c, b))
            return expr_const(c, v * cval(c, b));
        if (v == 0.0)
            return c->zero;
        if (v == 1.0)
            return b;
        if (v == -1.0)
            return expr_neg(c, b);
        if (c->nodes[b].op == EX_NEG) {  /* k * -x = (-k) * x */
            ex x = c->nodes[b].a;  /* read before a constructor may move nodes */
            return expr_mul(c, expr_const(c, -v), x);
        }
    }
    if (c->nodes[a].op == EX_NEG) {
        ex x = c->nodes[a].a;
        return expr_neg(c, expr_mul(c, x, b));
    }
    /* keep a constant factor in front: (k x) y = k (x y), so products print
     * as the papers write them and signs are visible to the printer */
    if (!is_const(c, a) && c->nodes[a].op == EX_MUL && is_const(c, c->nodes[a].a)) {
        ex k = c->nodes[a].a, x = c->nodes[a].b;
        return expr_mul(c, k, expr_mul(c, x, b));
    }
    if (!is_const(c, a) && c->nodes[b].op == EX_MUL && is_const(c, c->nodes[b].a)) {
        ex k = c->nodes[b].a, x = c->nodes[b].b;
        return expr_mul(c, k, expr_mul(c, a, x));
    }
    if (c->nodes[b].op == EX_NEG) {
        ex x = c->nodes[b].a;
        return expr_neg(c, expr_mul(c, a, x));
    }
    return intern(c, EX_MUL, -1, a, b, 0.0);
}

ex expr_sin(expr_ctx *c, ex a)
{
    if (is_const(c, a))
        return expr_const(c, quadrant_exact(cval(c, a), 1));
    return intern(c, EX_SIN, -1, a, -1, 0.0);
}

ex expr_cos(expr_ctx *c, ex a)
{
    if (is_const(c, a))
        return expr_const(c, quadrant_exact(cval(c, a), 0));
    return intern(c, EX_COS, -1, a, -1, 0.0);
}

int expr_fn_add(expr_ctx *c, const expr_fn *fn)
{
    for (int k = 0; k < c->nfns; k++)
        if (c->fns[k].eval == fn->eval && c->fns[k].data == fn->data)
            return k;
    expr_fn *more = xrealloc_array(c->fns, (size_t)c->nfns + 1, sizeof *more);
    if (!more) {
        c->failed = 1;
        return -1;
    }
    c->fns = more;
    c->fns[c->nfns] = *fn;
    return c->nfns++;
}

/* Not folded when a is a constant: the value may be NaN (a law where it is
 * not defined), which the caller must see where it is evaluated. */
ex expr_call(expr_ctx *c, int fn, int order, ex a)
{
    if (fn < 0 || fn >= c->nfns) {
        c->failed = 1;
        return 0;
    }
    return intern(c, EX_CALL, fn, a, -1, (double)order);
}

/* ---- traversals ----------------------------------------------------- */

static ex diff_rec(expr_ctx *c, ex e, int var)
{
    if (c->nodes[e].stamp == c->stamp)
        return c->nodes[e].memo;
    expr_node n = c->nodes[e];  /* copy: constructors may move the array */
    ex r;
    switch (n.op) {
    case EX_CONST:
        r = c->zero;
        break;
    case EX_VAR:
        r = n.var == var ? c->one : c->zero;
        break;
    case EX_ADD:
        r = expr_add(c, diff_rec(c, n.a, var), diff_rec(c, n.b, var));
        break;
    case EX_MUL: {
        ex da = diff_rec(c, n.a, var), db = diff_rec(c, n.b, var);
        r = expr_add(c, expr_mul(c, da, n.b), expr_mul(c, n.a, db));
        break;
    }
    case EX_NEG:
        r = expr_neg(c, diff_rec(c, n.a, var));
        break;
    case EX_SIN:
        r = expr_mul(c, diff_rec(c, n.a, var), expr_cos(c, n.a));
        break;
    case EX_COS:
        r = expr_neg(c, expr_mul(c, diff_rec(c, n.a, var), expr_sin(c, n.a)));
        break;
    case EX_CALL: {
        ex da = diff_rec(c, n.a, var);
        r = expr_is_const(c, da, 0.0) ? c->zero
                                       : expr_mul(c, da, expr_call(c, n.var, (int)n.value + 1, n.a));
        break;
    }
    default:
        abort(); /* unknown op: a new op needs a rule here */
    }
    if (c->failed)
        return 0;
    c->nodes[e].stamp = c->stamp;
    c->nodes[e].memo = r;
    return r;
}

ex expr_diff(expr_ctx *c, ex e, int var)
{
    c->stamp++;
    return diff_rec(c, e, var);
}

static int vars_rec(expr_ctx *c, ex e, int *vars, int n, int max)
{
    if (c->nodes[e].stamp == c->stamp)
        return n;
    c->nodes[e].stamp = c->stamp;
    const expr_node *nd = &c->nodes[e];
    if (nd->op == EX_VAR) {
        if (n < max)
            vars[n] = nd->var;
        return n + 1;
    }
    if (nd->a >= 0)
        n = vars_rec(c, nd->a, vars, n, max);
    if (nd->b >= 0)
        n = vars_rec(c, c->nodes[e].b, vars, n, max);
    return n;
}

int expr_vars(expr_ctx *c, ex e, int *vars, int max)
{
    c->stamp++;
    return vars_rec(c, e, vars, 0, max);
}

static double eval_rec(const expr_ctx *c, ex e, const double *vars)
{
    const expr_node *n = &c->nodes[e];
    switch (n->op) {
    case EX_CONST: return n->value;
    case EX_VAR: return vars[n->var];
    case EX_ADD: return eval_rec(c, n->a, vars) + eval_rec(c, n->b, vars);
    case EX_MUL: return eval_rec(c, n->a, vars) * eval_rec(c, n->b, vars);
    case EX_NEG: return -eval_rec(c, n->a, vars);
    case EX_SIN: return sin(eval_rec(c, n->a, vars));
    case EX_COS: return cos(eval_rec(c, n->a, vars));
    case EX_CALL: {
        const expr_fn *f = &c->fns[n->var];
        return f->eval(f->data, (int)n->value, eval_rec(c, n->a, vars));
    }
    }
    abort(); /* unknown op */
}

double expr_eval(expr_ctx *c, ex e, const double *vars) { return eval_rec(c, e, vars); }

/* ---- printing -------------------------------------------------------- */

enum { PREC_SUM = 1, PREC_PRODUCT = 2, PREC_UNARY = 3, PREC_ATOM = 4 };

static int precedence(const expr_node *n)
{
    switch (n->op) {
    case EX_ADD: return PREC_SUM;
    case EX_MUL: return PREC_PRODUCT;
    case EX_NEG: return PREC_UNARY;
    default: return PREC_ATOM;
    }
}

static void print_const(double v, FILE *out) { fprintf(out, "%.10g", v); }

static void print_rec(const expr_ctx *c, ex e, const expr_names *nm, int latex, FILE *out, int ctx);
static void print_product(const expr_ctx *c, ex e, const expr_names *nm, int latex, FILE *out);

/* A sum, flattened: a + b - c ... (a negated term prints as " - term"). */
static void print_sum(const expr_ctx *c, ex e, const expr_names *nm, int latex, FILE *out,
                      int *first)
{
    const expr_node *n = &c->nodes[e];
    if (n->op == EX_ADD) {
        print_sum(c, n->a, nm, latex, out, first);
        print_sum(c, n->b, nm, latex, out, first);
        return;
    }
    int neg = n->op == EX_NEG || (n->op == EX_CONST && n->value < 0) ||
              (n->op == EX_MUL && c->nodes[n->a].op == EX_CONST && c->nodes[n->a].value < 0);
    if (!*first)
        fputs(neg ? " - " : " + ", out);
    else if (neg)
        fputs("-", out);
    *first = 0;
    if (!neg) {
        print_rec(c, e, nm, latex, out, PREC_SUM);
    } else if (n->op == EX_NEG) {
        print_rec(c, n->a, nm, latex, out, PREC_SUM + 1);
    } else if (n->op == EX_CONST) {
        print_const(-n->value, out);
    } else {  /* (-k) * x */
        double k = -c->nodes[n->a].value;
        if (k != 1.0) {
            print_const(k, out);
            fputs(latex ? " " : "*", out);
        }
        print_rec(c, n->b, nm, latex, out, PREC_PRODUCT);
    }
}

enum { MAX_FACTORS = 64 };

/* The factors of a product tree, left to right (at most max; -1 if more). */
static int factors(const expr_ctx *c, ex e, ex *f, int nf, int max)
{
    const expr_node *n = &c->nodes[e];
    if (n->op != EX_MUL) {
        if (nf < 0 || nf >= max)
            return -1;
        f[nf] = e;
        return nf + 1;
    }
    return factors(c, n->b, f, factors(c, n->a, f, nf, max), max);
}

/* A product, its factors in order of first appearance, a repeated factor
 * once with its power: l*cos(th)*th'*th' prints as l*cos(th)*th'^2. */
static void print_product(const expr_ctx *c, ex e, const expr_names *nm, int latex, FILE *out)
{
    ex f[MAX_FACTORS];
    int nf = factors(c, e, f, 0, MAX_FACTORS), printed = 0;
    if (nf < 0) {  /* very long: as it is */
        print_rec(c, c->nodes[e].a, nm, latex, out, PREC_PRODUCT);
        fputs(latex ? " " : "*", out);
        print_rec(c, c->nodes[e].b, nm, latex, out, PREC_PRODUCT);
        return;
    }
    for (int i = 0; i < nf; i++) {
        int power = 1, seen = 0;
        for (int j = 0; j < i; j++)
            seen |= f[j] == f[i];
        if (seen)
            continue;
        for (int j = i + 1; j < nf; j++)
            power += f[j] == f[i];
        if (printed++)
            fputs(latex ? " " : "*", out);
        print_rec(c, f[i], nm, latex, out, power > 1 ? PREC_ATOM : PREC_PRODUCT);
        if (power > 1)
            fprintf(out, latex ? "^{%d}" : "^%d", power);
    }
}

static void print_rec(const expr_ctx *c, ex e, const expr_names *nm, int latex, FILE *out, int ctx)
{
    const expr_node *n = &c->nodes[e];
    int paren = precedence(n) < ctx;
    if (paren)
        fputs(latex ? "\\left(" : "(", out);
    switch (n->op) {
    case EX_CONST:
        print_const(n->value, out);
        break;
    case EX_VAR:
        fputs(latex ? nm->latex[n->var] : nm->text[n->var], out);
        break;
    case EX_ADD: {
        int first = 1;
        print_sum(c, e, nm, latex, out, &first);
        break;
    }
    case EX_MUL:
        print_product(c, e, nm, latex, out);
        break;
    case EX_NEG:
        fputs("-", out);  /* -(a*b) reads as -a*b */
        print_rec(c, n->a, nm, latex, out, PREC_PRODUCT);
        break;
    case EX_SIN:
    case EX_COS:
        fputs(n->op == EX_SIN ? (latex ? "\\sin" : "sin") : (latex ? "\\cos" : "cos"), out);
        fputs(latex ? "\\left(" : "(", out);
        print_rec(c, n->a, nm, latex, out, 0);
        fputs(latex ? "\\right)" : ")", out);
        break;
    case EX_CALL: {  /* p_crank(t), p_crank'(t), p_crank''(t), p_crank^(3)(t) */
        int k = (int)n->value;
        if (latex) {  /* \mathrm{p\_crank}: a name's underscores are no subscripts */
            fputs("\\mathrm{", out);
            for (const char *ch = c->fns[n->var].name; *ch; ch++)
                fputs(*ch == '_' ? "\\_" : (char[2]){*ch, 0}, out);
            fputs("}", out);
        } else {
            fputs(c->fns[n->var].name, out);
        }
        if (k > 0 && k <= 2)
            fputs(k == 1 ? "'" : "''", out);
        else if (k > 2)
            fprintf(out, latex ? "^{(%d)}" : "^(%d)", k);
        fputs(latex ? "\\left(" : "(", out);
        print_rec(c, n->a, nm, latex, out, 0);
        fputs(latex ? "\\right)" : ")", out);
        break;
    }
    }
    if (paren)
        fputs(latex ? "\\right)" : ")", out);
}

void expr_print(const expr_ctx *c, ex e, const expr_names *names, int latex, FILE *out)
{
    print_rec(c, e, names, latex, out, 0);
}
