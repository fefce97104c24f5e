/* tests/unit/test_springs.c: springs, dampers and flywheel sizing against
 * independent truths: a crank held by a linear spring, a damper and a
 * torsional spring (driver torque from the hand formula T = F dL/dq + ...),
 * the power balance of mechanisms/spring-slider-crank.yaml with every term
 * computed from the kinematic columns alone (finite differences of the
 * kinetic and potential energies), flywheel figures against closed forms
 * (a sine torque curve; a slider-crank under a constant piston force, whose
 * energy fluctuation is the force times the stroke), and the loader's
 * errors with their line:column. */
#include <criterion/criterion.h>
#include <math.h>
#include <string.h>

#include "study.h"
#include "helpers.h"

static const double PI = 3.14159265358979323846;

static mech_table solve_forces(const mech_model *m, int steps, double from, double to)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = 1;
    if (steps > 0) {
        o.has_range = 1;
        o.from = from;
        o.to = to;
        o.steps = steps;
    }
    return must_solve(m, &o);
}

/* ---- statics by hand: a crank held by springs -------------------------- */

/* Massless crank OA (r = 0.1 m) driven at w; S = (0, h) fixed. A linear
 * spring S-A (k, L0, preload P) with a damper c, and a torsional spring at
 * O (kt, free angle q0, preload tp) with a torsional damper ct. */
static const char CRANK[] =
    "name: sprung crank\n"
    "ground: {O: [0, 0], S: [0, 0.3]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [0.1, 0]}}\n"
    "driver: {link: crank, angle: {from: -150 deg, to: 170 deg, steps: 64}, speed: %s}\n"
    "springs:\n"
    "  - {name: k1, between: [S, A], stiffness: 800 N/m, free_length: 250 mm, preload: 3 N,\n"
    "     damping: 15 N*s/m}\n"
    "  - {name: t1, at: O, stiffness: 2 N*m/rad, free_angle: 20 deg, preload: 0.5 N*m,\n"
    "     damping: 0.05 N*m*s/rad}\n";

/* The driver torque that holds the crank: the virtual work of every spring
 * and damper, T dq = F dL + Tt dphi, with L = |A - S| and phi = q. */
static double crank_truth(double q, double w, double *len, double *force)
{
    const double r = 0.1, h = 0.3, k = 800, L0 = 0.25, P = 3, c = 15;
    const double kt = 2, q0 = 20 * PI / 180, tp = 0.5, ct = 0.05;
    double ax = r * cos(q), ay = r * sin(q);
    double L = hypot(ax, ay - h);
    double dLdq = -h * r * cos(q) / L;            /* (A - S) . dA/dq / L */
    double F = P + k * (L - L0) + c * dLdq * w;   /* tension */
    *len = L;
    *force = F;
    return F * dLdq + tp + kt * (q - q0) + ct * w;
}

static void check_crank(const char *speed, double w)
{
    char text[1024];
    snprintf(text, sizeof text, CRANK, speed);
    mech_model *m = load_text(text);
    mech_table t = solve_forces(m, 0, 0, 0);
    cr_assert_eq(t.nrows, 65);
    for (int i = 0; i < t.nrows; i++) {
        double q = table_at(&t, i, "q"), L, F;
        double T = crank_truth(q, w, &L, &F);
        cr_assert(fabs(table_at(&t, i, "driver.torque") - T) < 1e-12 * 100,
                  "q = %g deg: torque %.17g, by hand %.17g", q * 180 / PI,
                  table_at(&t, i, "driver.torque"), T);
        cr_assert(fabs(table_at(&t, i, "k1.length") - L) < 1e-15);
        cr_assert(fabs(table_at(&t, i, "k1.force") - F) < 1e-12 * 100);
        cr_assert(fabs(table_at(&t, i, "t1.angle") - q) < 1e-14);
        cr_assert(fabs(table_at(&t, i, "t1.rate") - w) < 1e-14);
        cr_assert(fabs(table_at(&t, i, "power.residual")) < 1e-13);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

Test(springs, crank_statics_by_hand) { check_crank("0 rad/s", 0.0); }
Test(springs, crank_with_dampers_by_hand) { check_crank("4 rad/s", 4.0); }

/* The torsional deflection is taken in (-180, 180] deg: a crank turned past
 * half a turn from the free angle is pulled the short way back. */
Test(springs, torsion_deflection_wraps)
{
    mech_model *m = load_text(
        "name: wound crank\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  crank: {points: {O: [0, 0], A: [0.1, 0]}}\n"
        "driver: {link: crank, angle: {from: 0 deg, to: 350 deg, steps: 35}, speed: 0 rad/s}\n"
        "springs: [{at: O, stiffness: 1 N*m/rad, free_angle: 0 deg}]\n");
    cr_assert_str_eq(m->springs[0].name, "torsion_O");
    mech_table t = solve_forces(m, 0, 0, 0);
    for (int i = 0; i < t.nrows; i++) {
        double q = table_at(&t, i, "q"), dev = q <= PI ? q : q - 2 * PI;
        cr_assert(fabs(table_at(&t, i, "driver.torque") - dev) < 1e-13, "q = %g", q);
        cr_assert(fabs(table_at(&t, i, "torsion_O.torque") - dev) < 1e-13);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- power balance of the example, from the kinematics alone ----------- */

/* Kinetic energy of mechanisms/spring-slider-crank.yaml at row i, from the
 * kinematic columns only: crank about O, rod from A's velocity and its
 * rotation, piston translating with B. */
static double kinetic_energy(const mech_table *t, int i)
{
    double w = table_at(t, i, "crank.omega");
    double e = 0.5 * (1e-4 + 0.5 * 0.02 * 0.02) * w * w;
    double th = table_at(t, i, "rod.angle"), wr = table_at(t, i, "rod.omega");
    double gx = 0.07 * cos(th), gy = 0.07 * sin(th);  /* G - A */
    double vx = table_at(t, i, "A.vx") - wr * gy, vy = table_at(t, i, "A.vy") + wr * gx;
    e += 0.5 * 0.3 * (vx * vx + vy * vy) + 0.5 * 6e-4 * wr * wr;
    double vb = table_at(t, i, "B.vx");
    return e + 0.5 * 0.4 * vb * vb;
}

/* Potential energy of the springs: the return spring S-B (S = (0.3, 0),
 * tension 2000 (L - 0.25) - 5 N) and the torsional spring at O (0.5 N*m/rad,
 * free at 0, deflection wrapped). */
static double potential_energy(const mech_table *t, int i)
{
    double L = hypot(0.3 - table_at(t, i, "B.x"), table_at(t, i, "B.y"));
    double dev = remainder(table_at(t, i, "crank.angle"), 2 * PI);
    return -5 * (L - 0.25) + 0.5 * 2000 * (L - 0.25) * (L - 0.25) + 0.5 * 0.5 * dev * dev;
}

Test(springs, example_power_balance_from_energies)
{
    mech_model *m = load_path("mechanisms/spring-slider-crank.yaml");
    const int n = 3600;
    mech_table t = solve_forces(m, n, 0, 2 * PI);
    double w = m->driver.speed, h = 2 * PI / n, dt = h / w, worst = 0;
    for (int i = 1; i < t.nrows - 1; i++) {
        double q = table_at(&t, i, "q");
        if (fabs(q - PI) < 2.5 * h)
            continue;  /* the torsional spring's deflection wraps at 180 deg */
        double dke = (kinetic_energy(&t, i + 1) - kinetic_energy(&t, i - 1)) / (2 * dt);
        double dpe = (potential_energy(&t, i + 1) - potential_energy(&t, i - 1)) / (2 * dt);
        double ldot = -table_at(&t, i, "B.vx");  /* L = 0.3 - x_B */
        double pdamp = 20 * ldot * ldot;
        double pdrive = table_at(&t, i, "driver.torque") * w;
        double scale = fabs(pdrive) + fabs(dke) + fabs(dpe) + pdamp;
        double r = fabs(pdrive - dke - dpe - pdamp) / scale;
        worst = fmax(worst, r);
        /* central differences: error ~ h^2/6 of the third derivative, about
           5e-7 relative at 0.1 deg steps */
        cr_assert(r < 2e-6, "q = %g deg: driver %g W, dKE/dt %g, dV/dt %g, damper %g (rel %g)",
                  q * 180 / PI, pdrive, dke, dpe, pdamp, r);
        cr_assert(fabs(table_at(&t, i, "damper.force") - 20 * ldot) < 1e-10);
    }
    cr_assert(worst > 0);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- flywheel figures --------------------------------------------------- */

static mech_table sine_table(int n, double span, double A, double B)
{
    mech_table t = {0};
    t.ncolumns = 2;
    t.columns = calloc(2, sizeof *t.columns);
    t.columns[0].name = strdup("q");
    t.columns[0].unit = strdup("rad");
    t.columns[1].name = strdup("driver.torque");
    t.columns[1].unit = strdup("N*m");
    t.nrows = n + 1;
    t.values = calloc((size_t)(n + 1) * 2, sizeof *t.values);
    for (int i = 0; i <= n; i++) {
        double q = span * i / n;
        t.values[2 * i] = q;
        t.values[2 * i + 1] = A * sin(q) + B;
    }
    return t;
}

/* T = A sin q + B: mean B, E(q) = A (1 - cos q), fluctuation 2 A (lowest
 * at 0, highest at 180 deg); the trapezoidal rule gives A (1 - cos q)
 * (h/2) cot(h/2), 1 - h^2/12 of it. */
Test(springs, flywheel_sine_torque)
{
    mech_model *m = load_text(
        "name: c\nground: {O: [0, 0]}\nlinks: {crank: {points: {O: [0, 0], A: [1, 0]}}}\n"
        "driver: {link: crank, angle: {from: 0 deg, to: 360 deg, steps: 4}, speed: 10 rad/s}\n");
    const double A = 30, B = 7, h = 2 * PI / 360;
    mech_table t = sine_table(360, 2 * PI, A, B);
    flywheel_figures f;
    char why[200];
    cr_assert_eq(flywheel_compute(&t, m, 0.02, &f, why, sizeof why), 0);
    cr_assert(fabs(f.mean_torque - B) < 1e-12 * A);
    double de = 2 * A * (h / 2) / tan(h / 2);
    cr_assert(fabs(f.fluctuation - de) < 1e-11 * A, "dE %.17g, expected %.17g", f.fluctuation, de);
    cr_assert(fabs(f.fluctuation - 2 * A) < 1e-4 * A);
    cr_assert(fabs(f.q_high - PI) < 1e-12 && fabs(f.q_low) < 1e-12);
    cr_assert(fabs(f.inertia - f.fluctuation / (0.02 * 100)) < 1e-12);
    cr_assert(f.full_cycle);
    mech_table_free(&t);
    t = sine_table(180, PI, A, B);  /* half a turn: flagged */
    cr_assert_eq(flywheel_compute(&t, m, 0.0, &f, why, sizeof why), 0);
    cr_assert(!f.full_cycle);
    cr_assert(isnan(f.inertia));
    mech_table_free(&t);
    mech_model_free(&m);
}

/* A massless slider-crank under a constant piston force F: the driver
 * torque is -F dx/dq, its mean over a turn 0, and the energy E(q) =
 * -F (x(q) - x(0)) swings by F times the stroke 2 r. */
Test(springs, flywheel_slider_crank_stroke)
{
    mech_model *m = load_text(
        "name: slider-crank under load\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  crank: {points: {O: [0, 0], A: [0.04, 0]}}\n"
        "  rod: {points: {A: [0, 0], B: [0.14, 0]}}\n"
        "  piston: {points: {B: [0, 0]}}\n"
        "joints:\n"
        "  - {slider: B, link: piston, on: ground, through: O, angle: 0, name: x_B}\n"
        "driver: {link: crank, angle: {from: 0 deg, to: 360 deg, steps: 3600}, speed: 50 rad/s}\n"
        "initial: {rod: -5 deg, x_B: 0.18}\n"
        "loads:\n"
        "  - {force: [-1000 N, 0], at: B, link: piston}\n");
    mech_table t = solve_forces(m, 0, 0, 0);
    flywheel_figures f;
    char why[200];
    cr_assert_eq(flywheel_compute(&t, m, 0.05, &f, why, sizeof why), 0);
    const double F = 1000, stroke = 0.08;
    cr_assert(fabs(f.mean_torque) < 1e-9 * F * stroke, "mean %g", f.mean_torque);
    /* trapezoidal error at 0.1 deg steps: below 1e-6 relative */
    cr_assert(fabs(f.fluctuation - F * stroke) < 1e-6 * F * stroke, "dE %.12g, expected %g",
              f.fluctuation, F * stroke);
    cr_assert(fabs(f.inertia - f.fluctuation / (0.05 * 2500)) < 1e-15);
    cr_assert(f.full_cycle);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- the loader's errors ------------------------------------------------ */

static const char BASE[] =
    "name: e\n"
    "ground: {O: [0, 0], S: [0, 1]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [0.1, 0], C: [0.05, 0]}}\n"
    "driver: {link: crank, angle: {from: 0 deg, to: 360 deg, steps: 4}}\n"
    "springs:\n"
    "  - %s\n";

/* The first error's line:column and that its message contains `part`. */
static void expect_error(const char *spring, int line, int col, const char *part)
{
    char text[1024];
    snprintf(text, sizeof text, BASE, spring);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    int rc = mech_load_string(text, strlen(text), "s.yaml", &m, &d);
    cr_assert_eq(rc, MECH_EINPUT, "%s: loaded", spring);
    cr_assert_geq(d.count, 1);
    const mech_diag_entry *e = &d.entries[0];
    cr_assert(strstr(e->message, part), "%s: message '%s' lacks '%s'", spring, e->message, part);
    cr_assert(e->mark.line == line && e->mark.col == col, "%s: at %d:%d, expected %d:%d (%s)",
              spring, e->mark.line, e->mark.col, line, col, e->message);
    mech_diag_free(&d);
}

Test(springs, loader_errors)
{
    expect_error("{between: [S, Q], stiffness: 1 N/m, free_length: 1 m}", 7, 19, "unknown point");
    expect_error("{between: [A, C], stiffness: 1 N/m, free_length: 1 m}", 7, 15, "both ends");
    expect_error("{between: [S, A], stiffness: -1 N/m, free_length: 1 m}", 7, 34, "negative");
    expect_error("{between: [S, A], stiffness: 1 N, free_length: 1 m}", 7, 34, "stiffness");
    expect_error("{between: [S, A], damping: 1 N*m*s/rad}", 7, 32, "damping");
    expect_error("{between: [S, A], stiffness: 1 N/m}", 7, 5, "free_length");
    expect_error("{between: [S, A]}", 7, 5, "'stiffness', 'damping'");
    expect_error("{at: A, stiffness: 1 N*m/rad, free_angle: 0}", 7, 10, "not a revolute");
    expect_error("{at: O, stiffness: 1 N*m, free_angle: 0}", 7, 24, "stiffness");
    expect_error("{at: O, between: [S, A], damping: 1 N*m*s/rad}", 7, 5, "either");
    expect_error("{at: O, free_length: 1 m, damping: 1 N*m*s/rad}", 7, 13, "does not apply");
    expect_error("{between: [S, A], links: [ground, rod], damping: 1 N*s/m}", 7, 39, "unknown link");
}

Test(springs, loader_duplicate_names)
{
    const char *text =
        "name: e\nground: {O: [0, 0], S: [0, 1]}\n"
        "links: {crank: {points: {O: [0, 0], A: [0.1, 0]}}}\n"
        "driver: {link: crank, angle: {from: 0 deg, to: 360 deg, steps: 4}}\n"
        "springs:\n"
        "  - {between: [S, A], damping: 1 N*s/m}\n"
        "  - {between: [S, A], damping: 2 N*s/m}\n";
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    cr_assert_eq(mech_load_string(text, strlen(text), "s.yaml", &m, &d), MECH_EINPUT);
    cr_assert(strstr(d.entries[0].message, "a second spring named 'damper_S_A'"),
              "%s", d.entries[0].message);
    cr_assert_eq(d.entries[0].mark.line, 7);
    mech_diag_free(&d);
}
