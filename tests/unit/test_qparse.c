/* tests/unit/test_qparse.c: the one parser of quantity expressions
 * (src/load/qparse.c) on its own, through a backend that writes down every hook
 * it is called with (the operations in reverse Polish notation), and its
 * three real backends against each other.
 *
 * Truths, all written out by hand here:
 *   - the order of the operations of a text from the grammar's precedence
 *     (power over unary minus over * and / over + and -, left to right);
 *   - where a bare number takes a unit (+ and -, not * and /), and which;
 *   - the byte offset and the words of each error, counted on the text;
 *   - values of constant expressions computed by hand (0.016 m for
 *     "2 mm * 3 + 1 cm"), reached by units.c (quantity_eval) and by
 *     drivers.c (a law without t, law_eval) alike. */
#include <criterion/criterion.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "load.h"

/* ---- a backend that records ------------------------------------------ */

typedef struct rec {
    char buf[512];
} rec;

static void put(qparse *p, const char *fmt, ...) MECH_PRINTF(2, 3);
static void put(qparse *p, const char *fmt, ...)
{
    rec *r = p->ctx;
    size_t n = strlen(r->buf);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->buf + n, sizeof r->buf - n, fmt, ap);
    va_end(ap);
}

static qv r_constant(qparse *p, double v)
{
    put(p, " %g", v);
    return (qv){v, 0, {{0, 0, 0, 0}}, 0};
}

static int r_unit(qparse *p, const char *u, double *scale, dim *d, const char **end)
{
    (void)p;
    return unit_parse(u, scale, d, end);
}

static int r_word(qparse *p, const char *at, size_t n, qv *out)
{
    if (!(n == 1 && *at == 't'))
        return 0;
    put(p, " T");
    *out = (qv){0, 0, {{0, 0, 1, 0}}, 0};
    return 1;
}

static qv r_call(qparse *p, const char *name, size_t n, const char *at, qv a, qv b, int two)
{
    (void)at, (void)a, (void)b;
    put(p, " %.*s/%d", (int)n, name, two ? 2 : 1);
    return (qv){0, 0, {{0, 0, 0, 0}}, 1};
}

static qv r_neg(qparse *p, qv a)
{
    put(p, " neg");
    return a;
}

static qv r_scale(qparse *p, qv a, double k)
{
    put(p, " scale(%g)", k);
    return a;
}

static qv r_add(qparse *p, qv a, qv b, char op, const char *at)
{
    (void)b, (void)at;
    put(p, " %c", op);
    return a;
}

static qv r_mul(qparse *p, qv a, qv b, char op, const char *at)
{
    (void)b, (void)at;
    put(p, " %c", op);
    return a;
}

static qv r_powi(qparse *p, qv a, int e, const char *at)
{
    (void)at;
    put(p, " ^%d", e);
    return a;
}

static qparse_ops rec_ops = {
    .constant = r_constant,
    .unit = r_unit,
    .word = r_word,
    .call = r_call,
    .neg = r_neg,
    .scale = r_scale,
    .add = r_add,
    .mul = r_mul,
    .powi = r_powi,
    .unknown_name = " (test)",
    .unit_alone = 1,
    .strict_exponent = 1,
    .checked_dims = 1,
    .after = "value",
};

static unit_defaults units_mm_deg(void)
{
    unit_defaults u;
    unit_defaults_init(&u);
    u.scale[Q_LENGTH] = 1e-3;
    u.scale[Q_ANGLE] = QPARSE_PI / 180.0;
    return u;
}

static const expr_param PARAMS[] = {{"r", 0.04, {{1, 0, 0, 0}}, 0, 0.0}};

typedef struct run {
    rec r;
    qv v;
    int failed;
    size_t pos;
    char err[256];
} run;

static run parse_with(const qparse_ops *ops, const char *text)
{
    static unit_defaults u;
    u = units_mm_deg();
    expr_env env = {&u, PARAMS, 1, NULL, NULL};
    run out;
    memset(&out, 0, sizeof out);
    qparse p;
    qparse_init(&p, text, &env, ops, &out.r, out.err, sizeof out.err);
    out.v = qparse_run(&p);
    out.failed = p.failed;
    out.pos = p.err_pos;
    return out;
}

/* the operations of `text` in reverse Polish notation */
static void expect_rpn(const char *text, const char *want)
{
    run o = parse_with(&rec_ops, text);
    cr_expect(!o.failed, "'%s': failed: %s", text, o.err);
    cr_expect_str_eq(o.r.buf[0] == ' ' ? o.r.buf + 1 : o.r.buf, want, "'%s'", text);
}

Test(qparse, precedence_and_order)
{
    expect_rpn("1 + 2 * 3", "1 2 3 * +");
    expect_rpn("1 - 2 - 3", "1 2 - 3 -");
    expect_rpn("8 / 2 / 2", "8 2 / 2 /");
    expect_rpn("8/2*2", "8 2 / 2 *");
    expect_rpn("-2^2", "2 ^2 neg");  /* -(2^2) */
    expect_rpn("2 * -3", "2 3 neg *");
    expect_rpn("(1 + 2) * 3", "1 2 + 3 *");
    expect_rpn("+1", "1");
    expect_rpn("2^-1", "2 ^-1");
    expect_rpn("2 ^ 3", "2 ^3");
    expect_rpn("sin(t) + 2", "T sin/1 2 +");
    expect_rpn("atan2(1, 2 * t)", "1 2 T * atan2/2");
    expect_rpn("pi", "3.14159");
}

Test(qparse, bare_numbers_take_units_under_plus_and_minus)
{
    /* the bare 3 becomes 3 mm (the default length here), after it is read */
    expect_rpn("2 mm + 3", "0.002 3 scale(0.001) +");
    expect_rpn("3 + 2 mm", "3 0.002 scale(0.001) +");
    expect_rpn("r - 1", "0.04 1 scale(0.001) -");
    expect_rpn("3 * 2 mm", "3 0.002 *");  /* a pure number under * */
    expect_rpn("1 + 2", "1 2 +");         /* both bare: still bare */
    expect_rpn("30 deg + 1", "0.523599 1 scale(0.0174533) +");

    run o = parse_with(&rec_ops, "2 mm * 3");
    cr_expect(dim_equal(o.v.d, (dim){{1, 0, 0, 0}}) && !o.v.bare, "2 mm * 3 is a length");
    o = parse_with(&rec_ops, "2 * 3");
    cr_expect(o.v.bare && dim_equal(o.v.d, (dim){{0, 0, 0, 0}}), "2 * 3 is bare");
    o = parse_with(&rec_ops, "1 mm^2 / 1 mm");
    cr_expect(dim_equal(o.v.d, (dim){{1, 0, 0, 0}}), "mm^2 / mm is a length");
    o = parse_with(&rec_ops, "(1 kg*m/s^2)^2");
    cr_expect(dim_equal(o.v.d, (dim){{2, 2, -4, 0}}), "N^2");
}

typedef struct bad {
    const char *text;
    size_t pos;
    const char *msg;
} bad;

Test(qparse, errors_at_their_byte_offsets)
{
    static const bad cases[] = {
        {"1 + (2", 6, "expected ')'"},
        {"1 +", 3, "value missing"},
        {"2 ^ x", 2, "expected an integer exponent after '^'"},
        {"2^100", 1, "expected an integer exponent after '^'"},
        {"1 + foo", 4, "unknown name 'foo' (test)"},
        {"1 + mm", 4, "unit 'mm' without a number (write 1 mm)"},
        {"1 mm + 1 s", 5, "cannot add a length (m) and a time (s)"},
        {"1 mm - 1 kg", 5, "cannot subtract a length (m) and a mass (kg)"},
        {"2 $", 2, "unexpected '$' after the value"},
        {"sin(1", 5, "expected ')' to close sin("},
        {"1 + #", 4, "unexpected '#'"},
        {"1e999", 0, "number out of range"},
        {"1 m^60 * 1 m^60", 7, "unit power out of range (at most 99)"},
        {"(1 m^50)^2", 8, "unit power out of range (at most 99)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        run o = parse_with(&rec_ops, cases[i].text);
        cr_expect(o.failed, "'%s' should fail", cases[i].text);
        cr_expect_eq(o.pos, cases[i].pos, "'%s': at %zu, not %zu", cases[i].text, o.pos,
                     cases[i].pos);
        cr_expect_str_eq(o.err, cases[i].msg, "'%s'", cases[i].text);
    }
    /* 70 '(' : the 65th unary (inside the 64th '(') is one too deep */
    char deep[80];
    memset(deep, '(', 70);
    strcpy(deep + 70, "1");
    run o = parse_with(&rec_ops, deep);
    cr_expect(o.failed && o.pos == 64, "too deep at %zu", o.pos);
    cr_expect_str_eq(o.err, "expression nested too deeply");
}

Test(qparse, lenient_exponent_and_wrapping_dimensions)
{
    /* drivers.c's flavour: the digits of a power stop at 100, and the powers
       of a dimension wrap as signed chars (no range check) */
    qparse_ops lax = rec_ops;
    lax.strict_exponent = 0;
    lax.checked_dims = 0;
    run o = parse_with(&lax, "2^1234");
    cr_expect(o.failed && o.pos == 5, "at %zu", o.pos);
    cr_expect_str_eq(o.err, "unexpected '4' after the value");
    cr_expect_str_eq(o.r.buf, " 2 ^123");
    o = parse_with(&lax, "(1 m^50)^2");
    cr_expect(!o.failed && o.v.d.e[DIM_LENGTH] == 100, "m^100: %d", o.v.d.e[DIM_LENGTH]);
}

/* ---- units.c and drivers.c: one value, one message ------------------- */

static double by_units(const char *text, char *err, size_t *pos)
{
    unit_defaults u = units_mm_deg();
    expr_env env = {&u, PARAMS, 1, NULL, NULL};
    double v = NAN;
    if (quantity_eval(text, Q_LENGTH, &env, &v, err, 256, pos) < 0)
        return NAN;
    return v;
}

static double by_law(const char *text, char *err, size_t *pos)
{
    unit_defaults u = units_mm_deg();
    expr_env env = {&u, PARAMS, 1, NULL, NULL};
    struct mech_law *l = NULL;
    if (law_parse(text, Q_LENGTH, &env, &l, err, 256, pos) < 0)
        return NAN;
    double v = law_eval(l, 0.37, NULL, NULL);
    law_free(l);
    return v;
}

Test(qparse, units_and_laws_agree)
{
    static const struct {
        const char *text;
        double want;  /* by hand, m */
    } cases[] = {
        {"2 mm * 3 + 1 cm", 0.016},
        {"sqrt(9 mm^2) + 1", 0.004},      /* 3 mm + 1 (mm) */
        {"100 * cos(60)", 0.05},          /* cos(60 deg) = 1/2, then mm */
        {"(2 mm)^2 / 1 mm", 0.004},
        {"-r + 50", 0.01},                /* -40 mm + 50 mm */
        {"-(1 + 2)^2 * 1 mm", -0.009},
        {"1 in - 25.4 mm + 2", 0.002},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char e1[256] = "", e2[256] = "";
        size_t p1 = 0, p2 = 0;
        double a = by_units(cases[i].text, e1, &p1), b = by_law(cases[i].text, e2, &p2);
        double tol = 4 * DBL_EPSILON * fabs(cases[i].want) + 1e-300;
        cr_expect(fabs(a - cases[i].want) <= tol, "units '%s': %.17g, want %.17g (%s)",
                  cases[i].text, a, cases[i].want, e1);
        cr_expect(fabs(b - cases[i].want) <= tol, "law '%s': %.17g, want %.17g (%s)",
                  cases[i].text, b, cases[i].want, e2);
    }
    /* the same errors, at the same offsets, from the one core */
    static const bad errs[] = {
        {"1 mm + 1 s", 5, "cannot add a length (m) and a time (s)"},
        {"sqrt(-4 mm^2)", 0, "sqrt of a negative value"},
        {"sqrt(1 mm)", 0, "sqrt of a quantity whose unit has an odd power"},
        {"1 mm / 0", 5, "division by zero"},
        {"(1 mm", 5, "expected ')'"},
        {"atan2(1)", 0, "atan2 takes two arguments: atan2(y, x)"},
        {"sin(1, 2)", 0, "sin takes one argument"},
        {"1 + mm", 4, "unit 'mm' without a number (write 1 mm)"},
    };
    for (size_t i = 0; i < sizeof errs / sizeof errs[0]; i++) {
        char e1[256] = "", e2[256] = "";
        size_t p1 = 99, p2 = 99;
        double a = by_units(errs[i].text, e1, &p1), b = by_law(errs[i].text, e2, &p2);
        cr_expect(isnan(a) && isnan(b), "'%s' should fail", errs[i].text);
        cr_expect_str_eq(e1, errs[i].msg, "units '%s'", errs[i].text);
        cr_expect_str_eq(e2, errs[i].msg, "law '%s'", errs[i].text);
        cr_expect(p1 == errs[i].pos && p2 == errs[i].pos, "'%s': at %zu and %zu, not %zu",
                  errs[i].text, p1, p2, errs[i].pos);
    }
}
