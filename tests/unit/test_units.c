/* tests/unit/test_units.c: units, dimensions and quantity expressions
 * (src/load/units.c).
 *
 * Expected SI values are written out independently of the unit table in
 * src/load/units.c (from the definitions: 1 in = 25.4 mm exactly, 1 rev = 2 pi rad,
 * 1 rpm = 2 pi / 60 rad/s, ...), never copied from it.
 *
 * Tolerances, relative to the expected value:
 *   EXACT (4 ulp): a conversion is one or two multiplications of correctly
 *     rounded constants (value * scale, scale^e), each adding at most half an
 *     ulp of rounding; 4 ulp leaves room for that and for a constant such as
 *     pi/180 being computed in a different order than ours.
 *   TRIG (16 ulp): sin, cos, tan, atan2 and sqrt of already rounded arguments;
 *     glibc's functions are within 1 ulp, but the argument (30 deg = pi/6
 *     rounded) carries its own rounding, amplified by at most the condition
 *     number of the function (about 1 near the values used here). */
#include <criterion/criterion.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base.h"

#define PI_ 3.14159265358979323846
#define EXACT 4.0
#define TRIG 16.0

static int rel_close(double got, double want, double ulps)
{
    if (want == 0.0)
        return fabs(got) <= ulps * DBL_MIN;
    return fabs(got - want) <= ulps * DBL_EPSILON * fabs(want);
}

#define expect_close(got, want, ulps, ...)                                                   \
    cr_expect(rel_close((got), (want), (ulps)), __VA_ARGS__)

/* ---- helpers ---------------------------------------------------------- */

typedef struct env_fixture {
    unit_defaults units;
    expr_param params[8];
    expr_env env;
} env_fixture;

/* All defaults SI, no parameters. */
static void env_si(env_fixture *f)
{
    memset(f, 0, sizeof *f);
    unit_defaults_init(&f->units);
    f->env.units = &f->units;
    f->env.params = f->params;
    f->env.nparams = 0;
}

/* Like a file with `units: {length: mm, angle: deg}`. */
static void env_mm_deg(env_fixture *f)
{
    env_si(f);
    f->units.scale[Q_LENGTH] = 1e-3;
    f->units.scale[Q_ANGLE] = PI_ / 180.0;
}

static void add_param(env_fixture *f, const char *name, double value, dim d, int bare)
{
    f->params[f->env.nparams++] = (expr_param){name, value, d, bare};
}

static const dim D_NONE = {{0, 0, 0, 0}};
static const dim D_LENGTH = {{1, 0, 0, 0}};
static const dim D_ANGLE = {{0, 0, 0, 1}};

/* Evaluate text as quantity q; the test fails with the message on error. */
static double eval_ok(const env_fixture *f, const char *text, quantity q)
{
    char msg[256] = "";
    size_t pos = 0;
    double v = NAN;
    int rc = quantity_eval(text, q, &f->env, &v, msg, sizeof msg, &pos);
    cr_expect_eq(rc, 0, "'%s' as %s: unexpected error at byte %zu: %s", text,
                 quantity_get(q)->noun, pos, msg);
    return v;
}

/* Evaluate text, expecting an error at byte `want_pos` whose message starts
 * with `want_msg` (messages may go on with a hint, e.g. "(did you mean ...)"). */
static void eval_fails(const env_fixture *f, const char *text, quantity q, const char *want_msg,
                       size_t want_pos)
{
    char msg[256] = "";
    size_t pos = 12345;
    double v = NAN;
    int rc = quantity_eval(text, q, &f->env, &v, msg, sizeof msg, &pos);
    cr_expect_eq(rc, -1, "'%s' as %s: expected an error, got %g", text, quantity_get(q)->noun, v);
    cr_expect(strncmp(msg, want_msg, strlen(want_msg)) == 0,
              "'%s': message '%s', expected it to start with '%s'", text, msg, want_msg);
    cr_expect_eq(pos, want_pos, "'%s': error at byte %zu, expected byte %zu", text, pos, want_pos);
}

/* ---- the unit table ---------------------------------------------------- */

typedef struct unit_case {
    const char *text;
    quantity q;
    double si;  /* SI value, written from the unit's definition */
} unit_case;

/* Every unit of src/load/units.c, one at a time (keep in step with its table). */
static const unit_case every_unit[] = {
    {"1 m", Q_LENGTH, 1.0},
    {"1 cm", Q_LENGTH, 0.01},
    {"1 mm", Q_LENGTH, 0.001},
    {"1 um", Q_LENGTH, 0.000001},
    {"1 km", Q_LENGTH, 1000.0},
    {"1 in", Q_LENGTH, 0.0254},                   /* 25.4 mm exactly (1959) */
    {"1 kg", Q_MASS, 1.0},
    {"1 g", Q_MASS, 0.001},
    {"1 t", Q_MASS, 1000.0},                      /* metric tonne */
    {"1 s", Q_TIME, 1.0},
    {"1 ms", Q_TIME, 0.001},
    {"1 min", Q_TIME, 60.0},
    {"1 h", Q_TIME, 3600.0},
    {"1 rad", Q_ANGLE, 1.0},
    {"1 deg", Q_ANGLE, 0.017453292519943295},     /* pi / 180 */
    {"1 rev", Q_ANGLE, 6.283185307179586},        /* 2 pi */
    {"1 rpm", Q_ANGULAR_SPEED, 0.10471975511965977}, /* 2 pi / 60 rad/s */
    {"1 N", Q_FORCE, 1.0},
    {"1 kN", Q_FORCE, 1000.0},
    {"1 mN", Q_FORCE, 0.001},
};

Test(units, every_unit_in_the_table)
{
    env_fixture f;
    env_si(&f);
    for (size_t i = 0; i < sizeof every_unit / sizeof every_unit[0]; i++) {
        const unit_case *c = &every_unit[i];
        double v = eval_ok(&f, c->text, c->q);
        expect_close(v, c->si, EXACT, "%s = %.17g, expected %.17g", c->text, v, c->si);
        const char *name = c->text + 2;
        cr_expect(unit_is_name(name, strlen(name)), "'%s' should be a unit name", name);
    }
}

Test(units, names_that_are_not_units)
{
    /* case matters, and common units outside the table are not guessed */
    static const char *const not_units[] = {"M", "MM", "Kg", "n", "Hz", "lb", "ft", "deg2",
                                            "sec", "meter", "rads", ""};
    for (size_t i = 0; i < sizeof not_units / sizeof not_units[0]; i++)
        cr_expect(!unit_is_name(not_units[i], strlen(not_units[i])), "'%s' is not a unit",
                  not_units[i]);
}

Test(units, compound_units)
{
    static const unit_case cases[] = {
        {"120 rpm", Q_ANGULAR_SPEED, 4.0 * PI_},               /* 2 rev/s */
        {"3000 rpm", Q_ANGULAR_SPEED, 100.0 * PI_},
        {"1 rev/min", Q_ANGULAR_SPEED, 2.0 * PI_ / 60.0},
        {"360 deg/s", Q_ANGULAR_SPEED, 2.0 * PI_},
        {"6.283185 rad/s", Q_ANGULAR_SPEED, 6.283185},
        {"2 kg*m^2", Q_INERTIA, 2.0},
        {"3 g*cm^2", Q_INERTIA, 3e-7},                          /* 1e-3 kg * 1e-4 m^2 */
        {"5 kg*mm^2", Q_INERTIA, 5e-6},
        {"5 rad/s^2", Q_ANGULAR_ACCELERATION, 5.0},
        {"180 deg/s^2", Q_ANGULAR_ACCELERATION, PI_},
        {"9.81 m/s^2", Q_ACCELERATION, 9.81},
        {"9.81 m/s/s", Q_ACCELERATION, 9.81},
        {"1 mm/ms^2", Q_ACCELERATION, 1000.0},
        {"7 N*m", Q_TORQUE, 7.0},
        {"7 N*mm", Q_TORQUE, 0.007},
        {"2 kN*m", Q_TORQUE, 2000.0},
        {"100 N/m", Q_FORCE_PER_LENGTH, 100.0},
        {"100 N/mm", Q_FORCE_PER_LENGTH, 100000.0},
        {"2 kN/m", Q_FORCE_PER_LENGTH, 2000.0},
        {"36 km/h", Q_SPEED, 10.0},
        {"1 in/s", Q_SPEED, 0.0254},
        {"1 kg*m/s^2", Q_FORCE, 1.0},                          /* a newton, spelled out */
        {"1 N/kg", Q_ACCELERATION, 1.0},
        {"2 m^2 / 1 m", Q_LENGTH, 2.0},
    };
    env_fixture f;
    env_si(&f);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double v = eval_ok(&f, cases[i].text, cases[i].q);
        expect_close(v, cases[i].si, EXACT, "%s = %.17g, expected %.17g", cases[i].text, v,
                     cases[i].si);
    }
}

Test(units, unit_parse_scale_dimension_and_end)
{
    double scale = 0;
    dim d;
    const char *end = NULL;
    const char *s = "kg*m^2";
    cr_assert(unit_parse(s, &scale, &d, &end));
    expect_close(scale, 1.0, EXACT, "kg*m^2 scale %g", scale);
    cr_expect(dim_equal(d, quantity_get(Q_INERTIA)->d));
    cr_expect_eq(end, s + strlen(s));

    s = "mm^-2";
    cr_assert(unit_parse(s, &scale, &d, &end));
    expect_close(scale, 1e6, EXACT, "mm^-2 scale %g", scale);
    cr_expect_eq(d.e[DIM_LENGTH], -2);

    s = "rpm";
    cr_assert(unit_parse(s, &scale, &d, &end));
    cr_expect(dim_equal(d, quantity_get(Q_ANGULAR_SPEED)->d), "rpm is an angular speed");

    /* "2 mm * k": the '*' is the expression's when no unit follows it */
    s = "mm * k";
    cr_assert(unit_parse(s, &scale, &d, &end));
    cr_expect_eq(end, s + 2, "unit ends after 'mm', at '%s'", end);

    /* a space around '*' and '/' between units is allowed */
    s = "N * m";
    cr_assert(unit_parse(s, &scale, &d, &end));
    cr_expect(dim_equal(d, quantity_get(Q_TORQUE)->d));
    cr_expect_eq(*end, '\0');

    cr_expect(!unit_parse("furlong", &scale, &d, &end));
    cr_expect(!unit_parse("", &scale, &d, &end));
    cr_expect(!unit_parse("2 mm", &scale, &d, &end));
}

Test(units, dimension_names)
{
    char buf[64];
    dim_format(quantity_get(Q_INERTIA)->d, buf, sizeof buf);
    cr_expect_str_eq(buf, "kg*m^2");
    dim_format(quantity_get(Q_FORCE)->d, buf, sizeof buf);
    cr_expect_str_eq(buf, "N");
    dim_format((dim){{2, 0, 0, 0}}, buf, sizeof buf);
    cr_expect_str_eq(buf, "m^2");
    dim_format((dim){{0, 0, -1, 0}}, buf, sizeof buf);
    cr_expect_str_eq(buf, "1/s");
    dim_format((dim){{3, -1, 0, 0}}, buf, sizeof buf);
    cr_expect_str_eq(buf, "m^3/kg");
    dim_format(D_NONE, buf, sizeof buf);
    cr_expect_str_eq(buf, "1");
}

Test(units, quantity_keys)
{
    static const char *const keys[] = {"length", "angle", "mass", "time", "force", "torque",
                                       "inertia", "speed", "acceleration", "angular_speed",
                                       "angular_acceleration", "force_per_length"};
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        int q = quantity_by_key(keys[i]);
        cr_expect(q > 0, "'%s' is a key of units:", keys[i]);
        if (q > 0)
            cr_expect_str_eq(quantity_get((quantity)q)->key, keys[i]);
    }
    cr_expect_eq(quantity_by_key("number"), -1, "pure numbers have no default unit to set");
    cr_expect_eq(quantity_by_key("Length"), -1);
    cr_expect_eq(quantity_by_key("velocity"), -1);
}

/* ---- expressions ------------------------------------------------------- */

Test(expressions, precedence_and_associativity)
{
    static const struct {
        const char *text;
        double want;
    } cases[] = {
        {"1 + 2 * 3", 7.0},
        {"(1 + 2) * 3", 9.0},
        {"2 * 3^2", 18.0},
        {"(2 * 3)^2", 36.0},
        {"10 - 2 - 3", 5.0},      /* left to right */
        {"10 / 2 / 5", 1.0},
        {"2^-1", 0.5},
        {"2 ^ -2", 0.25},
        {"-3 + 5", 2.0},
        {"- -3", 3.0},
        {"+5", 5.0},
        {"2 * -3", -6.0},
        {"2 - -3", 5.0},
        {"-(1 + 2)", -3.0},
        {"((((7))))", 7.0},
        {"  1.5e2\t/ 3 ", 50.0},
        {".5 * 4", 2.0},
        /* '^' binds tighter than unary minus, as in algebra: -2^2 = -(2^2) */
        {"-2^2", -4.0},
        {"(-2)^2", 4.0},
        {"0 - 2^2", -4.0},
    };
    env_fixture f;
    env_si(&f);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double v = eval_ok(&f, cases[i].text, Q_NUMBER);
        expect_close(v, cases[i].want, EXACT, "%s = %.17g, expected %g", cases[i].text, v,
                     cases[i].want);
    }
}

Test(expressions, bare_numbers_take_the_default_unit)
{
    env_fixture f;
    env_mm_deg(&f);
    /* at the top: the expected quantity's default unit */
    expect_close(eval_ok(&f, "50", Q_LENGTH), 0.05, EXACT, "50 -> 50 mm");
    expect_close(eval_ok(&f, "30", Q_ANGLE), PI_ / 6.0, EXACT, "30 -> 30 deg");
    expect_close(eval_ok(&f, "-90", Q_ANGLE), -PI_ / 2.0, EXACT, "-90 -> -90 deg");
    /* an explicit unit always wins */
    expect_close(eval_ok(&f, "2 m", Q_LENGTH), 2.0, EXACT, "2 m");
    expect_close(eval_ok(&f, "1 rad", Q_ANGLE), 1.0, EXACT, "1 rad");
    /* quantities without a `units:` entry stay SI */
    expect_close(eval_ok(&f, "10", Q_ANGULAR_SPEED), 10.0, EXACT,
                 "angular speed keeps rad/s when only angle is in deg");
    expect_close(eval_ok(&f, "3", Q_MASS), 3.0, EXACT, "mass stays kg");
    /* pure numbers are never scaled */
    expect_close(eval_ok(&f, "0.25", Q_NUMBER), 0.25, EXACT, "pure number");
}

Test(expressions, bare_numbers_under_plus_and_minus)
{
    env_fixture f;
    env_mm_deg(&f);
    /* the bare operand takes the default unit of the other operand's quantity
       (mm here), not the other operand's own unit (cm) */
    expect_close(eval_ok(&f, "10 + 1 cm", Q_LENGTH), 0.02, EXACT, "10 mm + 1 cm");
    expect_close(eval_ok(&f, "1 cm + 10", Q_LENGTH), 0.02, EXACT, "1 cm + 10 mm");
    expect_close(eval_ok(&f, "1 cm - 5", Q_LENGTH), 0.005, EXACT, "1 cm - 5 mm");
    expect_close(eval_ok(&f, "90 - 1 rad", Q_ANGLE), PI_ / 2.0 - 1.0, EXACT, "90 deg - 1 rad");
    expect_close(eval_ok(&f, "1 m + 2 + 3", Q_LENGTH), 1.005, EXACT, "1 m + 2 mm + 3 mm");
    /* two bare operands stay bare and take the expected quantity's unit */
    expect_close(eval_ok(&f, "10 + 5", Q_LENGTH), 0.015, EXACT, "15 mm");
    /* in SI, the same text means metres */
    env_si(&f);
    expect_close(eval_ok(&f, "10 + 1 cm", Q_LENGTH), 10.01, EXACT, "10 m + 1 cm");
}

Test(expressions, bare_numbers_are_pure_under_times_and_divide)
{
    env_fixture f;
    env_mm_deg(&f);
    expect_close(eval_ok(&f, "2 * 30 mm", Q_LENGTH), 0.06, EXACT, "2 * 30 mm");
    expect_close(eval_ok(&f, "30 mm / 2", Q_LENGTH), 0.015, EXACT, "30 mm / 2");
    expect_close(eval_ok(&f, "30 mm * 2 + 4", Q_LENGTH), 0.064, EXACT, "60 mm + 4 mm");
    /* a product of bare numbers is still bare: it takes the unit at the top */
    expect_close(eval_ok(&f, "2 * 3", Q_LENGTH), 0.006, EXACT, "6 mm");
    expect_close(eval_ok(&f, "3^2", Q_LENGTH), 0.009, EXACT, "9 mm");
    /* a unit times a unit */
    expect_close(eval_ok(&f, "2 N * 3 m", Q_TORQUE), 6.0, EXACT, "6 N*m");
    expect_close(eval_ok(&f, "1 m / 2 s", Q_SPEED), 0.5, EXACT, "0.5 m/s");
    expect_close(eval_ok(&f, "(3 mm)^2 / 1 mm", Q_LENGTH), 0.009, EXACT, "9 mm");
}

Test(expressions, parameters)
{
    env_fixture f;
    env_mm_deg(&f);
    add_param(&f, "r", 0.04, D_LENGTH, 0);       /* r: 40 mm */
    add_param(&f, "k", 2.0, D_NONE, 1);          /* k: 2 (bare) */
    add_param(&f, "beta", PI_ / 6.0, D_ANGLE, 0);/* beta: 30 deg */
    add_param(&f, "a_21", 0.05, D_LENGTH, 0);
    expect_close(eval_ok(&f, "r", Q_LENGTH), 0.04, EXACT, "r");
    expect_close(eval_ok(&f, "r + 10", Q_LENGTH), 0.05, EXACT, "r + 10 mm");
    expect_close(eval_ok(&f, "k * r", Q_LENGTH), 0.08, EXACT, "k * r");
    expect_close(eval_ok(&f, "k", Q_LENGTH), 0.002, EXACT, "a bare parameter adopts mm");
    expect_close(eval_ok(&f, "k", Q_ANGLE), 2.0 * PI_ / 180.0, EXACT, "... or deg");
    expect_close(eval_ok(&f, "beta - 10", Q_ANGLE), PI_ / 9.0, EXACT, "30 deg - 10 deg");
    expect_close(eval_ok(&f, "a_21 + r", Q_LENGTH), 0.09, EXACT, "a_21 + r");
    expect_close(eval_ok(&f, "r * cos(beta)", Q_LENGTH), 0.04 * cos(PI_ / 6.0), TRIG,
                 "r cos(beta)");
    /* r^2 is an area: no such quantity is expected anywhere */
    eval_fails(&f, "r^2", Q_LENGTH, "expected a length, got a quantity in m^2", 0);
    eval_fails(&f, "rr", Q_LENGTH, "unknown name 'rr'", 0);
}

Test(expressions, parameter_definitions_keep_their_dimension)
{
    env_fixture f;
    env_mm_deg(&f);
    expr_param p;
    char msg[256];
    size_t pos = 0;
    cr_assert_eq(quantity_eval_param("40 mm", &f.env, &p, msg, sizeof msg, &pos), 0, "%s", msg);
    expect_close(p.value, 0.04, EXACT, "40 mm");
    cr_expect(dim_equal(p.d, D_LENGTH));
    cr_expect_eq(p.bare, 0);
    cr_assert_eq(quantity_eval_param("3 * 4", &f.env, &p, msg, sizeof msg, &pos), 0, "%s", msg);
    expect_close(p.value, 12.0, EXACT, "bare 12");
    cr_expect_eq(p.bare, 1, "a bare definition stays bare until used");
    cr_assert_eq(quantity_eval_param("30 deg", &f.env, &p, msg, sizeof msg, &pos), 0, "%s", msg);
    cr_expect(dim_equal(p.d, D_ANGLE));
    cr_assert_eq(quantity_eval_param("2 m * 3 m", &f.env, &p, msg, sizeof msg, &pos), 0, "%s",
                 msg);
    cr_expect_eq(p.d.e[DIM_LENGTH], 2, "a parameter may be an area");
    cr_expect_eq(quantity_eval_param("2 m + 1 s", &f.env, &p, msg, sizeof msg, &pos), -1);
    cr_expect_str_eq(msg, "cannot add a length (m) and a time (s)");
    cr_expect_eq(pos, 4);
}

Test(expressions, functions_and_pi)
{
    env_fixture f;
    env_si(&f);
    expect_close(eval_ok(&f, "pi", Q_ANGLE), PI_, EXACT, "pi rad");
    expect_close(eval_ok(&f, "2*pi", Q_ANGLE), 2.0 * PI_, EXACT, "2 pi rad");
    expect_close(eval_ok(&f, "sqrt(2)", Q_NUMBER), 1.4142135623730951, TRIG, "sqrt 2");
    expect_close(eval_ok(&f, "sqrt(3^2 + 4^2)", Q_LENGTH), 5.0, TRIG, "hypotenuse");
    expect_close(eval_ok(&f, "sqrt(16 mm^2)", Q_LENGTH), 0.004, TRIG, "sqrt of an area");
    expect_close(eval_ok(&f, "sqrt(4 m^2/s^2)", Q_SPEED), 2.0, TRIG, "sqrt of a speed squared");
    expect_close(eval_ok(&f, "sin(pi/6)", Q_NUMBER), 0.5, TRIG, "sin 30 deg (rad default)");
    expect_close(eval_ok(&f, "sin(30 deg)", Q_NUMBER), 0.5, TRIG, "sin 30 deg");
    expect_close(eval_ok(&f, "cos(60 deg)", Q_NUMBER), 0.5, TRIG, "cos 60 deg");
    expect_close(eval_ok(&f, "tan(45 deg)", Q_NUMBER), 1.0, TRIG, "tan 45 deg");
    expect_close(eval_ok(&f, "atan2(1, 1)", Q_ANGLE), PI_ / 4.0, TRIG, "atan2");
    expect_close(eval_ok(&f, "atan2(-1 mm, -1 mm)", Q_ANGLE), -3.0 * PI_ / 4.0, TRIG,
                 "atan2 third quadrant");
    expect_close(eval_ok(&f, "atan2(30 mm, 0.04 m)", Q_ANGLE), atan2(3.0, 4.0), TRIG,
                 "atan2 with mixed length units");
    expect_close(eval_ok(&f, "2 * sin(30 deg) * 1 m", Q_LENGTH), 1.0, TRIG, "a product");
    expect_close(eval_ok(&f, "sin ( 90 deg )", Q_NUMBER), 1.0, TRIG, "spaces around '('");

    /* with angle in deg, a bare argument of sin/cos/tan is in degrees */
    env_mm_deg(&f);
    expect_close(eval_ok(&f, "sin(30)", Q_NUMBER), 0.5, TRIG, "sin(30) in deg");
    expect_close(eval_ok(&f, "100 mm * cos(60)", Q_LENGTH), 0.05, TRIG, "100 mm cos 60 deg");
    /* atan2 always answers in radians internally, whatever the default */
    expect_close(eval_ok(&f, "atan2(1, 1)", Q_ANGLE), PI_ / 4.0, TRIG, "atan2 = 45 deg");
    expect_close(eval_ok(&f, "atan2(1, 0)", Q_ANGLE), PI_ / 2.0, TRIG, "atan2 = 90 deg");
}

/* pi is pi rad (an angle) whatever the file's default angle unit, so
 * "pi/2" is a right angle in a degree file too. */
Test(expressions, pi_is_pi_radians)
{
    env_fixture f;
    env_mm_deg(&f);
    expect_close(eval_ok(&f, "pi/2", Q_ANGLE), PI_ / 2.0, EXACT, "pi/2 = 90 deg");
    expect_close(eval_ok(&f, "sin(pi/6)", Q_NUMBER), 0.5, TRIG, "sin 30 deg");
    expect_close(eval_ok(&f, "90 - pi/2 * 1 rad / 1 rad * 0", Q_ANGLE), PI_ / 2.0, EXACT,
                 "bare 90 takes deg next to pi's rad");
}

/* The result of sin, cos and tan is a pure number that is not "bare", and a
 * bare number times it is no longer bare either; so "100 * cos(60)" is a
 * pure number, not 100 mm * cos 60 deg, and it is rejected where a length is
 * expected ("expected a length, got a pure number"); the same for a bare
 * parameter, "r * cos(beta)" with r: 40. The natural reading (and the rule
 * "a bare number takes the default unit of whatever quantity it turns out to
 * be") says 50 mm. Disabled: a loader bug in src/load/units.c (parse_term sets
 * bare = a.bare && b.bare; a bare factor times a dimensionless non-bare one
 * should stay bare). Write "100 mm * cos(60)" meanwhile. */
Test(expressions, bare_number_times_cosine_is_a_length)
{
    env_fixture f;
    env_mm_deg(&f);
    add_param(&f, "r", 40.0, D_NONE, 1); /* r: 40 */
    expect_close(eval_ok(&f, "100 * cos(60)", Q_LENGTH), 0.05, TRIG, "100 mm cos 60 deg");
    expect_close(eval_ok(&f, "r * sin(30)", Q_LENGTH), 0.02, TRIG, "40 mm sin 30 deg");
    expect_close(eval_ok(&f, "cos(60) * 100 + 1", Q_LENGTH), 0.051, TRIG, "51 mm");
}

/* ---- errors: message and byte position --------------------------------- */

Test(expression_errors, dimension_mismatch)
{
    env_fixture f;
    env_mm_deg(&f);
    eval_fails(&f, "5 kg", Q_LENGTH, "expected a length, got a mass (kg)", 0);
    eval_fails(&f, "5 mm", Q_ANGLE, "expected an angle, got a length (m)", 0);
    eval_fails(&f, "10 rad/s", Q_SPEED, "expected a speed, got an angular speed (rad/s)", 0);
    eval_fails(&f, "1 N*m", Q_FORCE, "expected a force, got a torque (N*m)", 0);
    eval_fails(&f, "5 kg", Q_NUMBER, "expected a pure number, got a mass (kg)", 0);
    eval_fails(&f, "0.1 rad", Q_NUMBER, "expected a pure number, got an angle (rad)", 0);
    eval_fails(&f, "2 m * 2 s", Q_LENGTH, "expected a length, got a quantity in m*s", 0);
    eval_fails(&f, "2 m + 3 s", Q_LENGTH, "cannot add a length (m) and a time (s)", 4);
    eval_fails(&f, "1 m - 3 kg", Q_LENGTH, "cannot subtract a length (m) and a mass (kg)", 4);
    eval_fails(&f, "1 + 1 m + 1 N", Q_LENGTH, "cannot add a length (m) and a force (N)", 8);
    eval_fails(&f, "sin(1 m)", Q_NUMBER, "sin needs an angle", 0);
    eval_fails(&f, "sqrt(2 m)", Q_LENGTH, "sqrt of a quantity whose unit has an odd power", 0);
}

Test(expression_errors, syntax_and_names)
{
    env_fixture f;
    env_mm_deg(&f);
    eval_fails(&f, "5 furlong", Q_LENGTH, "unknown unit 'furlong'", 2);
    eval_fails(&f, "5 Mm", Q_LENGTH, "unknown unit 'Mm'", 2);
    /* the case is wrong: the unit of the same letters (issue 22 item 6) */
    eval_fails(&f, "5 Mm", Q_LENGTH, "unknown unit 'Mm' (did you mean 'mm'?)", 2);
    eval_fails(&f, "5 MM", Q_LENGTH, "unknown unit 'MM' (did you mean 'mm'?)", 2);
    eval_fails(&f, "30 RPM", Q_ANGULAR_SPEED, "unknown unit 'RPM' (did you mean 'rpm'?)", 3);
    eval_fails(&f, "2 MN", Q_FORCE, "unknown unit 'MN' (did you mean 'mN'?)", 2);
    eval_fails(&f, "foo + 1", Q_LENGTH, "unknown name 'foo'", 0);
    eval_fails(&f, "1 + foo", Q_LENGTH, "unknown name 'foo'", 4);
    eval_fails(&f, "mm", Q_LENGTH, "unit 'mm' without a number (write 1 mm)", 0);
    eval_fails(&f, "1 mm / 0", Q_LENGTH, "division by zero", 5);
    eval_fails(&f, "1 / (2 - 2)", Q_NUMBER, "division by zero", 2);
    eval_fails(&f, "5 mm x", Q_LENGTH, "unexpected 'x' after the value", 5);
    eval_fails(&f, "3 N m", Q_TORQUE, "unexpected 'm' after the value", 4);
    eval_fails(&f, "2 3", Q_LENGTH, "unexpected '3' after the value", 2);
    eval_fails(&f, "1 +", Q_LENGTH, "value missing", 3);
    eval_fails(&f, "", Q_LENGTH, "value missing", 0);
    eval_fails(&f, "(1 mm", Q_LENGTH, "expected ')'", 5);
    eval_fails(&f, "1 mm)", Q_LENGTH, "unexpected ')' after the value", 4);
    eval_fails(&f, "@", Q_LENGTH, "unexpected '@'", 0);
    eval_fails(&f, "2^x", Q_NUMBER, "expected an integer exponent after '^'", 1);
    eval_fails(&f, "2^100", Q_NUMBER, "expected an integer exponent after '^'", 1);
    eval_fails(&f, "1e999", Q_NUMBER, "number out of range", 0);
    eval_fails(&f, "10^99^2", Q_NUMBER, "unexpected '^' after the value", 5);
    eval_fails(&f, "sqrt(-4)", Q_NUMBER, "sqrt of a negative value", 0);
    eval_fails(&f, "2 * sqrt(-4 mm^2)", Q_LENGTH, "sqrt of a negative value", 4);
    eval_fails(&f, "sqrt(4", Q_NUMBER, "expected ')' to close sqrt(", 6);
    eval_fails(&f, "atan2(1)", Q_ANGLE, "atan2 takes two arguments: atan2(y, x)", 0);
    eval_fails(&f, "sin(1, 2)", Q_NUMBER, "sin takes one argument", 0);
    eval_fails(&f, "log(2)", Q_NUMBER,
               "unknown function 'log' (known: sqrt, sin, cos, tan, atan2)", 0);
    eval_fails(&f, "1 + log(2)", Q_NUMBER,
               "unknown function 'log' (known: sqrt, sin, cos, tan, atan2)", 4);
}

Test(expression_errors, nesting_is_bounded)
{
    env_fixture f;
    env_si(&f);
    char text[256];
    size_t n = 0;
    for (int i = 0; i < 100; i++)
        text[n++] = '(';
    text[n++] = '1';
    for (int i = 0; i < 100; i++)
        text[n++] = ')';
    text[n] = '\0';
    char msg[256] = "";
    size_t pos = 0;
    double v;
    cr_expect_eq(quantity_eval(text, Q_NUMBER, &f.env, &v, msg, sizeof msg, &pos), -1);
    cr_expect_str_eq(msg, "expression nested too deeply");

    /* 60 levels are fine */
    n = 0;
    for (int i = 0; i < 60; i++)
        text[n++] = '(';
    text[n++] = '2';
    for (int i = 0; i < 60; i++)
        text[n++] = ')';
    text[n] = '\0';
    expect_close(eval_ok(&f, text, Q_NUMBER), 2.0, EXACT, "60 parentheses");
}

Test(expression_errors, long_names_are_cut_in_messages)
{
    env_fixture f;
    env_si(&f);
    char text[200], msg[256] = "";
    memset(text, 'a', 150);
    text[150] = '\0';
    size_t pos = 0;
    double v;
    cr_expect_eq(quantity_eval(text, Q_NUMBER, &f.env, &v, msg, sizeof msg, &pos), -1);
    /* the name is quoted up to 64 characters (the longest valid name) */
    char a64[70], a65[70];
    memset(a64, 'a', 64);
    a64[64] = '\0';
    memset(a65, 'a', 65);
    a65[65] = '\0';
    cr_expect(strncmp(msg, "unknown name 'aaaa", 18) == 0, "%s", msg);
    cr_expect(strstr(msg, a64) != NULL && strstr(msg, a65) == NULL, "name cut at 64: %s", msg);
}
