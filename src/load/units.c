/* src/load/units.c: physical dimensions, unit names and quantity expressions
 * such as "60 mm", "a21 + 1 cm", "beta - gamma", "120 rpm".
 *
 * Quantity expressions are read by qparse.c (the grammar, the dimensions);
 * this file is its numeric backend. A unit after a number is
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

#include "base.h"
#include "load.h"

#define PI QPARSE_PI

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

static int dim_is_none(dim a) { return dim_equal(a, (dim){{0, 0, 0, 0}}); }

static const char *const si_base[NDIMS] = {"m", "kg", "s", "rad"};

/* d in the units base[] after `head` ("N" or ""): "kg*m^2/s^2", "N*m*rad". */
static void dim_format_base(dim d, const char *const *base, const char *head, char *buf,
                            size_t size)
{
    static const int order[NDIMS] = {DIM_MASS, DIM_LENGTH, DIM_ANGLE, DIM_TIME};
    size_t n = (size_t)snprintf(buf, size, "%s", head);
    if (n >= size)
        return;
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

void dim_format(dim d, char *buf, size_t size)
{
    for (int q = 1; q < NQUANTITIES; q++)
        if (dim_equal(d, quantity_table[q].d)) {
            snprintf(buf, size, "%s", quantity_table[q].si_unit);
            return;
        }
    /* a force times something, in the words the format knows: N*m*rad, not
     * kg*m^2*rad/s^2 (one newton, when the rest keeps no second upstairs) */
    dim rest = d;
    rest.e[DIM_MASS] -= 1;
    rest.e[DIM_LENGTH] -= 1;
    rest.e[DIM_TIME] += 2;
    if (d.e[DIM_MASS] == 1 && rest.e[DIM_TIME] <= 0)
        dim_format_base(rest, si_base, "N", buf, size);
    else
        dim_format_base(d, si_base, "", buf, size);
}

/* The file's unit of quantity q to the power e, SI per it (1 when the file
 * gives none). */
static double part_scale(const file_units *fu, int q, int e)
{
    double s = 1.0;
    for (int k = 0; fu->text[q][0] && k < (e < 0 ? -e : e); k++)
        s = e > 0 ? s * fu->scale[q] : s / fu->scale[q];
    return s;
}

double file_units_of(const file_units *fu, dim d, char *buf, size_t size)
{
    for (int q = 1; fu && q < NQUANTITIES; q++)  /* the file's own unit of that quantity */
        if (fu->text[q][0] && dim_equal(d, quantity_table[q].d)) {
            snprintf(buf, size, "%s", fu->text[q]);
            return fu->scale[q];
        }
    if (!fu) {
        dim_format(d, buf, size);
        return 1.0;
    }
    /* else its parts: a length in the file's length unit, an angle in its
     * angle unit...; a force's kg*m/s^2 stays N (N*mm for a torque) */
    static const int qof[NDIMS] = {[DIM_LENGTH] = Q_LENGTH, [DIM_MASS] = Q_MASS,
                                   [DIM_TIME] = Q_TIME, [DIM_ANGLE] = Q_ANGLE};
    const char *base[NDIMS];
    for (int i = 0; i < NDIMS; i++)
        base[i] = fu->text[qof[i]][0] ? fu->text[qof[i]] : si_base[i];
    dim rest = d;
    rest.e[DIM_MASS] -= 1;
    rest.e[DIM_LENGTH] -= 1;
    rest.e[DIM_TIME] += 2;
    double scale = 1.0;
    if (d.e[DIM_MASS] == 1 && rest.e[DIM_TIME] <= 0 && !fu->text[Q_MASS][0] &&
        !fu->text[Q_TIME][0]) {
        dim_format_base(rest, base, "N", buf, size);
        return part_scale(fu, Q_LENGTH, rest.e[DIM_LENGTH]) *
               part_scale(fu, Q_ANGLE, rest.e[DIM_ANGLE]);
    }
    for (int i = 0; i < NDIMS; i++)
        scale *= part_scale(fu, qof[i], d.e[i]);
    dim_format_base(d, base, "", buf, size);
    return scale;
}

/* ---- the unit expression parser ---------------------------------- */

/* "^2", "^-2": returns 1 and the exponent, or 0 when no '^' follows. */
static int parse_exponent(const char **ps, int *exp)
{
    const char *s = qparse_skip(*ps);
    if (*s != '^')
        return 0;
    s = qparse_skip(s + 1);
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
    const char *s = qparse_skip(*ps);
    size_t n = qparse_ident_len(s);
    const unit_info *u = n ? unit_lookup(s, n) : NULL;
    if (!u)
        return 0;
    s += n;
    int e = 1;
    if (parse_exponent(&s, &e) < 0)
        return 0;
    *scale = pow(u->scale, e);
    *d = qdim_scale(u->d, e);
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
        const char *t = qparse_skip(s);
        if (*t != '*' && *t != '/')
            break;
        int div = *t == '/';
        const char *u = t + 1;
        double fs;
        dim fd;
        if (!unit_factor(&u, &fs, &fd))
            break;  /* "2 mm * a1": the '*' belongs to the expression */
        sc = div ? sc / fs : sc * fs;
        dd = qdim_add(dd, fd, div ? -1 : 1);
        s = u;
    }
    *scale = sc;
    *d = dd;
    *end = s;
    return 1;
}

/* ---- the quantity expression evaluator: a backend of qparse.c ------- */

/* Values are numbers, qv.v. When the environment records (expr_env.record,
 * the loader's parameter expressions), each operation is also recorded:
 * qv.h is the value's handle in the tree (param_expr.h), a node when a
 * parameter is below it. The operations on numbers are the same either way. */

static param_exprs *recorder(const qparse *p) { return p->ctx; }

/* v = op(a, b) with k, recorded when the environment records. */
static int record(qparse *p, px_op op, double k, qv a, qv b, double v)
{
    param_exprs *pe = recorder(p);
    if (!pe)
        return PX_FIXED;
    return pexpr_make(pe, op, k, (pxq){a.v, a.h}, (pxq){b.v, b.h}, pxq_fixed(0), v).h;
}

static qv q_constant(qparse *p, double v)
{
    (void)p;
    return (qv){v, PX_FIXED, {{0, 0, 0, 0}}, 0};
}

static qv q_param(qparse *p, int k)
{
    double v = p->env->params[k].value;
    param_exprs *pe = recorder(p);
    return (qv){v, pe ? pexpr_param(pe, k, v).h : PX_FIXED, {{0, 0, 0, 0}}, 0};
}

static int q_unit(qparse *p, const char *u, double *scale, dim *d, const char **end)
{
    size_t n = qparse_ident_len(u);
    int known_unit = unit_parse(u, scale, d, end);
    if (!known_unit && unit_lookup(u, n)) {  /* "m^100": the unit is fine, its power is not */
        qparse_fail(p, u, "bad power of unit '%.*s' (write an integer from -99 to 99 after '^')",
                    (int)n, u);
        return -1;
    }
    if (known_unit && qdim_is_bad(*d)) {
        qparse_fail(p, u, "unit power out of range (at most %d)", QDIM_MAX);
        return -1;
    }
    if (known_unit)
        return 1;
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
        qparse_fail(p, u, "unknown unit '%s' (did you mean '%s'?)", word, near);
    else {
        char known[160];
        size_t k = 0;
        known[0] = '\0';
        for (size_t i = 0; i < NUNITS && k < sizeof known; i++)
            k += (size_t)snprintf(known + k, sizeof known - k, "%s%s", i ? " " : "", names[i]);
        qparse_fail(p, u, "unknown unit '%s' (known units: %s)", word, known);
    }
    return -1;
}

static qv q_call(qparse *p, const char *name, size_t n, const char *at, qv a, qv b, int two)
{
    const dim angle = quantity_table[Q_ANGLE].d;
#define IS(fn) qparse_is_fn(name, n, fn)
    if (IS("atan2")) {
        if (!two) {
            qparse_fail(p, at, "atan2 takes two arguments: atan2(y, x)");
            return a;
        }
        qparse_unify(p, &a, &b, at, "subtract");
        double r = atan2(a.v, b.v);
        return (qv){r, record(p, PX_ATAN2, 0.0, a, b, r), angle, 0};
    }
    if (two) {
        qparse_fail(p, at, "%.*s takes one argument", (int)n, name);
        return a;
    }
    if (IS("sqrt")) {
        dim half;
        if (qparse_sqrt_dim(p, a, at, 1, &half) < 0)
            return a;
        double r = sqrt(a.v);
        return (qv){r, record(p, PX_SQRT, 0.0, a, a, r), half, a.bare};
    }
    if (IS("sin") || IS("cos") || IS("tan")) {
        if (a.bare) {
            a = p->ops->scale(p, a, p->env->units->scale[Q_ANGLE]);
        } else if (!dim_equal(a.d, angle) && !dim_is_none(a.d)) {
            qparse_fail(p, at, "%.*s needs an angle", (int)n, name);
            return a;
        }
        double r = IS("sin") ? sin(a.v) : IS("cos") ? cos(a.v) : tan(a.v);
        px_op op = IS("sin") ? PX_SIN : IS("cos") ? PX_COS : PX_TAN;
        return (qv){r, record(p, op, 0.0, a, a, r), {{0, 0, 0, 0}}, 1};  /* a pure number:
                                                  100 * cos(60) takes the default length unit */
    }
#undef IS
    qparse_fail(p, at, "unknown function '%.*s' (known: sqrt, sin, cos, tan, atan2)", (int)n,
                name);
    return a;
}

static qv q_neg(qparse *p, qv a)
{
    double r = -a.v;
    a.h = record(p, PX_NEG, 0.0, a, a, r);
    a.v = r;
    return a;
}

static qv q_scale(qparse *p, qv a, double k)
{
    double r = a.v * k;
    a.h = record(p, PX_SCALE, k, a, a, r);
    a.v = r;
    return a;
}

static qv q_add(qparse *p, qv a, qv b, char op, const char *at)
{
    (void)at;
    double r = op == '+' ? a.v + b.v : a.v - b.v;
    a.h = record(p, op == '+' ? PX_ADD : PX_SUB, 0.0, a, b, r);
    a.v = r;
    return a;
}

static qv q_mul(qparse *p, qv a, qv b, char op, const char *at)
{
    if (op == '/' && b.v == 0) {
        qparse_fail(p, at, "division by zero");
        return a;
    }
    double r = op == '*' ? a.v * b.v : a.v / b.v;
    a.h = record(p, op == '*' ? PX_MUL : PX_DIV, 0.0, a, b, r);
    a.v = r;
    return a;
}

static qv q_powi(qparse *p, qv a, int e, const char *at)
{
    (void)at;
    double r = pow(a.v, e);
    a.h = record(p, PX_POWI, (double)e, a, a, r);
    a.v = r;
    return a;
}

static const qparse_ops quantity_ops = {
    .constant = q_constant,
    .param = q_param,
    .unit = q_unit,
    .call = q_call,
    .neg = q_neg,
    .scale = q_scale,
    .add = q_add,
    .mul = q_mul,
    .powi = q_powi,
    .unknown_name = " (not a unit, a function, or a parameter defined above)",
    .unit_alone = 1,
    .strict_exponent = 1,
    .checked_dims = 1,
    .after = "value",
};

static int run_parser(qparse *p, const char *text, const expr_env *env, char *err,
                      size_t errsize, qv *out)
{
    qparse_init(p, text, env, &quantity_ops, env->record, err, errsize);
    *out = qparse_run(p);
    if (!p->failed && !isfinite(out->v))
        qparse_fail(p, p->start, "value is not a finite number");
    return p->failed ? -1 : 0;
}

int quantity_eval(const char *text, quantity want, const expr_env *env, double *value,
                  char *err, size_t errsize, size_t *err_pos)
{
    qparse p;
    qv v;
    if (run_parser(&p, text, env, err, errsize, &v) < 0) {
        *err_pos = p.err_pos;
        return -1;
    }
    const quantity_info *qi = &quantity_table[want];
    if (v.bare)
        v = p.ops->scale(&p, v, env->units->scale[want]);
    if (env->root)
        *env->root = v.h;
    if (v.bare) {
        *value = v.v;
        return 0;
    }
    if (!dim_equal(v.d, qi->d)) {
        char got[96];
        qparse_describe(v.d, got, sizeof got);
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
    qparse p;
    qv v;
    if (run_parser(&p, text, env, err, errsize, &v) < 0) {
        *err_pos = p.err_pos;
        return -1;
    }
    out->value = v.v;
    out->root = v.h;
    out->d = v.d;
    out->bare = v.bare;
    return 0;
}

int mech_parse_value(const char *text, int is_angle, double *si, char *err, size_t errsize)
{
    double unused;
    if (!err)
        errsize = 0;  /* vsnprintf(NULL, 0, ...) writes nothing */
    if (!text)
        return snprintf(err, errsize, "mech_parse_value: text is NULL"), MECH_EINPUT;
    unit_defaults u;
    unit_defaults_init(&u);
    u.scale[Q_ANGLE] = 3.14159265358979323846 / 180.0;  /* bare angles: degrees */
    u.scale[Q_LENGTH] = 1e-3;                            /* bare lengths: millimetres */
    expr_env env = {&u, NULL, 0};
    size_t pos;
    quantity q = is_angle == 2 ? Q_TIME : is_angle ? Q_ANGLE : Q_LENGTH;  /* 2: a time, s */
    return quantity_eval(text, q, &env, si ? si : &unused, err, errsize, &pos) == 0
               ? MECH_OK : MECH_EINPUT;
}
