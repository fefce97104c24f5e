/* src/load/drivers.c: laws of time for the drivers (drivers.h): the parser of
 * a law into a tree, its evaluation, its expression DAG, and the hooks the
 * system and the continuation call.
 *
 * The parser is qparse.c's (the grammar and the dimensions of a quantity
 * expression, as units.c reads them); this file is its backend for laws,
 * with one more name, t (a time, the sweep variable). Parts that do not
 * depend on t are numbers at once (any function: sqrt, sin, cos, tan,
 * atan2); a part that depends on t may be added, subtracted, multiplied,
 * divided by a number, raised to a power 0..64, and given to sin or cos.
 * A bare number (no unit) is a pure number under * and /, and takes the
 * other operand's default unit under + and -, as in units.c. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

/* ---- the parser: a backend of qparse.c ------------------------------------
 * A value is a number (qv.h < 0, qv.v) or the tree node qv.h of a part
 * that depends on t. The tree goes to p->ctx, the law. */

static const dim NONE = {{0, 0, 0, 0}};
static const dim TIME = {{0, 0, 1, 0}};
static const dim ANGLE = {{0, 0, 0, 1}};

int law_add_node(struct mech_law *l, law_op op, int a, int b, double k)
{
    if (l->n >= LAW_MAX_NODES)
        return -1;
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 16;
        law_node *more = xrealloc_array(l->nodes, (size_t)cap, sizeof *more);
        if (!more) {
            l->nomem = 1;
            return -1;
        }
        l->nodes = more;
        l->cap = cap;
    }
    l->nodes[l->n] = (law_node){op, a, b, k};
    return l->n++;
}

struct mech_law *law_new(char var)
{
    struct mech_law *l = xcalloc(1, sizeof *l);
    if (l) {
        l->var = var;
        l->root = -1;
    }
    return l;
}

static int node(qparse *p, law_op op, int a, int b, double k)
{
    struct mech_law *l = p->ctx;
    if (op == LAW_CONST && !isfinite(k)) {  /* "t + 0^-1 s": no law */
        qparse_fail(p, p->s, "value is not a finite number");
        return 0;
    }
    int i = law_add_node(l, op, a, b, k);
    if (i < 0) {
        if (l->nomem)
            qparse_fail(p, p->s, "out of memory");
        else  /* law_eval works in a fixed buffer */
            qparse_fail(p, p->s, "the law is too long (more than %d operations)", LAW_MAX_NODES);
        return 0;
    }
    return i;
}

static int as_node(qparse *p, qv a)
{
    return a.h >= 0 ? a.h : node(p, LAW_CONST, -1, -1, a.v);
}

static qv number(double v, dim d, int bare) { return (qv){v, -1, d, bare}; }

static qv scaled(qparse *p, qv a, double k)
{
    if (k == 1.0)
        return a;
    if (a.h < 0)
        return number(a.v * k, a.d, a.bare);
    a.h = node(p, LAW_MUL, node(p, LAW_CONST, -1, -1, k), a.h, 0.0);
    return a;
}

static qv l_constant(qparse *p, double v)
{
    (void)p;
    return number(v, NONE, 0);
}

/* t is the time here, not the tonne: "10 rad/s * t" has the unit rad/s, so
 * the unit is read from a copy cut before a word t (or u) */
static int l_unit(qparse *p, const char *u, double *scale, dim *d, const char **end)
{
    const struct mech_law *l = p->ctx;
    char buf[128];
    size_t len = 0;
    for (; u[len] && len + 1 < sizeof buf; len++) {
        int starts = (isalpha((unsigned char)u[len]) || u[len] == '_') &&
                     (len == 0 || !(isalnum((unsigned char)u[len - 1]) || u[len - 1] == '_'));
        if (starts && qparse_ident_len(u + len) == 1 && u[len] == l->var)
            break;
        buf[len] = u[len];
    }
    buf[len] = '\0';
    const char *uend;
    if (!unit_parse(buf, scale, d, &uend))
        return 0;
    *end = u + (uend - buf);
    return 1;
}

static int l_word(qparse *p, const char *at, size_t n, qv *out)
{
    const struct mech_law *l = p->ctx;
    if (!(n == 1 && *at == l->var))
        return 0;
    *out = (qv){0, node(p, LAW_T, -1, -1, 0.0), l->var == 't' ? TIME : NONE, 0};
    return 1;
}

/* The functions of laws: those of the loads (docs/format.md 10.2). */
static const char *const law_fns[] = {"sin", "cos", "tan", "sqrt", "atan2", "abs", "min", "max",
                                      "exp", "log", "tanh", "step", "sign", "smoothsign"};

static int two_args(const char *name, size_t n)
{
    return qparse_is_fn(name, n, "atan2") || qparse_is_fn(name, n, "min") ||
           qparse_is_fn(name, n, "max") || qparse_is_fn(name, n, "smoothsign");
}

static qv unary(qparse *p, law_op op, qv a, dim d, int bare)
{
    return (qv){0, node(p, op, a.h, -1, 0.0), d, bare};
}

static qv binary(qparse *p, law_op op, qv a, qv b, dim d, int bare)
{
    return (qv){0, node(p, op, as_node(p, a), as_node(p, b), 0.0), d, bare};
}

/* a function of constant arguments: a number (NaN when not defined) */
static double fn_value(const char *name, size_t n, double a, double b)
{
#define IS(fn) qparse_is_fn(name, n, fn)
    if (IS("sin")) return sin(a);
    if (IS("cos")) return cos(a);
    if (IS("tan")) return tan(a);
    if (IS("sqrt")) return a < 0 ? NAN : sqrt(a);
    if (IS("atan2")) return atan2(a, b);
    if (IS("abs")) return fabs(a);
    if (IS("min")) return fmin(a, b);
    if (IS("max")) return fmax(a, b);
    if (IS("exp")) return exp(a);
    if (IS("log")) return a > 0 ? log(a) : NAN;
    if (IS("tanh")) return tanh(a);
    if (IS("step")) return a > 0 ? 1.0 : 0.0;
    if (IS("sign")) return a > 0 ? 1.0 : a < 0 ? -1.0 : 0.0;
    return a / sqrt(a * a + b * b);  /* smoothsign */
#undef IS
}

/* smoothsign(x, eps) = x / sqrt(x^2 + eps^2), of nodes */
static qv smoothsign(qparse *p, qv x, qv eps)
{
    int xn = as_node(p, x), en = as_node(p, eps);
    int sum = node(p, LAW_ADD, node(p, LAW_MUL, xn, xn, 0.0), node(p, LAW_MUL, en, en, 0.0), 0.0);
    return (qv){0, node(p, LAW_DIV, xn, node(p, LAW_SQRT, sum, -1, 0.0), 0.0), NONE, 1};
}

static int check_args(qparse *p, const char *name, size_t n, const char *at, qv *a, qv *b,
                      int two)
{
    int known = 0;
    for (size_t i = 0; i < COUNT(law_fns); i++)
        known |= qparse_is_fn(name, n, law_fns[i]);
    if (!known) {
        qparse_fail(p, at, "unknown function '%.*s' (known: sin, cos, tan, sqrt, atan2, abs, min, "
                    "max, exp, log, tanh, step, sign, smoothsign)", (int)n, name);
        return -1;
    }
    if (two != two_args(name, n)) {
        if (!two && qparse_is_fn(name, n, "atan2"))
            qparse_fail(p, at, "atan2 takes two arguments: atan2(y, x)");
        else
            qparse_fail(p, at, two ? "%.*s takes one argument" : "%.*s takes two arguments",
                        (int)n, name);
        return -1;
    }
    if (two)
        return qparse_unify(p, a, b, at, qparse_is_fn(name, n, "atan2") ? "subtract" : "compare");
    return 0;
}

static qv l_call(qparse *p, const char *name, size_t n, const char *at, qv a, qv b, int two)
{
#define IS(fn) qparse_is_fn(name, n, fn)
    if (check_args(p, name, n, at, &a, &b, two) < 0)
        return a;
    if (IS("smoothsign") && b.h < 0 && !(b.v > 0)) {
        qparse_fail(p, at, "smoothsign(x, eps) needs eps > 0");
        return a;
    }
    dim d = a.d;  /* abs, min, max keep it */
    int bare = a.bare;
    if (IS("sqrt") && qparse_sqrt_dim(p, a, at, a.h < 0, &d) < 0)
        return a;
    if (IS("sin") || IS("cos") || IS("tan")) {  /* of an angle; bare: the default angle unit */
        if (a.bare)
            a = scaled(p, a, p->env->units->scale[Q_ANGLE]);
        else if (!dim_equal(a.d, ANGLE) && !dim_equal(a.d, NONE)) {
            char da[96];
            qparse_describe(a.d, da, sizeof da);
            qparse_fail(p, at, "%.*s needs an angle or a pure number, not %s", (int)n, name, da);
            return a;
        }
        d = NONE, bare = 1;
    }
    if ((IS("exp") || IS("log") || IS("tanh")) && !a.bare && !dim_equal(a.d, NONE)) {
        char da[96];
        qparse_describe(a.d, da, sizeof da);
        qparse_fail(p, at, "%.*s needs a pure number, got %s (divide by a reference value)",
                    (int)n, name, da);
        return a;
    }
    if (IS("exp") || IS("log") || IS("tanh") || IS("step") || IS("sign") || IS("smoothsign"))
        d = NONE, bare = 1;
    if (IS("atan2"))
        d = ANGLE, bare = 0;
    if (a.h < 0 && b.h < 0) {  /* a number */
        double v = fn_value(name, n, a.v, b.v);
        if (!isfinite(v)) {
            qparse_fail(p, at, "%.*s is not defined here (value %g)", (int)n, name, a.v);
            return a;
        }
        return number(v, d, bare);
    }
    if (IS("smoothsign"))
        return smoothsign(p, a, b);
    if (two)
        return binary(p, IS("atan2") ? LAW_ATAN2 : IS("min") ? LAW_MIN : LAW_MAX, a, b, d, bare);
    static const struct { const char *name; law_op op; } ops[] = {
        {"sin", LAW_SIN}, {"cos", LAW_COS}, {"tan", LAW_TAN}, {"sqrt", LAW_SQRT},
        {"abs", LAW_ABS}, {"exp", LAW_EXP}, {"log", LAW_LOG}, {"tanh", LAW_TANH},
        {"step", LAW_STEP}, {"sign", LAW_SIGN}};
    law_op op = LAW_SIN;
    for (size_t i = 0; i < COUNT(ops); i++)
        if (IS(ops[i].name))
            op = ops[i].op;
    return unary(p, op, a, d, bare);
#undef IS
}

static qv l_neg(qparse *p, qv v)
{
    if (v.h < 0)
        v.v = -v.v;
    else
        v.h = node(p, LAW_NEG, v.h, -1, 0.0);
    return v;
}

static qv l_add(qparse *p, qv a, qv b, char op, const char *at)
{
    (void)at;
    if (op == '-')
        b = b.h < 0 ? number(-b.v, b.d, b.bare)
                    : (qv){0, node(p, LAW_NEG, b.h, -1, 0.0), b.d, b.bare};
    if (a.h < 0 && b.h < 0)
        a.v += b.v;
    else
        a.h = node(p, LAW_ADD, as_node(p, a), as_node(p, b), 0.0);
    return a;
}

/* a * b; the dimensions are the caller's */
static qv mul(qparse *p, qv a, qv b)
{
    if (a.h < 0 && b.h < 0)
        return number(a.v * b.v, NONE, 0);
    if (a.h < 0 || b.h < 0)  /* a number times an expression of t */
        return scaled(p, a.h < 0 ? b : a, a.h < 0 ? a.v : b.v);
    return (qv){0, node(p, LAW_MUL, a.h, b.h, 0.0), NONE, 0};
}

static qv l_mul(qparse *p, qv a, qv b, char op, const char *at)
{
    if (op == '/') {
        if (b.h >= 0)  /* a / b(t): defined where b(t) is not 0 (law_defined) */
            return (qv){0, node(p, LAW_DIV, as_node(p, a), b.h, 0.0), NONE, 0};
        if (b.v == 0) {
            qparse_fail(p, at, "division by zero");
            return a;
        }
        b.v = 1.0 / b.v;
    }
    return mul(p, a, b);
}

static qv l_powi(qparse *p, qv a, int e, const char *at)
{
    if (a.h < 0)
        return number(pow(a.v, e), NONE, 0);
    if (e < -64 || e > 64) {
        qparse_fail(p, at, "a power of an expression of t must be -64 to 64");
        return a;
    }
    int neg = e < 0;
    e = neg ? -e : e;
    qv r = number(1.0, NONE, a.bare);  /* by squaring: t^64 is 7 products */
    for (qv base = a; e > 0; e >>= 1) {
        if (e & 1)
            r = mul(p, r, base);
        if (e > 1)
            base = mul(p, base, base);
    }
    if (neg)  /* t^-n = 1 / t^n */
        r = (qv){0, node(p, LAW_DIV, node(p, LAW_CONST, -1, -1, 1.0), as_node(p, r), 0.0), NONE,
                 0};
    return r;
}

/* The backend, for a law of t and for a program segment's f(u): they
 * differ only in the name the message offers. */
#define LAW_OPS(unknown_)                                                                      \
    {                                                                                          \
        .constant = l_constant, .unit = l_unit, .word = l_word, .call = l_call, .neg = l_neg,   \
        .scale = scaled, .add = l_add, .mul = l_mul, .powi = l_powi, .unknown_name = unknown_,  \
        .unit_alone = 1, .strict_exponent = 0, .checked_dims = 0, .after = "law",               \
    }
static const qparse_ops law_ops =
    LAW_OPS(" (not the time t, a function, or a parameter defined under 'parameters')");
static const qparse_ops law_u_ops =
    LAW_OPS(" (not u, a function, or a parameter defined under 'parameters')");

int law_parse_into(const char *text, const quantity *wants, int nwants, const expr_env *env,
                   struct mech_law *l, quantity *got, char *err, size_t errsize,
                   size_t *err_pos)
{
    qparse p;
    qparse_init(&p, text, env, l->var == 'u' ? &law_u_ops : &law_ops, l, err, errsize);
    qv v = qparse_run(&p);
    int k = 0;
    while (!p.failed && !v.bare && k + 1 < nwants && !dim_equal(v.d, quantity_get(wants[k])->d))
        k++;
    const quantity_info *qi = quantity_get(wants[k]);
    if (!p.failed && v.bare)
        v = scaled(&p, v, env->units->scale[wants[k]]);
    else if (!p.failed && !dim_equal(v.d, qi->d)) {
        char got_d[96];
        qparse_describe(v.d, got_d, sizeof got_d);
        qparse_fail(&p, text, "the law must be %s of %s, not %s",
                    nwants > 1 ? "an angle, a length or a time" : qi->noun,
                    l->var == 't' ? "t" : "u", got_d);
    }
    if (!p.failed && v.h < 0 && !isfinite(v.v))
        qparse_fail(&p, text, "value is not a finite number");
    if (!p.failed)
        l->root = as_node(&p, v);
    if (got)
        *got = wants[k];
    if (p.failed) {
        *err_pos = p.err_pos;
        return l->nomem ? MECH_ENOMEM : -1;
    }
    return 0;
}

int law_parse(const char *text, quantity want, const expr_env *env, struct mech_law **out,
              char *err, size_t errsize, size_t *err_pos)
{
    *out = NULL;
    struct mech_law *l = law_new('t');
    if (!l) {
        snprintf(err, errsize, "out of memory");
        *err_pos = 0;
        return MECH_ENOMEM;
    }
    int rc = law_parse_into(text, &want, 1, env, l, NULL, err, errsize, err_pos);
    if (rc != 0) {
        law_free(l);
        return rc;
    }
    *out = l;
    return 0;
}

/* The law q of `driver:`: one tree shared by every model (read only), the
 * mark of the driver that is the sweep (drivers_is_sweep). */
static law_node sweep_node = {LAW_T, -1, -1, 0.0};
static struct mech_law sweep_law = {.nodes = &sweep_node, .n = 1, .cap = 1, .root = 0, .var = 't'};

void law_free(struct mech_law *l)
{
    if (!l || l == &sweep_law)
        return;
    for (int i = 0; i < l->nprogs; i++)
        program_free(l->progs[i]);
    free(l->progs);
    free((void *)l->rtprogs);
    free(l->nodes);
    free(l);
}

ex law_expr(const struct mech_law *l, expr_ctx *c, ex t)
{
    if (law_is_opaque(l)) {  /* one function of t, its derivatives by law_eval3 */
        expr_fn fn = {law_fn_eval, l, l->name[0] ? l->name : "p"};
        int k = expr_fn_add(c, &fn);
        return k < 0 ? c->zero : expr_call(c, k, 0, t);
    }
    ex small[256], *e = l->n <= 256 ? small : xcalloc((size_t)l->n, sizeof *e);
    if (!e) {
        c->failed = 1;
        return c->zero;
    }
    for (int i = 0; i < l->n; i++) {
        const law_node *nd = &l->nodes[i];
        switch (nd->op) {
        case LAW_CONST: e[i] = expr_const(c, nd->k); break;
        case LAW_T: e[i] = t; break;
        case LAW_ADD: e[i] = expr_add(c, e[nd->a], e[nd->b]); break;
        case LAW_NEG: e[i] = expr_neg(c, e[nd->a]); break;
        case LAW_MUL: e[i] = expr_mul(c, e[nd->a], e[nd->b]); break;
        case LAW_SIN: e[i] = expr_sin(c, e[nd->a]); break;
        case LAW_COS: e[i] = expr_cos(c, e[nd->a]); break;
        default: e[i] = c->zero; break;  /* opaque: not here */
        }
    }
    ex r = l->root >= 0 && l->root < l->n ? e[l->root] : c->zero;
    if (e != small)
        free(e);
    return r;
}

/* ---- the one model of drivers ------------------------------------------- */

int drivers_add_sweep(mech_model *m)
{
    mech_motion *d = xcalloc(1, sizeof *d);
    if (!d)
        return -1;
    *d = (mech_motion){m->driver.kind, m->driver.index, NULL, &sweep_law, m->driver.mark};
    m->drivers = d;
    m->ndrivers = 1;
    return 0;
}

/* The law of `driver:` itself, not any law that reads as t: a law of time
 * `1 rad/s * t` folds to the tree t too, but its driver keeps its row, its
 * columns and its name. */
int drivers_is_sweep(const mech_model *m, int k) { return m->drivers[k].law == &sweep_law; }

int drivers_sweep(const mech_model *m)
{
    for (int k = 0; k < m->ndrivers; k++)
        if (drivers_is_sweep(m, k))
            return k;
    return -1;
}

/* The coordinate of kind `kind` that is the sweep variable, or -1. */
static int sweep_coordinate(const mech_model *m, mech_drive_kind kind)
{
    int k = drivers_sweep(m);
    return k >= 0 && m->drivers[k].kind == kind ? m->drivers[k].index : -1;
}

int drivers_sweep_link(const mech_model *m) { return sweep_coordinate(m, MECH_DRIVE_ANGLE); }

int drivers_sweep_slider(const mech_model *m) { return sweep_coordinate(m, MECH_DRIVE_SLIDER); }

int drivers_rows(const mech_model *m)
{
    int n = 0;
    for (int k = 0; k < m->ndrivers; k++)
        n += !drivers_is_sweep(m, k);
    return n;
}

ex drivers_row(const mech_model *m, int k, expr_ctx *c, const ex *link_angle, const ex *slide,
               ex q)
{
    const mech_motion *mo = &m->drivers[k];
    ex coord = mo->kind == MECH_DRIVE_ANGLE ? link_angle[mo->index] : slide[mo->index];
    return expr_sub(c, coord, law_expr(mo->law, c, q));
}

void drivers_guess(const mech_model *m, const int *link_var, const int *joint_var, double q,
                   double *guess)
{
    for (int i = 0; i < m->ndrivers; i++) {  /* the sweep's own coordinate is no unknown */
        const mech_motion *mo = &m->drivers[i];
        int var = mo->kind == MECH_DRIVE_ANGLE ? link_var[mo->index] : joint_var[mo->index];
        if (var >= 0)
            guess[var] = law_eval(mo->law, q, NULL, NULL);
    }
}

int drivers_undefined(const mech_model *m, double q, char *why, size_t size)
{
    for (int k = 0; k < m->ndrivers; k++)
        if (!drivers_is_sweep(m, k) && law_is_opaque(m->drivers[k].law) &&
            !law_defined(m->drivers[k].law, q, why, size))
            return k;
    return -1;
}

const char *drivers_name(const mech_model *m, int i)
{
    const mech_motion *mo = &m->drivers[i];
    return mo->kind == MECH_DRIVE_ANGLE ? m->links[mo->index].name : m->joints[mo->index].name;
}

int drivers_of_link(const mech_model *m, int l)
{
    for (int i = 0; i < m->ndrivers; i++)
        if (m->drivers[i].kind == MECH_DRIVE_ANGLE && m->drivers[i].index == l)
            return i;
    return -1;
}

int drivers_of_slider(const mech_model *m, int j)
{
    for (int i = 0; i < m->ndrivers; i++)
        if (m->drivers[i].kind == MECH_DRIVE_SLIDER && m->drivers[i].index == j)
            return i;
    return -1;
}

int drivers_move_link(const mech_model *m, int l)
{
    for (int i = 0; i < m->ndrivers; i++) {
        const mech_motion *mo = &m->drivers[i];
        if (mo->kind == MECH_DRIVE_ANGLE ? mo->index == l : m->joints[mo->index].link[0] == l)
            return 1;
    }
    return 0;
}

/* The same tree, its numbers bit for bit. */
static int same_law(const struct mech_law *p, const struct mech_law *q);

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

static int same_program(const mech_program *p, const mech_program *q)
{
    if (p->n != q->n || p->continuity != q->continuity || !same_bits(p->start, q->start) ||
        !same_bits(p->period, q->period) || !same_bits(p->net, q->net) ||
        !same_bits(p->speed, q->speed))
        return 0;
    for (int i = 0; i < p->n; i++) {
        const prog_segment *x = &p->seg[i], *y = &q->seg[i];
        if (x->kind != y->kind || x->shape != y->shape || !same_bits(x->x0, y->x0) ||
            !same_bits(x->span, y->span) || !same_bits(x->s0, y->s0) ||
            !same_bits(x->lift, y->lift) || !same_law(x->user_law, y->user_law) ||
            x->npieces != y->npieces || memcmp(x->piece, y->piece, sizeof x->piece) != 0)
            return 0;
    }
    return 1;
}

static int same_law(const struct mech_law *p, const struct mech_law *q)
{
    if (!p || !q || p->n != q->n || p->root != q->root || p->nprogs != q->nprogs)
        return p == q;
    for (int i = 0; i < p->nprogs; i++)
        if (!same_program(p->progs[i], q->progs[i]))
            return 0;
    for (int i = 0; i < p->n; i++) {
        const law_node *x = &p->nodes[i], *y = &q->nodes[i];
        if (x->op != y->op || x->a != y->a || x->b != y->b || memcmp(&x->k, &y->k, sizeof x->k))
            return 0;
    }
    return 1;
}

int drivers_same(const mech_model *a, const mech_model *b)
{
    if (a->ndrivers != b->ndrivers)
        return 0;
    for (int k = 0; k < a->ndrivers; k++) {
        const mech_motion *x = &a->drivers[k], *y = &b->drivers[k];
        if (x->kind != y->kind || x->index != y->index || !same_law(x->law, y->law))
            return 0;
    }
    return 1;
}

struct mech_law *law_linear(double a, double b)
{
    struct mech_law *l = xcalloc(1, sizeof *l);
    law_node *n = l ? xcalloc(5, sizeof *n) : NULL;
    if (!n) {
        free(l);
        return NULL;
    }
    n[0] = (law_node){LAW_CONST, -1, -1, a};
    n[1] = (law_node){LAW_CONST, -1, -1, b};
    n[2] = (law_node){LAW_T, -1, -1, 0.0};
    n[3] = (law_node){LAW_MUL, 1, 2, 0.0};
    n[4] = (law_node){LAW_ADD, 0, 3, 0.0};
    l->nodes = n;
    l->n = l->cap = 5;
    l->root = 4;
    l->var = 't';
    return l;
}

const free_driver *drivers_free_of(const mech_model *m, int k)
{
    const struct free_drivers *f = m->free_drivers;
    for (int i = 0; f && i < f->n; i++)
        if (f->d[i].driver == k)
            return &f->d[i];
    return NULL;
}

void drivers_free(mech_model *m)
{
    if (m->free_drivers) {
        free(m->free_drivers->d);
        free(m->free_drivers);
        m->free_drivers = NULL;
    }
    for (int i = 0; i < m->ndrivers; i++) {
        free(m->drivers[i].text);
        law_free(m->drivers[i].law);
    }
    free(m->drivers);
    m->drivers = m->motions = NULL;
    m->ndrivers = m->nmotions = 0;
}
