/* tests/unit/test_sensitivity.c: mech_sensitivity against independent
 * truths. (1) Central finite differences of whole sweeps with the parameter
 * replaced (as `mech solve --set` does: mech_load_file_with), for every
 * position, velocity and acceleration column of a four-bar, the offset
 * slider-crank and the conveyor; relative steps 1e-5 and 5e-6 combined by
 * Richardson extrapolation (the conveyor's sensitivity to xF has a third
 * derivative large enough that a plain central difference is off by 5e-6
 * of the column's scale at h = 1e-5, shrinking as h^2: measured), Newton
 * tolerance 1e-15: measured, |exact - FD| is at most 1.7e-8 of the
 * column's scale (median 7e-11; MECH_HARD_VERBOSE=1 prints each), well
 * inside the 1e-6 asked. (2)
 * Closed-form derivatives of the positions: the slider-crank's
 * x = r cos q + sqrt(l^2 - (e - r sin q)^2) differentiated by hand, and the
 * four-bar's circle intersection differentiated by complex step (exact to
 * rounding): 1e-10 relative. */
#include <complex.h>
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "helpers.h"
#include "base.h"

static const char fourbar_yaml[] =
    "name: four-bar with parameters\n"
    "units: {length: mm, angle: deg}\n"
    "parameters: {a: 20 mm, b: 60 mm, c: 50 mm, d: 70 mm}\n"
    "ground: {O: [0, 0], C: [d, 0]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [a, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [b, 0], P: [b/2, 10 mm]}}\n"
    "  rocker: {points: {C: [0, 0], B: [c, 0]}}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 72}, speed: 10 rad/s, "
    "acceleration: 3 rad/s^2}\n"
    "initial: {coupler: 80, rocker: 100}\n"
    "outputs: {points: [A, B, P], links: [coupler, rocker]}\n";

/* Written whole under another name and renamed: two tests of this file in
 * parallel jobs (--jobs 2) write it while the other reads it. */
static const char *fourbar_path(void)
{
    static const char path[] = "build/test_sensitivity_fourbar.yaml";
    char tmp[64];
    snprintf(tmp, sizeof tmp, "%s.%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    cr_assert_not_null(f);
    fputs(fourbar_yaml, f);
    cr_assert_eq(fclose(f), 0);
    cr_assert_eq(rename(tmp, path), 0);
    return path;
}

/* The sweep of `path` with parameter `name` set to `value` (NULL: as in
 * the file), with the sensitivity columns of `sens` when not NULL. */
static mech_table solve(const char *path, const char *name, double value, const char *unit,
                        const char *sens)
{
    mech_model *m = load_with_value(path, name, value, unit);
    mech_diag d;
    mech_diag_init(&d);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.tol = 1e-15;
    mech_table t = {0};
    int rc = mech_solve(m, &o, &t, NULL, &d);
    cr_assert_eq(rc, MECH_OK, "%s does not solve", path);
    if (sens) {  /* the model holds its replacement: no overrides to pass again */
        rc = mech_sensitivity(m, NULL, 0, &o, &sens, 1, &t, &d);
        if (rc != MECH_OK)
            mech_diag_print(&d, stderr);
        cr_assert_eq(rc, MECH_OK, "mech_sensitivity failed");
    }
    mech_diag_free(&d);
    mech_model_free(&m);
    return t;
}

static const mech_param *param_of(const char *path, const char *name, mech_model **m)
{
    *m = load_path(path);
    for (int i = 0; i < (*m)->nparams; i++)
        if (strcmp((*m)->params[i].name, name) == 0)
            return &(*m)->params[i];
    cr_assert_fail("no parameter %s in %s", name, path);
    return NULL;
}

/* A position, velocity or acceleration column (not a force). */
static int kinematic(const char *name)
{
    static const char *const sfx[] = {"x", "y", "vx", "vy", "ax", "ay", "angle", "omega",
                                      "alpha", "s", "v", "a"};
    const char *dot = strrchr(name, '.');
    for (size_t i = 0; dot && i < sizeof sfx / sizeof *sfx; i++)
        if (strcmp(dot + 1, sfx[i]) == 0)
            return 1;
    return 0;
}

/* Every kinematic column's d()/d(name) against central differences. */
static void check_fd(const char *path, const char *name)
{
    mech_model *m;
    const mech_param *p = param_of(path, name, &m);
    double v = p->value, h = 1e-5 * fabs(v);
    mech_table s = solve(path, NULL, 0, "", name);
    mech_table hi = solve(path, name, v + h, p->unit, NULL);
    mech_table lo = solve(path, name, v - h, p->unit, NULL);
    mech_table hi2 = solve(path, name, v + h / 2, p->unit, NULL);
    mech_table lo2 = solve(path, name, v - h / 2, p->unit, NULL);
    cr_assert(hi.nrows == s.nrows && lo.nrows == s.nrows && hi2.nrows == s.nrows &&
              lo2.nrows == s.nrows);
    int checked = 0;
    for (int c = 1; c < hi.ncolumns; c++) {
        char dname[256];
        snprintf(dname, sizeof dname, "d(%s)/d(%s)", hi.columns[c].name, name);
        int sc = mech_table_column(&s, dname);
        if (!kinematic(hi.columns[c].name)) {  /* forces: no sensitivity column */
            cr_expect_lt(sc, 0, "%s: a column %s", path, dname);
            continue;
        }
        cr_assert_geq(sc, 0, "%s: no column %s", path, dname);
        double scale = 0, worst = 0;
        for (int r = 0; r < s.nrows; r++)
            scale = fmax(scale, fabs(mech_table_get(&hi, r, c) - mech_table_get(&lo, r, c)) / (2 * h));
        for (int r = 0; r < s.nrows; r++) {
            /* Richardson: (4 D(h/2) - D(h)) / 3 cancels the h^2 term of the difference */
            double fd1 = (mech_table_get(&hi, r, c) - mech_table_get(&lo, r, c)) / (2 * h);
            double fd2 = (mech_table_get(&hi2, r, c) - mech_table_get(&lo2, r, c)) / h;
            double fd = (4 * fd2 - fd1) / 3;
            worst = fmax(worst, fabs(mech_table_get(&s, r, sc) - fd));
        }
        /* columns that do not depend on the parameter: FD and exact both ~0 */
        double tol = 1e-6 * fmax(scale, 1e-6 * fabs(mech_table_get(&s, 0, c) + 1));
        cr_expect_leq(worst, tol, "%s %s: worst |exact - FD| %.3g, column scale %.3g", path,
                      dname, worst, scale);
        if (getenv("MECH_HARD_VERBOSE") && scale > 0)
            fprintf(stderr, "[sensitivity] %s %s: |exact - FD| / scale %.2g\n", path, dname,
                    worst / scale);
        checked++;
    }
    cr_expect_geq(checked, 9, "%s: only %d columns", path, checked);
    mech_table_free(&s);
    mech_table_free(&hi);
    mech_table_free(&lo);
    mech_table_free(&hi2);
    mech_table_free(&lo2);
    mech_model_free(&m);
}

Test(sensitivity, fourbar_matches_central_differences)
{
    const char *path = fourbar_path();
    check_fd(path, "a");
    check_fd(path, "b");
    check_fd(path, "d");
}

Test(sensitivity, slider_crank_matches_central_differences)
{
    check_fd("mechanisms/offset-slider-crank.yaml", "r");
    check_fd("mechanisms/offset-slider-crank.yaml", "l");
    check_fd("mechanisms/offset-slider-crank.yaml", "e");
}

Test(sensitivity, conveyor_matches_central_differences)
{
    check_fd("mechanisms/conveyor.yaml", "l1");
    check_fd("mechanisms/conveyor.yaml", "l3a");
    check_fd("mechanisms/conveyor.yaml", "xF");
}

/* x_B = r cos q + w, w = sqrt(l^2 - u^2), u = e - r sin q:
 * dx/dr = cos q + u sin q / w, dx/dl = l / w, dx/de = -u / w. */
Test(sensitivity, slider_crank_positions_match_closed_form_derivatives)
{
    const char *path = "mechanisms/offset-slider-crank.yaml";
    const double r = 0.04, l = 0.12, e = 0.03;
    const char *names[] = {"r", "l", "e"};
    for (int k = 0; k < 3; k++) {
        mech_table t = solve(path, NULL, 0, "", names[k]);
        char col[64];
        snprintf(col, sizeof col, "d(x_B.s)/d(%s)", names[k]);
        int c = mech_table_column(&t, col), qc = mech_table_column(&t, "q");
        cr_assert_geq(c, 0);
        for (int row = 0; row < t.nrows; row++) {
            double q = mech_table_get(&t, row, qc), u = e - r * sin(q), w = sqrt(l * l - u * u);
            double want = k == 0 ? cos(q) + u * sin(q) / w : k == 1 ? l / w : -u / w;
            cr_expect(fabs(mech_table_get(&t, row, c) - want) <= 1e-10 * fmax(1.0, fabs(want)),
                      "%s at q %g: %.17g, closed form %.17g", col, q, mech_table_get(&t, row, c),
                      want);
        }
        mech_table_free(&t);
    }
}

/* B of the four-bar by circle intersection, in complex arithmetic. */
static void fourbar_b(double complex a, double complex b, double complex c, double complex d,
                      double q, double complex *bx, double complex *by)
{
    double complex ax = a * cos(q), ay = a * sin(q), dx = d - ax, dy = -ay;
    double complex len = csqrt(dx * dx + dy * dy), ux = dx / len, uy = dy / len;
    double complex p = (b * b - c * c + len * len) / (2 * len), h = csqrt(b * b - p * p);
    /* the branch of the file's initial guess: B left of A -> C */
    *bx = ax + p * ux - h * uy;
    *by = ay + p * uy + h * ux;
}

Test(sensitivity, fourbar_positions_match_complex_step_of_the_closed_form)
{
    const char *path = fourbar_path();
    const char *names[] = {"a", "b", "c", "d"};
    const double g[4] = {0.02, 0.06, 0.05, 0.07}, step = 1e-30;
    for (int k = 0; k < 4; k++) {
        mech_table t = solve(path, NULL, 0, "", names[k]);
        char cx[64], cy[64];
        snprintf(cx, sizeof cx, "d(B.x)/d(%s)", names[k]);
        snprintf(cy, sizeof cy, "d(B.y)/d(%s)", names[k]);
        int ix = mech_table_column(&t, cx), iy = mech_table_column(&t, cy);
        int qc = mech_table_column(&t, "q"), by0 = mech_table_column(&t, "B.y");
        cr_assert(ix >= 0 && iy >= 0);
        for (int row = 0; row < t.nrows; row++) {
            double complex v[4];
            for (int i = 0; i < 4; i++)
                v[i] = g[i] + (i == k ? step * I : 0);
            double complex bx, by;
            fourbar_b(v[0], v[1], v[2], v[3], mech_table_get(&t, row, qc), &bx, &by);
            cr_assert(fabs(creal(by) - mech_table_get(&t, row, by0)) < 1e-12, "branch");
            double wx = cimag(bx) / step, wy = cimag(by) / step;
            cr_expect(fabs(mech_table_get(&t, row, ix) - wx) <= 1e-10 * fmax(1, fabs(wx)) &&
                          fabs(mech_table_get(&t, row, iy) - wy) <= 1e-10 * fmax(1, fabs(wy)),
                      "%s, %s at row %d: %.17g %.17g, closed form %.17g %.17g", cx, cy, row,
                      mech_table_get(&t, row, ix), mech_table_get(&t, row, iy), wx, wy);
        }
        mech_table_free(&t);
    }
}

Test(sensitivity, an_unknown_parameter_is_an_error_naming_the_known_ones)
{
    mech_model *m = load_path("mechanisms/offset-slider-crank.yaml");
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_table t = {0};
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
    const char *name = "rr";
    cr_assert_eq(mech_sensitivity(m, NULL, 0, &o, &name, 1, &t, &d), MECH_EINPUT);
    cr_assert_geq(d.count, 1);
    cr_expect(strstr(d.entries[d.count - 1].message, "no parameter 'rr' in the file (its "
                                                     "parameters: r, l, e)"),
              "%s", d.entries[d.count - 1].message);
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* A model loaded from memory has no file to read again: its sensitivities
 * and tolerance columns come from the model's parameter expressions, the
 * same bit for bit as the file's (main read the file once per parameter
 * and failed here with an I/O error). */
static void memory_and_file_columns(const char *text, const char *path, int tolerances)
{
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f);
    fputs(text, f);
    fclose(f);
    mech_model *mem = NULL, *file = NULL;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_load_string(text, strlen(text), "<memory>", &mem, &d), MECH_OK);
    cr_assert_eq(mech_load_file(path, &file, &d), MECH_OK);
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_table tm = {0}, tf = {0};
    cr_assert_eq(mech_solve(mem, &o, &tm, NULL, &d), MECH_OK);
    cr_assert_eq(mech_solve(file, &o, &tf, NULL, &d), MECH_OK);
    static const char *const names[] = {"r", "l"};
    int rm = tolerances ? mech_tolerances(mem, NULL, 0, &o, &tm, &d)
                        : mech_sensitivity(mem, NULL, 0, &o, names, 2, &tm, &d);
    if (rm != MECH_OK)
        mech_diag_print(&d, stderr);
    cr_assert_eq(rm, MECH_OK, "the model from memory: status %d", rm);
    int rf = tolerances ? mech_tolerances(file, NULL, 0, &o, &tf, &d)
                        : mech_sensitivity(file, NULL, 0, &o, names, 2, &tf, &d);
    cr_assert_eq(rf, MECH_OK);
    cr_assert_eq(tm.ncolumns, tf.ncolumns);
    cr_assert_eq(tm.nrows, tf.nrows);
    int derived = 0;
    for (int c = 0; c < tm.ncolumns; c++) {
        cr_assert_str_eq(tm.columns[c].name, tf.columns[c].name);
        derived += strncmp(tm.columns[c].name, tolerances ? "worst(" : "d(", tolerances ? 6 : 2) == 0;
    }
    cr_assert_gt(derived, 4, "%d derived columns", derived);
    cr_assert(memcmp(tm.values, tf.values, (size_t)tm.nrows * tm.ncolumns * sizeof *tm.values) == 0,
              "the columns of the model from memory differ from the file's");
    mech_table_free(&tm);
    mech_table_free(&tf);
    mech_diag_free(&d);
    mech_model_free(&mem);
    mech_model_free(&file);
    remove(path);
}

Test(sensitivity, a_model_from_memory_has_the_files_columns_bit_for_bit)
{
    static const char text[] =
        "name: offset slider-crank from memory\n"
        "units: {length: mm, angle: deg}\n"
        "parameters: {r: {value: 40 mm, tolerance: 0.05 mm}, l: {value: 3*r, tolerance: 0.1 mm},"
        " e: 10 mm}\n"
        "ground: {O: [0, 0], G: [0, e]}\n"
        "links:\n"
        "  crank: {points: {O: [0, 0], A: {length: r, angle: 30}}}\n"
        "  rod: {points: {A: [0, 0], B: [l, 0]}}\n"
        "  block: {points: {B: [0, 0]}}\n"
        "joints:\n"
        "  - {slider: B, link: block, on: ground, through: G, angle: 0}\n"
        "driver: {link: crank, angle: {from: 0, to: 360, steps: 36}, speed: 10 rad/s}\n"
        "outputs: {points: [A, B], links: [rod], sliders: [s_B]}\n";
    memory_and_file_columns(text, "build/test_sensitivity_memory.yaml", 0);
    memory_and_file_columns(text, "build/test_sensitivity_memory.yaml", 1);
}

/* ---- tolerance stack-up against a Monte Carlo sweep -------------------- */

/* The offset slider-crank with r = 40 +- 0.05 mm and l = 120 +- 0.1 mm. */
static const char *toleranced_path(void)
{
    static const char path[] = "build/test_sensitivity_tol.yaml";
    FILE *in = fopen("mechanisms/offset-slider-crank.yaml", "r"), *out = fopen(path, "w");
    cr_assert(in && out);
    char line[512];
    while (fgets(line, sizeof line, in)) {
        if (strncmp(line, "  r: 40 mm", 10) == 0)
            fputs("  r: {value: 40 mm, tolerance: 0.05 mm}\n", out);
        else if (strncmp(line, "  l: 120 mm", 11) == 0)
            fputs("  l: {value: 120 mm, tolerance: 0.1 mm}\n", out);
        else
            fputs(line, out);
    }
    fclose(in);
    fclose(out);
    return path;
}

static uint64_t lcg = 20261125;
static double uniform(void)  /* in [-1, 1), seeded: the test is reproducible */
{
    lcg = lcg * 6364136223846793005u + 1442695040888963407u;
    return (double)(lcg >> 11) / 4503599627370496.0 - 1.0;
}

/* worst(x_B.s) bounds every sample's deviation and is nearly reached at the
 * corners; the samples' standard deviation is RSS/sqrt(3) (uniform errors
 * of half-width tol have standard deviation tol/sqrt(3)): 10^4 samples give
 * it to about 1 % (the 5 % bound has margin). First order: the second-order
 * terms, about tol^2/l = 1e-7 of the deviations, are inside the margins. */
Test(sensitivity, stackup_bounds_a_monte_carlo_sweep_of_10000_samples, .timeout = 120)
{
    enum { N = 10000, STEPS = 24 };
    const char *path = toleranced_path();
    mech_model *m = load_path(path);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.has_range = 1;
    o.from = 0;
    o.to = 2 * 3.14159265358979323846;
    o.steps = STEPS;
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
    cr_assert_eq(mech_tolerances(m, NULL, 0, &o, &t, &d), MECH_OK);
    int xs = mech_table_column(&t, "x_B.s"), wc = mech_table_column(&t, "worst(x_B.s)");
    int rc = mech_table_column(&t, "rss(x_B.s)");
    cr_assert(xs >= 0 && wc >= 0 && rc >= 0);
    load_doc *doc = NULL;
    cr_assert_eq(load_doc_read(path, &doc, &d), MECH_OK);
    static double maxdev[STEPS + 1], sum2[STEPS + 1];
    for (int i = 0; i < N; i++) {
        char rt[64], lt[64];
        snprintf(rt, sizeof rt, "%.17g mm", 40 + 0.05 * uniform());
        snprintf(lt, sizeof lt, "%.17g mm", 120 + 0.1 * uniform());
        mech_override ov[2] = {{"r", rt}, {"l", lt}};
        mech_model *v = NULL;
        mech_table s = {0};
        cr_assert_eq(load_doc_model(doc, ov, 2, &v, &d), MECH_OK);
        cr_assert_eq(mech_solve(v, &o, &s, NULL, &d), MECH_OK);
        for (int r = 0; r <= STEPS; r++) {
            double dev = mech_table_get(&s, r, xs) - mech_table_get(&t, r, xs);
            maxdev[r] = fmax(maxdev[r], fabs(dev));
            sum2[r] += dev * dev;
        }
        mech_table_free(&s);
        mech_model_free(&v);
    }
    for (int r = 0; r <= STEPS; r++) {
        double worst = mech_table_get(&t, r, wc), rss = mech_table_get(&t, r, rc);
        double sigma = sqrt(sum2[r] / N);
        cr_expect_leq(maxdev[r], worst * 1.001 + 1e-12, "row %d: a sample deviates %.6g, worst "
                      "case %.6g", r, maxdev[r], worst);
        cr_expect_geq(maxdev[r], 0.9 * worst, "row %d: largest sample %.6g, worst case %.6g",
                      r, maxdev[r], worst);
        cr_expect(fabs(sigma - rss / sqrt(3.0)) <= 0.05 * rss / sqrt(3.0),
                  "row %d: sample sigma %.6g, RSS/sqrt(3) %.6g", r, sigma, rss / sqrt(3.0));
    }
    load_doc_free(&doc);
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}
