/* tests/unit/test_truths.c: independent truths for code that mutation
 * testing found unguarded (issue 16, "Tests that could not fail"). Every
 * expected value here is a closed form derived by hand from the geometry and
 * the loads, never the library's own formula applied to its own output. The
 * mechanisms are the files of tests/truths/ (README.md there).
 *
 * - the kinematics of a link placed through a slider (src/solve/kinematics.c,
 *   slide_offset and place_link): an oscillating cylinder written both ways
 *   round (rod sliding in the cylinder; cylinder sliding on the rod), so that
 *   the spanning tree places a link through the slider once from the guide
 *   and once from the sliding link; a point of that link against the closed
 *   form, over a full turn at four speeds with driver accelerations;
 * - slider friction: a block pushed up and down an inclined guide (driver
 *   force), the oscillating cylinder with friction in its bore (a moving
 *   guide: the guide's share of the friction in the ground pin's force),
 *   and a slider-crank with friction in the piston guide (driver torque,
 *   reactions), all against hand statics with mu |N|;
 * - pin friction: a slider-crank with friction in its three pins, the moments
 *   mu r |F| against the relative rotation of each pin (driver torque,
 *   reactions, the piston guide's couple, the dissipated power);
 * - the branch-jump guard (src/study/sweep.c, try_position): a four-bar, and two
 *   identical four-bars on one crank, output every half turn, which without
 *   the guard land on the other assembly (the twin silently: det J keeps its
 *   sign).
 */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "closed_forms.h"
#include "helpers.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* ---- helpers ----------------------------------------------------------- */

static double sgn(double v) { return v > 0.0 ? 1.0 : v < 0.0 ? -1.0 : 0.0; }

/* Compare the columns names[0..n-1] of every row with want[row * n + k]:
 * within tol_pos (lengths, angles) or tol_rate (speeds, accelerations)
 * relative to the largest |expected| of the same kind over the sweep (for
 * angles at least pi, and compared modulo 2 pi: the table's angles are
 * continuous over the sweep, the closed form's are atan2's). */
static void compare_rows(const mech_table *t, const char *const *names, int n, const double *want,
                         double tol_pos, double tol_rate, const char *what)
{
    double scale[6] = {0, 0, 0, PI, 0, 0};
    for (int r = 0; r < t->nrows; r++)
        for (int k = 0; k < n; k++) {
            int kind = column_kind(names[k]);
            scale[kind] = fmax(scale[kind], fabs(want[r * n + k]));
        }
    for (int r = 0; r < t->nrows; r++)
        for (int k = 0; k < n; k++) {
            int kind = column_kind(names[k]);
            double got = table_at(t, r, names[k]), exp = want[r * n + k];
            double err = kind == 3 ? remainder(got - exp, 2 * PI) : got - exp;
            double tol = (kind == 0 || kind == 3 ? tol_pos : tol_rate) * scale[kind];
            cr_assert(fabs(err) <= tol,
                      "%s, row %d (q = %.6g deg), %s: %.17g, expected %.17g (error %.3g, "
                      "tolerance %.3g)",
                      what, r, table_at(t, r, "q") / DEG, names[k], got, exp, err, tol);
        }
}

/* ---- 1. a link placed through a slider: the oscillating cylinder -------- */

/* The crank O-A (O = (0, 0), |OA| = r) drives the end A of a rod that slides,
 * without turning relative to it, in a cylinder pivoted on the ground at C.
 * In tests/truths/oscillating-cylinder.yaml the rod slides in the cylinder,
 * A = C + s u(phi); in oscillating-cylinder-guide.yaml the cylinder's C
 * slides on the rod, C = A + s u(phi), the rod's axis u pointing from A to C.
 * Both: phi is the rod's and the cylinder's angle, s = |CA| > 0.
 *
 * Closed form, by hand. Let D = A - C, A = r (cos q, sin q):
 *   D'  = r q' (-sin q, cos q),
 *   D'' = r q'' (-sin q, cos q) - r q'^2 (cos q, sin q).
 * First file, D = s u (u = (cos phi, sin phi), u_perp = (-sin phi, cos phi)):
 *   s = |D|, phi = atan2(Dy, Dx).
 *   s^2 = D.D         =>  s s' = D.D'  =>  s' = D.D' / s;
 *                         s s'' + s'^2 = D'.D' + D.D''
 *                     =>  s'' = (D'.D' + D.D'' - s'^2) / s.
 *   D' = s' u + s phi' u_perp and u x u_perp = 1, so
 *   D x D' = s^2 phi'  =>  phi' = (D x D') / s^2;
 *   differentiating (D' x D' = 0): D x D'' = 2 s s' phi' + s^2 phi''
 *                     =>  phi'' = (D x D'' - 2 s s' phi') / s^2.
 * Second file, -D = s u: the same s, s', s'', phi + pi instead of phi, the
 * same phi', phi''.
 * A point p (own frame) of the rod, whose frame has its origin at A (the
 * crank's pin, known above without the slider), and a point k of the
 * cylinder (origin at the fixed C), by the rigid-body formulas:
 *   P = A + R p, P' = A' + phi' k x R p, P'' = A'' + phi'' k x R p - phi'^2 R p.
 * The library instead builds the rod's frame through the slider:
 * C + s u and its rates with the sliding, Coriolis and centripetal terms
 * (src/solve/kinematics.c, slide_offset), so P tests those. */
typedef struct cylinder {
    double r, cx, cy;   /* crank, ground pivot C */
    double px, py;      /* P on the rod, rod frame (origin A) */
    double kx, ky;      /* K on the cylinder, cylinder frame (origin C) */
    int rod_is_guide;   /* 0: A = C + s u; 1: C = A + s u */
} cylinder;

static const char *const CYL_COLS[] = {
    "A.x", "A.y", "A.vx", "A.vy", "A.ax", "A.ay",
    "P.x", "P.y", "P.vx", "P.vy", "P.ax", "P.ay",
    "K.x", "K.y", "K.vx", "K.vy", "K.ax", "K.ay",
    "cylinder.angle", "cylinder.omega", "cylinder.alpha",
    "rod.angle", "rod.omega", "rod.alpha",
    "s.s", "s.v", "s.a"};
#define NCYL ((int)(sizeof CYL_COLS / sizeof *CYL_COLS))

/* A point (px, py) of a link at angle th with rates w, al whose frame origin
 * moves with o, vo, ao: position, velocity, acceleration into out[0..5]. */
static void rigid_point(const double o[6], double th, double w, double al, double px, double py,
                        double *out)
{
    double rx = cos(th) * px - sin(th) * py, ry = sin(th) * px + cos(th) * py;
    double v[6] = {o[0] + rx, o[1] + ry, o[2] - w * ry, o[3] + w * rx,
                   o[4] - al * ry - w * w * rx, o[5] + al * rx - w * w * ry};
    memcpy(out, v, sizeof v);
}

static void cylinder_ref(const cylinder *g, double q, double w, double al, double *out)
{
    double c = cos(q), s = sin(q);
    double A[6] = {g->r * c, g->r * s, -g->r * w * s, g->r * w * c,
                   -g->r * al * s - g->r * w * w * c, g->r * al * c - g->r * w * w * s};
    double Dx = A[0] - g->cx, Dy = A[1] - g->cy;
    double D1x = A[2], D1y = A[3], D2x = A[4], D2y = A[5];
    double sl = hypot(Dx, Dy);
    double sl1 = (Dx * D1x + Dy * D1y) / sl;
    double sl2 = (D1x * D1x + D1y * D1y + Dx * D2x + Dy * D2y - sl1 * sl1) / sl;
    double ph = g->rod_is_guide ? atan2(-Dy, -Dx) : atan2(Dy, Dx);
    double ph1 = (Dx * D1y - Dy * D1x) / (sl * sl);
    double ph2 = (Dx * D2y - Dy * D2x - 2 * sl * sl1 * ph1) / (sl * sl);
    double Cm[6] = {g->cx, g->cy, 0, 0, 0, 0};
    memcpy(out, A, sizeof A);
    rigid_point(A, ph, ph1, ph2, g->px, g->py, out + 6);
    rigid_point(Cm, ph, ph1, ph2, g->kx, g->ky, out + 12);
    double rest[] = {ph, ph1, ph2, ph, ph1, ph2, sl, sl1, sl2};
    memcpy(out + 18, rest, sizeof rest);
}

static void check_cylinder(const char *path, const cylinder *g)
{
    /* driver speed and acceleration: slow, the file's, reversed, fast */
    static const double runs[][2] = {{1, 0}, {10, 25}, {-40, 300}, {250, -2000}};
    mech_model *m = load_path(path);
    for (int k = 0; k < (int)(sizeof runs / sizeof *runs); k++) {
        m->driver.speed = runs[k][0];
        m->driver.accel = runs[k][1];
        mech_table t = must_solve(m, NULL);
        cr_assert_eq(t.nrows, 73);
        double *want = malloc(sizeof(double) * (size_t)t.nrows * NCYL);
        cr_assert_not_null(want);
        for (int r = 0; r < t.nrows; r++)
            cylinder_ref(g, table_at(&t, r, "q"), runs[k][0], runs[k][1], want + (size_t)r * NCYL);
        char what[256];
        snprintf(what, sizeof what, "%s at %g rad/s, %g rad/s^2", path, runs[k][0], runs[k][1]);
        compare_rows(&t, CYL_COLS, NCYL, want, 1e-12, 1e-10, what);
        free(want);
        mech_table_free(&t);
    }
    mech_model_free(&m);
}

/* The spanning tree reaches the rod through the slider, from its guide
 * (mover = guide point + s u). */
Test(truths, oscillating_cylinder_rod_slides)
{
    cylinder g = {0.05, 0.14, 0.03, -0.06, 0.015, -0.03, 0.012, 0};
    check_cylinder("tests/truths/oscillating-cylinder.yaml", &g);
}

/* The spanning tree reaches the rod, the guide, through the slider from the
 * sliding cylinder (guide point = mover - s u). */
Test(truths, oscillating_cylinder_rod_is_guide)
{
    cylinder g = {0.05, 0.14, 0.03, 0.06, 0.015, 0.03, 0.012, 1};
    check_cylinder("tests/truths/oscillating-cylinder-guide.yaml", &g);
}

/* ---- 2a. slider friction: a block on an inclined guide ----------------- */

/* tests/truths/incline-block.yaml: a block of mass m on a straight guide at
 * beta = 30 deg, driven along it (u = (cos beta, sin beta), up the slope)
 * with speed v and acceleration a, gravity g straight down, friction mu.
 * By hand, across the guide (n = u turned +90 deg): N + m g.n = 0, with
 * g.n = -g cos beta, so N = m g cos beta; along it, the driver's force F,
 * the weight's component -m g sin beta and the friction force, mu |N|
 * against the sliding velocity:
 *   F - m g sin beta - mu m g cos beta sign(v) = m a. */
Test(truths, slider_friction_incline)
{
    static const double runs[][2] = {{0.4, 0}, {-0.4, 0}, {0.4, 1.5}, {-0.25, -3}};
    const double mass = 2, g = 9.81, beta = 30 * DEG, mu = 0.25;
    mech_model *m = load_path("tests/truths/incline-block.yaml");
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = 1;
    o.friction = MECH_FRICTION_BOTH;
    for (int k = 0; k < (int)(sizeof runs / sizeof *runs); k++) {
        double v = runs[k][0], a = runs[k][1];
        m->driver.speed = v;
        m->driver.accel = a;
        mech_table t = must_solve(m, &o);
        double N = mass * g * cos(beta);
        double F0 = mass * a + mass * g * sin(beta);
        double F = F0 + mu * N * sgn(v);
        for (int r = 0; r < t.nrows; r++) {
            cr_assert(fabs(table_at(&t, r, "x.N") - N) < 1e-12 * N, "v %g row %d: N %.17g, expected %.17g",
                      v, r, table_at(&t, r, "x.N"), N);
            cr_assert(fabs(table_at(&t, r, "driver.force.nofriction") - F0) < 1e-12 * 20,
                      "v %g row %d: force without friction %.17g, expected %.17g", v, r,
                      table_at(&t, r, "driver.force.nofriction"), F0);
            cr_assert(fabs(table_at(&t, r, "driver.force") - F) < 1e-10 * 20,
                      "v %g a %g row %d: driver force %.17g, expected %.17g", v, a, r,
                      table_at(&t, r, "driver.force"), F);
            cr_assert(fabs(table_at(&t, r, "friction.power") - mu * N * fabs(v)) < 1e-10 * 20,
                      "v %g row %d: friction power %.17g, expected %.17g", v, r,
                      table_at(&t, r, "friction.power"), mu * N * fabs(v));
        }
        mech_table_free(&t);
    }
    mech_model_free(&m);
}

/* ---- 2a'. slider friction on a moving guide: the oscillating cylinder --- */

/* tests/truths/oscillating-cylinder-friction.yaml: the geometry of 1 (rod
 * sliding in the cylinder, A = C + s u, n = u turned +90 deg), no masses, a
 * torque tau = 2 N*m on the cylinder, friction mu = 0.3 between rod and
 * cylinder, the crank at w = 10 rad/s. By hand, with N n the cylinder's
 * normal force on the rod at the contact point A, M the couple between them
 * and f = -mu |N| sign(s') u the friction force on the rod (the cylinder
 * receives the opposite of all three):
 *   rod, moments about A: every force acts at A, so M = 0;
 *   cylinder, moments about C: tau - M + (s u) x (-N n) = tau - s N = 0,
 *     the friction force on the cylinder lies on the line through C, so
 *     N = tau / s;
 *   rod, forces: F_A + N n + f = 0 (F_A the crank's pin force on the rod);
 *   cylinder, forces: F_C - N n - f = 0 (F_C the ground's pin force), so
 *     F_C = N n - mu |N| sign(s') u: only the guide's share of the friction
 *     makes F_C differ from N n;
 *   crank: -F_A at A, T + A x (-F_A) = 0, so T = A x F_A;
 *   dissipated power: mu |N| |s'|.
 * s, s', u from the closed form of 1. */
Test(truths, slider_friction_moving_guide)
{
    const double w = 10, tau = 2, mu = 0.3;
    cylinder g = {0.05, 0.14, 0.03, -0.06, 0.015, -0.03, 0.012, 0};
    mech_model *m = load_path("tests/truths/oscillating-cylinder-friction.yaml");
    mech_table t = must_solve(m, NULL);
    int checked = 0;
    for (int row = 0; row < t.nrows; row++) {
        double q = table_at(&t, row, "q"), k[NCYL];
        cylinder_ref(&g, q, w, 0, k);
        double phi = k[18], sl = k[24], sl1 = k[25];
        if (fabs(sl1) < 0.2 * g.r * w)
            continue;  /* s' ~ 0 near the crank's nearest and farthest from C */
        double ux = cos(phi), uy = sin(phi), nx = -uy, ny = ux;
        double N = tau / sl, fr = mu * fabs(N) * sgn(sl1);
        double FAx = -N * nx + fr * ux, FAy = -N * ny + fr * uy;
        double FCx = N * nx - fr * ux, FCy = N * ny - fr * uy;
        double T = k[0] * FAy - k[1] * FAx;
        const double fs = 1e-9 * 25, ts = 1e-9 * 25 * 0.2;
        cr_assert(fabs(table_at(&t, row, "s.N") - N) < fs, "q %g deg: N %.17g, expected %.17g", q / DEG,
                  table_at(&t, row, "s.N"), N);
        cr_assert(fabs(table_at(&t, row, "s.M")) < ts, "q %g deg: M %.17g, expected 0", q / DEG,
                  table_at(&t, row, "s.M"));
        cr_assert(fabs(table_at(&t, row, "A.Fx") - FAx) < fs && fabs(table_at(&t, row, "A.Fy") - FAy) < fs,
                  "q %g deg: A (%.17g, %.17g), expected (%.17g, %.17g)", q / DEG,
                  table_at(&t, row, "A.Fx"), table_at(&t, row, "A.Fy"), FAx, FAy);
        cr_assert(fabs(table_at(&t, row, "C.Fx") - FCx) < fs && fabs(table_at(&t, row, "C.Fy") - FCy) < fs,
                  "q %g deg: C (%.17g, %.17g), expected (%.17g, %.17g)", q / DEG,
                  table_at(&t, row, "C.Fx"), table_at(&t, row, "C.Fy"), FCx, FCy);
        cr_assert(fabs(table_at(&t, row, "driver.torque") - T) < ts,
                  "q %g deg: driver torque %.17g, expected %.17g", q / DEG,
                  table_at(&t, row, "driver.torque"), T);
        cr_assert(fabs(table_at(&t, row, "friction.power") - mu * fabs(N * sl1)) < 1e-9 * 25 * 0.5,
                  "q %g deg: friction power %.17g, expected %.17g", q / DEG,
                  table_at(&t, row, "friction.power"), mu * fabs(N * sl1));
        checked++;
    }
    cr_assert_geq(checked, 20);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- the in-line slider-crank of 2b and 2c ------------------------------ */

/* Crank O-A of length r at angle q (speed w), rod A-B of length l, piston B
 * on the x axis to the right of A. sin phi = -r sin q / l, cos phi > 0;
 * phi' = -r w cos q / (l cos phi) (from l sin phi = -r sin q);
 * x_B' = -r w sin q - l sin phi phi'. */
typedef struct sc_state {
    double Ax, Ay, phi, c, s, phi1, vB;
} sc_state;

static sc_state slider_crank_at(double r, double l, double q, double w)
{
    sc_state k;
    k.Ax = r * cos(q);
    k.Ay = r * sin(q);
    k.s = -r * sin(q) / l;
    k.c = sqrt(1 - k.s * k.s);
    k.phi = atan2(k.s, k.c);
    k.phi1 = -r * w * cos(q) / (l * k.c);
    k.vB = -r * w * sin(q) - l * k.s * k.phi1;
    /* the same geometry from closed_forms.h (x_B and its rate): a check of
       this test's own algebra */
    slidercrank sc = {r, l, 0};
    double ref[NSLIDER];
    slider_ref(&sc, q, w, 0, ref);
    cr_assert(fabs(ref[15] - k.phi) < 1e-14 && fabs(ref[19] - k.vB) < 1e-13 * r * fabs(w),
              "slider_crank_at disagrees with closed_forms.h at q = %g", q);
    return k;
}

/* ---- 2b. slider friction: the piston guide of a slider-crank ------------ */

/* tests/truths/slider-crank-guide-friction.yaml: massless links, a load
 * P = -1000 N along x on the piston, friction mu = 0.3 in the piston's
 * guide only. By hand: the rod (no mass, frictionless pins) is a two-force
 * member, so its force on the piston is G = Gx (1, tan phi). The piston:
 *   y: Gy + N = 0                      (N the guide's normal force, along +y)
 *   x: Gx + P - mu |N| sign(x_B') = 0  (friction against the sliding)
 * => Gx (1 - mu |tan phi| sign(x_B')) = -P, with Gx > 0 (the rod pushes
 * back on the piston). The crank receives -G at A and the ground's force
 * at O; its moments about O: T + A x (-G) = 0, so T = Ax Gy - Ay Gx. */
static void check_guide_friction(double w)
{
    const double r = 0.04, l = 0.14, P = -1000, mu = 0.3;
    mech_model *m = load_path("tests/truths/slider-crank-guide-friction.yaml");
    m->driver.speed = w;
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.friction = MECH_FRICTION_BOTH;
    mech_table t = must_solve(m, &o);
    int checked = 0;
    for (int row = 0; row < t.nrows; row++) {
        double q = table_at(&t, row, "q");
        if (fabs(sin(q)) < 0.25)
            continue;  /* near the dead centres x_B' ~ 0: sign(v) is smoothed there */
        sc_state k = slider_crank_at(r, l, q, w);
        double tanp = k.s / k.c;
        double Gx = -P / (1 - mu * fabs(tanp) * sgn(k.vB)), Gy = Gx * tanp;
        double T = k.Ax * Gy - k.Ay * Gx, T0 = k.Ax * (-P * tanp) - k.Ay * (-P);
        const double fs = 1e-10 * 1000, ts = 1e-10 * 1000 * r;
        cr_assert(fabs(table_at(&t, row, "driver.torque.nofriction") - T0) < ts,
                  "w %g q %g deg: torque without friction %.17g, expected %.17g", w, q / DEG,
                  table_at(&t, row, "driver.torque.nofriction"), T0);
        cr_assert(fabs(table_at(&t, row, "driver.torque") - T) < ts,
                  "w %g q %g deg: driver torque %.17g, expected %.17g", w, q / DEG,
                  table_at(&t, row, "driver.torque"), T);
        cr_assert(fabs(table_at(&t, row, "x_B.N") + Gy) < fs, "w %g q %g deg: N %.17g, expected %.17g",
                  w, q / DEG, table_at(&t, row, "x_B.N"), -Gy);
        /* the rod's force on the piston, at B (the piston is the later link) */
        cr_assert(fabs(table_at(&t, row, "B.Fx") - Gx) < fs && fabs(table_at(&t, row, "B.Fy") - Gy) < fs,
                  "w %g q %g deg: B (%.17g, %.17g), expected (%.17g, %.17g)", w, q / DEG,
                  table_at(&t, row, "B.Fx"), table_at(&t, row, "B.Fy"), Gx, Gy);
        double pf = mu * fabs(Gy) * fabs(k.vB);
        cr_assert(fabs(table_at(&t, row, "friction.power") - pf) < 1e-10 * 1000 * r * fabs(w),
                  "w %g q %g deg: friction power %.17g, expected %.17g", w, q / DEG,
                  table_at(&t, row, "friction.power"), pf);
        checked++;
    }
    cr_assert_geq(checked, 16);
    mech_table_free(&t);
    mech_model_free(&m);
}

Test(truths, slider_friction_slider_crank) { check_guide_friction(10); }
Test(truths, slider_friction_slider_crank_reversed) { check_guide_friction(-10); }

/* ---- 2c. pin friction: the three pins of a slider-crank ----------------- */

/* tests/truths/slider-crank-pin-friction.yaml: massless links, the load
 * P = -1000 N on the piston, a frictionless guide, and Coulomb friction in
 * the pins O (mu_O, rho_O), A (mu_A, rho_A) and B (mu_B, rho_B). A pin's
 * friction moment is mu rho |F| (F the force through the pin) against the
 * rotation of one of its links relative to the other. By hand, with G the
 * rod's force on the piston:
 *   piston, x: Gx + P = 0 (the guide takes y and the couples), Gx = -P;
 *   rod: the force at A is G (no mass), |F_A| = |F_B| = |G|; the friction
 *     moments on the rod are M_A = -mu_A rho_A |G| sign(phi' - w) (against
 *     its rotation relative to the crank) and M_B = -mu_B rho_B |G|
 *     sign(phi') (relative to the piston, which does not turn); moments
 *     about A: (B - A) x (-G) + M_A + M_B = 0, i.e. with
 *     Lx = l cos phi, Ly = l sin phi, kappa = mu_A rho_A sign(phi' - w) +
 *     mu_B rho_B sign(phi'):
 *       Lx Gy - Ly Gx = -kappa |G|, so Gy = c0 - k |G|, c0 = Gx tan phi,
 *       k = kappa / Lx; squared: (1 - k^2) Gy^2 - 2 c0 Gy + c0^2 - k^2 Gx^2
 *       = 0, and the root with c0 - Gy of the sign of k is
 *       Gy = (c0 - k sqrt(c0^2 + (1 - k^2) Gx^2)) / (1 - k^2);
 *   piston, moments: the guide's couple balances -M_B: x_B.M = M_B;
 *   crank: -G at A, G from the ground at O (|F_O| = |G|), -M_A at A and
 *     M_O = -mu_O rho_O |G| sign(w) at O; moments about O:
 *       T + A x (-G) - M_A + M_O = 0  =>  T = A x G + M_A - M_O;
 *   dissipated power: |G| (mu_O rho_O |w| + mu_A rho_A |phi' - w| +
 *     mu_B rho_B |phi'|). */
static void check_pin_friction(double w)
{
    const double r = 0.04, l = 0.14, P = -1000;
    const double muO = 0.1, rhoO = 0.010, muA = 0.15, rhoA = 0.006, muB = 0.2, rhoB = 0.005;
    mech_model *m = load_path("tests/truths/slider-crank-pin-friction.yaml");
    m->driver.speed = w;
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.friction = MECH_FRICTION_ON;
    mech_table t = must_solve(m, &o);
    int checked = 0;
    for (int row = 0; row < t.nrows; row++) {
        double q = table_at(&t, row, "q");
        if (fabs(cos(q)) < 0.25)
            continue;  /* near 90 and 270 deg phi' ~ 0: sign(phi') is smoothed there */
        sc_state k = slider_crank_at(r, l, q, w);
        double Gx = -P, c0 = Gx * k.s / k.c;
        double kappa = muA * rhoA * sgn(k.phi1 - w) + muB * rhoB * sgn(k.phi1);
        double kk = kappa / (l * k.c);
        double Gy = (c0 - kk * sqrt(c0 * c0 + (1 - kk * kk) * Gx * Gx)) / (1 - kk * kk);
        double G = hypot(Gx, Gy);
        double MA = -muA * rhoA * G * sgn(k.phi1 - w), MB = -muB * rhoB * G * sgn(k.phi1);
        double MO = -muO * rhoO * G * sgn(w);
        double T = k.Ax * Gy - k.Ay * Gx + MA - MO;
        double pf = G * (muO * rhoO * fabs(w) + muA * rhoA * fabs(k.phi1 - w) +
                         muB * rhoB * fabs(k.phi1));
        const double fs = 1e-10 * 1000, ts = 1e-10 * 1000 * r;
        cr_assert(fabs(table_at(&t, row, "driver.torque") - T) < ts,
                  "w %g q %g deg: driver torque %.17g, expected %.17g", w, q / DEG,
                  table_at(&t, row, "driver.torque"), T);
        /* every pin carries G: on the crank from the ground (O), on the rod
           from the crank (A), on the piston from the rod (B) */
        static const char *const pins[][2] = {{"O.Fx", "O.Fy"}, {"A.Fx", "A.Fy"}, {"B.Fx", "B.Fy"}};
        for (int p = 0; p < 3; p++)
            cr_assert(fabs(table_at(&t, row, pins[p][0]) - Gx) < fs &&
                          fabs(table_at(&t, row, pins[p][1]) - Gy) < fs,
                      "w %g q %g deg: %s, %s = (%.17g, %.17g), expected (%.17g, %.17g)", w,
                      q / DEG, pins[p][0], pins[p][1], table_at(&t, row, pins[p][0]),
                      table_at(&t, row, pins[p][1]), Gx, Gy);
        cr_assert(fabs(table_at(&t, row, "x_B.M") - MB) < ts, "w %g q %g deg: x_B.M %.17g, expected %.17g",
                  w, q / DEG, table_at(&t, row, "x_B.M"), MB);
        cr_assert(fabs(table_at(&t, row, "friction.power") - pf) < 1e-10 * 1000 * r * fabs(w),
                  "w %g q %g deg: friction power %.17g, expected %.17g", w, q / DEG,
                  table_at(&t, row, "friction.power"), pf);
        checked++;
    }
    cr_assert_geq(checked, 16);
    mech_table_free(&t);
    mech_model_free(&m);
}

Test(truths, pin_friction_slider_crank) { check_pin_friction(10); }
Test(truths, pin_friction_slider_crank_reversed) { check_pin_friction(-10); }

/* ---- 3. the branch-jump guard ------------------------------------------- */

/* tests/truths/fourbar-coarse.yaml: the crank-rocker of
 * mechanisms/fourbar.yaml output every half turn, without a `branch:`
 * condition; fourbar-twin-coarse.yaml: two identical copies of its dyad on
 * one crank (B, coupler, rocker and E, coupler2, rocker2). From these start
 * angles (the files' 225 deg and its neighbours), Newton started from the
 * continuation's prediction for the row at q0 + 360 deg converges on the
 * crossed assembly; the guard in try_position rejects that step (the
 * correction is large next to the predicted move) and halves it. Every row
 * must match the closed form of the open assembly (closed_forms.h, sign +1),
 * on which row 0 is started (the guesses are set 2 deg from it for each
 * start). In the twin both dyads jump together and det J keeps its sign:
 * no warning either, a silent jump, which only the guard sees. */
static void check_coarse(const char *path, int twin)
{
    /* 195-255: the guard rejects the jump; 20 and every 5 deg to 180: a jump the
       guard lets pass over a long step, caught by the det J sign check */
    static const double starts[] = {195, 210, 225, 240, 255, 20, 25, 30, 35, 40, 45, 50, 55,
                                    60, 90, 120, 150, 180};
    fourbar g = {0.020, 0.060, 0.050, 0.070, 0, 0, +1};
    /* table column, and the closed form's column it must equal */
    static const char *const names[][2] = {
        {"A.x", "A.x"}, {"A.y", "A.y"}, {"A.vx", "A.vx"}, {"A.vy", "A.vy"}, {"A.ax", "A.ax"},
        {"A.ay", "A.ay"}, {"B.x", "B.x"}, {"B.y", "B.y"}, {"B.vx", "B.vx"}, {"B.vy", "B.vy"},
        {"B.ax", "B.ax"}, {"B.ay", "B.ay"}, {"crank.angle", "crank.angle"},
        {"crank.omega", "crank.omega"}, {"crank.alpha", "crank.alpha"},
        {"coupler.angle", "coupler.angle"}, {"coupler.omega", "coupler.omega"},
        {"coupler.alpha", "coupler.alpha"}, {"rocker.angle", "rocker.angle"},
        {"rocker.omega", "rocker.omega"}, {"rocker.alpha", "rocker.alpha"},
        /* the twin's second dyad */
        {"E.x", "B.x"}, {"E.y", "B.y"}, {"E.vx", "B.vx"}, {"E.vy", "B.vy"}, {"E.ax", "B.ax"},
        {"E.ay", "B.ay"}, {"coupler2.angle", "coupler.angle"},
        {"coupler2.omega", "coupler.omega"}, {"coupler2.alpha", "coupler.alpha"},
        {"rocker2.angle", "rocker.angle"}, {"rocker2.omega", "rocker.omega"},
        {"rocker2.alpha", "rocker.alpha"}};
    int n = twin ? 33 : 21;
    const char *cols[33];
    int ref_col[33];
    for (int c = 0; c < n; c++) {
        cols[c] = names[c][0];
        ref_col[c] = -1;
        for (int f = 0; f < NFOURBAR; f++)
            if (strcmp(FOURBAR_COLS[f], names[c][1]) == 0)
                ref_col[c] = f;
        cr_assert_geq(ref_col[c], 0);
    }
    mech_model *m = load_path(path);
    cr_assert_eq(m->nguesses, twin ? 4 : 2);
    for (int k = 0; k < (int)(sizeof starts / sizeof *starts); k++) {
        double q0 = starts[k] * DEG, ref[NFOURBAR];
        fourbar_ref(&g, q0, 10, 0, ref);
        for (int i = 0; i < m->nguesses; i++) {  /* coupler(2), rocker(2): 2 deg off */
            const char *link = m->links[m->guesses[i].index].name;
            cr_assert(!m->guesses[i].is_slider);
            m->guesses[i].value = ref[strncmp(link, "coupler", 7) == 0 ? 21 : 24] + 2 * DEG;
        }
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.has_range = 1;
        o.from = q0;
        o.to = q0 + 2 * PI;
        o.steps = 2;
        mech_table t = must_solve(m, &o);
        cr_assert_eq(t.nrows, 3);
        double want[3 * 33];
        for (int r = 0; r < t.nrows; r++) {
            double full[NFOURBAR];
            fourbar_ref(&g, table_at(&t, r, "q"), 10, 0, full);
            for (int c = 0; c < n; c++)
                want[r * n + c] = full[ref_col[c]];
        }
        char what[160];
        snprintf(what, sizeof what, "%s every 180 deg from %g deg", path, starts[k]);
        compare_rows(&t, cols, n, want, 1e-12, 1e-10, what);
        mech_table_free(&t);
    }
    mech_model_free(&m);
}

Test(truths, branch_jump_guard) { check_coarse("tests/truths/fourbar-coarse.yaml", 0); }
Test(truths, branch_jump_guard_twin) { check_coarse("tests/truths/fourbar-twin-coarse.yaml", 1); }
