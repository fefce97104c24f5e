/* tests/unit/test_state_loads.c: loads that depend on the motion
 * (docs/format.md 10.2) against independent truths:
 *   - a spring and a damper written as an expression (-k (x_B.s - s0) - c v)
 *     give the driver torque and reactions of the `springs:` spring;
 *   - a load -m a (B.ax, B.ay) on a massless piston is the piston's mass;
 *   - a velocity-dependent load on a heavy slider-crank under gravity: the
 *     driver power equals dKE/dt + dV/dt - load power, the energies from
 *     the kinematic columns alone (central differences) and the load power
 *     F . v computed here from the solved velocities;
 *   - step, sign, smoothsign and tanh loads on a massless slider-crank: the
 *     driver torque by virtual work, T = -F vB / w, switching where vB does;
 *   - units: bare numbers take the file's unit, a wrong unit is an error at
 *     its line:column, a constant expression stays a constant load. */
#include <criterion/criterion.h>
#include <math.h>
#include <string.h>

#include "helpers.h"
#include "base.h"
#include "load.h"

static const double PI = 3.14159265358979323846;

static mech_table solve_forces(const mech_model *m, int steps)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = 1;
    if (steps > 0) {
        o.has_range = 1;
        o.from = 0;
        o.to = 2 * PI;
        o.steps = steps;
    }
    return must_solve(m, &o);
}

/* The slider-crank of mechanisms/spring-slider-crank.yaml (crank 40 mm,
 * rod 140 mm, piston B on the ground's x axis), 600 rpm; %s: the piston's
 * mass line, then extra top-level keys (springs, loads, gravity, units). */
static const char SC[] =
    "name: loaded slider-crank\n"
    "units: {length: mm, angle: deg%s}\n"
    "ground: {O: [0, 0], S: [300, 0]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [40, 0]}%s}\n"
    "  rod: {points: {A: [0, 0], B: [140, 0]}%s}\n"
    "  piston: {points: {B: [0, 0]}%s}\n"
    "joints:\n"
    "  - {slider: B, link: piston, on: ground, through: O, angle: 0, name: x_B}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 72}, speed: 600 rpm}\n"
    "initial: {rod: -10, x_B: 180}\n"
    "outputs: {points: [A, B], links: [crank, rod], sliders: [x_B], forces: true}\n"
    "%s";

static const char CRANK_MASS[] = ", mass: 0.5 kg, center: [20, 0], inertia: 1e-4 kg*m^2";
static const char ROD_MASS[] = ", mass: 0.5 kg, center: [70, 0], inertia: 6e-4 kg*m^2";

/* heavy: the crank and the rod have their masses (else massless links). */
static mech_model *sc_model(const char *units, int heavy, const char *piston, const char *extra)
{
    static char text[4096];
    snprintf(text, sizeof text, SC, units, heavy ? CRANK_MASS : "", heavy ? ROD_MASS : "",
             piston, extra);
    return load_text(text);
}

static double max_diff(const mech_table *a, const mech_table *b, const char *col, double *size)
{
    double worst = 0.0;
    *size = 0.0;
    cr_assert_eq(a->nrows, b->nrows);
    for (int i = 0; i < a->nrows; i++) {
        double x = table_at(a, i, col), y = table_at(b, i, col);
        worst = fmax(worst, fabs(x - y));
        *size = fmax(*size, fabs(x));
    }
    return worst;
}

/* ---- a spring written as an expression is the spring ------------------- */

Test(state_loads, spring_expression_equals_spring)
{
    mech_model *a = sc_model("", 1, ", mass: 0.4 kg, center: [0, 0], inertia: 0 kg*m^2",
                             "springs:\n"
                             "  - {between: [S, B], links: [ground, piston], stiffness: 2000 N/m,\n"
                             "     free_length: 250 mm, preload: -5 N, damping: 20 N*s/m}\n");
    /* L = 300 mm - s, tension = -5 N + k (L - 250 mm) + c dL/dt, pulling B toward S (+x) */
    mech_model *b = sc_model("", 1, ", mass: 0.4 kg, center: [0, 0], inertia: 0 kg*m^2",
                             "loads:\n"
                             "  - force: [\"-2000 N/m * (x_B.s - 50 mm) - 5 N - 20 N*s/m * x_B.v\", 0]\n"
                             "    at: B\n"
                             "    link: piston\n");
    cr_assert_not_null(b->state_loads, "the expression must compile to a state load");
    cr_assert_eq(b->nloads, 0);
    mech_table ta = solve_forces(a, 720), tb = solve_forces(b, 720);
    static const char *const cols[] = {"driver.torque", "O.Fx", "O.Fy", "A.Fx", "A.Fy",
                                       "B.Fx", "B.Fy", "x_B.N"};
    for (size_t c = 0; c < sizeof cols / sizeof *cols; c++) {
        double size, d = max_diff(&ta, &tb, cols[c], &size);
        cr_assert(d <= 1e-12 * size, "%s: differs by %g (size %g)", cols[c], d, size);
    }
    for (int i = 0; i < tb.nrows; i++)
        cr_assert(fabs(table_at(&tb, i, "power.residual")) < 1e-13);
    mech_table_free(&ta);
    mech_table_free(&tb);
    mech_model_free(&a);
    mech_model_free(&b);
}

/* The same spring as a force along the line S-B ('between'), its length
 * and rate written out: L = |B - S|, dL/dt = (B - S) . vB / L. */
Test(state_loads, line_load_equals_spring)
{
    mech_model *a = sc_model("", 1, ", mass: 0.4 kg, center: [0, 0], inertia: 0 kg*m^2",
                             "springs:\n"
                             "  - {between: [S, B], links: [ground, piston], stiffness: 2000 N/m,\n"
                             "     free_length: 250 mm, preload: -5 N, damping: 20 N*s/m}\n");
    mech_model *b = sc_model("", 1, ", mass: 0.4 kg, center: [0, 0], inertia: 0 kg*m^2",
                             "parameters: {L0: 250 mm}\n"
                             "loads:\n"
                             "  - force: \"-5 N + 2000 N/m * (sqrt((B.x - S.x)^2 + (B.y - S.y)^2) - L0)\n"
                             "      + 20 N*s/m * ((B.x - S.x) * B.vx + (B.y - S.y) * B.vy)\n"
                             "      / sqrt((B.x - S.x)^2 + (B.y - S.y)^2)\"\n"
                             "    between: [S, B]\n"
                             "    links: [ground, piston]\n");
    cr_assert_eq(b->state_loads->loads[0].torque, 2);
    mech_table ta = solve_forces(a, 720), tb = solve_forces(b, 720);
    static const char *const cols[] = {"driver.torque", "O.Fx", "O.Fy", "A.Fx", "A.Fy",
                                       "B.Fx", "B.Fy", "x_B.N"};
    for (size_t c = 0; c < sizeof cols / sizeof *cols; c++) {
        double size, d = max_diff(&ta, &tb, cols[c], &size);
        cr_assert(d <= 1e-12 * size, "%s: differs by %g (size %g)", cols[c], d, size);
    }
    for (int i = 0; i < tb.nrows; i++)
        cr_assert(fabs(table_at(&tb, i, "power.residual")) < 1e-13, "row %d: %g", i,
                  table_at(&tb, i, "power.residual"));
    mech_table_free(&ta);
    mech_table_free(&tb);
    mech_model_free(&a);
    mech_model_free(&b);
}

/* ---- D'Alembert: -m a as a load is the mass ---------------------------- */

Test(state_loads, inertia_load_equals_mass)
{
    mech_model *a = sc_model("", 1, ", mass: 0.4 kg, center: [0, 0], inertia: 0 kg*m^2", "");
    mech_model *b = sc_model("", 1, "",
                             "loads:\n"
                             "  - {force: [-0.4 kg * B.ax, -0.4 kg * B.ay], at: B, link: piston}\n");
    mech_table ta = solve_forces(a, 360), tb = solve_forces(b, 360);
    double size, d = max_diff(&ta, &tb, "driver.torque", &size);
    cr_assert(size > 1.0);
    cr_assert(d <= 1e-12 * size, "driver torque differs by %g (size %g)", d, size);
    mech_table_free(&ta);
    mech_table_free(&tb);
    mech_model_free(&a);
    mech_model_free(&b);
}

/* ---- power balance with a velocity-dependent load ----------------------- */

/* Kinetic energy at row i from the kinematic columns: crank about O (0.5 kg
 * at 20 mm, 1e-4 kg m^2), rod (0.5 kg at 70 mm from A, 6e-4), piston 0.4 kg
 * translating with B. */
static double kinetic(const mech_table *t, int i)
{
    double w = table_at(t, i, "crank.omega");
    double e = 0.5 * (1e-4 + 0.5 * 0.02 * 0.02) * w * w;
    double th = table_at(t, i, "rod.angle"), wr = table_at(t, i, "rod.omega");
    double vx = table_at(t, i, "A.vx") - wr * 0.07 * sin(th);
    double vy = table_at(t, i, "A.vy") + wr * 0.07 * cos(th);
    e += 0.5 * 0.5 * (vx * vx + vy * vy) + 0.5 * 6e-4 * wr * wr;
    double vb = table_at(t, i, "B.vx");
    return e + 0.5 * 0.4 * vb * vb;
}

/* Gravity's potential energy, g = 9.81 down: the crank's and the rod's
 * centres (the piston stays on y = 0). */
static double potential(const mech_table *t, int i)
{
    double yc = 0.02 * sin(table_at(t, i, "crank.angle"));
    double yr = table_at(t, i, "A.y") + 0.07 * sin(table_at(t, i, "rod.angle"));
    return 9.81 * 0.5 * (yc + yr);
}

/* The loads of the file, evaluated here from the solved velocities:
 * quadratic drag on the piston, a viscous torque on the rod, a force on the
 * crank pin A that depends on the crank angle. Returns their power, W. */
static double load_power(const mech_table *t, int i)
{
    double vb = table_at(t, i, "B.vx"), wr = table_at(t, i, "rod.omega");
    double q = table_at(t, i, "crank.angle");
    double fb = -3.0 * vb * fabs(vb);
    double tr = -0.02 * wr;
    double fax = 10.0 * cos(q), fay = 5.0 + 2.0 * sin(q) * sin(q);
    return fb * vb + tr * wr + fax * table_at(t, i, "A.vx") + fay * table_at(t, i, "A.vy");
}

/* d/dt of e at row i: the fourth-order central difference (error ~ h^4). */
static double d4(const mech_table *t, int i, double dt, double (*e)(const mech_table *, int))
{
    return (-e(t, i + 2) + 8 * e(t, i + 1) - 8 * e(t, i - 1) + e(t, i - 2)) / (12 * dt);
}

Test(state_loads, velocity_load_power_balance)
{
    mech_model *m = sc_model("", 1, ", mass: 0.4 kg, center: [0, 0], inertia: 0 kg*m^2",
                             "gravity: [0, -9.81]\n"
                             "loads:\n"
                             "  - {force: [-3 N*s^2/m^2 * x_B.v * abs(B.vx), 0], at: B, link: piston}\n"
                             "  - {torque: -0.02 N*m*s/rad * rod.omega, link: rod}\n"
                             "  - {force: [10 N * cos(crank.angle), 5 N + 2 N * sin(crank.angle)^2], at: A, link: crank}\n");
    const int n = 3600;
    mech_table t = solve_forces(m, n);
    double w = m->driver.speed, dt = 2 * PI / n / w, worst = 0, lp = 0;
    for (int i = 2; i < t.nrows - 2; i++) {
        double dke = d4(&t, i, dt, kinetic), dpe = d4(&t, i, dt, potential);
        double pl = load_power(&t, i);
        double pd = table_at(&t, i, "driver.torque") * w;
        double scale = fabs(pd) + fabs(dke) + fabs(dpe) + fabs(pl);
        double r = fabs(pd - dke - dpe + pl) / scale;
        worst = fmax(worst, r);
        lp = fmax(lp, fabs(pl));
        cr_assert(r < 1e-9, "row %d: driver %g W, dKE/dt %g, dV/dt %g, loads %g (rel %g)", i, pd,
                  dke, dpe, pl, r);
        cr_assert(fabs(table_at(&t, i, "power.residual")) < 1e-12);
    }
    cr_assert(lp > 10.0, "the loads must matter: largest load power %g W", lp);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- switching loads by virtual work ------------------------------------ */

/* Massless links (forces: the loads alone): T w = -F vB for a force F along
 * x at the piston. f(vB) is the force law. */
static void check_switching(const char *expr, double (*f)(double))
{
    char extra[512];
    snprintf(extra, sizeof extra, "loads:\n  - {force: [\"%s\", 0], at: B, link: piston}\n", expr);
    mech_model *m = sc_model("", 0, "", extra);
    mech_table t = solve_forces(m, 360);
    double w = m->driver.speed;
    int pos = 0, neg = 0;
    for (int i = 0; i < t.nrows; i++) {
        double vb = table_at(&t, i, "B.vx"), truth = -f(vb) * vb / w;
        double T = table_at(&t, i, "driver.torque");
        cr_assert(fabs(T - truth) <= 1e-12 * (1 + fabs(truth)), "%s: row %d, vB %g: T %.17g, truth %.17g",
                  expr, i, vb, T, truth);
        pos += vb > 1e-9, neg += vb < -1e-9;
    }
    cr_assert(pos > 100 && neg > 100, "both strokes are in the sweep");
    mech_table_free(&t);
    mech_model_free(&m);
}

static double cut(double v) { return v > 0 ? -100.0 : 0.0; }
static double coulomb(double v) { return v > 0 ? -50.0 : v < 0 ? 50.0 : 0.0; }
static double smooth(double v) { return -50.0 * v / sqrt(v * v + 0.1 * 0.1); }
static double soft(double v) { return -50.0 * tanh(v / 0.2); }
static double limited(double v) { return fmin(fmax(-30.0 * v, -20.0), 20.0); }

Test(state_loads, step_cuts_on_one_stroke) { check_switching("-100 N * step(B.vx)", cut); }
Test(state_loads, sign_is_coulomb) { check_switching("-50 N * sign(x_B.v)", coulomb); }
Test(state_loads, smoothsign) { check_switching("-50 N * smoothsign(B.vx, 100 mm/s)", smooth); }
Test(state_loads, tanh_of_ratio) { check_switching("-50 N * tanh(B.vx / (0.2 m/s))", soft); }
Test(state_loads, min_max_clip)
{
    check_switching("min(max(-30 N*s/m * B.vx, -20 N), 20 N)", limited);
}

/* The step itself switches where the velocity changes sign: the torque is
 * zero on the return stroke and positive on the forward one. */
Test(state_loads, step_switches_at_the_dead_centres)
{
    mech_model *m = sc_model("", 0, "",
                             "loads:\n  - {force: [-100 N * step(B.vx), 0], at: B, link: piston}\n");
    mech_table t = solve_forces(m, 360);
    int changes = 0;
    for (int i = 1; i < t.nrows; i++) {
        int a = table_at(&t, i - 1, "driver.torque") > 1e-9, b = table_at(&t, i, "driver.torque") > 1e-9;
        changes += a != b;
    }
    /* B moves -x for 0 < q < 180 deg (toward the crank), +x after */
    cr_assert(fabs(table_at(&t, 90, "driver.torque")) < 1e-12);
    cr_assert(table_at(&t, 270, "driver.torque") > 1.0);
    cr_assert_eq(changes, 2, "on at 180 deg, off at 360 deg: %d changes", changes);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- units ------------------------------------------------------------- */

/* Bare numbers take the file's unit: force 5 is 5 N, or 5 kN with
 * units: {force: kN}; a crank torque T = -F vB / w is then 1000 times. */
Test(state_loads, bare_numbers_take_the_file_unit)
{
    mech_model *a = sc_model("", 0, "",
                             "loads:\n  - {force: [\"5 * step(B.vx)\", 0], at: B, link: piston}\n");
    mech_model *b = sc_model(", force: kN", 0, "",
                             "loads:\n  - {force: [\"5 * step(B.vx)\", 0], at: B, link: piston}\n");
    mech_table ta = solve_forces(a, 36), tb = solve_forces(b, 36);
    for (int i = 0; i < ta.nrows; i++) {
        double vb = table_at(&ta, i, "B.vx"), w = a->driver.speed;
        double truth = vb > 0 ? -5.0 * vb / w : 0.0;
        cr_assert(fabs(table_at(&ta, i, "driver.torque") - truth) < 1e-12);
        cr_assert(fabs(table_at(&tb, i, "driver.torque") - 1000 * truth) < 1e-9);
    }
    mech_table_free(&ta);
    mech_table_free(&tb);
    mech_model_free(&a);
    mech_model_free(&b);
}

/* A constant expression stays a constant load: today's code path. */
Test(state_loads, constant_load_stays_constant)
{
    mech_model *m = sc_model("", 0, "",
                             "parameters: {F: 20 N}\n"
                             "loads:\n  - {force: [F * cos(60 deg), -F], at: B, link: piston}\n");
    cr_assert_null(m->state_loads);
    cr_assert_eq(m->nloads, 1);
    cr_assert(fabs(m->loads[0].force[0] - 10.0) < 1e-14);
    mech_model_free(&m);
}

static void expect_error(const char *load, int line, int col, const char *part)
{
    char extra[512], text[4096];
    snprintf(extra, sizeof extra, "loads:\n  - %s\n", load);
    snprintf(text, sizeof text, SC, "", "", "", "", extra);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    int rc = mech_load_string(text, strlen(text), "s.yaml", &m, &d);
    cr_assert_eq(rc, MECH_EINPUT, "%s: loaded", load);
    cr_assert_geq(d.count, 1);
    const mech_diag_entry *e = &d.entries[0];
    cr_assert(strstr(e->message, part), "%s: message '%s' lacks '%s'", load, e->message, part);
    cr_assert(e->mark.line == line && e->mark.col == col, "%s: at %d:%d, expected %d:%d (%s)",
              load, e->mark.line, e->mark.col, line, col, e->message);
    mech_diag_free(&d);
}

Test(state_loads, units_enforced)
{
    /* line 14 of SC with one load; the load text starts at column 5 */
    expect_error("{force: [B.vx, 0], at: B, link: piston}", 14, 14, "expected a force, got a speed");
    expect_error("{force: [2 N/m * B.vx, 0], at: B, link: piston}", 14, 14,
                 "got a quantity in N/s");
    expect_error("{force: [2 N*s/m * B.vx + 1 m, 0], at: B, link: piston}", 14, 29,
                 "cannot add a force (N) and a length (m)");
    expect_error("{torque: 1 N*m * exp(crank.angle), link: crank}", 14, 22, "exp needs a pure number");
    expect_error("{torque: 1 N*m * sin(B.x), link: crank}", 14, 22, "sin needs an angle");
    expect_error("{torque: \"1 N*m * smoothsign(crank.omega, 0 rad/s)\", link: crank}", 14, 23,
                 "eps > 0");
    expect_error("{force: [sqrt(B.x) * 1 N, 0], at: B, link: piston}", 14, 14, "odd power");
}

Test(state_loads, names_checked)
{
    expect_error("{force: [Q.vx * 1 N*s/m, 0], at: B, link: piston}", 14, 14, "unknown name 'Q'");
    expect_error("{torque: pistn.omega * 1 N*m*s/rad, link: crank}", 14, 14,
                 "did you mean 'piston'");
    expect_error("{force: [B.v * 1 N*s/m, 0], at: B, link: piston}", 14, 16, "point 'B' has no 'v'");
    expect_error("{torque: ground.omega * 1 N*m*s/rad, link: crank}", 14, 14, "ground does not move");
    expect_error("{torque: A.s * 1 N, link: crank}", 14, 16, "point 'A' has no 's'");
    expect_error("{torque: driver.rate * 1 N*m*s/rad, link: crank}", 14, 21, "the driver has no 'rate'");
    expect_error("{force: [1 N, 0], between: [S, B]}", 14, 13, "one value, tension positive");
    expect_error("{force: 1 N, between: [S, B], at: B}", 14, 35, "'at' does not apply");
    expect_error("{force: 1 N, between: [O, S], links: [ground, ground]}", 14, 27, "both ends are on link 'ground'");
    expect_error("{force: 1 N, between: [S, Q]}", 14, 31, "unknown point 'Q'");
}

/* The driver's value and speed: a torque -c (q - q0) - d w on the crank
 * is held by the driver torque c (q - q0) + d w (massless links). */
Test(state_loads, driver_members)
{
    mech_model *m = sc_model("", 0, "",
                             "loads:\n  - {torque: -2 N*m/rad * (driver.value - 90 deg) - "
                             "0.01 N*m*s/rad * driver.speed, link: crank}\n");
    mech_table t = solve_forces(m, 36);
    for (int i = 0; i < t.nrows; i++) {
        double q = table_at(&t, i, "q");
        double truth = 2 * (q - PI / 2) + 0.01 * m->driver.speed;
        cr_assert(fabs(table_at(&t, i, "driver.torque") - truth) < 1e-12, "q %g", q);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- mechanisms/shaper.yaml: the cut by virtual work -------------------- */

/* The same file without its cutting load has the same motion; the driver
 * torque differs by the cut's power over the crank speed, -F . vT / w, with
 * F = (Fc, Ft) while the tool cuts (ram moving -x over 0 < x_C < 100 mm). */
Test(state_loads, shaper_cut_by_virtual_work)
{
    mech_model *m = load_path("mechanisms/shaper.yaml");
    mech_model *bare = load_path("mechanisms/shaper.yaml");
    cr_assert_not_null(bare->state_loads);
    state_loads_free(bare->state_loads);
    bare->state_loads = NULL;
    mech_table t = solve_forces(m, 0), u = solve_forces(bare, 0);
    double w = m->driver.speed;
    int cutting = 0;
    for (int i = 0; i < t.nrows; i++) {
        double s = table_at(&t, i, "x_C.s"), v = table_at(&t, i, "x_C.v");
        double c = (v < 0 && s > 0 && s < 0.1) ? 1.0 : 0.0;
        double p = 400.0 * c * table_at(&t, i, "T.vx") + 100.0 * c * table_at(&t, i, "T.vy");
        double dT = table_at(&t, i, "driver.torque") - table_at(&u, i, "driver.torque");
        cr_assert(fabs(dT + p / w) < 1e-11, "row %d: torque difference %.17g, -P/w %.17g", i, dT,
                  -p / w);
        cutting += c > 0;
    }
    cr_assert_eq(cutting, 162, "the tool cuts on rows 9 .. 170 deg");
    mech_table_free(&t);
    mech_table_free(&u);
    mech_model_free(&m);
    mech_model_free(&bare);
}

/* ---- mechanisms/stirling-gas.yaml: the Schmidt gas forces ---------------- */

/* The pressure of the file's Schmidt model, computed here from the two
 * slides (docs/stirling-gas.md): bore 40 mm, rod 8 mm, H = 13 cm, hp = 4 cm,
 * Te 600, Tc 300, Tr 432.81, dead volumes 10, 5 and 20 cm^3, m R = 1 bar *
 * 100 cm^3 / 300. *vol gets the working volume. */
static double schmidt(double r3, double r9, double *vol)
{
    double A = PI / 4 * 0.04 * 0.04, Ar = PI / 4 * 0.008 * 0.008, mR = 1e5 * 100e-6 / 300;
    double vc = (A - Ar) * (0.13 - 0.04 - r9 - r3) + 5e-6, ve = A * r9 + 10e-6, vr = 20e-6;
    *vol = vc + ve + vr;
    return mR / (vc / 300 + vr / 432.81 + ve / 600);
}

/* Without its gas loads the engine has the same motion; the driver torque
 * differs by -(F . v)/w at the piston D and the displacer L. Over the turn
 * the driver takes out the gas's cycle work, the integral of p dV. */
Test(state_loads, stirling_gas_by_virtual_work_and_cycle_work)
{
    mech_model *m = load_path("mechanisms/stirling-gas.yaml");
    mech_model *bare = load_path("mechanisms/stirling-gas.yaml");
    state_loads_free(bare->state_loads);
    bare->state_loads = NULL;
    mech_table t = solve_forces(m, 0), u = solve_forces(bare, 0);
    double w = m->driver.speed, A = PI / 4 * 0.04 * 0.04, Ar = PI / 4 * 0.008 * 0.008;
    double work = 0, drive = 0, pv = 0, vv = 0;
    for (int i = 0; i < t.nrows; i++) {
        double v, p = schmidt(table_at(&t, i, "r3.s"), table_at(&t, i, "r9.s"), &v);
        double fd = -(p - 1e5) * (A - Ar), fl = -(p - 1e5) * Ar;
        double pw = fd * table_at(&t, i, "D.vy") + fl * table_at(&t, i, "L.vy");
        double dT = table_at(&t, i, "driver.torque") - table_at(&u, i, "driver.torque");
        cr_assert(fabs(dT + pw / w) < 1e-10, "row %d: torque difference %.17g, -P/w %.17g", i, dT,
                  -pw / w);
        if (i > 0) {  /* trapezoids over the turn */
            double h = table_at(&t, i, "q") - table_at(&t, i - 1, "q");
            work += 0.5 * (p + pv) * (v - vv);
            drive += 0.5 * h * (table_at(&t, i, "driver.torque") + table_at(&t, i - 1, "driver.torque"));
        }
        pv = p, vv = v;
    }
    /* 2.0437 J a turn; the two trapezoid sums agree to O(h^2) */
    cr_assert(work > 2.0 && work < 2.1, "cycle work %g J", work);
    cr_assert(fabs(drive + work) < 1e-3 * work, "driver %g J a turn, gas %g J", drive, work);
    mech_table_free(&t);
    mech_table_free(&u);
    mech_model_free(&m);
    mech_model_free(&bare);
}

/* ---- out of memory ------------------------------------------------------ */

/* Every allocation of loading a file with a motion-dependent force and
 * torque made to fail in turn: the load either fails with an error or gives
 * the whole model, its loads included (never a model without them), and
 * never crashes (it did, before nearest_name skipped a name
 * whose copy had failed: util.c). */
Test(state_loads, out_of_memory_while_loading)
{
    static char text[4096];
    snprintf(text, sizeof text, SC, "", "", "", "",
             "loads:\n"
             "  - {force: [\"-5 N * step(B.vx) + 1 N*s/m * abs(x_B.v)\", 2 N], at: B, link: piston}\n"
             "  - {torque: -2 N*m*s/rad * crank.omega * tanh(rod.angle / 1 rad), link: crank}\n");
    long failures = 0;
    for (long k = 1; k < 1000000; k++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        xalloc_fail_countdown = k;
        int rc = mech_load_string(text, strlen(text), "s.yaml", &m, &d);
        int failed = xalloc_fail_countdown == 0;
        xalloc_fail_countdown = 0;
        if (!failed) {
            cr_assert_eq(rc, MECH_OK);
            cr_assert(m->state_loads && m->state_loads->nloads == 2);
            mech_model_free(&m);
            mech_diag_free(&d);
            break;
        }
        failures++;
        if (rc == MECH_OK) {  /* a failure that was recovered from must not lose a load */
            cr_assert(m->state_loads && m->state_loads->nloads == 2, "k = %ld", k);
            mech_model_free(&m);
        } else {
            /* an error is reported; "out of memory" itself is not asked for:
               some stages before 'loads:' fall back to a default name when
               a copy fails, and then report what follows from it */
            cr_assert_gt(d.nerrors, 0, "k = %ld: failed without an error", k);
        }
        mech_diag_free(&d);
    }
    cr_assert_gt(failures, 250);
}
