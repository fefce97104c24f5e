/* src/units.c: physical dimensions, unit names and quantity expressions
 * such as "60 mm", "a21 + 1 cm", "beta - gamma", "120 rpm".
 *
 * Grammar of a quantity expression (docs/format.md, "Values and units"):
 *   expr   := term  (('+' | '-') term)*
 *   term   := unary (('*' | '/') unary)*
 *   unary  := '-' unary | '+' unary | power
 *   power  := atom ('^' ['-'] integer)?
 *   atom   := number [unit] | name | func '(' expr [',' expr] ')' | '(' expr ')'
 *   unit   := uname ['^' ['-'] integer] (('*' | '/') uname ['^' ['-'] integer])*
 * A bare number (no unit) is "bare": it takes the file's default unit of
 * whatever quantity it turns out to be (the expected quantity at the top,
 * the other operand's quantity under + and -), and acts as a pure number
 * under * and /. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "internal.h"

#define PI 3.14159265358979323846

/* ORDER Q */
static const quantity_info quantity_table[NQUANTITIES] = {
    {"number", "a pure number", {{0, 0, 0, 0}}, ""},
    {"length", "a length", {{1, 0, 0, 0}}, "m"},
    {"angle", "an angle", {{0, 0, 0, 1}}, "rad"},
    {"mass", "a mass", {{0, 1, 0, 0}}, "kg"},
    {"time", "a time", {{0, 0, 1, 0}}, "s"},
    {"force", "a force", {{1, 1, -2, 0}}, "N"},
    {"torque", "a torque", {{2, 1, -2, 0}}, "N*m"},
    {"inertia", "a moment of inertia", {{2, 1, 0, 0}}, "kg*m^2"},
    {"speed", "a speed", {{1, 0, -1, 0}}, "m/s"},
    {"acceleration", "an acceleration", {{1, 0, -2, 0}}, "m/s^2"},
    {"angular_speed", "an angular speed", {{0, 0, -1, 1}}, "rad/s"},
    {"angular_acceleration", "an angular acceleration", {{0, 0, -2, 1}}, "rad/s^2"},
    {"force_per_length", "a force per length", {{0, 1, -2, 0}}, "N/m"},
    {"damping", "a damping coefficient", {{0, 1, -1, 0}}, "N*s/m"},
    {"torsion_stiffness", "a torsional stiffness", {{2, 1, -2, -1}}, "N*m/rad"},
    {"torsion_damping", "a torsional damping coefficient", {{2, 1, -1, -1}}, "N*m*s/rad"},
};

const quantity_info *quantity_get(quantity q) { return &quantity_table[q]; }

int quantity_by_key(const char *key)
{
    for (int q = 1; q < NQUANTITIES; q++)
        if (strcmp(key, quantity_table[q].key) == 0)
            return q;
    return -1;
}

void unit_defaults_init(unit_defaults *u)
{
    for (int q = 0; q < NQUANTITIES; q++)
        u->scale[q] = 1.0;
}

typedef struct unit_info {
    const char *name;
    double scale;   /* SI per unit */
    dim d;
} unit_info;

static const unit_info unit_table[] = {
    {"m", 1.0, {{1, 0, 0, 0}}},         {"cm", 1e-2, {{1, 0, 0, 0}}},
    {"mm", 1e-3, {{1, 0, 0, 0}}},       {"um", 1e-6, {{1, 0, 0, 0}}},
    {"km", 1e3, {{1, 0, 0, 0}}},        {"in", 0.0254, {{1, 0, 0, 0}}},
    {"kg", 1.0, {{0, 1, 0, 0}}},        {"g", 1e-3, {{0, 1, 0, 0}}},
    {"t", 1e3, {{0, 1, 0, 0}}},
    {"s", 1.0, {{0, 0, 1, 0}}},         {"ms", 1e-3, {{0, 0, 1, 0}}},
    {"min", 60.0, {{0, 0, 1, 0}}},      {"h", 3600.0, {{0, 0, 1, 0}}},
    {"rad", 1.0, {{0, 0, 0, 1}}},       {"deg", PI / 180.0, {{0, 0, 0, 1}}},
    {"rev", 2.0 * PI, {{0, 0, 0, 1}}},
    {"rpm", 2.0 * PI / 60.0, {{0, 0, -1, 1}}},
    {"N", 1.0, {{1, 1, -2, 0}}},        {"kN", 1e3, {{1, 1, -2, 0}}},
    {"mN", 1e-3, {{1, 1, -2, 0}}},
};
#define NUNITS (sizeof unit_table / sizeof unit_table[0])

static const unit_info *unit_lookup(const char *s, size_t len)
{
    for (size_t i = 0; i < NUNITS; i++)
        if (strlen(unit_table[i].name) == len && memcmp(unit_table[i].name, s, len) == 0)
            return &unit_table[i];
    return NULL;
}

int unit_is_name(const char *s, size_t len) { return unit_lookup(s, len) != NULL; }

int dim_equal(dim a, dim b) { return memcmp(a.e, b.e, sizeof a.e) == 0; }

/* Powers of a unit beyond +-99 would wrap around in a signed char (m^257
 * read as m): they become DIM_BAD, which sticks, and the evaluator reports it. */
enum { DIM_MAX = 99, DIM_BAD = 127 };

static signed char dim_clamp(int e) { return e > DIM_MAX || e < -DIM_MAX ? DIM_BAD : (signed char)e; }

static int dim_is_bad(dim a)
{
    for (int i = 0; i < NDIMS; i++)
        if (a.e[i] == DIM_BAD)
            return 1;
    return 0;
}

static dim dim_add(dim a, dim b, int sign)
{
    dim r;
    for (int i = 0; i < NDIMS; i++)
        r.e[i] = a.e[i] == DIM_BAD || b.e[i] == DIM_BAD ? DIM_BAD
                                                        : dim_clamp(a.e[i] + sign * b.e[i]);
    return r;
}

static dim dim_scale(dim a, int k)
{
    dim r;
    for (int i = 0; i < NDIMS; i++)
        r.e[i] = a.e[i] == DIM_BAD ? DIM_BAD : dim_clamp(a.e[i] * k);
    return r;
}

static int dim_is_none(dim a) { return dim_equal(a, (dim){{0, 0, 0, 0}}); }

void dim_format(dim d, char *buf, size_t size)
{
    static const char *const base[NDIMS] = {"m", "kg", "s", "rad"};
    static const int order[NDIMS] = {DIM_MASS, DIM_LENGTH, DIM_ANGLE, DIM_TIME};
    for (int q = 1; q < NQUANTITIES; q++)
        if (dim_equal(d, quantity_table[q].d)) {
            snprintf(buf, size, "%s", quantity_table[q].si_unit);
            return;
        }
    size_t n = 0;
    buf[0] = '\0';
    for (int pass = 0; pass < 2; pass++)
        for (int k = 0; k < NDIMS; k++) {
            int i = order[k], e = d.e[i];
            if ((pass == 0 && e <= 0) || (pass == 1 && e >= 0))
                continue;
            int ae = e < 0 ? -e : e;
            const char *sep = n == 0 ? (pass == 1 ? "1/" : "") : (pass == 1 ? "/" : "*");
            int w = ae == 1 ? snprintf(buf + n, size - n, "%s%s", sep, base[i])
                            : snprintf(buf + n, size - n, "%s%s^%d", sep, base[i], ae);
            if (w < 0 || (size_t)w >= size - n)
                return;
            n += (size_t)w;
        }
    if (n == 0)
        snprintf(buf, size, "1");
}

/* ---- the unit expression parser ---------------------------------- */

static size_t ident_len(const char *s)
{
    size_t n = 0;
    if (!(isalpha((unsigned char)s[0]) || s[0] == '_'))
        return 0;
    while (isalnum((unsigned char)s[n]) || s[n] == '_')
        n++;
    return n;
}

static const char *skip_space(const char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    return s;
}

/* "^2", "^-2": returns 1 and the exponent, or 0 when no '^' follows. */
static int parse_exponent(const char **ps, int *exp)
{
    const char *s = skip_space(*ps);
    if (*s != '^')
        return 0;
    s = skip_space(s + 1);
    int sign = 1;
    if (*s == '-') {
        sign = -1;
        s++;
    }
    if (!isdigit((unsigned char)*s))
        return -1;
    int v = 0;
    while (isdigit((unsigned char)*s) && v < 100)
        v = v * 10 + (*s++ - '0');
    if (v >= 100)
        return -1;
    *exp = sign * v;
    *ps = s;
    return 1;
}

/* one unit name with its optional exponent */
static int unit_factor(const char **ps, double *scale, dim *d)
{
    const char *s = skip_space(*ps);
    size_t n = ident_len(s);
    const unit_info *u = n ? unit_lookup(s, n) : NULL;
    if (!u)
        return 0;
    s += n;
    int e = 1;
    if (parse_exponent(&s, &e) < 0)
        return 0;
    *scale = pow(u->scale, e);
    *d = dim_scale(u->d, e);
    *ps = s;
    return 1;
}

int unit_parse(const char *s, double *scale, dim *d, const char **end)
{
    double sc;
    dim dd;
    if (!unit_factor(&s, &sc, &dd))
        return 0;
    for (;;) {
        const char *t = skip_space(s);
        if (*t != '*' && *t != '/')
            break;
        int div = *t == '/';
        const char *u = t + 1;
        double fs;
        dim fd;
        if (!unit_factor(&u, &fs, &fd))
            break;  /* "2 mm * a1": the '*' belongs to the expression */
        sc = div ? sc / fs : sc * fs;
        dd = dim_add(dd, fd, div ? -1 : 1);
        s = u;
    }
    *scale = sc;
    *d = dd;
    *end = s;
    return 1;
}

/* ---- the quantity expression evaluator ---------------------------- */

typedef struct qval {
    double v;
    dim d;
    int bare;  /* a number without unit whose quantity is not known yet */
    double dv; /* dv/dp for the parameter p the environment seeds (expr_param.dvalue):
                  forward-mode derivative, carried beside v through every operation */
} qval;

typedef struct qparser {
    const char *start, *s;
    const expr_env *env;
    char *err;
    size_t errsize;
    size_t err_pos;
    int failed;
    int depth;
} qparser;

static void qfail(qparser *p, const char *at, const char *fmt, ...) MECH_PRINTF(3, 4);
static void qfail(qparser *p, const char *at, const char *fmt, ...)
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

/* Default scale for a bare number that turns out to have dimension d. */
static double default_scale(const expr_env *env, dim d)
{
    for (int q = 1; q < NQUANTITIES; q++)
        if (dim_equal(d, quantity_table[q].d))
            return env->units->scale[q];
    return 1.0;
}

static void describe_dim(dim d, char *buf, size_t size)
{
    for (int q = 0; q < NQUANTITIES; q++)
        if (dim_equal(d, quantity_table[q].d)) {
            if (q == Q_NUMBER)
                snprintf(buf, size, "a pure number");
            else
                snprintf(buf, size, "%s (%s)", quantity_table[q].noun, quantity_table[q].si_unit);
            return;
        }
    char u[64];
    dim_format(d, u, sizeof u);
    snprintf(buf, size, "a quantity in %s", u);
}

static qval parse_expr(qparser *p);

static qval make_bare(double v) { return (qval){v, {{0, 0, 0, 0}}, 1, 0.0}; }

static qval parse_number(qparser *p)
{
    const char *s = p->s;
    char *end;
    if (!(isdigit((unsigned char)*s) || *s == '.')) {
        qfail(p, s, "expected a number");
        return make_bare(0);
    }
    double v = strtod(s, &end);
    if (end == s) {
        qfail(p, s, "expected a number");
        return make_bare(0);
    }
    if (!isfinite(v)) {
        qfail(p, s, "number out of range");
        return make_bare(0);
    }
    p->s = end;
    const char *u = skip_space(end);
    size_t n = ident_len(u);
    if (n == 0)
        return make_bare(v);
    double scale;
    dim d;
    const char *uend;
    int known_unit = unit_parse(u, &scale, &d, &uend);
    if (!known_unit && unit_lookup(u, n)) {  /* "m^100": the unit is fine, its power is not */
        qfail(p, u, "bad power of unit '%.*s' (write an integer from -99 to 99 after '^')",
              (int)n, u);
        return make_bare(v);
    }
    if (known_unit && dim_is_bad(d)) {
        qfail(p, u, "unit power out of range (at most %d)", DIM_MAX);
        return make_bare(v);
    }
    if (!known_unit) {
        char word[64];
        snprintf(word, sizeof word, "%.*s", (int)(n < 40 ? n : 40), u);
        const char *names[NUNITS];
        for (size_t i = 0; i < NUNITS; i++)
            names[i] = unit_table[i].name;
        const char *near = NULL;
        for (size_t i = 0; i < NUNITS && !near; i++)  /* "RPM", "MM": the case is wrong */
            if (strcasecmp(word, names[i]) == 0)
                near = names[i];
        if (!near)
            near = nearest_name(word, names, NUNITS);
        if (near)
            qfail(p, u, "unknown unit '%s' (did you mean '%s'?)", word, near);
        else {
            char known[160];
            size_t k = 0;
            known[0] = '\0';
            for (size_t i = 0; i < NUNITS && k < sizeof known; i++)
                k += (size_t)snprintf(known + k, sizeof known - k, "%s%s", i ? " " : "",
                                      names[i]);
            qfail(p, u, "unknown unit '%s' (known units: %s)", word, known);
        }
        return make_bare(v);
    }
    p->s = uend;
    return (qval){v * scale, d, 0, 0.0};
}

/* Under + or -, a bare operand takes the other operand's quantity. */
static void unify(qparser *p, qval *a, qval *b, const char *at, char op)
{
    if (a->bare && !b->bare) {
        a->v *= default_scale(p->env, b->d);
        a->dv *= default_scale(p->env, b->d);
        a->d = b->d;
        a->bare = 0;
    } else if (b->bare && !a->bare) {
        b->v *= default_scale(p->env, a->d);
        b->dv *= default_scale(p->env, a->d);
        b->d = a->d;
        b->bare = 0;
    } else if (!dim_equal(a->d, b->d)) {
        char da[96], db[96];
        describe_dim(a->d, da, sizeof da);
        describe_dim(b->d, db, sizeof db);
        qfail(p, at, "cannot %s %s and %s", op == '+' ? "add" : "subtract", da, db);
    }
}

static qval call_function(qparser *p, const char *name, size_t n, const char *at)
{
    /* the '(' has been consumed */
    qval a = parse_expr(p), b = make_bare(0);
    int two = 0;
    p->s = skip_space(p->s);
    if (*p->s == ',') {
        p->s++;
        b = parse_expr(p);
        two = 1;
        p->s = skip_space(p->s);
    }
    if (*p->s != ')') {
        qfail(p, p->s, "expected ')' to close %.*s(", (int)n, name);
        return a;
    }
    p->s++;
    const dim angle = quantity_table[Q_ANGLE].d;
    int is = 0;
#define IS(fn) (n == strlen(fn) && memcmp(name, fn, n) == 0)
    if (IS("atan2")) {
        if (!two) {
            qfail(p, at, "atan2 takes two arguments: atan2(y, x)");
            return a;
        }
        unify(p, &a, &b, at, '-');
        double r2 = a.v * a.v + b.v * b.v;  /* d atan2(y, x) = (x dy - y dx) / (x^2 + y^2) */
        double dv = r2 > 0 ? (b.v * a.dv - a.v * b.dv) / r2 : 0.0;
        return (qval){atan2(a.v, b.v), angle, 0, dv};
    }
    if (two) {
        qfail(p, at, "%.*s takes one argument", (int)n, name);
        return a;
    }
    if (IS("sqrt")) {
        for (int i = 0; i < NDIMS; i++)
            if (a.d.e[i] % 2)
                is = 1;
        if (is || a.v < 0) {
            qfail(p, at, a.v < 0 ? "sqrt of a negative value" : "sqrt of a quantity whose unit has an odd power");
            return a;
        }
        for (int i = 0; i < NDIMS; i++)
            a.d.e[i] = (signed char)(a.d.e[i] / 2);
        a.v = sqrt(a.v);
        a.dv = a.v > 0 ? a.dv / (2.0 * a.v) : 0.0;
        return a;
    }
    if (IS("sin") || IS("cos") || IS("tan")) {
        if (a.bare) {
            a.v *= p->env->units->scale[Q_ANGLE];
            a.dv *= p->env->units->scale[Q_ANGLE];
        } else if (!dim_equal(a.d, angle) && !dim_is_none(a.d)) {
            qfail(p, at, "%.*s needs an angle", (int)n, name);
            return a;
        }
        double r = IS("sin") ? sin(a.v) : IS("cos") ? cos(a.v) : tan(a.v);
        qval out = make_bare(r);
        out.dv = a.dv * (IS("sin") ? cos(a.v) : IS("cos") ? -sin(a.v) : 1.0 + r * r);
        return out;  /* a pure number: 100 * cos(60) takes the default length unit */
    }
#undef IS
    qfail(p, at, "unknown function '%.*s' (known: sqrt, sin, cos, tan, atan2)", (int)n, name);
    return a;
}

/* Index of the parameter named by the n bytes at `name`, or -1. Names are
 * at most 64 bytes (load.h), so a longer word is no parameter. */
static int find_param(const expr_env *env, const char *name, size_t n)
{
    if (env->param_index) {
        char word[65];
        if (n >= sizeof word)
            return -1;
        memcpy(word, name, n);
        word[n] = '\0';
        return name_map_get(env->param_index, word);
    }
    for (int i = 0; i < env->nparams; i++)
        if (strlen(env->params[i].name) == n && memcmp(env->params[i].name, name, n) == 0)
            return i;
    return -1;
}

static qval parse_atom(qparser *p)
{
    p->s = skip_space(p->s);
    const char *at = p->s;
    if (*at == '(') {
        p->s++;
        qval v = parse_expr(p);
        p->s = skip_space(p->s);
        if (*p->s != ')')
            qfail(p, p->s, "expected ')'");
        else
            p->s++;
        return v;
    }
    size_t n = ident_len(at);
    if (n) {
        p->s = at + n;
        const char *after = skip_space(p->s);
        if (*after == '(') {
            p->s = after + 1;
            return call_function(p, at, n, at);
        }
        if (n == 2 && memcmp(at, "pi", 2) == 0)  /* pi rad: angle: pi/2 is 90 deg whatever the default */
            return (qval){PI, quantity_table[Q_ANGLE].d, 0, 0.0};
        int found = find_param(p->env, at, n);
        if (found >= 0) {
            const expr_param *q = &p->env->params[found];
            return (qval){q->value, q->d, q->bare, q->dvalue};
        }
        if (unit_lookup(at, n))
            qfail(p, at, "unit '%.*s' without a number (write 1 %.*s)", (int)n, at, (int)n, at);
        else
            qfail(p, at, "unknown name '%.*s' (not a unit, a function, or a parameter defined "
                         "above)", (int)(n < 64 ? n : 64), at);
        return make_bare(0);
    }
    if (*at == '\0') {
        qfail(p, at, "value missing");
        return make_bare(0);
    }
    if (!(isdigit((unsigned char)*at) || *at == '.')) {
        qfail(p, at, "unexpected '%c'", *at);
        return make_bare(0);
    }
    return parse_number(p);
}

static qval parse_power(qparser *p);

/* unary := ('-' | '+') unary | power, so -r^2 is -(r^2) */
static qval parse_unary(qparser *p)
{
    p->s = skip_space(p->s);
    if (++p->depth > 64) {
        qfail(p, p->s, "expression nested too deeply");
        return make_bare(0);
    }
    qval v;
    if (*p->s == '-' || *p->s == '+') {
        int neg = *p->s == '-';
        p->s++;
        v = parse_unary(p);
        if (neg) {
            v.v = -v.v;
            v.dv = -v.dv;
        }
    } else {
        v = parse_power(p);
    }
    p->depth--;
    return v;
}

static qval parse_power(qparser *p)
{
    qval a = parse_atom(p);
    const char *at = skip_space(p->s);
    int e;
    int r = parse_exponent(&p->s, &e);
    if (r < 0) {
        qfail(p, at, "expected an integer exponent after '^'");
        return a;
    }
    if (r == 1) {
        a.dv = e == 0 ? 0.0 : e * pow(a.v, e - 1) * a.dv;
        a.v = pow(a.v, e);
        int was_bad = dim_is_bad(a.d);
        a.d = dim_scale(a.d, e);
        if (dim_is_bad(a.d) && !was_bad)
            qfail(p, at, "unit power out of range (at most %d)", DIM_MAX);
    }
    return a;
}

static qval parse_term(qparser *p)
{
    qval a = parse_unary(p);
    for (;;) {
        const char *at = skip_space(p->s);
        if (p->failed || (*at != '*' && *at != '/'))
            return a;
        p->s = at + 1;
        qval b = parse_unary(p);
        if (*at == '*') {
            a.dv = a.dv * b.v + a.v * b.dv;
            a.v *= b.v;
        } else {
            if (b.v == 0) {
                qfail(p, at, "division by zero");
                return a;
            }
            a.dv = a.dv / b.v - (a.v / b.v) * (b.dv / b.v);  /* (a/b)' without b^2 underflowing */
            a.v /= b.v;
        }
        a.d = dim_add(a.d, b.d, *at == '*' ? 1 : -1);
        a.bare = a.bare && b.bare;
        if (dim_is_bad(a.d) && !dim_is_bad(b.d)) {  /* report once, where it happens */
            qfail(p, at, "unit power out of range (at most %d)", DIM_MAX);
            return a;
        }
    }
}

static qval parse_expr(qparser *p)
{
    qval a = parse_term(p);
    for (;;) {
        const char *at = skip_space(p->s);
        if (p->failed || (*at != '+' && *at != '-'))
            return a;
        p->s = at + 1;
        qval b = parse_term(p);
        unify(p, &a, &b, at, *at);
        a.v = *at == '+' ? a.v + b.v : a.v - b.v;
        a.dv = *at == '+' ? a.dv + b.dv : a.dv - b.dv;
    }
}

static int run_parser(qparser *p, qval *out)
{
    *out = parse_expr(p);
    p->s = skip_space(p->s);
    if (!p->failed && *p->s != '\0')
        qfail(p, p->s, "unexpected '%c' after the value", *p->s);
    if (!p->failed && !isfinite(out->v))
        qfail(p, p->start, "value is not a finite number");
    return p->failed ? -1 : 0;
}

int quantity_eval(const char *text, quantity want, const expr_env *env, double *value,
                  char *err, size_t errsize, size_t *err_pos)
{
    qparser p = {text, text, env, err, errsize, 0, 0, 0};
    qval v;
    if (run_parser(&p, &v) < 0) {
        *err_pos = p.err_pos;
        return -1;
    }
    const quantity_info *qi = &quantity_table[want];
    if (env->dvalue)
        *env->dvalue = v.bare ? v.dv * env->units->scale[want] : v.dv;
    if (v.bare) {
        *value = v.v * env->units->scale[want];
        return 0;
    }
    if (!dim_equal(v.d, qi->d)) {
        char got[96];
        describe_dim(v.d, got, sizeof got);
        snprintf(err, errsize, "expected %s, got %s", qi->noun, got);
        *err_pos = 0;
        return -1;
    }
    *value = v.v;
    return 0;
}

int quantity_eval_param(const char *text, const expr_env *env, expr_param *out, char *err,
                        size_t errsize, size_t *err_pos)
{
    qparser p = {text, text, env, err, errsize, 0, 0, 0};
    qval v;
    if (run_parser(&p, &v) < 0) {
        *err_pos = p.err_pos;
        return -1;
    }
    out->value = v.v;
    out->dvalue = v.dv;
    out->d = v.d;
    out->bare = v.bare;
    return 0;
}

int mech_parse_value(const char *text, int is_angle, double *si, char *err, size_t errsize)
{
    unit_defaults u;
    unit_defaults_init(&u);
    u.scale[Q_ANGLE] = 3.14159265358979323846 / 180.0;  /* bare angles: degrees */
    u.scale[Q_LENGTH] = 1e-3;                            /* bare lengths: millimetres */
    expr_env env = {&u, NULL, 0};
    size_t pos;
    quantity q = is_angle == 2 ? Q_TIME : is_angle ? Q_ANGLE : Q_LENGTH;  /* 2: a time, s */
    return quantity_eval(text, q, &env, si, err, errsize, &pos) == 0
               ? MECH_OK : MECH_EINPUT;
}
