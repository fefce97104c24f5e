/* src/drivers.c: laws of time for the drivers (drivers.h): the parser of
 * a law into a tree, its evaluation, its expression DAG, and the hooks the
 * system and the continuation call.
 *
 * The grammar is that of a quantity expression (units.c):
 *   expr  := term (('+' | '-') term)*
 *   term  := unary (('*' | '/') unary)*
 *   unary := ('-' | '+') unary | power
 *   power := atom ('^' ['-'] integer)?
 *   atom  := number [unit] | name | func '(' expr [',' expr] ')' | '(' expr ')'
 * with one more name, t (a time, the sweep variable). Parts that do not
 * depend on t are numbers at once (any function: sqrt, sin, cos, tan,
 * atan2); a part that depends on t may be added, subtracted, multiplied,
 * divided by a number, raised to a power 0..64, and given to sin or cos.
 * A bare number (no unit) is a pure number under * and /, and takes the
 * other operand's default unit under + and -, as in units.c. */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <btf.h>

#include "drivers.h"
#include "system.h"

#define PI 3.14159265358979323846

typedef struct lval {
    double v;    /* the value when node < 0 */
    dim d;
    int bare;
    int node;    /* -1: a number (v); else the tree node of a part that depends on t */
} lval;

typedef struct lparser {
    const char *start, *s;
    const expr_env *env;
    struct mech_law *law;
    char *err;
    size_t errsize, err_pos;
    int failed, depth;
} lparser;

static void lfail(lparser *p, const char *at, const char *fmt, ...) MECH_PRINTF(3, 4);
static void lfail(lparser *p, const char *at, const char *fmt, ...)
{
    if (p->failed)
        return;
    p->failed = 1;
    p->err_pos = (size_t)(at - p->start);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->err, p->errsize, fmt, ap);
    va_end(ap);
}

static const dim NONE = {{0, 0, 0, 0}};
static const dim TIME = {{0, 0, 1, 0}};
static const dim ANGLE = {{0, 0, 0, 1}};

static void describe(dim d, char *buf, size_t size)
{
    for (int q = 0; q < NQUANTITIES; q++)
        if (dim_equal(d, quantity_get((quantity)q)->d)) {
            if (q == Q_NUMBER)
                snprintf(buf, size, "a pure number");
            else
                snprintf(buf, size, "%s (%s)", quantity_get((quantity)q)->noun,
                         quantity_get((quantity)q)->si_unit);
            return;
        }
    char u[64];
    dim_format(d, u, sizeof u);
    snprintf(buf, size, "a quantity in %s", u);
}

static double default_scale(const expr_env *env, dim d)
{
    for (int q = 1; q < NQUANTITIES; q++)
        if (dim_equal(d, quantity_get((quantity)q)->d))
            return env->units->scale[q];
    return 1.0;
}

static int node(lparser *p, law_op op, int a, int b, double k)
{
    struct mech_law *l = p->law;
    if (l->n >= LAW_MAX_NODES) {  /* law_eval works in a fixed buffer */
        lfail(p, p->s, "the law is too long (more than %d operations)", LAW_MAX_NODES);
        return 0;
    }
    if (op == LAW_CONST && !isfinite(k)) {  /* "t + 0^-1 s": no law */
        lfail(p, p->s, "value is not a finite number");
        return 0;
    }
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 16;
        law_node *more = xrealloc_array(l->nodes, (size_t)cap, sizeof *more);
        if (!more) {
            lfail(p, p->s, "out of memory");
            return 0;
        }
        l->nodes = more;
        l->cap = cap;
    }
    l->nodes[l->n] = (law_node){op, a, b, k};
    return l->n++;
}

static int as_node(lparser *p, lval a)
{
    return a.node >= 0 ? a.node : node(p, LAW_CONST, -1, -1, a.v);
}

static lval number(double v, dim d, int bare) { return (lval){v, d, bare, -1}; }

static lval scaled(lparser *p, lval a, double k)
{
    if (k == 1.0)
        return a;
    if (a.node < 0)
        return number(a.v * k, a.d, a.bare);
    a.node = node(p, LAW_MUL, node(p, LAW_CONST, -1, -1, k), a.node, 0.0);
    return a;
}

static size_t ident_len(const char *s)
{
    size_t n = 0;
    if (!(isalpha((unsigned char)s[0]) || s[0] == '_'))
        return 0;
    while (isalnum((unsigned char)s[n]) || s[n] == '_')
        n++;
    return n;
}

static const char *skip(const char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    return s;
}

static lval parse_expr(lparser *p);

static lval parse_number(lparser *p)
{
    char *end;
    double v = strtod(p->s, &end);
    if (end == p->s || !isfinite(v)) {
        lfail(p, p->s, end == p->s ? "expected a number" : "number out of range");
        return number(0, NONE, 1);
    }
    p->s = end;
    const char *u = skip(end), *uend;
    size_t n = ident_len(u);
    double scale;
    dim d;
    /* t is the time here, not the tonne: "10 rad/s * t" has the unit rad/s,
       so the unit is read from a copy cut before a word t */
    char buf[128];
    size_t len = 0;
    for (; u[len] && len + 1 < sizeof buf; len++) {
        int starts = (isalpha((unsigned char)u[len]) || u[len] == '_') &&
                     (len == 0 || !(isalnum((unsigned char)u[len - 1]) || u[len - 1] == '_'));
        if (starts && ident_len(u + len) == 1 && u[len] == 't')
            break;
        buf[len] = u[len];
    }
    buf[len] = '\0';
    if (n == 0 || !unit_parse(buf, &scale, &d, &uend))
        return number(v, NONE, 1);
    p->s = u + (uend - buf);
    return number(v * scale, d, 0);
}

static int find_param(const expr_env *env, const char *name, size_t n)
{
    char word[65];
    if (n >= sizeof word)
        return -1;
    memcpy(word, name, n);
    word[n] = '\0';
    if (env->param_index)
        return name_map_get(env->param_index, word);
    for (int i = 0; i < env->nparams; i++)
        if (strcmp(env->params[i].name, word) == 0)
            return i;
    return -1;
}

/* Under + and -: a bare operand takes the other's unit; else equal units. */
static int unify(lparser *p, lval *a, lval *b, const char *at, char op)
{
    if (a->bare && !b->bare) {
        *a = scaled(p, *a, default_scale(p->env, b->d));
        a->d = b->d, a->bare = 0;
    } else if (b->bare && !a->bare) {
        *b = scaled(p, *b, default_scale(p->env, a->d));
        b->d = a->d, b->bare = 0;
    } else if (!dim_equal(a->d, b->d)) {
        char da[96], db[96];
        describe(a->d, da, sizeof da);
        describe(b->d, db, sizeof db);
        lfail(p, at, "cannot %s %s and %s", op == '+' ? "add" : "subtract", da, db);
        return -1;
    }
    return 0;
}

static lval call(lparser *p, const char *name, size_t n, const char *at)
{
    lval a = parse_expr(p), b = number(0, NONE, 1);
    int two = 0;
    p->s = skip(p->s);
    if (*p->s == ',') {
        p->s++;
        b = parse_expr(p);
        two = 1;
        p->s = skip(p->s);
    }
    if (p->failed)
        return a;
    if (*p->s != ')') {
        lfail(p, p->s, "expected ')' to close %.*s(", (int)n, name);
        return a;
    }
    p->s++;
#define IS(fn) (n == strlen(fn) && memcmp(name, fn, n) == 0)
    int known = IS("sin") || IS("cos") || IS("tan") || IS("sqrt") || IS("atan2");
    if (!known) {
        lfail(p, at, "unknown function '%.*s' (known: sin, cos, tan, sqrt, atan2)", (int)n, name);
        return a;
    }
    if (two != IS("atan2")) {
        lfail(p, at, two ? "%.*s takes one argument" : "atan2 takes two arguments: atan2(y, x)",
              (int)n, name);
        return a;
    }
    if (a.node >= 0 || b.node >= 0) {
        if (!(IS("sin") || IS("cos"))) {
            lfail(p, at, "%.*s of an expression of t: only sin and cos may take t", (int)n,
                  name);
            return a;
        }
    }
    if (IS("atan2")) {
        if (unify(p, &a, &b, at, '-') < 0)
            return a;
        return number(atan2(a.v, b.v), ANGLE, 0);
    }
    if (IS("sqrt")) {
        for (int i = 0; i < NDIMS; i++)
            if (a.d.e[i] % 2 || a.v < 0) {
                lfail(p, at, a.v < 0 ? "sqrt of a negative value"
                                     : "sqrt of a quantity whose unit has an odd power");
                return a;
            }
        for (int i = 0; i < NDIMS; i++)
            a.d.e[i] = (signed char)(a.d.e[i] / 2);
        return number(sqrt(a.v), a.d, a.bare);
    }
    /* sin, cos, tan: of an angle (a bare number takes the default angle unit) */
    if (a.bare)
        a = scaled(p, a, p->env->units->scale[Q_ANGLE]);
    else if (!dim_equal(a.d, ANGLE) && !dim_equal(a.d, NONE)) {
        char da[96];
        describe(a.d, da, sizeof da);
        lfail(p, at, "%.*s needs an angle or a pure number, not %s", (int)n, name, da);
        return a;
    }
    if (a.node < 0)
        return number(IS("sin") ? sin(a.v) : IS("cos") ? cos(a.v) : tan(a.v), NONE, 1);
    return (lval){0, NONE, 1, node(p, IS("sin") ? LAW_SIN : LAW_COS, a.node, -1, 0.0)};
#undef IS
}

static lval parse_atom(lparser *p)
{
    p->s = skip(p->s);
    const char *at = p->s;
    if (*at == '(') {
        p->s++;
        lval v = parse_expr(p);
        p->s = skip(p->s);
        if (*p->s != ')')
            lfail(p, p->s, "expected ')'");
        else
            p->s++;
        return v;
    }
    size_t n = ident_len(at);
    if (n) {
        p->s = at + n;
        const char *after = skip(p->s);
        if (*after == '(') {
            p->s = after + 1;
            return call(p, at, n, at);
        }
        if (n == 1 && *at == 't')
            return (lval){0, TIME, 0, node(p, LAW_T, -1, -1, 0.0)};
        if (n == 2 && memcmp(at, "pi", 2) == 0)
            return number(PI, ANGLE, 0);
        int k = find_param(p->env, at, n);
        if (k >= 0)
            return number(p->env->params[k].value, p->env->params[k].d, p->env->params[k].bare);
        if (unit_is_name(at, n))
            lfail(p, at, "unit '%.*s' without a number (write 1 %.*s)", (int)n, at, (int)n, at);
        else
            lfail(p, at, "unknown name '%.*s' (not the time t, a function, or a parameter "
                         "defined under 'parameters')", (int)(n < 64 ? n : 64), at);
        return number(0, NONE, 1);
    }
    if (*at == '\0') {
        lfail(p, at, "value missing");
        return number(0, NONE, 1);
    }
    if (!(isdigit((unsigned char)*at) || *at == '.')) {
        lfail(p, at, "unexpected '%c'", *at);
        return number(0, NONE, 1);
    }
    return parse_number(p);
}

static lval mul(lparser *p, lval a, lval b)
{
    dim d;
    for (int i = 0; i < NDIMS; i++)
        d.e[i] = (signed char)(a.d.e[i] + b.d.e[i]);
    int bare = a.bare && b.bare;
    if (a.node < 0 && b.node < 0)
        return number(a.v * b.v, d, bare);
    if (a.node < 0 || b.node < 0) {  /* a number times an expression of t */
        lval r = scaled(p, a.node < 0 ? b : a, a.node < 0 ? a.v : b.v);
        r.d = d, r.bare = bare;
        return r;
    }
    return (lval){0, d, bare, node(p, LAW_MUL, a.node, b.node, 0.0)};
}

static lval parse_power(lparser *p)
{
    lval a = parse_atom(p);
    const char *at = skip(p->s);
    if (*at != '^' || p->failed)
        return a;
    const char *s = skip(at + 1);
    int sign = 1, e = 0;
    if (*s == '-')
        sign = -1, s++;
    if (!isdigit((unsigned char)*s)) {
        lfail(p, at, "expected an integer exponent after '^'");
        return a;
    }
    while (isdigit((unsigned char)*s) && e < 100)
        e = e * 10 + (*s++ - '0');
    p->s = s;
    e *= sign;
    if (a.node < 0) {
        dim d;
        for (int i = 0; i < NDIMS; i++)
            d.e[i] = (signed char)(a.d.e[i] * e);
        return number(pow(a.v, e), d, a.bare);
    }
    if (e < 0 || e > 64) {
        lfail(p, at, "a power of an expression of t must be 0 to 64");
        return a;
    }
    lval r = number(1.0, NONE, a.bare);  /* by squaring: t^64 is 7 products */
    for (lval base = a; e > 0; e >>= 1) {
        if (e & 1)
            r = mul(p, r, base);
        if (e > 1)
            base = mul(p, base, base);
    }
    return r;
}

static lval parse_unary(lparser *p)
{
    p->s = skip(p->s);
    if (++p->depth > 64) {
        lfail(p, p->s, "expression nested too deeply");
        return number(0, NONE, 1);
    }
    lval v;
    if (*p->s == '-' || *p->s == '+') {
        int neg = *p->s == '-';
        p->s++;
        v = parse_unary(p);
        if (neg && v.node < 0)
            v.v = -v.v;
        else if (neg)
            v.node = node(p, LAW_NEG, v.node, -1, 0.0);
    } else {
        v = parse_power(p);
    }
    p->depth--;
    return v;
}

static lval parse_term(lparser *p)
{
    lval a = parse_unary(p);
    for (;;) {
        const char *at = skip(p->s);
        if (p->failed || (*at != '*' && *at != '/'))
            return a;
        p->s = at + 1;
        lval b = parse_unary(p);
        if (*at == '/') {
            if (b.node >= 0) {
                lfail(p, at, "division by an expression of t (divide by numbers only)");
                return a;
            }
            if (b.v == 0) {
                lfail(p, at, "division by zero");
                return a;
            }
            for (int i = 0; i < NDIMS; i++)
                b.d.e[i] = (signed char)-b.d.e[i];
            b.v = 1.0 / b.v;
        }
        a = mul(p, a, b);
    }
}

static lval parse_expr(lparser *p)
{
    lval a = parse_term(p);
    for (;;) {
        const char *at = skip(p->s);
        if (p->failed || (*at != '+' && *at != '-'))
            return a;
        p->s = at + 1;
        lval b = parse_term(p);
        if (p->failed || unify(p, &a, &b, at, *at) < 0)
            return a;
        if (*at == '-')
            b = b.node < 0 ? number(-b.v, b.d, b.bare)
                           : (lval){0, b.d, b.bare, node(p, LAW_NEG, b.node, -1, 0.0)};
        if (a.node < 0 && b.node < 0)
            a.v += b.v;
        else
            a.node = node(p, LAW_ADD, as_node(p, a), as_node(p, b), 0.0);
    }
}

int law_parse(const char *text, quantity want, const expr_env *env, struct mech_law **out,
              char *err, size_t errsize, size_t *err_pos)
{
    *out = NULL;
    struct mech_law *l = xcalloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errsize, "out of memory");
        *err_pos = 0;
        return -1;
    }
    lparser p = {text, text, env, l, err, errsize, 0, 0, 0};
    lval v = parse_expr(&p);
    p.s = skip(p.s);
    if (!p.failed && *p.s != '\0')
        lfail(&p, p.s, "unexpected '%c' after the law", *p.s);
    const quantity_info *qi = quantity_get(want);
    if (!p.failed && v.bare)
        v = scaled(&p, v, env->units->scale[want]);
    else if (!p.failed && !dim_equal(v.d, qi->d)) {
        char got[96];
        describe(v.d, got, sizeof got);
        lfail(&p, text, "the law must be %s of t, not %s", qi->noun, got);
    }
    if (!p.failed && v.node < 0 && !isfinite(v.v))
        lfail(&p, text, "value is not a finite number");
    if (!p.failed)
        l->root = as_node(&p, v);
    if (p.failed) {
        *err_pos = p.err_pos;
        law_free(l);
        return -1;
    }
    *out = l;
    return 0;
}

void law_free(struct mech_law *l)
{
    if (l)
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

/* ---- hooks -------------------------------------------------------------- */

int drivers_rows(const mech_model *m)
{
    return m->has_driver && m->driver.kind == MECH_DRIVE_TIME ? m->nmotions : 0;
}

void drivers_residual(const mech_model *m, expr_ctx *c, const ex *link_angle, const ex *slide,
                      ex q, ex *f)
{
    for (int i = 0; i < drivers_rows(m); i++) {
        const mech_motion *mo = &m->motions[i];
        ex coord = mo->kind == MECH_DRIVE_ANGLE ? link_angle[mo->index] : slide[mo->index];
        f[i] = expr_sub(c, coord, law_expr(mo->law, c, q));
    }
}

void drivers_guess(const mech_model *m, const int *link_var, const int *joint_var, double q,
                   double *guess)
{
    for (int i = 0; i < drivers_rows(m); i++) {
        const mech_motion *mo = &m->motions[i];
        int var = mo->kind == MECH_DRIVE_ANGLE ? link_var[mo->index] : joint_var[mo->index];
        if (var >= 0)
            guess[var] = law_eval(mo->law, q, NULL, NULL);
    }
}

const char *drivers_name(const mech_model *m, int i)
{
    const mech_motion *mo = &m->motions[i];
    return mo->kind == MECH_DRIVE_ANGLE ? m->links[mo->index].name : m->joints[mo->index].name;
}

int drivers_of_link(const mech_model *m, int l)
{
    for (int i = 0; i < drivers_rows(m); i++)
        if (m->motions[i].kind == MECH_DRIVE_ANGLE && m->motions[i].index == l)
            return i;
    return -1;
}

int drivers_of_slider(const mech_model *m, int j)
{
    for (int i = 0; i < drivers_rows(m); i++)
        if (m->motions[i].kind == MECH_DRIVE_SLIDER && m->motions[i].index == j)
            return i;
    return -1;
}

void drivers_free(mech_model *m)
{
    for (int i = 0; i < m->nmotions; i++) {
        free(m->motions[i].text);
        law_free(m->motions[i].law);
    }
    free(m->motions);
    m->motions = NULL;
    m->nmotions = 0;
}

void drivers_report_count(const mech_model *m, int mobility, mech_diag *d)
{
    int nd = drivers_rows(m);
    char list[512];
    size_t at = 0;
    list[0] = '\0';
    if (nd > mobility) {  /* the drivers past the mobility conflict with the others */
        for (int i = mobility; i < nd && at < sizeof list; i++)
            at += (size_t)snprintf(list + at, sizeof list - at, "%s'%s'", i > mobility ? ", " : "",
                                   drivers_name(m, i));
        diag_error(d, m->file, m->motions[mobility].mark,
                   "over-driven: the mechanism has %d degree%s of freedom but %d drivers; the "
                   "driver%s of %s conflict%s with the others (remove %s)",
                   mobility, mobility == 1 ? "" : "s", nd, nd - mobility == 1 ? "" : "s", list,
                   nd - mobility == 1 ? "s" : "", nd - mobility == 1 ? "it" : "them");
        return;
    }
    /* the links on the ground, or sliding on it, that no law drives: one of
       them is left free */
    int count = 0;
    for (int j = 0; j < m->njoints && at < sizeof list; j++) {
        const mech_joint *jt = &m->joints[j];
        int l = jt->link[0] == 0 ? jt->link[1] : jt->link[1] == 0 ? jt->link[0] : -1;
        if (l <= 0)
            continue;
        int driven = jt->kind == MECH_JOINT_SLIDER ? drivers_of_slider(m, j) >= 0
                                                    : drivers_of_link(m, l) >= 0;
        if (driven)
            continue;
        const char *name = jt->kind == MECH_JOINT_SLIDER ? jt->name : m->links[l].name;
        at += (size_t)snprintf(list + at, sizeof list - at, "%s%s '%s'", count++ ? ", " : "",
                               jt->kind == MECH_JOINT_SLIDER ? "slider" : "link", name);
    }
    diag_error(d, m->file, m->motions[0].mark,
               "under-driven: the mechanism has %d degrees of freedom but %d driver%s, so %d "
               "motion%s %s free%s%s%s; add a driver for each (a link angle or a slider "
               "displacement as a law of t)",
               mobility, nd, nd == 1 ? "" : "s", mobility - nd, mobility - nd == 1 ? "" : "s",
               mobility - nd == 1 ? "is" : "are", count ? " (not driven: " : "",
               count ? list : "", count ? ")" : "");
}

/* Names of the listed items into buf: "'a', 'b' and 3 more". */
static void name_list(char *buf, size_t size, const char *const *names, int count)
{
    size_t at = 0;
    buf[0] = '\0';
    for (int i = 0; i < count && i < 8 && at < size; i++)
        at += (size_t)snprintf(buf + at, size - at, "%s'%s'", i == 0 ? "" : ", ", names[i]);
    if (count > 8 && at < size)
        snprintf(buf + at, size - at, " and %d more", count - 8);
}

/* Breadth-first over alternating paths of a maximum matching (the
 * Dulmage-Mendelsohn decomposition): from the unmatched rows (from_rows) or
 * columns, mark the rows and columns reached. Each node is queued once. */
static void alternate(int nr, int nc, const int *Ap, const int *Ai, const int *rp, const int *rc,
                      const int *row_match, const int *col_match, int from_rows,
                      unsigned char *row_seen, unsigned char *col_seen, int *queue)
{
    int head = 0, tail = 0;
    if (from_rows) {
        for (int r = 0; r < nr; r++)
            if (row_match[r] < 0)
                row_seen[r] = 1, queue[tail++] = r;
        while (head < tail) {
            int r = queue[head++];
            for (int p = rp[r]; p < rp[r + 1]; p++) {
                int c = rc[p];
                if (col_seen[c])
                    continue;
                col_seen[c] = 1;
                int r2 = col_match[c];
                if (r2 >= 0 && !row_seen[r2])
                    row_seen[r2] = 1, queue[tail++] = r2;
            }
        }
        return;
    }
    for (int c = 0; c < nc; c++)
        if (col_match[c] < 0)
            col_seen[c] = 1, queue[tail++] = c;
    while (head < tail) {
        int c = queue[head++];
        for (int p = Ap[c]; p < Ap[c + 1]; p++) {
            int r = Ai[p];
            if (row_seen[r])
                continue;
            row_seen[r] = 1;
            int c2 = row_match[r];
            if (c2 >= 0 && !col_seen[c2])
                col_seen[c2] = 1, queue[tail++] = c2;
        }
    }
}

int drivers_report_structure(const mech_system *s, mech_diag *d)
{
    const mech_model *m = s->model;
    int nr = s->m, nc = s->n, nd = drivers_rows(m), first = nr - nd;
    size_t big = (size_t)(nr > nc ? nr : nc) + 1;
    int *row_match = xcalloc(big, sizeof *row_match), *col_match = xcalloc(big, sizeof *col_match);
    int *work = xcalloc(5 * big, sizeof *work), *queue = xcalloc(big, sizeof *queue);
    int *rp = xcalloc(big + 1, sizeof *rp), *rc = xcalloc((size_t)s->nnz + 1, sizeof *rc);
    unsigned char *rs = xcalloc(big, 1), *cs = xcalloc(big, 1);
    unsigned char *rs2 = xcalloc(big, 1), *cs2 = xcalloc(big, 1);
    const char **names = xcalloc(big, sizeof *names);
    int rcode = MECH_EINPUT;
    if (!row_match || !col_match || !work || !queue || !rp || !rc || !rs || !cs || !rs2 || !cs2 ||
        !names) {
        diag_error(d, m->file, (mech_mark){0, 0}, "out of memory");
        rcode = MECH_ENOMEM;
        goto done;
    }
    double done_work;
    btf_maxtrans(nr, nc, s->Jp, s->Ji, 0.0, &done_work, row_match, work);
    for (int c = 0; c < nc; c++)
        col_match[c] = -1;
    for (int r = 0; r < nr; r++)
        if (row_match[r] >= 0)
            col_match[row_match[r]] = r;
    /* the row-wise pattern */
    for (int p = 0; p < s->nnz; p++)
        rp[s->Ji[p] + 1]++;
    for (int r = 0; r < nr; r++)
        rp[r + 1] += rp[r];
    for (int c = 0; c < nc; c++)
        for (int p = s->Jp[c]; p < s->Jp[c + 1]; p++)
            rc[rp[s->Ji[p]] + queue[s->Ji[p]]++] = c;
    alternate(nr, nc, s->Jp, s->Ji, rp, rc, row_match, col_match, 1, rs, cs, queue);
    alternate(nr, nc, s->Jp, s->Ji, rp, rc, row_match, col_match, 0, rs2, cs2, queue);
    /* the drivers among the over-determined rows, the unknowns left free */
    int nconf = 0, nfree = 0, at_driver = -1;
    char conf[512], freed[512];
    for (int r = first; r < nr; r++)
        if (rs[r]) {
            names[nconf++] = drivers_name(m, r - first);
            at_driver = at_driver < 0 ? r - first : at_driver;
        }
    name_list(conf, sizeof conf, names, nconf);
    for (int c = 0; c < nc; c++)  /* the link or slider of each free unknown */
        if (cs2[c])
            names[nfree++] = s->unk_kind[c] == UNK_ANGLE ? m->links[s->unk_index[c]].name
                                                         : m->joints[s->unk_index[c]].name;
    name_list(freed, sizeof freed, names, nfree);
    mech_mark at = at_driver >= 0 ? m->motions[at_driver].mark : m->driver.mark;
    if (nconf > 0 && nfree > 0)
        diag_error(d, m->file, at,
                   "the drivers do not match the mechanism's freedoms: the driver%s of %s "
                   "over-determine%s the part of the mechanism %s move%s, while %s move%s "
                   "freely; drive one of those instead", nconf == 1 ? "" : "s", conf,
                   nconf == 1 ? "s" : "", nconf == 1 ? "it" : "they", nconf == 1 ? "s" : "",
                   freed, nfree == 1 ? "s" : "");
    else if (nconf > 0)
        diag_error(d, m->file, at, "the driver%s of %s over-determine%s the mechanism (the loop "
                   "equations and the other drivers already fix %s)", nconf == 1 ? "" : "s",
                   conf, nconf == 1 ? "s" : "", nconf == 1 ? "it" : "them");
    else
        diag_error(d, m->file, at, "the loop equations are structurally singular: the motion "
                   "of %s is determined by no equation (see 'mech equations')",
                   nfree ? freed : "some link or slider");
done:
    free(row_match);
    free(col_match);
    free(work);
    free(queue);
    free(rp);
    free(rc);
    free(rs);
    free(cs);
    free(rs2);
    free(cs2);
    free(names);
    return rcode;
}
