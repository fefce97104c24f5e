/* tests/unit/test_simulate.c: mech_simulate (forward dynamics,
 * docs/dynamics.md) through the C API, against closed forms:
 *   - a block on a free slider pushed by a constant force along its guide
 *     (a load of the file, or the free slider's own `load:`), no gravity:
 *     s(t) = s0 + v0 t + F t^2 / (2 m) at every row;
 *   - a compound pendulum: its angular acceleration at the first row,
 *     -(m g d / I_O) cos(theta), and its first row's energies;
 *   - the refusals: no free driver, Coulomb friction. */
#include <math.h>

#include "helpers.h"

#define PI 3.14159265358979323846

static const char *const BLOCK =
    "name: pushed block\n"
    "ground: {O: [0, 0]}\n"
    "links:\n"
    "  block:\n"
    "    points: {B: [0, 0]}\n"
    "    mass: 2 kg\n"
    "    center: [0, 0]\n"
    "    inertia: 0.1 kg*m^2\n"
    "joints:\n"
    "  - {slider: B, link: block, on: ground, through: O, angle: 30 deg, name: s}\n"
    "loads:\n"
    "  - {force: [\"3 N * cos(30 deg)\", \"3 N * sin(30 deg)\"], at: B, link: block}\n"
    "sweep: {time: {from: 0 s, to: 2 s, steps: 20}}\n"
    "drivers:\n"
    "  - {slider: s, free: true, initial: {value: 100 mm, speed: -0.5 m/s}}\n"
    "outputs: {sliders: [s]}\n";

/* the same force as the free slider's own load: along its guide's line */
static const char *const BLOCK_LOAD =
    "name: pushed block\n"
    "ground: {O: [0, 0]}\n"
    "links:\n"
    "  block:\n"
    "    points: {B: [0, 0]}\n"
    "    mass: 2 kg\n"
    "    center: [0, 0]\n"
    "    inertia: 0.1 kg*m^2\n"
    "joints:\n"
    "  - {slider: B, link: block, on: ground, through: O, angle: 30 deg, name: s}\n"
    "sweep: {time: {from: 0 s, to: 2 s, steps: 20}}\n"
    "drivers:\n"
    "  - {slider: s, free: true, initial: {value: 100 mm, speed: -0.5 m/s}, load: 3 N}\n"
    "outputs: {sliders: [s]}\n";

static void block_case(const char *text)
{
    mech_model *m = load_text(text);
    mech_simulate_options o;
    mech_simulate_options_default(&o);
    o.rtol = 1e-10;
    o.atol = 1e-12;
    mech_table t;
    mech_simulate_stats st;
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_simulate(m, &o, &t, &st, &d);
    cr_assert_eq(rc, MECH_OK, "status %d", rc);
    cr_assert_eq(t.nrows, 21);
    int cs = mech_table_column(&t, "s.s"), cv = mech_table_column(&t, "s.v"),
        ca = mech_table_column(&t, "s.a"), cw = mech_table_column(&t, "work.loads"),
        ck = mech_table_column(&t, "energy.kinetic");
    cr_assert(cs >= 0 && cv >= 0 && ca >= 0 && cw >= 0 && ck >= 0);
    for (int r = 0; r < t.nrows; r++) {
        double tt = mech_table_get(&t, r, 0);
        double s = 0.1 - 0.5 * tt + 0.75 * tt * tt, v = -0.5 + 1.5 * tt;
        cr_assert_float_eq(mech_table_get(&t, r, cs), s, 1e-8, "s at t = %g", tt);
        cr_assert_float_eq(mech_table_get(&t, r, cv), v, 1e-8, "v at t = %g", tt);
        cr_assert_float_eq(mech_table_get(&t, r, ca), 1.5, 1e-9, "a at t = %g", tt);
        /* the force's work: F (s - s0); the kinetic energy: m v^2 / 2 */
        cr_assert_float_eq(mech_table_get(&t, r, cw), 3.0 * (s - 0.1), 1e-8);
        cr_assert_float_eq(mech_table_get(&t, r, ck), v * v, 1e-8);
    }
    cr_assert_float_eq(st.stop_time, 2.0, 0);
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}

Test(simulate, block_under_a_constant_force) { block_case(BLOCK); }

Test(simulate, block_pushed_by_its_free_slider_load) { block_case(BLOCK_LOAD); }

static const char *const PENDULUM =
    "name: pendulum\n"
    "gravity: [0, -9.81]\n"
    "ground: {O: [0, 0]}\n"
    "links:\n"
    "  bar:\n"
    "    points: {O: [0, 0], P: [0.5 m, 0]}\n"
    "    mass: 2 kg\n"
    "    center: [0.25 m, 0]\n"
    "    inertia: 0.041666666666666664 kg*m^2\n"
    "sweep: {time: {from: 0 s, to: 0.1 s, steps: 1}}\n"
    "drivers:\n"
    "  - {link: bar, free: true, initial: {value: 20 deg, speed: 1 rad/s}}\n"
    "outputs: {links: [bar]}\n";

Test(simulate, pendulum_first_row)
{
    mech_model *m = load_text(PENDULUM);
    mech_table t;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_simulate(m, NULL, &t, NULL, &d), MECH_OK);
    double th = 20 * PI / 180, io = 2.0 * 0.25 / 3.0, mgd = 2.0 * 9.81 * 0.25;
    cr_assert_float_eq(mech_table_get(&t, 0, mech_table_column(&t, "bar.alpha")),
                       -mgd / io * cos(th), 1e-12);
    cr_assert_float_eq(mech_table_get(&t, 0, mech_table_column(&t, "energy.kinetic")),
                       0.5 * io, 1e-14);
    cr_assert_float_eq(mech_table_get(&t, 0, mech_table_column(&t, "energy.gravity")),
                       mgd * sin(th), 1e-14);
    cr_assert_float_eq(mech_table_get(&t, 0, mech_table_column(&t, "bar.torque")), 0.0,
                       1e-12);
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}

Test(simulate, refusals)
{
    mech_model *m = load_path("mechanisms/five-bar.yaml");
    mech_table t;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_simulate(m, NULL, &t, NULL, &d), MECH_EINPUT);
    cr_assert_eq(t.nrows, 0);
    cr_assert(d.count > 0 && strstr(d.entries[0].message, "no driver is free"));
    mech_diag_free(&d);
    mech_model_free(&m);
}
