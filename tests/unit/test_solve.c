/* tests/unit/test_solve.c: mech_solve against independent truths.
 *
 * - closed forms written here (closed_forms.h), not taken from the library: the four-bar by
 *   circle intersection, its angular rates from the velocity and
 *   acceleration loop equations (2x2, Cramer), the coupler point by
 *   rigid-body formulas; the offset slider-crank by x = r cos q + sqrt(l^2 -
 *   (e - r sin q)^2) and its derivatives. Crank-rocker, double-crank and
 *   offset slider-crank sweeps of a full revolution, with a driver
 *   acceleration, match them to 1e-10 relative at every position;
 * - velocities against central differences of the solved positions, and
 *   accelerations against central differences of the solved velocities;
 * - periodicity: the row at 360 deg equals the row at 0 deg;
 * - failures: a non-Grashof four-bar driven as a crank cannot assemble, a
 *   slider-crank driven through its dead centre is singular;
 * - positions only: no velocity or acceleration columns;
 * - mechanisms/fourbar.yaml and mechanisms/slider-crank.yaml against the
 *   closed forms.
 * All table values are SI (m, rad, s); angles are continuous over a sweep. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mech.h"

#define PI 3.14159265358979323846
#define TWO_PI (2.0 * PI)
#define DEG (PI / 180.0)

/* ---- closed forms (tests/unit/closed_forms.h) ------------------------- */

#include "closed_forms.h"
#include "helpers.h"

/* ---- helpers ----------------------------------------------------------- */





static char *format(const char *fmt, ...)
{
    static char buf[4096];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    cr_assert(n > 0 && n < (int)sizeof buf);
    return buf;
}

/* Compare every row of t with the closed form f: each column listed in
 * names within tol relative to max(|expected|, the largest |expected| of
 * any listed column of the same kind over the sweep; for angles, the
 * largest |expected| in (-pi, pi]). Angles are compared
 * after unwrapping the closed form along the sweep and aligning its first
 * value to the solver's by a multiple of 2 pi, so a solver angle that jumps
 * by 2 pi (is not continuous) fails. Checks the q column against the
 * expected driver positions q_expected (when not NULL) first. With
 * only_present, names absent from the table are skipped (the caller checks
 * which columns there are). */
static void check_sweep(const mech_table *t, const char *const *names, int ncol, ref_fn f,
                        const void *geom, double w, double al, const double *q_expected,
                        double tol, int only_present)
{
    int nrows = t->nrows, qc = table_col(t, "q");
    int *col = malloc((size_t)ncol * sizeof *col);
    double *ref = malloc((size_t)nrows * (size_t)ncol * sizeof *ref);
    double *tmp = malloc((size_t)ncol * sizeof *tmp);
    double kind_max[6] = {0};
    for (int j = 0; j < ncol; j++)
        col[j] = only_present ? mech_table_column(t, names[j]) : table_col(t, names[j]);
    for (int i = 0; i < nrows; i++) {
        double q = mech_table_get(t, i, qc);
        if (q_expected)
            cr_assert(fabs(q - q_expected[i]) <= 1e-12 * fmax(1.0, fabs(q_expected[i])),
                      "row %d: q = %.17g, expected %.17g", i, q, q_expected[i]);
        f(geom, q, w, al, tmp);
        for (int j = 0; j < ncol; j++) {
            double *r = &ref[(size_t)i * (size_t)ncol + (size_t)j];
            *r = tmp[j];
            int k = column_kind(names[j]);
            if (k == 3 && col[j] >= 0) {  /* unwrap the closed form along the sweep */
                if (i > 0)
                    *r = r[-ncol] + remainder(*r - r[-ncol], TWO_PI);
                else
                    *r += TWO_PI * round((mech_table_get(t, 0, col[j]) - *r) / TWO_PI);
            }
            kind_max[k] = fmax(kind_max[k], fabs(k == 3 ? tmp[j] : *r));
        }
    }
    for (int i = 0; i < nrows; i++)
        for (int j = 0; j < ncol; j++) {
            if (col[j] < 0)
                continue;
            double want = ref[(size_t)i * (size_t)ncol + (size_t)j];
            double got = mech_table_get(t, i, col[j]);
            int k = column_kind(names[j]);
            double scale = k == 3 ? kind_max[k] : fmax(fabs(want), kind_max[k]);
            cr_assert(fabs(got - want) <= tol * scale,
                      "row %d (q = %.6f deg): %s = %.17g, closed form %.17g (error %.3g, "
                      "allowed %.3g)",
                      i, mech_table_get(t, i, qc) / DEG, names[j], got, want, fabs(got - want),
                      tol * scale);
        }
    free(col);
    free(ref);
    free(tmp);
}

/* The positions i * (to - from) / steps + from of a range, in rad. */
static double *range_deg(double from, double to, int steps)
{
    double *q = malloc((size_t)(steps + 1) * sizeof *q);
    for (int i = 0; i <= steps; i++)
        q[i] = (from + (to - from) * i / steps) * DEG;
    return q;
}

/* A four-bar file in SI units, angles in degrees where written with deg;
 * the initial guesses are the closed form at the first position, 3 deg off. */
static mech_model *fourbar_model(const fourbar *g, double from, double to, int steps,
                                 double speed, double accel)
{
    double v[NFOURBAR];
    fourbar_ref(g, from * DEG, speed, accel, v);
    const char *text = format(
        "name: test four-bar\n"
        "ground: {O: [0, 0], C: [%.15g, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [%.15g, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [%.15g, 0], P: [%.15g, %.15g]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [%.15g, 0]}}\n"
        "driver:\n"
        "  link: crank\n"
        "  angle: {from: %.15g deg, to: %.15g deg, steps: %d}\n"
        "  speed: %.15g rad/s\n"
        "  acceleration: %.15g rad/s^2\n"
        "initial: {coupler: %.6f deg, rocker: %.6f deg}\n"
        "branch:\n"
        "  - {points: [A, B, C], turn: %s}\n"
        "outputs:\n"
        "  points: [A, B, P]\n"
        "  links: [crank, coupler, rocker]\n",
        g->d, g->a, g->b, g->px, g->py, g->c, from, to, steps, speed, accel,
        v[21] / DEG + 3, v[24] / DEG - 3, /* coupler.angle, rocker.angle */
        g->sign > 0 ? "cw" : "ccw");
    return load_text(text);
}

static mech_model *slider_model(const slidercrank *g, double from, double to, int steps,
                                double speed, double accel)
{
    double v[NSLIDER];
    slider_ref(g, from * DEG, speed, accel, v);
    const char *text = format(
        "name: test offset slider-crank\n"
        "ground: {O: [0, 0], G: [0, %.15g]}\n"
        "links:\n"
        "  crank:  {points: {O: [0, 0], A: [%.15g, 0]}}\n"
        "  rod:    {points: {A: [0, 0], B: [%.15g, 0]}}\n"
        "  piston: {points: {B: [0, 0]}}\n"
        "joints:\n"
        "  - {slider: B, link: piston, on: ground, through: G, angle: 0 deg, name: x_B}\n"
        "driver:\n"
        "  link: crank\n"
        "  angle: {from: %.15g deg, to: %.15g deg, steps: %d}\n"
        "  speed: %.15g rad/s\n"
        "  acceleration: %.15g rad/s^2\n"
        "initial: {rod: %.6f deg, x_B: %.15g}\n"
        "outputs:\n"
        "  points: [A, B]\n"
        "  links: [crank, rod]\n"
        "  sliders: [x_B]\n",
        g->e, g->r, g->l, from, to, steps, speed, accel,
        v[15] / DEG + 2, v[18] * 1.01); /* rod.angle, x_B.s */
    return load_text(text);
}

/* Geometries. Crank-rocker: crank shortest, 0.03 + 0.09 < 0.08 + 0.06;
 * |CA| stays in [0.06, 0.12], inside (|b - c|, b + c) = (0.02, 0.14), so B
 * never crosses the line AC and the branch is one closed-form sign all
 * round. Double-crank (drag link): ground shortest, 0.02 + 0.07 < 0.06 +
 * 0.05, |CA| in [0.04, 0.08] inside (0.02, 0.12). Slider-crank: the rod
 * reaches the line for every crank angle, r + |e| = 0.07 < l = 0.18. */
static const fourbar CRANK_ROCKER = {.a = 0.03, .b = 0.08, .c = 0.06, .d = 0.09,
                                     .px = 0.05, .py = 0.02, .sign = +1};
static const fourbar DOUBLE_CRANK = {.a = 0.06, .b = 0.07, .c = 0.05, .d = 0.02,
                                     .px = 0.03, .py = -0.025, .sign = -1};
static const slidercrank OFFSET_SLIDER = {.r = 0.05, .l = 0.18, .e = 0.02};

/* ---- the closed forms themselves --------------------------------------- */

/* How many columns after a column its time derivative is (x -> vx, angle ->
 * omega, s -> v, ...), or 0 for an acceleration. */
static int rate_offset(const char *name)
{
    static const char *const two[] = {".x", ".y", ".vx", ".vy"};
    static const char *const one[] = {".s", ".v", ".angle", ".omega"};
    for (int i = 0; i < 4; i++) {
        if (ends_with(name, two[i]))
            return 2;
        if (ends_with(name, one[i]))
            return 1;
    }
    return 0;
}

/* The references close their loops, and their velocities and accelerations
 * are the time derivatives of their positions and velocities along q(t) =
 * q + w t + al t^2 / 2 (central differences, h = 1e-5 s: truncation about
 * h^2 |f'''| / 6 ~ 1e-9 and rounding ~ 1e-16 |f| / h ~ 1e-11 for these
 * sizes, all values of order 0.01 to 10), so a slip in them cannot pass. */
Test(solve, closed_forms_are_consistent)
{
    const double w = 1.7, al = -0.6, h = 1e-5;
    for (int k = 0; k < 3; k++) {
        const fourbar *g = k == 0 ? &CRANK_ROCKER : k == 1 ? &DOUBLE_CRANK : NULL;
        int n = g ? NFOURBAR : NSLIDER;
        const char *const *names = g ? FOURBAR_COLS : SLIDER_COLS;
        const void *geom = g ? (const void *)g : (const void *)&OFFSET_SLIDER;
        ref_fn f = g ? fourbar_ref : slider_ref;
        for (double q = 0.1; q < TWO_PI; q += 0.37) {
            double v[NFOURBAR], vp[NFOURBAR], vm[NFOURBAR];
            f(geom, q, w, al, v);
            if (g) { /* |AB| = b, |CB| = c */
                cr_assert(fabs(hypot(v[6] - v[0], v[7] - v[1]) - g->b) <= 1e-15);
                cr_assert(fabs(hypot(v[6] - g->d, v[7]) - g->c) <= 1e-15);
                /* the branch: B left (+1) or right (-1) of A -> C */
                double cross = (g->d - v[0]) * (v[7] - v[1]) - (-v[1]) * (v[6] - v[0]);
                cr_assert(cross * g->sign > 0);
            } else {
                cr_assert(fabs(hypot(v[6] - v[0], v[7] - v[1]) - OFFSET_SLIDER.l) <= 1e-15);
                cr_assert(v[6] > v[0]);
            }
            f(geom, q + w * h + al * h * h / 2, w + al * h, al, vp);
            f(geom, q - w * h + al * h * h / 2, w - al * h, al, vm);
            for (int j = 0; j < n; j++) {
                int off = rate_offset(names[j]);
                if (!off)
                    continue;
                double diff = vp[j] - vm[j];
                if (column_kind(names[j]) == 3)
                    diff = remainder(diff, TWO_PI);
                double got = diff / (2 * h), want = v[j + off];
                cr_assert(fabs(got - want) <= 1e-8 * fmax(1.0, fabs(want)),
                          "closed form %d at q = %g: d(%s)/dt = %.12g by differences, %s = "
                          "%.12g",
                          k, q, names[j], got, names[j + off], want);
            }
        }
    }
}

/* ---- full revolutions against the closed forms -------------------------- */

/* (a) Crank-rocker, 360 steps of 1 deg, 7 rad/s and -3 rad/s^2: every
 * position, velocity and acceleration within 1e-10 relative. */
Test(solve, crank_rocker_full_revolution)
{
    mech_model *m = fourbar_model(&CRANK_ROCKER, 0, 360, 360, 7, -3);
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 361);
    double *q = range_deg(0, 360, 360);
    check_sweep(&t, FOURBAR_COLS, NFOURBAR, fourbar_ref, &CRANK_ROCKER, 7, -3, q, 1e-10, 0);
    free(q);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* (b) Double-crank (drag link, the ground shortest), the other assembly
 * branch, swept backwards from 0 to -360 deg (the speed and acceleration
 * are still the rates at every position). */
Test(solve, double_crank_full_revolution)
{
    mech_model *m = fourbar_model(&DOUBLE_CRANK, 0, -360, 360, 2, 0.5);
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 361);
    double *q = range_deg(0, -360, 360);
    check_sweep(&t, FOURBAR_COLS, NFOURBAR, fourbar_ref, &DOUBLE_CRANK, 2, 0.5, q, 1e-10, 0);
    free(q);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* (c) Offset slider-crank: the piston's line 20 mm above the crank pivot. */
Test(solve, offset_slider_crank_full_revolution)
{
    mech_model *m = slider_model(&OFFSET_SLIDER, 30, 390, 360, 5, 2);
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 361);
    double *q = range_deg(30, 390, 360);
    check_sweep(&t, SLIDER_COLS, NSLIDER, slider_ref, &OFFSET_SLIDER, 5, 2, q, 1e-10, 0);
    free(q);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- rates against finite differences of the solver's own output ------- */

/* For each (position, velocity, acceleration) column triple: the velocity
 * is w dx/dq and the acceleration w dv/dq + al v / w (v = x'(q) w at every
 * position, a = x''(q) w^2 + x'(q) al), with the fourth-order central
 * difference f'(q) ~ (f[i-2] - 8 f[i-1] + 8 f[i+1] - f[i+2]) / (12 h) over
 * the sweep's rows. With h = 0.1 deg = 1.75e-3 rad the truncation is
 * h^4 |f^(5)| / 30 ~ 3e-13 |f^(5)|, below 1e-10 of the scale for these
 * linkages, and a position error e (the Newton tolerance, 1e-12 of the
 * largest length) grows to 18 e / (12 h) ~ 1e-9 of the length: tol = 1e-8
 * relative to the column kind's largest value is 100 times that and still
 * catches any wrong term of a rate. */
static void check_differences(const mech_table *t, const char *const (*cols)[3], int n,
                              double w, double al, double tol)
{
    int qc = table_col(t, "q"), nrows = t->nrows;
    cr_assert_geq(nrows, 5);
    double h = (mech_table_get(t, nrows - 1, qc) - mech_table_get(t, 0, qc)) / (nrows - 1);
    double vmax[2] = {0}, amax[2] = {0};  /* [0] linear, [1] angular */
    for (int k = 0; k < n; k++) {
        int ang = column_kind(cols[k][0]) == 3, vc = table_col(t, cols[k][1]),
            ac = table_col(t, cols[k][2]);
        for (int i = 0; i < nrows; i++) {
            vmax[ang] = fmax(vmax[ang], fabs(mech_table_get(t, i, vc)));
            amax[ang] = fmax(amax[ang], fabs(mech_table_get(t, i, ac)));
        }
    }
    for (int k = 0; k < n; k++) {
        int ang = column_kind(cols[k][0]) == 3;
        int c[3] = {table_col(t, cols[k][0]), table_col(t, cols[k][1]), table_col(t, cols[k][2])};
        for (int i = 2; i < nrows - 2; i++) {
            double d[2];
            for (int j = 0; j < 2; j++)
                d[j] = (mech_table_get(t, i - 2, c[j]) - 8 * mech_table_get(t, i - 1, c[j]) +
                        8 * mech_table_get(t, i + 1, c[j]) - mech_table_get(t, i + 2, c[j])) /
                       (12 * h);
            double v = mech_table_get(t, i, c[1]), a = mech_table_get(t, i, c[2]);
            double v_fd = w * d[0], a_fd = w * d[1] + al * v / w;
            cr_assert(fabs(v - v_fd) <= tol * vmax[ang],
                      "row %d (q = %.3f deg): %s = %.15g, differences of %s give %.15g", i,
                      mech_table_get(t, i, qc) / DEG, cols[k][1], v, cols[k][0], v_fd);
            cr_assert(fabs(a - a_fd) <= tol * amax[ang],
                      "row %d (q = %.3f deg): %s = %.15g, differences of %s give %.15g", i,
                      mech_table_get(t, i, qc) / DEG, cols[k][2], a, cols[k][1], a_fd);
        }
    }
}

Test(solve, fourbar_rates_match_differences)
{
    static const char *const cols[][3] = {
        {"A.x", "A.vx", "A.ax"}, {"A.y", "A.vy", "A.ay"},
        {"B.x", "B.vx", "B.ax"}, {"B.y", "B.vy", "B.ay"},
        {"P.x", "P.vx", "P.ax"}, {"P.y", "P.vy", "P.ay"},
        {"coupler.angle", "coupler.omega", "coupler.alpha"},
        {"rocker.angle", "rocker.omega", "rocker.alpha"}};
    mech_model *m = fourbar_model(&CRANK_ROCKER, 0, 360, 3600, 7, -3);
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 3601);
    check_differences(&t, cols, (int)(sizeof cols / sizeof *cols), 7, -3, 1e-8);
    mech_table_free(&t);
    mech_model_free(&m);
}

Test(solve, slider_crank_rates_match_differences)
{
    static const char *const cols[][3] = {
        {"B.x", "B.vx", "B.ax"}, {"B.y", "B.vy", "B.ay"},
        {"rod.angle", "rod.omega", "rod.alpha"}, {"x_B.s", "x_B.v", "x_B.a"}};
    mech_model *m = slider_model(&OFFSET_SLIDER, 0, 360, 3600, 5, 2);
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 3601);
    check_differences(&t, cols, (int)(sizeof cols / sizeof *cols), 5, 2, 1e-8);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- periodicity -------------------------------------------------------- */

/* The row at 360 deg equals the row at 0 deg to 1e-12 of each column kind's
 * largest value; angles differ by whole turns: the crank by one, the
 * crank-rocker's coupler and rocker by none (they swing back), the drag
 * link's coupler and rocker by one (they turn round with the crank). */
static void check_period(const fourbar *g, int turns_coupler_rocker)
{
    mech_model *m = fourbar_model(g, 0, 360, 360, 3, 1.5);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.tol = 1e-14;
    mech_table t = must_solve(m, &o);
    cr_assert_eq(t.nrows, 361);
    double kind_max[6] = {0};
    for (int j = 0; j < NFOURBAR; j++) {
        int c = table_col(&t, FOURBAR_COLS[j]), k = column_kind(FOURBAR_COLS[j]);
        for (int i = 0; i < t.nrows; i++)
            kind_max[k] = fmax(kind_max[k], fabs(mech_table_get(&t, i, c)));
    }
    for (int j = 0; j < NFOURBAR; j++) {
        const char *name = FOURBAR_COLS[j];
        int c = table_col(&t, name), k = column_kind(name);
        double first = mech_table_get(&t, 0, c), last = mech_table_get(&t, 360, c);
        double turns = k != 3 ? 0 : strcmp(name, "crank.angle") == 0 ? 1 : turns_coupler_rocker;
        cr_assert(fabs(last - first - TWO_PI * turns) <= 1e-12 * kind_max[k],
                  "%s at 0 deg %.17g, at 360 deg %.17g (expected %g turns apart)", name, first,
                  last, turns);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

Test(solve, full_revolution_returns_to_start)
{
    check_period(&CRANK_ROCKER, 0);
    check_period(&DOUBLE_CRANK, 1);
}

/* ---- documented failures ------------------------------------------------ */

static const char *first_message(const mech_diag *d)
{
    return d->count && d->entries[0].message ? d->entries[0].message : "(no message)";
}

static int any_message_has(const mech_diag *d, const char *text)
{
    for (size_t i = 0; i < d->count; i++)
        if (d->entries[i].message && strstr(d->entries[i].message, text))
            return 1;
    return 0;
}

/* (f) Non-Grashof (s + l = 0.04 + 0.06 > p + q = 0.05 + 0.045): the crank
 * assembles only while |CA| <= b + c, cos q >= (a^2 + d^2 - (b + c)^2) /
 * (2 a d) = -0.1875, |q| <= 100.807 deg; a 0..360 deg sweep in 1 deg steps
 * solves 0..100 deg (101 rows) and fails at 101 deg. */
Test(solve, non_grashof_crank_cannot_assemble)
{
    mech_model *m = load_text(
        "name: non-Grashof four-bar\n"
        "ground: {O: [0, 0], C: [0.06, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [0.05, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [0.04, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [0.045, 0]}}\n"
        "driver: {link: crank, angle: {from: 0 deg, to: 360 deg, steps: 360}}\n"
        "initial: {coupler: 114 deg, rocker: 126 deg}\n");
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    int rc = mech_solve(m, &o, &t, NULL, &d);
    cr_assert_eq(rc, MECH_ESOLVE, "mech_solve returned %d: %s", rc, first_message(&d));
    cr_assert_lt(t.nrows, 361);
    /* 0..100 and 260..360 deg: every row where it assembles (issue 17) */
    cr_assert_eq(t.nrows, 202, "%d rows solved, expected 202 (0..100, 260..360 deg): %s",
                 t.nrows, first_message(&d));
    cr_assert_eq(t.ngaps, 1);
    cr_assert_eq(t.gaps[0].first_row, 101);
    cr_assert_eq(t.gaps[0].last_row, 259);
    cr_assert(any_message_has(&d, "cannot assemble"), "no 'cannot assemble' message: %s",
              first_message(&d));
    cr_assert(any_message_has(&d, "deg"), "the driver position is not given in degrees: %s",
              first_message(&d));
    cr_assert(any_message_has(&d, "100"), "the range where it assembles (to 100.8 deg) is not "
                                          "given: %s", first_message(&d));
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* (g) In-line slider-crank r = 0.25 m, l = 0.75 m driven by its piston:
 * x_B = r + l = 1 m exactly (all values are binary fractions) is the dead
 * centre, crank and rod in line, where the loop's Jacobian is singular. */
Test(solve, slider_through_dead_centre_is_singular)
{
    mech_model *m = load_text(
        "name: slider-crank driven through its dead centre\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  crank:  {points: {O: [0, 0], A: [0.25, 0]}}\n"
        "  rod:    {points: {A: [0, 0], B: [0.75, 0]}}\n"
        "  piston: {points: {B: [0, 0]}}\n"
        "joints:\n"
        "  - {slider: B, link: piston, on: ground, through: O, angle: 0 deg, name: x_B}\n"
        "driver: {slider: x_B, displacement: [0.75, 0.875, 1, 0.875, 0.75], speed: 1 m/s}\n"
        "initial: {crank: 75 deg, rod: -19 deg}\n");
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    int rc = mech_solve(m, &o, &t, NULL, &d);
    cr_assert_eq(rc, MECH_ESOLVE, "mech_solve returned %d: %s", rc, first_message(&d));
    cr_assert_lt(t.nrows, 5);
    /* every row but the dead centre (issue 17: partial sweeps) */
    cr_assert_eq(t.nrows, 4, "%d rows solved, expected 4: %s", t.nrows, first_message(&d));
    cr_assert_eq(t.ngaps, 1);
    cr_assert_eq(t.gaps[0].first_row, 2);
    cr_assert_eq(t.gaps[0].last_row, 2);
    cr_assert_eq(t.gaps[0].kind, MECH_GAP_DEAD_POINT);
    cr_assert(any_message_has(&d, "singular"), "no 'singular' message: %s", first_message(&d));
    /* the rows solved are right: crank angle by the law of cosines */
    int qc = table_col(&t, "q"), cc = table_col(&t, "crank.angle");
    for (int i = 0; i < t.nrows; i++) {
        double x = mech_table_get(&t, i, qc);
        double want = acos((0.25 * 0.25 + x * x - 0.75 * 0.75) / (2 * 0.25 * x));
        cr_assert(fabs(remainder(mech_table_get(&t, i, cc) - want, TWO_PI)) <= 1e-10,
                  "x_B = %g: crank at %.15g rad, expected %.15g", x,
                  mech_table_get(&t, i, cc), want);
    }
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* ---- what is computed --------------------------------------------------- */

/* (h) Positions only: q and the position columns, nothing else; positions
 * and velocities: no accelerations. */
Test(solve, positions_only_have_no_rate_columns)
{
    static const char *const pos[] = {"A.x", "A.y", "B.x", "B.y", "crank.angle", "rod.angle",
                                      "x_B.s"};
    mech_model *m = slider_model(&OFFSET_SLIDER, 0, 360, 36, 5, 2);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.want = MECH_WANT_POSITION;
    mech_table t = must_solve(m, &o);
    cr_assert_eq(t.nrows, 37);
    cr_assert_eq(t.ncolumns, 8, "q and 7 positions expected, got %d columns", t.ncolumns);
    for (int j = 0; j < t.ncolumns; j++) {
        const char *name = t.columns[j].name;
        cr_assert(strcmp(name, "q") == 0 || column_kind(name) == 0 || column_kind(name) == 3,
                  "column '%s' in a positions-only table", name);
    }
    for (int j = 0; j < 7; j++)
        table_col(&t, pos[j]);
    check_sweep(&t, SLIDER_COLS, NSLIDER, slider_ref, &OFFSET_SLIDER, 5, 2, NULL, 1e-10, 1);
    mech_table_free(&t);

    o.want = MECH_WANT_POSITION | MECH_WANT_VELOCITY;
    t = must_solve(m, &o);
    cr_assert_eq(t.ncolumns, 15, "q, 7 positions and 7 velocities expected, got %d columns",
                 t.ncolumns);
    for (int j = 0; j < t.ncolumns; j++)
        cr_assert(strcmp(t.columns[j].name, "q") == 0 || rate_offset(t.columns[j].name) != 0,
                  "column '%s' in a table without accelerations", t.columns[j].name);
    check_sweep(&t, SLIDER_COLS, NSLIDER, slider_ref, &OFFSET_SLIDER, 5, 2, NULL, 1e-10, 1);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* ---- the example files -------------------------------------------------- */

/* (i) mechanisms/fourbar.yaml: 20, 60, 50, 70 mm, P 40 mm at 30 deg on the
 * coupler, B above AC, 10 rad/s, 0..360 deg in 360 steps. */
Test(solve, file_fourbar_matches_closed_form)
{
    const fourbar g = {.a = 0.020, .b = 0.060, .c = 0.050, .d = 0.070,
                       .px = 0.040 * cos(30 * DEG), .py = 0.040 * sin(30 * DEG), .sign = +1};
    mech_model *m = load_path("mechanisms/fourbar.yaml");
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 361);
    double *q = range_deg(0, 360, 360);
    check_sweep(&t, FOURBAR_COLS, NFOURBAR, fourbar_ref, &g, 10, 0, q, 1e-10, 0);
    free(q);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* mechanisms/slider-crank.yaml: in line (e = 0), r = 40 mm, l = 140 mm,
 * 3000 rpm = 100 pi rad/s, 0..360 deg in 72 steps. */
Test(solve, file_slider_crank_matches_closed_form)
{
    const slidercrank g = {.r = 0.040, .l = 0.140, .e = 0};
    mech_model *m = load_path("mechanisms/slider-crank.yaml");
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 73);
    double *q = range_deg(0, 360, 72);
    check_sweep(&t, SLIDER_COLS, NSLIDER, slider_ref, &g, 100 * PI, 0, q, 1e-10, 0);
    free(q);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* The smallest rcond --stats reports is the exact value's, not a bound's
 * (docs/solver.md, "Bounds first"): with tol 1e-10 the bounds serve on
 * every row of the conveyor and the Stirling engine, and the stats must be
 * those of MECH_RCOND=exact, the condition computed exactly at every row,
 * to the bit (tests/rcond.sh compares the tables and statuses). */
static mech_solve_stats stats_of(const char *path, const char *rcond_env)
{
    if (rcond_env)
        setenv("MECH_RCOND", rcond_env, 1);
    else
        unsetenv("MECH_RCOND");
    mech_model *m = load_path(path);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.tol = 1e-10;
    mech_table t = {0};
    mech_solve_stats st;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_solve(m, &o, &t, &st, &d), MECH_OK, "%s", path);
    mech_diag_free(&d);
    mech_table_free(&t);
    mech_model_free(&m);
    unsetenv("MECH_RCOND");
    return st;
}

Test(solve, stats_report_the_exact_smallest_rcond)
{
    const char *files[] = {"mechanisms/conveyor.yaml", "mechanisms/stirling.yaml",
                           "mechanisms/jansen.yaml"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        mech_solve_stats b = stats_of(files[i], NULL), e = stats_of(files[i], "exact");
        cr_expect(b.min_rcond == e.min_rcond && b.worst_rcond_q == e.worst_rcond_q,
                  "%s: smallest rcond %.17g at %.17g, exactly %.17g at %.17g", files[i],
                  b.min_rcond, b.worst_rcond_q, e.min_rcond, e.worst_rcond_q);
        cr_expect(b.worst_residual == e.worst_residual && b.iterations == e.iterations,
                  "%s: residual %g, %ld iterations; exactly %g, %ld", files[i],
                  b.worst_residual, b.iterations, e.worst_residual, e.iterations);
    }
}
