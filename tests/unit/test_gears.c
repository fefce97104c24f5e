/* tests/unit/test_gears.c: gear pairs and racks (src/equations/gears.c,
 * src/load/load_gears.c) against independent truths: an external pair's exact
 * ratio -r_a/r_b and an internal pair's +r_a/r_b for angles, speeds and
 * accelerations (with the 'offset' phase); the planetary train of
 * mechanisms/epicyclic.yaml and a sun-fixed variant against Willis' formula
 * (w_ring - w_c)/(w_sun - w_c) = -z_sun/z_ring; a rack and pinion s = r th
 * (pinion driven, and rack driven); the power balance of the planetary
 * train with the rate of kinetic energy computed from the kinematic columns
 * and the inertias alone, its tooth forces from the sun's moment balance by
 * hand; a rack's driver torque T = (I + m r^2) alpha and tooth force
 * W cos(phi) = m a; and the loader's errors with their line:column. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "helpers.h"
#include "base.h"

static const double PI = 3.14159265358979323846;
#define DEG (PI / 180.0)

static mech_table solve_all(const mech_model *m, int forces)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = forces;
    return must_solve(m, &o);
}

static void close_to(double got, double want, double tol, const char *what, int row)
{
    cr_assert(fabs(got - want) <= tol * fmax(1.0, fabs(want)),
              "%s, row %d: %.17g, expected %.17g (difference %.3g)", what, row, got, want,
              got - want);
}

/* ---- an external pair on the ground ------------------------------------ */

/* g1 (30 mm) drives g2 (60 mm, 20:40 teeth of module 3 mm) with the phase
 * offset [10 deg, 4 deg]: 30 (th1 - 10 deg) + 60 (th2 - 4 deg) = 0. The
 * pivots are not on an axis, to check the centre distance in 2-D. */
static const char EXTERNAL[] =
    "name: external pair\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O1: [10, 20], O2: [64, 92]}\n"  /* |O2 - O1| = |(54, 72)| = 90 mm */
    "links:\n"
    "  g1: {points: {O1: [0, 0]}}\n"
    "  g2: {points: {O2: [0, 0], M: [60, 0]}}\n"
    "driver: {link: g1, angle: {from: -40, to: 320, steps: 36}, speed: 7 rad/s,\n"
    "         acceleration: -3 rad/s^2}\n"
    "gears:\n"
    "  - {name: g12, gear: g1, with: g2, teeth: [20, 40], module: 3 mm, offset: [10, 4]}\n"
    "outputs: {links: [g1, g2]}\n";

static mech_model *external_pair(void) { return load_text(EXTERNAL); }

Test(gears, external_pair_exact_ratio)
{
    mech_model *m = external_pair();
    mech_table t = solve_all(m, 0);
    cr_assert_eq(t.nrows, 37);
    const double k = -30.0 / 60.0;
    for (int i = 0; i < t.nrows; i++) {
        double q = table_at(&t, i, "q");
        close_to(table_at(&t, i, "g2.angle"), 4 * DEG + k * (q - 10 * DEG), 1e-14, "angle", i);
        close_to(table_at(&t, i, "g2.omega"), k * 7.0, 1e-14, "omega", i);
        close_to(table_at(&t, i, "g2.alpha"), k * -3.0, 1e-14, "alpha", i);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- an internal pair: a pinion inside a ring gear ----------------------- */

/* Pinion p (radii given: 25 mm) turns about A = (0, 0); the ring (75 mm)
 * about C = (50 mm, 0), its internal teeth meshing with the pinion's:
 * 25 th_p - 75 th_ring = 0, the ring turns the same way, a third as fast. */
static const char INTERNAL[] =
    "name: internal pair\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {A: [0, 0], C: [50, 0]}\n"
    "links:\n"
    "  pinion: {points: {A: [0, 0]}}\n"
    "  ring: {points: {C: [0, 0], R: [75, 0]}}\n"
    "driver: {link: pinion, angle: {from: 0, to: 720, steps: 48}, speed: -12 rad/s,\n"
    "         acceleration: 2 rad/s^2}\n"
    "gears:\n"
    "  - {gear: pinion, with: ring, radii: [25, 75], internal: true}\n"
    "outputs: {points: [R], links: [ring]}\n";

Test(gears, internal_pair_exact_ratio)
{
    mech_model *m = load_text(INTERNAL);
    cr_assert_str_eq(m->gears[0].name, "pinion_ring");
    mech_table t = solve_all(m, 0);
    const double k = 25.0 / 75.0;
    for (int i = 0; i < t.nrows; i++) {
        double q = table_at(&t, i, "q"), th = k * q;
        close_to(table_at(&t, i, "ring.angle"), th, 1e-14, "angle", i);
        close_to(table_at(&t, i, "ring.omega"), k * -12.0, 1e-14, "omega", i);
        close_to(table_at(&t, i, "ring.alpha"), k * 2.0, 1e-14, "alpha", i);
        /* the point R on the ring's pitch circle, by hand */
        close_to(table_at(&t, i, "R.x"), 0.05 + 0.075 * cos(th), 1e-14, "R.x", i);
        close_to(table_at(&t, i, "R.vy"), 0.075 * cos(th) * k * -12.0, 1e-13, "R.vy", i);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* The internal pair's tooth force by hand: only the mesh turns the ring
 * (I_ring alpha_ring = 75 mm F), and the separating part |F| tan(20 deg)
 * pushes the pinion away from the ring's teeth at (-25 mm, 0), towards +x:
 * its pivot A holds it with -|F| tan(20 deg) in x, whichever of the two is
 * named 'gear' (the ring as 'gear' turns the separating direction round). */
Test(gears, internal_pair_forces_by_hand)
{
    for (int swap = 0; swap < 2; swap++) {
        char text[2048];
        snprintf(text, sizeof text, "%s", INTERNAL);
        char *g = strstr(text, "  - {gear: pinion");
        cr_assert(g);
        snprintf(g, sizeof text - (size_t)(g - text),
                 "  - {name: mesh, gear: %s, with: %s, radii: [%s], internal: true}\n"
                 "outputs: {links: [ring], forces: true}\n",
                 swap ? "ring" : "pinion", swap ? "pinion" : "ring", swap ? "75, 25" : "25, 75");
        char *l = strstr(text, "  pinion: {points: {A: [0, 0]}}");
        cr_assert(l);
        const char *links =
            "  pinion: {points: {A: [0, 0]}, mass: 0.1 kg, center: [0, 0], inertia: 1e-4 kg*m^2}\n"
            "  ring: {points: {C: [0, 0], R: [75, 0]}, mass: 1 kg, center: [0, 0],"
            " inertia: 0.002 kg*m^2}\n";
        char rest[1024];
        snprintf(rest, sizeof rest, "%s", strstr(l, "driver:"));
        snprintf(l, sizeof text - (size_t)(l - text), "%s%s", links, rest);
        mech_model *m = load_text(text);
        mech_table t = solve_all(m, 1);
        double F = 0.002 * (2.0 / 3.0) / 0.075;
        for (int i = 0; i < t.nrows; i++) {
            close_to(fabs(table_at(&t, i, "mesh.W")) * cos(20 * DEG), F, 1e-12, "W", i);
            close_to(table_at(&t, i, "A.Fx"), -F * tan(20 * DEG), 1e-12, "A.Fx", i);
            close_to(table_at(&t, i, "driver.torque"), (1e-4 + 0.002 / 9.0) * 2.0, 1e-12,
                     "torque", i);
        }
        mech_table_free(&t);
        mech_model_free(&m);
    }
}

/* ---- the planetary train: Willis' formula --------------------------------- */

static void check_willis(const mech_table *t, const char *sun, const char *ring, double zs,
                         double zr)
{
    for (int i = 0; i < t->nrows; i++) {
        /* ring, sun and carrier angles, speeds and accelerations: the relative
           motion against the carrier is in the ratio -zs/zr */
        static const char *const what[] = {".angle", ".omega", ".alpha"};
        for (int k = 0; k < 3; k++) {
            char cs[64], cr[64], cc[64];
            snprintf(cs, sizeof cs, "%s%s", sun, what[k]);
            snprintf(cr, sizeof cr, "%s%s", ring, what[k]);
            snprintf(cc, sizeof cc, "carrier%s", what[k]);
            double s = strcmp(sun, "ground") ? table_at(t, i, cs) : 0.0;
            double r = strcmp(ring, "ground") ? table_at(t, i, cr) : 0.0;
            double c = table_at(t, i, cc);
            close_to(r - c, -zs / zr * (s - c), 1e-13, what[k], i);
        }
    }
}

Test(gears, planetary_train_willis)
{
    mech_model *m = load_path("mechanisms/epicyclic.yaml");
    mech_table t = solve_all(m, 0);
    cr_assert_eq(t.nrows, 145);
    check_willis(&t, "sun", "ground", 20, 100);
    /* and the figures the file's comments give */
    close_to(table_at(&t, 7, "carrier.omega"), 50.0, 1e-14, "carrier omega", 7);
    close_to(table_at(&t, 7, "planet.omega"), -75.0, 1e-14, "planet omega", 7);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* The same train with the sun fixed (it is the ground) and the ring driven:
 * w_c = w_ring z_ring / (z_ring + z_sun). The ring is a gear of the pair
 * on its own pivot O, shared with the carrier. */
static const char SUN_FIXED[] =
    "name: sun fixed\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0]}\n"
    "links:\n"
    "  ring: {points: {O: [0, 0], Q: [100, 0]}}\n"
    "  carrier: {points: {O: [0, 0], P: [0, 48]}}\n"
    "  planet: {points: {P: [0, 0]}}\n"
    "driver: {link: ring, angle: {from: 0, to: 360, steps: 24}, speed: 10 rad/s,\n"
    "         acceleration: 4 rad/s^2}\n"
    "gears:\n"
    "  - {name: sp, gear: ground, with: planet, teeth: [18, 30], arm: carrier}\n"
    "  - {name: pr, gear: planet, with: ring, teeth: [30, 78], internal: true, arm: carrier}\n"
    "outputs: {links: [ring, carrier, planet]}\n";

Test(gears, sun_fixed_willis)
{
    mech_model *m = load_text(SUN_FIXED);
    /* 'teeth' without 'module': the module from the centre distance 48 mm */
    cr_assert(fabs(m->gears[0].radius[0] - 0.018) < 1e-15, "%.17g", m->gears[0].radius[0]);
    cr_assert(fabs(m->gears[1].radius[1] - 0.078) < 1e-15, "%.17g", m->gears[1].radius[1]);
    mech_table t = solve_all(m, 0);
    check_willis(&t, "ground", "ring", 18, 78);
    close_to(table_at(&t, 3, "carrier.omega"), 10.0 * 78 / 96, 1e-14, "carrier omega", 3);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- rack and pinion --------------------------------------------------- */

/* Pinion (r = 20 mm, or 16 teeth of module 2.5 mm) about O = (0, 20 mm);
 * the rack a block sliding along the ground's x axis (through T), its pitch
 * line; the pinion above it: s = r th; below it (O at y = -20 mm): s = -r th. */
static const char RACK[] =
    "name: rack and pinion\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, %s], T: [0, 0]}\n"
    "links:\n"
    "  pinion: {points: {O: [0, 0]}, mass: 0.5 kg, center: [0, 0], inertia: 1e-4 kg*m^2}\n"
    "  rack: {points: {R: [0, 0]}, mass: 2 kg, center: [0, 0], inertia: 0 kg*m^2}\n"
    "joints:\n"
    "  - {slider: R, link: rack, on: ground, through: T, angle: 0, name: x_R}\n"
    "driver: %s\n"
    "gears:\n"
    "  - {name: rp, pinion: pinion, rack: x_R, %s}\n"
    "outputs: {points: [R], links: [pinion], sliders: [x_R], forces: true}\n";

static mech_model *rack(const char *y, const char *driver, const char *size)
{
    char text[2048];
    snprintf(text, sizeof text, RACK, y, driver, size);
    return load_text(text);
}

static const char PINION_DRIVEN[] =
    "{link: pinion, angle: {from: -90, to: 270, steps: 36}, speed: 5 rad/s,"
    " acceleration: 30 rad/s^2}";

Test(gears, rack_and_pinion_s_equals_r_theta)
{
    for (int below = 0; below < 2; below++) {
        mech_model *m = rack(below ? "-20" : "20", PINION_DRIVEN,
                             below ? "teeth: 16, module: 2.5 mm" : "radius: 20 mm");
        double r = 0.02 * (below ? -1 : 1);
        mech_table t = solve_all(m, 0);
        for (int i = 0; i < t.nrows; i++) {
            double q = table_at(&t, i, "q");
            close_to(table_at(&t, i, "x_R.s"), r * q, 1e-14, "s", i);
            close_to(table_at(&t, i, "x_R.v"), r * 5.0, 1e-14, "v", i);
            close_to(table_at(&t, i, "x_R.a"), r * 30.0, 1e-14, "a", i);
            close_to(table_at(&t, i, "R.x"), r * q, 1e-14, "R.x", i);
        }
        mech_table_free(&t);
        mech_model_free(&m);
    }
    /* the phase: s - 5 mm = r (th - 30 deg) */
    mech_model *mo = rack("20", PINION_DRIVEN, "radius: 20 mm, offset: 30 deg, rack_offset: 5 mm");
    mech_table to = solve_all(mo, 0);
    for (int i = 0; i < to.nrows; i++)
        close_to(table_at(&to, i, "x_R.s"), 0.005 + 0.02 * (table_at(&to, i, "q") - 30 * DEG),
                 1e-14, "s with offsets", i);
    mech_table_free(&to);
    mech_model_free(&mo);
    /* the rack driven: the pinion follows, th = s / r */
    mech_model *m = rack("20", "{slider: x_R, displacement: {from: -30, to: 50, steps: 16}, speed: 0.4 m/s}",
                         "radius: 20 mm");
    mech_table t = solve_all(m, 0);
    for (int i = 0; i < t.nrows; i++) {
        close_to(table_at(&t, i, "pinion.angle"), table_at(&t, i, "q") / 0.02, 1e-13, "th", i);
        close_to(table_at(&t, i, "pinion.omega"), 0.4 / 0.02, 1e-13, "omega", i);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* The rack's statics by hand: T = (I + m r^2) alpha (the rack's inertia
 * force m r alpha at the pitch radius); the tooth force's tangential part
 * F = W cos(20 deg) = m r alpha carries the rack, and its separating part
 * |F| tan(20 deg) pushes the rack down onto its guide and the pinion up off
 * it, whichever flank carries the load (alpha of either sign): the pivot O
 * holds the pinion with (F, -|F| tan 20 deg), the guide the rack with
 * N = |F| tan 20 deg. */
Test(gears, rack_forces_by_hand)
{
    for (int sign = -1; sign <= 1; sign += 2) {
        char driver[256];
        snprintf(driver, sizeof driver, "{link: pinion, angle: {from: -90, to: 270, steps: 36}, "
                 "speed: 5 rad/s, acceleration: %d rad/s^2}", 30 * sign);
        mech_model *m = rack("20", driver, "radius: 20 mm");
        mech_table t = solve_all(m, 1);
        const double r = 0.02, I = 1e-4, mass = 2.0, al = 30.0 * sign, tn = tan(20 * DEG);
        const double F = mass * r * al;
        for (int i = 0; i < t.nrows; i++) {
            close_to(table_at(&t, i, "driver.torque"), (I + mass * r * r) * al, 1e-13, "torque",
                     i);
            close_to(table_at(&t, i, "rp.W") * cos(20 * DEG), F, 1e-13, "W", i);
            close_to(table_at(&t, i, "O.Fx"), F, 1e-13, "O.Fx", i);
            close_to(table_at(&t, i, "O.Fy"), -fabs(F) * tn, 1e-13, "O.Fy", i);
            close_to(table_at(&t, i, "x_R.N"), fabs(F) * tn, 1e-13, "x_R.N", i);
            cr_assert(fabs(table_at(&t, i, "power.residual")) < 1e-13);
        }
        mech_table_free(&t);
        mech_model_free(&m);
    }
}

/* ---- the planetary train's power balance ----------------------------------- */

/* The planet's pin reaction from its own balance, given the solved tooth
 * forces W of the two meshes: each acts on its `with` gear as
 * W cos(phi) t + |W| sin(phi) r (t the tangent, n rotated +90 deg, n the
 * unit from the `gear`'s centre through the pitch point, r the separating
 * direction). Here n = P / |P| for both meshes (the sun's centre O to the
 * planet; the planet inside the ring: outwards), r = n; the sun-planet
 * force acts on the planet, the planet-ring force on the ring (its
 * opposite on the planet). So P (on the planet) = m_p a_P - F_sp + F_pr. */
static void check_planet_pin(const mech_table *t, int i, double mp)
{
    const double phi = 20 * DEG, c = cos(phi), sn = sin(phi);
    double px = table_at(t, i, "P.x"), py = table_at(t, i, "P.y"), d = hypot(px, py);
    double n[2] = {px / d, py / d}, tg[2] = {-n[1], n[0]};
    double wsp = table_at(t, i, "g_sp.W"), wpr = table_at(t, i, "g_pr.W");
    for (int k = 0; k < 2; k++) {
        double fsp = wsp * c * tg[k] + fabs(wsp) * sn * n[k];
        double fpr = wpr * c * tg[k] + fabs(wpr) * sn * n[k];
        double want = mp * table_at(t, i, k ? "P.ay" : "P.ax") - fsp + fpr;
        close_to(table_at(t, i, k ? "P.Fy" : "P.Fx"), want, 1e-12, "planet pin", i);
    }
}

/* d/dt of the kinetic energy from the kinematic columns and the file's
 * inertias (sun at O: no translation; carrier's centre 20 mm along it,
 * from its angle and rates; planet's centre at P, an output point). */
Test(gears, planetary_power_balance)
{
    mech_model *m = load_path("mechanisms/epicyclic.yaml");
    mech_table t = solve_all(m, 1);
    const double Is = 4e-5, mc = 0.3, Ic = 2e-4, mp = 0.4, Ip = 3.2e-4, rg = 0.02;
    const double phi = 20 * DEG, rs = 0.02;
    double worst = 0.0;
    for (int i = 0; i < t.nrows; i++) {
        double ws = table_at(&t, i, "sun.omega"), as = table_at(&t, i, "sun.alpha");
        double tc = table_at(&t, i, "carrier.angle"), wc = table_at(&t, i, "carrier.omega");
        double ac = table_at(&t, i, "carrier.alpha");
        double wp = table_at(&t, i, "planet.omega"), ap = table_at(&t, i, "planet.alpha");
        double vg[2] = {-wc * rg * sin(tc), wc * rg * cos(tc)};
        double ag[2] = {-ac * rg * sin(tc) - wc * wc * rg * cos(tc),
                        ac * rg * cos(tc) - wc * wc * rg * sin(tc)};
        double vp[2] = {table_at(&t, i, "P.vx"), table_at(&t, i, "P.vy")};
        double apn[2] = {table_at(&t, i, "P.ax"), table_at(&t, i, "P.ay")};
        double dT = Is * ws * as + Ic * wc * ac + mc * (vg[0] * ag[0] + vg[1] * ag[1]) +
                    Ip * wp * ap + mp * (vp[0] * apn[0] + vp[1] * apn[1]);
        double torque = table_at(&t, i, "driver.torque");
        double r = fabs(torque * ws - dT) / fabs(dT);
        worst = fmax(worst, r);
        cr_assert(r < 1e-13, "row %d: driver power %.17g, dT/dt %.17g", i, torque * ws, dT);
        check_planet_pin(&t, i, mp);
        /* the sun: driver torque - its inertia = the tooth force's moment */
        close_to(fabs(table_at(&t, i, "g_sp.W")) * cos(phi) * rs, fabs(torque - Is * as), 1e-13,
                 "sun-planet tooth force", i);
    }
    cr_log_info("planetary power balance: worst relative difference %.3g", worst);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- the loader's errors ------------------------------------------------- */

static const char BASE[] =
    "name: e\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0], C: [90, 0], T: [0, -40]}\n"
    "links:\n"
    "  g1: {points: {O: [0, 0]}}\n"
    "  g2: {points: {C: [0, 0], M: [10, 0]}}\n"
    "  rack: {points: {R: [0, 0]}}\n"
    "joints:\n"
    "  - {slider: R, link: rack, on: ground, through: T, angle: 0, name: x_R}\n"
    "driver: {link: g1, angle: {from: 0, to: 360, steps: 4}}\n"
    "gears:\n"
    "  - %s\n";

/* The first error's line:column and that its message contains `part`. */
static void expect_error(const char *gear, int line, int col, const char *part)
{
    char text[2048];
    snprintf(text, sizeof text, BASE, gear);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    int rc = mech_load_string(text, strlen(text), "g.yaml", &m, &d);
    cr_assert_eq(rc, MECH_EINPUT, "%s: loaded", gear);
    cr_assert_geq(d.count, 1);
    const mech_diag_entry *e = &d.entries[0];
    cr_assert(strstr(e->message, part), "%s: message '%s' lacks '%s'", gear, e->message, part);
    cr_assert(e->mark.line == line && e->mark.col == col, "%s: at %d:%d, expected %d:%d (%s)",
              gear, e->mark.line, e->mark.col, line, col, e->message);
    mech_diag_free(&d);
}

Test(gears, loader_errors)
{
    /* 90 mm apart: 20 + 40 teeth of module 2 mm need 60 mm */
    expect_error("{gear: g1, with: g2, teeth: [20, 40], module: 2 mm}", 12, 33,
                 "are 90 mm apart on 'ground', but external gears of pitch radii 20 mm and "
                 "40 mm need a centre distance of 60 mm");
    expect_error("{gear: g1, with: g2, radii: [30, 50]}", 12, 33, "centre distance of 80 mm");
    expect_error("{gear: g1, with: g2, radii: [30, 100], internal: true}", 12, 33,
                 "internal gears of pitch radii 30 mm and 100 mm need a centre distance of 70 mm");
    expect_error("{gear: g1, with: g1, teeth: [20, 40]}", 12, 22, "cannot mesh with itself");
    expect_error("{gear: g1, with: g3, teeth: [20, 40]}", 12, 22, "unknown link 'g3'");
    expect_error("{gear: g1, with: g2}", 12, 5, "a gear pair needs 'teeth");
    expect_error("{gear: g1, with: g2, teeth: [20]}", 12, 33, "two tooth counts");
    expect_error("{gear: g1, with: g2, teeth: [20, 20], internal: true}", 12, 33,
                 "ring larger");
    expect_error("{gear: g1, with: g2, teeth: [20, 40], module: 3 mm, arm: g2}", 12, 62,
                 "gear 'g1' has no pivot on the arm 'g2'");
    expect_error("{gear: g1, with: g2, teeth: [20, 40], module: 3 mm, arm: g1}", 12, 62,
                 "gear 'g1' is the arm 'g1' itself");
    expect_error("{gear: g1, with: rack, radii: [30, 60]}", 12, 5,
                 "gear 'rack' has no pivot on the 'ground'");
    expect_error("{gear: g1, with: g2, teeth: [20, 40], pressure_angle: 50 deg}", 12, 59,
                 "pressure_angle");
    expect_error("{gear: g1, with: g2, teeth: [20, 40], radius: 3}", 12, 43,
                 "'radius' does not apply to a gear pair");
    expect_error("{pinion: g1, rack: x_R, radius: 30 mm}", 12, 37,
                 "the pinion's centre O is 40 mm from the rack's pitch line");
    expect_error("{pinion: g1, rack: g2, radius: 40 mm}", 12, 24, "unknown slider 'g2'");
    expect_error("{pinion: g1, rack: x_R}", 12, 5, "needs 'radius'");
    expect_error("{pinion: g1, rack: x_R, radius: 40 mm, internal: true}", 12, 44,
                 "'internal' does not apply to a rack");
}

Test(gears, mobility_counts_a_mesh)
{
    mech_model *m = external_pair();
    mech_summary s;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_check(m, &s, &d), MECH_OK);
    cr_assert_eq(s.ngears, 1);
    cr_assert_eq(s.nloops, 0);          /* two gears on the ground: no loop at all */
    cr_assert_eq(s.nequations, 1);
    cr_assert_eq(s.mobility, 1);        /* 3*2 - 2*2 - 1 */
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* ---- the geared five-bar ------------------------------------------------- */

/* mechanisms/geared-five-bar.yaml by hand: th2 = 90 deg - q / 2 (the mesh),
 * A = 15 mm (cos q, sin q), D = C + 15 mm (cos th2, sin th2), B the
 * intersection of the circles of 60 mm about A and D to the left of A->D;
 * and the driver power against the rate of kinetic energy from the columns
 * (cranks turning about their fixed centres, the couplers' centres at the
 * middle of AB and DB: v_G = (v_A + v_B) / 2, a_G likewise). */
Test(gears, geared_five_bar_closed_form_and_power)
{
    mech_model *m = load_path("mechanisms/geared-five-bar.yaml");
    mech_table t = solve_all(m, 1);
    cr_assert_eq(t.nrows, 145);
    const double L = 0.06, c = 0.06, w = 20.0;
    double worst = 0.0;
    for (int i = 0; i < t.nrows; i++) {
        double q = table_at(&t, i, "q"), th2 = PI / 2 - q / 2;
        close_to(table_at(&t, i, "crank2.angle"), th2, 1e-14, "th2", i);
        double ax = 0.015 * cos(q), ay = 0.015 * sin(q);
        double dx = c + 0.015 * cos(th2), dy = 0.015 * sin(th2);
        double ex = dx - ax, ey = dy - ay, d = hypot(ex, ey);
        double h = sqrt(L * L - d * d / 4);
        double bx = ax + ex / 2 - h * ey / d, by = ay + ey / 2 + h * ex / d;
        close_to(table_at(&t, i, "B.x"), bx, 1e-13, "B.x", i);
        close_to(table_at(&t, i, "B.y"), by, 1e-13, "B.y", i);
        static const char *const cpl[2][2] = {{"A", "B"}, {"D", "B"}};
        static const char *const name[2] = {"coupler", "rod"};
        /* crank1 turns at a constant speed: no term */
        double dT = 2.4e-4 * table_at(&t, i, "crank2.omega") * table_at(&t, i, "crank2.alpha");
        for (int k = 0; k < 2; k++) {
            char col[32];
            double v[2], a[2], om, al;
            for (int x = 0; x < 2; x++) {
                snprintf(col, sizeof col, "%s.v%c", cpl[k][0], "xy"[x]);
                v[x] = table_at(&t, i, col);
                snprintf(col, sizeof col, "%s.v%c", cpl[k][1], "xy"[x]);
                v[x] = 0.5 * (v[x] + table_at(&t, i, col));
                snprintf(col, sizeof col, "%s.a%c", cpl[k][0], "xy"[x]);
                a[x] = table_at(&t, i, col);
                snprintf(col, sizeof col, "%s.a%c", cpl[k][1], "xy"[x]);
                a[x] = 0.5 * (a[x] + table_at(&t, i, col));
            }
            snprintf(col, sizeof col, "%s.omega", name[k]);
            om = table_at(&t, i, col);
            snprintf(col, sizeof col, "%s.alpha", name[k]);
            al = table_at(&t, i, col);
            dT += 0.05 * (v[0] * a[0] + v[1] * a[1]) + 1.5e-5 * om * al;
        }
        double P = table_at(&t, i, "driver.torque") * w;
        double scale = fmax(fabs(dT), 1e-6);
        worst = fmax(worst, fabs(P - dT) / scale);
        cr_assert(fabs(P - dT) <= 1e-12 * scale, "row %d: driver power %.17g, dT/dt %.17g", i,
                  P, dT);
    }
    cr_log_info("geared five-bar power balance: worst relative difference %.3g", worst);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- friction in a train ---------------------------------------------------- */

/* mechanisms/epicyclic.yaml with Coulomb friction in the planet's pin P
 * (mu 0.2, pin radius 5 mm) and the sun's pivot O (0.1, 4 mm): the driver
 * power less the friction losses mu r |F| |w_rel| of the two pins, from
 * their reaction columns (which carry the teeth's separating forces), is
 * the rate of kinetic energy, computed as in planetary_power_balance; and
 * the planet's pin balances it with the tooth forces on their flanks. */
Test(gears, planetary_friction_losses)
{
    FILE *f = fopen("mechanisms/epicyclic.yaml", "r");
    cr_assert(f);
    static char text[16384];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    char *drv = strstr(text, "\ndriver:\n");
    cr_assert(drv);
    static char with[17000];
    snprintf(with, sizeof with, "%.*s\njoints:\n"
             "  - {revolute: P, links: [carrier, planet], friction: 0.2, pin_radius: 5 mm}\n"
             "  - {revolute: O, links: [ground, sun], friction: 0.1, pin_radius: 4 mm}%s",
             (int)(drv - text), text, drv);
    mech_model *m = load_text(with);
    mech_table t = solve_all(m, 1);
    const double Is = 4e-5, mc = 0.3, Ic = 2e-4, mp = 0.4, Ip = 3.2e-4, rg = 0.02;
    for (int i = 0; i < t.nrows; i++) {
        double ws = table_at(&t, i, "sun.omega"), as = table_at(&t, i, "sun.alpha");
        double tc = table_at(&t, i, "carrier.angle"), wc = table_at(&t, i, "carrier.omega");
        double ac = table_at(&t, i, "carrier.alpha");
        double wp = table_at(&t, i, "planet.omega"), ap = table_at(&t, i, "planet.alpha");
        double vg[2] = {-wc * rg * sin(tc), wc * rg * cos(tc)};
        double ag[2] = {-ac * rg * sin(tc) - wc * wc * rg * cos(tc),
                        ac * rg * cos(tc) - wc * wc * rg * sin(tc)};
        double vp[2] = {table_at(&t, i, "P.vx"), table_at(&t, i, "P.vy")};
        double apn[2] = {table_at(&t, i, "P.ax"), table_at(&t, i, "P.ay")};
        double dT = Is * ws * as + Ic * wc * ac + mc * (vg[0] * ag[0] + vg[1] * ag[1]) +
                    Ip * wp * ap + mp * (vp[0] * apn[0] + vp[1] * apn[1]);
        double loss = 0.2 * 0.005 * table_at(&t, i, "P.F") * fabs(wp - wc) +
                      0.1 * 0.004 * table_at(&t, i, "O.F") * fabs(ws);
        double P = table_at(&t, i, "driver.torque") * ws;
        check_planet_pin(&t, i, mp);
        cr_assert(loss > 0.1 * dT, "row %d: losses %g, dT/dt %g: friction too small to see", i,
                  loss, dT);
        cr_assert(fabs(P - loss - dT) <= 1e-10 * (fabs(P) + loss),
                  "row %d: driver power %.17g - losses %.17g != dT/dt %.17g", i, P, loss, dT);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- out of memory ------------------------------------------------------- */

/* The k-th allocation fails, k = 1, 2, ... until loading and checking the
 * planetary train succeed: never a crash (make test-san: no leak either),
 * and when the load fails, with an error. (Not stricter: the loader lets
 * some failures pass silently, a link's name in its map for one, so the
 * message may be a follow-on such as "unknown link 'ground'"; and a solve
 * under failed allocations crashes for every mechanism, gears or not, in
 * columns.c and tape.c: reported, not this module's.) */
Test(gears, out_of_memory_is_not_a_crash)
{
    int tried = 0;
    for (long k = 1; k < 1000000; k++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_summary s;
        xalloc_fail_countdown = k;
        int rc = mech_load_file("mechanisms/epicyclic.yaml", &m, &d);
        if (rc == MECH_OK)
            rc = mech_check(m, &s, &d);
        int failed = xalloc_fail_countdown == 0;
        xalloc_fail_countdown = 0;
        tried += failed;
        if (rc != MECH_OK)
            cr_assert(d.nerrors >= 1, "allocation %ld: load failed without an error", k);
        else if (!failed)
            cr_assert_eq(m->ngears, 2);
        mech_model_free(&m);
        mech_diag_free(&d);
        if (!failed)
            break;
    }
    cr_log_info("out of memory: %d allocations made to fail", tried);
    cr_assert_gt(tried, 50, "only %d allocations were tried", tried);
}

/* ---- sensitivities ----------------------------------------------------- */

/* A parameter that sets a gear pair's radii is refused by --sensitivity
 * (the derivative through the gear row is not carried), at the pair's
 * place, rather than giving derivatives without that term. */
Test(gears, sensitivity_through_gears_refused)
{
    FILE *in = fopen("mechanisms/geared-five-bar.yaml", "r");
    cr_assert(in);
    static char text[16384], out[17000];
    size_t n = fread(text, 1, sizeof text - 1, in);
    fclose(in);
    text[n] = '\0';
    char *u = strstr(text, "units: {length: mm, angle: deg}\n"), *mod = strstr(text, "module: 2 mm");
    cr_assert(u && mod);
    u += strlen("units: {length: mm, angle: deg}\n");
    snprintf(out, sizeof out, "%.*sparameters: {md: 2 mm}\n%.*smodule: md%s", (int)(u - text),
             text, (int)(mod - u), u, mod + strlen("module: 2 mm"));
    char path[] = "/tmp/test_gears_XXXXXX";
    int fd = mkstemp(path);
    cr_assert(fd >= 0);
    cr_assert_eq(write(fd, out, strlen(out)), (ssize_t)strlen(out));
    close(fd);
    mech_model *m = load_path(path);
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_table t = must_solve(m, &o);
    mech_diag d;
    mech_diag_init(&d);
    const char *names[] = {"md"};
    int rc = mech_sensitivity(m, NULL, 0, &o, names, 1, &t, &d);
    unlink(path);
    cr_assert_neq(rc, MECH_OK);
    cr_assert(d.count >= 1 && strstr(d.entries[0].message, "gear pair 'g12'"), "%s",
              d.count ? d.entries[0].message : "no message");
    cr_assert_eq(d.entries[0].mark.line, m->gears[0].mark.line);
    mech_diag_free(&d);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- diagnostics that name gear rows ---------------------------------------- */

/* Three equal gears meshing in a triangle jam (w_a = -w_b = w_c = -w_a):
 * at the start the three rows have rank 2 (the third is implied) and no
 * other position assembles; both messages name the gear rows, each by its
 * own pair (the row that closes worst is a_b's). */
Test(gears, jammed_triangle_names_the_gears)
{
    static const char TRI[] =
        "name: three gears in a triangle\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {A: [0, 0], B: [60, 0], C: [30, 51.96152422706632]}\n"
        "links:\n"
        "  a: {points: {A: [0, 0]}}\n"
        "  b: {points: {B: [0, 0]}}\n"
        "  c: {points: {C: [0, 0]}}\n"
        "driver: {link: a, angle: {from: 0, to: 90, steps: 3}}\n"
        "gears:\n"
        "  - {gear: a, with: b, radii: [30, 30]}\n"
        "  - {gear: b, with: c, radii: [30, 30]}\n"
        "  - {gear: c, with: a, radii: [30, 30]}\n";
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    mech_summary s;
    cr_assert_eq(mech_load_string(TRI, strlen(TRI), "tri.yaml", &m, &d), MECH_OK);
    cr_assert_eq(mech_check(m, &s, &d), MECH_OK);  /* a warning: over-constrained by the count */
    cr_assert_eq(s.mobility, 0);
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_table t = {0};
    mech_solve(m, &o, &t, NULL, &d);
    int rank = 0, jam = 0;
    for (size_t e = 0; e < d.count; e++) {
        rank |= strstr(d.entries[e].message, "implied by the others: the row of gear pair "
                                             "'c_a'") != NULL;
        jam |= strstr(d.entries[e].message, "cannot assemble at driver angle = 30 deg: gear "
                                            "pair 'a_b' does not close") != NULL;
    }
    cr_assert(rank && jam, "rank %d, jam %d: %s", rank, jam,
              d.count ? d.entries[d.count - 1].message : "");
    cr_assert_eq(t.nrows, 1);
    mech_table_free(&t);
    mech_model_free(&m);
    mech_diag_free(&d);
}

/* The rack driven (0.5 m/s, 3 m/s^2) turning a pinion of inertia I: the
 * driver force is m a + I (a / r) / r by hand, the tooth's tangential
 * part I (a / r) / r, on the rack against its motion (W < 0). */
Test(gears, rack_driven_force_by_hand)
{
    mech_model *m = rack("20", "{slider: x_R, displacement: {from: 0, to: 60, steps: 6}, "
                         "speed: 0.5 m/s, acceleration: 3 m/s^2}", "radius: 20 mm");
    mech_table t = solve_all(m, 1);
    const double r = 0.02, I = 1e-4, mass = 2.0, a = 3.0;
    for (int i = 0; i < t.nrows; i++) {
        close_to(table_at(&t, i, "driver.force"), mass * a + I * (a / r) / r, 1e-13, "force", i);
        close_to(table_at(&t, i, "rp.W") * cos(20 * DEG), -I * (a / r) / r, 1e-13, "W", i);
        close_to(table_at(&t, i, "pinion.alpha"), a / r, 1e-13, "alpha", i);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}
