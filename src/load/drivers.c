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

static int node(qparse *p, law_op op, int a, int b, double k)
{
    struct mech_law *l = p->ctx;
    if (l->n >= LAW_MAX_NODES) {  /* law_eval works in a fixed buffer */
        qparse_fail(p, p->s, "the law is too long (more than %d operations)", LAW_MAX_NODES);
        return 0;
    }
    if (op == LAW_CONST && !isfinite(k)) {  /* "t + 0^-1 s": no law */
        qparse_fail(p, p->s, "value is not a finite number");
        return 0;
    }
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 16;
        law_node *more = xrealloc_array(l->nodes, (size_t)cap, sizeof *more);
        if (!more) {
            l->nomem = 1;
            qparse_fail(p, p->s, "out of memory");
            return 0;
        }
        l->nodes = more;
        l->cap = cap;
    }
    l->nodes[l->n] = (law_node){op, a, b, k};
    return l->n++;
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
 * the unit is read from a copy cut before a word t */
static int l_unit(qparse *p, const char *u, double *scale, dim *d, const char **end)
{
    (void)p;
    char buf[128];
    size_t len = 0;
    for (; u[len] && len + 1 < sizeof buf; len++) {
        int starts = (isalpha((unsigned char)u[len]) || u[len] == '_') &&
                     (len == 0 || !(isalnum((unsigned char)u[len - 1]) || u[len - 1] == '_'));
        if (starts && qparse_ident_len(u + len) == 1 && u[len] == 't')
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
    if (!(n == 1 && *at == 't'))
        return 0;
    *out = (qv){0, node(p, LAW_T, -1, -1, 0.0), TIME, 0};
    return 1;
}

static qv l_call(qparse *p, const char *name, size_t n, const char *at, qv a, qv b, int two)
{
#define IS(fn) qparse_is_fn(name, n, fn)
    int known = IS("sin") || IS("cos") || IS("tan") || IS("sqrt") || IS("atan2");
    if (!known) {
        qparse_fail(p, at, "unknown function '%.*s' (known: sin, cos, tan, sqrt, atan2)", (int)n,
                    name);
        return a;
    }
    if (two != IS("atan2")) {
        qparse_fail(p, at,
                    two ? "%.*s takes one argument" : "atan2 takes two arguments: atan2(y, x)",
                    (int)n, name);
        return a;
    }
    if (a.h >= 0 || b.h >= 0) {
        if (!(IS("sin") || IS("cos"))) {
            qparse_fail(p, at, "%.*s of an expression of t: only sin and cos may take t", (int)n,
                        name);
            return a;
        }
    }
    if (IS("atan2")) {
        if (qparse_unify(p, &a, &b, at, "subtract") < 0)
            return a;
        return number(atan2(a.v, b.v), ANGLE, 0);
    }
    if (IS("sqrt")) {
        dim half;
        if (qparse_sqrt_dim(p, a, at, 1, &half) < 0)
            return a;
        return number(sqrt(a.v), half, a.bare);
    }
    /* sin, cos, tan: of an angle (a bare number takes the default angle unit) */
    if (a.bare)
        a = scaled(p, a, p->env->units->scale[Q_ANGLE]);
    else if (!dim_equal(a.d, ANGLE) && !dim_equal(a.d, NONE)) {
        char da[96];
        qparse_describe(a.d, da, sizeof da);
        qparse_fail(p, at, "%.*s needs an angle or a pure number, not %s", (int)n, name, da);
        return a;
    }
    if (a.h < 0)
        return number(IS("sin") ? sin(a.v) : IS("cos") ? cos(a.v) : tan(a.v), NONE, 1);
    return (qv){0, node(p, IS("sin") ? LAW_SIN : LAW_COS, a.h, -1, 0.0), NONE, 1};
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
        if (b.h >= 0) {
            qparse_fail(p, at, "division by an expression of t (divide by numbers only)");
            return a;
        }
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
    if (e < 0 || e > 64) {
        qparse_fail(p, at, "a power of an expression of t must be 0 to 64");
        return a;
    }
    qv r = number(1.0, NONE, a.bare);  /* by squaring: t^64 is 7 products */
    for (qv base = a; e > 0; e >>= 1) {
        if (e & 1)
            r = mul(p, r, base);
        if (e > 1)
            base = mul(p, base, base);
    }
    return r;
}

static const qparse_ops law_ops = {
    .constant = l_constant,
    .unit = l_unit,
    .word = l_word,
    .call = l_call,
    .neg = l_neg,
    .scale = scaled,
    .add = l_add,
    .mul = l_mul,
    .powi = l_powi,
    .unknown_name = " (not the time t, a function, or a parameter defined under 'parameters')",
    .unit_alone = 1,
    .strict_exponent = 0,
    .checked_dims = 0,
    .after = "law",
};

int law_parse(const char *text, quantity want, const expr_env *env, struct mech_law **out,
              char *err, size_t errsize, size_t *err_pos)
{
    *out = NULL;
    struct mech_law *l = xcalloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errsize, "out of memory");
        *err_pos = 0;
        return MECH_ENOMEM;
    }
    qparse p;
    qparse_init(&p, text, env, &law_ops, l, err, errsize);
    qv v = qparse_run(&p);
    const quantity_info *qi = quantity_get(want);
    if (!p.failed && v.bare)
        v = scaled(&p, v, env->units->scale[want]);
    else if (!p.failed && !dim_equal(v.d, qi->d)) {
        char got[96];
        qparse_describe(v.d, got, sizeof got);
        qparse_fail(&p, text, "the law must be %s of t, not %s", qi->noun, got);
    }
    if (!p.failed && v.h < 0 && !isfinite(v.v))
        qparse_fail(&p, text, "value is not a finite number");
    if (!p.failed)
        l->root = as_node(&p, v);
    if (p.failed) {
        int nomem = l->nomem;
        *err_pos = p.err_pos;
        law_free(l);
        return nomem ? MECH_ENOMEM : -1;
    }
    *out = l;
    return 0;
}

/* The law q of `driver:`: one tree shared by every model (read only), the
 * mark of the driver that is the sweep (drivers_is_sweep). */
static law_node sweep_node = {LAW_T, -1, -1, 0.0};
static struct mech_law sweep_law = {&sweep_node, 1, 1, 0};

void law_free(struct mech_law *l)
{
    if (!l || l == &sweep_law)
        return;
    free(l->nodes);
    free(l);
}

/* Value, first and second derivative of every node, in order (no recursion:
 * operands come first). */
double law_eval(const struct mech_law *l, double t, double *dt, double *dtt)
{
    double buf[3 * LAW_MAX_NODES];  /* no allocation: called at a restart of the sweep */
    double *f = buf, *f1 = buf + l->n, *f2 = buf + 2 * l->n;
    for (int i = 0; i < l->n; i++) {
        const law_node *nd = &l->nodes[i];
        int a = nd->a, b = nd->b;
        switch (nd->op) {
        case LAW_CONST: f[i] = nd->k, f1[i] = f2[i] = 0.0; break;
        case LAW_T: f[i] = t, f1[i] = 1.0, f2[i] = 0.0; break;
        case LAW_ADD: f[i] = f[a] + f[b], f1[i] = f1[a] + f1[b], f2[i] = f2[a] + f2[b]; break;
        case LAW_NEG: f[i] = -f[a], f1[i] = -f1[a], f2[i] = -f2[a]; break;
        case LAW_MUL:
            f[i] = f[a] * f[b];
            f1[i] = f1[a] * f[b] + f[a] * f1[b];
            f2[i] = f2[a] * f[b] + 2.0 * f1[a] * f1[b] + f[a] * f2[b];
            break;
        case LAW_SIN:
            f[i] = sin(f[a]);
            f1[i] = cos(f[a]) * f1[a];
            f2[i] = cos(f[a]) * f2[a] - sin(f[a]) * f1[a] * f1[a];
            break;
        case LAW_COS:
            f[i] = cos(f[a]);
            f1[i] = -sin(f[a]) * f1[a];
            f2[i] = -sin(f[a]) * f2[a] - cos(f[a]) * f1[a] * f1[a];
            break;
        }
    }
    double r = l->root >= 0 && l->root < l->n ? f[l->root] : NAN;
    if (dt)
        *dt = isnan(r) ? NAN : f1[l->root];
    if (dtt)
        *dtt = isnan(r) ? NAN : f2[l->root];
    return r;
}

ex law_expr(const struct mech_law *l, expr_ctx *c, ex t)
{
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
static int same_law(const struct mech_law *p, const struct mech_law *q)
{
    if (!p || !q || p->n != q->n || p->root != q->root)
        return p == q;
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
