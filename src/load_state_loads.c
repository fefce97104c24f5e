/* src/load_state_loads.c: the loader's part of the loads that depend on
 * the motion (docs/format.md section 10.2). A load component that does not
 * read as a constant quantity is parsed here, with the grammar and the unit
 * rules of units.c's quantity expressions (bare numbers take their
 * context's unit, + - min max atan2 need one dimension, sin cos tan an
 * angle, sqrt even powers), plus
 *   dotted names of the state: P.x P.y P.vx P.vy P.ax P.ay (a point),
 *     L.angle L.omega L.alpha (a link), J.s J.v J.a (a slider joint),
 *     driver.value driver.speed driver.accel;
 *   functions: abs min max exp log tanh step sign smoothsign(x, eps).
 * It compiles into the model's state_loads program (src/state_loads.c),
 * folding constants; every error is reported at its line:column. */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"
#include "state_loads.h"

static const double PI = 3.14159265358979323846;

typedef struct sval {
    int reg;   /* -1: failed */
    dim d;
    int bare;  /* a number without unit whose quantity is not known yet */
} sval;

typedef struct sparser {
    loader *ld;
    state_loads *s;
    const char *start, *p;
    char err[256];
    size_t err_pos;
    int failed;
    int depth;
    int uses_state;  /* a dotted name or a function units.c does not know was seen */
    int nomem;       /* an allocation failed */
} sparser;

static const dim NONE = {{0, 0, 0, 0}};

static void sfail(sparser *sp, const char *at, const char *fmt, ...) MECH_PRINTF(3, 4);
static void sfail(sparser *sp, const char *at, const char *fmt, ...)
{
    if (sp->failed)
        return;
    sp->failed = 1;
    sp->err_pos = (size_t)(at - sp->start);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(sp->err, sizeof sp->err, fmt, ap);
    va_end(ap);
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

/* With laws of time (`sweep: {time}`, MECH_DRIVE_TIME) a load may read the
 * time as `t`, as the drivers' laws do: the word `t` is then the time, never
 * the tonne. Where the first standalone word `t` starts in s, or NULL. */
static const char *time_word(const loader *ld, const char *s)
{
    if (!ld->m->has_driver || ld->m->driver.kind != MECH_DRIVE_TIME)
        return NULL;
    for (const char *c = s; *c; c++) {
        int before = c > s && (isalnum((unsigned char)c[-1]) || c[-1] == '_' || c[-1] == '.');
        if (*c == 't' && !before && !(isalnum((unsigned char)c[1]) || c[1] == '_'))
            return c;
    }
    return NULL;
}

static const char *skip_space(const char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    return s;
}

static dim dim_combine(dim a, dim b, int sign)
{
    dim r;
    for (int i = 0; i < NDIMS; i++)
        r.e[i] = (signed char)(a.e[i] + sign * b.e[i]);
    return r;
}

static int dim_none(dim d) { return dim_equal(d, NONE); }

static double default_scale(const sparser *sp, dim d)
{
    for (int q = 1; q < NQUANTITIES; q++)
        if (dim_equal(d, quantity_get((quantity)q)->d))
            return sp->ld->units.scale[q];
    return 1.0;
}

static void describe_dim(dim d, char *buf, size_t size)
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

static sval fail_val(void) { return (sval){-1, NONE, 1}; }

static int emit(sparser *sp, int op, int a, int b, int k)
{
    if (sp->failed || a < 0 || (b < -1))
        return -1;
    int r = sl_emit(sp->s, op, a, b, k);
    if (r < 0)
        sp->nomem = 1, sfail(sp, sp->p, "out of memory");
    return r;
}

static int constant(sparser *sp, double v)
{
    int r = sl_const(sp->s, v);
    if (r < 0)
        sp->nomem = 1, sfail(sp, sp->p, "out of memory");
    return r;
}

/* A bare value given dimension d: times the default unit of d. */
static void adopt(sparser *sp, sval *a, dim d)
{
    double k = default_scale(sp, d);
    if (k != 1.0)
        a->reg = emit(sp, SLOP_MUL, a->reg, constant(sp, k), 0);
    a->d = d;
    a->bare = 0;
}

/* Under + - min max atan2 smoothsign: one dimension; a bare operand takes
 * the other's. */
static void unify(sparser *sp, sval *a, sval *b, const char *at, const char *what)
{
    if (a->bare && !b->bare)
        adopt(sp, a, b->d);
    else if (b->bare && !a->bare)
        adopt(sp, b, a->d);
    else if (!dim_equal(a->d, b->d)) {
        char da[96], db[96];
        describe_dim(a->d, da, sizeof da);
        describe_dim(b->d, db, sizeof db);
        sfail(sp, at, "cannot %s %s and %s", what, da, db);
    }
}

static sval parse_expr(sparser *sp);

/* ---- names of the state -------------------------------------------- */

typedef struct member {
    const char *name;
    int kind;      /* sl_input_kind */
    quantity q;
} member;

static const member point_members[] = {
    {"x", SLIN_PX, Q_LENGTH}, {"y", SLIN_PY, Q_LENGTH}, {"vx", SLIN_PVX, Q_SPEED},
    {"vy", SLIN_PVY, Q_SPEED}, {"ax", SLIN_PAX, Q_ACCELERATION}, {"ay", SLIN_PAY, Q_ACCELERATION}};
static const member link_members[] = {
    {"angle", SLIN_ANGLE, Q_ANGLE}, {"omega", SLIN_OMEGA, Q_ANGULAR_SPEED},
    {"alpha", SLIN_ALPHA, Q_ANGULAR_ACCELERATION}};
static const member slider_members[] = {
    {"s", SLIN_S, Q_LENGTH}, {"v", SLIN_SV, Q_SPEED}, {"a", SLIN_SA, Q_ACCELERATION}};
static const member driver_members[] = {
    {"value", SLIN_DRIVER, Q_ANGLE}, {"speed", SLIN_DRIVER_SPEED, Q_ANGULAR_SPEED},
    {"accel", SLIN_DRIVER_ACCEL, Q_ANGULAR_ACCELERATION}};

static const member *find_member(const member *ms, size_t n, const char *name, size_t len)
{
    for (size_t i = 0; i < n; i++)
        if (strlen(ms[i].name) == len && memcmp(ms[i].name, name, len) == 0)
            return &ms[i];
    return NULL;
}

static void list_members(const member *ms, size_t n, char *buf, size_t size)
{
    size_t at = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < n && at < size; i++)
        at += (size_t)snprintf(buf + at, size - at, "%s%s", i ? ", " : "", ms[i].name);
}

static sval input(sparser *sp, int kind, int index, quantity q)
{
    int r = sl_input_reg(sp->s, kind, index);
    if (r < 0)
        sp->nomem = 1, sfail(sp, sp->p, "out of memory");
    return (sval){r, quantity_get(q)->d, 0};
}

/* NAME.MEMBER at `at` (name n bytes, member at mem, mlen bytes). */
static sval dotted(sparser *sp, const char *at, size_t n, const char *mem, size_t mlen)
{
    loader *ld = sp->ld;
    const mech_model *m = ld->m;
    char name[MAX_NAME + 1], list[128];
    sp->uses_state = 1;
    if (n > MAX_NAME) {
        sfail(sp, at, "name too long");
        return fail_val();
    }
    memcpy(name, at, n);
    name[n] = '\0';
    const member *pm = find_member(point_members, COUNT(point_members), mem, mlen);
    const member *lm = find_member(link_members, COUNT(link_members), mem, mlen);
    const member *jm = find_member(slider_members, COUNT(slider_members), mem, mlen);
    int pt = find_point(ld, name), li = find_link(ld, name), jt = find_joint(ld, name);
    int is_driver = strcmp(name, "driver") == 0 && pt < 0 && li < 0 && jt < 0;
    if (is_driver) {
        const member *dm = find_member(driver_members, COUNT(driver_members), mem, mlen);
        if (!dm || !m->has_driver) {
            list_members(driver_members, COUNT(driver_members), list, sizeof list);
            sfail(sp, mem, m->has_driver ? "the driver has no '%.*s' (it has: %s)"
                                         : "no driver to read '%.*s' of (%s)",
                  (int)mlen, mem, list);
            return fail_val();
        }
        quantity q = dm->q;
        if (m->driver.kind == MECH_DRIVE_TIME) {  /* the sweep variable is the time */
            if (dm->kind != SLIN_DRIVER) {
                sfail(sp, mem, "with laws of time the driver's value is the time t and has no "
                               "'%.*s': read the driven links' or sliders' rates instead",
                      (int)mlen, mem);
                return fail_val();
            }
            q = Q_TIME;
        }
        if (m->driver.kind == MECH_DRIVE_SLIDER)
            q = dm->kind == SLIN_DRIVER ? Q_LENGTH
                : dm->kind == SLIN_DRIVER_SPEED ? Q_SPEED : Q_ACCELERATION;
        return input(sp, dm->kind, 0, q);
    }
    if (pm && pt >= 0)
        return input(sp, pm->kind, pt, pm->q);
    if (lm && li >= 0) {
        if (li == 0) {
            sfail(sp, at, "the ground does not move: '%s.%.*s' is always 0", name, (int)mlen, mem);
            return fail_val();
        }
        return input(sp, lm->kind, li, lm->q);
    }
    if (jm && jt >= 0 && m->joints[jt].kind == MECH_JOINT_SLIDER)
        return input(sp, jm->kind, jt, jm->q);
    /* the name is something, but not with that member */
    const member *ms = pt >= 0 ? point_members : li >= 0 ? link_members : jt >= 0 ? slider_members
                                                                              : NULL;
    if (ms) {
        size_t nm = pt >= 0 ? COUNT(point_members) : li >= 0 ? COUNT(link_members)
                                                             : COUNT(slider_members);
        const char *what = pt >= 0 ? "point" : li >= 0 ? "link" : "joint";
        if (jt >= 0 && pt < 0 && li < 0 && m->joints[jt].kind != MECH_JOINT_SLIDER)
            sfail(sp, at, "'%s' is a revolute joint: it has no value to read (a slider has s, "
                          "v, a)", name);
        else {
            list_members(ms, nm, list, sizeof list);
            sfail(sp, mem, "%s '%s' has no '%.*s' (it has: %s)", what, name, (int)mlen, mem, list);
        }
        return fail_val();
    }
    const char *near = nearest_name(name, (const char *const *)m->point_names,
                                    (size_t)m->npoint_names);
    if (!near && li < 0) {
        const char *links[64];
        size_t k = 0;
        for (int i = 0; i < m->nlinks && k < COUNT(links); i++)
            links[k++] = m->links[i].name;
        near = nearest_name(name, links, k);
    }
    if (near)
        sfail(sp, at, "unknown name '%s' in '%s.%.*s' (did you mean '%s'?)", name, name,
              (int)mlen, mem, near);
    else
        sfail(sp, at, "unknown name '%s' in '%s.%.*s' (not a point, link, slider or 'driver')",
              name, name, (int)mlen, mem);
    return fail_val();
}

/* ---- functions ------------------------------------------------------ */

static int is_fn(const char *name, size_t n, const char *fn)
{
    return n == strlen(fn) && memcmp(name, fn, n) == 0;
}

static sval call(sparser *sp, const char *name, size_t n, const char *at)
{
    static const char *const new_fns[] = {"abs", "min", "max", "exp", "log", "tanh",
                                          "step", "sign", "smoothsign"};
    for (size_t i = 0; i < COUNT(new_fns); i++)
        if (is_fn(name, n, new_fns[i]))
            sp->uses_state = 1;
    sval a = parse_expr(sp), b = {-1, NONE, 1};
    int two = 0;
    sp->p = skip_space(sp->p);
    if (*sp->p == ',') {
        sp->p++;
        b = parse_expr(sp);
        two = 1;
        sp->p = skip_space(sp->p);
    }
    if (sp->failed)
        return fail_val();
    if (*sp->p != ')') {
        sfail(sp, sp->p, "expected ')' to close %.*s(", (int)n, name);
        return fail_val();
    }
    sp->p++;
    const dim angle = quantity_get(Q_ANGLE)->d;
    int wants_two = is_fn(name, n, "atan2") || is_fn(name, n, "min") || is_fn(name, n, "max") ||
                    is_fn(name, n, "smoothsign");
    int known = wants_two || is_fn(name, n, "sqrt") || is_fn(name, n, "sin") ||
                is_fn(name, n, "cos") || is_fn(name, n, "tan");
    for (size_t i = 0; i < COUNT(new_fns); i++)
        known |= is_fn(name, n, new_fns[i]);
    if (!known) {
        sfail(sp, at, "unknown function '%.*s' (known: sqrt, sin, cos, tan, atan2, abs, min, "
                      "max, exp, log, tanh, step, sign, smoothsign)", (int)n, name);
        return fail_val();
    }
    if (wants_two != two) {
        sfail(sp, at, wants_two ? "%.*s takes two arguments" : "%.*s takes one argument",
              (int)n, name);
        return fail_val();
    }
    if (wants_two) {
        unify(sp, &a, &b, at, is_fn(name, n, "atan2") ? "compare" : "compare");
        if (is_fn(name, n, "atan2"))
            return (sval){emit(sp, SLOP_ATAN2, a.reg, b.reg, 0), angle, 0};
        if (is_fn(name, n, "smoothsign")) {
            if (sl_is_const(sp->s, b.reg) && !(sp->s->reg0[b.reg] > 0.0)) {
                sfail(sp, at, "smoothsign(x, eps) needs eps > 0");
                return fail_val();
            }
            return (sval){emit(sp, SLOP_SMOOTHSIGN, a.reg, b.reg, 0), NONE, 1};
        }
        a.reg = emit(sp, is_fn(name, n, "min") ? SLOP_MIN : SLOP_MAX, a.reg, b.reg, 0);
        return a;
    }
    if (is_fn(name, n, "sqrt")) {
        for (int i = 0; i < NDIMS; i++)
            if (a.d.e[i] % 2) {
                sfail(sp, at, "sqrt of a quantity whose unit has an odd power");
                return fail_val();
            }
        for (int i = 0; i < NDIMS; i++)
            a.d.e[i] = (signed char)(a.d.e[i] / 2);
        a.reg = emit(sp, SLOP_SQRT, a.reg, -1, 0);
        return a;
    }
    if (is_fn(name, n, "sin") || is_fn(name, n, "cos") || is_fn(name, n, "tan")) {
        if (a.bare)
            adopt(sp, &a, angle);
        else if (!dim_equal(a.d, angle) && !dim_none(a.d)) {
            sfail(sp, at, "%.*s needs an angle", (int)n, name);
            return fail_val();
        }
        int op = is_fn(name, n, "sin") ? SLOP_SIN : is_fn(name, n, "cos") ? SLOP_COS : SLOP_TAN;
        return (sval){emit(sp, op, a.reg, -1, 0), NONE, 1};
    }
    if (is_fn(name, n, "abs")) {
        a.reg = emit(sp, SLOP_ABS, a.reg, -1, 0);
        return a;
    }
    if (is_fn(name, n, "step") || is_fn(name, n, "sign"))
        return (sval){emit(sp, is_fn(name, n, "step") ? SLOP_STEP : SLOP_SIGN, a.reg, -1, 0),
                      NONE, 1};
    /* exp, log, tanh: of a pure number */
    if (!a.bare && !dim_none(a.d)) {
        char da[96];
        describe_dim(a.d, da, sizeof da);
        sfail(sp, at, "%.*s needs a pure number, got %s (divide by a reference value)", (int)n,
              name, da);
        return fail_val();
    }
    int op = is_fn(name, n, "exp") ? SLOP_EXP : is_fn(name, n, "log") ? SLOP_LOG : SLOP_TANH;
    return (sval){emit(sp, op, a.reg, -1, 0), NONE, 1};
}

/* ---- the grammar (units.c's) -------------------------------------- */

static int param_index(const sparser *sp, const char *name, size_t n)
{
    char word[MAX_NAME + 1];
    if (n > MAX_NAME)
        return -1;
    memcpy(word, name, n);
    word[n] = '\0';
    const expr_env *env = &sp->ld->env;
    if (env->param_index)
        return name_map_get(env->param_index, word);
    for (int i = 0; i < env->nparams; i++)
        if (strcmp(env->params[i].name, word) == 0)
            return i;
    return -1;
}

static sval parse_number(sparser *sp)
{
    const char *s = sp->p;
    char *end;
    double v = strtod(s, &end);
    if (end == s || !isfinite(v)) {
        sfail(sp, s, end == s ? "expected a number" : "number out of range");
        return fail_val();
    }
    sp->p = end;
    const char *u = skip_space(end);
    if (ident_len(u) == 0)
        return (sval){constant(sp, v), NONE, 1};
    double scale;
    dim d;
    const char *uend, *tw = time_word(sp->ld, u);
    char unit[128];
    if (tw) {  /* the unit ends before `t` and the operator in front of it */
        size_t len = (size_t)(tw - u);
        while (len > 0 && (u[len - 1] == ' ' || u[len - 1] == '\t' || u[len - 1] == '*' ||
                           u[len - 1] == '/'))
            len--;
        if (len >= sizeof unit)
            len = sizeof unit - 1;
        memcpy(unit, u, len);
        unit[len] = '\0';
    }
    if (tw && unit[0] == '\0')
        return (sval){constant(sp, v), NONE, 1};  /* `2 * t`: a bare number */
    if (!unit_parse(tw ? unit : u, &scale, &d, &uend)) {
        sfail(sp, u, "unknown unit '%.*s'", (int)ident_len(u), u);
        return fail_val();
    }
    sp->p = tw ? u + (uend - unit) : uend;
    return (sval){constant(sp, v * scale), d, 0};
}

static sval parse_atom(sparser *sp)
{
    sp->p = skip_space(sp->p);
    const char *at = sp->p;
    if (*at == '(') {
        sp->p++;
        sval v = parse_expr(sp);
        sp->p = skip_space(sp->p);
        if (*sp->p != ')')
            sfail(sp, sp->p, "expected ')'");
        else
            sp->p++;
        return v;
    }
    size_t n = ident_len(at);
    if (n) {
        sp->p = at + n;
        if (*sp->p == '.') {
            const char *mem = sp->p + 1;
            size_t ml = ident_len(mem);
            if (!ml) {
                sfail(sp, mem, "expected a name after '.'");
                return fail_val();
            }
            sp->p = mem + ml;
            return dotted(sp, at, n, mem, ml);
        }
        const char *after = skip_space(sp->p);
        if (*after == '(') {
            sp->p = after + 1;
            return call(sp, at, n, at);
        }
        if (n == 1 && time_word(sp->ld, at) == at) {  /* the time of laws of time */
            sp->uses_state = 1;
            return input(sp, SLIN_DRIVER, 0, Q_TIME);
        }
        if (n == 2 && memcmp(at, "pi", 2) == 0)
            return (sval){constant(sp, PI), quantity_get(Q_ANGLE)->d, 0};
        int found = param_index(sp, at, n);
        if (found >= 0) {
            const expr_param *q = &sp->ld->env.params[found];
            return (sval){constant(sp, q->value), q->d, q->bare};
        }
        sfail(sp, at, "unknown name '%.*s' (not a unit, a function, a parameter defined above, "
                      "or NAME.MEMBER of the motion)", (int)(n < 64 ? n : 64), at);
        return fail_val();
    }
    if (*at == '\0') {
        sfail(sp, at, "value missing");
        return fail_val();
    }
    if (!(isdigit((unsigned char)*at) || *at == '.')) {
        sfail(sp, at, "unexpected '%c'", *at);
        return fail_val();
    }
    return parse_number(sp);
}

static sval parse_power(sparser *sp)
{
    sval a = parse_atom(sp);
    const char *s = skip_space(sp->p);
    if (*s != '^')
        return a;
    const char *at = s;
    s = skip_space(s + 1);
    int sign = 1, e = 0;
    if (*s == '-')
        sign = -1, s++;
    if (!isdigit((unsigned char)*s)) {
        sfail(sp, at, "expected an integer exponent after '^'");
        return fail_val();
    }
    while (isdigit((unsigned char)*s) && e < 100)
        e = e * 10 + (*s++ - '0');
    if (e >= 100) {
        sfail(sp, at, "expected an integer exponent after '^'");
        return fail_val();
    }
    sp->p = s;
    e *= sign;
    for (int i = 0; i < NDIMS; i++)
        a.d.e[i] = (signed char)(a.d.e[i] * e);
    a.reg = emit(sp, SLOP_POWI, a.reg, -1, e);
    return a;
}

static sval parse_unary(sparser *sp)
{
    sp->p = skip_space(sp->p);
    if (++sp->depth > 64) {
        sfail(sp, sp->p, "expression nested too deeply");
        return fail_val();
    }
    sval v;
    if (*sp->p == '-' || *sp->p == '+') {
        int neg = *sp->p == '-';
        sp->p++;
        v = parse_unary(sp);
        if (neg)
            v.reg = emit(sp, SLOP_NEG, v.reg, -1, 0);
    } else {
        v = parse_power(sp);
    }
    sp->depth--;
    return v;
}

static sval parse_term(sparser *sp)
{
    sval a = parse_unary(sp);
    for (;;) {
        const char *at = skip_space(sp->p);
        if (sp->failed || (*at != '*' && *at != '/'))
            return a;
        sp->p = at + 1;
        sval b = parse_unary(sp);
        if (sp->failed)
            return a;
        if (*at == '/' && sl_is_const(sp->s, b.reg) && sp->s->reg0[b.reg] == 0.0) {
            sfail(sp, at, "division by zero");
            return a;
        }
        a.reg = emit(sp, *at == '*' ? SLOP_MUL : SLOP_DIV, a.reg, b.reg, 0);
        a.d = dim_combine(a.d, b.d, *at == '*' ? 1 : -1);
        a.bare = a.bare && b.bare;
    }
}

static sval parse_expr(sparser *sp)
{
    sval a = parse_term(sp);
    for (;;) {
        const char *at = skip_space(sp->p);
        if (sp->failed || (*at != '+' && *at != '-'))
            return a;
        sp->p = at + 1;
        sval b = parse_term(sp);
        if (sp->failed)
            return a;
        unify(sp, &a, &b, at, *at == '+' ? "add" : "subtract");
        a.reg = emit(sp, *at == '+' ? SLOP_ADD : SLOP_SUB, a.reg, b.reg, 0);
    }
}

/* ---- load components ---------------------------------------------- */

static state_loads *model_program(loader *ld)
{
    if (!ld->m->state_loads)
        ld->m->state_loads = state_loads_new();
    return ld->m->state_loads;
}

/* Compile the scalar n as quantity q into a register: a constant quantity
 * (units.c's evaluation, exactly) or an expression of the state. -1 when
 * it was reported. */
static int component(loader *ld, const ynode *n, quantity q, const char *what)
{
    state_loads *s = model_program(ld);
    if (!s)
        return load_err(ld, n, "out of memory"), -1;
    if (!load_want_kind(ld, n, YNODE_SCALAR, what))
        return -1;
    char msg[256];
    size_t pos;
    double v;
    if (!time_word(ld, n->text) &&
        quantity_eval(n->text, q, &ld->env, &v, msg, sizeof msg, &pos) == 0) {
        int r = sl_const(s, v);
        if (r < 0)
            load_err(ld, n, "out of memory");
        return r;
    }
    sparser sp = {ld, s, n->text, n->text, "", 0, 0, 0, 0, 0};
    sval r = parse_expr(&sp);
    sp.p = skip_space(sp.p);
    if (!sp.failed && *sp.p != '\0')
        sfail(&sp, sp.p, "unexpected '%c' after the value", *sp.p);
    if (!sp.failed) {
        if (r.bare)
            adopt(&sp, &r, quantity_get(q)->d);
        else if (!dim_equal(r.d, quantity_get(q)->d)) {
            char got[96];
            describe_dim(r.d, got, sizeof got);
            sfail(&sp, sp.start, "expected %s, got %s", quantity_get(q)->noun, got);
        }
    }
    if (!sp.failed && r.reg >= 0)
        return r.reg;
    if (sp.nomem)
        return load_err(ld, n, "out of memory"), -1;
    if (!sp.uses_state) {  /* nothing of the motion: units.c's own message */
        load_get_quantity(ld, n, q, what, &v);
        return -1;
    }
    if (load_uses_bad_param(ld, n->text))
        return -1;
    mech_mark at = n->mark;
    if (!strchr(n->text, '\n'))
        at.col += (int)sp.err_pos + (n->quoted ? 1 : 0);
    diag_error(ld->d, ld->file, at, "%s: %s", what, sp.err);
    return -1;
}

int load_state_wanted(loader *ld, const ynode *n)
{
    const ynode *one[1] = {n};
    const ynode *const *items = one;
    size_t count = 1;
    if (n->kind == YNODE_SEQ) {
        if (n->n != 2)
            return 0;
        items = (const ynode *const *)n->items;
        count = 2;
    }
    char msg[256];
    size_t pos;
    for (size_t i = 0; i < count; i++) {
        if (items[i]->kind != YNODE_SCALAR)
            return 0;
        expr_param val;
        if (time_word(ld, items[i]->text))  /* the time of laws of time */
            return 1;
        if (quantity_eval_param(items[i]->text, &ld->env, &val, msg, sizeof msg, &pos) != 0 &&
            !load_uses_bad_param(ld, items[i]->text))
            return 1;
    }
    return 0;
}

void load_state_load(loader *ld, const ynode *map, const ynode *value, int link, int point)
{
    sl_load l = {value->kind != YNODE_SEQ, link, point, {-1, -1}, map->mark};
    int ok;
    if (l.torque)
        ok = (l.reg[0] = component(ld, value, Q_TORQUE, "torque")) >= 0;
    else {
        int a = component(ld, value->items[0], Q_FORCE, "force");
        int b = component(ld, value->items[1], Q_FORCE, "force");
        l.reg[0] = a, l.reg[1] = b;
        ok = a >= 0 && b >= 0;
    }
    if (!ok || link < 0 || (!l.torque && point < 0))
        return;
    if (link == 0)
        return (void)load_err(ld, map, "a load on the ground does nothing; put it on a moving link");
    if (sl_add_load(ld->m->state_loads, &l) < 0)
        load_err(ld, map, "out of memory");
}

/* ---- a force along a line ------------------------------------------ */

void load_state_line(loader *ld, const ynode *map)
{
    static const char *const not_here[] = {"torque", "distributed", "link", "at", "from", "to",
                                           "direction"};
    for (size_t i = 0; i < COUNT(not_here); i++) {
        const ynode *k = load_key_of(map, not_here[i]);
        if (k)
            return (void)load_err(ld, k, "'%s' does not apply to a force along a line "
                                         "('between:')", not_here[i]);
    }
    const ynode *f = ymap_get(map, "force"), *btw = ymap_get(map, "between"),
                *links = ymap_get(map, "links");
    if (!btw)
        return (void)load_err(ld, map, "'links' needs 'between: [P, Q]' (a force along a line)");
    if (!f)
        return (void)load_err(ld, map, "a load 'between' two points needs 'force: TENSION'");
    if (!load_want_kind(ld, f, YNODE_SCALAR, "force along a line (one value, tension positive)") ||
        !load_want_kind(ld, btw, YNODE_SEQ, "'between'"))
        return;
    if (btw->n != 2)
        return (void)load_err(ld, btw, "'between' needs two points, [P, Q]");
    if (links && !load_want_kind(ld, links, YNODE_SEQ, "'links'"))
        return;
    if (links && links->n != 2)
        return (void)load_err(ld, links, "'links' needs two links, [a, b]");
    int id[2], cand[2][8], n[2];
    for (int k = 0; k < 2; k++) {
        id[k] = load_find_point_or_report(ld, btw->items[k], "load end");
        n[k] = id[k] < 0 ? -1 : load_end_candidates(ld, links, k, id[k], btw->items[k], "loaded link", cand[k], 8);
    }
    int reg = component(ld, f, Q_FORCE, "force");
    if (n[0] <= 0 || n[1] <= 0 || reg < 0)
        return;
    for (int a = 0; a < n[0]; a++)
        for (int b = 0; b < n[1]; b++)
            if (cand[0][a] != cand[1][b]) {
                sl_load l = {2, cand[0][a], load_point_in_link(ld, cand[0][a], id[0]), {reg, -1},
                             map->mark, cand[1][b], load_point_in_link(ld, cand[1][b], id[1])};
                if (sl_add_load(ld->m->state_loads, &l) < 0)
                    load_err(ld, map, "out of memory");
                return;
            }
    load_err(ld, btw, "both ends are on link '%s': a force between them does nothing; attach "
                      "it between two links", ld->m->links[cand[0][0]].name);
}
