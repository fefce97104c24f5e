/* src/load/load_state_loads.c: the loader's part of the loads that depend on
 * the motion (docs/format.md section 10.2). A load component that does not
 * read as a constant quantity is parsed by qparse.c (the grammar and the
 * unit rules of units.c's quantity expressions: bare numbers take their
 * context's unit, + - min max atan2 need one dimension, sin cos tan an
 * angle, sqrt even powers) with this file as its backend, which adds
 *   dotted names of the state: P.x P.y P.vx P.vy P.ax P.ay (a point),
 *     L.angle L.omega L.alpha (a link), J.s J.v J.a (a slider joint),
 *     driver.value driver.speed driver.accel;
 *   functions: abs min max exp log tanh step sign smoothsign(x, eps);
 *   the time t under laws of time.
 * It compiles into the model's state_loads program (src/load/state_loads.c),
 * folding constants; every error is reported at its line:column. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

/* The backend's state (qparse.h: p->ctx). A value is a register, qv.h
 * (-1: failed). */
typedef struct sparser {
    loader *ld;
    state_loads *s;
    int uses_state;  /* a dotted name or a function units.c does not know was seen */
    int nomem;       /* an allocation failed */
} sparser;

static const dim NONE = {{0, 0, 0, 0}};

/* With laws of time (`sweep: {time}`, MECH_DRIVE_TIME) a load may read the
 * time as `t`, as the drivers' laws do: the word `t` is then the time, never
 * the tonne. Where the first standalone word `t` starts in s, or NULL.
 * The sweep's kind is set before the drivers are read (has_driver only
 * after), so a free driver's `load:` sees `t` too. */
static const char *time_word(const loader *ld, const char *s)
{
    if (ld->m->driver.kind != MECH_DRIVE_TIME)
        return NULL;
    for (const char *c = s; *c; c++) {
        int before = c > s && (isalnum((unsigned char)c[-1]) || c[-1] == '_' || c[-1] == '.');
        if (*c == 't' && !before && !(isalnum((unsigned char)c[1]) || c[1] == '_'))
            return c;
    }
    return NULL;
}

static int dim_none(dim d) { return dim_equal(d, NONE); }

static qv fail_val(void) { return (qv){0, -1, {{0, 0, 0, 0}}, 1}; }

static qv reg_val(int reg, dim d, int bare) { return (qv){0, reg, d, bare}; }

static int emit(qparse *p, int op, int a, int b, int k)
{
    sparser *sp = p->ctx;
    if (p->failed || a < 0 || (b < -1))
        return -1;
    int r = sl_emit(sp->s, op, a, b, k);
    if (r < 0)
        sp->nomem = 1, qparse_fail(p, p->s, "out of memory");
    return r;
}

static int constant(qparse *p, double v)
{
    sparser *sp = p->ctx;
    int r = sl_const(sp->s, v);
    if (r < 0)
        sp->nomem = 1, qparse_fail(p, p->s, "out of memory");
    return r;
}

/* a bare value taking the unit k times SI */
static qv s_scale(qparse *p, qv a, double k)
{
    if (k != 1.0)
        a.h = emit(p, SLOP_MUL, a.h, constant(p, k), 0);
    return a;
}

/* A bare value given dimension d: times the default unit of d. */
static void adopt(qparse *p, qv *a, dim d)
{
    *a = s_scale(p, *a, qparse_default_scale(p, d));
    a->d = d;
    a->bare = 0;
}



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

static qv input(qparse *p, int kind, int index, quantity q)
{
    sparser *sp = p->ctx;
    int r = sl_input_reg(sp->s, kind, index);
    if (r < 0)
        sp->nomem = 1, qparse_fail(p, p->s, "out of memory");
    return reg_val(r, quantity_get(q)->d, 0);
}

/* NAME.MEMBER at `at` (name n bytes, member at mem, mlen bytes). */
static qv s_dotted(qparse *p, const char *at, size_t n, const char *mem, size_t mlen)
{
    sparser *sp = p->ctx;
    loader *ld = sp->ld;
    const mech_model *m = ld->m;
    char name[MAX_NAME + 1], list[128];
    sp->uses_state = 1;
    if (n > MAX_NAME) {
        qparse_fail(p, at, "name too long");
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
            qparse_fail(p, mem, m->has_driver ? "the driver has no '%.*s' (it has: %s)"
                                         : "no driver to read '%.*s' of (%s)",
                  (int)mlen, mem, list);
            return fail_val();
        }
        quantity q = dm->q;
        if (m->driver.kind == MECH_DRIVE_TIME) {  /* the sweep variable is the time */
            if (dm->kind != SLIN_DRIVER) {
                qparse_fail(p, mem, "with laws of time the driver's value is the time t and has no "
                               "'%.*s': read the driven links' or sliders' rates instead",
                      (int)mlen, mem);
                return fail_val();
            }
            q = Q_TIME;
        }
        if (m->driver.kind == MECH_DRIVE_SLIDER)
            q = dm->kind == SLIN_DRIVER ? Q_LENGTH
                : dm->kind == SLIN_DRIVER_SPEED ? Q_SPEED : Q_ACCELERATION;
        return input(p, dm->kind, 0, q);
    }
    if (pm && pt >= 0)
        return input(p, pm->kind, pt, pm->q);
    if (lm && li >= 0) {
        if (li == 0) {
            qparse_fail(p, at, "the ground does not move: '%s.%.*s' is always 0", name, (int)mlen, mem);
            return fail_val();
        }
        return input(p, lm->kind, li, lm->q);
    }
    if (jm && jt >= 0 && m->joints[jt].kind == MECH_JOINT_SLIDER)
        return input(p, jm->kind, jt, jm->q);
    /* the name is something, but not with that member */
    const member *ms = pt >= 0 ? point_members : li >= 0 ? link_members : jt >= 0 ? slider_members
                                                                              : NULL;
    if (ms) {
        size_t nm = pt >= 0 ? COUNT(point_members) : li >= 0 ? COUNT(link_members)
                                                             : COUNT(slider_members);
        const char *what = pt >= 0 ? "point" : li >= 0 ? "link" : "joint";
        if (jt >= 0 && pt < 0 && li < 0 && m->joints[jt].kind != MECH_JOINT_SLIDER)
            qparse_fail(p, at, "'%s' is a revolute joint: it has no value to read (a slider has s, "
                          "v, a)", name);
        else {
            list_members(ms, nm, list, sizeof list);
            qparse_fail(p, mem, "%s '%s' has no '%.*s' (it has: %s)", what, name, (int)mlen, mem, list);
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
        qparse_fail(p, at, "unknown name '%s' in '%s.%.*s' (did you mean '%s'?)", name, name,
              (int)mlen, mem, near);
    else
        qparse_fail(p, at, "unknown name '%s' in '%s.%.*s' (not a point, link, slider or 'driver')",
              name, name, (int)mlen, mem);
    return fail_val();
}

/* ---- functions ------------------------------------------------------ */

static const char *const new_fns[] = {"abs", "min", "max", "exp", "log", "tanh",
                                      "step", "sign", "smoothsign"};

static void s_call_start(qparse *p, const char *name, size_t n)
{
    sparser *sp = p->ctx;
    for (size_t i = 0; i < COUNT(new_fns); i++)
        if (qparse_is_fn(name, n, new_fns[i]))
            sp->uses_state = 1;
}

static qv s_call(qparse *p, const char *name, size_t n, const char *at, qv a, qv b, int two)
{
    sparser *sp = p->ctx;
    const dim angle = quantity_get(Q_ANGLE)->d;
#define IS(fn) qparse_is_fn(name, n, fn)
    int wants_two = IS("atan2") || IS("min") || IS("max") || IS("smoothsign");
    int known = wants_two || IS("sqrt") || IS("sin") || IS("cos") || IS("tan");
    for (size_t i = 0; i < COUNT(new_fns); i++)
        known |= IS(new_fns[i]);
    if (!known) {
        qparse_fail(p, at, "unknown function '%.*s' (known: sqrt, sin, cos, tan, atan2, abs, "
                           "min, max, exp, log, tanh, step, sign, smoothsign)", (int)n, name);
        return fail_val();
    }
    if (wants_two != two) {
        qparse_fail(p, at, wants_two ? "%.*s takes two arguments" : "%.*s takes one argument",
                    (int)n, name);
        return fail_val();
    }
    if (wants_two) {
        qparse_unify(p, &a, &b, at, "compare");
        if (IS("atan2"))
            return reg_val(emit(p, SLOP_ATAN2, a.h, b.h, 0), angle, 0);
        if (IS("smoothsign")) {
            if (sl_is_const(sp->s, b.h) && !(sp->s->reg0[b.h] > 0.0)) {
                qparse_fail(p, at, "smoothsign(x, eps) needs eps > 0");
                return fail_val();
            }
            return reg_val(emit(p, SLOP_SMOOTHSIGN, a.h, b.h, 0), NONE, 1);
        }
        a.h = emit(p, IS("min") ? SLOP_MIN : SLOP_MAX, a.h, b.h, 0);
        return a;
    }
    if (IS("sqrt")) {
        if (qparse_sqrt_dim(p, a, at, 0, &a.d) < 0)
            return fail_val();
        a.h = emit(p, SLOP_SQRT, a.h, -1, 0);
        return a;
    }
    if (IS("sin") || IS("cos") || IS("tan")) {
        if (a.bare)
            adopt(p, &a, angle);
        else if (!dim_equal(a.d, angle) && !dim_none(a.d)) {
            qparse_fail(p, at, "%.*s needs an angle", (int)n, name);
            return fail_val();
        }
        int op = IS("sin") ? SLOP_SIN : IS("cos") ? SLOP_COS : SLOP_TAN;
        return reg_val(emit(p, op, a.h, -1, 0), NONE, 1);
    }
    if (IS("abs")) {
        a.h = emit(p, SLOP_ABS, a.h, -1, 0);
        return a;
    }
    if (IS("step") || IS("sign"))
        return reg_val(emit(p, IS("step") ? SLOP_STEP : SLOP_SIGN, a.h, -1, 0), NONE, 1);
    /* exp, log, tanh: of a pure number */
    if (!a.bare && !dim_none(a.d)) {
        char da[96];
        qparse_describe(a.d, da, sizeof da);
        qparse_fail(p, at, "%.*s needs a pure number, got %s (divide by a reference value)",
                    (int)n, name, da);
        return fail_val();
    }
    int op = IS("exp") ? SLOP_EXP : IS("log") ? SLOP_LOG : SLOP_TANH;
    return reg_val(emit(p, op, a.h, -1, 0), NONE, 1);
#undef IS
}

/* ---- the rest of the backend of qparse.c ---------------------------- */

static qv s_constant(qparse *p, double v)
{
    return reg_val(constant(p, v), NONE, 0);
}

static int s_unit(qparse *p, const char *u, double *scale, dim *d, const char **end)
{
    sparser *sp = p->ctx;
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
        return 0;  /* `2 * t`: a bare number */
    if (!unit_parse(tw ? unit : u, scale, d, &uend)) {
        qparse_fail(p, u, "unknown unit '%.*s'", (int)qparse_ident_len(u), u);
        return -1;
    }
    *end = tw ? u + (uend - unit) : uend;
    return 1;
}

static int s_word(qparse *p, const char *at, size_t n, qv *out)
{
    sparser *sp = p->ctx;
    if (!(n == 1 && time_word(sp->ld, at) == at))
        return 0;
    sp->uses_state = 1;  /* the time of laws of time */
    *out = input(p, SLIN_DRIVER, 0, Q_TIME);
    return 1;
}

static qv s_neg(qparse *p, qv v)
{
    v.h = emit(p, SLOP_NEG, v.h, -1, 0);
    return v;
}

static qv s_add(qparse *p, qv a, qv b, char op, const char *at)
{
    (void)at;
    a.h = emit(p, op == '+' ? SLOP_ADD : SLOP_SUB, a.h, b.h, 0);
    return a;
}

static qv s_mul(qparse *p, qv a, qv b, char op, const char *at)
{
    sparser *sp = p->ctx;
    if (op == '/' && sl_is_const(sp->s, b.h) && sp->s->reg0[b.h] == 0.0) {
        qparse_fail(p, at, "division by zero");
        return a;
    }
    a.h = emit(p, op == '*' ? SLOP_MUL : SLOP_DIV, a.h, b.h, 0);
    return a;
}

static qv s_powi(qparse *p, qv a, int e, const char *at)
{
    (void)at;
    a.h = emit(p, SLOP_POWI, a.h, -1, e);
    return a;
}

static const qparse_ops state_ops = {
    .constant = s_constant,
    .unit = s_unit,
    .word = s_word,
    .dotted = s_dotted,
    .call_start = s_call_start,
    .call = s_call,
    .neg = s_neg,
    .scale = s_scale,
    .add = s_add,
    .mul = s_mul,
    .powi = s_powi,
    .unknown_name = " (not a unit, a function, a parameter defined above, or NAME.MEMBER of "
                    "the motion)",
    .unit_alone = 0,
    .strict_exponent = 1,
    .checked_dims = 0,
    .after = "value",
};

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
        return load_nomem(ld, n), -1;
    if (!load_want_kind(ld, n, YNODE_SCALAR, what))
        return -1;
    char msg[256];
    size_t pos;
    double v;
    if (!time_word(ld, n->text) &&
        quantity_eval(n->text, q, &ld->env, &v, msg, sizeof msg, &pos) == 0) {
        int r = sl_const(s, v);
        if (r < 0)
            load_nomem(ld, n);
        return r;
    }
    sparser sp = {ld, s, 0, 0};
    char err[256] = "";
    qparse p;
    qparse_init(&p, n->text, &ld->env, &state_ops, &sp, err, sizeof err);
    qv r = qparse_run(&p);
    if (!p.failed) {
        if (r.bare)
            adopt(&p, &r, quantity_get(q)->d);
        else if (!dim_equal(r.d, quantity_get(q)->d)) {
            char got[96];
            qparse_describe(r.d, got, sizeof got);
            qparse_fail(&p, p.start, "expected %s, got %s", quantity_get(q)->noun, got);
        }
    }
    if (!p.failed && r.h >= 0)
        return r.h;
    if (sp.nomem)
        return load_nomem(ld, n), -1;
    if (!sp.uses_state) {  /* nothing of the motion: units.c's own message */
        load_get_quantity(ld, n, q, what, &v);
        return -1;
    }
    if (load_uses_bad_param(ld, n->text))
        return -1;
    mech_mark at = n->mark;
    if (!strchr(n->text, '\n'))
        at.col += (int)p.err_pos + (n->quoted ? 1 : 0);
    diag_error(ld->d, ld->file, at, "%s: %s", what, err);
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
    if (!l.torque && value->n != 2)
        return (void)load_err(ld, value, "a force needs two components, [Fx, Fy], not %zu",
                              value->n);
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
        load_nomem(ld, map);
}

/* A force of size `value` along the direction dir (rad, ground frame) at
 * point `point` of `link`: a free slider's load (load_drivers.c). */
void load_state_along(loader *ld, const ynode *map, const ynode *value, int link, int point,
                      double dir)
{
    int r = component(ld, value, Q_FORCE, "force");
    if (r < 0)
        return;
    state_loads *s = ld->m->state_loads;
    int c = sl_const(s, cos(dir)), sn = sl_const(s, sin(dir));
    sl_load l = {0, link, point, {-1, -1}, map->mark};
    l.reg[0] = c < 0 ? -1 : sl_emit(s, SLOP_MUL, r, c, 0);
    l.reg[1] = sn < 0 ? -1 : sl_emit(s, SLOP_MUL, r, sn, 0);
    if (l.reg[0] < 0 || l.reg[1] < 0 || sl_add_load(s, &l) < 0)
        load_nomem(ld, map);
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
        n[k] = id[k] < 0 ? -1
                         : load_end_candidates(ld, links, k, id[k], btw->items[k], "loaded link",
                                               cand[k], 8);
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
                    load_nomem(ld, map);
                return;
            }
    load_err(ld, btw, "both ends are on link '%s': a force between them does nothing; attach "
                      "it between two links", ld->m->links[cand[0][0]].name);
}
