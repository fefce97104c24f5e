/* src/load/qparse.c: the grammar and the dimension checker of quantity
 * expressions, shared by units.c, drivers.c and load_state_loads.c through
 * their qparse_ops (qparse.h). */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

static const dim NONE = {{0, 0, 0, 0}};
static const dim ANGLE = {{0, 0, 0, 1}};

/* the value of a part that failed: a bare 0, no node, no register */
static qv failed_value(void) { return (qv){0.0, -1, {{0, 0, 0, 0}}, 1}; }

void qparse_init(qparse *p, const char *text, const expr_env *env, const qparse_ops *ops,
                 void *ctx, char *err, size_t errsize)
{
    *p = (qparse){text, text, env, ops, ctx, err, errsize, 0, 0, 0};
}

void qparse_fail(qparse *p, const char *at, const char *fmt, ...)
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

/* ---- dimensions ----------------------------------------------------- */

static signed char dim_clamp(int e)
{
    return e > QDIM_MAX || e < -QDIM_MAX ? QDIM_BAD : (signed char)e;
}

int qdim_is_bad(dim a)
{
    for (int i = 0; i < NDIMS; i++)
        if (a.e[i] == QDIM_BAD)
            return 1;
    return 0;
}

dim qdim_add(dim a, dim b, int sign)
{
    dim r;
    for (int i = 0; i < NDIMS; i++)
        r.e[i] = a.e[i] == QDIM_BAD || b.e[i] == QDIM_BAD ? QDIM_BAD
                                                          : dim_clamp(a.e[i] + sign * b.e[i]);
    return r;
}

dim qdim_scale(dim a, int k)
{
    dim r;
    for (int i = 0; i < NDIMS; i++)
        r.e[i] = a.e[i] == QDIM_BAD ? QDIM_BAD : dim_clamp(a.e[i] * k);
    return r;
}

double qparse_default_scale(const qparse *p, dim d)
{
    for (int q = 1; q < NQUANTITIES; q++)
        if (dim_equal(d, quantity_get((quantity)q)->d))
            return p->env->units->scale[q];
    return 1.0;
}

void qparse_describe(dim d, char *buf, size_t size)
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

int qparse_sqrt_dim(qparse *p, qv a, const char *at, int value_known, dim *half)
{
    int odd = 0;
    for (int i = 0; i < NDIMS; i++)
        odd |= a.d.e[i] % 2 != 0;
    if (odd || (value_known && a.v < 0)) {
        qparse_fail(p, at, value_known && a.v < 0 ? "sqrt of a negative value"
                                                  : "sqrt of a quantity whose unit has an odd power");
        return -1;
    }
    for (int i = 0; i < NDIMS; i++)
        half->e[i] = (signed char)(a.d.e[i] / 2);
    return 0;
}

int qparse_unify(qparse *p, qv *a, qv *b, const char *at, const char *what)
{
    if (a->bare && !b->bare) {
        *a = p->ops->scale(p, *a, qparse_default_scale(p, b->d));
        a->d = b->d;
        a->bare = 0;
    } else if (b->bare && !a->bare) {
        *b = p->ops->scale(p, *b, qparse_default_scale(p, a->d));
        b->d = a->d;
        b->bare = 0;
    } else if (!dim_equal(a->d, b->d)) {
        char da[96], db[96];
        qparse_describe(a->d, da, sizeof da);
        qparse_describe(b->d, db, sizeof db);
        qparse_fail(p, at, "cannot %s %s and %s", what, da, db);
        return -1;
    }
    return 0;
}

/* ---- the grammar ---------------------------------------------------- */

static qv constant(qparse *p, double v, dim d, int bare)
{
    qv r = p->ops->constant(p, v);
    r.d = d;
    r.bare = bare;
    return r;
}

/* Index of the parameter named by the n bytes at `name`, or -1. Names are
 * at most 64 bytes (load.h), so a longer word is no parameter. */
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

static qv parse_expr(qparse *p);

static qv parse_number(qparse *p)
{
    const char *s = p->s;
    char *end;
    double v = strtod(s, &end);
    if (end == s || !isfinite(v)) {
        qparse_fail(p, s, end == s ? "expected a number" : "number out of range");
        return failed_value();
    }
    p->s = end;
    const char *u = qparse_skip(end), *uend;
    if (qparse_ident_len(u) == 0)
        return constant(p, v, NONE, 1);
    double scale;
    dim d;
    int r = p->ops->unit(p, u, &scale, &d, &uend);
    if (r < 0)
        return failed_value();
    if (r == 0)
        return constant(p, v, NONE, 1);
    p->s = uend;
    return constant(p, v * scale, d, 0);
}

static qv call(qparse *p, const char *name, size_t n)
{
    /* the '(' has been read */
    if (p->ops->call_start)
        p->ops->call_start(p, name, n);
    qv a = parse_expr(p), b = failed_value();
    int two = 0;
    p->s = qparse_skip(p->s);
    if (*p->s == ',') {
        p->s++;
        b = parse_expr(p);
        two = 1;
        p->s = qparse_skip(p->s);
    }
    if (p->failed)
        return a;
    if (*p->s != ')') {
        qparse_fail(p, p->s, "expected ')' to close %.*s(", (int)n, name);
        return a;
    }
    p->s++;
    return p->ops->call(p, name, n, name, a, b, two);
}

static qv parse_atom(qparse *p)
{
    p->s = qparse_skip(p->s);
    const char *at = p->s;
    if (*at == '(') {
        p->s++;
        qv v = parse_expr(p);
        p->s = qparse_skip(p->s);
        if (*p->s != ')')
            qparse_fail(p, p->s, "expected ')'");
        else
            p->s++;
        return v;
    }
    size_t n = qparse_ident_len(at);
    if (n) {
        p->s = at + n;
        if (p->ops->dotted && *p->s == '.') {
            const char *mem = p->s + 1;
            size_t ml = qparse_ident_len(mem);
            if (!ml) {
                qparse_fail(p, mem, "expected a name after '.'");
                return failed_value();
            }
            p->s = mem + ml;
            return p->ops->dotted(p, at, n, mem, ml);
        }
        const char *after = qparse_skip(p->s);
        if (*after == '(') {
            p->s = after + 1;
            return call(p, at, n);
        }
        qv w;
        if (p->ops->word && p->ops->word(p, at, n, &w))
            return w;
        if (n == 2 && memcmp(at, "pi", 2) == 0)  /* pi rad: pi/2 is 90 deg whatever the default */
            return constant(p, QPARSE_PI, ANGLE, 0);
        int found = find_param(p->env, at, n);
        if (found >= 0) {
            const expr_param *q = &p->env->params[found];
            qv r = p->ops->param ? p->ops->param(p, found) : p->ops->constant(p, q->value);
            r.d = q->d;
            r.bare = q->bare;
            return r;
        }
        if (p->ops->unit_alone && unit_is_name(at, n))
            qparse_fail(p, at, "unit '%.*s' without a number (write 1 %.*s)", (int)n, at, (int)n,
                        at);
        else
            qparse_fail(p, at, "unknown name '%.*s'%s", (int)(n < 64 ? n : 64), at,
                        p->ops->unknown_name);
        return failed_value();
    }
    if (*at == '\0') {
        qparse_fail(p, at, "value missing");
        return failed_value();
    }
    if (!(isdigit((unsigned char)*at) || *at == '.')) {
        qparse_fail(p, at, "unexpected '%c'", *at);
        return failed_value();
    }
    return parse_number(p);
}

static qv parse_power(qparse *p)
{
    qv a = parse_atom(p);
    const char *at = qparse_skip(p->s);
    if (*at != '^' || p->failed)
        return a;
    const char *s = qparse_skip(at + 1);
    int sign = 1, e = 0;
    if (*s == '-')
        sign = -1, s++;
    if (!isdigit((unsigned char)*s)) {
        qparse_fail(p, at, "expected an integer exponent after '^'");
        return a;
    }
    while (isdigit((unsigned char)*s) && e < 100)
        e = e * 10 + (*s++ - '0');
    if (e >= 100 && p->ops->strict_exponent) {
        qparse_fail(p, at, "expected an integer exponent after '^'");
        return a;
    }
    p->s = s;
    e *= sign;
    dim d = a.d;
    int bare = a.bare;
    qv r = p->ops->powi(p, a, e, at);
    if (p->ops->checked_dims) {
        r.d = qdim_scale(d, e);
        if (qdim_is_bad(r.d) && !qdim_is_bad(d))
            qparse_fail(p, at, "unit power out of range (at most %d)", QDIM_MAX);
    } else {
        for (int i = 0; i < NDIMS; i++)
            r.d.e[i] = (signed char)(d.e[i] * e);
    }
    r.bare = bare;
    return r;
}

/* unary := ('-' | '+') unary | power, so -r^2 is -(r^2) */
static qv parse_unary(qparse *p)
{
    p->s = qparse_skip(p->s);
    if (++p->depth > 64) {
        qparse_fail(p, p->s, "expression nested too deeply");
        return failed_value();
    }
    qv v;
    if (*p->s == '-' || *p->s == '+') {
        int neg = *p->s == '-';
        p->s++;
        v = parse_unary(p);
        if (neg)
            v = p->ops->neg(p, v);
    } else {
        v = parse_power(p);
    }
    p->depth--;
    return v;
}

static qv parse_term(qparse *p)
{
    qv a = parse_unary(p);
    for (;;) {
        const char *at = qparse_skip(p->s);
        if (p->failed || (*at != '*' && *at != '/'))
            return a;
        p->s = at + 1;
        qv b = parse_unary(p);
        if (p->failed)
            return a;
        int sign = *at == '*' ? 1 : -1, bare = a.bare && b.bare;
        dim d = a.d;
        qv r = p->ops->mul(p, a, b, *at, at);
        if (p->failed)
            return a;
        if (p->ops->checked_dims) {
            r.d = qdim_add(d, b.d, sign);
            if (qdim_is_bad(r.d) && !qdim_is_bad(b.d)) {  /* report once, where it happens */
                qparse_fail(p, at, "unit power out of range (at most %d)", QDIM_MAX);
                return r;
            }
        } else {
            for (int i = 0; i < NDIMS; i++)
                r.d.e[i] = (signed char)(d.e[i] + sign * b.d.e[i]);
        }
        r.bare = bare;
        a = r;
    }
}

static qv parse_expr(qparse *p)
{
    qv a = parse_term(p);
    for (;;) {
        const char *at = qparse_skip(p->s);
        if (p->failed || (*at != '+' && *at != '-'))
            return a;
        p->s = at + 1;
        qv b = parse_term(p);
        if (p->failed || qparse_unify(p, &a, &b, at, *at == '+' ? "add" : "subtract") < 0)
            return a;
        dim d = a.d;
        int bare = a.bare;
        a = p->ops->add(p, a, b, *at, at);
        a.d = d;
        a.bare = bare;
    }
}

qv qparse_run(qparse *p)
{
    qv v = parse_expr(p);
    p->s = qparse_skip(p->s);
    if (!p->failed && *p->s != '\0')
        qparse_fail(p, p->s, "unexpected '%c' after the %s", *p->s, p->ops->after);
    return v;
}
