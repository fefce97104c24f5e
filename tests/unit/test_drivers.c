/* tests/unit/test_drivers.c: drivers as laws of time (`sweep:` and
 * `drivers:`, docs/format.md section 7.3), against independent truths:
 *   - a two-crank five-bar under two pairs of laws: the coupler point P by
 *     circle-circle intersection, its velocity and acceleration from the
 *     differentiated distance constraints with the laws' derivatives written
 *     out by hand, and the velocity once more by central differences of the
 *     closed-form positions in t;
 *   - a four-bar driven by `angle: "10 rad/s * t"` against the same four-bar
 *     with the old `driver:` at 10 rad/s, row by row, to 1e-13;
 *   - the five-bar with masses: the sum of the drivers' powers against the
 *     rate of kinetic energy minus the power of gravity, each link's centre
 *     of mass motion computed here from the pivots and link angles;
 *   - one model of drivers (`driver:` is the law q, with no row) and the
 *     row descriptor (rows.h): each row's kind, owner, mark and name, and a
 *     dead point whose message names the driver's row, against the
 *     geometry of the fold. */
#include <math.h>

#include "helpers.h"
#include "load.h"
#include "equations.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static const double R1 = 0.025, R2 = 0.025, L1 = 0.060, L2 = 0.060, EX = 0.050;

/* Two laws of each crank: angle, rate, acceleration at t (by hand). */
typedef struct law3 {
    double th, om, al;
} law3;

static law3 law_a1(double t) { return (law3){90 * DEG + 2.0 * t, 2.0, 0.0}; }
static law3 law_a2(double t)
{
    double w = 6.2832;
    return (law3){60 * DEG + 20 * DEG * sin(w * t), 20 * DEG * w * cos(w * t),
                  -20 * DEG * w * w * sin(w * t)};
}
/* quadratic start from rest, and a cycloidal rise of 40 deg in 1 s */
static law3 law_b1(double t) { return (law3){100 * DEG + 1.5 * t * t, 3.0 * t, 3.0}; }
static law3 law_b2(double t)
{
    const double w = 2 * PI, h = 40 * DEG;
    return (law3){45 * DEG + h * (t - sin(w * t) / w), h * (1 - cos(w * t)), h * w * sin(w * t)};
}

static const char *const FIVE_BAR =
    "name: five-bar\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0], E: [50, 0]}\n"
    "links:\n"
    "  crank1:   {points: {O: [0, 0], A: [25, 0]}}\n"
    "  coupler1: {points: {A: [0, 0], P: [60, 0]}}\n"
    "  coupler2: {points: {B: [0, 0], P: [60, 0]}}\n"
    "  crank2:   {points: {E: [0, 0], B: [25, 0]}}\n"
    "sweep: {time: {from: 0 s, to: 1 s, steps: 50}}\n"
    "drivers:\n"
    "  - {link: crank1, angle: \"%s\"}\n"
    "  - {link: crank2, angle: \"%s\"}\n"
    "outputs: {points: [A, B, P], links: [crank1, crank2]}\n";

/* P from the closed form: the intersection of the circles (A, L1) and
 * (B, L2) left of A->B, and its rates from (P - A).(P' - A') = 0,
 * (P - B).(P' - B') = 0 and their time derivatives. */
static void five_bar_truth(law3 c1, law3 c2, double *p, double *v, double *a)
{
    double A[2] = {R1 * cos(c1.th), R1 * sin(c1.th)};
    double B[2] = {EX + R2 * cos(c2.th), R2 * sin(c2.th)};
    double Av[2] = {-R1 * sin(c1.th) * c1.om, R1 * cos(c1.th) * c1.om};
    double Bv[2] = {-R2 * sin(c2.th) * c2.om, R2 * cos(c2.th) * c2.om};
    double Aa[2] = {-R1 * (cos(c1.th) * c1.om * c1.om + sin(c1.th) * c1.al),
                    -R1 * (sin(c1.th) * c1.om * c1.om - cos(c1.th) * c1.al)};
    double Ba[2] = {-R2 * (cos(c2.th) * c2.om * c2.om + sin(c2.th) * c2.al),
                    -R2 * (sin(c2.th) * c2.om * c2.om - cos(c2.th) * c2.al)};
    double dx = B[0] - A[0], dy = B[1] - A[1], d = hypot(dx, dy);
    double along = (L1 * L1 - L2 * L2 + d * d) / (2 * d), h = sqrt(L1 * L1 - along * along);
    p[0] = A[0] + along * dx / d - h * dy / d;
    p[1] = A[1] + along * dy / d + h * dx / d;
    /* [ (P-A)^T ; (P-B)^T ] P' = [ (P-A).A' ; (P-B).B' ] */
    double u[2] = {p[0] - A[0], p[1] - A[1]}, w[2] = {p[0] - B[0], p[1] - B[1]};
    double det = u[0] * w[1] - u[1] * w[0];
    double r1 = u[0] * Av[0] + u[1] * Av[1], r2 = w[0] * Bv[0] + w[1] * Bv[1];
    v[0] = (r1 * w[1] - u[1] * r2) / det;
    v[1] = (u[0] * r2 - r1 * w[0]) / det;
    /* (P-A).(P''-A'') + |P'-A'|^2 = 0 */
    double du[2] = {v[0] - Av[0], v[1] - Av[1]}, dw[2] = {v[0] - Bv[0], v[1] - Bv[1]};
    double s1 = u[0] * Aa[0] + u[1] * Aa[1] - (du[0] * du[0] + du[1] * du[1]);
    double s2 = w[0] * Ba[0] + w[1] * Ba[1] - (dw[0] * dw[0] + dw[1] * dw[1]);
    a[0] = (s1 * w[1] - u[1] * s2) / det;
    a[1] = (u[0] * s2 - s1 * w[0]) / det;
}

static void check_five_bar(const char *law1, const char *law2, law3 (*c1)(double),
                           law3 (*c2)(double))
{
    char text[2048];
    snprintf(text, sizeof text, FIVE_BAR, law1, law2);
    mech_model *m = load_text(text);
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 51);
    double worst[4] = {0, 0, 0, 0};
    for (int r = 0; r < t.nrows; r++) {
        double tm = table_at(&t, r, "t"), p[2], v[2], a[2];
        cr_assert_float_eq(tm, r / 50.0, 1e-15);
        five_bar_truth(c1(tm), c2(tm), p, v, a);
        static const char *const pc[] = {"P.x", "P.y"}, *const vc[] = {"P.vx", "P.vy"},
                                 *const ac[] = {"P.ax", "P.ay"};
        for (int k = 0; k < 2; k++) {
            worst[0] = fmax(worst[0], fabs(table_at(&t, r, pc[k]) - p[k]));
            worst[1] = fmax(worst[1], fabs(table_at(&t, r, vc[k]) - v[k]));
            worst[2] = fmax(worst[2], fabs(table_at(&t, r, ac[k]) - a[k]));
        }
        /* the velocity once more: central differences of the closed form */
        const double h = 1e-6;
        double pp[2], pm[2], vv[2], aa[2];
        five_bar_truth(c1(tm + h), c2(tm + h), pp, vv, aa);
        five_bar_truth(c1(tm - h), c2(tm - h), pm, vv, aa);
        for (int k = 0; k < 2; k++)
            worst[3] = fmax(worst[3], fabs(table_at(&t, r, vc[k]) - (pp[k] - pm[k]) / (2 * h)));
        cr_assert_float_eq(table_at(&t, r, "crank2.angle"), c2(tm).th, 1e-14);
        cr_assert_float_eq(table_at(&t, r, "crank2.omega"), c2(tm).om, 1e-13);
        cr_assert_float_eq(table_at(&t, r, "crank2.alpha"), c2(tm).al, 1e-12);
    }
    cr_assert_lt(worst[0], 1e-14, "position off by %g m", worst[0]);
    cr_assert_lt(worst[1], 1e-13, "velocity off by %g m/s", worst[1]);
    cr_assert_lt(worst[2], 1e-12, "acceleration off by %g m/s^2", worst[2]);
    cr_assert_lt(worst[3], 1e-8, "velocity against differences off by %g m/s", worst[3]);
    if (getenv("MECH_HARD_VERBOSE"))
        fprintf(stderr, "[drivers] five-bar %s | %s: %.2g m, %.2g m/s, %.2g m/s^2, fd %.2g\n",
                law1, law2, worst[0], worst[1], worst[2], worst[3]);
    mech_table_free(&t);
    mech_model_free(&m);
}

Test(drivers, five_bar_closed_form_sine)
{
    check_five_bar("90 deg + 2 rad/s * t", "60 deg + 20 deg * sin(6.2832 * t / 1 s)", law_a1,
                   law_a2);
}

Test(drivers, five_bar_closed_form_cycloidal)
{
    check_five_bar("100 deg + 1.5 rad/s^2 * t^2",
                   "45 deg + 40 deg * (t / 1 s - sin(2 * pi * t / 1 s) / (2 * pi / 1 rad))",
                   law_b1, law_b2);
}

static const char *const FOUR_BAR =
    "name: four-bar\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0], C: [70, 0]}\n"
    "links:\n"
    "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [60, 0], P: [30, 15]}}\n"
    "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
    "initial: {coupler: 60, rocker: 100}\n"
    "%s";

/* The four-bar in both forms: the crank swept at 10 rad/s through 72 steps
 * of a turn (`driver:`), and the law 10 rad/s * t over the same 2 pi / 10 s. */
static void four_bar_both_forms(mech_model **driver, mech_model **law)
{
    char a[1024], b[1024];
    snprintf(a, sizeof a, FOUR_BAR,
             "driver: {link: crank, angle: {from: 0, to: 360, steps: 72}, speed: 10 rad/s}\n");
    snprintf(b, sizeof b, FOUR_BAR,
             "sweep: {time: {from: 0 s, to: 0.6283185307179586 s, steps: 72}}\n"
             "drivers: [{link: crank, angle: \"10 rad/s * t\"}]\n");
    *driver = load_text(a);
    *law = load_text(b);
}

Test(drivers, single_law_reproduces_the_driver_form)
{
    mech_model *ma, *mb;
    four_bar_both_forms(&ma, &mb);
    mech_table ta = must_solve(ma, NULL), tb = must_solve(mb, NULL);
    cr_assert_eq(ta.nrows, 73);
    cr_assert_eq(tb.nrows, 73);
    double worst = 0.0;
    int compared = 0;
    for (int c = 1; c < ta.ncolumns; c++) {
        int cb = mech_table_column(&tb, ta.columns[c].name);
        cr_assert_geq(cb, 0, "column %s missing", ta.columns[c].name);
        for (int r = 0; r < ta.nrows; r++, compared++) {
            double x = mech_table_get(&ta, r, c), y = mech_table_get(&tb, r, cb);
            worst = fmax(worst, fabs(x - y) / fmax(1.0, fabs(x)));
        }
    }
    cr_assert_gt(compared, 1000);
    cr_assert_lt(worst, 1e-13, "the two forms differ by %g", worst);
    if (getenv("MECH_HARD_VERBOSE"))
        fprintf(stderr, "[drivers] four-bar law vs driver: %d values, worst %.2g\n", compared,
                worst);
    mech_table_free(&ta);
    mech_table_free(&tb);
    mech_model_free(&ma);
    mech_model_free(&mb);
}

/* Sum of tau_i omega_i against dT/dt - P_gravity, computed here. */
Test(drivers, five_bar_power_balance)
{
    static const char *const text =
        "name: five-bar with masses\n"
        "units: {length: mm, angle: deg}\n"
        "gravity: [0, -9.81]\n"
        "ground: {O: [0, 0], E: [50, 0]}\n"
        "links:\n"
        "  crank1:   {points: {O: [0, 0], A: [25, 0]}, mass: 0.2 kg, center: [10, 0],"
        " inertia: 2e-5 kg*m^2}\n"
        "  coupler1: {points: {A: [0, 0], P: [60, 0]}, mass: 0.3 kg, center: [30, 5],"
        " inertia: 9e-5 kg*m^2}\n"
        "  coupler2: {points: {B: [0, 0], P: [60, 0]}, mass: 0.25 kg, center: [25, 0],"
        " inertia: 8e-5 kg*m^2}\n"
        "  crank2:   {points: {E: [0, 0], B: [25, 0]}, mass: 0.2 kg, center: [12, -3],"
        " inertia: 2e-5 kg*m^2}\n"
        "sweep: {time: {from: 0 s, to: 1 s, steps: 40}}\n"
        "drivers:\n"
        "  - {link: crank1, angle: \"90 deg + 2 rad/s * t + 1 rad/s^2 * t^2\"}\n"
        "  - {link: crank2, angle: \"60 deg + 20 deg * sin(6.2832 * t / 1 s)\"}\n"
        "outputs: {points: [O, A, B, E], links: [crank1, coupler1, coupler2, crank2],"
        " forces: true}\n";
    mech_model *m = load_text(text);
    mech_table t = must_solve(m, NULL);
    static const char *const link[] = {"crank1", "coupler1", "coupler2", "crank2"};
    static const char *const pivot[] = {"O", "A", "B", "E"};
    const double mass[] = {0.2, 0.3, 0.25, 0.2}, inertia[] = {2e-5, 9e-5, 8e-5, 2e-5};
    const double cx[] = {0.010, 0.030, 0.025, 0.012}, cy[] = {0, 0.005, 0, -0.003};
    double worst = 0.0, biggest = 0.0;
    for (int r = 0; r < t.nrows; r++) {
        double dT = 0.0, pg = 0.0;
        for (int l = 0; l < 4; l++) {
            char name[64];
#define AT(fmt, s) (snprintf(name, sizeof name, fmt, s), table_at(&t, r, name))
            double th = AT("%s.angle", link[l]), om = AT("%s.omega", link[l]),
                   al = AT("%s.alpha", link[l]);
            double px = AT("%s.x", pivot[l]), py = AT("%s.y", pivot[l]);
            double vx = AT("%s.vx", pivot[l]), vy = AT("%s.vy", pivot[l]);
            double ax = AT("%s.ax", pivot[l]), ay = AT("%s.ay", pivot[l]);
#undef AT
            (void)px, (void)py;
            /* G = pivot + R(th) c */
            double rx = cos(th) * cx[l] - sin(th) * cy[l], ry = sin(th) * cx[l] + cos(th) * cy[l];
            double gvx = vx - om * ry, gvy = vy + om * rx;
            double gax = ax - al * ry - om * om * rx, gay = ay + al * rx - om * om * ry;
            dT += mass[l] * (gvx * gax + gvy * gay) + inertia[l] * om * al;
            pg += mass[l] * (-9.81) * gvy;
        }
        double pd = table_at(&t, r, "crank1.torque") * table_at(&t, r, "crank1.omega") +
                    table_at(&t, r, "crank2.torque") * table_at(&t, r, "crank2.omega");
        worst = fmax(worst, fabs(pd + pg - dT));
        biggest = fmax(biggest, fabs(pd));
        /* the solver's own balance (forces.c sums the drivers' powers) */
        cr_assert_lt(fabs(table_at(&t, r, "power.residual")), 1e-12, "row %d: power.residual %g",
                     r, table_at(&t, r, "power.residual"));
    }
    cr_assert_gt(biggest, 1e-3, "the drivers do no work (%g W)", biggest);
    cr_assert_lt(worst, 1e-12 * fmax(1.0, biggest), "power balance off by %g W (of %g W)", worst,
                 biggest);
    if (getenv("MECH_HARD_VERBOSE"))
        fprintf(stderr, "[drivers] five-bar power balance: worst %.2g W of %.2g W\n", worst,
                biggest);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* A slider driven by a law: the piston of an in-line slider-crank pushed
 * by s(t) turns the crank; the crank angle from the law of cosines. */
Test(drivers, slider_law)
{
    static const char *const text =
        "name: pushed slider-crank\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  crank: {points: {O: [0, 0], A: [20, 0]}}\n"
        "  rod:   {points: {A: [0, 0], B: [60, 0]}}\n"
        "  block: {points: {B: [0, 0]}}\n"
        "joints:\n"
        "  - {slider: B, link: block, on: ground, through: O, angle: 0, name: s_B}\n"
        "initial: {crank: 60 deg}\n"
        "sweep: {time: {from: 0 s, to: 1 s, steps: 20}}\n"
        "drivers: [{slider: s_B, displacement: \"70 mm + 5 mm * t^2 / 1 s^2\"}]\n"
        "outputs: {links: [crank], sliders: [s_B]}\n";
    mech_model *m = load_text(text);
    mech_table t = must_solve(m, NULL);
    for (int r = 0; r < t.nrows; r++) {
        double tm = table_at(&t, r, "t"), s = 0.070 + 0.005 * tm * tm, sd = 0.010 * tm;
        cr_assert_float_eq(table_at(&t, r, "s_B.s"), s, 1e-15);
        cr_assert_float_eq(table_at(&t, r, "s_B.v"), sd, 1e-14);
        cr_assert_float_eq(table_at(&t, r, "s_B.a"), 0.010, 1e-13);
        /* 60^2 = 20^2 + s^2 - 2 20 s cos(th) */
        double c = (0.020 * 0.020 + s * s - 0.060 * 0.060) / (2 * 0.020 * s);
        cr_assert_float_eq(table_at(&t, r, "crank.angle"), acos(c), 1e-12);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* A slider driver with masses: its force times its velocity against the
 * rate of kinetic energy minus gravity's power, computed here from the
 * crank angle, the rod angle and the block's motion. */
Test(drivers, slider_force_power_balance)
{
    static const char *const text =
        "name: pushed slider-crank with masses\n"
        "units: {length: mm, angle: deg}\n"
        "gravity: [0, -9.81]\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  crank: {points: {O: [0, 0], A: [20, 0]}, mass: 0.5 kg, center: [10, 2],"
        " inertia: 3e-5 kg*m^2}\n"
        "  rod:   {points: {A: [0, 0], B: [60, 0]}, mass: 0.4 kg, center: [30, 0],"
        " inertia: 1.2e-4 kg*m^2}\n"
        "  block: {points: {B: [0, 0]}, mass: 1.5 kg, center: [0, 0], inertia: 1e-4 kg*m^2}\n"
        "joints:\n"
        "  - {slider: B, link: block, on: ground, through: O, angle: 0, name: s_B}\n"
        "initial: {crank: 60 deg}\n"
        "sweep: {time: {from: 0 s, to: 1 s, steps: 20}}\n"
        "drivers: [{slider: s_B, displacement: \"70 mm + 5 mm * sin(2 * pi * t / 1 s)\"}]\n"
        "outputs: {points: [A], links: [rod], forces: true}\n";
    mech_model *m = load_text(text);
    mech_table t = must_solve(m, NULL);
    double worst = 0.0, biggest = 0.0;
    for (int r = 0; r < t.nrows; r++) {
        double tm = table_at(&t, r, "t");
        /* the block: s(t) and its derivatives by hand */
        double w = 2 * PI, s = 0.070 + 0.005 * sin(w * tm), sd = 0.005 * w * cos(w * tm),
               sdd = -0.005 * w * w * sin(w * tm);
        cr_assert_float_eq(table_at(&t, r, "s_B.s"), s, 1e-15);  /* always output */
        cr_assert_float_eq(table_at(&t, r, "s_B.v"), sd, 1e-14);
        cr_assert_float_eq(table_at(&t, r, "s_B.a"), sdd, 1e-13);
        double ax = table_at(&t, r, "A.x"), ay = table_at(&t, r, "A.y");
        double avx = table_at(&t, r, "A.vx"), avy = table_at(&t, r, "A.vy");
        double aax = table_at(&t, r, "A.ax"), aay = table_at(&t, r, "A.ay");
        double th = atan2(ay, ax), om = (ax * avy - ay * avx) / (ax * ax + ay * ay);
        double al = (ax * aay - ay * aax) / (ax * ax + ay * ay);  /* |OA| constant */
        double rth = table_at(&t, r, "rod.angle"), rom = table_at(&t, r, "rod.omega"),
               ral = table_at(&t, r, "rod.alpha");
        /* crank centre G1 = R(th) (10, 2) mm; rod centre G2 = A + R(rth) (30, 0) mm */
        double g1x = 0.010 * cos(th) - 0.002 * sin(th), g1y = 0.010 * sin(th) + 0.002 * cos(th);
        double v1x = -om * g1y, v1y = om * g1x;
        double a1x = -al * g1y - om * om * g1x, a1y = al * g1x - om * om * g1y;
        double rx = 0.030 * cos(rth), ry = 0.030 * sin(rth);
        double v2x = avx - rom * ry, v2y = avy + rom * rx;
        double a2x = aax - ral * ry - rom * rom * rx, a2y = aay + ral * rx - rom * rom * ry;
        double dT = 0.5 * (v1x * a1x + v1y * a1y) + 3e-5 * om * al +
                    0.4 * (v2x * a2x + v2y * a2y) + 1.2e-4 * rom * ral + 1.5 * sd * sdd;
        double pg = -9.81 * (0.5 * v1y + 0.4 * v2y);  /* the block moves along x */
        double pd = table_at(&t, r, "s_B.force") * sd;
        worst = fmax(worst, fabs(pd + pg - dT));
        biggest = fmax(biggest, fabs(pd));
    }
    cr_assert_gt(biggest, 1e-3, "the driver does no work (%g W)", biggest);
    cr_assert_lt(worst, 1e-12 * fmax(1.0, biggest), "power balance off by %g W (of %g W)", worst,
                 biggest);
    if (getenv("MECH_HARD_VERBOSE"))
        fprintf(stderr, "[drivers] slider driver power balance: worst %.2g W of %.2g W\n", worst,
                biggest);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* Laws that are refused, each with its message and column (the law is the
 * 2nd driver of FIVE_BAR, at line 12, its text from column 28). */
static void expect_law_error(const char *law, int col, const char *part)
{
    char text[2048];
    snprintf(text, sizeof text, FIVE_BAR, "90 deg + 2 rad/s * t", law);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    cr_assert_eq(mech_load_string(text, strlen(text), "l.yaml", &m, &d), MECH_EINPUT, "%s: loaded",
                 law);
    cr_assert_geq(d.count, 1);
    const mech_diag_entry *e = &d.entries[0];
    cr_assert(strstr(e->message, part), "%s: message '%s' lacks '%s'", law, e->message, part);
    cr_assert(e->mark.line == 12 && e->mark.col == col, "%s: at %d:%d, expected 12:%d (%s)", law,
              e->mark.line, e->mark.col, col, e->message);
    mech_diag_free(&d);
}

Test(drivers, law_errors)
{
    expect_law_error("10 mm/s * t", 28, "must be an angle of t, not a length");
    expect_law_error("1 rad + omega * t", 36, "unknown name 'omega'");
    expect_law_error("1 rad * log(t)", 36, "log needs a pure number, got a time");
    expect_law_error("1 rad * foo(t / 1 s)", 36, "unknown function 'foo'");
    expect_law_error("1 rad * exp(t / 1 s, 2)", 36, "exp takes one argument");
    expect_law_error("1 rad * log(-1)", 36, "log is not defined here");
    expect_law_error("1 rad * sin(t)", 36, "needs an angle or a pure number, not a time");
    expect_law_error("1 rad * (t / 1 s)^65", 45, "power of an expression of t must be -64 to 64");
    expect_law_error("1 rad + 2 s", 34, "cannot add an angle (rad) and a time (s)");
    expect_law_error("2 t", 30, "unexpected 't' after the law");
    expect_law_error("", 28, "value missing");
}

/* The laws' own derivatives (drivers.c law_eval, used for the golden check
 * and the starts) against central differences. */
Test(drivers, law_derivatives)
{
    char text[2048];
    snprintf(text, sizeof text, FIVE_BAR, "0.3 rad + 1.5 rad/s^2 * t^2 - 0.2 rad/s^3 * t^3",
             "45 deg + 40 deg * (t / 1 s - sin(2 * pi * t / 1 s) / (2 * pi / 1 rad)) + "
             "5 deg * cos(3 rad/s * t)^2");
    mech_model *m = load_text(text);
    cr_assert_eq(m->nmotions, 2);
    for (int k = 0; k < 2; k++)
        for (double tm = 0.05; tm < 1.0; tm += 0.1) {
            double d1, d2, h = 1e-4;
            double f = law_eval(m->motions[k].law, tm, &d1, &d2);
            double fp = law_eval(m->motions[k].law, tm + h, NULL, NULL);
            double fm = law_eval(m->motions[k].law, tm - h, NULL, NULL);
            cr_assert_float_eq(d1, (fp - fm) / (2 * h), 1e-7, "law %d at %g: %g", k, tm, d1);
            cr_assert_float_eq(d2, (fp - 2 * f + fm) / (h * h), 1e-5, "law %d at %g: %g", k, tm,
                               d2);
        }
    /* and the first law by hand */
    double d1, d2, f = law_eval(m->motions[0].law, 0.5, &d1, &d2);
    cr_assert_float_eq(f, 0.3 + 1.5 * 0.25 - 0.2 * 0.125, 1e-15);
    cr_assert_float_eq(d1, 3.0 * 0.5 - 0.6 * 0.25, 1e-15);
    cr_assert_float_eq(d2, 3.0 - 1.2 * 0.5, 1e-15);
    mech_model_free(&m);
}

/* m solved with the default options into *t (zeroed first), its messages
 * into *d (initialised here); the status. */
static int solve_noting(const mech_model *m, mech_table *t, mech_diag *d)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_diag_init(d);
    *t = (mech_table){0};
    return mech_solve(m, &o, t, NULL, d);
}

/* As many drivers as degrees of freedom, but both on the four-bar of a
 * four-bar plus a separate dyad: the solve names the conflicting drivers
 * and the links left free (a maximum matching of the equations). */
Test(drivers, conflicting_drivers_named)
{
    static const char *const text =
        "name: four-bar plus a dyad\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {O: [0, 0], C: [70, 0], D: [0, 100], F: [80, 100]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
        "  arm1:    {points: {D: [0, 0], G: [50, 0]}}\n"
        "  arm2:    {points: {G: [0, 0], H: [50, 0]}}\n"
        "  arm3:    {points: {F: [0, 0], H: [40, 0]}}\n"
        "sweep: {time: {from: 0 s, to: 0.1 s, steps: 10}}\n"
        "drivers:\n"
        "  - {link: crank, angle: \"10 rad/s * t\"}\n"
        "  - {link: rocker, angle: \"100 deg\"}\n";
    mech_model *m = load_text(text);  /* the counts agree: mech_check passes */
    mech_diag d;
    mech_table t;
    cr_assert_eq(solve_noting(m, &t, &d), MECH_EINPUT);
    cr_assert_geq(d.count, 1);
    const mech_diag_entry *e = &d.entries[0];
    cr_assert(strstr(e->message, "the drivers of 'crank', 'rocker' over-determine") &&
                  strstr(e->message, "'arm1', 'arm2', 'arm3' move freely"),
              "message: %s", e->message);
    cr_assert(e->mark.line == 13 && e->mark.col == 5, "at %d:%d", e->mark.line, e->mark.col);
    mech_diag_free(&d);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- one driver model, one row descriptor ---------------------------------- */

/* `driver:` is the driver whose law is q itself: one entry of the model's
 * drivers, its coordinate the sweep variable (no unknown, no row); the laws
 * of `drivers:` are the same list, each with a row after the loop rows. */
Test(drivers, one_list_of_drivers)
{
    mech_model *ma, *mb;
    four_bar_both_forms(&ma, &mb);
    int crank = mech_find_link(ma, "crank");
    cr_assert_eq(ma->ndrivers, 1);
    cr_assert_eq(ma->drivers[0].kind, MECH_DRIVE_ANGLE);
    cr_assert_eq(ma->drivers[0].index, crank);
    cr_assert_null(ma->drivers[0].text);
    cr_assert(drivers_is_sweep(ma, 0));
    double d1, d2;  /* the law q: value q, rate 1, no curvature */
    cr_assert_eq(law_eval(ma->drivers[0].law, 0.7, &d1, &d2), 0.7);
    cr_assert(d1 == 1.0 && d2 == 0.0);
    cr_assert(ma->nmotions == 0 && !ma->motions, "0.1's view lists laws of time only");
    cr_assert_eq(drivers_sweep_link(ma), crank);
    cr_assert_eq(drivers_rows(ma), 0);
    cr_assert(mb->ndrivers == 1 && mb->motions == mb->drivers && mb->nmotions == 1);
    cr_assert(!drivers_is_sweep(mb, 0));
    cr_assert_eq(drivers_sweep_link(mb), -1);
    cr_assert_eq(drivers_rows(mb), 1);
    mech_system *sa = NULL, *sb = NULL;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_system_new(ma, &sa, &d), MECH_OK);
    cr_assert_eq(mech_system_new(mb, &sb, &d), MECH_OK);
    cr_assert(sa->n == 2 && sa->m == 2, "driver: the crank is q, %d x %d", sa->m, sa->n);
    cr_assert(sb->n == 3 && sb->m == 3, "a law: the crank is an unknown, %d x %d", sb->m, sb->n);
    cr_assert(sb->rows[2].kind == ROW_DRIVER && sb->rows[2].owner == 0);
    cr_assert_eq(sb->rows[2].mark.line, 10);  /* the entry of `drivers:` */
    mech_system_free(&sa);
    mech_system_free(&sb);
    mech_diag_free(&d);
    mech_model_free(&ma);
    mech_model_free(&mb);
}

/* A law of time that folds to t itself (1 rad/s * t) is still a law: its
 * driver keeps its unknown, its row, its columns and its load's name; only
 * `driver:` is the sweep. */
Test(drivers, a_law_equal_to_t_is_still_a_law)
{
    char text[1024];
    snprintf(text, sizeof text, FOUR_BAR,
             "sweep: {time: {from: 0 s, to: 1 s, steps: 4}}\n"
             "drivers: [{link: crank, angle: \"1 rad/s * t\"}]\n"
             "outputs: {points: [P], forces: true}\n");
    mech_model *m = load_text(text);
    cr_assert(!drivers_is_sweep(m, 0) && drivers_rows(m) == 1 && drivers_sweep(m) < 0);
    mech_table t = must_solve(m, NULL);
    cr_assert_geq(mech_table_column(&t, "crank.angle"), 0);
    cr_assert_geq(mech_table_column(&t, "crank.torque"), 0);
    cr_assert_lt(mech_table_column(&t, "driver.torque"), 0);
    int ct = mech_table_column(&t, "t"), ca = mech_table_column(&t, "crank.angle");
    for (int r = 0; r < t.nrows; r++)  /* th = 1 rad/s * t */
        cr_assert_float_eq(mech_table_get(&t, r, ca), mech_table_get(&t, r, ct), 1e-15);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* The descriptor of a gear train with a law and a listed loop: the rows in
 * order (loop x, loop y, the gear pair, the driver), each owner named, and
 * mech equations' tags from it. */
Test(drivers, row_descriptor_names_each_owner)
{
    static const char *const text =
        "name: a four-bar and a gear pair\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {O: [0, 0], C: [70, 0], G: [0, 100], H: [60, 100]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
        "  wa: {points: {G: [0, 0]}}\n"
        "  wb: {points: {H: [0, 0]}}\n"
        "loops: [[O, A, B, C, O]]\n"
        "initial: {coupler: 60, rocker: 100}\n"
        "sweep: {time: {from: 0 s, to: 1 s, steps: 4}}\n"
        "drivers:\n"
        "  - {link: crank, angle: \"10 rad/s * t\"}\n"
        "  - {link: wa, angle: \"2 rad/s * t\"}\n"
        "gears:\n"
        "  - {name: mesh, gear: wa, with: wb, radii: [30, 30]}\n";
    mech_model *m = load_text(text);
    mech_system *s = NULL;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_system_new(m, &s, &d), MECH_OK, "%s", d.count ? d.entries[0].message : "");
    static const row_kind kinds[] = {ROW_LOOP_X, ROW_LOOP_Y, ROW_GEAR, ROW_DRIVER, ROW_DRIVER};
    static const int owners[] = {0, 0, 0, 0, 1}, lines[] = {10, 10, 17, 14, 15};
    static const char *const names[] = {"loop 1 (O-A-B-C-O)", "loop 1 (O-A-B-C-O)",
                                        "gear pair 'mesh'", "driver 'crank'", "driver 'wa'"};
    cr_assert_eq(s->m, 5);
    int count[ROW_KINDS];
    cr_assert_eq(rows_count(m, 1, count), 5);
    cr_assert(count[ROW_LOOP_X] == 1 && count[ROW_GEAR] == 1 && count[ROW_DRIVER] == 2);
    for (int r = 0; r < s->m; r++) {
        char buf[160];
        cr_assert_eq(s->rows[r].kind, kinds[r], "row %d", r);
        cr_assert_eq(s->rows[r].owner, owners[r], "row %d", r);
        cr_assert_eq(s->rows[r].mark.line, lines[r], "row %d", r);
        cr_assert_str_eq(rows_owner(s, r, buf, sizeof buf), names[r]);
    }
    cr_assert(rows_same_owner(s, 0, 1) && !rows_same_owner(s, 1, 2) && !rows_same_owner(s, 3, 4));
    char *out = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&out, &len);
    mech_system_print(s, MECH_FORMAT_TEXT, f);
    fclose(f);
    cr_assert(strstr(out, "    [loop 1, y]\n") && strstr(out, "    [gear pair 'mesh']\n") &&
                  strstr(out, "    [driver 'wa']\n"), "%s", out);
    free(out);
    mech_system_free(&s);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* A crank-rocker (20, 70, 50 on 60 mm of ground) driven by its rocker to
 * its limit: crank and coupler fold in line when |OB| = 70 - 20, at B =
 * (30, 40) mm, the rocker at atan2(40, -30) = 126.8699 deg. There the
 * unknowns are not determined by the loop and by the rocker's own row,
 * which the message names as that driver's. */
Test(drivers, dead_point_names_the_driver_row)
{
    static const char *const text =
        "name: a crank-rocker driven by its rocker\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {O: [0, 0], C: [60, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [70, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
        "sweep: {time: {from: 0 s, to: 1 s, steps: 4}}\n"
        "drivers: [{link: rocker, angle: \"90 deg + 36.869897645844021 deg/s * t\"}]\n"
        "initial: {crank: 90, coupler: 20}\n";
    mech_model *m = load_text(text);
    mech_diag d;
    mech_table t;
    cr_assert_eq(solve_noting(m, &t, &d), MECH_ESOLVE);
    const char *msg = NULL;
    for (size_t e = 0; e < d.count; e++)
        if (strstr(d.entries[e].message, "singular position at time = 1 s"))
            msg = d.entries[e].message;
    cr_assert_not_null(msg, "%s", d.count ? d.entries[d.count - 1].message : "");
    double crank = atan2(-40.0, -30.0) / DEG;  /* A = -(20/50) B: folded back */
    char at[64];
    snprintf(at, sizeof at, "th_crank (at %.3f deg)", crank);
    cr_assert(strstr(msg, at) && strstr(msg, "crank and coupler folded in line") &&
                  strstr(msg, "not determined by loop 1 (B-C-O-A-B), driver 'rocker'; "),
              "%s", msg);
    cr_assert_eq(t.nrows, 4);
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}
