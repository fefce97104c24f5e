/* tests/unit/test_forces.c: joint reactions and driver torque against
 * independent truths: a driven physical pendulum (Newton-Euler in closed
 * form, with and without pin friction), a massless slider-crank under a
 * piston load (virtual work in closed form; the rod is a two-force member),
 * and the power balance of a four-bar with masses, gravity and loads. */
#include <criterion/criterion.h>
#include <math.h>
#include <string.h>

#include "helpers.h"

static const double PI = 3.14159265358979323846;


static void solve(const mech_model *m, int friction, mech_table *t)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = 1;
    o.friction = friction;
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_solve(m, &o, t, NULL, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK);
}

/* ---- a driven physical pendulum ---------------------------------------- */

static const char PENDULUM[] =
    "name: pendulum\n"
    "gravity: [0, -9.81]\n"
    "ground: {O: [0, 0]}\n"
    "links:\n"
    "  arm:\n"
    "    points: {O: [0, 0], P: [0.3, 0]}\n"
    "    mass: 2 kg\n"
    "    center: [0.1, 0.02]\n"
    "    inertia: 0.01 kg*m^2\n"
    "joints:\n"
    "  - {revolute: O, friction: 0.2, pin_radius: 0.01}\n"
    "driver: {link: arm, angle: {from: 0 deg, to: 360 deg, steps: 72}, speed: 3 rad/s,\n"
    "         acceleration: 2 rad/s^2}\n";

/* Newton-Euler of the arm about its centre G = R(q) (0.1, 0.02):
 *   F_O + m g = m a_G,   T + (O - G) x F_O = I_G alpha. */
static void pendulum_truth(double q, double *fx, double *fy, double *torque)
{
    const double m = 2, I = 0.01, w = 3, al = 2, g = -9.81, cx = 0.1, cy = 0.02;
    double gx = cos(q) * cx - sin(q) * cy, gy = sin(q) * cx + cos(q) * cy;  /* G - O */
    double ax = -al * gy - w * w * gx, ay = al * gx - w * w * gy;
    *fx = m * ax;
    *fy = m * ay - m * g;
    *torque = I * al - ((-gx) * *fy - (-gy) * *fx);
}

Test(forces, pendulum_newton_euler)
{
    mech_model *m = load_text(PENDULUM);
    mech_table t = {0};
    solve(m, MECH_FRICTION_BOTH, &t);
    cr_assert_eq(t.nrows, 73);
    for (int r = 0; r < t.nrows; r++) {
        double q = table_at(&t, r, "q"), fx, fy, tq;
        pendulum_truth(q, &fx, &fy, &tq);
        double scale = 20.0;  /* N; |F| ~ m (g + w^2 r) */
        cr_assert(fabs(table_at(&t, r, "O.Fx.nofriction") - fx) < 1e-12 * scale, "row %d Fx", r);
        cr_assert(fabs(table_at(&t, r, "O.Fy.nofriction") - fy) < 1e-12 * scale, "row %d Fy", r);
        cr_assert(fabs(table_at(&t, r, "driver.torque.nofriction") - tq) < 1e-12 * scale,
                  "row %d torque %.17g, expected %.17g", r, table_at(&t, r, "driver.torque.nofriction"), tq);
        /* friction: the pin's reaction is the same (one moving link), the
           driver supplies the friction moment mu r |F| against w > 0 */
        cr_assert(fabs(table_at(&t, r, "O.Fx") - fx) < 1e-12 * scale);
        double tf = tq + 0.2 * 0.01 * hypot(fx, fy);
        cr_assert(fabs(table_at(&t, r, "driver.torque") - tf) < 1e-11 * scale,
                  "row %d torque with friction %.17g, expected %.17g", r, table_at(&t, r, "driver.torque"), tf);
        cr_assert(fabs(table_at(&t, r, "friction.power") - 0.2 * 0.01 * hypot(fx, fy) * 3) < 1e-10);
        cr_assert(fabs(table_at(&t, r, "power.residual")) < 1e-12);
        cr_assert(fabs(table_at(&t, r, "power.residual.nofriction")) < 1e-12);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- a massless slider-crank under a piston load ---------------------- */

Test(forces, slider_crank_virtual_work)
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
        "driver: {link: crank, angle: {from: 5 deg, to: 355 deg, steps: 70}, speed: 10 rad/s}\n"
        "initial: {rod: -5 deg, x_B: 0.18}\n"
        "loads:\n"
        "  - {force: [-1000 N, 0], at: B, link: piston}\n");
    mech_table t = {0};
    solve(m, MECH_FRICTION_ON, &t);
    const double r = 0.04, l = 0.14, P = -1000;
    for (int k = 0; k < t.nrows; k++) {
        double q = table_at(&t, k, "q"), s = sin(q), c = cos(q);
        double dxdq = -r * s - r * r * s * c / sqrt(l * l - r * r * s * s);
        /* virtual work: T dq + P dx = 0 */
        double T = -P * dxdq;
        cr_assert(fabs(table_at(&t, k, "driver.torque") - T) < 1e-10 * 50.0,
                  "row %d: torque %.17g, expected %.17g", k, table_at(&t, k, "driver.torque"), T);
        /* the massless rod is a two-force member: the crank pin's force on
           the rod is along the rod */
        double ax = table_at(&t, k, "A.Fx"), ay = table_at(&t, k, "A.Fy");
        double phi = table_at(&t, k, "rod.angle");
        cr_assert(fabs(ax * sin(phi) - ay * cos(phi)) < 1e-9 * hypot(ax, ay),
                  "row %d: force at A not along the rod", k);
        /* the guide carries the rod force's y component */
        cr_assert(fabs(table_at(&t, k, "x_B.Fx")) < 1e-12 * 1000);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- power balance of a loaded four-bar ------------------------------- */

/* Substitute the frictionless reactions back into the coupler's Newton-Euler
 * equations, computed here from the CSV alone: A's pin acts on the coupler
 * (the later link), B's pin acts on the rocker, so -B on the coupler. */
static void check_coupler_equilibrium(const mech_table *t)
{
    const double m = 0.3, I = 1e-4, g = -9.81, q = 100.0;  /* N/m, at -60 deg */
    for (int r = 0; r < t->nrows; r++) {
        double th = table_at(t, r, "coupler.angle"), w = table_at(t, r, "coupler.omega");
        double al = table_at(t, r, "coupler.alpha"), c = cos(th), s = sin(th);
        double Ax = table_at(t, r, "A.x"), Ay = table_at(t, r, "A.y"), Bx = table_at(t, r, "B.x"), By = table_at(t, r, "B.y");
        double Px = table_at(t, r, "P.x"), Py = table_at(t, r, "P.y");
        double rx = c * 0.030 - s * 0.005, ry = s * 0.030 + c * 0.005;  /* G - A */
        double Gx = Ax + rx, Gy = Ay + ry;
        double agx = table_at(t, r, "A.ax") - al * ry - w * w * rx;
        double agy = table_at(t, r, "A.ay") + al * rx - w * w * ry;
        double fAx = table_at(t, r, "A.Fx.nofriction"), fAy = table_at(t, r, "A.Fy.nofriction");
        double fBx = -table_at(t, r, "B.Fx.nofriction"), fBy = -table_at(t, r, "B.Fy.nofriction");
        double wl = q * 0.060, fdx = wl * cos(-PI / 3), fdy = wl * sin(-PI / 3);
        double Mx = 0.5 * (Ax + Bx), My = 0.5 * (Ay + By);
        double sx = fAx + fBx + 5 + fdx, sy = fAy + fBy - 20 + fdy + m * g;
        double mom = (Ax - Gx) * fAy - (Ay - Gy) * fAx + (Bx - Gx) * fBy - (By - Gy) * fBx +
                     (Px - Gx) * -20 - (Py - Gy) * 5 + (Mx - Gx) * fdy - (My - Gy) * fdx;
        cr_assert(fabs(sx - m * agx) < 1e-10 * 100, "row %d: coupler x: %g vs %g", r, sx, m * agx);
        cr_assert(fabs(sy - m * agy) < 1e-10 * 100, "row %d: coupler y: %g vs %g", r, sy, m * agy);
        cr_assert(fabs(mom - I * al) < 1e-10 * 10, "row %d: coupler moment: %g vs %g", r, mom, I * al);
    }
}


Test(forces, fourbar_power_balance)
{
    mech_model *m = load_text(
        "name: loaded four-bar\n"
        "units: {length: mm, angle: deg}\n"
        "gravity: [0, -9.81]\n"
        "ground: {O: [0, 0], C: [70, 0]}\n"
        "links:\n"
        "  crank: {points: {O: [0, 0], A: [20, 0]}, mass: 0.1 kg, center: [10, 0], inertia: 3e-6 kg*m^2}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0], P: [30, 15]}, mass: 0.3 kg, center: [30, 5],\n"
        "            inertia: 1e-4 kg*m^2}\n"
        "  rocker: {points: {C: [0, 0], B: [50, 0]}, mass: 0.2 kg, center: [25, 0], inertia: 4e-5 kg*m^2}\n"
        "joints:\n"
        "  - {revolute: A, friction: 0.1, pin_radius: 3}\n"
        "  - {revolute: C, friction: 0.1, pin_radius: 4}\n"
        "driver: {link: crank, angle: {from: 0, to: 360, steps: 360}, speed: 50 rad/s,\n"
        "         acceleration: 20 rad/s^2}\n"
        "initial: {coupler: 40, rocker: 100}\n"
        "loads:\n"
        "  - {force: [5 N, -20 N], at: P}\n"
        "  - {torque: -0.5 N*m, link: rocker}\n"
        "  - {distributed: 100 N/m, link: coupler, from: A, to: B, direction: -60}\n");
    mech_table t = {0};
    solve(m, MECH_FRICTION_BOTH, &t);
    double worst = 0, worst_f = 0, loss = 0;
    for (int r = 0; r < t.nrows; r++) {
        worst = fmax(worst, fabs(table_at(&t, r, "power.residual.nofriction")));
        worst_f = fmax(worst_f, fabs(table_at(&t, r, "power.residual")));
        cr_assert_geq(table_at(&t, r, "friction.power"), 0.0, "friction must dissipate");
        loss += table_at(&t, r, "friction.power");
        cr_assert_leq(table_at(&t, r, "friction.iterations"), 30);
    }
    cr_assert_lt(worst, 1e-12, "power balance without friction: %g", worst);
    check_coupler_equilibrium(&t);
    cr_assert_lt(worst_f, 1e-12, "power balance with friction: %g", worst_f);
    cr_assert_gt(loss, 0.0);
    /* friction changes the torque */
    cr_assert(fabs(table_at(&t, 10, "driver.torque") - table_at(&t, 10, "driver.torque.nofriction")) > 1e-4);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* Without friction coefficients no friction columns appear, and forces are
 * only computed when asked for. */
Test(forces, columns_only_when_asked)
{
    mech_model *m = load_text(
        "name: bare four-bar\n"
        "ground: {O: [0, 0], C: [0.07, 0]}\n"
        "links:\n"
        "  crank: {points: {O: [0, 0], A: [0.02, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [0.06, 0]}}\n"
        "  rocker: {points: {C: [0, 0], B: [0.05, 0]}}\n"
        "driver: {link: crank, angle: {from: 0 deg, to: 10 deg, steps: 2}}\n"
        "initial: {coupler: 40 deg, rocker: 100 deg}\n");
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_table t = {0};
    cr_assert_eq(mech_solve(m, &o, &t, NULL, NULL), MECH_OK);
    cr_assert_eq(mech_table_column(&t, "driver.torque"), -1);
    mech_table_free(&t);
    solve(m, MECH_FRICTION_BOTH, &t);
    cr_assert_geq(mech_table_column(&t, "driver.torque"), 0);
    cr_assert_eq(mech_table_column(&t, "friction.power"), -1);
    cr_assert_eq(mech_table_column(&t, "driver.torque.nofriction"), -1);
    for (int r = 0; r < t.nrows; r++)
        cr_assert(fabs(table_at(&t, r, "driver.torque")) < 1e-15, "massless, unloaded: no torque");
    mech_table_free(&t);
    mech_model_free(&m);
}
